"""Kernels of a 6-DOF leg (:mod:`legkin.legs.sixdof`): forward map, Jacobian, Newton polish, every IK solution of
a leg with intersecting hip axes (subproblems 3, 2, 2, 1 of :mod:`.subproblems`), the solution inside the limits.

Poses travel as 16 floats (a 4x4 homogeneous matrix, row-major); the leg's geometry as the float64 array of
:mod:`._sixdof_layout`. The forward map is the product of exponentials about the neutral configuration with the
measured axes ``a_j`` through the measured origins ``o_j`` (root frame), which is what Pinocchio computes::

    T(q) = E_1(q_1) ... E_6(q_6) M_0,    E_j(t) = (R(a_j, t), o_j - R(a_j, t) o_j)
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_loop, kernel
from ._ik_kernels import _in_limits_k
from ._sixdof_layout import (
    _ANK,
    _AX,
    _BAD_INPUT,
    _HI6,
    _HIP,
    _LO6,
    _M0,
    _OR,
    POLISH_BELOW6,
    POLISH_DAMPING6,
    POLISH_STEPS6,
)
from .subproblems import cross, dot, rot_cs, sp1_cs, sp2_cs, sp3

_NAN = math.nan


@kernel
def _axis(g, j):
    return g[_AX + 3 * j], g[_AX + 3 * j + 1], g[_AX + 3 * j + 2]


@kernel
def _origin(g, j):
    return g[_OR + 3 * j], g[_OR + 3 * j + 1], g[_OR + 3 * j + 2]


@kernel
def _pose6(q, g, rot_out, pos_out, axes_w, orig_w) -> None:
    """Foot rotation ``rot_out`` (3, 3) and position ``pos_out`` (3,) of ``T(q) = E_1 ... E_6 M_0``; with the world
    axes ``axes_w`` (6, 3) and points ``orig_w`` (6, 3) of the joints at ``q`` (for the Jacobian)."""
    r, t = _pose6_cs(
        (math.cos(q[0]), math.cos(q[1]), math.cos(q[2]), math.cos(q[3]), math.cos(q[4]), math.cos(q[5])),
        (math.sin(q[0]), math.sin(q[1]), math.sin(q[2]), math.sin(q[3]), math.sin(q[4]), math.sin(q[5])),
        _geometry(g), axes_w, orig_w)
    for i in range(3):
        pos_out[i] = t[i]
        for c in range(3):
            rot_out[i, c] = r[3 * i + c]


@kernel
def _times_joint(r, t, a, o, c, s):
    """``(r, t) E_j = (r m, t + r o - (r m) o)`` with ``m = R(a, q_j)`` (``c``, ``s``: its cosine and sine), ``o`` a
    point of the axis ``a``; ``r`` a row-major 9-tuple, ``t`` a 3-tuple."""
    v = 1.0 - c
    m00, m01, m02 = c + v * a[0] * a[0], v * a[0] * a[1] - s * a[2], v * a[0] * a[2] + s * a[1]
    m10, m11, m12 = v * a[0] * a[1] + s * a[2], c + v * a[1] * a[1], v * a[1] * a[2] - s * a[0]
    m20, m21, m22 = v * a[0] * a[2] - s * a[1], v * a[1] * a[2] + s * a[0], c + v * a[2] * a[2]
    n = _mat_mat(r, (m00, m01, m02, m10, m11, m12, m20, m21, m22))
    d = (o[0] * (1.0 - c) - v * a[0] * (a[0] * o[0] + a[1] * o[1] + a[2] * o[2]) + s * (a[2] * o[1] - a[1] * o[2]),
         o[1] * (1.0 - c) - v * a[1] * (a[0] * o[0] + a[1] * o[1] + a[2] * o[2]) + s * (a[0] * o[2] - a[2] * o[0]),
         o[2] * (1.0 - c) - v * a[2] * (a[0] * o[0] + a[1] * o[1] + a[2] * o[2]) + s * (a[1] * o[0] - a[0] * o[1]))
    return n, (t[0] + r[0] * d[0] + r[1] * d[1] + r[2] * d[2], t[1] + r[3] * d[0] + r[4] * d[1] + r[5] * d[2],
               t[2] + r[6] * d[0] + r[7] * d[1] + r[8] * d[2])


@kernel
def _geometry(g):
    """The leg's axes and joint origins (6-tuples of 3-tuples) and ``M_0`` (12: rotation row-major, position) from
    its geometry array ``g``, as tuples."""
    axes = (_axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 4), _axis(g, 5))
    origins = (_origin(g, 0), _origin(g, 1), _origin(g, 2), _origin(g, 3), _origin(g, 4), _origin(g, 5))
    m0 = (g[_M0], g[_M0 + 1], g[_M0 + 2], g[_M0 + 3], g[_M0 + 4], g[_M0 + 5], g[_M0 + 6], g[_M0 + 7], g[_M0 + 8],
          g[_M0 + 9], g[_M0 + 10], g[_M0 + 11])
    return axes, origins, m0


@kernel(inline=True)
def _pose6_cs(cq, sq, geo, axes_w, orig_w):
    """``T(q)`` (:func:`_pose6`) from the cosines ``cq`` and sines ``sq`` (6-tuples) of the joint angles and the
    leg's :func:`_geometry` ``geo``, as tuples ``(R, p)`` (``R`` row-major, 9): no trigonometry (a closed-form
    candidate comes with them), no array but the joints' axes ``axes_w`` and points ``orig_w`` (None: not
    written)."""
    r, t = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0)
    for j in range(6):
        a, o = geo[0][j], geo[1][j]
        if axes_w is not None:  # the joint's axis and a point of it, in the root frame at q
            for i in range(3):
                axes_w[j, i] = r[3 * i] * a[0] + r[3 * i + 1] * a[1] + r[3 * i + 2] * a[2]
                orig_w[j, i] = r[3 * i] * o[0] + r[3 * i + 1] * o[1] + r[3 * i + 2] * o[2] + t[i]
        r, t = _times_joint(r, t, a, o, cq[j], sq[j])
    m = geo[2]
    return _mat_mat(r, m), (t[0] + r[0] * m[9] + r[1] * m[10] + r[2] * m[11],
                            t[1] + r[3] * m[9] + r[4] * m[10] + r[5] * m[11],
                            t[2] + r[6] * m[9] + r[7] * m[10] + r[8] * m[11])


@kernel
def _mat_mat(a, b):
    """``a b`` of two row-major 9-tuples."""
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8], a[3] * b[0] + a[4] * b[3] + a[5] * b[6],
            a[3] * b[1] + a[4] * b[4] + a[5] * b[7], a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@kernel
def _finite(x, n) -> bool:
    for i in range(n):
        if not np.isfinite(x[i]):
            return False
    return True


@kernel(entry=True)
def _fk6_k(q, g, out) -> int:
    """The foot pose ``T(q)`` (16 floats, row-major 4x4) in the root frame."""
    if not _finite(q, 6):
        return _BAD_INPUT
    rm, p = np.empty((3, 3)), np.empty(3)
    aw, ow = np.empty((6, 3)), np.empty((6, 3))
    _pose6(q, g, rm, p, aw, ow)
    for i in range(3):
        for c in range(3):
            out[4 * i + c] = rm[i, c]
        out[4 * i + 3] = p[i]
        out[12 + i] = 0.0
    out[15] = 1.0
    return OK


@kernel
def _jac6(q, g, jac, rm, p, aw, ow) -> None:
    """Pinocchio's LOCAL_WORLD_ALIGNED foot Jacobian (6, 6): column j = ``(w_j x (p - o_j), w_j)`` with the joint's
    axis ``w_j`` and point ``o_j`` at ``q`` (root frame); also the foot rotation ``rm`` and position ``p``
    (``aw``, ``ow``: (6, 3) work arrays)."""
    _pose6(q, g, rm, p, aw, ow)
    for j in range(6):
        w = (aw[j, 0], aw[j, 1], aw[j, 2])
        lin = cross(w, (p[0] - ow[j, 0], p[1] - ow[j, 1], p[2] - ow[j, 2]))
        for i in range(3):
            jac[i, j] = lin[i]
            jac[3 + i, j] = w[i]


@kernel(entry=True)
def _jacobian6_k(q, g, out) -> int:
    """The (6, 6) foot Jacobian, linear rows then angular (LOCAL_WORLD_ALIGNED at the foot frame)."""
    if not _finite(q, 6):
        return _BAD_INPUT
    _jac6(q, g, out, np.empty((3, 3)), np.empty(3), np.empty((6, 3)), np.empty((6, 3)))
    return OK


@kernel
def _rot_gap(tg, r):
    """``(v, c)`` of ``R_target R^T`` (the target's rotation in ``tg`` (16), ``R`` = ``r``, a row-major 9-tuple):
    its axial part ``v`` = ``sin(t) u`` (a 3-tuple) and ``c = cos t``, for the rotation by ``t`` about ``u``
    between them."""
    m00 = tg[0] * r[0] + tg[1] * r[1] + tg[2] * r[2]
    m11 = tg[4] * r[3] + tg[5] * r[4] + tg[6] * r[5]
    m22 = tg[8] * r[6] + tg[9] * r[7] + tg[10] * r[8]
    m21 = tg[8] * r[3] + tg[9] * r[4] + tg[10] * r[5]
    m12 = tg[4] * r[6] + tg[5] * r[7] + tg[6] * r[8]
    m02 = tg[0] * r[6] + tg[1] * r[7] + tg[2] * r[8]
    m20 = tg[8] * r[0] + tg[9] * r[1] + tg[10] * r[2]
    m10 = tg[4] * r[0] + tg[5] * r[1] + tg[6] * r[2]
    m01 = tg[0] * r[3] + tg[1] * r[4] + tg[2] * r[5]
    return (0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)), 0.5 * (m00 + m11 + m22 - 1.0)


@kernel
def _pose_error(tg, rm, p, e) -> float:
    """``e`` (6,) = ``(p_target - p, log(R_target R^T))`` (m, rad; root frame) and its norm."""
    for i in range(3):
        e[i] = tg[4 * i + 3] - p[i]
    v, c = _rot_gap(tg, (rm[0, 0], rm[0, 1], rm[0, 2], rm[1, 0], rm[1, 1], rm[1, 2], rm[2, 0], rm[2, 1], rm[2, 2]))
    sn = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    ang = math.atan2(sn, c)
    f = ang / sn if sn > 1e-300 else 1.0
    e[3], e[4], e[5] = f * v[0], f * v[1], f * v[2]
    return math.sqrt(e[0] ** 2 + e[1] ** 2 + e[2] ** 2 + e[3] ** 2 + e[4] ** 2 + e[5] ** 2)


@kernel(inline=True)
def _gap6(tt, geo, cq, sq) -> float:
    """The error of a closed-form candidate whose joints' cosines and sines are ``cq`` and ``sq`` (6-tuples), for the
    target ``tt`` (16-tuple) and the leg's :func:`_geometry` ``geo``: the forward map from those
    (:func:`_pose6_cs`: no trigonometry, no array), and when it reproduces the target to :data:`POLISH_BELOW6`
    (the closed form's usual case, ~1e-15) the larger of its position error (m) and ``sin`` of its rotation error
    (rad; equal to it there), else inf (the caller then polishes the candidate, :func:`_polish6`)."""
    r, p = _pose6_cs(cq, sq, geo, None, None)
    v, cos = _rot_gap(tt, r)
    pos2 = (tt[3] - p[0]) ** 2 + (tt[7] - p[1]) ** 2 + (tt[11] - p[2]) ** 2
    rot2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    if cos > 0.0 and pos2 + rot2 <= POLISH_BELOW6 * POLISH_BELOW6:
        return math.sqrt(max(pos2, rot2))
    return math.inf


@kernel
def _solve6(a, b, x) -> bool:
    """Solve the symmetric positive definite ``a x = b`` (6, 6) by Cholesky (``a`` overwritten); False if not SPD."""
    for j in range(6):
        s = a[j, j]
        for k in range(j):
            s -= a[j, k] * a[j, k]
        if not s > 0.0:
            return False
        a[j, j] = math.sqrt(s)
        for i in range(j + 1, 6):
            s = a[i, j]
            for k in range(j):
                s -= a[i, k] * a[j, k]
            a[i, j] = s / a[j, j]
    for i in range(6):
        s = b[i]
        for k in range(i):
            s -= a[i, k] * x[k]
        x[i] = s / a[i, i]
    for i in range(5, -1, -1):
        s = x[i]
        for k in range(i + 1, 6):
            s -= a[k, i] * x[k]
        x[i] = s / a[i, i]
    return True


@kernel
def _split_error(e) -> float:
    """``max(|e_position|, |e_rotation|)`` of a pose error ``e`` (6,) (m, rad)."""
    return max(math.sqrt(e[0] ** 2 + e[1] ** 2 + e[2] ** 2), math.sqrt(e[3] ** 2 + e[4] ** 2 + e[5] ** 2))


@kernel
def _newton_step6(tg, g, q, ws, fixed) -> float:
    """One damped Newton correction ``dq = (J^T J + lambda^2 I)^-1 J^T e`` at ``q`` into ``ws[30]`` (``e`` in
    ``ws[28]``, the pose error at ``q``), the joints of the bit mask ``fixed`` held (their Jacobian columns zeroed);
    returns ``|dq|`` (rad), or -1 if the normal matrix is not positive definite."""
    aw, ow, rm, p, e = ws[12:18, 0:3], ws[18:24, 0:3], ws[24:27, 0:3], ws[27, 0:3], ws[28]
    jac, a, b, dq = ws[0:6], ws[6:12], ws[29], ws[30]
    _jac6(q, g, jac, rm, p, aw, ow)
    for c in range(6):
        if fixed >> c & 1:
            for i in range(6):
                jac[i, c] = 0.0
    lam2 = POLISH_DAMPING6 * POLISH_DAMPING6
    for i in range(6):
        b[i] = 0.0
        for k in range(6):
            b[i] += jac[k, i] * e[k]
        for c in range(6):
            s = lam2 if i == c else 0.0
            for k in range(6):
                s += jac[k, i] * jac[k, c]
            a[i, c] = s
    if not _solve6(a, b, dq):
        return -1.0
    return math.sqrt(dq[0] ** 2 + dq[1] ** 2 + dq[2] ** 2 + dq[3] ** 2 + dq[4] ** 2 + dq[5] ** 2)


@kernel
def _polish6(tg, g, q, ws, fixed=0) -> float:
    """Damped Newton steps (:func:`_newton_step6`) on the exact forward map while ``|e|`` exceeds
    :data:`POLISH_BELOW6`, at most :data:`POLISH_STEPS6`, as long as the corrections shrink (``|dq|`` less than the
    previous step's: Deuflhard's natural monotonicity test, affine invariant). A step may raise ``|e|``: near a
    singular pose (least singular value ``sigma`` of ``J``) the closed form can land ``~1e-5`` rad off along the
    near-null direction with ``|e| ~ 1e-11``, where the first full step overshoots the residual (10x) but lands
    ``1e-9`` rad from the root and the next one at ``|e| ~ 1e-16`` (talos, ``sigma = 1.7e-7``); a test on ``|e|``
    stopped there. ``q`` ends at the iterate of least ``|e|``. ``ws``: a work array of at least 32 rows of 6.
    Returns the error of the final ``q``: the larger of its position error (m) and its rotation error (rad)."""
    aw, ow, rm, p, e, dq, qb = ws[12:18, 0:3], ws[18:24, 0:3], ws[24:27, 0:3], ws[27, 0:3], ws[28], ws[30], ws[31]
    _pose6(q, g, rm, p, aw, ow)
    err = _pose_error(tg, rm, p, e)
    best, split = err, _split_error(e)
    if err <= POLISH_BELOW6:  # the closed form's usual case: no work space for the steps
        return split
    for i in range(6):
        qb[i] = q[i]
    last = math.inf
    for _ in range(POLISH_STEPS6):
        if err <= POLISH_BELOW6:
            break
        size = _newton_step6(tg, g, q, ws, fixed)
        if not 0.0 <= size < last:  # not a descent any more: no root near, or the rounding floor
            break
        last = size
        for i in range(6):
            q[i] += dq[i]
        _pose6(q, g, rm, p, aw, ow)
        err = _pose_error(tg, rm, p, e)
        if err < best:
            best, split = err, _split_error(e)
            for i in range(6):
                qb[i] = q[i]
    for i in range(6):
        q[i] = qb[i]
    return split


@kernel
def _mat_vec(m, v):
    """``m v`` for a (3, 3) array ``m``."""
    return _m9_vec((m[0, 0], m[0, 1], m[0, 2], m[1, 0], m[1, 1], m[1, 2], m[2, 0], m[2, 1], m[2, 2]), v)


@kernel
def _mat_t_vec(m, v):
    """``m^T v`` for a (3, 3) array ``m``."""
    return _m9_vec((m[0, 0], m[1, 0], m[2, 0], m[0, 1], m[1, 1], m[2, 1], m[0, 2], m[1, 2], m[2, 2]), v)


@kernel
def _m9_vec(m, v):
    """``m v`` for a row-major 9-tuple ``m``."""
    return (m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2])


@kernel
def _target_motion(tg, g, gr):
    """``G = T M_0^-1`` of the target ``T`` (16 floats): its rotation into ``gr`` (3, 3), its translation returned."""
    for i in range(3):
        for k in range(3):  # R_G = R_T R_0^T
            j = _M0 + 3 * k
            gr[i, k] = tg[4 * i] * g[j] + tg[4 * i + 1] * g[j + 1] + tg[4 * i + 2] * g[j + 2]
    gp0 = _mat_vec(gr, (g[_M0 + 9], g[_M0 + 10], g[_M0 + 11]))
    return tg[3] - gp0[0], tg[7] - gp0[1], tg[11] - gp0[2]


@kernel
def _in_window(t, r, lo, hi):
    """``(x, (x - r)^2, x is not NaN)``: ``x`` the 2 pi representative of the angle ``t`` inside ``[lo, hi]`` nearest
    ``r`` (NaN if none; :func:`legkin.legs._ik_kernels._in_limits_k`, the cost of
    :func:`legkin.legs._ik6_kernels._limited`)."""
    x, _ = _in_limits_k(t, r, lo, hi)
    return x, (x - r) ** 2, x == x


@kernel(inline=True)
def _kept(t, j, lim, prune):
    """Joint ``j``'s angle ``t`` as a candidate row of :func:`_hip_candidates` holds it, ``(x, cost, kept)``:
    ``(t, 0, True)``, or with ``prune`` :func:`_in_window` of the joint's limits and reference (``lim``: the
    6-tuples ``(lower, upper, ref)``)."""
    if prune:
        return _in_window(t, lim[2][j], lim[0][j], lim[1][j])
    return t, 0.0, True


@kernel(inline=True)
def _sp2_branch(sol, i, j, lim, prune):
    """Branch ``i`` (0 or 1) of the answer ``sol`` of :func:`sp2_cs` for joints ``j``, ``j + 1`` (the cosine and sine
    of ``-q_j`` and of ``q_(j+1)``): ``(p_j, p_(j+1), x_j, x_(j+1), cost, kept)``, the pairs and the angles as
    :func:`_kept` gives them, the sum of their costs, and whether both are kept (the second angle not computed
    when the first is not)."""
    pa, pb = (sol[1], sol[2]) if i == 0 else (sol[3], sol[4])
    xa, ka, kept = _kept(-math.atan2(pa[1], pa[0]), j, lim, prune)
    if not kept:
        return pa, pb, xa, xa, ka, False
    xb, kb, kept = _kept(math.atan2(pb[1], pb[0]), j + 1, lim, prune)
    return pa, pb, xa, xb, ka + kb, kept


@kernel(inline=True)
def _hip_setup(tg, g, ref, gr):
    """What :func:`_hip_candidates` reads of the target ``tg`` and the leg ``g``, as tuples (no array is touched
    in its branches: each array a helper receives costs atomic reference counts): ``R_G`` (row-major 9-tuple),
    ``d - a``, ``c - o_4``, ``a - o_4``, the leg's :func:`_geometry`, the unit ``v`` normal to ``a_3`` and ``a_2``,
    ``(lower, upper, ref)`` and the target (16-tuple)."""
    gt = _target_motion(tg, g, gr)
    rg = (gr[0, 0], gr[0, 1], gr[0, 2], gr[1, 0], gr[1, 1], gr[1, 2], gr[2, 0], gr[2, 1], gr[2, 2])
    c = (g[_HIP], g[_HIP + 1], g[_HIP + 2])
    an = (g[_ANK], g[_ANK + 1], g[_ANK + 2])
    d = _mat_t_vec(gr, (c[0] - gt[0], c[1] - gt[1], c[2] - gt[2]))
    geo = _geometry(g)
    o4 = geo[1][3]
    v = cross(geo[0][2], geo[0][1])
    nv = math.sqrt(dot(v, v))
    lo = (g[_LO6], g[_LO6 + 1], g[_LO6 + 2], g[_LO6 + 3], g[_LO6 + 4], g[_LO6 + 5])
    hi = (g[_HI6], g[_HI6 + 1], g[_HI6 + 2], g[_HI6 + 3], g[_HI6 + 4], g[_HI6 + 5])
    return (rg, (d[0] - an[0], d[1] - an[1], d[2] - an[2]), (c[0] - o4[0], c[1] - o4[1], c[2] - o4[2]),
            (an[0] - o4[0], an[1] - o4[1], an[2] - o4[2]), geo, (v[0] / nv, v[1] / nv, v[2] / nv),
            (lo, hi, (ref[0], ref[1], ref[2], ref[3], ref[4], ref[5])),
            (tg[0], tg[1], tg[2], tg[3], tg[4], tg[5], tg[6], tg[7], tg[8], tg[9], tg[10], tg[11], 0.0, 0.0, 0.0, 1.0))


@kernel
def _hip_candidates(tg, g, ref, prune, cand, cost, resid, gr) -> int:
    """The closed-form solutions (rows of ``cand`` (8, 6)) of a leg whose hip axes 1-3 meet at the hip centre
    ``c`` and whose ankle axes 5, 6 meet at the ankle centre ``a``; returns how many rows are filled. Each row's
    error goes to ``resid`` (:func:`_gap6`: a forward map from the subproblems' cosines and sines, inf above
    :data:`POLISH_BELOW6`: the row then needs the polish). Every branch (rows in
    the branch order of ``ik_all``), or with ``prune`` only those inside the limits (:func:`_kept`): each angle at
    its representative inside them nearest ``ref``, a branch dropped at its first joint without one (a knee root
    bent the wrong way: its four rows never built), and ``|q - ref|^2`` in ``cost``. ``gr``: a (3, >= 3) work
    array.

    With ``G = T M_0^-1`` and ``d = G^-1 c``: ``E_4 E_5 E_6 d = c``. Then (i) SP3: ``|E_4^-1 c - a| = |d - a|``
    gives ``q_4``; (ii) SP2: ``R(a_5, -q_5)(E_4^-1 c - a) = R(a_6, q_6)(d - a)`` gives ``(q_5, q_6)``; (iii) the hip
    rotation ``R_h = R_G R_6^T R_5^T R_4^T``: SP2 ``R(a_1, -q_1) R_h a_3 = R(a_2, q_2) a_3`` gives ``(q_1, q_2)``,
    SP1 ``R(a_3, q_3) v = R_2^T R_1^T R_h v`` (``v`` normal to ``a_3``) gives ``q_3`` (:func:`_hip_branch`).
    Branches that the subproblems find absent are filled with their least-squares angles (the check and the
    residual decide)."""
    rg, da, co, ao, geo, v, lim, tt = _hip_setup(tg, g, ref, gr)
    ax = geo[0]
    a4, a5, a6 = ax[3], ax[4], ax[5]
    _, t4a, t4b, _ = sp3(co, ao, a4, math.sqrt(dot(da, da)))
    n = 0
    for i4 in range(2):
        q4 = -(t4a if i4 == 0 else t4b)
        x4, k4, kept = _kept(q4, 3, lim, prune)
        if not kept:
            continue
        c4, s4 = math.cos(q4), -math.sin(q4)  # R(a_4, -q_4)
        e = rot_cs(a4, c4, s4, co)
        s56 = sp2_cs((e[0] - ao[0], e[1] - ao[1], e[2] - ao[2]), da, a5, a6)  # (cos, sin) of -q_5 and of q_6
        r4a3, r4v = rot_cs(a4, c4, s4, ax[2]), rot_cs(a4, c4, s4, v)
        for i56 in range(2):
            p5, p6, x5, x6, k56, kept = _sp2_branch(s56, i56, 4, lim, prune)
            if not kept:
                continue
            # R_h y = R_G R_6^T R_5^T R_4^T y
            h3 = _m9_vec(rg, rot_cs(a6, p6[0], -p6[1], rot_cs(a5, p5[0], p5[1], r4a3)))
            hv = _m9_vec(rg, rot_cs(a6, p6[0], -p6[1], rot_cs(a5, p5[0], p5[1], r4v)))
            s12 = sp2_cs(h3, ax[2], ax[0], ax[1])  # (cos, sin) of -q_1 and of q_2
            for i12 in range(2):
                kept, q123, cs123, k123 = _hip_branch(s12, i12, hv, v, ax, lim, prune)
                if not kept:
                    continue
                row = (q123[0], q123[1], q123[2], x4, x5, x6)
                cq = (cs123[0], cs123[2], cs123[4], c4, p5[0], p6[0])
                sq = (cs123[1], cs123[3], cs123[5], -s4, -p5[1], p6[1])
                for j in range(6):
                    cand[n, j] = row[j]
                cost[n], resid[n] = k4 + k56 + k123, _gap6(tt, geo, cq, sq)
                n += 1
    return n


@kernel
def _hip_branch(s12, i12, hv, v, ax, lim, prune):
    """Hip branch ``i12`` of :func:`_hip_candidates` (step iii; ``s12`` the answer of its SP2, ``R_h v = hv``):
    ``(kept, (q_1, q_2, q_3), (cos, sin) of each, cost)``."""
    p1, p2, x1, x2, k12, kept = _sp2_branch(s12, i12, 0, lim, prune)
    if not kept:
        return False, (x1, x2, x2), (p1[0], p1[1], p2[0], p2[1], p2[0], p2[1]), k12
    p3 = sp1_cs(v, rot_cs(ax[1], p2[0], -p2[1], rot_cs(ax[0], p1[0], p1[1], hv)), ax[2])
    x3, k3, kept = _kept(math.atan2(p3[1], p3[0]), 2, lim, prune)
    return kept, (x1, x2, x3), (p1[0], -p1[1], p2[0], p2[1], p3[0], p3[1]), k12 + k3


@kernel(inline=True)
def _valid_pose(tg) -> bool:
    """``tg`` (16) is a finite homogeneous transform: bottom row ``0 0 0 1`` (to 1e-12), ``R^T R = I`` and
    ``det R = 1`` to 1e-6 (the same test as :func:`legkin.legs.sixdof._pose_input`)."""
    if not _finite(tg, 16):
        return False
    if abs(tg[12]) > 1e-12 or abs(tg[13]) > 1e-12 or abs(tg[14]) > 1e-12 or abs(tg[15] - 1.0) > 1e-12:
        return False
    for i in range(3):
        for c in range(3):
            s = tg[i] * tg[c] + tg[4 + i] * tg[4 + c] + tg[8 + i] * tg[8 + c]
            if abs(s - (1.0 if i == c else 0.0)) > 1e-6:
                return False
    det = dot((tg[0], tg[4], tg[8]), cross((tg[1], tg[5], tg[9]), (tg[2], tg[6], tg[10])))
    return abs(det - 1.0) <= 1e-6


_fk6_batch = batch_loop(_fk6_k, min_parallel=2048)
_jacobian6_batch = batch_loop(_jacobian6_k, min_parallel=1024)
