"""The 12-DOF quadruped with POPI's leg geometry (seeds 004 + 002).

The package is the mechanism: its registry entry (``spec``), its geometry (``Geometry``), its kinematics
(``fk``, ``jacobian``, ``ik``, ``ik_all``, ... re-exported here from :mod:`legkin.quadruped.kinematics`,
imported on first use so that ``import legkin`` stays light: no numba), the helpers of ``configuration``,
the ``contract`` of the generic test, its checks against Pinocchio (``checks``), bench (``bench``), figures
(``figures``) and clips (``clips``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_exports
from .spec import SPEC as SPEC

if TYPE_CHECKING:  # the names a type checker and an IDE see; at run time they load on first use
    from . import kinematics as kinematics
    from .kinematics import *  # noqa: F403

_SUBMODULES = (
    "kinematics", "geometry", "constants", "measured", "textbook", "configuration", "contract", "checks", "bench",
    "figures", "clips",
)
#: Names served without importing the kernels (numba).
_LIGHT = {"Geometry": "geometry", "DEFAULT_GEOMETRY": "geometry"}

__getattr__, __dir__ = lazy_exports(__name__, globals(), _SUBMODULES, _LIGHT)
