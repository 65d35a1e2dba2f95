"""Closed-form kinematics of the hybrid leg: a 2-RSS + centre platform, its extension joint and foot (seed 003).

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
  OCR artefact) with ``theta0`` the leg-extension motor angle;
* assembly modes: the forward kinematics (:func:`platform_orientation`, :func:`foot_position`,
  :func:`foot_jacobian`) and the IK (:func:`foot_ik`) take ``branch`` and ``assembly`` (:func:`assembly_mode`),
  by default ``(1, 1)`` and ``+1``, the mode of the SRDF reference pose ``neutral``; the IK-only branches
  ``ll_branch``, ``roll_branch`` are searched in :data:`FOOT_IK_ORDER` (docs/hybrid_leg.md, "IK contract").

Every function takes arrays with leading batch dimensions. A single input (the core shape exactly)
returns plain arrays and raises on failure; a batch returns NaN where an item fails, and
``return_mask=True`` also returns the boolean mask of successes.
"""

from __future__ import annotations

import math
from typing import NamedTuple, Sequence

import numpy as np

from ..errors import (
    AssemblyModeError,
    ConvergenceError,
    InvalidInputError,
    InvalidParameterError,
    JointLimitError,
    SingularityError,
    UnreachableError,
)
from .._batch import as_angles, as_input, finish
from .._kernels import OK, batch_kernel, kernel, prange

__all__ = [
    "CENTER",
    "BETA",
    "MOTOR_POS",
    "MOTOR_YAW",
    "LEVER",
    "ROD_LENGTH",
    "ATTACH",
    "LL_ORIGIN",
    "FOOT_X",
    "SCREW_LEAD",
    "ARC_RADIUS",
    "RATIO",
    "MOTOR_BRANCHES",
    "FOOT_IK_BRANCHES",
    "LL_DELTA",
    "ll_angle",
    "extension_motor_angle",
    "platform_rotation",
    "rod_spans",
    "motor_angles",
    "motor_angles_from_rotation",
    "motor_jacobian",
    "sphere_joint_angles",
    "platform_orientation",
    "foot_position_from_platform",
    "foot_position",
    "foot_platform_ik",
    "foot_ik",
    "foot_jacobian",
    "spherical_free_axis",
    "K_TOL",
    "IK_K_TOL",
    "CLIP_FOOT_TOL",
    "BOUNDARY_TOL",
    "LL_TOL",
    "RHO_TOL",
    "PLATFORM_LIMIT",
    "LL_LIMIT",
    "MOTOR_LIMIT",
    "FK_GAIN_MAX",
    "PITCH_SPLIT",
    "FOOT_IK_ORDER",
    "assembly_mode",
    "platform_poses",
    "PlatformPoses",
    "foot_ik_solutions",
    "FootIKSolutions",
]

# ----------------------------------------------------------------------------- geometry (seed 003)
#: Centre of the central joint LCS in CCS (eq 2's translation).
CENTER = np.array([0.265, 0.0, 0.014])
#: Yaw of the motor base frames (rad): the printed positions lie at exactly 21.4745 deg
#: (atan2(0.0549998406976098, 0.139807669447128)); eqs 5 and 12 print its cosine/sine rounded to 4 digits.
BETA = math.radians(21.4745)
#: Motor base origins in CCS (eqs 5, 12), chain 1 then chain 2.
MOTOR_POS = np.array([[0.139807669447128, 0.0549998406976098, -0.051], [0.139807669447128, -0.0549998406976098, -0.051]])
#: Base yaw of each motor: Rz(+BETA) for MCS1, Rz(-BETA) for MCS2.
MOTOR_YAW = np.array([BETA, -BETA])
_SIGMA = np.array([1.0, -1.0])
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
#: Branch order of ``foot_ik(..., all_branches=True)``: (ll_branch, roll_branch, b1, b2).
FOOT_IK_BRANCHES = tuple((ll, rb, b1, b2) for ll in (-1, 1) for rb in (1, -1) for (b1, b2) in MOTOR_BRANCHES)

# LL closed form: |f_P|^2 = LL0^2 + h^2 - 2 h LL0 cos(theta_LL - LL_DELTA), h = |FOOT_X|.
_LL0 = math.hypot(LL_ORIGIN[0], LL_ORIGIN[2])
#: theta_LL (rad) at which the foot is nearest the LCS centre: the two LL branches of foot_ik meet there.
LL_DELTA = math.atan2(-LL_ORIGIN[2], LL_ORIGIN[0])
_H = abs(FOOT_X)


#: Reach tolerance: a chain whose reach ratio |k| (see :func:`motor_angles`) exceeds 1 by at most this counts
#: as reachable, with acos(k) clipped (rounding at the reach boundary: a pose built on the boundary gives
#: |k| = 1 +- a few 1e-16; clipping 1e-14 leaves a rod-length error of ~1e-15 m).
K_TOL = 1e-14
#: The same for foot_ik: its platform pose, computed from a foot target, carries ~1e-14 of rounding in k (the
#: foot is up to 3 m from the centre). Clipping leaves a rod-length error; foot_ik keeps a clipped candidate only if
#: the foot error it implies (one Newton step of the rod equations, times the lever of the foot) is at most
#: CLIP_FOOT_TOL.
IK_K_TOL = 1e-11
CLIP_FOOT_TOL = 1e-10
#: The forward kinematics labels a chain with 1 - |k| <= BOUNDARY_TOL (acos(k) <= 1.4e-5 rad) as on its reach
#: boundary, matching both motor branches: the motor angles foot_ik clips there give FK poses that close the chain
#: within ~1e-11 of |k| = 1 on either side.
BOUNDARY_TOL = 1e-10
#: The same for the LL arc: |cos(theta_LL - LL_DELTA)| up to 1 + LL_TOL is reachable (~1e-12 m at the arc's ends).
LL_TOL = 1e-12
#: Feet within this distance (m) of the roll axis (x through the LCS centre), but not exactly on it: the roll
#: moves the foot by at most 2 RHO_TOL, so foot_ik and foot_platform_ik take roll = 0 (roll_branch +1) or pi (-1).
RHO_TOL = 1e-12
#: URDF limits (rad): LCS_x and LCS_y (roll, pitch) in [-pi/2, pi/2], LL in [-pi, pi], MCS1/MCS2 in [-pi, pi].
#: (Sph_i_1_y is limited to [-pi/2, pi/2], which its closed form -asin(u_z) always meets.)
PLATFORM_LIMIT = math.pi / 2
LL_LIMIT = math.pi
MOTOR_LIMIT = math.pi
_LIMIT_TOL = 1e-12
#: Forward-singularity band: where the foot moves more than this (m) per radian of the motors (spectral norm of
#: d(foot)/d(theta1, theta2)), double-precision motor angles fix the foot only to ~1e-15 x this; foot_position
#: and foot_ik refuse such poses (SingularityError), so that every foot_ik answer is reproduced by foot_position
#: to better than 1e-10 m. Only the neighbourhood of det N = 0 (the forward singularity) reaches it.
FK_GAIN_MAX = 1e4
#: In the assembly mode of the neutral pose on branch (1, 1) the platform's pitch stays below 0.9634 rad; a second
#: region of the same sign of det(dtheta/dx) lies at pitch >= 1.48 rad, separated from it by the other mode. A
#: pitch below PITCH_SPLIT puts a pose of that mode in the neutral aspect, where the motor map is one-to-one.
PITCH_SPLIT = 1.2
#: Order in which the default foot_ik / foot_platform_ik try the two IK-only branches: (ll_branch, roll_branch).
FOOT_IK_ORDER = ((-1, 1), (1, 1), (-1, -1), (1, -1))
_FOOT_IK_COMBOS = np.array(FOOT_IK_ORDER, dtype=np.float64)


def _wrap(a):
    """Wrap angles to (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


class InvalidArgumentError(InvalidParameterError, InvalidInputError):
    """A keyword argument of the wrong kind or out of range.

    Both an :class:`InvalidParameterError` and an :class:`InvalidInputError` (hence a ``ValueError``).
    """


def _is_int(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _is_real(value) -> bool:
    return (_is_int(value) or isinstance(value, (float, np.floating))) and not isinstance(value, (bool, np.bool_))


def _to_float(value) -> float:
    """float(value) for a real scalar, NaN for anything else (including ints too large for a float)."""
    if not _is_real(value):
        return math.nan
    try:
        return float(value)
    except (OverflowError, ValueError, TypeError):
        return math.nan


def _check_branch(branch) -> np.ndarray:
    """Motor branch pair (b1, b2), each +1 or -1, as a float array."""
    b = None
    if not isinstance(branch, (str, bytes)):
        try:
            raw = np.asarray(branch)
        except (TypeError, ValueError):
            raw = None
        if raw is not None and raw.dtype.kind in "iuf" and raw.shape == (2,) and np.all(np.abs(raw) == 1):
            b = raw.astype(float)
    if b is None:
        raise InvalidArgumentError(
            f"branch must be one of {', '.join(map(str, MOTOR_BRANCHES))} (b1, b2: the motor branch of each chain), "
            f"got {branch!r}"
        )
    return b


def _check_sign(value, name: str, allow_none: bool = False):
    """+1 or -1 (as float), or None if allowed."""
    if value is None and allow_none:
        return None
    if _is_real(value) and value in (1, -1):
        return float(value)
    valid = "+1 or -1" + (" (or None: try both, see FOOT_IK_ORDER)" if allow_none else "")
    raise InvalidArgumentError(f"{name} must be {valid}, got {value!r}")


def _check_assembly(value) -> float:
    if _is_real(value) and value in (1, -1):
        return float(value)
    raise InvalidArgumentError(
        f"assembly must be +1 (the assembly mode of the neutral pose, R_P = I, on the given branch) or -1 (the other "
        f"sign of det(dtheta/d(roll, pitch))), got {value!r}"
    )


def _check_offset(starting_value) -> float:
    x = _to_float(starting_value)
    if not (math.isfinite(x) and abs(x) <= math.pi):
        raise InvalidArgumentError(
            f"starting_value must be a finite real number in [-pi, pi] rad (the LL zero offset of eq 19, the xacro "
            f"argument's range), got {starting_value!r}"
        )
    return x


def _check_flag(value, name: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgumentError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _check_real(value, name: str, lo: float, hi: float, what: str) -> float:
    x = _to_float(value)
    if not (math.isfinite(x) and lo < x <= hi):
        raise InvalidArgumentError(f"{name} must be a finite real number in ({lo:g}, {hi:g}] ({what}), got {value!r}")
    return x


def _check_count(value, name: str, lo: int, hi: int, what: str) -> int:
    if not (_is_int(value) and lo <= value <= hi):
        raise InvalidArgumentError(f"{name} must be an integer in [{lo}, {hi}] ({what}), got {value!r}")
    return int(value)


#: Scalar types a single-call fast path passes straight to a kernel (anything else takes the checked path).
_SCALARS = (float, np.float64)


#: Batches smaller than this run the serial loop: starting numba's threads costs more than they save.
_PARALLEL_MIN = 64


def _loop(parallel, serial, n: int):
    """The compiled batch loop to run for n items: the prange one (parallel) or the plain one (serial)."""
    return parallel if n >= _PARALLEL_MIN else serial


def _flat(a: np.ndarray) -> np.ndarray:
    """A checked input as a fresh, writeable, C-contiguous float64 vector (for a kernel)."""
    return np.array(a, dtype=np.float64).reshape(-1)


def _fast_branch(branch):
    """(b1, b2) as floats for a plain tuple of two ints +-1, else None (the checked path then)."""
    if type(branch) is tuple and len(branch) == 2:
        b1, b2 = branch
        if type(b1) is int and type(b2) is int and (b1 == 1 or b1 == -1) and (b2 == 1 or b2 == -1):
            return float(b1), float(b2)
    return None


def _fast_sign(value):
    """+-1.0 for a plain int +-1, else None."""
    if type(value) is int and (value == 1 or value == -1):
        return float(value)
    return None


def _fast_offset(value):
    """starting_value as a float for a plain float in [-pi, pi], else None."""
    if type(value) is float and -math.pi <= value <= math.pi:
        return value
    return None


def _rotz(t):
    c, s = np.cos(t), np.sin(t)
    z, o = np.zeros_like(t), np.ones_like(t)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _check_rotation(rotation, name: str = "rotation") -> np.ndarray:
    r = as_input(rotation, name, (3, 3))
    err = np.abs(np.swapaxes(r, -1, -2) @ r - np.eye(3)).max(axis=(-1, -2)) if r.size else np.zeros(0)
    det = np.linalg.det(r) if r.size else np.ones(0)
    if np.any(err > 1e-9) or np.any(det < 0):
        raise InvalidInputError(f"{name} must be rotation matrices (orthonormal, det +1 within 1e-9); worst |R^T R - I| = {np.max(err):.3g}")
    return r


# ----------------------------------------------------------------------------- eq 19
def ll_angle(theta0, starting_value: float = 0.0):
    """LL joint angle driven by the leg-extension motor (seed eq 19, OCR artefact removed).

    .. math:: \\theta_{LL} = -\\theta_0 \\frac{0.07}{2 \\pi \\, 1.5} + \\text{startingValue}

    The seed prints ``-1 * theta0 * 0 * 0.07 / (2 pi 1.5)``: the ``* 0`` is an OCR artefact (taken literally
    theta_LL would not depend on the motor). 0.07 m of travel per motor revolution applied on the 1.5 m arc
    of the foot: ~70 mm of near-vertical foot travel per revolution.

    Args:
        theta0: extension-motor angles (rad), any shape.
        starting_value: zero offset of the LL joint (rad; the xacro argument ``starting_value``).

    Returns:
        theta_LL (rad), same shape.
    """
    (t0,) = as_angles(theta0, names=("theta0",))
    return -RATIO * t0 + _check_offset(starting_value)


def extension_motor_angle(theta_ll, starting_value: float = 0.0):
    """Inverse of :func:`ll_angle`: ``theta0 = (starting_value - theta_LL) / RATIO`` (eq 19 solved for theta0)."""
    (t,) = as_angles(theta_ll, names=("theta_ll",))
    with np.errstate(over="ignore"):  # |theta_LL| > 1e306 rad: inf
        return (_check_offset(starting_value) - t) / RATIO


# ----------------------------------------------------------------------------- platform and chains
def platform_rotation(roll, pitch) -> np.ndarray:
    """``R_P = Rx(roll) Ry(pitch)``, shape (..., 3, 3): the universal centre (x fixed in CCS, then y).

    Seed eq 2 writes R_P as a unit quaternion (a spherical joint); the universal joint is the physical
    2-DOF platform (see the docs: the spherical centre leaves one rotation uncontrolled).
    """
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    return _rot(r, p)


def _rot(r, p) -> np.ndarray:
    """Rx(r) Ry(p) without input checks (internal: NaN propagates)."""
    cr, sr, cp, sp = np.cos(r), np.sin(r), np.cos(p), np.sin(p)
    z = np.zeros_like(r)
    return np.stack(
        [np.stack([cp, z, sp], -1), np.stack([sr * sp, cr, -sr * cp], -1), np.stack([-cr * sp, sr, cr * cp], -1)], -2
    )


def _attach_world(rot: np.ndarray) -> np.ndarray:
    """Rod attachment points A_i = CENTER + R a_i, shape (..., 2, 3)."""
    return CENTER + np.einsum("...jk,ik->...ij", rot, ATTACH)


def _lever_tips(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lever tips S_i (..., 2, 3) and dS_i/dtheta_i (..., 2, 3) for motor angles (..., 2)."""
    phi = theta + MOTOR_YAW
    c, s = np.cos(phi), np.sin(phi)
    tip = np.stack([LEVER[0] * c, LEVER[0] * s, np.broadcast_to(LEVER[2], c.shape)], -1) + MOTOR_POS
    dtip = np.stack([-LEVER[0] * s, LEVER[0] * c, np.zeros_like(c)], -1)
    return tip, dtip


