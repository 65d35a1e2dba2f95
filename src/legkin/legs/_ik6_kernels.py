"""The inverse kinematics kernels of a 6-DOF leg (:mod:`legkin.legs.sixdof`): every solution (the closed form's or
the one-dimensional search's candidates, each checked on the exact forward map, polished where that misses 1e-13,
and kept if it reproduces the target), and the solution inside the limits nearest a reference (the closed form
builds only its branches inside the limits); scalar and batch, a batch allocating its work arrays once."""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_kernel, kernel
from .._rotations import wrap_k
from ._ik_kernels import _in_limits_k, _near_k
from ._search_kernels import _search_candidates
from ._sixdof_kernels import _hip_candidates, _polish6, _valid_pose
from ._sixdof_layout import (
    _BAD_INPUT,
    _HI6,
    _JOINT_LIMIT,
    _KIND,
    _LO6,
    _NSOLS,
    _QREF,
    _UNREACHABLE,
    HIP_SPHERICAL,
    IK_TOL,
    LIMIT_SLACK6,
    POLISH_BELOW6,
)

_NAN = math.nan


#: The candidate rows a search may hold: twice the K rows of ``ik_all``. A root can be found twice (by two cells, or
#: as two roots of a near-tangent pair that polish to one solution), and a list of K candidates once lost the 17th,
#: a distinct solution (g1, ``legkin check g1 --random-seed 7 --samples 100000``).
_CAND_ROWS = 2
#: Two polished rows closer than this in every angle (rad, modulo 2 pi) are one solution: the polish lands within
#: ~1e-15 rad of a solution, and two distinct solutions this close make the same pose to far below ``IK_TOL``.
_SAME_ROW = 1e-9
#: A row reproducing the pose to no better than this (``_polish6``'s residual: m and rad) while another reproduces
#: it to this is a least-squares point of its branch, not a solution, and is dropped (``tol`` keeps a target within
#: it of the reachable set solvable, not a pose already reached). Exact rows land at <= 1e-13 (the sweep's worst,
#: g1); alexander's stretched-knee row (``--random-seed 17 --samples 100000``) reached 7.7e-9.
EXACT6 = 1e-10


@kernel
def _work6(g, extra):
    """The work arrays of :func:`_ik6_k` and :func:`_ik_all6_k` for the leg ``g``, allocated once per batch (not once
    per target): ``(work, cost)``, ``work`` (36 + 2 k, 6) (:func:`_views`) and ``cost`` (2 k + ``extra``,): the
    candidates' costs, then their errors (:func:`_candidates`); ``k`` = :data:`_CAND_ROWS` times the rows of
    ``ik_all``."""
    k = _CAND_ROWS * int(g[_NSOLS])
    return np.empty((36 + 2 * k, 6)), np.empty(2 * k + extra)


@kernel(inline=True)
def _views(work, cost, g):
    """The parts of ``work`` and ``cost`` (:func:`_work6`; slices, no copy): the polish's work space and polished
    row ``ws`` (33, 6), a (3, 6) work array, the candidate rows ``cand`` (k, 6), their in-limit representatives
    ``lim`` (k, 6), their costs (k,) and their errors ``resid`` (k,)."""
    k = _CAND_ROWS * int(g[_NSOLS])
    return work[:33], work[33:36], work[36:36 + k], work[36 + k:36 + 2 * k], cost[:k], cost[k:2 * k]


@kernel
def _candidates(tg, g, ref, work, cost) -> int:
    """Every candidate row of the leg's structure into ``cand`` of :func:`_views`, its error in ``resid`` (the
    closed form's from its subproblems' cosines and sines, :func:`_hip_candidates`; inf for the search's, which
    are all polished); returns how many."""
    _, gr, cand, _, costs, resid = _views(work, cost, g)
    if g[_KIND] == HIP_SPHERICAL:
        return _hip_candidates(tg, g, ref, False, cand, costs, resid, gr)
    n = _search_candidates(tg, g, cand) if g[_KIND] != 0.0 else 0
    for b in range(n):
        resid[b] = math.inf
    return n


