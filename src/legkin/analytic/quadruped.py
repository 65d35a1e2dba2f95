"""Closed-form kinematics of the quadruped's legs (seeds 004 and 002).

Conventions (base frame: x forward, y left, z up; metres, radians):

* legs ``"LF"``, ``"LH"``, ``"RF"``, ``"RH"``; ``sx = +1`` front / ``-1`` hind, ``sy = +1`` left / ``-1`` right;
* joint vector ``q = (q1, q2, q3)`` = (``<LEG>_HAA``, ``<LEG>_HFE``, ``<LEG>_KFE``), the seed's
  (aile, epaule, coude) angles; the foot frame ``<LEG>_FOOT`` is the seed's "pied";
* seed 004's transforms with its sign typo resolved: ``T01 = Tr(h) Rx(sy q1)``, ``T12 = Tr(0, sy y12, 0) Ry(-q2)``,
  ``T23 = Tr(x23, 0, z23) Ry(q3)``, ``T34 = Tr(x34, 0, foot_z)``.

Every function takes arrays with leading batch dimensions. A single input (``q`` or ``p`` of shape (3,))
returns plain arrays and raises on failure; a batch returns NaN rows where an item fails, and
``return_mask=True`` also returns the boolean mask of successes. Where two arrays come in (``foot_ik``'s ``p``
and ``q_ref``) their leading shapes broadcast, and the call is a single one only if the broadcast shape is ``()``
(a single target with a batch of ``q_ref`` is a batch).

Inputs are checked at every public function: arrays by :func:`legkin.analytic._batch.as_input` (wrong shape,
NaN/inf, complex, strings, ragged: ``InvalidInputError``), keyword parameters for kind and range
(``InvalidParameterError`` naming the value and the valid range; ``foot_z``'s range is the registry's,
:data:`legkin.models.quadruped.SPEC`). No numpy exception escapes: a failed item is NaN in a batch (mask False)
and a legkin error in a single call.
"""

from __future__ import annotations

import math
import numbers
from typing import NamedTuple

import numpy as np

from ..errors import InvalidInputError, InvalidParameterError, JointLimitError, UnreachableError
from ..models.quadruped import SPEC as _SPEC
from ._batch import as_input, finish

__all__ = [
    "LEGS",
    "X01",
    "Y01",
    "Z01",
    "Y12",
    "X23",
    "Z23",
    "X34",
    "JOINT_LIMITS",
    "hip_position",
    "foot_position",
    "foot_jacobian",
    "foot_ik",
    "foot_ik_all",
    "within_limits",
    "textbook_ik",
    "textbook_frame",
    "textbook_to_joints",
]

LEGS = ("LF", "LH", "RF", "RH")

# Seed 004 offsets (m): base_aile, aile_epaule, epaule_coude, coude_pied.
X01, Y01, Z01 = 0.3305, 0.175, -0.051
Y12 = 0.1077
X23, Z23 = -0.35192, -0.041509
X34 = 0.29604

#: Joint limits (POPI's), rows q1, q2, q3: (lower, upper) in rad.
JOINT_LIMITS = np.array([[-0.4, 0.4], [0.0, math.pi], [0.26, 1.92]])

#: Distance (m) by which a target may lie outside the reachable set and still be solved (on the boundary).
REACH_TOL = 1e-12

#: Branch order of :func:`foot_ik_all`: (s_u, k) with s_u = -1 foot below the hip plane, k the knee sign.
BRANCHES = ((-1, -1), (-1, 1), (1, -1), (1, 1))

#: Default slack (rad) of :func:`within_limits`, and of the representative choice of q2 near +-pi.
LIMIT_TOL = 1e-9
#: A branch of :func:`foot_ik` up to this far (rad) outside :data:`JOINT_LIMITS` is a candidate: targets made
#: at a limit come back a rounding error outside it, and near the abduction singularity (rho -> 0) the joints
#: err by up to ~rho / y12 <= 1.4e-8 rad along the singular direction (the foot itself stays exact). Such a
#: branch is clipped into the limits and the other joints re-solved (Gauss-Newton on the foot position); it is
#: kept only if the result is inside the limits and reproduces the target within :data:`CLIP_TOL`.
LIMIT_SLACK = 1e-7
#: Largest foot error (m) of a branch clipped into the limits.
CLIP_TOL = 1e-12


