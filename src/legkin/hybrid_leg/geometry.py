"""The hybrid leg's geometry (seed 003): the fixed constants of the mechanism, its tolerances and limits, and
:class:`Geometry`, the xacro arguments that matter to the kinematics.

Conventions (closed-chain frame ``CCS``; metres, radians):

* platform ``P`` on the central joint ``LCS`` at :data:`CENTER`; with the default universal centre
  ``R_P = Rx(roll) Ry(pitch)`` (first axis x fixed in CCS, then y), joints ``LCS_x``, ``LCS_y``;
* motor chains ``i = 1, 2`` (index 0, 1 here, sign ``sigma = +1, -1``): base frame at :data:`MOTOR_POS`
  ``[i]`` rotated ``Rz(sigma * BETA)`` (seed eqs 5, 12, re-orthonormalised), motor ``Rz(theta_i)``
  about the base z (eqs 6, 13), lever tip ``S_i = p_i + Rz(sigma BETA + theta_i) LEVER`` (eqs 7, 14),
  rod of length :data:`ROD_LENGTH` (eqs 8, 15) to the platform point ``A_i = CENTER + R_P ATTACH[i]``
  (eqs 9, 16);
* motor branches ``branch = (b1, b2)``, each ``+1`` or ``-1``; ``+1`` is the branch of the neutral pose
  (R_P = I at theta1 = -theta2 = +18.255 deg), ``-1`` the other solution of the same rod-length
  equation (R_P = I at theta1 = -theta2 = -82.217 deg);
* open sub-chain (eqs 17, 18, 20): joint ``LL`` at :data:`LL_ORIGIN` in P, ``Ry(theta_LL)``, foot ``FCS`` at
  ``(FOOT_X, 0, 0)`` in the LL frame; ``theta_LL = -RATIO * theta0 + starting_value`` (eq 19 without its
  OCR artefact) with ``theta0`` the leg-extension motor angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import InvalidArgumentError

__all__ = [
    "Geometry", "CENTER", "BETA", "MOTOR_POS", "MOTOR_YAW", "LEVER", "ROD_LENGTH", "ATTACH", "LL_ORIGIN", "FOOT_X",
    "SCREW_LEAD", "ARC_RADIUS", "RATIO", "MOTOR_BRANCHES", "FOOT_IK_BRANCHES", "LL_DELTA", "K_TOL", "IK_K_TOL",
    "CLIP_FOOT_TOL", "BOUNDARY_TOL", "LL_TOL", "RHO_TOL", "PLATFORM_LIMIT", "LL_LIMIT", "MOTOR_LIMIT", "FK_GAIN_MAX",
    "PITCH_SPLIT", "FOOT_IK_ORDER",
]

# ----------------------------------------------------------------------------- fixed geometry (seed 003)
#: Centre of the central joint LCS in CCS (eq 2's translation).
CENTER = np.array([0.265, 0.0, 0.014])
#: Yaw of the motor base frames (rad): the printed positions lie at exactly 21.4745 deg
#: (atan2(0.0549998406976098, 0.139807669447128)); eqs 5 and 12 print its cosine/sine rounded to 4 digits.
BETA = math.radians(21.4745)
#: Motor base origins in CCS (eqs 5, 12), chain 1 then chain 2.
MOTOR_POS = np.array([[0.139807669447128, 0.0549998406976098, -0.051],
                      [0.139807669447128, -0.0549998406976098, -0.051]])
#: Base yaw of each motor: Rz(+BETA) for MCS1, Rz(-BETA) for MCS2.
MOTOR_YAW = np.array([BETA, -BETA])
#: Lever from the motor axis to the first spherical joint, in the motor frame (eqs 7, 14).
LEVER = np.array([0.085, 0.0, -0.0245])
#: Coupling rod length, sphere to sphere (eqs 8, 15).
ROD_LENGTH = 0.11
#: Rod attachment points in P (eqs 9, 16 inverted: the seed gives P in the rod-end sphere frame).
ATTACH = np.array([[0.015, 0.029, -0.0965], [0.015, -0.029, -0.0965]])
#: LL joint origin in P (eq 18).
LL_ORIGIN = np.array([1.640, 0.0, -0.037])
#: Foot frame FCS along the LL frame's x (eq 20).
FOOT_X = -1.5
#: Eq 19: linear travel per extension-motor revolution (m) and the arc radius it is applied on (m).
SCREW_LEAD = 0.07
ARC_RADIUS = 1.5
#: theta_LL per radian of theta0 (with a minus sign in eq 19): 0.07 / (2 pi 1.5).
RATIO = SCREW_LEAD / (2.0 * math.pi * ARC_RADIUS)

#: Motor branch pairs (b1, b2).
MOTOR_BRANCHES = ((1, 1), (1, -1), (-1, 1), (-1, -1))
#: Branch order of :func:`~legkin.hybrid_leg.ik_all`: (ll_branch, roll_branch, b1, b2).
FOOT_IK_BRANCHES = tuple((ll, rb, b1, b2) for ll in (-1, 1) for rb in (1, -1) for (b1, b2) in MOTOR_BRANCHES)

# LL closed form: |f_P|^2 = LL0^2 + h^2 - 2 h LL0 cos(theta_LL - LL_DELTA), h = |FOOT_X|.
LL0 = math.hypot(LL_ORIGIN[0], LL_ORIGIN[2])
#: theta_LL (rad) at which the foot is nearest the LCS centre: the two LL branches of the IK meet there.
LL_DELTA = math.atan2(-LL_ORIGIN[2], LL_ORIGIN[0])
#: Reach tolerance of the LL arc (as :data:`K_TOL` for the motor chains): |cos(theta_LL - LL_DELTA)| up to
#: 1 + LL_TOL is reachable (~1e-12 m at the arc's ends).
LL_TOL = 1e-12
H = abs(FOOT_X)

# ----------------------------------------------------------------------------- tolerances and limits
#: Reach tolerance: a chain whose reach ratio |k| (see :func:`~legkin.hybrid_leg.motor_angles`) exceeds 1 by at
#: most this counts as reachable, with acos(k) clipped (rounding at the reach boundary: a pose built on the boundary
#: gives |k| = 1 +- a few 1e-16; clipping 1e-14 leaves a rod-length error of ~1e-15 m).
K_TOL = 1e-14
#: The same for the IK: its platform pose, computed from a foot target, carries ~1e-14 of rounding in k (the foot is
#: up to 3 m from the centre). Clipping leaves a rod-length error; the IK keeps a clipped candidate only if the foot
#: error it implies (one Newton step of the rod equations, times the lever of the foot) is at most CLIP_FOOT_TOL.
IK_K_TOL = 1e-11
CLIP_FOOT_TOL = 1e-10
#: The forward kinematics labels a chain with 1 - |k| <= BOUNDARY_TOL (acos(k) <= 1.4e-5 rad) as on its reach
#: boundary, matching both motor branches: the motor angles the IK clips there give FK poses that close the chain
#: within ~1e-11 of |k| = 1 on either side.
BOUNDARY_TOL = 1e-10
#: Feet within this distance (m) of the roll axis (x through the LCS centre), but not exactly on it: the roll moves
#: the foot by at most 2 RHO_TOL, so the IK takes roll = 0 (roll_branch +1) or pi (-1).
RHO_TOL = 1e-12
#: URDF limits (rad): LCS_x and LCS_y (roll, pitch) in [-pi/2, pi/2], LL in [-pi, pi], MCS1/MCS2 in [-pi, pi].
#: (Sph_i_1_y is limited to [-pi/2, pi/2], which its closed form -asin(u_z) always meets.)
PLATFORM_LIMIT = math.pi / 2
LL_LIMIT = math.pi
MOTOR_LIMIT = math.pi
LIMIT_TOL = 1e-12
#: Forward-singularity band: where the foot moves more than this (m) per radian of the motors (spectral norm of
#: d(foot)/d(theta1, theta2)), double-precision motor angles fix the foot only to ~1e-15 x this; fk and ik refuse
#: such poses (SingularityError), so that every ik answer is reproduced by fk to better than 1e-10 m. Only the
#: neighbourhood of det N = 0 (the forward singularity) reaches it.
FK_GAIN_MAX = 1e4
#: In the assembly mode of the neutral pose on branch (1, 1) the platform's pitch stays below 0.9634 rad; a second
#: region of the same sign of det(dtheta/dx) lies at pitch >= 1.48 rad, separated from it by the other mode. A
#: pitch below PITCH_SPLIT puts a pose of that mode in the neutral aspect, where the motor map is one-to-one.
PITCH_SPLIT = 1.2
#: Order in which the default ik / foot_platform_ik try the two IK-only branches: (ll_branch, roll_branch).
FOOT_IK_ORDER = ((-1, 1), (1, 1), (-1, -1), (1, -1))

_CENTERS = ("universal", "spherical")


def _offset(value: object) -> float:
    """The LL zero offset as a float, or raise (the xacro argument's range, [-pi, pi] rad)."""
    x = math.nan
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_)):
        try:
            x = float(value)
        except (OverflowError, ValueError):
            x = math.nan
    if not (math.isfinite(x) and abs(x) <= math.pi):
        raise InvalidArgumentError(
            f"starting_value must be a finite real number in [-pi, pi] rad (the LL zero offset of eq 19, the xacro "
            f"argument's range), got {value!r}"
        )
    return x


