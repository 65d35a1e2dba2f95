"""The inverse kinematics kernels of a 6-DOF leg (:mod:`legkin.legs.sixdof`): every solution (the closed form's or
the one-dimensional search's candidates, each polished on the exact forward map and kept if it reproduces the
target), and the solution inside the limits nearest a reference; scalar and batch."""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_kernel, kernel
from ._ik_kernels import _in_limits_k, _near_k
from ._parallel_kernels import _parallel_candidates
from ._sixdof_kernels import _hip_candidates, _polish6, _valid_pose
from ._sixdof_layout import (
    _BAD_INPUT,
    _HI6,
    _JOINT_LIMIT,
    _KIND,
    _LO6,
    _NSOLS,
    _UNREACHABLE,
    HIP_SPHERICAL,
    THREE_PARALLEL,
)

_NAN = math.nan


@kernel(entry=True)
def _ik_all6_k(tg, g, ref, tol, out, info) -> int:
    """Every solution (rows of ``out`` (K, 6), NaN rows for absent ones) of the foot pose ``tg`` (16 floats): the
    candidates of the leg's structure (closed form or search), each polished (:func:`_polish6`) and kept if it
    reproduces ``tg`` to ``tol``, each angle moved to its 2 pi representative nearest ``ref``. ``info[0]``: on
    failure the least residual."""
    k = out.shape[0]
    for b in range(k):
        for j in range(6):
            out[b, j] = _NAN
    if not _valid_pose(tg):
        return _BAD_INPUT
    ws = np.empty((33 + k, 6))  # rows 0-31: the polish's work space, 32: the polished row, then the candidates
    cand, qb = ws[33:], ws[32]
    if g[_KIND] == HIP_SPHERICAL:
        n = _hip_candidates(tg, g, cand)
    elif g[_KIND] == THREE_PARALLEL:
        n = _parallel_candidates(tg, g, cand)
    else:
        n = 0
    best, found = math.inf, 0
    for b in range(n):
        for j in range(6):
            qb[j] = cand[b, j]
        res = _polish6(tg, g, qb, ws)
        if res <= tol:
            for j in range(6):
                out[b, j] = _near_k(qb[j], ref[j])
            found += 1
        elif res < best:
            best = res
    if found == 0:
        info[0], info[1] = best, 0.0
        return _UNREACHABLE
    return OK


@kernel(entry=True)
def _ik6_k(tg, g, ref, tol, out, info) -> int:
    """The solution of :func:`_ik_all6_k` inside the limits nearest ``ref`` (least sum of squared differences;
    ties to the earlier row). ``info``: the least residual, or the least limit violation (rad) and the count of
    solutions."""
    qa = np.empty((int(g[_NSOLS]), 6))
    status = _ik_all6_k(tg, g, ref, tol, qa, info)
    for j in range(6):
        out[j] = _NAN
    if status != OK:
        return status
    best, viol, nb = math.inf, math.inf, 0
    x = np.empty(6)
    for b in range(qa.shape[0]):
        if not np.isfinite(qa[b, 0]):
            continue
        nb += 1
        worst, inside = 0.0, True
        for j in range(6):
            x[j], m = _in_limits_k(qa[b, j], ref[j], g[_LO6 + j], g[_HI6 + j])
            worst = max(worst, m)
            inside = inside and np.isfinite(x[j])
        viol = min(viol, worst)
        if not inside:
            continue
        cost = 0.0
        for j in range(6):
            cost += (x[j] - ref[j]) ** 2
        if cost < best:
            best = cost
            for j in range(6):
                out[j] = x[j]
    if best == math.inf:
        info[0], info[1] = viol, nb
        return _JOINT_LIMIT
    return OK


@batch_kernel(rows="tg ref out status info", min_parallel=256)
def _ik_all6_batch(tg, g, ref, tol, out, status, info) -> None:
    n, m = tg.shape[0], ref.shape[0]
    for i in range(n):
        status[i] = _ik_all6_k(tg[i], g, ref[i if m > 1 else i - i], tol, out[i], info[i])


@batch_kernel(rows="tg ref out status info", min_parallel=256)
def _ik6_batch(tg, g, ref, tol, out, status, info) -> None:
    n, m = tg.shape[0], ref.shape[0]
    for i in range(n):
        status[i] = _ik6_k(tg[i], g, ref[i if m > 1 else i - i], tol, out[i], info[i])