def _number(value, name: str, valid) -> float:
    """A real scalar parameter (int, float, numpy real, 0-d real array; not bool, str, complex) as float.
    ``valid``: the range text for the message (or a callable making it)."""
    if type(value) is float:  # the common case, fast
        return value
    ok = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    if not ok and isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        ok, value = True, value.item()
    if not ok:
        text = valid() if callable(valid) else valid
        raise InvalidParameterError(f"{name} must be a real number, got {value!r}; valid range {text}")
    return float(value)


def _checked_foot_z(foot_z) -> float:
    """``foot_z`` checked against the registry's range (:data:`legkin.models.quadruped.SPEC`)."""
    param = _SPEC.params["foot_z"]
    return param.check("foot_z", _number(foot_z, "foot_z", param.range_text))


def _flag(value, name: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidParameterError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _signs(leg: str) -> tuple[float, float]:
    try:
        return {"LF": (1.0, 1.0), "LH": (-1.0, 1.0), "RF": (1.0, -1.0), "RH": (-1.0, -1.0)}[leg]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"leg must be one of {', '.join(LEGS)}, got {leg!r}") from None


def hip_position(leg: str) -> np.ndarray:
    """Point of the abduction axis ``base_aile`` of ``leg`` in the base frame (seed 004)."""
    sx, sy = _signs(leg)
    return np.array([sx * X01, sy * Y01, Z01])


def _wrap(a: np.ndarray) -> np.ndarray:
    """Wrap angles to (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def _knee_vector(q3: np.ndarray, foot_z: float) -> tuple[np.ndarray, np.ndarray]:
    """``v = t23 + Ry(q3) t34`` in the thigh's x-z plane (foot from the shoulder, before q2)."""
    c3, s3 = np.cos(q3), np.sin(q3)
    return X23 + X34 * c3 + foot_z * s3, Z23 - X34 * s3 + foot_z * c3


def _forward(q: np.ndarray, leg: str, foot_z: float):
    sx, sy = _signs(leg)
    a = sy * q[..., 0]
    c1, s1 = np.cos(a), np.sin(a)
    c2, s2 = np.cos(q[..., 1]), np.sin(q[..., 1])
    vx, vz = _knee_vector(q[..., 2], foot_z)
    ux = vx * c2 - vz * s2  # Ry(-q2) v
    uz = vx * s2 + vz * c2
    uy = sy * Y12
    return sx, sy, c1, s1, c2, s2, ux, uy, uz


def _foot(q: np.ndarray, leg: str, foot_z: float) -> np.ndarray:
    """Unchecked :func:`foot_position`."""
    _, _, c1, s1, _, _, ux, uy, uz = _forward(q, leg, foot_z)
    h = hip_position(leg)
    return np.stack([h[0] + ux, h[1] + c1 * uy - s1 * uz, h[2] + s1 * uy + c1 * uz], axis=-1)


def foot_position(q, leg: str, *, foot_z: float = 0.0) -> np.ndarray:
    """Foot position in the base frame: the product of seed 004's transforms T01 T12 T23 T34.

    .. math:: p = h + R_x(s_y q_1)\\,\\big[(0, s_y y_{12}, 0) + R_y(-q_2)(t_{23} + R_y(q_3) t_{34})\\big]

    Seed 004 prints T01 with the ``+-`` signs stacked identically in rows 2 and 3 (not a rotation);
    the consistent reading, used here, is Rx(+q1) for left legs and Rx(-q1) for right legs.

    Args:
        q: joint angles (..., 3).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        foot_z: the foot drop below the shank axis (xacro argument ``foot_z``).

    Returns:
        Positions (..., 3) in metres.
    """
    foot_z = _checked_foot_z(foot_z)
    _signs(leg)
    q = as_input(q, "q", (3,))
    return _foot(q, leg, foot_z)