@kernel
def _listed(out, m, q) -> bool:
    """Whether ``q`` (6,) is one of the rows ``out[:m]`` to :data:`_SAME_ROW` in every angle, modulo 2 pi."""
    for i in range(m):
        same = True
        for j in range(6):
            same = same and abs(wrap_k(out[i, j] - q[j])) <= _SAME_ROW
        if same:
            return True
    return False


@kernel
def _ik_all6_k(tg, g, ref, tol, out, info, work, cost) -> int:
    """Every solution (rows of ``out`` (K, 6), NaN rows for absent ones) of the foot pose ``tg`` (16 floats): the
    candidates of the leg's structure (closed form or search), each checked (:func:`_candidates`) or polished and
    kept if it reproduces ``tg`` to ``tol``, each angle moved to its 2 pi representative nearest ``ref``. The closed
    form's rows keep their branch order; the search's are packed, a row polished onto an earlier one dropped
    (:func:`_listed`). Where a row reproduces ``tg`` to :data:`EXACT6`, the rows that do not are dropped.
    ``info[0]``: on failure the least residual. ``work``, ``cost``: :func:`_work6`."""
    k = out.shape[0]
    for b in range(k):
        for j in range(6):
            out[b, j] = _NAN
    if not _valid_pose(tg):
        return _BAD_INPUT
    ws, _, cand, _, kept, resid = _views(work, cost, g)
    qb = ws[32]
    n = _candidates(tg, g, ref, work, cost)
    packed = g[_KIND] != HIP_SPHERICAL
    best, found, least = math.inf, 0, math.inf
    for b in range(n):
        for j in range(6):
            qb[j] = cand[b, j]
        res = resid[b] if resid[b] <= POLISH_BELOW6 else _polish6(tg, g, qb, ws)
        if not res <= tol:
            best = min(best, res)
            continue
        if packed and (found >= k or _listed(out, found, qb)):
            continue
        row = found if packed else b
        for j in range(6):
            out[row, j] = _near_k(qb[j], ref[j])
        kept[row], least = res, min(least, res)
        found += 1
    if found == 0:
        info[0], info[1] = best, 0.0
        return _UNREACHABLE
    if least <= EXACT6:
        _drop_inexact(out, kept, found if packed else n, packed)
    return OK


@kernel
def _drop_inexact(out, res, m, packed) -> None:
    """Drop the rows of ``out[:m]`` whose residual ``res`` exceeds :data:`EXACT6` (NaN rows; ``packed``: the rows
    after them move up)."""
    w = 0
    for i in range(m):
        if out[i, 0] != out[i, 0]:
            continue
        keep = res[i] <= EXACT6
        target = w if packed else i
        for j in range(6):
            out[target, j] = out[i, j] if keep else _NAN
        w += 1 if keep else 0
    if packed:
        for i in range(w, m):
            for j in range(6):
                out[i, j] = _NAN


@kernel
def _limited(q, ref, g, x) -> tuple[float, bool]:
    """``x`` = each angle of ``q`` at its 2 pi representative inside the limits nearest ``ref``; returns the cost
    ``|x - ref|^2`` and whether every angle has one (else the cost is the worst limit violation, rad)."""
    worst, inside = 0.0, True
    for j in range(6):
        x[j], m = _in_limits_k(q[j], ref[j], g[_LO6 + j], g[_HI6 + j])
        worst = max(worst, m)
        inside = inside and np.isfinite(x[j])
    if not inside:
        return worst, False
    cost = 0.0
    for j in range(6):
        cost += (x[j] - ref[j]) ** 2
    return cost, True


