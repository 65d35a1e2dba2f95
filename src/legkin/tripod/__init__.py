"""The 2-DOF constant-velocity parallel wrist (tripod, seed 000).

The package is the mechanism: its registry entry (``spec``), its ``Geometry`` (``geometry``), its kinematics
(re-exported here from ``kinematics``, imported on first use so that ``import legkin`` stays light; split by concept
into ``legs``, ``platform``, ``closure``, ``inverse``, ``forward_kernels``, ``forward``, ``reachable``), the helpers of
``configuration``, its contract (``contract``), checks against Pinocchio (``checks``), bench (``bench``), figures
(``figures``) and clips (``clips``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .spec import SPEC as SPEC

if TYPE_CHECKING:  # the names a type checker and an IDE see; at run time they load on first use
    from . import kinematics as kinematics
    from .kinematics import *  # noqa: F403

_SUBMODULES = ("kinematics", "geometry", "configuration", "contract", "checks", "bench", "figures", "clips")


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    kinematics = importlib.import_module(f"{__name__}.kinematics")
    if name == "__all__":
        return ["SPEC", *kinematics.__all__]
    if name in kinematics.__all__:
        value = getattr(kinematics, name)
        globals()[name] = value  # later look-ups skip this function
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBMODULES) | set(importlib.import_module(f"{__name__}.kinematics").__all__))