def foot_jacobian(q, leg: str, *, foot_z: float = 0.0) -> np.ndarray:
    """Closed-form Jacobian d(foot position)/dq, shape (..., 3, 3) (columns q1, q2, q3).

    Differentiates :func:`foot_position` (seed 004's product) factor by factor:
    ``dp/dq1 = s_y R_x' u``, ``dp/dq2 = R_x (-u_z, 0, u_x)``, ``dp/dq3 = R_x R_y(-q_2) dv/dq_3``.
    """
    foot_z = _checked_foot_z(foot_z)
    _signs(leg)
    return _jacobian(as_input(q, "q", (3,)), leg, foot_z)


def _jacobian(q: np.ndarray, leg: str, foot_z: float) -> np.ndarray:
    """Unchecked :func:`foot_jacobian`."""
    _, sy, c1, s1, c2, s2, ux, uy, uz = _forward(q, leg, foot_z)
    c3, s3 = np.cos(q[..., 2]), np.sin(q[..., 2])
    dvx = -X34 * s3 + foot_z * c3
    dvz = -X34 * c3 - foot_z * s3
    dux3, duz3 = dvx * c2 - dvz * s2, dvx * s2 + dvz * c2
    zero = np.zeros_like(ux)
    col1 = np.stack([zero, sy * (-s1 * uy - c1 * uz), sy * (c1 * uy - s1 * uz)], axis=-1)
    col2 = np.stack([-uz, -s1 * ux, c1 * ux], axis=-1)
    col3 = np.stack([dux3, -s1 * duz3, c1 * duz3], axis=-1)
    return np.stack([col1, col2, col3], axis=-1)


def within_limits(q, tol: float = LIMIT_TOL) -> np.ndarray:
    """Whether joint vectors (..., 3) lie inside :data:`JOINT_LIMITS` (with slack ``tol`` rad).

    NaN and infinite entries (e.g. the unreachable rows of :func:`foot_ik_all`) count as outside.

    Raises:
        InvalidInputError: ``q`` not a real array of shape (..., 3).
        InvalidParameterError: ``tol`` not a finite number >= 0.
    """
    tol = _number(tol, "tol", "[0, inf)")
    if not (math.isfinite(tol) and tol >= 0):
        raise InvalidParameterError(f"tol={tol!r} is out of range: must be in [0, inf) (rad)")
    q = as_input(q, "q", (3,), allow_nan=True)
    lo, hi = JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1]
    with np.errstate(invalid="ignore"):
        return np.all((q >= lo - tol) & (q <= hi + tol), axis=-1)


class _Solution(NamedTuple):
    q: np.ndarray  # (..., n_branches, 3) in the order of ``branches``
    branches: tuple[tuple[int, int], ...]
    reachable: np.ndarray
    rho2: np.ndarray
    r2: np.ndarray
    l1: float
    l2: float


def _inside(x: np.ndarray, row: int, tol: float = LIMIT_TOL) -> np.ndarray:
    lo, hi = JOINT_LIMITS[row]
    return (x >= lo - tol) & (x <= hi + tol)


def _toward_limits(x: np.ndarray, row: int, tol: float = LIMIT_TOL) -> np.ndarray:
    """The representative of angle ``x`` (mod 2 pi) inside the limits of joint ``row`` when one is.

    Needed where a limit is +-pi (q2's upper limit): rounding can return -pi + eps for pi - eps.
    """
    lo, hi = JOINT_LIMITS[row]
    x = np.where((x < lo - tol) & (x + 2 * np.pi <= hi + tol), x + 2 * np.pi, x)
    return np.where((x > hi + tol) & (x - 2 * np.pi >= lo - tol), x - 2 * np.pi, x)


def _solve(p: np.ndarray, leg: str, foot_z: float, limited: bool = False) -> _Solution:
    """The closed form, branch by branch.

    Angle differences are taken in one ``atan2`` (``atan2(a) - atan2(b) = atan2(a x b, a . b)``), which is
    also wrapped to (-pi, pi] already. With ``limited=True`` a knee branch is computed only if its q3 is
    inside the limits for some target (q3 depends on the knee sign alone): inside POPI's limits the k = +1
    branch never is, which halves the work of :func:`foot_ik`.
    """
    with np.errstate(over="ignore", invalid="ignore"):  # huge finite targets: inf, never reachable
        return _solve_unchecked(p, leg, foot_z, limited)


