"""Every IK solution of a 6-DOF leg without a closed form, by a one-dimensional search (:mod:`legkin.legs.sixdof`):
one joint ``t`` is searched over a full turn; for each trial value the others follow by subproblems along a few
*branches*, each with a scalar residual ``r_b(t)`` that vanishes at a solution. Two structures:

**Three parallel axes** (alexander: joints 3-5 parallel to ``n``), ``t = q_6``, 2 branches.
``E_3 E_4 E_5 = H = E_2^-1 E_1^-1 G E_6^-1`` (``G = T M_0^-1``) is a planar motion about ``n``:

1. rotation: ``R_1 R_2 n = R_G R(a_6, -t) n``: SP2 ``R(a_1, -q_1) m = R(a_2, q_2) n`` gives ``(q_1, q_2)`` (branch b);
2. ``r_b(t) = n . (H o_3 - o_3)`` (m): ``H`` must keep the plane of ``o_3``;
3. at a root, the planar 3R: SP3 ``|R(a_3, -q_3)(P - o_3) - (o_4 - o_3)| = |o_5 - o_4|`` with ``P = H o_5``
   (2 rows), SP1 for ``q_4`` (``E_4 o_5 = E_3^-1 P``) and for ``q_5`` (a vector ``v`` normal to ``n``).

**Offset hip** (g1: axes 2, 3 meet at ``h``, axes 4, 5 parallel to ``n``, hip pitch axis 1 off them), ``t = q_1``,
4 branches. With ``d = G^-1 E_1(t) h``, ``E_4 E_5 E_6 d = h`` (``E_2 E_3`` fixes ``h``):

1. SP4 ``n . R(a_6, q_6)(d - o_6) = n . (h - o_6)`` (the planar pair keeps ``n . x``) gives ``q_6`` (2);
2. with ``y = E_6 d``, SP3 ``|R(a_4, -q_4)(h - o_4) - (o_5 - o_4)| = |y - o_5|`` gives ``q_4`` (2), SP1
   ``R(a_5, q_5)(y - o_5) = E_4^-1 h - o_5`` gives ``q_5``;
3. ``R_23 = R(a_1, -t) R_G R_6^T R_5^T R_4^T`` must turn about the two hip axes only:
   ``r_b(t) = a_2 . (R_23 a_3) - a_2 . a_3``; at a root SP1 gives ``q_2`` (``R_2 a_3 = R_23 a_3``) and ``q_3``.

The search: every sign change of ``r_b`` between the :data:`SEARCH_GRID` grid points is bracketed (also between
a grid point and a *fold* where the branch stops existing, found by bisection) and refined by the Illinois method
to 1e-15 rad; where ``|r_b|`` dips at a grid point without a sign change (or next to a fold, where g1's knee
nears full stretch and the two ``q_4`` branches meet), a golden-section search finds the dip's extremum: two close
roots are bracketed on its sides, a tangential root (``|r| <=`` :data:`TANGENT_TOL`) kept.
Every candidate is then polished on the exact forward map and kept only if it reproduces the target
(:mod:`._ik6_kernels`).
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from ._sixdof_kernels import _axis, _mat_t_vec, _mat_vec, _origin, _target_motion
from ._sixdof_layout import _HIP, _KIND, SEARCH_GRID, TANGENT_TOL, THREE_PARALLEL
from .subproblems import cross, dot, rot, sp1, sp2, sp3, sp4

_REFINE_STEPS = 100
_NB = 4  # branches at most


@kernel
def _sub(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@kernel
def _add(a, b):
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


@kernel
def _unit_normal(n, a, b):
    """A unit vector normal to ``n``: ``n x a`` (or ``n x b`` when ``a`` is nearly along ``n``)."""
    v = cross(n, a) if abs(dot(n, a)) < 0.9 else cross(n, b)
    nv = math.sqrt(dot(v, v))
    return v[0] / nv, v[1] / nv, v[2] / nv


# ---------------------------------------------------------------- three parallel axes (search over q6)
@kernel
def _h_point(x, t, q1, q2, gr, gt, g):
    """``H x = E_2^-1 E_1^-1 G E_6^-1 x`` for ``q_6 = t``."""
    a1, a2, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 5)
    o1, o2, o6 = _origin(g, 0), _origin(g, 1), _origin(g, 5)
    z = _add(_mat_vec(gr, _add(rot(a6, -t, _sub(x, o6)), o6)), gt)
    return _add(rot(a2, -q2, _add(rot(a1, -q1, _sub(z, o1)), _sub(o1, o2))), o2)


@kernel
def _par_hip(t, b, gr, g):
    """``(exists, q1, q2)``: SP2 branch ``b`` of the hip at ``q_6 = t``."""
    n, a1, a2, a6 = _axis(g, 2), _axis(g, 0), _axis(g, 1), _axis(g, 5)
    cnt, t1a, t2a, t1b, t2b, _ = sp2(_mat_vec(gr, rot(a6, -t, n)), n, a1, a2)
    return (cnt == 2, -t1a, t2a) if b == 0 else (cnt == 2, -t1b, t2b)


@kernel
def _add_row(cand, n, q1, q2, q3, q4, q5, q6) -> int:
    """Append a row to ``cand`` unless full or already there (every angle within 1e-12 rad); returns the count."""
    for k in range(n):
        if max(abs(cand[k, 0] - q1), abs(cand[k, 1] - q2), abs(cand[k, 2] - q3), abs(cand[k, 3] - q4),
               abs(cand[k, 4] - q5), abs(cand[k, 5] - q6)) <= 1e-12:
            return n
    if n >= cand.shape[0]:
        return n
    cand[n, 0], cand[n, 1], cand[n, 2], cand[n, 3], cand[n, 4], cand[n, 5] = q1, q2, q3, q4, q5, q6
    return n + 1


@kernel
def _par_eval(t, gr, gt, g, ok, r) -> None:
    """Both branches at ``q_6 = t``, sharing the SP2 solve."""
    n, a1, a2, a6, o3 = _axis(g, 2), _axis(g, 0), _axis(g, 1), _axis(g, 5), _origin(g, 2)
    cnt, t1a, t2a, t1b, t2b, _ = sp2(_mat_vec(gr, rot(a6, -t, n)), n, a1, a2)
    ok[0], ok[1], ok[2], ok[3] = cnt == 2, cnt == 2, False, False
    r[0] = dot(n, _sub(_h_point(o3, t, -t1a, t2a, gr, gt, g), o3))
    r[1] = dot(n, _sub(_h_point(o3, t, -t1b, t2b, gr, gt, g), o3))


@kernel
def _par_rows(t, b, gr, gt, g, cand, n) -> int:
    """The planar 3R (joints 3-5) at the root ``q_6 = t`` of branch ``b``: up to 2 rows of ``cand`` from ``n``."""
    a1, a2, a3, a4, a5, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 4), _axis(g, 5)
    o3, o4, o5 = _origin(g, 2), _origin(g, 3), _origin(g, 4)
    _, q1, q2 = _par_hip(t, b, gr, g)
    p = _h_point(o5, t, q1, q2, gr, gt, g)
    d45 = math.sqrt(dot(_sub(o5, o4), _sub(o5, o4)))
    _, ta, tb, _ = sp3(_sub(p, o3), _sub(o4, o3), a3, d45)
    v = _unit_normal(a3, a1, a2)
    hv = rot(a2, -q2, rot(a1, -q1, _mat_vec(gr, rot(a6, -t, v))))  # R_H v
    for i in range(2):
        q3 = -(ta if i == 0 else tb)
        e = _add(rot(a3, -q3, _sub(p, o3)), o3)
        q4 = sp1(_sub(o5, o4), _sub(e, o4), a4)
        q5 = sp1(v, rot(a4, -q4, rot(a3, -q3, hv)), a5)
        n = _add_row(cand, n, q1, q2, q3, q4, q5, t)
    return n


# ---------------------------------------------------------------- offset hip (search over q1)
@kernel
def _off_q6(t, gr, gt, g):
    """``(count, q6_a, q6_b, d)``: SP4 for the ankle roll at ``q_1 = t``, with ``d = G^-1 E_1(t) h``."""
    a1, a4, a6 = _axis(g, 0), _axis(g, 3), _axis(g, 5)
    o1, o6 = _origin(g, 0), _origin(g, 5)
    h = (g[_HIP], g[_HIP + 1], g[_HIP + 2])
    d = _mat_t_vec(gr, _sub(_add(rot(a1, t, _sub(h, o1)), o1), gt))
    c6, t6a, t6b, _ = sp4(a4, _sub(d, o6), a6, dot(a4, _sub(h, o6)))
    return c6, t6a, t6b, d


@kernel
def _off_q4(d, q6, g):
    """``(count, q4_a, q4_b, y)``: SP3 for the knee, with ``y = E_6(q6) d``."""
    a4, a6 = _axis(g, 3), _axis(g, 5)
    o4, o5, o6 = _origin(g, 3), _origin(g, 4), _origin(g, 5)
    h = (g[_HIP], g[_HIP + 1], g[_HIP + 2])
    y = _add(rot(a6, q6, _sub(d, o6)), o6)
    ry = math.sqrt(dot(_sub(y, o5), _sub(y, o5)))
    c4, t4a, t4b, _ = sp3(_sub(h, o4), _sub(o5, o4), a4, ry)
    return c4, -t4a, -t4b, y


@kernel
def _off_r(t, q4, q6, y, gr, g):
    """``(q5, r)``: SP1 for the ankle pitch and the hip residual ``a_2 . (R_23 a_3) - a_2 . a_3``."""
    a1, a2, a3, a4, a5, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 4), _axis(g, 5)
    o4, o5 = _origin(g, 3), _origin(g, 4)
    h = (g[_HIP], g[_HIP + 1], g[_HIP + 2])
    e = _add(rot(a4, -q4, _sub(h, o4)), o4)
    q5 = sp1(_sub(y, o5), _sub(e, o5), a5)
    w = rot(a1, -t, _mat_vec(gr, rot(a6, -q6, rot(a5, -q5, rot(a4, -q4, a3)))))  # R_23 a_3
    return q5, dot(a2, w) - dot(a2, a3)


@kernel
def _off_chain(t, b, gr, gt, g):
    """``(exists, q4, q5, q6, r)`` of branch ``b`` (``q_6`` branch ``b // 2``, ``q_4`` branch ``b % 2``) at
    ``q_1 = t``."""
    c6, t6a, t6b, d = _off_q6(t, gr, gt, g)
    q6 = t6a if b < 2 else t6b
    c4, q4a, q4b, y = _off_q4(d, q6, g)
    q4 = q4a if b % 2 == 0 else q4b
    q5, r = _off_r(t, q4, q6, y, gr, g)
    return c6 == 2 and c4 == 2, q4, q5, q6, r


@kernel
def _off_eval(t, gr, gt, g, ok, r) -> None:
    """All four branches at ``q_1 = t``, sharing the SP4 and SP3 solves."""
    c6, t6a, t6b, d = _off_q6(t, gr, gt, g)
    for i6 in range(2):
        q6 = t6a if i6 == 0 else t6b
        c4, q4a, q4b, y = _off_q4(d, q6, g)
        for i4 in range(2):
            b = 2 * i6 + i4
            ok[b] = c6 == 2 and c4 == 2
            r[b] = _off_r(t, q4a if i4 == 0 else q4b, q6, y, gr, g)[1]


@kernel
def _off_rows(t, b, gr, gt, g, cand, n) -> int:
    """The hip pair (SP1, SP1) at the root ``q_1 = t`` of branch ``b``: one row of ``cand``."""
    a1, a2, a3, a4, a5, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 4), _axis(g, 5)
    _, q4, q5, q6, _ = _off_chain(t, b, gr, gt, g)
    w = rot(a1, -t, _mat_vec(gr, rot(a6, -q6, rot(a5, -q5, rot(a4, -q4, a3)))))
    q2 = sp1(a3, w, a2)
    v = _unit_normal(a3, a2, a1)
    rv = rot(a2, -q2, rot(a1, -t, _mat_vec(gr, rot(a6, -q6, rot(a5, -q5, rot(a4, -q4, v))))))
    return _add_row(cand, n, t, q2, sp1(v, rv, a3), q4, q5, q6)


# ---------------------------------------------------------------- the search
@kernel
def _eval(t, gr, gt, g, ok, r) -> None:
    """Every branch's existence ``ok`` (4,) and residual ``r`` (4,) at the searched value ``t``."""
    if g[_KIND] == THREE_PARALLEL:
        _par_eval(t, gr, gt, g, ok, r)
    else:
        _off_eval(t, gr, gt, g, ok, r)


@kernel
def _eval1(t, b, gr, gt, g, ws):
    """``(exists, r)`` of branch ``b`` at ``t``."""
    if g[_KIND] == THREE_PARALLEL:
        ok, q1, q2 = _par_hip(t, b, gr, g)
        n, o3 = _axis(g, 2), _origin(g, 2)
        return ok, dot(n, _sub(_h_point(o3, t, q1, q2, gr, gt, g), o3))
    ok, _, _, _, r = _off_chain(t, b, gr, gt, g)
    return ok, r


@kernel
def _rows(t, b, gr, gt, g, cand, n) -> int:
    if g[_KIND] == THREE_PARALLEL:
        return _par_rows(t, b, gr, gt, g, cand, n)
    return _off_rows(t, b, gr, gt, g, cand, n)


@kernel
def _refine(lo, hi, rlo, rhi, b, gr, gt, g, ws) -> float:
    """A root of ``r_b`` in ``[lo, hi]`` (``rlo``, ``rhi`` of opposite signs) by the Illinois (regula falsi) method."""
    side = 0
    for _ in range(_REFINE_STEPS):
        t = (lo * rhi - hi * rlo) / (rhi - rlo)
        if not (lo < t < hi) and not (hi < t < lo):
            t = 0.5 * (lo + hi)
        ok, r = _eval1(t, b, gr, gt, g, ws)
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
def _root(lo, hi, rlo, rhi, b, gr, gt, g, ws, cand, n) -> int:
    """Refine the bracket ``[lo, hi]`` of branch ``b`` and add the root's rows to ``cand`` (nothing when ``rlo`` and
    ``rhi`` have the same sign)."""
    if (rlo > 0.0) == (rhi > 0.0) and rlo != 0.0 and rhi != 0.0:
        return n
    t = _refine(lo, hi, rlo, rhi, b, gr, gt, g, ws)
    return _rows(t, b, gr, gt, g, cand, n) if _eval1(t, b, gr, gt, g, ws)[0] else n


@kernel
def _fold(t_ok, t_bad, b, gr, gt, g, ws) -> float:
    """Where branch ``b`` stops existing between ``t_ok`` and ``t_bad``, by bisection (the existing side)."""
    for _ in range(60):
        mid = 0.5 * (t_ok + t_bad)
        if _eval1(mid, b, gr, gt, g, ws)[0]:
            t_ok = mid
        else:
            t_bad = mid
    return t_ok


@kernel
def _dip(t0, t2, r1, b, gr, gt, g, ws, cand, n) -> int:
    """``r_b`` dips toward zero between ``t0`` and ``t2`` without a sign change (``r1``: a value of that sign): the
    golden-section search for the extremum of ``r_b`` (the minimum of ``sign(r1) r_b``); two roots bracketed on its
    sides if it crosses zero, a tangential root if within :data:`TANGENT_TOL` of it."""
    sg = 1.0 if r1 > 0.0 else -1.0
    k = 0.5 * (math.sqrt(5.0) - 1.0)
    lo, hi = t0, t2
    x1, x2 = hi - k * (hi - lo), lo + k * (hi - lo)
    f1, f2 = sg * _eval1(x1, b, gr, gt, g, ws)[1], sg * _eval1(x2, b, gr, gt, g, ws)[1]
    for _ in range(80):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - k * (hi - lo)
            f1 = sg * _eval1(x1, b, gr, gt, g, ws)[1]
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + k * (hi - lo)
            f2 = sg * _eval1(x2, b, gr, gt, g, ws)[1]
        if hi - lo <= 1e-15 * (1.0 + abs(lo)):
            break
    tm = 0.5 * (lo + hi)
    okm, rm = _eval1(tm, b, gr, gt, g, ws)
    if not okm:
        return n
    if (rm > 0.0) != (r1 > 0.0):
        r0, r2 = _eval1(t0, b, gr, gt, g, ws)[1], _eval1(t2, b, gr, gt, g, ws)[1]
        n = _root(t0, tm, r0, rm, b, gr, gt, g, ws, cand, n)
        return _root(tm, t2, rm, r2, b, gr, gt, g, ws, cand, n)
    return _rows(tm, b, gr, gt, g, cand, n) if abs(rm) <= TANGENT_TOL else n


@kernel
def _step(t, prev_t, step, b, ok, r, was_ok, was_r, was_r2, gr, gt, g, ws, cand, n) -> int:
    """The search between grid points ``prev_t`` and ``t`` on branch ``b``."""
    if ok and was_ok:
        if (r > 0.0) != (was_r > 0.0) or r == 0.0:
            return _root(prev_t, t, was_r, r, b, gr, gt, g, ws, cand, n)
        if (was_r2 > 0.0) == (r > 0.0) and abs(was_r) < abs(was_r2) and abs(was_r) <= abs(r):
            return _dip(prev_t - step, t, was_r, b, gr, gt, g, ws, cand, n)
    elif ok or was_ok:  # a fold between the two grid points: bracket up to it, and look for a dip next to it
        good, bad, good_r = (t, prev_t, r) if ok else (prev_t, t, was_r)
        f = _fold(good, bad, b, gr, gt, g, ws)
        rf = _eval1(f, b, gr, gt, g, ws)[1]
        if (rf > 0.0) != (good_r > 0.0):
            lo, hi, rlo, rhi = (f, good, rf, good_r) if f < good else (good, f, good_r, rf)
            return _root(lo, hi, rlo, rhi, b, gr, gt, g, ws, cand, n)
        far = good + step if f < good else good - step
        if _eval1(far, b, gr, gt, g, ws)[0]:
            return _dip(min(far, f), max(far, f), good_r, b, gr, gt, g, ws, cand, n)
    return n


@kernel
def _search_candidates(tg, g, cand) -> int:
    """The candidate rows (``cand`` (K, 6)) of the target ``tg`` (16 floats); returns how many are filled."""
    gr = np.empty((3, 3))
    gt = _target_motion(tg, g, gr)
    ws = np.empty((2, _NB))
    cur = np.empty((2, _NB))  # existence, residual at t
    prev = np.empty((3, _NB))  # existence, residual at the previous grid point, residual one before (NaN: none)
    step = 2.0 * math.pi / SEARCH_GRID
    prev_t = -math.pi
    _eval(prev_t, gr, gt, g, prev[0], prev[1])
    for b in range(_NB):
        prev[2, b] = math.nan
    n = 0
    for i in range(1, SEARCH_GRID + 1):
        t = -math.pi + i * step
        _eval(t, gr, gt, g, cur[0], cur[1])
        for b in range(_NB):
            ok, r, was_ok = cur[0, b] > 0.0, cur[1, b], prev[0, b] > 0.0
            n = _step(t, prev_t, step, b, ok, r, was_ok, prev[1, b], prev[2, b], gr, gt, g, ws, cand, n)
            prev[2, b] = prev[1, b] if (ok and was_ok) else math.nan
            prev[0, b], prev[1, b] = cur[0, b], r
        prev_t = t
    return n
