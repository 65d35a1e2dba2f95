"""Deprecated alias of :mod:`legkin.tripod` (kept for one release)."""

import warnings as _warnings

from ..tripod import kinematics as _kinematics
from ..tripod.kinematics import *  # noqa: F403

_warnings.warn(
    "legkin.analytic.tripod is deprecated; use `from legkin import tripod`", DeprecationWarning, stacklevel=2
)


def __getattr__(name: str):
    return getattr(_kinematics, name)