def _solve_unchecked(p: np.ndarray, leg: str, foot_z: float, limited: bool) -> _Solution:
    _, sy = _signs(leg)
    h = hip_position(leg)
    dx, dy, dz = p[..., 0] - h[0], p[..., 1] - h[1], p[..., 2] - h[2]
    axis2 = dy * dy + dz * dz
    rho2 = axis2 - Y12**2
    rho = np.sqrt(np.maximum(rho2, 0.0))
    r2 = dx * dx + rho2
    l1 = math.hypot(X23, Z23)
    l2 = math.hypot(X34, foot_z)
    kk = np.minimum(np.maximum((r2 - l1 * l1 - l2 * l2) * (0.5 / (l1 * l2)), -1.0), 1.0)
    sk = np.sqrt(1.0 - kk * kk)
    # Targets on the workspace boundary, built in floating point, may land a rounding error outside it:
    # accept them within REACH_TOL metres (the clipped K / zero rho then give the boundary solution).
    reachable = (
        (axis2 >= (Y12 - REACH_TOL) ** 2)
        & (r2 <= (l1 + l2 + REACH_TOL) ** 2)
        & (r2 >= (abs(l1 - l2) - REACH_TOL) ** 2)
    )
    offset = math.atan2(foot_z, X34) - math.atan2(Z23, X23)  # q3 = offset + k acos K
    co, so = math.cos(offset), math.sin(offset)
    acos_k = np.arccos(kk)
    knees = {}
    for k in (-1, 1):
        q3 = offset + k * acos_k  # within 3 pi of 0: one shift wraps it (cheaper than a modulo)
        q3 = np.where(q3 > np.pi, q3 - 2 * np.pi, np.where(q3 <= -np.pi, q3 + 2 * np.pi, q3))
        if limited and not np.any(_inside(q3, 2) & reachable):
            continue
        c3, s3 = co * kk - k * so * sk, so * kk + k * co * sk  # cos, sin of q3 without trig calls
        knees[k] = (q3, X23 + X34 * c3 + foot_z * s3, Z23 - X34 * s3 + foot_z * c3)
    branches = tuple((s_u, k) for s_u, k in BRANCHES if k in knees)
    out = np.empty(p.shape[:-1] + (len(branches), 3))
    for b, (s_u, k) in enumerate(branches):
        uz = s_u * rho
        q3, vx, vz = knees[k]
        out[..., b, 0] = sy * np.arctan2(sy * Y12 * dz - dy * uz, sy * Y12 * dy + dz * uz)
        out[..., b, 1] = np.arctan2(uz * vx - dx * vz, dx * vx + uz * vz)
        out[..., b, 2] = q3
    return _Solution(out, branches, reachable, rho2, r2, l1, l2)


def _unreachable_message(leg, p, rho2, r2, l1, l2) -> str:
    # distances recomputed from p with hypot (no overflow for huge finite targets)
    d = np.asarray(p, dtype=float) - hip_position(leg)
    axis = math.hypot(float(d[1]), float(d[2]))
    if axis < Y12 - REACH_TOL:
        return (
            f"target {p.tolist()} for leg {leg} is inside the abduction cylinder: its distance to the "
            f"abduction axis is {axis:.6g} m < {Y12} m (by {Y12 - axis:.3g} m)"
        )
    rho = math.sqrt(max(axis - Y12, 0.0)) * math.sqrt(axis + Y12)
    r = math.hypot(float(d[0]), rho)
    if r > l1 + l2:
        return (
            f"target {p.tolist()} for leg {leg} is beyond full stretch: the hip-to-foot distance in the "
            f"leg plane is {r:.6g} m > L1 + L2 = {l1 + l2:.6g} m (by {r - l1 - l2:.3g} m)"
        )
    return (
        f"target {p.tolist()} for leg {leg} is too close to the hip: the hip-to-foot distance in the leg "
        f"plane is {r:.6g} m < |L1 - L2| = {abs(l1 - l2):.6g} m (by {abs(l1 - l2) - r:.3g} m)"
    )


