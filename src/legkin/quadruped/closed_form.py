"""The closed-form IK of a leg (seed 004's geometry, knee offset included): every branch, :func:`ik_all`.

1. ``d = p - h``; ``rho^2 = d_y^2 + d_z^2 - y12^2`` (< 0: inside the abduction cylinder);
2. ``u_z = s_u rho``, ``u_x = d_x``; ``q1 = s_y [atan2(d_z, d_y) - atan2(u_z, s_y y12)]``;
3. ``K = (|d|^2 - y12^2 - L1^2 - L2^2) / (2 L1 L2)`` (|K| > 1: out of reach);
   ``q3 = (beta - alpha) + k acos K`` with ``alpha = atan2(z23, x23)``, ``beta = atan2(z34, x34)``;
4. ``q2 = atan2(u_z, u_x) - atan2(v_z, v_x)`` with ``v = t23 + Ry(q3) t34``; every angle wrapped to (-pi, pi].

Each step is one kernel below (:func:`_reach_k`, :func:`_knee_angle_k`, :func:`_knee_branch_k`,
:func:`_branch_k`); :mod:`legkin.quadruped.inverse` chooses among the branches.
"""

from __future__ import annotations

import math
from typing import Literal, overload

import numpy as np
import numpy.typing as npt

from .._batch import check_flag
from .._kernels import OK, as_rows, batch_kernel, kernel, prange
from ..errors import UnreachableError
from ._common import F64, LEG_INDEX, S3, S43, foot_z_of, leg_index, raise_bad, rows
from .constants import (
    ALPHA,
    BAD_INPUT,
    KS,
    L1,
    PI,
    REACH_TOL,
    SU,
    SX,
    SY,
    TWO_PI,
    UNREACHABLE,
    X01,
    X23,
    X34,
    Y01,
    Y12,
    Y12_SQ,
    Z01,
    Z23,
)
from .forward import _finite3, hip_position
from .geometry import Geometry

__all__ = ["ik_all"]


def _leg_plane(foot_z: float) -> tuple[float, float, float, float]:
    offset = math.atan2(foot_z, X34) - ALPHA
    return math.hypot(X34, foot_z), offset, math.cos(offset), math.sin(offset)


_L2_0, _OFFSET_0, _CO_0, _SO_0 = _leg_plane(0.0)  # foot_z = 0 (the default), the same libm calls


@kernel
def _leg_plane_k(foot_z):
    """What the IK needs of ``foot_z`` (the same for every target of a call): ``L2 = |t34|``, the knee angle
    offset ``beta - alpha`` with ``alpha = atan2(z23, x23)``, ``beta = atan2(z34, x34)``, and its cosine and sine."""
    if foot_z == 0.0:
        return _L2_0, _OFFSET_0, _CO_0, _SO_0
    offset = math.atan2(foot_z, X34) - ALPHA  # q3 = offset + k acos K
    return math.hypot(X34, foot_z), offset, math.cos(offset), math.sin(offset)


@kernel
def _reach_k(p, li, l2):
    """Steps 1 and 3, the target's leg-plane quantities: (dx, dy, dz, rho, K, sqrt(1 - K^2), acos K, reachable).

    ``d = p - h``; ``rho^2 = d_y^2 + d_z^2 - y12^2``; ``K = (|d|^2 - y12^2 - L1^2 - L2^2) / (2 L1 L2)`` clipped
    to [-1, 1]. Targets on the workspace boundary, built in floating point, may land a rounding error outside
    it: they are accepted within REACH_TOL metres (the clipped K / zero rho then give the boundary solution).
    Huge finite targets overflow to inf and are simply unreachable.
    """
    dx, dy, dz = p[0] - SX[li] * X01, p[1] - SY[li] * Y01, p[2] - Z01
    axis2 = dy * dy + dz * dz
    rho2 = axis2 - Y12_SQ
    rho = np.sqrt(max(rho2, 0.0))
    r2 = dx * dx + rho2
    kk = min(max((r2 - L1 * L1 - l2 * l2) * (0.5 / (L1 * l2)), -1.0), 1.0)
    sk = np.sqrt(1.0 - kk * kk)
    reachable = (
        axis2 >= (Y12 - REACH_TOL) ** 2
        and r2 <= (L1 + l2 + REACH_TOL) ** 2
        and r2 >= (abs(L1 - l2) - REACH_TOL) ** 2
    )
    return dx, dy, dz, rho, kk, sk, np.arccos(kk), reachable


@kernel
def _knee_angle_k(acos_k, k, offset):
    """Step 3, knee branch ``k``: ``q3 = (beta - alpha) + k acos K`` wrapped to (-pi, pi]."""
    q3 = offset + k * acos_k  # within 3 pi of 0: one shift wraps it (cheaper than a modulo)
    if q3 > PI:
        return q3 - TWO_PI
    if q3 <= -PI:
        return q3 + TWO_PI
    return q3


@kernel
def _knee_branch_k(kk, sk, k, co, so, foot_z):
    """``v`` (vx, vz) of knee branch ``k``, from the cosine and sine of q3 built without trig calls."""
    c3, s3 = co * kk - k * so * sk, so * kk + k * co * sk
    return X23 + X34 * c3 + foot_z * s3, Z23 - X34 * s3 + foot_z * c3


