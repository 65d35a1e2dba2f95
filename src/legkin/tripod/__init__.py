"""The 2-DOF constant-velocity parallel wrist (tripod, seed 000).

The package is the mechanism: its registry entry (``spec``), its ``Geometry`` (``geometry``), its kinematics
(re-exported here from ``kinematics``, imported on first use so that ``import legkin`` stays light; split by concept
into ``legs``, ``platform``, ``closure``, ``inverse``, ``forward_kernels``, ``forward``, ``reachable``), the helpers of
``configuration``, its contract (``contract``), checks against Pinocchio (``checks``), bench (``bench``), figures
(``figures``) and clips (``clips``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_exports
from .spec import SPEC as SPEC

if TYPE_CHECKING:  # the names a type checker and an IDE see; at run time they load on first use
    from . import kinematics as kinematics
    from .kinematics import *  # noqa: F403

_SUBMODULES = ("kinematics", "geometry", "configuration", "contract", "checks", "bench", "figures", "clips")


#: Names served without importing the kernels (numba).
_LIGHT = {"Geometry": "geometry"}

__getattr__, __dir__ = lazy_exports(__name__, globals(), _SUBMODULES, _LIGHT)
