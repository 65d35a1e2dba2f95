"""Wheel-leg geometry: the design constants, :class:`Geometry` (the xacro arguments that matter to the
kinematics) and the leg names."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Mapping

import numpy as np

from ..errors import InvalidParameterError, JointLimitError
from .spec import SPEC
from .spec import TYRE_THICKNESS as TYRE_THICKNESS  # the tyre offset, defined beside the mesh section it sizes

LEGS = ("FL", "FR", "RR", "RL")
THETA0 = math.radians(17.0)
THETA_MIN = math.radians(17.0)
THETA_MAX = math.radians(160.0)
#: Half-angle of the seed's toe arc (rad).
PSI_FG = math.radians(40.0)

_ARC_HF = math.radians(130.0)
_ARC_BC = math.radians(101.0)
_ARC_FG = math.pi - _ARC_HF  # 50 deg: each lower rim
_J_ANGLE = math.radians(140.0)  # J = U + r exp(i (140 deg + arg(H - U)))


@dataclass(frozen=True)
class Geometry:
    """Parameters of the wheel-leg robot (the xacro arguments that matter to kinematics).

    Attributes:
        R: wheel pitch radius (m); every linkage length is proportional to it.
        L_body: wheel base, front to rear module origin (m).
        W_body: hip-to-hip width (m).
        d_abad: height of the module origins above {R} (m).
        d_wheel: offset of the leg plane from the module origin along x_M (m).
        T: rim thickness (m); the lateral contact coordinate w is in [-T/2, T/2].
    """

    R: float = 0.1
    L_body: float = 0.51
    W_body: float = 0.24
    d_abad: float = 0.057166
    d_wheel: float = 0.091675
    T: float = 0.04

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, float(SPEC.params[f.name].check(f.name, getattr(self, f.name))))
        # the kernels' constants are cached per geometry: hash once (a dataclass hashes its fields every time)
        object.__setattr__(self, "_hash", hash(tuple(getattr(self, f.name) for f in fields(self))))

    def __hash__(self) -> int:
        return self._hash  # type: ignore[attr-defined, no-any-return]

    @classmethod
    def from_params(cls, params: Mapping[str, object] | None) -> "Geometry":
        """Build from a mapping (e.g. ``Robot.params``); keys that are not kinematic are ignored."""
        if params is None:
            return cls()
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in params.items() if k in names})  # type: ignore[arg-type]


def _geometry(geometry) -> Geometry:
    """``geometry`` or the default; anything but a :class:`Geometry` is refused."""
    if geometry is None:
        return _DEFAULT_GEOMETRY
    if not isinstance(geometry, Geometry):
        raise InvalidParameterError(f"geometry must be a wheel_leg.Geometry, got {type(geometry).__name__}")
    return geometry


_DEFAULT_GEOMETRY = Geometry()


def _leg(leg) -> tuple[int, str, float]:
    """(index, side "L"/"R", sx) of a leg given by name or index."""
    if isinstance(leg, (int, np.integer)) and not isinstance(leg, bool) and 0 <= int(leg) < 4:
        i = int(leg)
    elif isinstance(leg, str) and leg in LEGS:
        i = LEGS.index(leg)
    else:
        raise InvalidParameterError(f"leg must be one of {', '.join(LEGS)} or an index 0-3, got {leg!r}")
    return i, ("L" if i in (0, 3) else "R"), (1.0 if i in (0, 1) else -1.0)




#: ABAD joint limit (rad): the URDF's ``<leg>_abad`` joints range over [-ABAD_LIMIT, ABAD_LIMIT].
ABAD_LIMIT = math.pi / 2


def abad_limit_error(message: str, leg: object, target: np.ndarray, gamma: float,
                     closest: np.ndarray | None = None) -> JointLimitError:
    """The :class:`~legkin.errors.JointLimitError` of a target reached only with the ABAD angle ``gamma`` (rad)
    outside [-ABAD_LIMIT, ABAD_LIMIT]: ``joint`` is the URDF joint ``<leg>_abad``."""
    distance = float(np.linalg.norm(np.asarray(closest) - target)) if closest is not None else math.nan
    return JointLimitError(message, target=target, closest=closest, distance=distance,
                           joint=f"{LEGS[_leg(leg)[0]]}_abad", value=float(gamma), lower=-ABAD_LIMIT, upper=ABAD_LIMIT)
#: Beyond a limit by at most this (rad) counts as on it (the answer is clipped onto the limit).
_LIMIT_ROUNDING = 1e-12

