"""The 2-RSS hybrid leg with an extension joint (seed 003).

The package is the mechanism: its registry entry (``spec``), its kinematics (re-exported here, imported on first use
so that ``import legkin`` stays light), its checks against Pinocchio (``checks``), bench (``bench``), figures
(``figures``) and clips (``clips``); its geometry (``geometry.Geometry``), configurations and samplers
(``configuration``) and its kinematic contract (``contract``).
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
    """The lazy re-export; a name found once is kept in the package's namespace (later look-ups are plain
    attribute reads, not a trip through here)."""
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name == "Geometry":  # light: no numba
        value = importlib.import_module(f"{__name__}.geometry").Geometry
    else:
        kinematics = importlib.import_module(f"{__name__}.kinematics")
        if name == "__all__":
            value = ["SPEC", *kinematics.__all__]
        elif name in kinematics.__all__:
            value = getattr(kinematics, name)
        else:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_SUBMODULES) | set(importlib.import_module(f"{__name__}.kinematics").__all__))