@dataclass(frozen=True)
class Geometry:
    """The xacro arguments of the hybrid leg that matter to its kinematics (defaults = the xacro defaults).

    Attributes:
        center: the central joint LCS: ``"universal"`` (the physical 2-DOF platform, ``R_P = Rx(roll) Ry(pitch)``,
            default) or ``"spherical"`` (as the seed: one platform rotation left free with the motors locked, see
            :func:`~legkin.hybrid_leg.spherical_free_axis`; the forward kinematics and the mode-checked IK are
            those of the universal centre and refuse it).
        starting_value: the LL zero offset of eq 19 (rad, in [-pi, pi]):
            ``theta_LL = -RATIO * theta0 + starting_value``.

    Raises:
        InvalidParameterError: (an :class:`~legkin.errors.InvalidArgumentError`) a value out of its range.
    """

    center: str = "universal"
    starting_value: float = 0.0

    def __post_init__(self) -> None:
        if not (isinstance(self.center, str) and self.center in _CENTERS):
            raise InvalidArgumentError(f"center must be one of {', '.join(map(repr, _CENTERS))}, got {self.center!r}")
        object.__setattr__(self, "starting_value", _offset(self.starting_value))

    @classmethod
    def from_params(cls, params: Mapping[str, object] | None) -> Geometry:
        """The geometry of a loaded model's xacro arguments (e.g. ``robot.params``); other keys are ignored."""
        from .spec import SPEC

        if params is None:
            return cls()
        kw = {k: SPEC.params[k].check(k, params[k]) for k in ("center", "starting_value") if k in params}
        return cls(**kw)  # type: ignore[arg-type]


#: The default geometry (the xacro defaults).
DEFAULT = Geometry()
