"""Deprecated alias of :mod:`legkin.hybrid_leg` (kept for one release)."""

import warnings as _warnings

from ..hybrid_leg import kinematics as _kinematics
from ..hybrid_leg.kinematics import *  # noqa: F403

_warnings.warn(
    "legkin.analytic.hybrid_leg is deprecated; use `from legkin import hybrid_leg`", DeprecationWarning, stacklevel=2
)


def __getattr__(name: str):
    return getattr(_kinematics, name)
