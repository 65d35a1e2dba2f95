"""The 12-DOF quadruped with POPI's leg geometry (seeds 004 + 002).

The package is the mechanism: its registry entry (``spec``), its geometry (``Geometry``), its kinematics
(``fk``, ``jacobian``, ``ik``, ``ik_all``, ... re-exported here from :mod:`legkin.quadruped.kinematics`,
imported on first use so that ``import legkin`` stays light: no numba), the helpers of ``configuration``,
the ``contract`` of the generic test, its checks against Pinocchio (``checks``), bench (``bench``), figures
(``figures``) and clips (``clips``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from .spec import SPEC as SPEC

if TYPE_CHECKING:  # the names a type checker and an IDE see; at run time they load on first use
    from . import kinematics as kinematics
    from .kinematics import *  # noqa: F403

_SUBMODULES = (
    "kinematics", "geometry", "constants", "forward", "closed_form", "inverse", "repair", "limits", "textbook",
    "deprecated", "configuration", "contract", "checks", "bench", "figures", "clips",
)
#: Names served without importing the kernels (numba).
_LIGHT = {"Geometry": "geometry", "DEFAULT_GEOMETRY": "geometry"}


def __getattr__(name: str) -> Any:
    """The lazy re-export; a name found once is kept in the package's namespace, so that later look-ups
    (``quadruped.fk`` in a loop) are plain attribute reads and not a ~5 us trip through here."""
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _LIGHT:
        value = getattr(importlib.import_module(f"{__name__}.{_LIGHT[name]}"), name)
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
