"""The Corgi leg-wheel robot of BioRoLa (wheel-leg, seed 001).

The package is the mechanism: its registry entry (``spec``), its geometry (``geometry``), its kinematics
(``linkage``, ``rim``, ``frames``, ``inverse``, ``ik_radial``, ``ik_iterative``; the tyre surface ``tyre``; the
ground contact and stance IK ``ground``; the public API re-exported by ``kinematics`` and here, imported on first
use so that ``import legkin`` stays light), helpers (``configuration``), its contract (``contract``), its checks
against Pinocchio (``checks``, ``tyre_checks``), bench (``bench``), figures (``figures``, ``tyre_figures``) and
clips (``clips``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_exports
from .spec import SPEC as SPEC

if TYPE_CHECKING:  # the names a type checker and an IDE see; at run time they load on first use
    from . import kinematics as kinematics
    from .kinematics import *  # noqa: F403

_SUBMODULES = (
    "kinematics", "geometry", "linkage", "rim", "frames", "inverse", "ik_radial", "ik_iterative", "configuration",
    "contract", "checks", "bench", "figures", "clips", "tyre", "ground", "stance", "tyre_checks",
    "tyre_figures",
)


#: Names served without importing the kernels (numba).
_LIGHT = {"Geometry": "geometry"}

__getattr__, __dir__ = lazy_exports(__name__, globals(), _SUBMODULES, _LIGHT)
