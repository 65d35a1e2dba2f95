"""Seed 004's forward kinematics of a leg and its Jacobian: the kernels and their wrappers :func:`fk`,
:func:`jacobian` and :func:`hip_position`.

Seed 004's transforms, with its sign typo resolved (see :func:`fk`):
``T01 = Tr(h) Rx(sy q1)``, ``T12 = Tr(0, sy y12, 0) Ry(-q2)``, ``T23 = Tr(x23, 0, z23) Ry(q3)``,
``T34 = Tr(x34, 0, foot_z)``, with ``h = (sx x01, sy y01, z01)`` the leg's hip.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .._kernels import OK, as_rows, batch_kernel, kernel, prange
from ._common import F64, LEG_INDEX, S3, S33, foot_z_of, leg_index, raise_bad, rows
from .constants import BAD_INPUT, SX, SY, X01, X23, X34, Y01, Y12, Z01, Z23
from .geometry import Geometry

__all__ = ["fk", "jacobian", "hip_position"]


# ----------------------------------------------------------------------------- kernels
@kernel
def _finite3(x) -> bool:
    return np.isfinite(x[0]) and np.isfinite(x[1]) and np.isfinite(x[2])


@kernel
def _knee_k(q3, foot_z):
    """``v = t23 + Ry(q3) t34`` in the thigh's x-z plane (foot from the shoulder, before q2)."""
    c3, s3 = np.cos(q3), np.sin(q3)
    return X23 + X34 * c3 + foot_z * s3, Z23 - X34 * s3 + foot_z * c3


@kernel
def _forward_k(q1, q2, q3, li, foot_z):
    """``R_x(s_y q_1)`` (c1, s1), ``R_y(-q_2)`` (c2, s2) and ``u = (0, s_y y12, 0) + R_y(-q_2) v``."""
    sy = SY[li]
    a = sy * q1
    c1, s1 = np.cos(a), np.sin(a)
    c2, s2 = np.cos(q2), np.sin(q2)
    vx, vz = _knee_k(q3, foot_z)
    ux = vx * c2 - vz * s2  # Ry(-q2) v
    uz = vx * s2 + vz * c2
    uy = sy * Y12
    return c1, s1, c2, s2, ux, uy, uz


@kernel
def _foot_k(q1, q2, q3, li, foot_z):
    """Foot position ``h + R_x(s_y q_1) u`` (seed 004's product T01 T12 T23 T34)."""
    c1, s1, _, _, ux, uy, uz = _forward_k(q1, q2, q3, li, foot_z)
    return SX[li] * X01 + ux, SY[li] * Y01 + c1 * uy - s1 * uz, Z01 + s1 * uy + c1 * uz


@kernel
def _jacobian_k(q1, q2, q3, li, foot_z, jac):
    """d(foot)/dq into ``jac`` (3, 3), factor by factor of seed 004's product (see :func:`jacobian`)."""
    sy = SY[li]
    c1, s1, c2, s2, ux, uy, uz = _forward_k(q1, q2, q3, li, foot_z)
    c3, s3 = np.cos(q3), np.sin(q3)
    dvx = -X34 * s3 + foot_z * c3
    dvz = -X34 * c3 - foot_z * s3
    dux3, duz3 = dvx * c2 - dvz * s2, dvx * s2 + dvz * c2
    jac[0, 0] = 0.0
    jac[1, 0] = sy * (-s1 * uy - c1 * uz)
    jac[2, 0] = sy * (c1 * uy - s1 * uz)
    jac[0, 1] = -uz
    jac[1, 1] = -s1 * ux
    jac[2, 1] = c1 * ux
    jac[0, 2] = dux3
    jac[1, 2] = -s1 * duz3
    jac[2, 2] = c1 * duz3


@kernel(entry=True)
def _fk_k(q, li, foot_z, out) -> int:
    """:func:`fk` of one joint vector ``q`` (3,) into ``out`` (3,)."""
    if not _finite3(q):
        return BAD_INPUT
    out[0], out[1], out[2] = _foot_k(q[0], q[1], q[2], li, foot_z)
    return OK


@kernel(entry=True)
def _jac_k(q, li, foot_z, out) -> int:
    """:func:`jacobian` of one joint vector ``q`` (3,) into ``out`` (3, 3)."""
    if not _finite3(q):
        return BAD_INPUT
    _jacobian_k(q[0], q[1], q[2], li, foot_z, out)
    return OK


@batch_kernel(rows="q out", min_parallel=256, parfor=True)
def _fk_batch(q, li, foot_z, out) -> int:
    n, bad = q.shape[0], 0
    for i in prange(n):
        bad += _fk_k(q[i], li, foot_z, out[i]) != OK
    return bad