def foot_ik_all(p, leg: str, *, foot_z: float = 0.0, return_mask: bool = False):
    """Every closed-form IK branch of a foot target: shape (..., 4, 3), branches in :data:`BRANCHES` order.

    The closed form for this geometry (knee offset included), checked against Pinocchio:

    1. ``d = p - h``; ``rho^2 = d_y^2 + d_z^2 - y12^2`` (< 0: inside the abduction cylinder);
    2. ``u_z = s_u rho``, ``u_x = d_x``; ``q1 = s_y [atan2(d_z, d_y) - atan2(u_z, s_y y12)]``;
    3. ``K = (|d|^2 - y12^2 - L1^2 - L2^2) / (2 L1 L2)`` (|K| > 1: out of reach);
       ``q3 = (beta - alpha) + k acos K`` with ``alpha = atan2(z23, x23)``, ``beta = atan2(z34, x34)``;
    4. ``q2 = atan2(u_z, u_x) - atan2(v_z, v_x)`` with ``v = t23 + Ry(q3) t34``; every angle wrapped to (-pi, pi].

    Joint limits are not applied (see :func:`within_limits`); rows are NaN where the target is unreachable.

    Raises:
        UnreachableError: single target out of reach (message says why and by how much).
        InvalidInputError: ``p`` not a finite real array (..., 3). InvalidParameterError: bad ``leg``/``foot_z``.
    """
    foot_z = _checked_foot_z(foot_z)
    return_mask = _flag(return_mask, "return_mask")
    _signs(leg)
    p = as_input(p, "p", (3,))
    sol = _solve(p, leg, foot_z)
    ok = sol.reachable
    q = np.where(ok[..., None, None], sol.q, np.nan)

    def error():
        return UnreachableError(_unreachable_message(leg, p, float(sol.rho2), float(sol.r2), sol.l1, sol.l2), target=p)

    q = finish(q, ok, p.ndim == 1, False, error)
    return (q, np.repeat(ok[..., None], 4, axis=-1)) if return_mask else q


def _clip_repair(qc: np.ndarray, q: np.ndarray, p: np.ndarray, leg: str, foot_z: float):
    """Branches ``q`` (k, 3) clipped into the limits (``qc``): re-solve the unclipped joints for the foot ``p``.

    Up to three Gauss-Newton steps on the foot position over the joints that clipping left alone (the clipped ones
    stay on their limit), keeping the best iterate (the clipped branch itself when clipping moved it by a rounding
    error only). Near the abduction singularity the branch's error lies along the singular direction of the
    Jacobian, which the free joints absorb. Returns the joints (inside the limits) and whether they reproduce
    ``p`` within :data:`CLIP_TOL`.
    """
    lo, hi = JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1]
    free = qc == q
    best, best_err = qc, np.full(len(qc), np.inf)
    for it in range(4):
        r = p - _foot(qc, leg, foot_z)
        err = np.linalg.norm(r, axis=-1)
        better = err < best_err  # keep the best iterate: near rho -> 0 a step can only add rounding
        best, best_err = np.where(better[:, None], qc, best), np.where(better, err, best_err)
        if it == 3 or np.all(best_err <= 0.5 * CLIP_TOL):
            break
        step = (np.linalg.pinv(_jacobian(qc, leg, foot_z) * free[:, None, :], rcond=1e-10) @ r[..., None])[..., 0]
        moved = qc + step
        qc = np.minimum(np.maximum(moved, lo), hi)
        free &= qc == moved  # a joint pushed onto its limit by the step stays there
    return best, best_err <= CLIP_TOL


