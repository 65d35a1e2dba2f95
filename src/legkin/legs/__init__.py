"""Exact leg kinematics measured from any URDF: HAA-HFE-KFE legs (issue 13) and 6-DOF humanoid legs (issue 26).

>>> from legkin import legs
>>> model, urdf, dirs = legs.load_erd("go2")
>>> go2 = legs.from_model(model)            # {"FL": Leg, "FR": Leg, "RL": Leg, "RR": Leg}
>>> q = go2["FL"].ik([0.19, 0.14, -0.3])    # the branch inside the URDF limits
>>> talos = legs.from_model(legs.load_erd("talos")[0])   # {"leg_left": Leg6, "leg_right": Leg6}

Modules: :mod:`.kinematics` (the :class:`Leg`; its compiled kernels in :mod:`._fk_kernels` (forward map, Jacobian)
and :mod:`._ik_kernels` (closed-form IK, Newton polish), constants in :mod:`._layout`), :mod:`.sixdof` (the
:class:`Leg6`; kernels in :mod:`._sixdof_kernels` (forward map, Jacobian, polish, the spherical hip's closed form),
:mod:`._search_kernels` (the one-dimensional searches), :mod:`._ik6_kernels` (every solution, the one inside the
limits); the subproblems SP1-SP4 in :mod:`.subproblems`, constants in :mod:`._sixdof_layout`), :mod:`.extract`
(finding and measuring legs in a Pinocchio model), :mod:`.erd` (the legged robots of example-robot-data),
:mod:`.registry`, :mod:`.checks` / :mod:`.checks6` (rows of ``legkin check``), :mod:`.bench` / :mod:`.bench6`,
:mod:`.clips` (``feet_circles``, ``squat``), :mod:`.figures`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # at run time the names load on first use: `import legkin` (its registry) imports no numba
    from .erd import (
        ERD_ALL,
        ERD_BIPEDS,
        ERD_ROBOTS,
        ErdRobot,
        erd_files,
        external_models,
        load_erd,
        reference_configuration,
    )
    from .extract import find_chains, from_model, from_urdf
    from .kinematics import BRANCHES, Leg, LegStructureError
    from .registry import erd_spec
    from .sixdof import Leg6

_WHERE = {
    "ERD_ROBOTS": "erd", "ERD_BIPEDS": "erd", "ERD_ALL": "erd", "ErdRobot": "erd", "erd_files": "erd",
    "external_models": "erd", "load_erd": "erd",
    "reference_configuration": "erd", "find_chains": "extract", "from_model": "extract", "from_urdf": "extract",
    "BRANCHES": "kinematics", "Leg": "kinematics", "LegStructureError": "kinematics", "erd_spec": "registry",
    "Leg6": "sixdof",
}

__all__ = [
    "Leg",
    "Leg6",
    "LegStructureError",
    "BRANCHES",
    "from_model",
    "from_urdf",
    "find_chains",
    "ERD_ROBOTS",
    "ERD_BIPEDS",
    "ERD_ALL",
    "ErdRobot",
    "erd_files",
    "load_erd",
    "reference_configuration",
    "external_models",
    "erd_spec",
]


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
