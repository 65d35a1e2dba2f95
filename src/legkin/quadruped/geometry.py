"""The quadruped's geometry: the xacro arguments that matter to its kinematics (``foot_z`` alone).

POPI's link offsets (X01, Y01, ... in :mod:`legkin.quadruped.constants`) are constants of the model, not
arguments. Importing this module does not import numba.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

from .._batch import real_number
from ..errors import InvalidParameterError
from .spec import SPEC

__all__ = ["Geometry", "DEFAULT_GEOMETRY"]

_FOOT_Z = SPEC.params["foot_z"]
# the fast path of the foot_z check: a float inside the registry's closed range is taken as it is
_FZ_LO = -math.inf if _FOOT_Z.low is None or _FOOT_Z.low_open else float(_FOOT_Z.low)
_FZ_HI = math.inf if _FOOT_Z.high is None or _FOOT_Z.high_open else float(_FOOT_Z.high)


def checked_foot_z(foot_z: object) -> float:
    """``foot_z`` as a float, checked against the registry's range (:data:`legkin.quadruped.spec.SPEC`).

    Raises:
        InvalidParameterError: not a real number (bool, str, complex, arrays refused), NaN/inf, or outside
            [-0.1, 0.1]; the message names the value and the range.
    """
    if type(foot_z) is float and _FZ_LO <= foot_z <= _FZ_HI:
        return foot_z
    value = _FOOT_Z.check("foot_z", real_number(foot_z, "foot_z", _FOOT_Z.range_text))
    assert isinstance(value, float)
    return value


@dataclass(frozen=True)
class Geometry:
    """The geometry of the quadruped's legs (the xacro arguments of :data:`legkin.quadruped.spec.SPEC`).

    Attributes:
        foot_z: the foot drop (m) below the knee-foot axis: seed 004's ``T34 = Tr(x34, 0, foot_z)``; xacro
            argument ``foot_z``, default 0 (POPI's own URDF: -0.015), range [-0.1, 0.1].

    Raises:
        InvalidParameterError: a value that is not a real number in its range (named with the range).
    """

    foot_z: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "foot_z", checked_foot_z(self.foot_z))

    @classmethod
    def from_params(cls, params: Mapping[str, object] | None) -> Geometry:
        """The geometry of a model's parameters (e.g. ``robot.params``); keys that are not kinematic are
        ignored, missing ones take the default. ``None``: the default geometry."""
        if params is None:
            return DEFAULT_GEOMETRY
        if not isinstance(params, Mapping):
            raise InvalidParameterError(f"params must be a mapping of xacro arguments, got {params!r}")
        if "foot_z" not in params:
            return DEFAULT_GEOMETRY
        return cls(foot_z=params["foot_z"])  # type: ignore[arg-type]  # checked in __post_init__


#: The default geometry (the xacro defaults): what ``geometry=None`` means.
DEFAULT_GEOMETRY = Geometry()
