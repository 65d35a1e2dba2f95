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

On the offset hip every quantity of one point is ``X_0 + X_c cos t + X_s sin t`` with per-target coefficients
(:func:`_off_prepare`) and the subproblems' roots are taken as cosine/sine pairs: a point costs one cosine, one sine
and a few square roots for all 4 branches, no allocation.

The search (:data:`SEARCH_GRID` points by structure). No root may be missed, so every cell between two grid points is
*settled* by a bound, not by its end values alone. On a cell ``[a, b]`` of width ``w`` where ``|r_b''| <= M``: the
chord's slope ``(r(b) - r(a)) / w`` is ``r_b'`` somewhere, so ``|r(b) - r(a)| > M w^2`` keeps ``r_b'`` from vanishing
(one root if the signs differ, none if not), and ``min(|r(a)|, |r(b)|) > M w^2 / 8`` with equal signs leaves none (the
chord minus the parabola of curvature ``M``). ``M`` is ``S`` = :data:`CURVATURE_SAFETY` times the larger second
difference at the cell's ends, over ``w^2``: exact with ``S = 1`` for a cubic, whose ``r''`` is linear (so largest at an
end) and equals its centred second difference; with ``S``, ``M`` bounds ``|r''|`` whenever ``w^2 |r''''| <= 24 (S - 1) /
(2 S + 3) max(|r''(a)|, |r''(b)|)`` on the cell (3.4 for ``S = 2``: ``r''`` strays from its chord by ``<= w^2 |r''''| /
8``, the second difference from ``r''`` by ``<= w^2 |r''''| / 12``). A cell is concluded empty only with :data:`DOUBT`
times that bound: near g1's singular poses a pair of roots 1e-3 to 1e-2 rad apart sits next to a fold, where the
residual curves far more than its second differences at the cell's ends say. A cell the bound does not settle is halved,
each half's ``M`` the larger of the parent's and ``S`` times its own second difference, down to :data:`_MIN_CELL`. That
catches what values alone miss: three roots of a branch within one or two cells (g1, a pose near a cusp of its
solutions), two roots in a cell of equal signs. Sign changes are refined by the Illinois method to 1e-15 rad.

Where a branch stops existing (a *fold*, where g1's knee nears full stretch and two branches meet; found by the
Illinois method on the existence margin), the residual moves like ``sqrt(|t - f|)``, whose derivatives have no
bound; in ``u`` with ``t = f + (t_g - f) u^2`` it is smooth, so the piece from the fold to the grid point ``t_g``
beyond the next is searched as above on :data:`_FOLD_CELLS` cells equally spaced in ``u`` (the fold itself a
candidate where the residual nearly vanishes there). Islands (the branch exists between grid points only) and holes
(it stops existing between them) are found where the existence margin's parabola through three grid points comes
near zero, by Brent's minimisation of the margin, and searched from their folds.
Every candidate is then polished on the exact forward map and kept only if it reproduces the target
(:mod:`._ik6_kernels`).

The bound rests on that condition on the residual's fourth derivative, which the search does not verify: it is a bound
checked by measurement (with :data:`DOUBT` as a margin), not a proof for every target. ``python
scripts/legs6_completeness.py`` (docs/legs.md): the sampled configuration among ``ik_all``'s rows on every random
in-limit sample (10^6 per leg of g1, 6x10^5 per leg of alexander), where the values alone missed about 1 in 10^5
on g1; ``python scripts/check_sweep.py g1 alexander``: every check row for seeds 0-19 at up to 10^5 samples."""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from ._sixdof_kernels import _axis, _mat_t_vec, _mat_vec, _origin, _target_motion
from ._sixdof_layout import _GRID, _HIP, _KIND, TANGENT_TOL, THREE_PARALLEL
from .subproblems import cross, dot, rot, rot_cs, sp1, sp2, sp3

_REFINE_STEPS = 100
#: Brent's minimisation of an existence margin (an island's peak, a hole's dip) stops at this width (rad).
_DIP_WIDTH = 1e-8
#: Cells of the search from a fold to the grid point beyond the next (equal in u, t = f + span u^2: widths in t growing
#: quadratically, as the sqrt(t - f) of a fold).
_FOLD_CELLS = 6
_NB = 4  # branches at most
#: A cell's residual is taken to curve at most this many times as much as the second differences at its ends say
#: (:func:`_cell`; the module docstring gives the condition on the fourth derivative that makes it a bound).
CURVATURE_SAFETY = 2.0
#: A cell is concluded to hold no root only where the curvature bound shows it with this factor on the bound (the
#: bound rests on a condition on the fourth derivative that the search does not verify). The poses that it missed
#: with no such factor (g1 near its singular poses, ``sigma_min`` 2e-5 to 2e-4, at 10^5 samples of seeds 10, 15, 16,
#: 19: a pair of roots 1e-3 to 1e-2 rad apart in a cell of equal signs, next to a fold) were all settled by less than
#: 8 times the bound; an unsettled cell is halved (:func:`_cell`), each level raising the margin about 4 times.
DOUBT = 16.0
#: A bisection stops at this width (the searched variable's units; rad on the grid): a sign change there is one root
#: (two roots this close are the same solution to the polish), a residual within TANGENT_TOL a tangential root.
_MIN_CELL = 1e-10
_STACK = 64  # cells waiting on :func:`_cell`'s stack at most


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
    m = 1.0 if cnt == 2 else -1.0
    ok[0], ok[1], ok[2], ok[3] = m, m, -1.0, -1.0
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
# The per-target coefficients ``co`` of the offset-hip search (:func:`_off_prepare`): every quantity that the
# residual needs at ``q_1 = t`` is ``X_0 + X_c cos t + X_s sin t`` or a constant, so one point of the search costs
# a cosine, a sine, a few square roots and products (no other transcendental function).
_CP = 0  # p(t) = d(t) - o_6 (3 vectors: constant, cos, sin)
_CX = 9  # a_6 x p(t)
_CU = 18  # u(t) = R_G^T R(a_1, t) a_2
_CK = 27  # a_6 . p(t) (3 numbers), then SP4's A(t) (3) and B(t) (3)
_CE = 36  # E_4^-1 h - o_5 (vectors of 1, cos q_4, -sin q_4)
_CV = 45  # R_4^T a_3 (idem)
_CC = 54  # constants: SP4's a_4 . (h - o_6), a_6 . a_4; SP3's x offset and ry^2 factor, radius, cos/sin phi; a_2 . a_3
_NCO = 62


@kernel
def _put(co, i, v) -> None:
    co[i], co[i + 1], co[i + 2] = v[0], v[1], v[2]


@kernel
def _at(co, i, c, s):
    """The vector ``X_0 + c X_c + s X_s`` stored at ``co[i:i + 9]``."""
    return (co[i] + c * co[i + 3] + s * co[i + 6], co[i + 1] + c * co[i + 4] + s * co[i + 7],
            co[i + 2] + c * co[i + 5] + s * co[i + 8])


@kernel
def _off_prepare(gr, gt, g, co) -> None:
    """Fill ``co`` for the target motion ``(gr, gt)``: ``d(t) = G^-1 E_1(t) h`` is a circle, so ``p = d - o_6``,
    ``a_6 x p``, SP4's coefficients and ``u(t) = R_G^T R(a_1, t) a_2`` are each ``X_0 + X_c cos t + X_s sin t``;
    ``E_4^-1 h - o_5`` and ``R_4^T a_3`` are ``X_0 + X_c cos q_4 - X_s sin q_4``."""
    a1, a2, a3, a4, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 5)
    o1, o4, o5, o6 = _origin(g, 0), _origin(g, 3), _origin(g, 4), _origin(g, 5)
    h = (g[_HIP], g[_HIP + 1], g[_HIP + 2])
    p = _sub(h, o1)
    ap, a12 = dot(a1, p), dot(a1, a2)
    base = _sub(_add(o1, (ap * a1[0], ap * a1[1], ap * a1[2])), gt)
    parts = (_sub(_mat_t_vec(gr, base), o6), _mat_t_vec(gr, _sub(p, (ap * a1[0], ap * a1[1], ap * a1[2]))),
             _mat_t_vec(gr, cross(a1, p)))
    us = (_mat_t_vec(gr, (a12 * a1[0], a12 * a1[1], a12 * a1[2])),
          _mat_t_vec(gr, _sub(a2, (a12 * a1[0], a12 * a1[1], a12 * a1[2]))), _mat_t_vec(gr, cross(a1, a2)))
    a46, n46 = dot(a6, a4), cross(a4, a6)
    p1, p2 = _sub(h, o4), _sub(o5, o4)  # SP3 |R(a_4, -q_4) p1 - p2| = |y - o_5|: only the distance changes
    k1, k3 = dot(a4, p1), dot(a4, a3)
    es = (_add((k1 * a4[0], k1 * a4[1], k1 * a4[2]), _sub(o4, o5)), _sub(p1, (k1 * a4[0], k1 * a4[1], k1 * a4[2])),
          cross(a4, p1))
    vs = ((k3 * a4[0], k3 * a4[1], k3 * a4[2]), _sub(a3, (k3 * a4[0], k3 * a4[1], k3 * a4[2])), cross(a4, a3))
    for k in range(3):
        v = parts[k]
        _put(co, _CP + 3 * k, v)
        _put(co, _CX + 3 * k, cross(a6, v))
        _put(co, _CU + 3 * k, us[k])
        _put(co, _CE + 3 * k, es[k])
        _put(co, _CV + 3 * k, vs[k])
        co[_CK + k] = dot(a6, v)
        co[_CK + 3 + k] = dot(a4, v) - co[_CK + k] * a46
        co[_CK + 6 + k] = dot(n46, v)
    n2 = math.sqrt(dot(p2, p2))
    hh = (p2[0] / n2, p2[1] / n2, p2[2] / n2)
    kk = k1 * dot(a4, hh)
    aa, bb = dot(hh, p1) - kk, dot(hh, cross(a4, p1))
    rr = math.hypot(aa, bb)
    co[_CC], co[_CC + 1] = dot(a4, _sub(h, o6)), a46
    co[_CC + 2], co[_CC + 3] = (dot(p1, p1) + n2 * n2) / (2.0 * n2) - kk, 1.0 / (2.0 * n2)
    co[_CC + 4], co[_CC + 5], co[_CC + 6], co[_CC + 7] = rr, aa / rr, bb / rr, dot(a2, a3)


@kernel
def _branch_cs(x, r, cphi, sphi, sgn):
    """``(margin, cos, sin)`` of ``phi + sgn g`` with ``cos g = x / r`` (SP4's two roots without trigonometry); the
    roots exist where ``margin = r - |x| >= 0``."""
    cg = min(1.0, max(-1.0, x / r)) if r > 0.0 else 1.0
    sg = math.sqrt(1.0 - cg * cg)
    return r - abs(x), cphi * cg - sgn * sphi * sg, sphi * cg + sgn * cphi * sg


@kernel
def _off_q6(c, s, i6, g, co):
    """``(margin, cos q_6, sin q_6, y - o_5)``: SP4 ``a_4 . R(a_6, q_6) p = a_4 . (h - o_6)`` (root ``i6``) at
    ``(cos q_1, sin q_1) = (c, s)``, and ``y = o_6 + R(a_6, q_6) p``."""
    a6, o5, o6 = _axis(g, 5), _origin(g, 4), _origin(g, 5)
    p, x6 = _at(co, _CP, c, s), _at(co, _CX, c, s)
    kp = co[_CK] + c * co[_CK + 1] + s * co[_CK + 2]
    aa = co[_CK + 3] + c * co[_CK + 4] + s * co[_CK + 5]
    bb = co[_CK + 6] + c * co[_CK + 7] + s * co[_CK + 8]
    rr = math.sqrt(aa * aa + bb * bb)
    rr_ = rr if rr > 0.0 else 1.0
    m6, c6, s6 = _branch_cs(co[_CC] - kp * co[_CC + 1], rr, aa / rr_, bb / rr_, -1.0 if i6 == 0 else 1.0)
    w = (1.0 - c6) * kp
    y5 = (c6 * p[0] + s6 * x6[0] + w * a6[0] + o6[0] - o5[0], c6 * p[1] + s6 * x6[1] + w * a6[1] + o6[1] - o5[1],
          c6 * p[2] + s6 * x6[2] + w * a6[2] + o6[2] - o5[2])
    return m6, c6, s6, y5


@kernel
def _off_r(u, i4, y5, c6, s6, g, co):
    """``(margin, r, cos q_4, sin q_4, cos q_5, sin q_5)`` of the ``q_4`` root ``i4`` given ``y - o_5`` and ``q_6``:
    SP3 ``|R(a_4, -q_4)(h - o_4) - (o_5 - o_4)| = |y - o_5|``, SP1 ``R(a_5, q_5)(y - o_5) = E_4^-1 h - o_5``, and
    ``r = u . R_6^T R_5^T R_4^T a_3 - a_2 . a_3`` (``u = R_G^T R(a_1, q_1) a_2``)."""
    a5, a6 = _axis(g, 4), _axis(g, 5)
    m4, c4, s4 = _branch_cs(co[_CC + 2] - co[_CC + 3] * dot(y5, y5), co[_CC + 4], co[_CC + 5], co[_CC + 6],
                            -1.0 if i4 == 0 else 1.0)  # (c4, s4): cos, sin of -q_4
    e5 = _at(co, _CE, c4, s4)
    ky, ke = dot(a5, y5), dot(a5, e5)
    num, den = dot(a5, cross(y5, e5)), dot(y5, e5) - ky * ke
    hy = math.sqrt(num * num + den * den)
    c5, s5 = (den / hy, num / hy) if hy > 0.0 else (1.0, 0.0)
    v = rot_cs(a6, c6, -s6, rot_cs(a5, c5, -s5, _at(co, _CV, c4, s4)))
    return m4, dot(u, v) - co[_CC + 7], c4, -s4, c5, s5


@kernel
def _off_at(c, s, b, g, co):
    """Branch ``b`` (``q_6`` root ``b // 2``, ``q_4`` root ``b % 2``) at ``(cos q_1, sin q_1) = (c, s)``:
    ``(margin, r, cos q_4, sin q_4, cos q_5, sin q_5, cos q_6, sin q_6)``; the branch exists where ``margin >= 0``,
    ``r = a_2 . R_23 a_3 - a_2 . a_3`` (:func:`_off_r`)."""
    m6, c6, s6, y5 = _off_q6(c, s, b // 2, g, co)
    m4, r, c4, s4, c5, s5 = _off_r(_at(co, _CU, c, s), b % 2, y5, c6, s6, g, co)
    return min(m6, m4), r, c4, s4, c5, s5, c6, s6


@kernel
def _off_rows(t, b, gr, g, co, cand, n) -> int:
    """The hip pair (SP1, SP1) at the root ``q_1 = t`` of branch ``b``: one row of ``cand``."""
    a1, a2, a3, a4, a5, a6 = _axis(g, 0), _axis(g, 1), _axis(g, 2), _axis(g, 3), _axis(g, 4), _axis(g, 5)
    c, s = math.cos(t), math.sin(t)
    _, _, c4, s4, c5, s5, c6, s6 = _off_at(c, s, b, g, co)
    v = _unit_normal(a3, a2, a1)
    w3 = rot_cs(a1, c, -s, _mat_vec(gr, rot_cs(a6, c6, -s6, rot_cs(a5, c5, -s5, rot_cs(a4, c4, -s4, a3)))))
    wv = rot_cs(a1, c, -s, _mat_vec(gr, rot_cs(a6, c6, -s6, rot_cs(a5, c5, -s5, rot_cs(a4, c4, -s4, v)))))
    q2 = sp1(a3, w3, a2)
    q3 = sp1(v, rot(a2, -q2, wv), a3)
    return _add_row(cand, n, t, q2, q3, math.atan2(s4, c4), math.atan2(s5, c5), math.atan2(s6, c6))


# ---------------------------------------------------------------- the search
@kernel
def _eval(t, gr, gt, g, ws, ok, r) -> None:
    """Every branch's existence margin ``ok`` (4,) (:func:`_margin`) and residual ``r`` (4,) at the searched value
    ``t`` (``ws``: the offset-hip coefficients of :func:`_off_prepare`)."""
    if g[_KIND] == THREE_PARALLEL:
        _par_eval(t, gr, gt, g, ok, r)
        return
    c, s = math.cos(t), math.sin(t)
    u = _at(ws, _CU, c, s)
    for i6 in range(2):
        m6, c6, s6, y5 = _off_q6(c, s, i6, g, ws)
        for i4 in range(2):
            m4, rb = _off_r(u, i4, y5, c6, s6, g, ws)[:2]
            ok[2 * i6 + i4], r[2 * i6 + i4] = min(m6, m4), rb


@kernel
def _eval1(t, b, gr, gt, g, ws):
    """``(exists, r)`` of branch ``b`` at ``t``."""
    if g[_KIND] == THREE_PARALLEL:
        ok, q1, q2 = _par_hip(t, b, gr, g)
        n, o3 = _axis(g, 2), _origin(g, 2)
        return ok, dot(n, _sub(_h_point(o3, t, q1, q2, gr, gt, g), o3))
    res = _off_at(math.cos(t), math.sin(t), b, g, ws)
    return res[0] >= 0.0, res[1]


@kernel
def _rows(t, b, gr, gt, g, ws, cand, n) -> int:
    if g[_KIND] == THREE_PARALLEL:
        return _par_rows(t, b, gr, gt, g, cand, n)
    return _off_rows(t, b, gr, g, ws, cand, n)


@kernel
def _illinois(t, f, a, b, fa, fb, side):
    """One step of the Illinois method: the bracket ``(a, b)`` (``fa``, ``fb`` of opposite signs) with the new point
    ``(t, f)``; ``side``: which end moved last (the other end's value is halved when the same end moves twice).
    Returns ``(a, b, fa, fb, side)``."""
    if (f > 0.0) == (fb > 0.0):
        return a, t, fa * 0.5 if side == 1 else fa, f, 1
    return t, b, f, fb * 0.5 if side == -1 else fb, -1


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
        lo, hi, rlo, rhi, side = _illinois(t, r, lo, hi, rlo, rhi, side)
        if abs(hi - lo) <= 1e-15 * (1.0 + abs(t)):
            break
    return (lo * rhi - hi * rlo) / (rhi - rlo)


@kernel
def _root1(lo, hi, rlo, rhi, b, gr, gt, g, ws, cand, n):
    """Refine the bracket ``[lo, hi]`` of branch ``b`` and add the root's rows to ``cand``: ``(n, t)`` with ``t`` the
    point where the branch does not exist if the refinement met one (NaN otherwise)."""
    if (rlo > 0.0) == (rhi > 0.0) and rlo != 0.0 and rhi != 0.0:
        return n, math.nan
    t = _refine(lo, hi, rlo, rhi, b, gr, gt, g, ws)
    if _eval1(t, b, gr, gt, g, ws)[0]:
        return _rows(t, b, gr, gt, g, ws, cand, n), math.nan
    return n, t


@kernel
def _root(lo, hi, rlo, rhi, b, gr, gt, g, ws, cand, n) -> int:
    """:func:`_root1`; where the bracket holds a gap of the branch (two folds between the grid points), each side is
    bracketed up to its fold."""
    n, gap = _root1(lo, hi, rlo, rhi, b, gr, gt, g, ws, cand, n)
    if gap == gap:
        f1, f2 = _fold(lo, gap, b, gr, gt, g, ws), _fold(hi, gap, b, gr, gt, g, ws)
        n = _root1(lo, f1, rlo, _eval1(f1, b, gr, gt, g, ws)[1], b, gr, gt, g, ws, cand, n)[0]
        n = _root1(f2, hi, _eval1(f2, b, gr, gt, g, ws)[1], rhi, b, gr, gt, g, ws, cand, n)[0]
    return n


@kernel
def _margin(t, b, gr, gt, g, ws) -> float:
    """Where branch ``b`` exists: ``>= 0`` at ``t``; a smooth function of ``t`` for the offset hip (SP4's and SP3's
    ``r - |x|``), else ``+1`` / ``-1``."""
    if g[_KIND] == THREE_PARALLEL:
        return 1.0 if _eval1(t, b, gr, gt, g, ws)[0] else -1.0
    return _off_at(math.cos(t), math.sin(t), b, g, ws)[0]


@kernel
def _fold(t_ok, t_bad, b, gr, gt, g, ws) -> float:
    """Where branch ``b`` stops existing between ``t_ok`` and ``t_bad`` (the existing side, to ~1e-15 rad): the
    Illinois method on :func:`_margin` (bisection where the margin is only a sign)."""
    m_ok, m_bad = _margin(t_ok, b, gr, gt, g, ws), _margin(t_bad, b, gr, gt, g, ws)
    side = 0
    for _ in range(_REFINE_STEPS):
        t = (t_ok * m_bad - t_bad * m_ok) / (m_bad - m_ok)
        if not (t_ok < t < t_bad) and not (t_bad < t < t_ok):
            t = 0.5 * (t_ok + t_bad)
        m = _margin(t, b, gr, gt, g, ws)
        t_bad, t_ok, m_bad, m_ok, side = _illinois(t, m if m != 0.0 else 1e-300, t_bad, t_ok, m_bad, m_ok, side)
        if abs(t_bad - t_ok) <= 1e-15 * (1.0 + abs(t)):
            break
    return t_ok


@kernel
def _parabola_step(x, w, v, fx, fw, fv):
    """``(p, q)``: the step ``p / q`` from ``x`` to the vertex of the parabola through ``(x, fx), (w, fw), (v, fv)``
    (``q >= 0``)."""
    r = (x - w) * (fx - fv)
    q = (x - v) * (fx - fw)
    p = (x - v) * q - (x - w) * r
    q = 2.0 * (q - r)
    return (-p, q) if q > 0.0 else (p, -q)


@kernel
def _dip_f(t, sg, b, gr, gt, g, ws) -> float:
    """``sg margin_b(t)`` (``sg = +-1``): the function whose minimum :func:`_dip_minimum` seeks."""
    return sg * _margin(t, b, gr, gt, g, ws)


@kernel
def _dip_minimum(lo, hi, sg, b, gr, gt, g, ws):
    """``(t, f)``: the minimum of ``f`` (:func:`_dip_f`) on ``[lo, hi]`` by Brent's method (parabolic steps
    safeguarded by golden sections), to :data:`_DIP_WIDTH`; it stops early where ``f`` goes negative."""
    gold = 0.5 * (3.0 - math.sqrt(5.0))
    x = w = v = lo + gold * (hi - lo)
    fx = fw = fv = _dip_f(x, sg, b, gr, gt, g, ws)
    d = e = 0.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if fx < 0.0 or abs(x - mid) <= 2.0 * _DIP_WIDTH - 0.5 * (hi - lo):
            break
        p, q = _parabola_step(x, w, v, fx, fw, fv) if abs(e) > _DIP_WIDTH else (0.0, 0.0)
        if q != 0.0 and abs(p) < abs(0.5 * q * e) and q * (lo - x) < p < q * (hi - x):
            e, d = d, p / q
        else:
            e = hi - x if x < mid else lo - x
            d = gold * e
        u = x + (d if abs(d) >= _DIP_WIDTH else math.copysign(_DIP_WIDTH, d))
        fu = _dip_f(u, sg, b, gr, gt, g, ws)
        if fu <= fx:
            lo, hi = (lo, x) if u < x else (x, hi)
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            lo, hi = (u, hi) if u < x else (lo, u)
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x, fx


@kernel
def _second(ra, rm, rb) -> float:
    """``|ra - 2 rm + rb|``: the second difference of three equally spaced values (NaN if one is NaN)."""
    return abs(ra - 2.0 * rm + rb)


@kernel
def _verdict(ra, rb, w, m2) -> int:
    """What ``|r''| <= m2`` on a cell of width ``w`` with end values ``ra``, ``rb`` proves: 0 no root, 1 exactly one
    root, -1 nothing. The chord's slope ``s = (rb - ra) / w`` is ``r'`` somewhere in the cell, so ``|s| > m2 w``
    keeps ``r' != 0`` throughout (``r`` monotone); with equal signs, ``r >= min(|ra|, |rb|) - m2 w^2 / 8`` on the
    cell (the chord minus the parabola of curvature ``m2``). No root is concluded only where that holds with
    :data:`DOUBT` times ``m2``."""
    if (ra > 0.0) == (rb > 0.0) and ra != 0.0 and rb != 0.0:
        m2 *= DOUBT
        return 0 if abs(rb - ra) > m2 * w * w or min(abs(ra), abs(rb)) > 0.125 * m2 * w * w else -1
    return 1 if abs(rb - ra) > m2 * w * w else -1


@kernel
def _cell(ua, ub, ra, rb, m2, base, span, quad, b, gr, gt, g, ws, cand, n) -> int:
    """Every root of ``r_b`` on the cell ``[t(ua), t(ub)]`` (the branch exists at both ends, residuals ``ra``,
    ``rb``), ``t(u) = base + span u`` (``quad``: ``base + span u^2``, the piece next to a fold, where ``r_b`` is
    smooth in ``u``); ``m2``: the bound taken for ``|d^2 r_b / du^2|`` on the cell (NaN: none).

    A cell is settled when :func:`_verdict` proves it holds no root or exactly one (refined by :func:`_root`); else
    it is halved, the bound raised to :data:`CURVATURE_SAFETY` times the curvature that the midpoint's second
    difference shows if larger, and both halves examined in turn (a stack in ``ws``). Halves narrower than
    :data:`_MIN_CELL` keep a sign change as one root and a residual within :data:`TANGENT_TOL` of zero as a tangential
    root. A midpoint where the branch does not exist ends the cell's search (a hole: :func:`_hole` searches it)."""
    st, top = ws[_NCO:], 1
    st[0], st[1], st[2], st[3], st[4] = ua, ub, ra, rb, m2
    while top > 0:
        top -= 1
        k = 5 * top
        ua, ub, ra, rb, m2 = st[k], st[k + 1], st[k + 2], st[k + 3], st[k + 4]
        w = ub - ua
        v = _verdict(ra, rb, w, m2) if m2 == m2 else -1
        if v == 0:
            continue
        ta, tb = base + span * (ua * ua if quad else ua), base + span * (ub * ub if quad else ub)
        if v == 1 or w <= _MIN_CELL or top >= _STACK - 2:
            if (ra > 0.0) != (rb > 0.0) or ra == 0.0 or rb == 0.0:
                n = _root(ta, tb, ra, rb, b, gr, gt, g, ws, cand, n)
            elif min(abs(ra), abs(rb)) <= TANGENT_TOL:
                n = _rows(ta if abs(ra) <= abs(rb) else tb, b, gr, gt, g, ws, cand, n)
            continue
        um = 0.5 * (ua + ub)
        okm, rm = _eval1(base + span * (um * um if quad else um), b, gr, gt, g, ws)
        if not okm:
            continue
        mm = CURVATURE_SAFETY * _second(ra, rm, rb) / (0.25 * w * w)
        mm = max(mm, m2) if m2 == m2 else mm
        st[k], st[k + 1], st[k + 2], st[k + 3], st[k + 4] = um, ub, rm, rb, mm
        st[k + 5], st[k + 6], st[k + 7], st[k + 8], st[k + 9] = ua, um, ra, rm, mm
        top += 2
    return n


@kernel
def _bound(r, j, w) -> float:
    """The curvature bound of the cell ``[j, j + 1]`` of the equally spaced values ``r`` (``w`` apart; NaN where the
    branch does not exist): :data:`CURVATURE_SAFETY` times the larger second difference centred on its ends, over
    ``w^2``; NaN if neither exists."""
    d = -1.0
    if j >= 1 and r[j - 1] == r[j - 1]:
        d = _second(r[j - 1], r[j], r[j + 1])
    if j + 2 < r.shape[0] and r[j + 2] == r[j + 2]:
        d = max(d, _second(r[j], r[j + 1], r[j + 2]))
    return CURVATURE_SAFETY * d / (w * w) if d >= 0.0 else math.nan


@kernel
def _from_fold(good, good_r, bad, b, gr, gt, g, ws, cand, n) -> int:
    """The piece from the fold between ``good`` (the branch exists, residual ``good_r``) and ``bad`` (it does not) to
    ``good``. There ``r_b`` moves like ``sqrt(|t - f|)``, smooth in ``u`` with ``t = f + (good - f) u^2``: the
    values at :data:`_FOLD_CELLS` + 1 equally spaced ``u`` and :func:`_cell` on each cell; the fold itself is a
    candidate where the residual nearly vanishes there."""
    x0 = _fold(good, bad, b, gr, gt, g, ws)
    span, rs = good - x0, ws[_NCO + 5 * _STACK:_NCO + 5 * _STACK + _FOLD_CELLS + 1]
    rs[0], rs[_FOLD_CELLS] = _eval1(x0, b, gr, gt, g, ws)[1], good_r
    if abs(rs[0]) <= TANGENT_TOL:  # a root at the fold (a stretched knee), or a target just beyond it
        n = _rows(x0, b, gr, gt, g, ws, cand, n)
    for j in range(1, _FOLD_CELLS):
        ok, rs[j] = _eval1(x0 + span * (j / _FOLD_CELLS) ** 2, b, gr, gt, g, ws)
        if not ok:  # another fold between the two: left to the polish of its neighbours
            return n
    for j in range(_FOLD_CELLS):
        m2 = _bound(rs, j, 1.0 / _FOLD_CELLS)
        n = _cell(j / _FOLD_CELLS, (j + 1) / _FOLD_CELLS, rs[j], rs[j + 1], m2, x0, span, True, b, gr, gt, g, ws,
                  cand, n)
    return n


@kernel
def _island(lo, hi, b, gr, gt, g, ws, cand, n) -> int:
    """The branch does not exist at the grid points ``lo``, ``(lo + hi) / 2``, ``hi`` but its margin peaks near zero
    between them: where the peak is positive (the branch exists on an island between two folds), both halves of the
    island are searched from their folds (:func:`_from_fold`)."""
    x, f = _dip_minimum(lo, hi, -1.0, b, gr, gt, g, ws)
    if not f < 0.0:
        return n
    rx = _eval1(x, b, gr, gt, g, ws)[1]
    n = _from_fold(x, rx, lo, b, gr, gt, g, ws, cand, n)
    return _from_fold(x, rx, hi, b, gr, gt, g, ws, cand, n)


@kernel
def _hole(lo, hi, b, gr, gt, g, ws, cand, n) -> int:
    """The branch exists at the grid points ``lo``, ``(lo + hi) / 2``, ``hi`` but its margin dips near zero between
    them: where the dip is negative (a gap between two folds), the pieces from each fold to the grid points on its
    side are searched (:func:`_from_fold`)."""
    x, f = _dip_minimum(lo, hi, 1.0, b, gr, gt, g, ws)
    if not f < 0.0:
        return n
    mid = 0.5 * (lo + hi)
    for good in (lo, mid, hi):
        if good != x:
            n = _from_fold(good, _eval1(good, b, gr, gt, g, ws)[1], x, b, gr, gt, g, ws, cand, n)
    return n


@kernel
def _peak(m2, m1, m0) -> bool:
    """Three negative margins at consecutive grid points with a peak in the middle whose parabola comes within half
    its second difference of zero: the branch may exist between the grid points (an island)."""
    c2 = m2 - 2.0 * m1 + m0
    if not (m0 < 0.0 and m1 < 0.0 and m2 < 0.0 and m1 > m2 and m1 >= m0 and c2 < 0.0):
        return False
    return m1 - (m2 - m0) ** 2 / (8.0 * c2) >= 0.5 * c2


@kernel
def _grid_cell(i, b, t0, h, mg, rg, gr, gt, g, ws, cand, n) -> int:
    """The search of branch ``b`` around grid point ``i`` (at ``t0``; margins ``mg``, residuals ``rg`` of the grid,
    NaN residuals where the branch does not exist): an island or a hole centred there, then the cell
    ``[t0, t0 + h]``: :func:`_cell` where the branch exists at both ends and at their outer neighbours; where it
    ends in the cell, the piece from the fold to the grid point beyond the next (:func:`_from_fold`: the
    ``sqrt`` of the fold reaches into the next cell too, which is then left to it)."""
    m0, m1, mp = mg[i], mg[i + 1], mg[i - 1]
    if _peak(mp, m0, m1):
        n = _island(t0 - h, t0 + h, b, gr, gt, g, ws, cand, n)
    elif m0 >= 0.0 and mp >= 0.0 and m1 >= 0.0 and _peak(-mp, -m0, -m1):
        n = _hole(t0 - h, t0 + h, b, gr, gt, g, ws, cand, n)
    if m0 >= 0.0 and m1 >= 0.0:
        if mp < 0.0 or mg[i + 2] < 0.0:
            return n
        m2 = _bound(rg, i, h)
        v = _verdict(rg[i], rg[i + 1], h, m2) if m2 == m2 else -1
        if v == 1:
            return _root(t0, t0 + h, rg[i], rg[i + 1], b, gr, gt, g, ws, cand, n)
        return n if v == 0 else _cell(t0, t0 + h, rg[i], rg[i + 1], m2, 0.0, 1.0, False, b, gr, gt, g, ws, cand, n)
    if m0 >= 0.0:
        far = mp >= 0.0
        return _from_fold(t0 - h if far else t0, rg[i - 1] if far else rg[i], t0 + h, b, gr, gt, g, ws, cand, n)
    if m1 >= 0.0:
        far = mg[i + 2] >= 0.0
        return _from_fold(t0 + 2.0 * h if far else t0 + h, rg[i + 2] if far else rg[i + 1], t0, b, gr, gt, g, ws,
                          cand, n)
    return n


@kernel
def _search_candidates(tg, g, cand) -> int:
    """The candidate rows (``cand`` (K, 6)) of the target ``tg`` (16 floats); returns how many are filled. The grid
    has one point more on each side of the turn ``[-pi, pi]``, for the second differences at its ends."""
    gr = np.empty((3, 3))
    gt = _target_motion(tg, g, gr)
    ws = np.empty(_NCO + 5 * _STACK + _FOLD_CELLS + 1)
    if g[_KIND] != THREE_PARALLEL:
        _off_prepare(gr, gt, g, ws)
    grid = int(g[_GRID])
    h = 2.0 * math.pi / grid
    vals = np.empty((2 * _NB, grid + 3))  # margins, then residuals (NaN where the branch does not exist)
    for i in range(grid + 3):
        _eval(-math.pi + (i - 1) * h, gr, gt, g, ws, vals[:_NB, i], vals[_NB:, i])
        for b in range(_NB):
            if vals[b, i] < 0.0:
                vals[_NB + b, i] = math.nan
    n = 0
    for b in range(_NB):
        mg, rg = vals[b], vals[_NB + b]
        for i in range(1, grid + 1):
            if (mg[i - 1] >= 0.0 and mg[i] >= 0.0 and mg[i + 1] >= 0.0 and mg[i + 2] >= 0.0
                    and not _peak(-mg[i - 1], -mg[i], -mg[i + 1])):
                m2 = _bound(rg, i, h)  # the common cell, settled here when it holds no root
                if m2 == m2 and _verdict(rg[i], rg[i + 1], h, m2) == 0:
                    continue
            elif mg[i] < 0.0 and mg[i + 1] < 0.0 and not _peak(mg[i - 1], mg[i], mg[i + 1]):
                continue
            n = _grid_cell(i, b, -math.pi + (i - 1) * h, h, mg, rg, gr, gt, g, ws, cand, n)
    return n
