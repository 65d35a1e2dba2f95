"""Every IK solution of a 6-DOF leg whose joints 3, 4, 5 have parallel axes (alexander's hip pitch, knee and
ankle pitch) by a one-dimensional search over the ankle roll ``q_6`` (:mod:`legkin.legs.sixdof`).

With ``n`` the common direction of axes 3-5, ``E_3 E_4 E_5 = H`` is a planar motion: it turns about ``n`` and
keeps every plane normal to ``n``. With ``G = T M_0^-1``, ``H = E_2^-1 E_1^-1 G E_6^-1``, so for a trial ``t = q_6``:

1. rotation: ``R_1 R_2 n = m(t) = R_G R(a_6, -t) n``: SP2 ``R(a_1, -q_1) m = R(a_2, q_2) n`` gives ``(q_1, q_2)``
   (two branches, where the cones meet);
2. the residual ``r(t) = n . (H o_3 - o_3)`` (m) must vanish (``H`` keeps the plane of ``o_3``): every sign change
   of ``r`` between the :data:`SEARCH_GRID` grid points is bracketed (also between a grid point and a fold
   where the two SP2 branches meet) and refined by the Illinois method to 1e-15 rad; where ``|r|`` dips at a grid
   point without a sign change, a golden-section search finds the dip's extremum: two close roots are bracketed
   on either side of it, a tangential root (``|r| <=`` :data:`TANGENT_TOL` there) is kept;
3. at each root, the planar 3R by subproblems: SP3 ``|R(a_3, -q_3)(P - o_3) - (o_4 - o_3)| = |o_5 - o_4|`` with
   ``P = H o_5`` gives ``q_3`` (2 solutions), SP1 ``R(a_4, q_4)(o_5 - o_4) = E_3^-1 P - o_4`` gives ``q_4``, SP1 on a
   vector ``v`` normal to ``n`` gives ``q_5``.

Every candidate is then polished on the exact forward map and kept only if it reproduces the target
(:mod:`._ik6_kernels`), so a root refined on the ideal structure never yields an approximate answer.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from ._sixdof_kernels import _axis, _mat_vec, _origin, _target_motion
from ._sixdof_layout import SEARCH_GRID, TANGENT_TOL
from .subproblems import cross, dot, rot, sp1, sp2, sp3

_REFINE_STEPS = 100


@kernel
def _h_point(x, t, q1, q2, gr, gt, g):
    """``H x = E_2^-1 E_1^-1 G E_6^-1 x`` for ``q_6 = t``."""
    a1, a2, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 5)
    o1, o2, o6 = _origin(g, 0), _origin(g, 1), _origin(g, 5)
    y = rot(a6, -t, (x[0] - o6[0], x[1] - o6[1], x[2] - o6[2]))
    z = _mat_vec(gr, (y[0] + o6[0], y[1] + o6[1], y[2] + o6[2]))
    w = rot(a1, -q1, (z[0] + gt[0] - o1[0], z[1] + gt[1] - o1[1], z[2] + gt[2] - o1[2]))
    u = rot(a2, -q2, (w[0] + o1[0] - o2[0], w[1] + o1[1] - o2[1], w[2] + o1[2] - o2[2]))
    return u[0] + o2[0], u[1] + o2[1], u[2] + o2[2]


@kernel
def _residual(t, branch, gr, gt, g):
    """``(valid, q1, q2, r(t))`` of the SP2 branch ``branch`` (0, 1) at ``q_6 = t``; not valid where the cones miss."""
    n, a1, a2, a6 = _axis(g, 2), _axis(g, 0), _axis(g, 1), _axis(g, 5)
    m = _mat_vec(gr, rot(a6, -t, n))
    cnt, t1a, t2a, t1b, t2b, _ = sp2(m, n, a1, a2)
    q1, q2 = (-t1a, t2a) if branch == 0 else (-t1b, t2b)
    o3 = _origin(g, 2)
    h = _h_point(o3, t, q1, q2, gr, gt, g)
    return cnt == 2, q1, q2, dot(n, (h[0] - o3[0], h[1] - o3[1], h[2] - o3[2]))


@kernel
def _residual2(t, gr, gt, g):
    """``(valid, r_0(t), r_1(t))``: the residual of both SP2 branches from one SP2 solve."""
    n, a1, a2, a6 = _axis(g, 2), _axis(g, 0), _axis(g, 1), _axis(g, 5)
    m = _mat_vec(gr, rot(a6, -t, n))
    cnt, t1a, t2a, t1b, t2b, _ = sp2(m, n, a1, a2)
    o3 = _origin(g, 2)
    ha = _h_point(o3, t, -t1a, t2a, gr, gt, g)
    hb = _h_point(o3, t, -t1b, t2b, gr, gt, g)
    return (cnt == 2, dot(n, (ha[0] - o3[0], ha[1] - o3[1], ha[2] - o3[2])),
            dot(n, (hb[0] - o3[0], hb[1] - o3[1], hb[2] - o3[2])))


@kernel
def _refine(lo, hi, rlo, rhi, branch, gr, gt, g) -> float:
    """A root of ``r`` in ``[lo, hi]`` (``rlo``, ``rhi`` of opposite signs) by the Illinois (regula falsi) method."""
    side = 0
    for _ in range(_REFINE_STEPS):
        t = (lo * rhi - hi * rlo) / (rhi - rlo)
        if not (lo < t < hi) and not (hi < t < lo):
            t = 0.5 * (lo + hi)
        ok, _, _, r = _residual(t, branch, gr, gt, g)
        if not ok or r == 0.0:
            return t
        if (r > 0.0) == (rhi > 0.0):
            hi, rhi = t, r
            if side == 1:
                rlo *= 0.5
            side = 1
        else:
            lo, rlo = t, r
            if side == -1:
                rhi *= 0.5
            side = -1
        if abs(hi - lo) <= 1e-15 * (1.0 + abs(t)):
            break
    return (lo * rhi - hi * rlo) / (rhi - rlo)


@kernel
def _fold(t_ok, t_bad, gr, gt, g) -> float:
    """The fold (where the SP2 cones become tangent) between a valid ``t_ok`` and an invalid ``t_bad``, by bisection
    (the valid side returned)."""
    for _ in range(60):
        mid = 0.5 * (t_ok + t_bad)
        if _residual(mid, 0, gr, gt, g)[0]:
            t_ok = mid
        else:
            t_bad = mid
    return t_ok


@kernel
def _dip(lo, hi, b, gr, gt, g):
    """Golden-section search for the extremum of ``r`` (branch ``b``) in ``[lo, hi]`` toward zero (``|r|``
    minimal); returns ``(t, r(t))``."""
    k = 0.5 * (math.sqrt(5.0) - 1.0)
    x1, x2 = hi - k * (hi - lo), lo + k * (hi - lo)
    f1, f2 = abs(_residual(x1, b, gr, gt, g)[3]), abs(_residual(x2, b, gr, gt, g)[3])
    for _ in range(60):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - k * (hi - lo)
            f1 = abs(_residual(x1, b, gr, gt, g)[3])
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + k * (hi - lo)
            f2 = abs(_residual(x2, b, gr, gt, g)[3])
        if hi - lo <= 1e-15:
            break
    t = 0.5 * (lo + hi)
    return t, _residual(t, b, gr, gt, g)[3]


@kernel
def _near_double_root(t0, t2, r1, b, gr, gt, g, cand, n) -> int:
    """Where ``|r|`` dips between grid points ``t0 < t1 < t2`` (same sign at all three): two roots closer than the
    grid, or a tangential (double) root. Brackets both sides of the dip's extremum when it changes sign, keeps the
    extremum itself when ``|r|`` reaches :data:`TANGENT_TOL` there."""
    tm, rm = _dip(t0, t2, b, gr, gt, g)
    if (rm > 0.0) != (r1 > 0.0):
        r0, r2 = _residual(t0, b, gr, gt, g)[3], _residual(t2, b, gr, gt, g)[3]
        n = _root_rows(t0, tm, r0, rm, b, gr, gt, g, cand, n)
        return _root_rows(tm, t2, rm, r2, b, gr, gt, g, cand, n)
    if abs(rm) <= TANGENT_TOL:
        ok, q1, q2, _ = _residual(tm, b, gr, gt, g)
        if ok:
            return _planar(tm, q1, q2, gr, gt, g, cand, n)
    return n


@kernel
def _planar(t, q1, q2, gr, gt, g, cand, n) -> int:
    """The planar 3R (joints 3-5) at the root ``q_6 = t`` with hip ``(q1, q2)``: up to 2 rows of ``cand`` from ``n``."""
    a1, a2, a3, a4, a5, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 4), _axis(g, 5)
    o3, o4, o5 = _origin(g, 2), _origin(g, 3), _origin(g, 4)
    p = _h_point(o5, t, q1, q2, gr, gt, g)
    d45 = math.sqrt((o5[0] - o4[0]) ** 2 + (o5[1] - o4[1]) ** 2 + (o5[2] - o4[2]) ** 2)
    _, ta, tb, _ = sp3((p[0] - o3[0], p[1] - o3[1], p[2] - o3[2]), (o4[0] - o3[0], o4[1] - o3[1], o4[2] - o3[2]),
                       a3, d45)
    v = cross(a3, a1) if abs(dot(a3, a1)) < 0.9 else cross(a3, a2)
    nv = math.sqrt(dot(v, v))
    v = (v[0] / nv, v[1] / nv, v[2] / nv)
    hv = rot(a2, -q2, rot(a1, -q1, _mat_vec(gr, rot(a6, -t, v))))  # R_H v
    for i in range(2):
        if n >= cand.shape[0]:
            return n
        q3 = -(ta if i == 0 else tb)
        e = rot(a3, -q3, (p[0] - o3[0], p[1] - o3[1], p[2] - o3[2]))
        q4 = sp1((o5[0] - o4[0], o5[1] - o4[1], o5[2] - o4[2]),
                 (e[0] + o3[0] - o4[0], e[1] + o3[1] - o4[1], e[2] + o3[2] - o4[2]), a4)
        q5 = sp1(v, rot(a4, -q4, rot(a3, -q3, hv)), a5)
        cand[n, 0], cand[n, 1], cand[n, 2], cand[n, 3], cand[n, 4], cand[n, 5] = q1, q2, q3, q4, q5, t
        n += 1
    return n


@kernel
def _root_rows(lo, hi, rlo, rhi, b, gr, gt, g, cand, n) -> int:
    """Refine the bracket ``[lo, hi]`` of branch ``b`` and add the root's planar solutions to ``cand``."""
    t = _refine(lo, hi, rlo, rhi, b, gr, gt, g)
    ok, q1, q2, _ = _residual(t, b, gr, gt, g)
    return _planar(t, q1, q2, gr, gt, g, cand, n) if ok else n