@kernel
def _clip_solution(tg, g, q, ref, tol, out, ws) -> bool:
    """A solution ``q`` a hair outside the limits (a target rounded to float32 near a limit): each angle at its 2 pi
    representative nearest ``ref``, clipped onto the limits, into ``out``, the other joints re-solved by the polish
    with the clipped ones fixed; True if that reproduces ``tg`` to ``tol`` (the target is then within ``tol`` of the
    in-limit reachable set), else ``out`` is NaN."""
    fixed = 0
    for j in range(6):
        lo, hi = g[_LO6 + j], g[_HI6 + j]
        x = _near_k(q[j], min(max(ref[j], lo), hi))
        out[j] = min(max(x, lo), hi)
        fixed |= (out[j] != x) << j
    if _polish6(tg, g, out, ws, fixed) <= tol and _limited(out, ref, g, ws[29])[1]:
        return True
    for j in range(6):
        out[j] = _NAN
    return False


@kernel(inline=True)
def _ranked(tg, g, ref, work, cost) -> int:
    """The candidates inside the limits, for :func:`_ik6_k`: their representatives inside the limits nearest
    ``ref`` in ``lim`` of :func:`_views` and their costs ``|q - ref|^2`` in ``cost`` (inf for a candidate outside
    them); returns the count of rows. The closed form builds only the branches inside the limits (their rows go
    straight to ``lim``); the search's candidates all go to ``cand``, each moved inside the limits
    (:func:`_limited`)."""
    _, gr, cand, lim, costs, resid = _views(work, cost, g)
    if g[_KIND] == HIP_SPHERICAL:
        return _hip_candidates(tg, g, ref, True, lim, costs, resid, gr)
    n = _candidates(tg, g, ref, work, cost)
    for b in range(n):
        c, inside = _limited(cand[b], ref, g, lim[b])
        costs[b] = c if inside else math.inf
    return n


@kernel(inline=True)
def _ik6_k(tg, g, ref, tol, out, info, work, cost) -> int:
    """The solution inside the limits nearest ``ref`` (least sum of squared differences): the candidates inside the
    limits (:func:`_ranked`) are checked or polished in the order of that cost until one
    reproduces ``tg`` to ``tol`` (its angles then moved inside the limits again), so a single answer costs one
    check, not one per candidate (a row reproducing ``tg`` to ``tol`` but not to :data:`EXACT6` only when no later
    one does); when none does, :func:`_polished_fallback` on every candidate. ``info``: the
    least residual, or the least limit violation (rad) and the count of solutions. ``work``, ``cost``:
    :func:`_work6`."""
    for j in range(6):
        out[j] = _NAN
    if not _valid_pose(tg):
        return _BAD_INPUT
    ws, _, _, lim, costs, resid = _views(work, cost, g)
    qb = ws[32]
    n = _ranked(tg, g, ref, work, cost)
    best, inexact = math.inf, -1
    for _ in range(n):  # the in-limit candidates, cheapest first
        i = 0
        for b in range(1, n):
            if costs[b] < costs[i]:
                i = b
        if costs[i] == math.inf:
            break
        costs[i] = math.inf
        for j in range(6):
            qb[j] = lim[i, j]
        checked = resid[i] <= POLISH_BELOW6
        res = resid[i] if checked else _polish6(tg, g, qb, ws)
        if res <= tol and checked:  # the row as built: its angles are inside the limits already
            for j in range(6):
                out[j] = qb[j]
            return OK
        if res <= tol:
            c, inside = _limited(qb, ref, g, out)
            if inside and res <= EXACT6:
                return OK
            inexact = i if inside and inexact < 0 else inexact  # kept unless an exact row follows (EXACT6)
            for j in range(6):
                out[j] = _NAN
        best = min(best, res)
    if inexact >= 0:
        for j in range(6):
            qb[j] = lim[inexact, j]
        _polish6(tg, g, qb, ws)
        _limited(qb, ref, g, out)
        return OK
    return _polished_fallback(tg, g, ref, tol, n, best, out, info, work, cost)