def foot_ik(p, leg: str, q_ref=None, *, foot_z: float = 0.0, return_mask: bool = False) -> np.ndarray:
    """Joint angles (..., 3) placing the foot at ``p``: the branch inside the joint limits.

    Branch choice (the knee and abduction branches are IK-only choices: the forward map has none). Among the
    four branches of :func:`foot_ik_all`, keeps those inside :data:`JOINT_LIMITS` (a branch a hair outside,
    by at most :data:`LIMIT_SLACK`, is clipped into the limits and kept if it still reaches the target within
    :data:`CLIP_TOL`, see :func:`_clip_repair`: the answer is always inside the URDF limits); picks
    the one nearest ``q_ref`` (Euclidean norm of the wrapped joint differences; ties go to the earlier
    branch) when given, else the first in :data:`BRANCHES` order: (s_u, k) = (-1, -1), (-1, 1), (1, -1), (1, 1)
    (foot below the hip plane first). Inside POPI's limits only the k = -1 knee branch occurs, but both s_u
    branches do (s_u = +1 for large q2), so the choice is made here, not assumed.

    Args:
        p: foot targets (..., 3) in the base frame.
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        q_ref: configurations (..., 3) to stay near. The leading shapes of ``p`` and ``q_ref`` broadcast
            together: a single target with a batch of ``q_ref`` is a batch (one answer per ``q_ref``).
        foot_z: the foot drop (m), in the registry's range [-0.1, 0.1].
        return_mask: also return the boolean mask of targets solved inside the limits.

    Raises:
        UnreachableError: single target out of reach.
        JointLimitError: single target reachable only outside the joint limits.
        InvalidInputError: ``p`` or ``q_ref`` not finite real arrays (..., 3), or not broadcastable.
        InvalidParameterError: bad ``leg``, ``foot_z`` or ``return_mask``.
    """
    foot_z = _checked_foot_z(foot_z)
    return_mask = _flag(return_mask, "return_mask")
    _signs(leg)
    p = as_input(p, "p", (3,))
    batch = p.shape[:-1]
    if q_ref is not None:
        q_ref = as_input(q_ref, "q_ref", (3,))
        try:
            batch = np.broadcast_shapes(batch, q_ref.shape[:-1])
        except ValueError:
            raise InvalidInputError(
                f"p (shape {p.shape}) and q_ref (shape {q_ref.shape}) do not broadcast together"
            ) from None
    sol = _solve(p, leg, foot_z, limited=True)
    ok = sol.reachable
    lo, hi = JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1]
    # Walk the candidate branches keeping, per target, the first inside the limits (or the nearest q_ref).
    q = np.full(batch + (3,), np.nan)
    best = np.full(batch, np.inf)
    with np.errstate(invalid="ignore", over="ignore"):
        for b in range(len(sol.branches)):
            qb = sol.q[..., b, :].copy()
            qb[..., 1] = _toward_limits(qb[..., 1], 1)  # q1 and q3 limits are far from +-pi
            inside, strict = ok, True
            for k in range(3):  # column by column: cheaper than comparisons and reductions over (..., 3)
                x = qb[..., k]
                inside = inside & (x >= lo[k] - LIMIT_SLACK) & (x <= hi[k] + LIMIT_SLACK)
                strict = strict & (x >= lo[k]) & (x <= hi[k])
            moved = inside & ~strict
            clipped = qb
            if moved.any():  # a branch just outside the limits: clip it and re-solve the other joints
                inside = np.array(inside)
                clipped = np.minimum(np.maximum(qb, lo), hi)
                fixed, good = _clip_repair(clipped[moved], qb[moved], np.broadcast_to(p, qb.shape)[moved], leg, foot_z)
                clipped[moved] = fixed
                inside[moved] = good
            if q_ref is None:
                take = inside & np.isinf(best)
                best = np.where(take, 0.0, best)
            else:
                cost = np.linalg.norm(_wrap(clipped - q_ref), axis=-1)
                take = inside & (cost < best)
                best = np.where(take, cost, best)
            q = np.where(take[..., None], clipped, q)
    solved = np.isfinite(best)

    def error():
        if not bool(ok):
            return UnreachableError(_unreachable_message(leg, p, float(sol.rho2), float(sol.r2), sol.l1, sol.l2), target=p)
        q_all = _solve(p, leg, foot_z).q
        return JointLimitError(
            f"target {p.tolist()} for leg {leg} is reachable only outside the joint limits "
            f"{JOINT_LIMITS.tolist()}: branches {np.round(q_all, 4).tolist()}",
            target=p,
        )

    return finish(q, solved, len(batch) == 0, return_mask, error)


# ----------------------------------------------------------------------------- seed 002
def textbook_frame(p, leg: str) -> np.ndarray:
    """Express base-frame foot targets in seed 002's frame for ``leg``.

    Seed 002 works from the abduction axis with x lateral (towards the hip offset, so mirrored on right
    legs: x_f -> -x_f), y forward and z down: ``(x_f, y_f, z_f) = (s_y d_y, d_x, -d_z)`` with ``d = p - h``.
    """
    _, sy = _signs(leg)
    d = as_input(p, "p", (3,)) - hip_position(leg)
    return np.stack([sy * d[..., 1], d[..., 0], -d[..., 2]], axis=-1)