@kernel
def _parallel_candidates(tg, g, cand) -> int:
    """The candidate rows (``cand`` (K, 6)) of the target ``tg`` (16 floats); returns how many are filled."""
    gr = np.empty((3, 3))
    gt = _target_motion(tg, g, gr)
    step = 2.0 * math.pi / SEARCH_GRID
    n = 0
    prev_t = -math.pi
    prev = np.empty((2, 3))  # per branch: valid, r at the previous grid point, r at the one before (NaN: none)
    ok, r0, r1 = _residual2(prev_t, gr, gt, g)
    prev[0, 0], prev[0, 1], prev[1, 0], prev[1, 1] = ok, r0, ok, r1
    prev[0, 2], prev[1, 2] = math.nan, math.nan
    for i in range(1, SEARCH_GRID + 1):
        t = -math.pi + i * step
        ok, r0, r1 = _residual2(t, gr, gt, g)
        for b in range(2):
            r = r0 if b == 0 else r1
            was_ok, was_r, was_r2 = prev[b, 0] > 0.0, prev[b, 1], prev[b, 2]
            if ok and was_ok:
                if (r > 0.0) != (was_r > 0.0) or r == 0.0:
                    n = _root_rows(prev_t, t, was_r, r, b, gr, gt, g, cand, n)
                elif (was_r2 > 0.0) == (r > 0.0) and abs(was_r) < abs(was_r2) and abs(was_r) <= abs(r):
                    n = _near_double_root(prev_t - step, t, was_r, b, gr, gt, g, cand, n)
            elif ok or was_ok:  # a fold between the two grid points: bracket up to it
                good, bad = (t, prev_t) if ok else (prev_t, t)
                good_r = r if ok else was_r
                f = _fold(good, bad, gr, gt, g)
                rf = _residual(f, b, gr, gt, g)[3]
                if (rf > 0.0) != (good_r > 0.0):
                    n = _root_rows(good, f, good_r, rf, b, gr, gt, g, cand, n)
            prev[b, 2] = was_r if (ok and was_ok) else math.nan
            prev[b, 0], prev[b, 1] = ok, r
        prev_t = t
    return n
