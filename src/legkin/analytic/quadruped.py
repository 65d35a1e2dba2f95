"""Deprecated alias of :mod:`legkin.quadruped` (kept for one release)."""

import warnings as _warnings

from ..quadruped import kinematics as _kinematics
from ..quadruped.kinematics import *  # noqa: F403

_warnings.warn(
    "legkin.analytic.quadruped is deprecated; use `from legkin import quadruped`", DeprecationWarning, stacklevel=2
)


def __getattr__(name: str):
    return getattr(_kinematics, name)