@batch_kernel(rows="q out", min_parallel=256, parfor=True)
def _jac_batch(q, li, foot_z, out) -> int:
    n, bad = q.shape[0], 0
    for i in prange(n):
        bad += _jac_k(q[i], li, foot_z, out[i]) != OK
    return bad


@kernel(entry=True)
def _hip_position_k(li, out) -> int:
    out[0], out[1], out[2] = SX[li] * X01, SY[li] * Y01, Z01
    return OK


@batch_kernel(rows="q3 out", min_parallel=256, parfor=True)
def _knee_batch(q3, foot_z, out) -> None:
    for i in prange(q3.shape[0]):
        out[i, 0], out[i, 1] = _knee_k(q3[i], foot_z)


def _knee_vector(q3: npt.ArrayLike, foot_z: float) -> tuple[np.ndarray, np.ndarray] | tuple[float, float]:
    """``(v_x, v_z)`` of :func:`_knee_k` for angles ``q3`` (any shape, or a scalar)."""
    a = np.asarray(q3, dtype=np.float64)
    out = np.empty(a.shape + (2,))
    _knee_batch(np.ascontiguousarray(a).reshape(-1), float(foot_z), out.reshape(-1, 2))
    return (out[..., 0], out[..., 1]) if a.ndim else (float(out[0]), float(out[1]))


# ----------------------------------------------------------------------------- wrappers
def hip_position(leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Point (3,) of the abduction axis ``base_aile`` of ``leg`` in the base frame (seed 004), in metres.

    ``geometry`` is accepted like everywhere (checked; the hip does not depend on ``foot_z``).
    """
    if geometry is not None:
        foot_z_of(geometry)
    out = np.empty(3)
    _hip_position_k(leg_index(leg), out)
    return out


def fk(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Foot position in the base frame: the product of seed 004's transforms T01 T12 T23 T34.

    .. math:: p = h + R_x(s_y q_1)\\,\\big[(0, s_y y_{12}, 0) + R_y(-q_2)(t_{23} + R_y(q_3) t_{34})\\big]

    Seed 004 prints T01 with the ``+-`` signs stacked identically in rows 2 and 3 (not a rotation);
    the consistent reading, used here, is Rx(+q1) for left legs and Rx(-q1) for right legs.

    Args:
        q: joint angles (..., 3) (rad): (``<LEG>_HAA``, ``<LEG>_HFE``, ``<LEG>_KFE``).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        geometry: the leg's :class:`~legkin.quadruped.Geometry` (None: the default, ``foot_z = 0``).

    Returns:
        Positions (..., 3) in metres. Every finite ``q`` has one (no failure: no mask).

    Raises:
        InvalidInputError: ``q`` not a finite real array (..., 3).
        InvalidParameterError: bad ``leg`` or ``geometry``.
    """
    fz = 0.0 if geometry is None else foot_z_of(geometry)
    try:
        li = LEG_INDEX[leg]
    except (KeyError, TypeError):
        li = leg_index(leg)
    if type(q) is np.ndarray and q.shape == S3 and q.dtype is F64:  # the single call, fast
        out = np.empty(S3)
        if _fk_k(q, li, fz, out):
            raise_bad(q, "q")
        return out
    arr = rows(q, "q")
    if arr.ndim == 1:
        out = np.empty(S3)
        if _fk_k(arr, li, fz, out):
            raise_bad(q, "q")
        return out
    out = np.empty(arr.shape)
    if _fk_batch(as_rows(arr, 3), li, fz, out.reshape(-1, 3)):
        raise_bad(q, "q")
    return out


def jacobian(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Closed-form Jacobian d(foot position)/dq of :func:`fk`, shape (..., 3, 3) (columns q1, q2, q3), m/rad.

    Differentiates seed 004's product factor by factor:
    ``dp/dq1 = s_y R_x' u``, ``dp/dq2 = R_x (-u_z, 0, u_x)``, ``dp/dq3 = R_x R_y(-q_2) dv/dq_3``.

    Raises:
        InvalidInputError: ``q`` not a finite real array (..., 3).
        InvalidParameterError: bad ``leg`` or ``geometry``.
    """
    fz = 0.0 if geometry is None else foot_z_of(geometry)
    try:
        li = LEG_INDEX[leg]
    except (KeyError, TypeError):
        li = leg_index(leg)
    if type(q) is np.ndarray and q.shape == S3 and q.dtype is F64:  # the single call, fast
        out = np.empty(S33)
        if _jac_k(q, li, fz, out):
            raise_bad(q, "q")
        return out
    arr = rows(q, "q")
    if arr.ndim == 1:
        out = np.empty(S33)
        if _jac_k(arr, li, fz, out):
            raise_bad(q, "q")
        return out
    out = np.empty(arr.shape + (3,))
    if _jac_batch(as_rows(arr, 3), li, fz, out.reshape(-1, 3, 3)):
        raise_bad(q, "q")
    return out