def rod_spans(theta1, theta2, roll=0.0, pitch=0.0) -> np.ndarray:
    """Distances |A_i - S_i| (..., 2) from each lever tip to its platform point (closed iff = ROD_LENGTH).

    The chains of seed eqs 3-9 and 10-16 up to the first spherical joint, and the platform points of
    eqs 9, 16. At zero motors and R_P = I the span is 0.0839 m, not 0.11: that pose does not close.
    """
    t1, t2, r, p = as_angles(theta1, theta2, roll, pitch, names=("theta1", "theta2", "roll", "pitch"))
    tip, _ = _lever_tips(np.stack([t1, t2], -1))
    return np.linalg.norm(_attach_world(platform_rotation(r, p)) - tip, axis=-1)


def _chains(rot: np.ndarray, b: np.ndarray, tol: float = K_TOL):
    """Closed form of both rod-length equations for rotations (..., 3, 3) (the kernel :func:`_chain_k`).

    b (2,) or (n, 2) per rotation. Returns theta (..., 2) (NaN where unreachable), the reach ratio k (..., 2),
    and ok (..., 2) (|k| <= 1 + tol).
    """
    shape = rot.shape[:-2]
    rr = np.array(rot.reshape(-1, 3, 3), dtype=np.float64)
    n = len(rr)
    bb = np.asarray(b, dtype=np.float64)
    if bb.ndim == 1:
        b1, b2 = np.full(n, bb[0]), np.full(n, bb[1])
    else:
        bb = bb.reshape(-1, 2)
        b1, b2 = np.array(bb[:, 0], dtype=np.float64), np.array(bb[:, 1], dtype=np.float64)
    theta, k, ok = np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2), dtype=np.bool_)
    _loop(_chains_b, _chains_s, n)(rr, b1, b2, float(tol), theta, k, ok)
    return theta.reshape(shape + (2,)), k.reshape(shape + (2,)), ok.reshape(shape + (2,))


def _unreachable(what: str, k: np.ndarray) -> UnreachableError:
    bad = [f"chain {i + 1} (|k| = {abs(float(k[i])):.15g})" for i in range(2) if not abs(float(k[i])) <= 1.0 + K_TOL]
    return UnreachableError(
        f"{what} is out of the motors' reach: the rod-length equation A cos(theta) + B sin(theta) = C has no "
        f"solution for {', '.join(bad) or 'a chain (|k| not finite)'}; it needs |k| = |C| / sqrt(A^2 + B^2) <= 1 "
        f"(+ {K_TOL:g} for rounding)",
        target=None,
    )


def _levers_at(rotation, branch, return_mask=False):
    """Checked rotation, motor angles, chain flags, success mask and lever tips for a platform rotation."""
    rot = _check_rotation(rotation)
    _check_flag(return_mask, "return_mask")
    theta, k, ok2 = _chains(rot, _check_branch(branch))
    ok = np.all(ok2, axis=-1)
    tip, _ = _lever_tips(np.where(ok[..., None], theta, 0.0))
    return rot, theta, k, ok, tip