@kernel
def _abduction_k(dy, dz, rho, s_u, li):
    """Step 2: q1 of abduction branch ``s_u``, ``s_y [atan2(d_z, d_y) - atan2(u_z, s_y y12)]`` in one atan2
    (``atan2(a) - atan2(b) = atan2(a x b, a . b)``, wrapped to (-pi, pi] already)."""
    sy = SY[li]
    uz = s_u * rho
    return sy * np.arctan2(sy * Y12 * dz - dy * uz, sy * Y12 * dy + dz * uz)


@kernel
def _hip_k(dx, rho, s_u, vx, vz):
    """Step 4: q2 = atan2(u_z, u_x) - atan2(v_z, v_x) of abduction branch ``s_u`` for a knee vector ``v``, in
    one atan2 like :func:`_abduction_k`."""
    uz = s_u * rho
    return np.arctan2(uz * vx - dx * vz, dx * vx + uz * vz)


@kernel(inline=True)
def _branch_k(dx, dy, dz, rho, s_u, vx, vz, li):
    """Steps 2 and 4: q1 and q2 of abduction branch ``s_u`` for a knee vector ``v``."""
    return _abduction_k(dy, dz, rho, s_u, li), _hip_k(dx, rho, s_u, vx, vz)


@kernel
def _ik_all_core(p, li, foot_z, l2, offset, co, so, out) -> int:
    """Every branch of :func:`ik_all` for one target ``p`` (3,) into ``out`` (4, 3) (NaN if unreachable)."""
    if not _finite3(p):
        return BAD_INPUT
    dx, dy, dz, rho, kk, sk, acos_k, reachable = _reach_k(p, li, l2)
    if not reachable:
        out[:, :] = np.nan
        return UNREACHABLE
    for b in range(4):
        k = KS[b]
        vx, vz = _knee_branch_k(kk, sk, k, co, so, foot_z)
        q1, q2 = _branch_k(dx, dy, dz, rho, SU[b], vx, vz, li)
        out[b, 0], out[b, 1], out[b, 2] = q1, q2, _knee_angle_k(acos_k, k, offset)
    return OK


@kernel(entry=True)
def _ik_all_k(p, li, foot_z, out) -> int:
    l2, offset, co, so = _leg_plane_k(foot_z)
    return _ik_all_core(p, li, foot_z, l2, offset, co, so, out)


@batch_kernel(rows="p out ok", min_parallel=256, parfor=True)
def _ik_all_batch(p, li, foot_z, out, ok) -> int:
    n, bad = p.shape[0], 0
    l2, offset, co, so = _leg_plane_k(foot_z)
    for i in prange(n):
        s = _ik_all_core(p[i], li, foot_z, l2, offset, co, so, out[i])
        ok[i] = s == OK
        bad += s == BAD_INPUT
    return bad


def unreachable_message(leg: str, p: np.ndarray, foot_z: float) -> str:
    """Why a single target is out of reach, and by how much (only on the error path)."""
    # distances recomputed from p with hypot (no overflow for huge finite targets)
    d = np.asarray(p, dtype=float) - hip_position(leg)
    l1, l2 = L1, math.hypot(X34, foot_z)
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


@overload
def ik_all(
    p: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None, return_mask: Literal[False] = False
) -> np.ndarray: ...
@overload
def ik_all(
    p: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None, return_mask: Literal[True]
) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def ik_all(
    p: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None, return_mask: bool = False
) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...


def ik_all(
    p: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None, return_mask: bool = False
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Every closed-form IK branch of a foot target: shape (..., 4, 3), branches in :data:`BRANCHES` order.

    The closed form of :mod:`legkin.quadruped.closed_form` (checked against Pinocchio). Joint limits are not
    applied (see :func:`~legkin.quadruped.within_limits`); rows are NaN where the target is unreachable.

    Args:
        p: foot targets (..., 3) in the base frame (m).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        geometry: the :class:`~legkin.quadruped.Geometry` (None: the default).
        return_mask: also return the mask (..., 4) of reachable targets (the same for the four branches).

    Raises:
        UnreachableError: single target out of reach (message says why and by how much).
        InvalidInputError: ``p`` not a finite real array (..., 3).
        InvalidParameterError: bad ``leg``, ``geometry`` or ``return_mask``.
    """
    fz = 0.0 if geometry is None else foot_z_of(geometry)
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    try:
        li = LEG_INDEX[leg]
    except (KeyError, TypeError):
        li = leg_index(leg)
    arr = p if type(p) is np.ndarray and p.shape == S3 and p.dtype is F64 else rows(p, "p")
    if arr.ndim == 1:
        out = np.empty(S43)
        status = _ik_all_k(arr, li, fz, out)
        if status:
            if status == BAD_INPUT:
                raise_bad(p, "p")
            raise UnreachableError(unreachable_message(leg, arr, fz), target=arr)
        return (out, np.ones(4, dtype=bool)) if return_mask else out
    out = np.empty(arr.shape[:-1] + (4, 3))
    ok = np.empty(arr.shape[:-1], dtype=np.bool_)
    if _ik_all_batch(as_rows(arr, 3), li, fz, out.reshape(-1, 4, 3), ok.reshape(-1)):
        raise_bad(p, "p")
    return (out, np.repeat(ok[..., None], 4, axis=-1)) if return_mask else out