def textbook_ik(p, a: float, b: float, c: float, *, literal: bool = False) -> np.ndarray:
    """Seed 002's law-of-cosines IK: (theta_abad, theta_hip, theta_knee), shape (..., 3).

    .. math::
        \\theta_{abad} = \\operatorname{atan2}(x_f, z_f) + \\arccos\\frac{a}{\\sqrt{x_f^2 + z_f^2}}, \\quad
        \\theta_{hip} = \\frac{\\pi}{2} - \\arcsin\\frac{-y_f}{\\sqrt{L - a^2}}
            - \\arccos\\frac{b^2 - a^2 - c^2 + L}{2 b \\sqrt{L - a^2}}, \\quad
        \\theta_{knee} = \\arccos\\frac{a^2 + b^2 + c^2 - L}{2 b c}

    with ``L = x_f^2 + y_f^2 + z_f^2`` and ``p = (x_f, y_f, z_f)`` in seed 002's frame (:func:`textbook_frame`).
    Two fixes to the seed as printed: "90" is pi/2 (radians), and ``atan(x_f / z_f)`` is ``atan2(x_f, z_f)``
    (the literal atan is wrong for every z_f < 0 and divides by zero at z_f = 0). ``literal=True`` keeps the
    printed atan, to show that failure. Only one branch (knee k = -1, foot below the hip) is returned.
    ``theta_adab`` and ``theta_abd`` in the seed are typos for theta_abad. NaN where acos/asin are out of range
    (a transcription of the seed: it does not follow the single-call-raises rule of the other functions).

    Raises:
        InvalidInputError: ``p`` not a finite real array (..., 3).
        InvalidParameterError: ``a`` not a finite number >= 0, ``b`` or ``c`` not finite and > 0, ``literal`` not a bool.
    """
    a = _number(a, "a", "[0, inf)")
    b = _number(b, "b", "(0, inf)")
    c = _number(c, "c", "(0, inf)")
    for name, value, positive in (("a", a, False), ("b", b, True), ("c", c, True)):
        if not math.isfinite(value) or value < 0 or (positive and value == 0):
            raise InvalidParameterError(
                f"{name}={value!r} is out of range: must be in {'(0, inf)' if positive else '[0, inf)'} (m)"
            )
    literal = _flag(literal, "literal")
    p = as_input(p, "p", (3,))
    xf, yf, zf = p[..., 0], p[..., 1], p[..., 2]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        big_l = xf * xf + yf * yf + zf * zf
        m = np.sqrt(big_l - a * a)
        first = np.arctan(xf / zf) if literal else np.arctan2(xf, zf)
        abad = first + np.arccos(a / np.sqrt(xf * xf + zf * zf))
        hip = np.pi / 2 - np.arcsin(-yf / m) - np.arccos((b * b - a * a - c * c + big_l) / (2 * b * m))
        knee = np.arccos((a * a + b * b + c * c - big_l) / (2 * b * c))
    return np.stack([abad, hip, knee], axis=-1)


#: Angle of the thigh offset: atan(|z23| / |x23|) = 0.1174 rad, the seed-002 servo zero offset.
KNEE_OFFSET = math.atan2(-Z23, -X23)


def textbook_to_joints(theta, leg: str) -> np.ndarray:
    """Map seed 002's (theta_abad, theta_hip, theta_knee) onto the quadruped's (q1, q2, q3) of ``leg``.

    With a = y12, b = L1, c = L2 (foot_z = 0): ``q1 = theta_abad - pi/2``, ``q2 = theta_hip - 0.1174``,
    ``q3 = theta_knee - 0.1174`` (0.1174 = atan(0.041509 / 0.35192), the thigh's offset angle); this is
    foot_ik's branch (s_u, k) = (-1, -1). The same formulas hold on both sides because seed 002's frame is
    mirrored on right legs (see :func:`textbook_frame`).
    """
    _signs(leg)
    theta = as_input(theta, "theta", (3,), allow_nan=True)  # NaN (textbook_ik out of range) maps to NaN
    q = theta - np.array([np.pi / 2, KNEE_OFFSET, KNEE_OFFSET])
    with np.errstate(invalid="ignore"):
        return _wrap(q)
