"""Deprecated alias of :mod:`legkin.wheel_leg` (kept for one release)."""

import warnings as _warnings

from ..wheel_leg import kinematics as _kinematics
from ..wheel_leg.kinematics import *  # noqa: F403

_warnings.warn(
    "legkin.analytic.wheel_leg is deprecated; use `from legkin import wheel_leg`", DeprecationWarning, stacklevel=2
)


def __getattr__(name: str):
    return getattr(_kinematics, name)
