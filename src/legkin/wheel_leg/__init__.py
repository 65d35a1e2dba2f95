"""The Corgi leg-wheel robot of BioRoLa (wheel-leg, seed 001).

The package is the mechanism: its registry entry (``spec``), its geometry (``geometry``), its kinematics (``linkage``,
``rim``, ``frames``, ``inverse``, ``ik_radial``, ``ik_iterative``; the public API re-exported by ``kinematics`` and
here, imported on first use so that ``import legkin`` stays light), helpers (``configuration``), its contract
(``contract``), its checks against Pinocchio (``checks``), bench (``bench``), figures (``figures``) and clips
(``clips``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .spec import SPEC as SPEC

if TYPE_CHECKING:  # the names a type checker and an IDE see; at run time they load on first use
    from . import kinematics as kinematics
    from .kinematics import *  # noqa: F403

_SUBMODULES = (
    "kinematics", "geometry", "linkage", "rim", "frames", "inverse", "ik_radial", "ik_iterative", "configuration",
    "contract", "checks", "bench", "figures", "clips",
)


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    kinematics = importlib.import_module(f"{__name__}.kinematics")
    if name == "__all__":
        return ["SPEC", *kinematics.__all__]
    if name in kinematics.__all__:
        return getattr(kinematics, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBMODULES) | set(importlib.import_module(f"{__name__}.kinematics").__all__))
