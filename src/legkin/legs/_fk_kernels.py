"""Forward map and foot Jacobian kernels of an HAA-HFE-KFE leg (the product of exponentials with the measured
axes, see :mod:`legkin.legs.kinematics`), scalar and batch."""

from __future__ import annotations

import math

from .._kernels import OK, batch_kernel, kernel, prange
from ._layout import _A1, _A2, _A3, _BAD_INPUT, _O, _V3F, _V21, _V32


@kernel(inline=True)
def _finite_k(x, y, z) -> bool:
    """Whether three floats are finite."""
    return math.isfinite(x) and math.isfinite(y) and math.isfinite(z)


@kernel
def _finite3(x) -> bool:
    return _finite_k(x[0], x[1], x[2])


@kernel
def _rot_k(g, ia, c, s, vx, vy, vz):
    """Rodrigues: ``R(a, t) v = cos t v + sin t (a x v) + (1 - cos t) (a . v) a`` with ``a = g[ia:ia + 3]``; for an
    axis along a root axis (``a = +-e_x``, ``+-e_y``, ``+-e_z``: the unit axes of most URDFs, exactly) the plane
    rotation it reduces to (as Pinocchio's ``JointModelRX``... : 6 products, not 15)."""
    ax, ay, az = g[ia], g[ia + 1], g[ia + 2]
    if ay == 0.0 and az == 0.0:
        s *= ax
        return vx, c * vy - s * vz, c * vz + s * vy
    if ax == 0.0 and az == 0.0:
        s *= ay
        return c * vx + s * vz, vy, c * vz - s * vx
    if ax == 0.0 and ay == 0.0:
        s *= az
        return c * vx - s * vy, c * vy + s * vx, vz
    k = (1.0 - c) * (ax * vx + ay * vy + az * vz)
    return (
        c * vx + s * (ay * vz - az * vy) + k * ax,
        c * vy + s * (az * vx - ax * vz) + k * ay,
        c * vz + s * (ax * vy - ay * vx) + k * az,
    )


@kernel(inline=True)
def _cross_k(g, ia, vx, vy, vz):
    """``a x v`` with ``a = g[ia:ia + 3]``."""
    ax, ay, az = g[ia], g[ia + 1], g[ia + 2]
    return ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx


@kernel
def _fk3_k(q0, q1, q2, g):
    """The product of exponentials with the measured axes and origins (what Pinocchio computes)::

        t3 = R(a3, q3) (f - o3),  t2 = R(a2, q2) [(o3 - o2) + t3],  p = o1 + R(a1, q1) [(o2 - o1) + t2]
    """
    c, s = math.cos(q2), math.sin(q2)
    t3x, t3y, t3z = _rot_k(g, _A3, c, s, g[_V3F], g[_V3F + 1], g[_V3F + 2])
    c, s = math.cos(q1), math.sin(q1)
    t2x, t2y, t2z = _rot_k(g, _A2, c, s, g[_V32] + t3x, g[_V32 + 1] + t3y, g[_V32 + 2] + t3z)
    c, s = math.cos(q0), math.sin(q0)
    px, py, pz = _rot_k(g, _A1, c, s, g[_V21] + t2x, g[_V21 + 1] + t2y, g[_V21 + 2] + t2z)
    return g[_O] + px, g[_O + 1] + py, g[_O + 2] + pz


@kernel(entry=True)
def _fk_k(q, g, out) -> int:
    """Foot position: :func:`_fk3_k`,
    ``p = o1 + R(a1, q1) [(o2 - o1) + R(a2, q2) ((o3 - o2) + R(a3, q3) (f - o3))]``."""
    if not _finite3(q):
        return _BAD_INPUT
    out[0], out[1], out[2] = _fk3_k(q[0], q[1], q[2], g)
    return OK


@kernel
def _jac3_t(q0, q1, q2, g):
    """The Jacobian's nine entries, row-major: columns ``a1 x R1 v1``, ``R1 (a2 x t2)``, ``R1 R2 (a3 x t3)`` (each
    joint: its spatial axis crossed with the lever from its origin to the foot), with ``R_j = R(a_j, q_j)`` and
    ``t3, t2, v1`` of :func:`_fk3_k` (scalars: the Newton polish calls it without an array)."""
    c3, s3 = math.cos(q2), math.sin(q2)
    c2, s2 = math.cos(q1), math.sin(q1)
    c1, s1 = math.cos(q0), math.sin(q0)
    t3x, t3y, t3z = _rot_k(g, _A3, c3, s3, g[_V3F], g[_V3F + 1], g[_V3F + 2])
    t2x, t2y, t2z = _rot_k(g, _A2, c2, s2, g[_V32] + t3x, g[_V32 + 1] + t3y, g[_V32 + 2] + t3z)
    # column 1: a1 x R1 v1 = R1 (a1 x v1)
    x, y, z = _cross_k(g, _A1, g[_V21] + t2x, g[_V21 + 1] + t2y, g[_V21 + 2] + t2z)
    j00, j10, j20 = _rot_k(g, _A1, c1, s1, x, y, z)
    x, y, z = _cross_k(g, _A2, t2x, t2y, t2z)
    j01, j11, j21 = _rot_k(g, _A1, c1, s1, x, y, z)
    x, y, z = _cross_k(g, _A3, t3x, t3y, t3z)
    x, y, z = _rot_k(g, _A2, c2, s2, x, y, z)
    j02, j12, j22 = _rot_k(g, _A1, c1, s1, x, y, z)
    return j00, j01, j02, j10, j11, j12, j20, j21, j22


@kernel(entry=True)
def _jacobian_k(q, g, out) -> int:
    """Foot Jacobian ``dp/dq`` (3, 3): :func:`_jac3_t`."""
    if not _finite3(q):
        return _BAD_INPUT
    j = _jac3_t(q[0], q[1], q[2], g)
    out[0, 0], out[0, 1], out[0, 2] = j[0], j[1], j[2]
    out[1, 0], out[1, 1], out[1, 2] = j[3], j[4], j[5]
    out[2, 0], out[2, 1], out[2, 2] = j[6], j[7], j[8]
    return OK


@batch_kernel(rows="q out", min_parallel=256, parfor=True)
def _fk_batch(q, g, out) -> int:
    """:func:`_fk3_k` over rows (scalars in and out: no array view, no reference count a row); returns the number
    of rows with a non-finite entry (their rows of ``out`` are left as they are)."""
    n, bad = q.shape[0], 0
    for i in prange(n):
        q0, q1, q2 = q[i, 0], q[i, 1], q[i, 2]
        if _finite_k(q0, q1, q2):
            out[i, 0], out[i, 1], out[i, 2] = _fk3_k(q0, q1, q2, g)
        else:
            bad += 1
    return bad


@batch_kernel(rows="q out", min_parallel=256, parfor=True)
def _jacobian_batch(q, g, out) -> int:
    """:func:`_jac3_t` over rows, as :func:`_fk_batch`."""
    n, bad = q.shape[0], 0
    for i in prange(n):
        q0, q1, q2 = q[i, 0], q[i, 1], q[i, 2]
        if _finite_k(q0, q1, q2):
            j = _jac3_t(q0, q1, q2, g)
            out[i, 0, 0], out[i, 0, 1], out[i, 0, 2] = j[0], j[1], j[2]
            out[i, 1, 0], out[i, 1, 1], out[i, 1, 2] = j[3], j[4], j[5]
            out[i, 2, 0], out[i, 2, 1], out[i, 2, 2] = j[6], j[7], j[8]
        else:
            bad += 1
    return bad
