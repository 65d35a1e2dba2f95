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
  OCR artefact) with ``theta0`` the leg-extension motor angle.

Every function takes arrays with leading batch dimensions. A single input (the core shape exactly)
returns plain arrays and raises on failure; a batch returns NaN where an item fails, and
``return_mask=True`` also returns the boolean mask of successes.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..errors import ConvergenceError, InvalidInputError, SingularityError, UnreachableError
from ._batch import as_angles, as_input, finish

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


def _wrap(a):
    """Wrap angles to (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def _check_branch(branch) -> np.ndarray:
    try:
        b = np.asarray(branch, dtype=float)
    except (TypeError, ValueError):
        b = None
    if b is None or b.shape != (2,) or not np.all(np.abs(b) == 1.0):
        raise InvalidInputError(f"branch must be a pair of +1/-1 (one per motor chain), got {branch!r}")
    return b


def _check_sign(value, name: str) -> float:
    if value not in (1, -1):
        raise InvalidInputError(f"{name} must be +1 or -1, got {value!r}")
    return float(value)


def _check_offset(starting_value) -> float:
    try:
        x = float(starting_value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"starting_value must be a finite number (rad), got {starting_value!r}") from None
    if not math.isfinite(x):
        raise InvalidInputError(f"starting_value must be a finite number (rad), got {starting_value!r}")
    return x


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
    return (_check_offset(starting_value) - t) / RATIO


# ----------------------------------------------------------------------------- platform and chains
def platform_rotation(roll, pitch) -> np.ndarray:
    """``R_P = Rx(roll) Ry(pitch)``, shape (..., 3, 3): the universal centre (x fixed in CCS, then y).

    Seed eq 2 writes R_P as a unit quaternion (a spherical joint); the universal joint is the physical
    2-DOF platform (see the docs: the spherical centre leaves one rotation uncontrolled).
    """
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
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


def _chains(rot: np.ndarray, b: np.ndarray):
    """Closed form of both rod-length equations for rotations (..., 3, 3).

    Returns theta (..., 2) (NaN where unreachable), the reach ratio k (..., 2), and ok (..., 2).
    """
    w = MOTOR_POS - _attach_world(rot)  # w_i = p_i - A_i  so  S_i - A_i = w_i + Rz(phi_i) l
    lx, lz = LEVER[0], LEVER[2]
    a = lx * w[..., 0]
    bb = lx * w[..., 1]
    c = 0.5 * (ROD_LENGTH**2 - np.sum(w * w, axis=-1) - lx * lx - lz * lz - 2.0 * lz * w[..., 2])
    rho = np.hypot(a, bb)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = c / rho
    ok = np.isfinite(k) & (np.abs(k) <= 1.0)
    phi = np.arctan2(bb, a) - _SIGMA * b * np.arccos(np.clip(k, -1.0, 1.0))
    theta = np.where(ok, _wrap(phi - MOTOR_YAW), np.nan)
    return theta, k, ok


def _unreachable(what: str, k: np.ndarray) -> UnreachableError:
    bad = [f"chain {i + 1} (|k| = {abs(float(k[i])):.6g})" for i in range(2) if not abs(float(k[i])) <= 1.0]
    return UnreachableError(
        f"{what} is out of the motors' reach: the rod-length equation A cos(theta) + B sin(theta) = C has no "
        f"solution for {', '.join(bad)}; it needs |k| = |C| / sqrt(A^2 + B^2) <= 1",
        target=None,
    )


def _levers_at(rotation, branch):
    """Checked rotation, motor angles, chain flags, success mask and lever tips for a platform rotation."""
    rot = _check_rotation(rotation)
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
    rot = _check_rotation(rotation)
    b = _check_branch(branch)
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
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = _check_branch(branch)
    theta, k, ok2 = _chains(platform_rotation(r, p), b)
    ok = np.all(ok2, axis=-1)
    theta = np.where(ok[..., None], theta, np.nan)
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


def motor_jacobian(roll, pitch, branch: Sequence[int] = (1, 1), *, return_mask: bool = False):
    """d(theta1, theta2)/d(roll, pitch), shape (..., 2, 2), by implicit differentiation of the rod lengths.

    With ``d_i = A_i - S_i``: ``dtheta_i/dx_k = (d_i . dA_i/dx_k) / (d_i . dS_i/dtheta_i)`` where
    ``dA/droll = e_x x R a``, ``dA/dpitch = (Rx(roll) e_y) x R a``, ``dS/dtheta = e_z x Rz(phi) l``.
    Infinite (NaN here) on the reach boundary, where ``d_i . dS_i/dtheta_i = 0``.

    Raises:
        UnreachableError: single (roll, pitch) out of reach.
        SingularityError: single pose on the reach boundary (a motor cannot move its rod end).
    """
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = _check_branch(branch)
    rot = platform_rotation(r, p)
    theta, k, ok2 = _chains(rot, b)
    reach = np.all(ok2, axis=-1)
    n, dd = _jacobian_parts(rot, r, np.where(reach[..., None], theta, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        jac = n / dd[..., None]
    ok = reach & np.all(np.isfinite(jac), axis=(-1, -2)) & np.all(dd != 0.0, axis=-1)
    jac = np.where(ok[..., None, None], jac, np.nan)

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
    rot, theta, k, ok, tip = _levers_at(rotation, branch)
    d = _attach_world(rot) - tip
    rz = _rotz(theta + MOTOR_YAW)
    u = np.einsum("...ji,...j->...i", rz, d) / ROD_LENGTH
    alpha = np.arctan2(u[..., 1], u[..., 0])
    beta = -np.arcsin(np.clip(u[..., 2], -1.0, 1.0))
    out = np.stack([alpha, beta, np.zeros_like(alpha)], -1)
    out = np.where(ok[..., None, None], out, np.nan)
    return finish(out, ok, rot.ndim == 2, return_mask, lambda: _unreachable("the platform rotation", k))


# ----------------------------------------------------------------------------- forward kinematics
def _newton(target: np.ndarray, b: np.ndarray, x: np.ndarray, max_iter: int, tol: float, sign0: float = 0.0):
    """Damped Newton on motor_angles(x) = target, x = (roll, pitch), rows (n, 2). Returns x, ok.

    With ``sign0`` (+-1) a step is accepted only if det(dtheta/dx) keeps that sign: the iterates stay in
    one assembly mode, the forward-singularity curve acting as a barrier.

    An item is done when its last accepted step was below 1e-10 rad (the error before it was then
    ~1e-10 and quadratic convergence leaves rounding error) and its residual is <= ``tol``.
    """
    n = len(x)
    done = np.zeros(n, dtype=bool)
    failed = np.zeros(n, dtype=bool)
    err = np.full(n, np.inf)
    for _ in range(max_iter):
        act = np.flatnonzero(~(done | failed))
        if not len(act):
            break
        xa, tg = x[act], target[act]
        rot = platform_rotation(xa[:, 0], xa[:, 1])
        th, _, ok2 = _chains(rot, b)
        res = _wrap(th - tg)
        cur = np.linalg.norm(res, axis=-1)
        nmat, dd = _jacobian_parts(rot, xa[:, 0], np.where(ok2, th, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            jac = nmat / dd[..., None]
        fin = np.all(ok2, -1) & np.all(np.isfinite(jac), axis=(-1, -2))
        det = np.linalg.det(np.where(fin[:, None, None], jac, np.eye(2)))
        good = fin & (np.abs(det) > 1e-14)
        step = np.zeros_like(xa)
        if good.any():
            step[good] = -np.linalg.solve(jac[good], res[good][..., None])[..., 0]
        lam = np.ones(len(xa))
        accept = np.zeros(len(xa), dtype=bool)
        new = cur.copy()
        for _ in range(25):  # backtracking: the step must stay reachable and not increase the residual
            trial = good & ~accept
            if not trial.any():
                break
            xt = xa[trial] + lam[trial, None] * step[trial]
            tht, _, okt = _chains(platform_rotation(xt[:, 0], xt[:, 1]), b)
            nt = np.linalg.norm(_wrap(tht - tg[trial]), axis=-1)
            acc = np.all(okt, -1) & ((nt < cur[trial]) | (nt <= 1e-15))
            if sign0:
                acc &= np.sign(_jac_det(xt, b)) == sign0
            idx = np.flatnonzero(trial)
            accept[idx[acc]] = True
            new[idx[acc]] = nt[acc]
            lam[idx[~acc]] *= 0.5
        xa = np.where(accept[:, None], xa + lam[:, None] * step, xa)
        x[act] = xa
        err[act] = np.where(accept, new, cur)
        size = np.abs(step).max(axis=-1) * lam
        # done: the step is at rounding level, or the residual (<= tol) stopped shrinking (rounding floor;
        # near the forward singularity the last steps are eps / sigma_min, not smaller)
        done[act[accept & (new <= tol) & ((size <= 1e-14) | (new >= 0.5 * cur))]] = True
        # no acceptable step: converged at rounding level if the residual is tiny, else stuck
        stuck = good & ~accept
        done[act[stuck & (cur <= tol)]] = True
        failed[act[(stuck & (cur > tol)) | ~good]] = True
    return x, done & (err <= tol)


#: Restarts of platform_orientation, inside the neutral mode, nearest the forward singularity first.
_FALLBACK_GUESSES = np.array([[0.0, 0.8], [-0.45, 0.8], [0.45, 0.8], [-0.85, 0.65], [0.85, 0.65], [0.0, 0.4], [0.0, -0.4]])


def _jac_det(x: np.ndarray, b: np.ndarray) -> np.ndarray:
    """det(dtheta/dx) at rows x (n, 2) (NaN where unreachable)."""
    rot = platform_rotation(x[:, 0], x[:, 1])
    th, _, ok2 = _chains(rot, b)
    nmat, dd = _jacobian_parts(rot, x[:, 0], np.where(ok2, th, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.all(ok2, -1), np.linalg.det(nmat) / (dd[:, 0] * dd[:, 1]), np.nan)


def platform_orientation(
    theta1,
    theta2,
    branch: Sequence[int] = (1, 1),
    *,
    guess=None,
    steps: int = 4,
    tol: float = 1e-12,
    max_iter: int = 50,
    return_mask: bool = False,
):
    """(roll, pitch) (..., 2) of the universal-centre platform for motor angles (theta1, theta2).

    Forward kinematics of the closed sub-chain (seed eqs 1-16 with both motors given): Newton's method on
    :func:`motor_angles` ``(x) = theta`` with its analytic Jacobian :func:`motor_jacobian`, damped by
    backtracking (a step that leaves the reachable set or increases the residual is halved). Without a
    ``guess`` it follows the assembly mode of the neutral pose: a continuation from R_P = I (the
    closed-form motor angles of ``branch`` at roll = pitch = 0) to ``theta`` in ``steps`` stages; where
    that path leaves the image of the motor map (near the forward singularity), Newton restarts from a
    coarse grid of guesses. Every accepted step keeps the sign of det dtheta/dx it had at R_P = I, so
    the solution is always of the neutral assembly mode. Near the forward singularity (det N = 0, where the platform could move
    with the motors locked) the solution is ill-conditioned: error ~ 1e-16 / sigma_min(dtheta/dx).

    Args:
        theta1, theta2: motor angles (rad), broadcast together.
        branch: the motor branch pair the solution must lie on.
        guess: starting (roll, pitch) (..., 2) instead of the continuation.
        steps: continuation stages.
        tol: required residual |motor_angles(x) - theta| (rad).
        max_iter: Newton iterations per stage.

    Raises:
        ConvergenceError: single input for which Newton did not converge (the motor angles may not
            assemble on this branch, or the path crossed a singularity: try a ``guess``).
    """
    t1, t2 = as_angles(theta1, theta2, names=("theta1", "theta2"))
    b = _check_branch(branch)
    shape = t1.shape
    target = np.stack([t1, t2], -1).reshape(-1, 2)
    n = len(target)
    if guess is not None:
        g = np.broadcast_to(as_input(guess, "guess", (2,)), shape + (2,)).reshape(-1, 2)
        x, ok = _newton(target, b, g.astype(float).copy(), max_iter, tol)
    else:
        th0 = _chains(np.eye(3)[None], b)[0][0]
        if not np.all(np.isfinite(th0)):
            raise ConvergenceError(f"branch {tuple(b.astype(int))} has no neutral pose to start from: give a guess")
        delta = _wrap(target - th0)
        sign0 = float(np.sign(_jac_det(np.zeros((1, 2)), b)[0]))
        x = np.zeros((n, 2))
        nsteps = max(int(steps), 1)
        for s in range(1, nsteps + 1):
            # intermediate stages only provide starting points; the last one decides
            stage = _wrap(th0 + delta * (s / nsteps))
            xs, ok = _newton(stage, b, x.copy(), max_iter, tol if s == nsteps else 1e-6, sign0)
            x = np.where(ok[:, None], xs, x)
        # fallback where the straight path in motor space leaves the image (near the forward
        # singularity): Newton from a coarse grid of guesses, kept in the neutral assembly mode
        for guess_x in _FALLBACK_GUESSES:
            todo = np.flatnonzero(~ok)
            if not len(todo):
                break
            g = np.tile(guess_x, (len(todo), 1))
            if not np.sign(_jac_det(g[:1], b)[0]) == sign0:
                continue
            xs, oks = _newton(target[todo], b, g, min(max_iter, 30), tol, sign0)
            x[todo[oks]] = xs[oks]
            ok[todo[oks]] = True
    x = np.where(ok[:, None], _wrap(x), np.nan).reshape(shape + (2,))
    ok = ok.reshape(shape)

    def error():
        return ConvergenceError(
            f"platform_orientation did not converge for (theta1, theta2) = ({float(t1):.6g}, {float(t2):.6g}) "
            f"on branch {tuple(b.astype(int))}: the motor angles may not assemble, or the path from the neutral "
            "pose crosses a singularity (pass a guess)"
        )

    return finish(x, ok, t1.ndim == 0, return_mask, error)


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
    r, p, t = as_angles(roll, pitch, theta_ll, names=("roll", "pitch", "theta_ll"))
    f, _ = _foot_in_p(t)
    return CENTER + np.einsum("...ij,...j->...i", platform_rotation(r, p), f)


def foot_position(
    theta1, theta2, theta0, *, starting_value: float = 0.0, branch: Sequence[int] = (1, 1), return_mask: bool = False
):
    """Foot FCS in CCS (..., 3) for the three motors: (theta1, theta2) -> (roll, pitch) -> foot.

    :func:`platform_orientation` (Newton on the closed sub-chain, eqs 1-16), :func:`ll_angle` (eq 19) and
    :func:`foot_position_from_platform` (eqs 17, 18, 20).

    Raises:
        ConvergenceError: single input whose closed sub-chain did not assemble.
    """
    t1, t2, t0 = as_angles(theta1, theta2, theta0, names=("theta1", "theta2", "theta0"))
    x, ok = platform_orientation(t1.ravel(), t2.ravel(), branch, return_mask=True)
    tll = ll_angle(t0.ravel(), starting_value)
    p = foot_position_from_platform(np.where(ok, x[:, 0], 0.0), np.where(ok, x[:, 1], 0.0), tll)
    p = np.where(ok[:, None], p, np.nan).reshape(t1.shape + (3,))
    ok = ok.reshape(t1.shape)

    def error():
        return ConvergenceError(
            f"the closed sub-chain does not assemble for (theta1, theta2) = ({float(t1):.6g}, {float(t2):.6g}) "
            f"on branch {tuple(branch)}"
        )

    return finish(p, ok, t1.ndim == 0, return_mask, error)


def _platform_ik(u: np.ndarray, ll_branch: float, roll_branch: float):
    """(theta_LL, roll, pitch) (..., 3) for u = p - CENTER, plus reach ratio, rho and ok."""
    r2 = np.sum(u * u, -1)
    kk = (_LL0**2 + _H**2 - r2) / (2.0 * _H * _LL0)
    reach = np.abs(kk) <= 1.0
    tll = LL_DELTA + ll_branch * np.arccos(np.clip(kk, -1.0, 1.0))
    f, _ = _foot_in_p(tll)
    rho = np.hypot(u[..., 1], u[..., 2])
    s = np.where(u[..., 2] >= 0.0, 1.0, -1.0) * roll_branch
    vz = s * rho
    roll = np.arctan2(-u[..., 1] * s, u[..., 2] * s)
    pitch = np.arctan2(f[..., 2], f[..., 0]) - np.arctan2(vz, u[..., 0])
    out = _wrap(np.stack([tll, roll, pitch], -1))
    nonsing = rho > 1e-12 * np.sqrt(r2)
    return out, kk, rho, reach, nonsing


def foot_platform_ik(p, *, ll_branch: int = -1, roll_branch: int = 1, return_mask: bool = False):
    """(theta_LL, roll, pitch) (..., 3) placing the foot at ``p`` (CCS), in closed form.

    Inverts :func:`foot_position_from_platform`:

    1. the distance from the LCS centre depends on theta_LL alone:
       ``|p - c|^2 = |o|^2 + h^2 - 2 h |o| cos(theta_LL - delta)`` with ``o = (1.640, -0.037)``,
       ``h = 1.5``, ``delta = atan2(0.037, 1.640)``; ``theta_LL = delta + ll_branch acos(...)``
       (``ll_branch = -1``: theta_LL <= delta, the extension side, default). Unreachable unless
       ``|o| - h <= |p - c| <= |o| + h`` (0.14042 to 3.14042 m).
    2. ``u = p - c = Rx(roll) v``, ``v = Ry(pitch) f`` with ``f`` the foot in P: ``v_y = 0`` gives
       ``v_z = +-sqrt(u_y^2 + u_z^2)``, ``roll = atan2(-u_y / v_z, u_z / v_z)`` (``roll_branch = +1``:
       |roll| <= pi/2, default), and ``pitch = atan2(f_z, f_x) - atan2(v_z, u_x)``.

    Singular where the foot lies on the roll axis (``u_y = u_z = 0``: roll is undetermined).

    Raises:
        UnreachableError: single target out of reach.
        SingularityError: single target on the roll axis.
    """
    p = as_input(p, "p", (3,))
    llb = _check_sign(ll_branch, "ll_branch")
    rb = _check_sign(roll_branch, "roll_branch")
    out, kk, rho, reach, nonsing = _platform_ik(p - CENTER, llb, rb)
    ok = reach & nonsing
    out = np.where(ok[..., None], out, np.nan)

    def error():
        return _foot_error(p, kk, reach)

    return finish(out, ok, p.ndim == 1, return_mask, error)


def _foot_error(p: np.ndarray, kk, reach) -> Exception:
    r = float(np.linalg.norm(p - CENTER))
    if not bool(reach):
        return UnreachableError(
            f"foot target {p.tolist()} is {r:.6g} m from the LCS centre; the LL arc reaches "
            f"[{_LL0 - _H:.6g}, {_LL0 + _H:.6g}] m",
            target=p,
        )
    return SingularityError(f"foot target {p.tolist()} lies on the platform's roll axis (x through the LCS centre): roll is undetermined")


def foot_ik(
    p,
    *,
    starting_value: float = 0.0,
    ll_branch: int = -1,
    roll_branch: int = 1,
    branch: Sequence[int] = (1, 1),
    all_branches: bool = False,
    return_mask: bool = False,
):
    """Motor angles (theta1, theta2, theta0) (..., 3) placing the foot at ``p`` (CCS), all in closed form.

    :func:`foot_platform_ik` (target -> theta_LL -> roll, pitch), :func:`motor_angles` (eqs 3-16 per chain)
    and :func:`extension_motor_angle` (eq 19 inverted).

    Args:
        p: foot targets (..., 3) in CCS.
        starting_value: LL zero offset (rad) of eq 19.
        ll_branch, roll_branch, branch: which solution (see :func:`foot_platform_ik`, :func:`motor_angles`).
        all_branches: return every branch instead, shape (..., 16, 3) in :data:`FOOT_IK_BRANCHES` order,
            NaN rows where a branch does not exist; the mask (with ``return_mask``) is then (..., 16).
            A single target raises only when no branch exists.

    Raises:
        UnreachableError: single target out of reach (of the LL arc or of the motors).
        SingularityError: single target on the roll axis.
    """
    p = as_input(p, "p", (3,))
    sv = _check_offset(starting_value)
    u = p - CENTER
    if all_branches:
        outs, oks = [], []
        for llb, rb, b1, b2 in FOOT_IK_BRANCHES:
            o, ok = _foot_ik_one(u, sv, llb, rb, np.array([b1, b2], float))
            outs.append(o)
            oks.append(ok)
        out = np.stack(outs, -2)
        ok = np.stack(oks, -1)
        any_ok = np.any(ok, -1)
        if p.ndim == 1 and not bool(any_ok):
            _, kk, _, reach, nonsing = _platform_ik(u, -1.0, 1.0)
            if bool(reach) and bool(nonsing):
                raise UnreachableError(f"foot target {p.tolist()} is out of the motors' reach on every branch", target=p)
            raise _foot_error(p, kk, reach)
        return (out, ok) if return_mask else out
    llb = _check_sign(ll_branch, "ll_branch")
    rb = _check_sign(roll_branch, "roll_branch")
    b = _check_branch(branch)
    out, ok = _foot_ik_one(u, sv, llb, rb, b)

    def error():
        _, kk, _, reach, nonsing = _platform_ik(u, llb, rb)
        if bool(reach) and bool(nonsing):
            x = _platform_ik(u, llb, rb)[0]
            _, k, _ = _chains(platform_rotation(x[1], x[2]), b)
            return UnreachableError(
                f"foot target {p.tolist()} needs (roll, pitch) = ({float(x[1]):.6g}, {float(x[2]):.6g}): "
                + str(_unreachable("that platform pose", k)).split(": ", 1)[1].replace("is out", "out", 1),
                target=p,
            )
        return _foot_error(p, kk, reach)

    return finish(out, ok, p.ndim == 1, return_mask, error)


def _foot_ik_one(u, sv, llb, rb, b):
    x, _, _, reach, nonsing = _platform_ik(u, llb, rb)
    th, _, ok2 = _chains(platform_rotation(x[..., 1], x[..., 2]), b)
    ok = reach & nonsing & np.all(ok2, -1)
    t0 = (sv - x[..., 0]) / RATIO
    out = np.concatenate([th, t0[..., None]], -1)
    return np.where(ok[..., None], out, np.nan), ok


def foot_jacobian(
    theta1, theta2, theta0, *, starting_value: float = 0.0, branch: Sequence[int] = (1, 1), return_mask: bool = False
):
    """d(foot position)/d(theta1, theta2, theta0), shape (..., 3, 3), of the closed-loop leg.

    With x = (roll, pitch) from :func:`platform_orientation` and ``dtheta/dx = D^-1 N``
    (:func:`motor_jacobian`), ``dx/dtheta = N^-1 D``; the foot ``p = c + R_P f(theta_LL)`` gives
    ``dp/droll = e_x x R f``, ``dp/dpitch = (Rx(roll) e_y) x R f``, ``dp/dtheta_LL = R_P df/dtheta_LL`` and
    ``dtheta_LL/dtheta0 = -RATIO`` (eq 19). Finite on the reach boundary (D = 0: a column vanishes);
    undefined where N is singular (the platform moves with the motors locked).

    Raises:
        ConvergenceError: single input whose closed sub-chain did not assemble.
        SingularityError: single input where N is singular.
    """
    t1, t2, t0 = as_angles(theta1, theta2, theta0, names=("theta1", "theta2", "theta0"))
    sv = _check_offset(starting_value)
    b = _check_branch(branch)
    x, assembled = platform_orientation(t1.ravel(), t2.ravel(), b, return_mask=True)
    r = np.where(assembled, x[:, 0], 0.0)
    pch = np.where(assembled, x[:, 1], 0.0)
    rot = platform_rotation(r, pch)
    theta = np.stack([t1.ravel(), t2.ravel()], -1)
    nmat, dd = _jacobian_parts(rot, r, theta)
    det = np.linalg.det(nmat)
    scale = np.abs(nmat).max(axis=(-1, -2)) ** 2
    nonsing = np.abs(det) > 1e-12 * np.maximum(scale, 1e-300)
    ninv = np.linalg.inv(np.where(nonsing[:, None, None], nmat, np.eye(2)))
    dx_dth = ninv * dd[:, None, :]
    tll = ll_angle(t0.ravel(), sv)
    f, df = _foot_in_p(tll)
    rf = np.einsum("...ij,...j->...i", rot, f)
    ey_r = np.stack([np.zeros_like(r), np.cos(r), np.sin(r)], -1)
    dp_dx = np.stack([np.cross(np.array([1.0, 0.0, 0.0]), rf), np.cross(ey_r, rf)], -1)  # (n, 3, 2)
    cols12 = dp_dx @ dx_dth
    col0 = -RATIO * np.einsum("...ij,...j->...i", rot, df)
    jac = np.concatenate([cols12, col0[..., None]], -1)
    ok = assembled & nonsing
    jac = np.where(ok[:, None, None], jac, np.nan).reshape(t1.shape + (3, 3))
    ok = ok.reshape(t1.shape)
    assembled = assembled.reshape(t1.shape)

    def error():
        if not bool(assembled):
            return ConvergenceError(
                f"the closed sub-chain does not assemble for (theta1, theta2) = ({float(t1):.6g}, {float(t2):.6g})"
            )
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
    rot, theta, k, ok, tip = _levers_at(rotation, branch)
    ra = np.einsum("...jk,ik->...ij", rot, ATTACH)
    d = CENTER + ra - tip
    g = np.cross(ra, d)
    axis = np.cross(g[..., 0, :], g[..., 1, :])
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    axis = np.where(axis[..., 2:3] < 0, -axis, axis)
    axis = np.where(ok[..., None], axis, np.nan)
    return finish(axis, ok, rot.ndim == 2, return_mask, lambda: _unreachable("the platform rotation", k))