@kernel
def _polished_fallback(tg, g, ref, tol, n, best, out, info, work, cost) -> int:
    """:func:`_ik6_k` when no in-limit candidate polished to a solution: every candidate (the closed form's built
    again, all of them; the search's ``n`` as they are) polished first, then moved inside the limits (a candidate
    outside them can polish to an in-limit solution near a stretched knee; one a hair outside, up to
    :data:`LIMIT_SLACK6`, is clipped onto them, :func:`_clip_solution`); the in-limit solution nearest ``ref``
    wins. Else ``info``: the least limit violation (rad) and the count of solutions, or the least residual."""
    ws, _, cand, lim, _, _ = _views(work, cost, g)
    qb = ws[32]
    if g[_KIND] == HIP_SPHERICAL:
        n = _candidates(tg, g, ref, work, cost)
    viol, nb, best_in = math.inf, 0, math.inf
    for b in range(n):
        for j in range(6):
            qb[j] = cand[b, j]
        res = _polish6(tg, g, qb, ws)
        if not res <= tol:
            best = min(best, res)
            continue
        nb += 1
        c, inside = _limited(qb, ref, g, lim[b])
        if not inside and c <= LIMIT_SLACK6 and _clip_solution(tg, g, qb, ref, tol, lim[b], ws):
            c, inside = 0.0, True
            for j in range(6):
                c += (lim[b, j] - ref[j]) ** 2
        if inside and c < best_in:
            best_in = c
            for j in range(6):
                out[j] = lim[b, j]
        elif not inside:
            viol = min(viol, c)
    if best_in < math.inf:
        return OK
    if nb == 0:
        info[0], info[1] = best, 0.0
        return _UNREACHABLE
    info[0], info[1] = viol, nb
    return _JOINT_LIMIT


@kernel
def _one(t, g, out, solve_all) -> int:
    """The single call's fast path of :meth:`Leg6.ik` (``solve_all`` False, ``out`` (6,)) and :meth:`Leg6.ik_all`
    (``out`` (K, 6)): one pose ``t`` (4, 4) in any memory layout, the leg's ``q_ref`` and the default ``IK_TOL``;
    ``_BAD_INPUT`` (the wrapper's full checks then say why) for a bad pose or a leg without an IK."""
    if g[_KIND] == 0.0:
        return _BAD_INPUT
    work, cost = _work6(g, 18)
    tg, info = cost[-18:-2], cost[-2:]
    for i in range(4):
        for j in range(4):
            tg[4 * i + j] = t[i, j]
    ref = g[_QREF:_QREF + 6]
    if solve_all:
        return _ik_all6_k(tg, g, ref, IK_TOL, out, info, work, cost)
    return _ik6_k(tg, g, ref, IK_TOL, out[0], info, work, cost)


@kernel(entry=True)
def _ik6_one(t, g, out) -> int:
    """:func:`_one` for :meth:`Leg6.ik`: ``out`` (1, 6)."""
    return _one(t, g, out, False)


@kernel(entry=True)
def _ik_all6_one(t, g, out) -> int:
    """:func:`_one` for :meth:`Leg6.ik_all`: ``out`` (K, 6)."""
    return _one(t, g, out, True)


@batch_kernel(rows="tg ref out status info", min_parallel=256)
def _ik_all6_batch(tg, g, ref, tol, out, status, info) -> None:
    n, m = tg.shape[0], ref.shape[0]
    work, cost = _work6(g, 0)
    for i in range(n):
        status[i] = _ik_all6_k(tg[i], g, ref[i if m > 1 else i - i], tol, out[i], info[i], work, cost)


@batch_kernel(rows="tg ref out status info", min_parallel=256)
def _ik6_batch(tg, g, ref, tol, out, status, info) -> None:
    n, m = tg.shape[0], ref.shape[0]
    work, cost = _work6(g, 0)
    for i in range(n):
        status[i] = _ik6_k(tg[i], g, ref[i if m > 1 else i - i], tol, out[i], info[i], work, cost)