def motor_angles_from_rotation(rotation, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """Motor angles (..., 2) = (theta1, theta2) for platform rotations (..., 3, 3) (any centre joint).

    Seed eqs 3-16: each chain closes when ``|A_i - S_i(theta_i)| = L``. With ``w_i = p_i - A_i`` and
    ``phi_i = sigma_i BETA + theta_i`` this is, per chain,

    .. math:: A \\cos\\phi + B \\sin\\phi = C,\\quad A = l_x w_x,\\ B = l_x w_y,\\
              C = \\tfrac12 (L^2 - |w|^2 - l_x^2 - l_z^2 - 2 l_z w_z)

    so ``phi = atan2(B, A) - sigma_i b_i acos(C / sqrt(A^2 + B^2))``. Unreachable where
    ``|C| > sqrt(A^2 + B^2)``. Angles wrapped to (-pi, pi].

    Raises:
        UnreachableError: single rotation out of reach.
    """
    if return_mask is False and type(rotation) is np.ndarray and rotation.shape == (3, 3) \
            and rotation.dtype == np.float64:
        fb = _fast_branch(branch)
        if fb is not None:
            theta, k = np.empty(2), np.empty(2)
            if _motor_angles_rot_k(rotation, fb[0], fb[1], theta, k) == OK:
                return theta
    rot = _check_rotation(rotation)
    b = _check_branch(branch)
    _check_flag(return_mask, "return_mask")
    theta, k, ok2 = _chains(rot, b)
    ok = np.all(ok2, axis=-1)
    theta = np.where(ok[..., None], theta, np.nan)
    return finish(theta, ok, rot.ndim == 2, return_mask, lambda: _unreachable("the platform rotation", k))


def motor_angles(roll, pitch, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """Motor angles (..., 2) = (theta1, theta2) putting the universal-centre platform at (roll, pitch).

    :func:`motor_angles_from_rotation` applied to ``R_P = Rx(roll) Ry(pitch)`` (seed eq 2's quaternion
    replaced by the universal joint). Each chain's rod-length condition is A cos(theta) + B sin(theta) = C,
    solved in closed form; ``branch = (b1, b2)`` picks one of its two solutions per chain.

    Raises:
        UnreachableError: single (roll, pitch) out of reach (message names the chain and its |k|).
    """
    if return_mask is False and type(roll) in _SCALARS and type(pitch) in _SCALARS:
        fb = _fast_branch(branch)
        if fb is not None:
            theta, k = np.empty(2), np.empty(2)
            if _motor_angles_k(roll, pitch, fb[0], fb[1], theta, k) == OK:
                return theta
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = _check_branch(branch)
    _check_flag(return_mask, "return_mask")
    n = r.size
    theta, k, ok = np.empty((n, 2)), np.empty((n, 2)), np.empty(n, dtype=np.bool_)
    _loop(_motor_angles_b, _motor_angles_s, n)(_flat(r), _flat(p), float(b[0]), float(b[1]),
                    theta, k, ok)
    theta, k, ok = theta.reshape(r.shape + (2,)), k.reshape(r.shape + (2,)), ok.reshape(r.shape)
    what = f"(roll, pitch) = ({float(r):.6g}, {float(p):.6g})" if r.ndim == 0 else ""
    return finish(theta, ok, r.ndim == 0, return_mask, lambda: _unreachable(what, k))


def _jacobian_parts(rot: np.ndarray, roll: np.ndarray, theta: np.ndarray):
    """N (..., 2, 2) = d_i . dA_i/dx_k and D (..., 2) = d_i . dS_i/dtheta_i, with d_i = A_i - S_i.

    dtheta/dx = D^-1 N (implicit differentiation of |d_i|^2 = L^2); x = (roll, pitch).
    """
    ra = np.einsum("...jk,ik->...ij", rot, ATTACH)  # R a_i
    tip, dtip = _lever_tips(theta)
    d = CENTER + ra - tip
    ex = np.array([1.0, 0.0, 0.0])
    ey_r = np.stack([np.zeros_like(roll), np.cos(roll), np.sin(roll)], -1)[..., None, :]  # Rx(roll) e_y
    dar = np.cross(ex, ra)
    dap = np.cross(ey_r, ra)
    n = np.stack([np.sum(d * dar, -1), np.sum(d * dap, -1)], -1)
    dd = np.sum(d * dtip, -1)
    return n, dd


def _jacobian_and_mode(r: np.ndarray, p: np.ndarray, b: np.ndarray):
    """The kernel :func:`_motor_jacobian_k` over checked (roll, pitch) arrays: jac (..., 2, 2), k (..., 2),
    status (...), mode (...)."""
    n = r.size
    jac, k, mode, st = np.empty((n, 2, 2)), np.empty((n, 2)), np.empty((n, 1)), np.empty(n, dtype=np.int64)
    _loop(_motor_jacobian_b, _motor_jacobian_s, n)(_flat(r), _flat(p), float(b[0]), float(b[1]), jac, k, mode, st)
    sh = r.shape
    return jac.reshape(sh + (2, 2)), k.reshape(sh + (2,)), st.reshape(sh), mode.reshape(sh)


def motor_jacobian(roll, pitch, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """d(theta1, theta2)/d(roll, pitch), shape (..., 2, 2), by implicit differentiation of the rod lengths.

    With ``d_i = A_i - S_i``: ``dtheta_i/dx_k = (d_i . dA_i/dx_k) / (d_i . dS_i/dtheta_i)`` where
    ``dA/droll = e_x x R a``, ``dA/dpitch = (Rx(roll) e_y) x R a``, ``dS/dtheta = e_z x Rz(phi) l``.
    Infinite (NaN here) on the reach boundary, where ``d_i . dS_i/dtheta_i = 0``.

    Raises:
        UnreachableError: single (roll, pitch) out of reach.
        SingularityError: single pose on the reach boundary (a motor cannot move its rod end).
    """
    if return_mask is False and type(roll) in _SCALARS and type(pitch) in _SCALARS:
        fb = _fast_branch(branch)
        if fb is not None:
            jac, k, mode = np.empty((2, 2)), np.empty(2), np.empty(1)
            if _motor_jacobian_k(roll, pitch, fb[0], fb[1], jac, k, mode) == OK:
                return jac
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = _check_branch(branch)
    _check_flag(return_mask, "return_mask")
    jac, k, st = _jacobian_and_mode(r, p, b)[:3]
    reach = st != _ST_REACH
    ok = st == OK

    def error():
        if not bool(reach):
            return _unreachable(f"(roll, pitch) = ({float(r):.6g}, {float(p):.6g})", k)
        return SingularityError(f"(roll, pitch) = ({float(r):.6g}, {float(p):.6g}) is on the reach boundary: "
                                "a lever is perpendicular to its rod's motion, dtheta/d(roll, pitch) is infinite")

    return finish(jac, ok, r.ndim == 0, return_mask, error)


def sphere_joint_angles(rotation, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """Angles (..., 2, 3) of each lever-tip spherical joint (z, y, x revolutes) that close the chains.

    The model writes spherical joint i-1 (seed eqs 7, 14: ``R_quat(a, b, c, d)`` relative to the lever
    frame) as ``Rz(alpha) Ry(beta) Rx(gamma)``, the rod along the x axis of the result (eqs 8, 15). With
    ``u = Rz(phi_i)^T (A_i - S_i) / L`` the rod direction in the lever frame,
    ``alpha = atan2(u_y, u_x)``, ``beta = -asin(u_z)``; ``gamma`` is the rod's spin about its own axis,
    a trivial internal DOF, returned as 0. Gimbal lock would need the rod along the lever's z axis
    (|beta| = 90 deg); at the neutral pose |beta| = 3.65 deg. The rod-end sphere (i-2) is the point
    closure itself and has no joint angles.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    rot, theta, k, ok, tip = _levers_at(rotation, branch, return_mask)
    d = _attach_world(rot) - tip
    rz = _rotz(theta + MOTOR_YAW)
    u = np.einsum("...ji,...j->...i", rz, d) / ROD_LENGTH
    alpha = np.arctan2(u[..., 1], u[..., 0])
    beta = -np.arcsin(np.clip(u[..., 2], -1.0, 1.0))
    out = np.stack([alpha, beta, np.zeros_like(alpha)], -1)
    out = np.where(ok[..., None, None], out, np.nan)
    return finish(out, ok, rot.ndim == 2, return_mask, lambda: _unreachable("the platform rotation", k))


# ----------------------------------------------------------------------------- forward kinematics
# The closed sub-chain's forward kinematics in closed form. With the lever tips S_i known (motor angles given),
# rod i closes iff |A_i - S_i| = L, A_i = c + R a_i, i.e. w_i . R a_i = kappa_i with w_i = c - S_i and
# kappa_i = (L^2 - |w_i|^2 - |a_i|^2) / 2. With R = Rx(roll) Ry(pitch) and q = Rx(roll)^T w that is, per rod,
#     alpha_i cos(pitch) + beta_i sin(pitch) + gamma_i = 0,
#     alpha = w_x a_x + a_z q_z,  beta = w_x a_z - a_x q_z,  gamma = a_y q_y - kappa,
#     q_y = cos(roll) w_y + sin(roll) w_z,  q_z = -sin(roll) w_y + cos(roll) w_z,
# two linear equations in (cos pitch, sin pitch): Cramer gives cos = C / D, sin = S / D, and cos^2 + sin^2 = 1
# is C^2 + S^2 - D^2 = 0, a trigonometric polynomial of degree 4 in roll. With t = tan(roll / 2) (times
# (1 + t^2)^4) it is a polynomial of degree 8: up to 8 poses; roll in the joint limits is |t| <= 1.
def _n_matrix(ra: np.ndarray, d: np.ndarray, roll: np.ndarray) -> np.ndarray:
    """N (..., 2, 2), N_ik = d_i . dA_i/dx_k, for R a_i = ra (..., 2, 3), d_i = A_i - S_i, x = (roll, pitch).

    dA/droll = e_x x R a, dA/dpitch = (Rx(roll) e_y) x R a, Rx(roll) e_y = (0, c, s), written out.
    """
    c, s = np.cos(roll)[..., None], np.sin(roll)[..., None]
    ax, ay, az = ra[..., 0], ra[..., 1], ra[..., 2]
    n_roll = -d[..., 1] * az + d[..., 2] * ay
    n_pitch = d[..., 0] * (c * az - s * ay) + (d[..., 1] * s - d[..., 2] * c) * ax
    return np.stack([n_roll, n_pitch], -1)


def _det2(m: np.ndarray) -> np.ndarray:
    return m[..., 0, 0] * m[..., 1, 1] - m[..., 0, 1] * m[..., 1, 0]


#: Offsets (rad) of the extra starting poses on either side of a near-singular solution (along the null vector of
#: N), from which Newton runs with the forward-singularity barrier: near det N = 0 two poses of opposite modes are
#: close together, and the plain Newton iteration from the roots may find only one of them.
_FOLD_OFFSETS = (1e-9, 1e-7, 1e-5, 1e-3)


# ----------------------------------------------------------------------------- compiled kernels (issue 16)
# Each kinematic quantity below is written once, as a scalar numba kernel (the seed equations it implements are
# cited); the batch functions are compiled prange loops over the same kernels (each with a serial twin, _s, run
# below _PARALLEL_MIN items). Status codes: OK and the _ST_*.
_ST_INPUT = 1  # a non-finite input: the wrapper's checks raise the InvalidInputError
_ST_REACH = 2  # a chain out of the motors' reach (|k| > 1 + tol)
_ST_ASSEMBLE = 3  # the closed sub-chain does not assemble in the mode asked for
_ST_BAND = 4  # the forward-singularity band (foot gain >= FK_GAIN_MAX)
_ST_SINGULAR = 5  # N singular / reach boundary

_CX, _CY, _CZ = float(CENTER[0]), float(CENTER[1]), float(CENTER[2])
_LX, _LZ = float(LEVER[0]), float(LEVER[2])
_PX0, _PY0, _PZ0 = (float(v) for v in MOTOR_POS[0])
_PX1, _PY1, _PZ1 = (float(v) for v in MOTOR_POS[1])
_AX0, _AY0, _AZ0 = (float(v) for v in ATTACH[0])
_AX1, _AY1, _AZ1 = (float(v) for v in ATTACH[1])
_OX, _OZ = float(LL_ORIGIN[0]), float(LL_ORIGIN[2])
_L = ROD_LENGTH
_TWO_PI = 2.0 * math.pi


@kernel
def _wrap_k(a):
    """Wrap an angle to (-pi, pi] (as :func:`_wrap`)."""
    return math.pi - np.mod(math.pi - a, _TWO_PI)


@kernel
def _rot_k(r, p, m):
    """m (3, 3) = Rx(r) Ry(p), the universal centre (seed eq 2 with the universal joint)."""
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    m[0, 0], m[0, 1], m[0, 2] = cp, 0.0, sp
    m[1, 0], m[1, 1], m[1, 2] = sr * sp, cr, -sr * cp
    m[2, 0], m[2, 1], m[2, 2] = -cr * sp, sr, cr * cp


@kernel
def _chain_k(m, i, bi, tol, theta, kout):
    """Chain i's rod-length equation (seed eqs 3-9, 10-16) for the platform rotation m (3, 3), branch bi.

    ``A cos(phi) + B sin(phi) = C`` with ``w = p_i - A_i``, ``A = l_x w_x``, ``B = l_x w_y``,
    ``C = (L^2 - |w|^2 - l_x^2 - l_z^2 - 2 l_z w_z) / 2``; ``phi = atan2(B, A) - sigma_i b_i acos(k)``,
    ``k = C / sqrt(A^2 + B^2)``. Writes theta[i] (wrapped; NaN when unreachable) and kout[i]; returns reachable.
    """
    if i == 0:
        ax, ay, az, px, py, pz, sg, yaw = _AX0, _AY0, _AZ0, _PX0, _PY0, _PZ0, 1.0, BETA
    else:
        ax, ay, az, px, py, pz, sg, yaw = _AX1, _AY1, _AZ1, _PX1, _PY1, _PZ1, -1.0, -BETA
    wx = px - (_CX + (m[0, 0] * ax + m[0, 1] * ay + m[0, 2] * az))
    wy = py - (_CY + (m[1, 0] * ax + m[1, 1] * ay + m[1, 2] * az))
    wz = pz - (_CZ + (m[2, 0] * ax + m[2, 1] * ay + m[2, 2] * az))
    a = _LX * wx
    b = _LX * wy
    c = 0.5 * (_L * _L - (wx * wx + wy * wy + wz * wz) - _LX * _LX - _LZ * _LZ - 2.0 * _LZ * wz)
    k = c / math.hypot(a, b)
    kout[i] = k
    if not (math.isfinite(k) and abs(k) <= 1.0 + tol):
        theta[i] = math.nan
        return False
    kc = min(max(k, -1.0), 1.0)
    theta[i] = _wrap_k(math.atan2(b, a) - sg * bi * math.acos(kc) - yaw)
    return True


@kernel
def _chains_k(m, b1, b2, tol, theta, kout):
    """Both chains (:func:`motor_angles_from_rotation`); returns _OK or _ST_REACH (theta NaN then)."""
    ok1 = _chain_k(m, 0, b1, tol, theta, kout)
    ok2 = _chain_k(m, 1, b2, tol, theta, kout)
    if ok1 and ok2:
        return OK
    theta[0] = math.nan
    theta[1] = math.nan
    return _ST_REACH


@kernel
def _motor_angles_k(r, p, b1, b2, theta, kout):
    """:func:`motor_angles`: the chains at R_P = Rx(r) Ry(p)."""
    if not (math.isfinite(r) and math.isfinite(p)):
        theta[0] = math.nan
        theta[1] = math.nan
        return _ST_INPUT
    m = np.empty((3, 3))
    _rot_k(r, p, m)
    return _chains_k(m, b1, b2, K_TOL, theta, kout)


@batch_kernel
def _motor_angles_b(r, p, b1, b2, theta, kout, ok):
    for j in prange(r.shape[0]):
        ok[j] = _motor_angles_k(r[j], p[j], b1, b2, theta[j], kout[j]) == OK


@kernel
def _motor_angles_s(r, p, b1, b2, theta, kout, ok):
    for j in range(r.shape[0]):
        ok[j] = _motor_angles_k(r[j], p[j], b1, b2, theta[j], kout[j]) == OK


@batch_kernel
def _chains_b(rot, b1, b2, tol, theta, kout, ok):
    for j in prange(rot.shape[0]):
        ok[j, 0] = _chain_k(rot[j], 0, b1[j], tol, theta[j], kout[j])
        ok[j, 1] = _chain_k(rot[j], 1, b2[j], tol, theta[j], kout[j])


@kernel
def _chains_s(rot, b1, b2, tol, theta, kout, ok):
    for j in range(rot.shape[0]):
        ok[j, 0] = _chain_k(rot[j], 0, b1[j], tol, theta[j], kout[j])
        ok[j, 1] = _chain_k(rot[j], 1, b2[j], tol, theta[j], kout[j])


@kernel
def _motor_angles_rot_k(m, b1, b2, theta, kout):
    """:func:`motor_angles_from_rotation` of one matrix m (3, 3): _ST_INPUT unless finite and a rotation (as
    :func:`_check_rotation`: |R^T R - I| <= 1e-9, det >= 0), else the chains."""
    err = 0.0
    for i in range(3):
        for j in range(3):
            if not math.isfinite(m[i, j]):
                return _ST_INPUT
            v = m[0, i] * m[0, j] + m[1, i] * m[1, j] + m[2, i] * m[2, j] - (1.0 if i == j else 0.0)
            err = max(err, abs(v))
    det = (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]) - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
           + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]))
    if not (err <= 1e-9 and det >= 0.0):
        return _ST_INPUT
    return _chains_k(m, b1, b2, K_TOL, theta, kout)


@kernel
def _foot_k(r, p, t, out):
    """Foot FCS in CCS (seed eqs 1, 17, 18, 20): ``CENTER + R_P (o_LL + Ry(t) (FOOT_X, 0, 0))``."""
    if not (math.isfinite(r) and math.isfinite(p) and math.isfinite(t)):
        out[0], out[1], out[2] = math.nan, math.nan, math.nan
        return _ST_INPUT
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    fx = _OX + FOOT_X * math.cos(t)
    fz = _OZ - FOOT_X * math.sin(t)
    out[0] = _CX + (cp * fx + sp * fz)
    out[1] = _CY + (sr * sp * fx - sr * cp * fz)
    out[2] = _CZ + (-cr * sp * fx + cr * cp * fz)
    return OK


@batch_kernel
def _foot_b(r, p, t, out):
    for j in prange(r.shape[0]):
        _foot_k(r[j], p[j], t[j], out[j])


@kernel
def _foot_s(r, p, t, out):
    for j in range(r.shape[0]):
        _foot_k(r[j], p[j], t[j], out[j])


# --- forward kinematics of the closed sub-chain (the polynomial in tan(roll / 2), see the comment above
# _n_matrix: T_C = cos(roll) (1 + t^2) = 1 - t^2, T_S = sin(roll) (1 + t^2) = 2 t, T_1 = 1 + t^2)
@kernel
def _tips_k(t1, t2, tip, dtip):
    """Lever tips S_i (2, 3) and dS_i/dtheta_i (seed eqs 7, 14) for motor angles t1, t2."""
    for i in range(2):
        if i == 0:
            phi, px, py, pz = t1 + BETA, _PX0, _PY0, _PZ0
        else:
            phi, px, py, pz = t2 - BETA, _PX1, _PY1, _PZ1
        c, s = math.cos(phi), math.sin(phi)
        tip[i, 0] = _LX * c + px
        tip[i, 1] = _LX * s + py
        tip[i, 2] = _LZ + pz
        dtip[i, 0] = -_LX * s
        dtip[i, 1] = _LX * c
        dtip[i, 2] = 0.0


@kernel
def _pmul_k(a, b, out):
    """out = a * b (ascending polynomial coefficients; len(out) = len(a) + len(b) - 1)."""
    for j in range(out.shape[0]):
        out[j] = 0.0
    for i in range(a.shape[0]):
        for j in range(b.shape[0]):
            out[i + j] += a[i] * b[j]


@kernel
def _roll_poly_k(tip, poly, al, be, ga):
    """The degree-8 polynomial poly (9,) in t = tan(roll / 2) and the per-rod quadratics al, be, ga (2, 3)."""
    for i in range(2):
        if i == 0:
            ax, ay, az = _AX0, _AY0, _AZ0
        else:
            ax, ay, az = _AX1, _AY1, _AZ1
        wx, wy, wz = _CX - tip[i, 0], _CY - tip[i, 1], _CZ - tip[i, 2]
        kap = 0.5 * (_L * _L - (wx * wx + wy * wy + wz * wz) - (ax * ax + ay * ay + az * az))
        qz0, qz1, qz2 = wz * 1.0, -wy * 2.0, wz * -1.0  # -wy T_S + wz T_C
        qy0, qy1, qy2 = wy * 1.0, wz * 2.0, wy * -1.0  # wy T_C + wz T_S
        al[i, 0] = wx * ax + az * qz0
        al[i, 1] = az * qz1
        al[i, 2] = wx * ax + az * qz2
        be[i, 0] = wx * az - ax * qz0
        be[i, 1] = -ax * qz1
        be[i, 2] = wx * az - ax * qz2
        ga[i, 0] = ay * qy0 - kap
        ga[i, 1] = ay * qy1
        ga[i, 2] = ay * qy2 - kap
    t1 = np.empty(5)
    t2 = np.empty(5)
    det = np.empty(5)
    cc = np.empty(5)
    ss = np.empty(5)
    _pmul_k(al[0], be[1], t1)
    _pmul_k(al[1], be[0], t2)
    det[:] = t1 - t2
    _pmul_k(be[0], ga[1], t1)
    _pmul_k(be[1], ga[0], t2)
    cc[:] = t1 - t2
    _pmul_k(al[1], ga[0], t1)
    _pmul_k(al[0], ga[1], t2)
    ss[:] = t1 - t2
    p1 = np.empty(9)
    p2 = np.empty(9)
    p3 = np.empty(9)
    _pmul_k(cc, cc, p1)
    _pmul_k(ss, ss, p2)
    _pmul_k(det, det, p3)
    poly[:] = p1 + p2 - p3


@kernel
def _roots_k(c, z):
    """Complex roots z (8,) of the polynomial c (9,) (ascending), NaN-padded: Aberth-Ehrlich iteration.

    Zero leading coefficients lower the degree (a pose at roll = pi); a non-finite polynomial has no roots.
    Returns the number of roots.
    """
    for j in range(8):
        z[j] = complex(math.nan, math.nan)
    for j in range(9):
        if not math.isfinite(c[j]):
            return 0
    n = 8
    while n > 0 and c[n] == 0.0:
        n -= 1
    if n == 0:
        return 0
    lead = c[n]
    # starting points on a circle: the geometric mean of the roots' moduli, at most Fujiwara's bound
    rad = 0.0
    for k in range(n):
        v = (abs(c[k] / lead) / (2.0 if k == 0 else 1.0)) ** (1.0 / (n - k))
        if v > rad:
            rad = v
    rad = 2.0 * rad
    if not (rad > 0.0 and math.isfinite(rad)):
        rad = 1.0
    g0 = abs(c[0] / lead) ** (1.0 / n)
    if g0 > 0.0 and g0 < rad:
        rad = g0
    zr = np.empty(8)
    zi = np.empty(8)
    for j in range(n):
        ang = _TWO_PI * j / n + 0.4
        zr[j], zi[j] = rad * math.cos(ang), rad * math.sin(ang)
    done = np.zeros(8, dtype=np.bool_)
    prev = np.full(8, math.inf)
    for _ in range(100):
        ndone = 0
        for j in range(n):
            if done[j]:
                ndone += 1
                continue
            xr, xi = zr[j], zi[j]
            pr, pi_ = c[n], 0.0
            dr, di = 0.0, 0.0
            for k in range(n - 1, -1, -1):
                dr, di = dr * xr - di * xi + pr, dr * xi + di * xr + pi_
                pr, pi_ = pr * xr - pi_ * xi + c[k], pr * xi + pi_ * xr
            if pr == 0.0 and pi_ == 0.0:
                done[j] = True
                continue
            # ratio = p / p'
            dd = dr * dr + di * di
            rr, ri = (pr * dr + pi_ * di) / dd, (pi_ * dr - pr * di) / dd
            sr, si = 0.0, 0.0
            for k in range(n):
                if k != j:
                    er, ei = xr - zr[k], xi - zi[k]
                    e2 = er * er + ei * ei
                    sr += er / e2
                    si -= ei / e2
            # w = ratio / (1 - ratio s)
            qr, qi = 1.0 - (rr * sr - ri * si), -(rr * si + ri * sr)
            q2 = qr * qr + qi * qi
            wr, wi = (rr * qr + ri * qi) / q2, (ri * qr - rr * qi) / q2
            if not (math.isfinite(wr) and math.isfinite(wi)):
                wr, wi = rr, ri
            zr[j], zi[j] = xr - wr, xi - wi
            # converged (cubically: the last correction leaves rounding only), or stalled at the rounding floor
            # of a (near-)multiple root, where the convergence is linear
            aw = math.hypot(wr, wi)
            az = math.hypot(xr, xi)
            if aw <= 1e-12 * az or (aw <= 1e-6 * az and aw >= 0.5 * prev[j]):
                done[j] = True
            prev[j] = aw
        if ndone == n:
            break
    for j in range(n):
        z[j] = complex(zr[j], zi[j])
    return n


@kernel
def _rod_system_k(x0, x1, tip, g, nm):
    """Rod equations g_i = (|A_i - S_i|^2 - L^2) / 2 (2,) and N (2, 2) (N_ik = d_i . dA_i/dx_k) at (x0, x1).

    Returns max |g_i| (NaN if not finite)."""
    cr, sr, cp, sp = math.cos(x0), math.sin(x0), math.cos(x1), math.sin(x1)
    worst = 0.0
    for i in range(2):
        if i == 0:
            ax, ay, az = _AX0, _AY0, _AZ0
        else:
            ax, ay, az = _AX1, _AY1, _AZ1
        rx = cp * ax + sp * az
        ry = sr * sp * ax + cr * ay - sr * cp * az
        rz = -cr * sp * ax + sr * ay + cr * cp * az
        d0, d1, d2 = _CX + rx - tip[i, 0], _CY + ry - tip[i, 1], _CZ + rz - tip[i, 2]
        g[i] = 0.5 * ((d0 * d0 + d1 * d1 + d2 * d2) - _L * _L)
        nm[i, 0] = -d1 * rz + d2 * ry
        nm[i, 1] = d0 * (cr * rz - sr * ry) + (d1 * sr - d2 * cr) * rx
        a = abs(g[i])
        if not (a <= worst):
            worst = a if math.isfinite(a) or math.isnan(worst) else math.nan
    return worst if math.isfinite(worst) else math.nan


@kernel
def _sgn(v):
    return 1.0 if v > 0.0 else (-1.0 if v < 0.0 else (0.0 if v == 0.0 else math.nan))


@kernel
def _rod_newton_k(x, tip, max_iter, keep_sign):
    """Damped Newton on both rod equations from x (2,) (in place; as in the numpy version of issue 15): each
    accepted step decreases max|g|; with keep_sign it also keeps the sign of det N of the start. Returns the
    rod-length error (m), inf where not finite."""
    g = np.empty(2)
    nm = np.empty((2, 2))
    gt = np.empty(2)
    nt = np.empty((2, 2))
    cur = _rod_system_k(x[0], x[1], tip, g, nm)
    sign = _sgn(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])
    act = math.isfinite(cur)
    for it in range(max_iter):
        if it == 8 and not (cur <= 1e-4 * _L):
            act = False
        if not act:
            break
        det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
        s0 = -((nm[1, 1] * g[0] - nm[0, 1] * g[1]) / det)
        s1 = -((nm[0, 0] * g[1] - nm[1, 0] * g[0]) / det)
        fin = math.isfinite(s0) and math.isfinite(s1)
        if fin:
            s0 = min(max(s0, -0.3), 0.3)
            s1 = min(max(s1, -0.3), 0.3)
        else:
            s0 = 0.0
            s1 = 0.0
        smax = max(abs(s0), abs(s1))
        fin = fin and smax > 1e-16 * (1.0 + max(abs(x[0]), abs(x[1])))
        lam = 1.0
        acc = False
        if fin:
            for _ in range(16):
                xt0 = x[0] + lam * s0
                xt1 = x[1] + lam * s1
                ct = _rod_system_k(xt0, xt1, tip, gt, nt)
                ok = ct < cur
                if keep_sign:
                    ok = ok and _sgn(nt[0, 0] * nt[1, 1] - nt[0, 1] * nt[1, 0]) == sign
                if ok:
                    acc = True
                    x[0], x[1], cur = xt0, xt1, ct
                    g[0], g[1] = gt[0], gt[1]
                    nm[:, :] = nt
                    break
                lam *= 0.5
        if not acc or smax * lam <= 1e-16:
            act = False
    gm = max(abs(g[0]), abs(g[1]))
    err = gm * 2.0 / (_L + math.sqrt(max(2.0 * gm + _L * _L, 0.0)))
    return err if math.isfinite(err) else math.inf


@kernel
def _null_k(nm, v):
    """Singular values (s_max, s_min) of N (2, 2) and the right singular vector v (2,) of s_min."""
    a = nm[0, 0] * nm[0, 0] + nm[1, 0] * nm[1, 0]
    b = nm[0, 0] * nm[0, 1] + nm[1, 0] * nm[1, 1]
    c = nm[0, 1] * nm[0, 1] + nm[1, 1] * nm[1, 1]
    h = math.sqrt(0.25 * (a - c) ** 2 + b * b)
    lmax = 0.5 * (a + c) + h
    smax = math.sqrt(lmax)
    det = abs(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])
    smin = det / smax if smax > 0.0 else 0.0
    lmin = smin * smin
    # eigenvector of N^T N for lmin: (b, lmin - a) or (lmin - c, b), the better conditioned
    v0, v1 = b, lmin - a
    u0, u1 = lmin - c, b
    if u0 * u0 + u1 * u1 > v0 * v0 + v1 * v1:
        v0, v1 = u0, u1
    nv = math.hypot(v0, v1)
    if nv > 0.0:
        v[0], v[1] = v0 / nv, v1 / nv
    elif a <= c:
        v[0], v[1] = 1.0, 0.0
    else:
        v[0], v[1] = 0.0, 1.0
    return smax, smin


#: Most seeds per motor pair: 8 roots (x3 where the rod equations are parallel), and the fold seeds of each.
_MAX_SEEDS = 24
_MAX_SOL = _MAX_SEEDS * (1 + 2 * len(_FOLD_OFFSETS))
_FOLD = np.array(_FOLD_OFFSETS)


@kernel
def _solutions_k(t1, t2, tol, max_iter, xs, bl, sdet):
    """Every platform pose within the joint limits closing both rods for motors (t1, t2): xs (m, 2), motor
    branch bl (m, 2) (0 on a chain's reach boundary), sign det N sdet (m,). Returns m (duplicates possible).

    The roots of the degree-8 polynomial in tan(roll / 2) with |roll| <= ~pi/2 (and nearly real complex pairs),
    their pitch from the two rod equations (linear in cos, sin pitch), each polished by Newton; near the forward
    singularity, extra Newton runs from both sides of each near-singular solution with the det N barrier.
    """
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    _tips_k(t1, t2, tip, dtip)
    poly = np.empty(9)
    al = np.empty((2, 3))
    be = np.empty((2, 3))
    ga = np.empty((2, 3))
    _roll_poly_k(tip, poly, al, be, ga)
    z = np.empty(8, dtype=np.complex128)
    nr = _roots_k(poly, z)
    x0 = np.empty((_MAX_SOL, 2))
    imag = np.empty(_MAX_SOL)
    m = 0
    nbad = 0
    bad = np.empty((8, 4))  # roll, base, c, imag of the seeds whose rod equations are (nearly) parallel
    for j in range(nr):
        zr, zi = z[j].real, z[j].imag
        if not (math.isfinite(zr) and math.isfinite(zi)):
            continue
        if not (abs(zi) <= 1e-2 * (1.0 + abs(z[j])) and abs(zr) <= 1.0 + 1e-3):
            continue
        t = zr
        a0 = (al[0, 2] * t + al[0, 1]) * t + al[0, 0]
        a1 = (al[1, 2] * t + al[1, 1]) * t + al[1, 0]
        b0 = (be[0, 2] * t + be[0, 1]) * t + be[0, 0]
        b1 = (be[1, 2] * t + be[1, 1]) * t + be[1, 0]
        g0 = (ga[0, 2] * t + ga[0, 1]) * t + ga[0, 0]
        g1 = (ga[1, 2] * t + ga[1, 1]) * t + ga[1, 0]
        det = a0 * b1 - a1 * b0
        cp = (b0 * g1 - b1 * g0) / det
        sp = (a1 * g0 - a0 * g1) / det
        roll = 2.0 * math.atan(t)
        pitch = math.atan2(sp, cp)
        x0[m, 0] = roll if math.isfinite(roll) else 0.0
        x0[m, 1] = pitch if math.isfinite(pitch) else 0.0
        imag[m] = abs(zi)
        m += 1
        if not (abs(det) > 1e-6 * (abs(a0 * b1) + abs(a1 * b0))):
            if math.hypot(a1, b1) > math.hypot(a0, b0):
                ak, bk, gk = a1, b1, g1
            else:
                ak, bk, gk = a0, b0, g0
            bad[nbad, 0] = roll
            bad[nbad, 1] = math.atan2(bk, ak)
            kc = -gk / math.hypot(ak, bk)
            bad[nbad, 2] = math.acos(min(max(kc, -1.0), 1.0)) if not math.isnan(kc) else math.nan
            bad[nbad, 3] = abs(zi)
            nbad += 1
    for sgn in (1.0, -1.0):
        for j in range(nbad):
            r_, p_ = bad[j, 0], bad[j, 1] + sgn * bad[j, 2]
            x0[m, 0] = r_ if math.isfinite(r_) else 0.0
            x0[m, 1] = p_ if math.isfinite(p_) else 0.0
            imag[m] = bad[j, 3]
            m += 1
    nseed = m
    x = np.empty((_MAX_SOL, 2))
    err = np.empty(_MAX_SOL)
    g = np.empty(2)
    nm = np.empty((2, 2))
    v = np.empty(2)
    for j in range(nseed):
        x[j, 0], x[j, 1] = x0[j, 0], x0[j, 1]
        err[j] = _rod_newton_k(x[j], tip, max_iter, False)
    # near the forward singularity: seeds on both sides of each near-singular solution (or unconverged nearly
    # real root), along the null vector of N, Newton with the det N barrier
    near = np.empty((_MAX_SEEDS, 4))
    nnear = 0
    for j in range(nseed):
        if err[j] <= 1e-6:
            y0, y1 = x[j, 0], x[j, 1]
        else:
            y0, y1 = x0[j, 0], x0[j, 1]
        _rod_system_k(y0, y1, tip, g, nm)
        for q in range(2):
            for r in range(2):
                if not math.isfinite(nm[q, r]):
                    nm[q, r] = 0.0
        smax, smin = _null_k(nm, v)
        if err[j] <= tol:
            isnear = smin < 1e-3 * max(smax, 1e-300)
        else:
            isnear = imag[j] <= 1e-4
        if isnear:
            near[nnear, 0], near[nnear, 1], near[nnear, 2], near[nnear, 3] = y0, y1, v[0], v[1]
            nnear += 1
    for h in _FOLD:
        for sgn in (1.0, -1.0):
            for j in range(nnear):
                x[m, 0] = near[j, 0] + sgn * h * near[j, 2]
                x[m, 1] = near[j, 1] + sgn * h * near[j, 3]
                err[m] = _rod_newton_k(x[m], tip, max_iter, True)
                m += 1
    kk = np.empty(2)
    th = np.empty(2)
    rot = np.empty((3, 3))
    out = 0
    for j in range(m):
        r_, p_ = _wrap_k(x[j, 0]), _wrap_k(x[j, 1])
        if not (err[j] <= tol and abs(r_) <= PLATFORM_LIMIT + _LIMIT_TOL and abs(p_) <= PLATFORM_LIMIT + _LIMIT_TOL):
            continue
        r_ = min(max(r_, -PLATFORM_LIMIT), PLATFORM_LIMIT)
        p_ = min(max(p_, -PLATFORM_LIMIT), PLATFORM_LIMIT)
        _rot_k(r_, p_, rot)
        _chain_k(rot, 0, 1.0, K_TOL, th, kk)
        _chain_k(rot, 1, 1.0, K_TOL, th, kk)
        _rod_system_k(r_, p_, tip, g, nm)
        xs[out, 0], xs[out, 1] = r_, p_
        cr, sr, cp, sp = math.cos(r_), math.sin(r_), math.cos(p_), math.sin(p_)
        for i in range(2):
            if i == 0:
                ax, ay, az, sg = _AX0, _AY0, _AZ0, 1.0
            else:
                ax, ay, az, sg = _AX1, _AY1, _AZ1, -1.0
            rx = cp * ax + sp * az
            ry = sr * sp * ax + cr * ay - sr * cp * az
            rz = -cr * sp * ax + sr * ay + cr * cp * az
            dd = ((_CX + rx - tip[i, 0]) * dtip[i, 0] + (_CY + ry - tip[i, 1]) * dtip[i, 1]
                  + (_CZ + rz - tip[i, 2]) * dtip[i, 2])
            bl[out, i] = 0.0 if abs(abs(kk[i]) - 1.0) <= BOUNDARY_TOL else -sg * _sgn(dd)
        sdet[out] = _sgn(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])
        out += 1
    return out


@kernel
def _ref_sign_k(b1, b2):
    """Sign of det N at the neutral pose R_P = I on motor branch (b1, b2) (the reference of assembly +1)."""
    rot = np.eye(3)
    th = np.empty(2)
    kk = np.empty(2)
    _chains_k(rot, b1, b2, K_TOL, th, kk)
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    _tips_k(th[0], th[1], tip, dtip)
    g = np.empty(2)
    nm = np.empty((2, 2))
    _rod_system_k(0.0, 0.0, tip, g, nm)
    return _sgn(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])


_REF = np.array([[_ref_sign_k(-1.0, -1.0), _ref_sign_k(-1.0, 1.0)], [_ref_sign_k(1.0, -1.0), _ref_sign_k(1.0, 1.0)]])


@kernel
def _ref_of(b1, b2):
    return _REF[1 if b1 > 0 else 0, 1 if b2 > 0 else 0]


@kernel
def _fk_select_k(t1, t2, b1, b2, s, tol, max_iter, x):
    """The pose x (2,) of motors (t1, t2) in mode (b1, b2), s within the limits nearest R_P = I (the numpy
    ``_fk_select``). Returns _OK, _ST_INPUT (non-finite motors) or _ST_ASSEMBLE (x NaN)."""
    x[0] = math.nan
    x[1] = math.nan
    if not (math.isfinite(t1) and math.isfinite(t2)):
        return _ST_INPUT
    xs = np.empty((_MAX_SOL, 2))
    bl = np.empty((_MAX_SOL, 2))
    sdet = np.empty(_MAX_SOL)
    m = _solutions_k(t1, t2, tol, max_iter, xs, bl, sdet)
    ref = _ref_of(b1, b2)
    best = math.inf
    for j in range(m):
        if not ((bl[j, 0] == b1 or bl[j, 0] == 0.0) and (bl[j, 1] == b2 or bl[j, 1] == 0.0) and sdet[j] * ref == s):
            continue
        nrm = math.hypot(xs[j, 0], xs[j, 1])
        if nrm < best:
            best = nrm
            x[0], x[1] = xs[j, 0], xs[j, 1]
    return OK if best < math.inf else _ST_ASSEMBLE


@batch_kernel
def _fk_select_b(t1, t2, b1, b2, s, tol, max_iter, x, ok):
    for j in prange(t1.shape[0]):
        ok[j] = _fk_select_k(t1[j], t2[j], b1[j], b2[j], s[j], tol, max_iter, x[j]) == OK


@kernel
def _fk_select_s(t1, t2, b1, b2, s, tol, max_iter, x, ok):
    for j in range(t1.shape[0]):
        ok[j] = _fk_select_k(t1[j], t2[j], b1[j], b2[j], s[j], tol, max_iter, x[j]) == OK


@kernel
def _poses_k(t1, t2, tol, max_iter, x, br, asm):
    """:func:`platform_poses` for one motor pair: every pose (nearest R_P = I first, duplicates - the same pose
    with the same sign of det N - dropped), its motor branch and assembly mode, into x (8, 2), br (8, 2),
    asm (8,) (NaN / 0 padded). Returns the number of poses."""
    x[:, :] = math.nan
    br[:, :] = 0
    asm[:] = 0
    if not (math.isfinite(t1) and math.isfinite(t2)):
        return 0
    xs = np.empty((_MAX_SOL, 2))
    bl = np.empty((_MAX_SOL, 2))
    sdet = np.empty(_MAX_SOL)
    m = _solutions_k(t1, t2, tol, max_iter, xs, bl, sdet)
    nrm = np.empty(m)
    for j in range(m):
        nrm[j] = math.hypot(xs[j, 0], xs[j, 1])
    order = np.argsort(nrm, kind="mergesort")
    sd = np.zeros(8)
    cnt = 0
    for c in order:
        if cnt >= 8:
            break
        dup = False
        for q in range(cnt):
            if max(abs(x[q, 0] - xs[c, 0]), abs(x[q, 1] - xs[c, 1])) <= 1e-9 and sd[q] == sdet[c]:
                dup = True
                break
        if dup:
            continue
        x[cnt, 0], x[cnt, 1] = xs[c, 0], xs[c, 1]
        sd[cnt] = sdet[c]
        br[cnt, 0], br[cnt, 1] = int(bl[c, 0]), int(bl[c, 1])
        asm[cnt] = int(sdet[c] * _ref_of(1.0 if bl[c, 0] == 0.0 else bl[c, 0], 1.0 if bl[c, 1] == 0.0 else bl[c, 1]))
        cnt += 1
    return cnt


@batch_kernel
def _poses_b(t1, t2, tol, max_iter, x, br, asm):
    for j in prange(t1.shape[0]):
        _poses_k(t1[j], t2[j], tol, max_iter, x[j], br[j], asm[j])


@kernel
def _poses_s(t1, t2, tol, max_iter, x, br, asm):
    for j in range(t1.shape[0]):
        _poses_k(t1[j], t2[j], tol, max_iter, x[j], br[j], asm[j])


@kernel
def _fk_guess_k(t1, t2, g0, g1, b1, b2, tol, max_iter, x):
    """:func:`platform_orientation` from a guess: plain Newton from (g0, g1), then the pose must close both rods
    within tol and give back the motors (t1, t2) on branch (b1, b2). Returns _OK or _ST_ASSEMBLE (x NaN)."""
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    _tips_k(t1, t2, tip, dtip)
    x[0], x[1] = g0, g1
    err = _rod_newton_k(x, tip, max_iter, False)
    x[0], x[1] = _wrap_k(x[0]), _wrap_k(x[1])
    ok = err <= tol
    if ok:
        rot = np.empty((3, 3))
        _rot_k(x[0], x[1], rot)
        th = np.empty(2)
        kk = np.empty(2)
        ok = _chains_k(rot, b1, b2, K_TOL, th, kk) == OK
        ok = ok and max(abs(_wrap_k(th[0] - t1)), abs(_wrap_k(th[1] - t2))) <= 1e-6
    if ok:
        return OK
    x[0], x[1] = math.nan, math.nan
    return _ST_ASSEMBLE


@batch_kernel
def _fk_guess_b(t1, t2, g, b1, b2, tol, max_iter, x, ok):
    for j in prange(t1.shape[0]):
        ok[j] = _fk_guess_k(t1[j], t2[j], g[j, 0], g[j, 1], b1, b2, tol, max_iter, x[j]) == OK


@kernel
def _fk_guess_s(t1, t2, g, b1, b2, tol, max_iter, x, ok):
    for j in range(t1.shape[0]):
        ok[j] = _fk_guess_k(t1[j], t2[j], g[j, 0], g[j, 1], b1, b2, tol, max_iter, x[j]) == OK


@kernel
def _rod_rates_k(r, p, tip, dtip, nm, dd):
    """The rod system's Jacobian ``N = dg/d(roll, pitch)`` (into nm) and ``D_i = (c_i - tip_i) . dtip_i``, the
    rate of rod i's residual per motor radian (into dd), at the pose (r, p) closed by the lever tips tip."""
    g = np.empty(2)
    _rod_system_k(r, p, tip, g, nm)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    for i in range(2):
        if i == 0:
            ax, ay, az = _AX0, _AY0, _AZ0
        else:
            ax, ay, az = _AX1, _AY1, _AZ1
        rx = cp * ax + sp * az
        ry = sr * sp * ax + cr * ay - sr * cp * az
        rz = -cr * sp * ax + sr * ay + cr * cp * az
        dd[i] = ((_CX + rx - tip[i, 0]) * dtip[i, 0] + (_CY + ry - tip[i, 1]) * dtip[i, 1]
                 + (_CZ + rz - tip[i, 2]) * dtip[i, 2])


@kernel
def _gain_k(r, p, tll, tip, dtip):
    """Spectral norm of d(foot)/d(theta1, theta2) (m/rad) at the pose (r, p) closed by the lever tips tip:
    ``dx/dtheta = N^-1 diag(D)``, ``dp/dx = [e_x x R f, (Rx(roll) e_y) x R f]``; inf on det N = 0."""
    nm = np.empty((2, 2))
    dd = np.empty(2)
    _rod_rates_k(r, p, tip, dtip, nm, dd)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
    # adj(N) diag(D)
    j00, j01 = nm[1, 1] * dd[0], -nm[0, 1] * dd[1]
    j10, j11 = -nm[1, 0] * dd[0], nm[0, 0] * dd[1]
    ffx = _OX + FOOT_X * math.cos(tll)
    ffz = _OZ - FOOT_X * math.sin(tll)
    fx = cp * ffx + sp * ffz
    fy = sr * sp * ffx - sr * cp * ffz
    fz = -cr * sp * ffx + cr * cp * ffz
    # dp/dx rows: (0, cr fz - sr fy), (-fz, sr fx), (fy, -cr fx)
    q0, q1 = cr * fz - sr * fy, sr * fx
    m00, m01 = q0 * j10, q0 * j11
    m10, m11 = -fz * j00 + q1 * j10, -fz * j01 + q1 * j11
    m20, m21 = fy * j00 - cr * fx * j10, fy * j01 - cr * fx * j11
    a = m00 * m00 + m10 * m10 + m20 * m20
    b = m00 * m01 + m10 * m11 + m20 * m21
    c = m01 * m01 + m11 * m11 + m21 * m21
    gain = math.sqrt(0.5 * (a + c) + math.sqrt(0.25 * (a - c) ** 2 + b * b)) / abs(det)
    return gain if math.isfinite(gain) else math.inf


@kernel
def _foot_position_k(t1, t2, t0, sv, b1, b2, s, out, aux):
    """:func:`foot_position`: the FK pose in mode (b1, b2), s, the band check, the foot. aux = (roll, pitch,
    gain). Returns _OK, _ST_INPUT, _ST_ASSEMBLE or _ST_BAND (out NaN then)."""
    out[0] = math.nan
    out[1] = math.nan
    out[2] = math.nan
    if not math.isfinite(t0):
        return _ST_INPUT
    x = aux[:2]
    st = _fk_select_k(t1, t2, b1, b2, s, 1e-12, 50, x)
    aux[2] = math.inf
    if st != OK:
        return st
    tll = -RATIO * t0 + sv
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    _tips_k(t1, t2, tip, dtip)
    aux[2] = _gain_k(x[0], x[1], tll, tip, dtip)
    if not (aux[2] < FK_GAIN_MAX):
        return _ST_BAND
    return _foot_k(x[0], x[1], tll, out)


@batch_kernel
def _foot_position_b(t1, t2, t0, sv, b1, b2, s, out, aux, st):
    for j in prange(t1.shape[0]):
        st[j] = _foot_position_k(t1[j], t2[j], t0[j], sv, b1, b2, s, out[j], aux[j])


@kernel
def _foot_position_s(t1, t2, t0, sv, b1, b2, s, out, aux, st):
    for j in range(t1.shape[0]):
        st[j] = _foot_position_k(t1[j], t2[j], t0[j], sv, b1, b2, s, out[j], aux[j])


# --- foot IK (closed form per branch; see foot_platform_ik and foot_ik)
@kernel
def _ik_candidate_k(ux, uy, uz, sv, llb, rb, b1, b2, pose, motors, info):
    """One (ll_branch, roll_branch, motor branch) closed-form candidate for the target u = p - CENTER.

    pose (3,) = (theta_LL, roll, pitch) (:func:`foot_platform_ik`: the LL arc, then roll and pitch), motors (3,)
    = (theta1, theta2, theta0) (the chains of :func:`motor_angles` with IK_K_TOL, eq 19 inverted), NaN where the
    candidate does not exist; info (7,) = (exists, inlim, mode, gain, kk, reach, axis) as floats (see
    :func:`_ik_candidate`). Returns _OK if the candidate exists, else _ST_REACH.
    """
    # the LL arc: |u|^2 = LL0^2 + h^2 - 2 h LL0 cos(theta_LL - delta)
    r2 = ux * ux + uy * uy + uz * uz
    kk = (_LL0 * _LL0 + _H * _H - r2) / (2.0 * _H * _LL0)
    reach = math.isfinite(kk) and abs(kk) <= 1.0 + LL_TOL
    kc = min(max(kk if reach else 1.0, -1.0), 1.0)
    tll = LL_DELTA + llb * math.acos(kc)
    fx = _OX + FOOT_X * math.cos(tll)
    fz = _OZ - FOOT_X * math.sin(tll)
    # roll and pitch: u = Rx(roll) v, v = Ry(pitch) f, v_y = 0
    rho = math.hypot(uy, uz)
    sg = (1.0 if uz >= 0.0 else -1.0) * rb
    vz = sg * rho
    if rho <= RHO_TOL:
        roll = 0.0 if rb > 0 else math.pi
    else:
        roll = math.atan2(-uy * sg, uz * sg)
    pitch = math.atan2(fz, fx) - math.atan2(vz, ux)
    x0, x1, x2 = _wrap_k(tll), _wrap_k(roll), _wrap_k(pitch)
    near1 = abs(x1) <= PLATFORM_LIMIT + _LIMIT_TOL
    near2 = abs(x2) <= PLATFORM_LIMIT + _LIMIT_TOL
    inlim = near1 and near2
    if near1:  # rounding at a limit
        x1 = min(max(x1, -PLATFORM_LIMIT), PLATFORM_LIMIT)
    if near2:
        x2 = min(max(x2, -PLATFORM_LIMIT), PLATFORM_LIMIT)
    pose[0], pose[1], pose[2] = x0, x1, x2
    rot = np.empty((3, 3))
    _rot_k(x1, x2, rot)
    th = np.empty(2)
    kx = np.empty(2)
    ok1 = _chain_k(rot, 0, b1, IK_K_TOL, th, kx)
    ok2 = _chain_k(rot, 1, b2, IK_K_TOL, th, kx)
    exists = reach and ok1 and ok2
    gain = math.inf
    mode = 0.0
    if exists:
        tip = np.empty((2, 3))
        dtip = np.empty((2, 3))
        _tips_k(th[0], th[1], tip, dtip)
        g = np.empty(2)
        nm = np.empty((2, 2))
        _rod_system_k(x1, x2, tip, g, nm)
        # a chain clipped at its reach boundary (|k| up to 1 + IK_K_TOL) leaves its rod off by g: the FK pose of
        # these motor angles moves by ~N^-1 g and the foot by at most |u| sqrt(2) times that
        det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
        s0 = (nm[1, 1] * g[0] - nm[0, 1] * g[1]) / det
        s1 = (nm[0, 0] * g[1] - nm[1, 0] * g[0]) / det
        shift = math.sqrt(s0 * s0 + s1 * s1) * math.sqrt(2.0) * math.sqrt(r2)
        clipped = min(abs(abs(kx[0]) - 1.0), abs(abs(kx[1]) - 1.0)) <= IK_K_TOL
        exists = (not clipped) or shift <= CLIP_FOOT_TOL
        if exists:
            mode = _sgn(det) * _ref_of(b1, b2)
            gain = _gain_k(x1, x2, x0, tip, dtip)
    if exists:
        motors[0], motors[1], motors[2] = th[0], th[1], (sv - x0) / RATIO
    else:
        motors[0], motors[1], motors[2] = math.nan, math.nan, math.nan
    info[0] = 1.0 if exists else 0.0
    info[1] = 1.0 if inlim else 0.0
    info[2], info[3], info[4] = mode, gain, kk
    info[5] = 1.0 if reach else 0.0
    info[6] = 0.0 if rho > 0.0 else 1.0
    return OK if exists else _ST_REACH


@batch_kernel
def _ik_candidate_b(u, sv, llb, rb, b1, b2, pose, motors, info):
    for j in prange(u.shape[0]):
        _ik_candidate_k(u[j, 0], u[j, 1], u[j, 2], sv, llb[j], rb[j], b1[j], b2[j], pose[j], motors[j], info[j])


@kernel
def _ik_candidate_s(u, sv, llb, rb, b1, b2, pose, motors, info):
    for j in range(u.shape[0]):
        _ik_candidate_k(u[j, 0], u[j, 1], u[j, 2], sv, llb[j], rb[j], b1[j], b2[j], pose[j], motors[j], info[j])


@kernel
def _accepted_k(pose, motors, info, b1, b2, s):
    """The mode-checked IK keeps the candidate: inside the limits, in mode (b1, b2), s, off the forward-singularity
    band, and the pose the forward kinematics of its motor angles returns in that mode. The neutral aspect
    (branch (1, 1), mode +1, pitch < PITCH_SPLIT) is one-to-one and nearer R_P = I than the other region of that
    mode: there the forward kinematics returns exactly these poses; elsewhere it is asked."""
    if not (info[0] == 1.0 and info[1] == 1.0 and info[2] == s and info[3] < FK_GAIN_MAX):
        return False
    if b1 == 1.0 and b2 == 1.0 and s == 1.0 and pose[2] < PITCH_SPLIT:
        return True
    xf = np.empty(2)
    if _fk_select_k(motors[0], motors[1], b1, b2, s, 1e-12, 50, xf) != OK:
        return False
    return max(abs(xf[0] - pose[1]), abs(xf[1] - pose[2])) <= 1e-7


@kernel
def _foot_ik_k(ux, uy, uz, sv, combos, b1, b2, s, limits_only, axis_ok, motors, pose):
    """The mode-checked foot IK of one target u = p - CENTER: the first candidate, in the order combos (k, 2) of (ll_branch,
    roll_branch), that :func:`_accepted_k` keeps (limits_only: that reaches the LL arc inside the joint limits,
    as the default :func:`foot_platform_ik`; not axis_ok: off the roll axis). motors (3,), pose (3,); returns _OK
    or _ST_ASSEMBLE (NaN)."""
    info = np.empty(7)
    if not (math.isfinite(ux) and math.isfinite(uy) and math.isfinite(uz)):
        motors[:] = math.nan
        pose[:] = math.nan
        return _ST_INPUT
    for c in range(combos.shape[0]):
        _ik_candidate_k(ux, uy, uz, sv, combos[c, 0], combos[c, 1], b1, b2, pose, motors, info)
        if limits_only:
            acc = info[5] == 1.0 and info[1] == 1.0
        else:
            acc = _accepted_k(pose, motors, info, b1, b2, s)
        if acc and (axis_ok or info[6] == 0.0):
            return OK
    motors[:] = math.nan
    pose[:] = math.nan
    return _ST_ASSEMBLE


@batch_kernel
def _foot_ik_b(u, sv, combos, b1, b2, s, limits_only, axis_ok, motors, pose, ok):
    for j in prange(u.shape[0]):
        ok[j] = _foot_ik_k(u[j, 0], u[j, 1], u[j, 2], sv, combos, b1, b2, s, limits_only, axis_ok, motors[j],
                           pose[j]) == OK


@kernel
def _foot_ik_s(u, sv, combos, b1, b2, s, limits_only, axis_ok, motors, pose, ok):
    for j in range(u.shape[0]):
        ok[j] = _foot_ik_k(u[j, 0], u[j, 1], u[j, 2], sv, combos, b1, b2, s, limits_only, axis_ok, motors[j],
                           pose[j]) == OK


@kernel
def _foot_jacobian_k(t1, t2, t0, sv, b1, b2, s, jac):
    """:func:`foot_jacobian`: d(foot)/d(theta1, theta2, theta0) (3, 3) at the FK pose in mode (b1, b2), s.

    ``dx/dtheta = N^-1 diag(D)``, ``dp/droll = e_x x R f``, ``dp/dpitch = (Rx(roll) e_y) x R f``,
    ``dp/dtheta0 = -RATIO R_P df/dtheta_LL`` (eq 19). Returns _OK, _ST_INPUT, _ST_ASSEMBLE or _ST_SINGULAR
    (N singular; jac NaN then)."""
    jac[:, :] = math.nan
    if not math.isfinite(t0):
        return _ST_INPUT
    x = np.empty(2)
    st = _fk_select_k(t1, t2, b1, b2, s, 1e-12, 50, x)
    if st != OK:
        return st
    r, p = x[0], x[1]
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    _tips_k(t1, t2, tip, dtip)
    nm = np.empty((2, 2))
    dd = np.empty(2)
    _rod_rates_k(r, p, tip, dtip, nm, dd)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
    scale = max(max(abs(nm[0, 0]), abs(nm[0, 1])), max(abs(nm[1, 0]), abs(nm[1, 1]))) ** 2
    if not abs(det) > 1e-12 * max(scale, 1e-300):
        return _ST_SINGULAR
    # dx/dtheta = N^-1 diag(D)
    d00, d01 = nm[1, 1] / det * dd[0], -nm[0, 1] / det * dd[1]
    d10, d11 = -nm[1, 0] / det * dd[0], nm[0, 0] / det * dd[1]
    tll = -RATIO * t0 + sv
    ct, st_ = math.cos(tll), math.sin(tll)
    ffx, ffz = _OX + FOOT_X * ct, _OZ - FOOT_X * st_
    dfx, dfz = -FOOT_X * st_, -FOOT_X * ct
    fx = cp * ffx + sp * ffz
    fy = sr * sp * ffx - sr * cp * ffz
    fz = -cr * sp * ffx + cr * cp * ffz
    # dp/dx (3, 2): columns e_x x R f = (0, -fz, fy) and (0, cr, sr) x R f = (cr fz - sr fy, sr fx, -cr fx)
    a0, a1, a2 = 0.0, -fz, fy
    c0, c1, c2 = cr * fz - sr * fy, sr * fx, -cr * fx
    jac[0, 0], jac[0, 1] = a0 * d00 + c0 * d10, a0 * d01 + c0 * d11
    jac[1, 0], jac[1, 1] = a1 * d00 + c1 * d10, a1 * d01 + c1 * d11
    jac[2, 0], jac[2, 1] = a2 * d00 + c2 * d10, a2 * d01 + c2 * d11
    jac[0, 2] = -RATIO * (cp * dfx + sp * dfz)
    jac[1, 2] = -RATIO * (sr * sp * dfx - sr * cp * dfz)
    jac[2, 2] = -RATIO * (-cr * sp * dfx + cr * cp * dfz)
    return OK


@batch_kernel
def _foot_jacobian_b(t1, t2, t0, sv, b1, b2, s, jac, st):
    for j in prange(t1.shape[0]):
        st[j] = _foot_jacobian_k(t1[j], t2[j], t0[j], sv, b1, b2, s, jac[j])


@kernel
def _foot_jacobian_s(t1, t2, t0, sv, b1, b2, s, jac, st):
    for j in range(t1.shape[0]):
        st[j] = _foot_jacobian_k(t1[j], t2[j], t0[j], sv, b1, b2, s, jac[j])


@kernel
def _motor_jacobian_k(r, p, b1, b2, jac, kout, mode):
    """:func:`motor_jacobian` jac (2, 2) = d(theta1, theta2)/d(roll, pitch) = D^-1 N and :func:`assembly_mode`
    mode (1,) = sign(det N) x its sign at R_P = I on (b1, b2), at the pose (r, p). Returns _OK, _ST_INPUT,
    _ST_REACH (jac NaN, mode 0) or _ST_SINGULAR (on the reach boundary, D = 0: jac NaN)."""
    jac[:, :] = math.nan
    mode[0] = 0.0
    th = np.empty(2)
    st = _motor_angles_k(r, p, b1, b2, th, kout)
    if st != OK:
        return st
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    _tips_k(th[0], th[1], tip, dtip)
    nm = np.empty((2, 2))
    dd = np.empty(2)
    _rod_rates_k(r, p, tip, dtip, nm, dd)
    mode[0] = _sgn(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]) * _ref_of(b1, b2)
    for i in range(2):
        if dd[i] == 0.0:
            jac[:, :] = math.nan
            return _ST_SINGULAR
        jac[i, 0] = nm[i, 0] / dd[i]
        jac[i, 1] = nm[i, 1] / dd[i]
    for i in range(2):
        for j in range(2):
            if not math.isfinite(jac[i, j]):
                jac[:, :] = math.nan
                return _ST_SINGULAR
    return OK


@batch_kernel
def _motor_jacobian_b(r, p, b1, b2, jac, kout, mode, st):
    for j in prange(r.shape[0]):
        st[j] = _motor_jacobian_k(r[j], p[j], b1, b2, jac[j], kout[j], mode[j])


@kernel
def _motor_jacobian_s(r, p, b1, b2, jac, kout, mode, st):
    for j in range(r.shape[0]):
        st[j] = _motor_jacobian_k(r[j], p[j], b1, b2, jac[j], kout[j], mode[j])






_REF_SIGN = {b: float(_ref_of(float(b[0]), float(b[1]))) for b in MOTOR_BRANCHES}


def _assembly_ref(b: np.ndarray):
    """Sign of det N at the neutral pose on motor branch b: (2,) -> float, (..., 2) -> (...,)."""
    b = np.asarray(b, dtype=float)
    if b.ndim == 1:
        return _REF_SIGN[(int(b[0]), int(b[1]))]
    p0, p1 = b[..., 0] > 0, b[..., 1] > 0
    return np.where(p0, np.where(p1, _REF_SIGN[(1, 1)], _REF_SIGN[(1, -1)]),
                    np.where(p1, _REF_SIGN[(-1, 1)], _REF_SIGN[(-1, -1)]))


def _fk_select(theta: np.ndarray, b: np.ndarray, s, tol: float = 1e-12, max_iter: int = 50):
    """The pose (n, 2) of motor angles theta (n, 2) in mode (b, s) within the limits nearest R_P = I, and ok
    (the batch kernel :func:`_fk_select_b`). b (2,) or (n, 2), s scalar or (n,)."""
    n = len(theta)
    bb = np.broadcast_to(np.asarray(b, dtype=np.float64), (n, 2))
    ss = np.array(np.broadcast_to(np.asarray(s, dtype=np.float64), (n,)), dtype=np.float64)
    x = np.empty((n, 2))
    ok = np.empty(n, dtype=np.bool_)
    _loop(_fk_select_b, _fk_select_s, n)(np.array(theta[:, 0], dtype=np.float64), np.array(theta[:, 1], dtype=np.float64),
                                         np.array(bb[:, 0]), np.array(bb[:, 1]), ss, float(tol), int(max_iter), x, ok)
    return x, ok


def assembly_mode(roll, pitch, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """Assembly mode (..., ) of platform poses on a motor branch: +1, -1 (0 on the forward singularity).

    +1 where det(dtheta/d(roll, pitch)) (:func:`motor_jacobian`) has the sign it has at the neutral pose
    R_P = I on the same branch (equivalently det N, ``N_ik = d_i . dA_i/dx_k``), -1 where it has the other
    sign. The mechanism is built in mode +1 on branch (1, 1) (the SRDF pose ``neutral``).

    Raises:
        UnreachableError: single pose out of the motors' reach on that branch.
    """
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = _check_branch(branch)
    _check_flag(return_mask, "return_mask")
    _, k, st, mode = _jacobian_and_mode(r, p, b)
    ok = st != _ST_REACH
    mode = mode.astype(int)
    what = f"(roll, pitch) = ({float(r):.6g}, {float(p):.6g})" if r.ndim == 0 else ""
    return finish(mode, ok, r.ndim == 0, return_mask, lambda: _unreachable(what, k))


class PlatformPoses(NamedTuple):
    """Every platform pose of :func:`platform_poses`, nearest R_P = I first (NaN / 0 padded to 8)."""

    #: (..., 8, 2) (roll, pitch), NaN where there is no further pose.
    x: np.ndarray
    #: (..., 8, 2) motor branch of each chain: +1, -1, or 0 on the chain's reach boundary (both branches).
    branch: np.ndarray
    #: (..., 8) assembly mode on that branch (+1: as at R_P = I); for a boundary chain, that of branch +1.
    assembly: np.ndarray
    #: (..., 8) True where there is a pose.
    mask: np.ndarray


def platform_poses(theta1, theta2, *, tol: float = 1e-12, max_iter: int = 50) -> PlatformPoses:
    """Every platform pose within the joint limits for motor angles (theta1, theta2), with its mode.

    The forward kinematics of the closed sub-chain in closed form (see :func:`platform_orientation`): the real
    roots of a degree-8 polynomial in tan(roll / 2), the pitch of each from the two (linear in cos, sin) rod
    equations, polished by Newton's method. All modes, nearest R_P = I first. Never raises for valid input (a
    single input gives arrays of shape (8, ...)).
    """
    t1, t2 = as_angles(theta1, theta2, names=("theta1", "theta2"))
    tol = _check_real(tol, "tol", 0.0, 1e-6, "rod-length residual, m")
    max_iter = _check_count(max_iter, "max_iter", 1, 10_000, "Newton iterations")
    shape = t1.shape
    n = t1.size
    x = np.empty((n, 8, 2))
    bran = np.empty((n, 8, 2), dtype=np.int64)
    asm = np.empty((n, 8), dtype=np.int64)
    _loop(_poses_b, _poses_s, n)(_flat(t1), _flat(t2),
             tol, max_iter, x, bran, asm)
    mask = np.isfinite(x[..., 0])
    return PlatformPoses(x.reshape(shape + (8, 2)), bran.reshape(shape + (8, 2)), asm.reshape(shape + (8,)),
                         mask.reshape(shape + (8,)))


def platform_orientation(
    theta1,
    theta2,
    branch: Sequence[int] = (1, 1),
    *,
    assembly: int = 1,
    guess=None,
    steps: int = 4,
    tol: float = 1e-12,
    max_iter: int = 50,
    return_mask: bool = False,
):
    """(roll, pitch) (..., 2) of the universal-centre platform for motor angles (theta1, theta2).

    Forward kinematics of the closed sub-chain (seed eqs 1-16 with both motors given), in closed form: with
    the lever tips known, rod i closes iff ``w_i . R_P a_i = kappa_i`` (``w_i = c - S_i``), which is linear in
    (cos pitch, sin pitch); eliminating the pitch leaves a polynomial of degree 8 in tan(roll / 2). Its real
    roots with |roll| <= pi/2 give every pose within the joint limits (:func:`platform_poses`), each polished by
    Newton's method on the rod equations (with the forward-singularity barrier near det N = 0). The answer is
    the pose on motor branch ``branch`` in assembly mode ``assembly`` (:func:`assembly_mode`); if that mode
    holds several poses, the one nearest R_P = I. The defaults (branch (1, 1), mode +1) are the mode the
    mechanism is built in (SRDF ``neutral``); there the motor map is one-to-one over the pitches below
    :data:`PITCH_SPLIT`, and the region of the same sign beyond it (pitch >= 1.48 rad) is only used when the
    motors reach no pose below it. Near the forward singularity (det N = 0, where the platform could move with
    the motors locked) the solution is ill-conditioned: error ~ 1e-16 / sigma_min(dtheta/dx).

    Args:
        theta1, theta2: motor angles (rad), broadcast together.
        branch: the motor branch pair (b1, b2) the solution must lie on (a chain on its reach boundary lies on
            both).
        assembly: +1 (default) or -1, see :func:`assembly_mode`.
        guess: starting (roll, pitch) (..., 2): plain Newton from it instead (the pose it reaches on ``branch``,
            whatever its assembly mode).
        steps: unused since the forward kinematics is solved in closed form (kept for compatibility;
            an integer in [1, 1000]).
        tol: required rod-length residual | |A_i - S_i| - L | (m), in (0, 1e-6].
        max_iter: Newton iterations, in [1, 10000].

    Raises:
        ConvergenceError: single input whose closed sub-chain does not assemble in that mode within the joint
            limits (the message lists the modes in which it does).
    """
    if (return_mask is False and guess is None and type(theta1) in _SCALARS and type(theta2) in _SCALARS
            and type(steps) is int and 1 <= steps <= 1000 and type(tol) is float and 0.0 < tol <= 1e-6
            and type(max_iter) is int and 1 <= max_iter <= 10_000):
        fb, fs = _fast_branch(branch), _fast_sign(assembly)
        if fb is not None and fs is not None:
            x = np.empty(2)
            if _fk_select_k(theta1, theta2, fb[0], fb[1], fs, tol, max_iter, x) == OK:
                return x
    t1, t2 = as_angles(theta1, theta2, names=("theta1", "theta2"))
    b = _check_branch(branch)
    s = _check_assembly(assembly)
    _check_count(steps, "steps", 1, 1000, "unused, kept for compatibility")
    tol = _check_real(tol, "tol", 0.0, 1e-6, "rod-length residual, m")
    max_iter = _check_count(max_iter, "max_iter", 1, 10_000, "Newton iterations")
    _check_flag(return_mask, "return_mask")
    shape = t1.shape
    target = np.stack([t1, t2], -1).reshape(-1, 2)
    if guess is not None:
        g = as_input(guess, "guess", (2,))
        try:
            g = np.broadcast_to(g, shape + (2,)).reshape(-1, 2)
        except ValueError:
            raise InvalidInputError(f"guess must broadcast to shape {shape + (2,)}, got shape {g.shape}") from None
        x = np.empty((len(target), 2))
        ok = np.empty(len(target), dtype=np.bool_)
        _loop(_fk_guess_b, _fk_guess_s, len(target))(
            np.array(target[:, 0], dtype=np.float64), np.array(target[:, 1], dtype=np.float64),
            np.array(g, dtype=np.float64), float(b[0]), float(b[1]), tol, max_iter, x, ok)
    else:
        x, ok = _fk_select(target, b, s, tol, max_iter)
    x = np.where(ok[:, None], x, np.nan).reshape(shape + (2,))
    ok = ok.reshape(shape)

    def error():
        return ConvergenceError(_fk_failure(float(t1), float(t2), b, s, guess is not None))

    return finish(x, ok, t1.ndim == 0, return_mask, error)


def _mode_text(b, s) -> str:
    return f"branch=({int(b[0])}, {int(b[1])}), assembly={int(s):+d}"


def _fk_failure(t1: float, t2: float, b: np.ndarray, s: float, guessed: bool = False) -> str:
    what = f"(theta1, theta2) = ({t1:.17g}, {t2:.17g})"
    if guessed:
        return (f"platform_orientation: Newton from the guess did not close both rods for {what} on branch "
                f"({int(b[0])}, {int(b[1])}) within the joint limits")
    poses = platform_poses(t1, t2)
    found = [f"({pose[0]:.6g}, {pose[1]:.6g}) on branch ({br[0]}, {br[1]}) in assembly mode {a:+d}"
             for pose, br, a, m in zip(poses.x, poses.branch, poses.assembly, poses.mask) if m]
    return (f"the closed sub-chain does not assemble for {what} in mode {_mode_text(b, s)} within the joint limits "
            f"(|roll|, |pitch| <= pi/2); " + ("it does at (roll, pitch) = " + "; ".join(found) if found
                                              else "it assembles nowhere within the limits"))


# ----------------------------------------------------------------------------- foot
def _foot_in_p(theta_ll):
    """FCS in P (eqs 18, 20): (ox - 1.5 cos t, 0, oz + 1.5 sin t) and its derivative."""
    c, s = np.cos(theta_ll), np.sin(theta_ll)
    z = np.zeros_like(c)
    f = np.stack([LL_ORIGIN[0] + FOOT_X * c, z, LL_ORIGIN[2] - FOOT_X * s], -1)
    df = np.stack([-FOOT_X * s, z, -FOOT_X * c], -1)
    return f, df


def foot_position_from_platform(roll, pitch, theta_ll) -> np.ndarray:
    """Foot FCS in CCS (..., 3) from the platform angles and theta_LL: ``CENTER + R_P (o_LL + Ry(theta_LL) (-1.5, 0, 0))``.

    Seed eqs 1, 17, 18, 20 (eq 18 printed without its last row (0, 0, 0, 1)). At theta_LL = 0 the foot is at
    (0.140, 0, -0.037) in P.
    """
    if type(roll) in _SCALARS and type(pitch) in _SCALARS and type(theta_ll) in _SCALARS:
        out = np.empty(3)
        if _foot_k(roll, pitch, theta_ll, out) == OK:
            return out
    r, p, t = as_angles(roll, pitch, theta_ll, names=("roll", "pitch", "theta_ll"))
    return _foot_from_pose(r, p, t)


def _foot_from_pose(r, p, t):
    """:func:`foot_position_from_platform` of checked arrays (the batch kernel :func:`_foot_b`)."""
    out = np.empty((r.size, 3))
    _loop(_foot_b, _foot_s, r.size)(_flat(r), _flat(p),
            _flat(t), out)
    return out.reshape(r.shape + (3,))


def foot_position(
    theta1,
    theta2,
    theta0,
    *,
    starting_value: float = 0.0,
    branch: Sequence[int] = (1, 1),
    assembly: int = 1,
    return_mask: bool = False,
):
    """Foot FCS in CCS (..., 3) for the three motors: (theta1, theta2) -> (roll, pitch) -> foot.

    :func:`platform_orientation` (the closed sub-chain, eqs 1-16, in the mode ``branch``, ``assembly``; the
    defaults are the mode of the SRDF reference pose), :func:`ll_angle` (eq 19) and
    :func:`foot_position_from_platform` (eqs 17, 18, 20). Poses in the forward-singularity band (the foot moving
    more than :data:`FK_GAIN_MAX` m per motor radian) are refused: there double-precision motor angles do not fix
    the foot to 1e-9 m.

    Raises:
        ConvergenceError: single input whose closed sub-chain does not assemble in that mode.
        SingularityError: single input in the forward-singularity band.
    """
    if (return_mask is False and type(theta1) in _SCALARS and type(theta2) in _SCALARS
            and type(theta0) in _SCALARS):
        fb, fs, fv = _fast_branch(branch), _fast_sign(assembly), _fast_offset(starting_value)
        if fb is not None and fs is not None and fv is not None:
            out, aux = np.empty(3), np.empty(3)
            if _foot_position_k(theta1, theta2, theta0, fv, fb[0], fb[1], fs, out, aux) == OK:
                return out
    t1, t2, t0 = as_angles(theta1, theta2, theta0, names=("theta1", "theta2", "theta0"))
    sv = _check_offset(starting_value)
    b = _check_branch(branch)
    s = _check_assembly(assembly)
    _check_flag(return_mask, "return_mask")
    n = t1.size
    p, aux, st = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int64)
    _loop(_foot_position_b, _foot_position_s, n)(_flat(t1), _flat(t2),
                     _flat(t0), sv, float(b[0]), float(b[1]), s, p, aux, st)
    ok = st == OK
    x, gain = aux[:, :2], aux[:, 2]
    assembled = st != _ST_ASSEMBLE
    p = p.reshape(t1.shape + (3,))

    def error():
        if not bool(assembled[0]):
            return ConvergenceError(_fk_failure(float(t1), float(t2), b, s))
        return SingularityError(_band_message(f"(theta1, theta2) = ({float(t1):.17g}, {float(t2):.17g})", x[0], gain[0]))

    return finish(p, ok.reshape(t1.shape), t1.ndim == 0, return_mask, error)


def _band_message(what: str, x, gain: float) -> str:
    return (
        f"{what}: the platform pose (roll, pitch) = ({float(x[0]):.6g}, {float(x[1]):.6g}) is at the forward "
        f"singularity (det N = 0, the platform could move with the motors locked) or within its band: the foot moves "
        f"{gain:.3g} m per motor radian (limit FK_GAIN_MAX = {FK_GAIN_MAX:g}), so double-precision motor angles do not "
        "fix it to 1e-9 m"
    )


def _platform_ik(u: np.ndarray, ll_branch, roll_branch):
    """(theta_LL, roll, pitch) (..., 3) for u = p - CENTER, plus LL ratio kk, rho, LL reach and not-on-axis.

    ll_branch, roll_branch: +-1, scalars or per target.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        r2 = np.sum(u * u, -1)
        kk = (_LL0**2 + _H**2 - r2) / (2.0 * _H * _LL0)
    reach = np.isfinite(kk) & (np.abs(kk) <= 1.0 + LL_TOL)
    tll = LL_DELTA + ll_branch * np.arccos(np.clip(np.where(reach, kk, 1.0), -1.0, 1.0))
    f, _ = _foot_in_p(tll)
    with np.errstate(over="ignore", invalid="ignore"):
        rho = np.hypot(u[..., 1], u[..., 2])
    s = np.where(u[..., 2] >= 0.0, 1.0, -1.0) * roll_branch
    vz = s * rho
    roll = np.where(rho <= RHO_TOL, np.where(roll_branch > 0, 0.0, np.pi), np.arctan2(-u[..., 1] * s, u[..., 2] * s))
    pitch = np.arctan2(f[..., 2], f[..., 0]) - np.arctan2(vz, u[..., 0])
    out = _wrap(np.stack([tll, roll, pitch], -1))
    return out, kk, rho, reach, rho > 0.0


def _ik_candidate(u: np.ndarray, sv: float, llb, rb, b: np.ndarray) -> dict:
    """One (ll_branch, roll_branch, motor branch) closed-form candidate for targets u = p - CENTER (n, 3)
    (llb, rb scalars or (n,), b (2,) or (n, 2)).

    Keys: pose (n, 3) (theta_LL, roll, pitch), motors (n, 3) (theta1, theta2, theta0), exists (LL arc and motors
    reach), inlim (inside the URDF limits), mode (+1/-1/0, :func:`assembly_mode`), gain (m/rad), kk, reach (LL
    arc), axis (exactly on the roll axis).
    """
    n = len(u)
    ll = np.array(np.broadcast_to(np.asarray(llb, dtype=np.float64), (n,)), dtype=np.float64)
    rr = np.array(np.broadcast_to(np.asarray(rb, dtype=np.float64), (n,)), dtype=np.float64)
    bb = np.broadcast_to(np.asarray(b, dtype=np.float64), (n, 2))
    pose, motors, info = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 7))
    _loop(_ik_candidate_b, _ik_candidate_s, n)(np.array(u, dtype=np.float64).reshape(n, 3), float(sv), ll, rr,
                                               np.array(bb[:, 0]), np.array(bb[:, 1]), pose, motors, info)
    return {"pose": pose, "motors": motors, "exists": info[:, 0] == 1.0, "inlim": info[:, 1] == 1.0,
            "mode": info[:, 2], "gain": info[:, 3], "kk": info[:, 4], "reach": info[:, 5] == 1.0,
            "axis": info[:, 6] == 1.0}


def _accepted(c: dict, b: np.ndarray, s: float) -> np.ndarray:
    """Candidates the mode-checked IK keeps: inside the limits, in mode (b, s), off the forward-singularity band,
    and the pose the forward kinematics of their motor angles returns in that mode."""
    acc = c["exists"] & c["inlim"] & (c["mode"] == s) & (c["gain"] < FK_GAIN_MAX)
    # the neutral aspect (branch (1, 1), mode +1, pitch < PITCH_SPLIT) is one-to-one and nearer R_P = I than the
    # other region of that mode: the forward kinematics returns exactly these poses. Elsewhere ask it.
    n = len(acc)
    b = np.broadcast_to(np.asarray(b, dtype=float), (n, 2))
    s = np.broadcast_to(np.asarray(s, dtype=float), (n,))
    fast = np.all(b == 1.0, -1) & (s == 1.0)
    need = acc & ~(fast & (c["pose"][:, 2] < PITCH_SPLIT))
    if need.any():
        xf, okf = _fk_select(c["motors"][need, :2], b[need], s[need])
        same = okf & (np.abs(xf - c["pose"][need, 1:]).max(-1, initial=0.0) <= 1e-7)
        acc[np.flatnonzero(need)[~same]] = False
    return acc


def _combos(llb, rb) -> list:
    return [(l, r) for l, r in FOOT_IK_ORDER if (llb is None or l == llb) and (rb is None or r == rb)]


def _search(u: np.ndarray, sv: float, combos: list, b: np.ndarray, s, limits_only: bool = False,
            axis_ok: bool = True):
    """First candidate per target, in the order ``combos``, that is accepted; returns motors, pose, ok.

    limits_only: accept by LL reach and joint limits alone (foot_platform_ik); axis_ok: accept targets exactly on
    the roll axis (with roll 0 or pi).
    """
    n, k = len(u), len(combos)
    if np.ndim(b) == 1 and np.ndim(s) == 0:
        motors, pose, ok = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.bool_)
        _loop(_foot_ik_b, _foot_ik_s, n)(np.array(u, dtype=np.float64).reshape(n, 3), float(sv),
                                         np.array(combos, dtype=np.float64).reshape(-1, 2), float(b[0]), float(b[1]),
                                         float(s), bool(limits_only), bool(axis_ok), motors, pose, ok)
        return motors, pose, ok
    lls = np.repeat([float(c[0]) for c in combos], n)
    rbs = np.repeat([float(c[1]) for c in combos], n)
    uu = np.tile(u, (k, 1))
    c = _ik_candidate(uu, sv, lls, rbs, b)
    acc = (c["reach"] & c["inlim"]) if limits_only else _accepted(c, b, s)
    if not axis_ok:
        acc &= ~c["axis"]
    acc = acc.reshape(k, n)
    first = np.argmax(acc, 0)
    ok = acc[first, np.arange(n)] if n else np.zeros(0, dtype=bool)
    row = first * n + np.arange(n)
    motors = np.where(ok[:, None], c["motors"][row], np.nan)
    pose = np.where(ok[:, None], c["pose"][row], np.nan)
    return motors, pose, ok


def _fmt(p) -> str:
    return "[" + ", ".join(f"{float(v):.17g}" for v in np.ravel(p)) + "]"


def _arc_error(p: np.ndarray, kk: float) -> UnreachableError:
    r = math.hypot(*(float(v) for v in p - CENTER))  # no overflow for |p| near the float limit
    lo, hi = _LL0 - _H, _LL0 + _H
    side = f"{r - hi:.3g} m beyond its outer end" if r > hi else f"{lo - r:.3g} m inside its inner end"
    return UnreachableError(
        f"foot target {_fmt(p)} is {r:.17g} m from the LCS centre; the LL arc reaches [{lo:.17g}, {hi:.17g}] m "
        f"(+- {LL_TOL:g} in the arc's cosine for rounding): the target is {side}",
        target=p,
    )


def _axis_error(p: np.ndarray, pose: bool = True) -> SingularityError:
    if pose:
        return SingularityError(
            f"foot target {_fmt(p)} lies exactly on the platform's roll axis (x through the LCS centre): roll is "
            "undetermined, any roll reaches it (foot_ik takes roll = 0 or pi there; or move the target off the axis "
            "by any amount)"
        )
    return SingularityError(
        f"foot target {_fmt(p)} lies exactly on the platform's roll axis (x through the LCS centre), where roll is "
        "undetermined, and neither roll = 0 nor roll = pi reaches it in the mode asked for (another roll might)"
    )


def _mode_dict(llb, rb, b, s) -> dict:
    return {"ll_branch": int(llb), "roll_branch": int(rb), "branch": (int(b[0]), int(b[1])), "assembly": int(s)}


def _mode_str(m: dict) -> str:
    return (f"ll_branch={m['ll_branch']:+d}, roll_branch={m['roll_branch']:+d}, branch=({m['branch'][0]}, "
            f"{m['branch'][1]}), assembly={m['assembly']:+d}")


def _ik_error(p: np.ndarray, sv: float, combos: list, b: np.ndarray, s: float, limits_only: bool = False) -> Exception:
    """Why the mode-checked search found nothing for the single target p (3,)."""
    u = (p - CENTER)[None]
    _, kk, rho, reach, nonsing = _platform_ik(u, -1.0, 1.0)
    if not bool(reach[0]):
        return _arc_error(p, float(kk[0]))
    if not bool(nonsing[0]):
        return _axis_error(p, limits_only)
    asked = f"ll_branch, roll_branch in {combos}" + ("" if limits_only else f", {_mode_text(b, s)}")
    rows = [(llb, rb, bb) for llb, rb in FOOT_IK_ORDER for bb in MOTOR_BRANCHES]
    lls = np.array([r[0] for r in rows], float)
    rbs = np.array([r[1] for r in rows], float)
    bs = np.array([r[2] for r in rows], float)
    c16 = _ik_candidate(np.repeat(u, len(rows), 0), sv, lls, rbs, bs)
    # which of them the forward kinematics reproduces in their own mode (the band is judged separately below)
    probe = dict(c16, gain=np.zeros(len(rows)))
    fk = np.zeros(len(rows), dtype=bool)
    live = c16["exists"] & c16["inlim"] & (c16["mode"] != 0)
    if live.any():
        fk[live] = _accepted({k: v[live] for k, v in probe.items()}, bs[live], c16["mode"][live])
    cands = []
    for j, (llb, rb, bb) in enumerate(rows):
        c = {k: v[j] for k, v in c16.items()}
        bv = bs[j]
        c.update(ll=llb, rb=rb, b=bv, fk=bool(fk[j]),
                 requested=(llb, rb) in combos and (limits_only or bool(np.all(bv == b))))
        cands.append(c)
    if limits_only:
        inl = [c for c in cands if c["requested"] and c["inlim"]]
        if not inl:
            x = _platform_ik(u, combos[0][0], combos[0][1])[0][0]
            return JointLimitError(
                f"foot target {_fmt(p)} needs (theta_LL, roll, pitch) = ({x[0]:.6g}, {x[1]:.6g}, {x[2]:.6g}) or the "
                f"other branches asked for ({asked}): outside the joint limits |roll|, |pitch| <= pi/2 (LCS_x, LCS_y)",
                target=p,
            )
    # reachable in the mode asked for, but in the forward-singularity band
    band = [c for c in cands if c["requested"] and c["exists"] and c["inlim"] and c["mode"] == s and c["fk"]
            and not c["gain"] < FK_GAIN_MAX]
    if band:
        c = band[0]
        return SingularityError(_band_message(f"foot target {_fmt(p)}", c["pose"][1:], c["gain"]))
    valid = [c for c in cands if c["exists"] and c["inlim"] and c["fk"] and c["gain"] < FK_GAIN_MAX]
    if valid:
        modes = [_mode_dict(c["ll"], c["rb"], c["b"], c["mode"]) for c in valid]
        where = "; ".join(f"{_mode_str(m)} at (roll, pitch) = ({c['pose'][1]:.6g}, {c['pose'][2]:.6g})"
                          for m, c in zip(modes, valid))
        return AssemblyModeError(
            f"foot target {_fmt(p)} is reachable within the joint limits, but not in the mode asked for ({asked}); "
            f"it is reachable with {where}",
            target=p, modes=modes,
        )
    inl = [c for c in cands if c["exists"] and c["inlim"]]
    if inl:
        c = inl[0]
        return AssemblyModeError(
            f"foot target {_fmt(p)} needs (roll, pitch) = ({c['pose'][1]:.6g}, {c['pose'][2]:.6g}) (branch "
            f"({int(c['b'][0])}, {int(c['b'][1])})), a pose the forward kinematics of its motor angles does not return "
            f"(another pose of the same mode is nearer R_P = I, or it is in the forward-singularity band); asked: {asked}",
            target=p, modes=[],
        )
    out = [c for c in cands if c["exists"]]
    if out:
        c = out[0]
        raw = _platform_ik(u, float(c["ll"]), float(c["rb"]))[0][0]
        return JointLimitError(
            f"foot target {_fmt(p)} is reachable only outside the joint limits |roll|, |pitch| <= pi/2 (LCS_x, LCS_y): "
            f"{len(out)} of the 16 closed-form branches reach it, none within the limits (e.g. (roll, pitch) = "
            f"({raw[1]:.6g}, {raw[2]:.6g}) with ll_branch={c['ll']:+d}, roll_branch={c['rb']:+d})",
            target=p,
        )
    x = _platform_ik(u, combos[0][0], combos[0][1])[0][0]
    _, k, _ = _chains(_rot(x[1], x[2]), b)
    return UnreachableError(
        f"foot target {_fmt(p)} needs (roll, pitch) = ({x[1]:.6g}, {x[2]:.6g}) (ll_branch={combos[0][0]:+d}, "
        f"roll_branch={combos[0][1]:+d}): " + str(_unreachable("that platform pose", k)).split(": ", 1)[1].replace(
            "is out", "out", 1) + "; no other branch reaches it either",
        target=p,
    )


def foot_platform_ik(
    p,
    *,
    ll_branch: int | None = None,
    roll_branch: int | None = None,
    branch: Sequence[int] | None = None,
    assembly: int | None = None,
    return_mask: bool = False,
):
    """(theta_LL, roll, pitch) (..., 3) placing the foot at ``p`` (CCS), in closed form.

    Inverts :func:`foot_position_from_platform`:

    1. the distance from the LCS centre depends on theta_LL alone:
       ``|p - c|^2 = |o|^2 + h^2 - 2 h |o| cos(theta_LL - delta)`` with ``o = (1.640, -0.037)``,
       ``h = 1.5``, ``delta = atan2(0.037, 1.640)``; ``theta_LL = delta + ll_branch acos(...)``
       (``ll_branch = -1``: theta_LL <= delta, the extension side). Unreachable unless
       ``|o| - h <= |p - c| <= |o| + h`` (0.14042 to 3.14042 m, :data:`LL_TOL` of rounding allowed).
    2. ``u = p - c = Rx(roll) v``, ``v = Ry(pitch) f`` with ``f`` the foot in P: ``v_y = 0`` gives
       ``v_z = +-sqrt(u_y^2 + u_z^2)``, ``roll = atan2(-u_y / v_z, u_z / v_z)`` (``roll_branch = +1``:
       |roll| <= pi/2), and ``pitch = atan2(f_z, f_x) - atan2(v_z, u_x)``.

    Branches: with neither ``ll_branch`` nor ``roll_branch`` given (default) the branches are tried in the order
    :data:`FOOT_IK_ORDER` and the first inside the joint limits (|roll|, |pitch| <= pi/2) is returned; with
    ``branch`` / ``assembly`` given (either; the other defaults to (1, 1) / +1), also in that assembly mode, as
    :func:`foot_ik` (the foot's forward map from the pose has no assembly mode, hence no mode check by default).
    Giving ``ll_branch`` or ``roll_branch`` alone returns that closed-form branch as is (the other defaulting to
    -1 / +1), unchecked, as before.

    Singular exactly on the roll axis (``u_y = u_z = 0``: roll undetermined, SingularityError; with ``branch`` /
    ``assembly`` given, as :func:`foot_ik`, roll 0 or pi is tried there); within :data:`RHO_TOL` of it roll is
    taken as 0 (roll_branch +1) or pi (-1).

    Raises:
        UnreachableError: single target out of reach (JointLimitError: only outside the limits;
            AssemblyModeError: only in another mode).
        SingularityError: single target exactly on the roll axis.
    """
    if (ll_branch is None and roll_branch is None and branch is None and assembly is None and return_mask is False
            and type(p) is np.ndarray and p.shape == (3,) and p.dtype == np.float64):
        motors, pose = np.empty(3), np.empty(3)
        if _foot_ik_k(p[0] - _CX, p[1] - _CY, p[2] - _CZ, 0.0, _FOOT_IK_COMBOS, 1.0, 1.0, 1.0, True, False, motors,
                      pose) == OK:
            return pose
    p = as_input(p, "p", (3,))
    llb = _check_sign(ll_branch, "ll_branch", allow_none=True)
    rb = _check_sign(roll_branch, "roll_branch", allow_none=True)
    moded = branch is not None or assembly is not None
    b = _check_branch((1, 1) if branch is None else branch)
    s = _check_assembly(1 if assembly is None else assembly)
    _check_flag(return_mask, "return_mask")
    shape = p.shape[:-1]
    u = (p - CENTER).reshape(-1, 3)
    if (llb is not None or rb is not None) and not moded:
        out, kk, rho, reach, nonsing = _platform_ik(u, -1.0 if llb is None else llb, 1.0 if rb is None else rb)
        ok = reach & nonsing
        out = np.where(ok[:, None], out, np.nan)

        def error():
            return _arc_error(p, float(kk[0])) if not bool(reach[0]) else _axis_error(p)

        return finish(out.reshape(shape + (3,)), ok.reshape(shape), p.ndim == 1, return_mask, error)
    combos = _combos(llb, rb)
    _, pose, ok = _search(u, 0.0, combos, b, s, limits_only=not moded, axis_ok=moded)
    return finish(pose.reshape(shape + (3,)), ok.reshape(shape), p.ndim == 1, return_mask,
                  lambda: _ik_error(p, 0.0, combos, b, s, limits_only=not moded))


def foot_ik(
    p,
    *,
    starting_value: float = 0.0,
    ll_branch: int | None = None,
    roll_branch: int | None = None,
    branch: Sequence[int] = (1, 1),
    assembly: int = 1,
    all_branches: bool = False,
    return_mask: bool = False,
):
    """Motor angles (theta1, theta2, theta0) (..., 3) placing the foot at ``p`` (CCS), all in closed form.

    :func:`foot_platform_ik` (target -> theta_LL -> roll, pitch), :func:`motor_angles` (eqs 3-16 per chain)
    and :func:`extension_motor_angle` (eq 19 inverted).

    The IK contract: the answer is in the mode ``branch`` (motor branches), ``assembly`` (:func:`assembly_mode`)
    that :func:`foot_position` uses with the same arguments (defaults: the mode of the SRDF reference pose
    ``neutral``), inside the URDF joint limits, and :func:`foot_position` of it is the target. The IK-only
    branches ``ll_branch`` (LL side) and ``roll_branch`` are tried in the order :data:`FOOT_IK_ORDER`
    ((-1, +1), (+1, +1), (-1, -1), (+1, -1)); giving one restricts the search to it. The first candidate kept is
    inside the limits, in the mode, outside the forward-singularity band (:data:`FK_GAIN_MAX`) and the pose the
    forward kinematics returns for its motor angles.

    Args:
        p: foot targets (..., 3) in CCS.
        starting_value: LL zero offset (rad) of eq 19, in [-pi, pi].
        ll_branch, roll_branch: None (search both, default) or +1 / -1.
        branch, assembly: the assembly mode (default (1, 1), +1).
        all_branches: return every closed-form branch instead, unchecked (no limit or mode check), shape
            (..., 16, 3) in :data:`FOOT_IK_BRANCHES` order, NaN rows where a branch does not exist; the mask
            (with ``return_mask``) is then (..., 16). A single target raises only when no branch exists. Their
            modes and validity: :func:`foot_ik_solutions`.

    Raises:
        UnreachableError: single target out of reach (of the LL arc or of the motors);
            JointLimitError: reachable only outside the joint limits;
            AssemblyModeError: reachable only in other modes (``.modes`` lists the arguments that reach it).
        SingularityError: single target in the forward-singularity band, or exactly on the roll axis (where roll
            is undetermined and foot_ik tries roll = 0 and pi) with neither roll reaching it in the mode.
    """
    if (ll_branch is None and roll_branch is None and all_branches is False and return_mask is False
            and type(p) is np.ndarray and p.shape == (3,) and p.dtype == np.float64):
        fb, fs, fv = _fast_branch(branch), _fast_sign(assembly), _fast_offset(starting_value)
        if fb is not None and fs is not None and fv is not None:
            motors, pose = np.empty(3), np.empty(3)
            if _foot_ik_k(p[0] - _CX, p[1] - _CY, p[2] - _CZ, fv, _FOOT_IK_COMBOS, fb[0], fb[1], fs, False, True,
                          motors, pose) == OK:
                return motors
    p = as_input(p, "p", (3,))
    sv = _check_offset(starting_value)
    llb = _check_sign(ll_branch, "ll_branch", allow_none=True)
    rb = _check_sign(roll_branch, "roll_branch", allow_none=True)
    b = _check_branch(branch)
    s = _check_assembly(assembly)
    all_branches = _check_flag(all_branches, "all_branches")
    _check_flag(return_mask, "return_mask")
    shape = p.shape[:-1]
    u = (p - CENTER).reshape(-1, 3)
    if all_branches:
        outs, oks = [], []
        for l_, r_, b1, b2 in FOOT_IK_BRANCHES:
            c = _ik_candidate(u, sv, float(l_), float(r_), np.array([b1, b2], float))
            outs.append(c["motors"])
            oks.append(c["exists"])
        out = np.stack(outs, -2).reshape(shape + (16, 3))
        ok = np.stack(oks, -1).reshape(shape + (16,))
        if p.ndim == 1 and not bool(np.any(ok)):
            _, kk, _, reach, nonsing = _platform_ik(u, -1.0, 1.0)
            if not bool(reach[0]):
                raise _arc_error(p, float(kk[0]))
            if not bool(nonsing[0]):
                raise _axis_error(p, False)
            raise UnreachableError(f"foot target {_fmt(p)} is out of the motors' reach on every branch", target=p)
        return (out, ok) if return_mask else out
    combos = _combos(llb, rb)
    motors, _, ok = _search(u, sv, combos, b, s)
    return finish(motors.reshape(shape + (3,)), ok.reshape(shape), p.ndim == 1, return_mask,
                  lambda: _ik_error(p, sv, combos, b, s))


class FootIKSolutions(NamedTuple):
    """Every closed-form foot IK branch of :func:`foot_ik_solutions`, in :data:`FOOT_IK_BRANCHES` order."""

    #: (..., 16, 3) motor angles (theta1, theta2, theta0), NaN where the branch does not exist.
    motors: np.ndarray
    #: (..., 16, 3) (theta_LL, roll, pitch) of each branch.
    pose: np.ndarray
    #: (..., 16) the branch exists (LL arc and motors reach, target off the roll axis).
    mask: np.ndarray
    #: (..., 16) assembly mode of the branch's pose on its motor branch (+1 / -1, 0 where it does not exist).
    assembly: np.ndarray
    #: (..., 16) the branch's pose is inside the joint limits.
    within_limits: np.ndarray
    #: (..., 16) what :func:`foot_ik` returns with these mode arguments: inside the limits, off the
    #: forward-singularity band, reproduced by :func:`foot_position` in that mode.
    valid: np.ndarray


def foot_ik_solutions(p, *, starting_value: float = 0.0) -> FootIKSolutions:
    """Every foot IK solution with its mode: the 16 closed-form branches ((ll_branch, roll_branch, b1, b2) in
    :data:`FOOT_IK_BRANCHES` order) with their assembly mode, joint-limit and validity flags. Never raises for
    valid input."""
    p = as_input(p, "p", (3,))
    sv = _check_offset(starting_value)
    shape = p.shape[:-1]
    u = (p - CENTER).reshape(-1, 3)
    parts = {k: [] for k in ("motors", "pose", "exists", "mode", "inlim", "valid")}
    for l_, r_, b1, b2 in FOOT_IK_BRANCHES:
        bv = np.array([b1, b2], float)
        c = _ik_candidate(u, sv, float(l_), float(r_), bv)
        valid = np.zeros(len(u), dtype=bool)
        for s in (1.0, -1.0):
            valid |= _accepted(c, bv, s)
        c["valid"] = valid
        for k in parts:
            parts[k].append(c[k])
    st = {k: np.stack(v, 1) for k, v in parts.items()}
    return FootIKSolutions(
        st["motors"].reshape(shape + (16, 3)), np.where(st["exists"][..., None], st["pose"], np.nan).reshape(
            shape + (16, 3)), st["exists"].reshape(shape + (16,)), st["mode"].astype(int).reshape(shape + (16,)),
        (st["inlim"] & st["exists"]).reshape(shape + (16,)), st["valid"].reshape(shape + (16,)),
    )


def foot_jacobian(
    theta1,
    theta2,
    theta0,
    *,
    starting_value: float = 0.0,
    branch: Sequence[int] = (1, 1),
    assembly: int = 1,
    return_mask: bool = False,
):
    """d(foot position)/d(theta1, theta2, theta0), shape (..., 3, 3), of the closed-loop leg.

    With x = (roll, pitch) from :func:`platform_orientation` (mode ``branch``, ``assembly``) and
    ``dtheta/dx = D^-1 N`` (:func:`motor_jacobian`), ``dx/dtheta = N^-1 D``; the foot ``p = c + R_P f(theta_LL)``
    gives ``dp/droll = e_x x R f``, ``dp/dpitch = (Rx(roll) e_y) x R f``, ``dp/dtheta_LL = R_P df/dtheta_LL`` and
    ``dtheta_LL/dtheta0 = -RATIO`` (eq 19). Finite on the reach boundary (D = 0: a column vanishes);
    undefined where N is singular (the platform moves with the motors locked).

    Raises:
        ConvergenceError: single input whose closed sub-chain did not assemble in that mode.
        SingularityError: single input where N is singular.
    """
    if (return_mask is False and type(theta1) in _SCALARS and type(theta2) in _SCALARS
            and type(theta0) in _SCALARS):
        fb, fs, fv = _fast_branch(branch), _fast_sign(assembly), _fast_offset(starting_value)
        if fb is not None and fs is not None and fv is not None:
            jac = np.empty((3, 3))
            if _foot_jacobian_k(theta1, theta2, theta0, fv, fb[0], fb[1], fs, jac) == OK:
                return jac
    t1, t2, t0 = as_angles(theta1, theta2, theta0, names=("theta1", "theta2", "theta0"))
    sv = _check_offset(starting_value)
    b = _check_branch(branch)
    s = _check_assembly(assembly)
    _check_flag(return_mask, "return_mask")
    n = t1.size
    jac, st = np.empty((n, 3, 3)), np.empty(n, dtype=np.int64)
    _loop(_foot_jacobian_b, _foot_jacobian_s, n)(_flat(t1), _flat(t2), _flat(t0), sv, float(b[0]), float(b[1]), s,
                                                 jac, st)
    assembled = st != _ST_ASSEMBLE
    jac = jac.reshape(t1.shape + (3, 3))
    ok = (st == OK).reshape(t1.shape)

    def error():
        if not bool(assembled[0]):
            return ConvergenceError(_fk_failure(float(t1), float(t2), b, s))
        return SingularityError(
            f"(theta1, theta2) = ({float(t1):.6g}, {float(t2):.6g}) is a forward singularity: the platform can move "
            "with both motors locked (N singular), the foot Jacobian is undefined"
        )

    return finish(jac, ok, t1.ndim == 0, return_mask, error)


def spherical_free_axis(rotation, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """Unit axis (..., 3) in CCS of the rotation left free by the seed's spherical centre, motors locked.

    With a spherical joint at LCS the platform's angular velocity w changes rod i's squared span at the rate
    ``2 d_i . (w x R a_i) = 2 w . ((R a_i) x d_i)``; both rods are held when ``w`` is orthogonal to
    ``g_i = (R a_i) x d_i``, so the free axis is ``g_1 x g_2`` (normalised; sign: positive z component).
    At R_P = I on the neutral branch it is ~(-0.39, 0, 0.92) through the LCS centre.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    rot, theta, k, ok, tip = _levers_at(rotation, branch, return_mask)
    ra = np.einsum("...jk,ik->...ij", rot, ATTACH)
    d = CENTER + ra - tip
    g = np.cross(ra, d)
    axis = np.cross(g[..., 0, :], g[..., 1, :])
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    axis = np.where(axis[..., 2:3] < 0, -axis, axis)
    axis = np.where(ok[..., None], axis, np.nan)
    return finish(axis, ok, rot.ndim == 2, return_mask, lambda: _unreachable("the platform rotation", k))
