"""The radial IK (``method="radial"``): gamma and beta in closed form, theta from a bracketed 1-D Newton."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .._kernels import as_rows, batch_kernel, kernel
from .._rotations import wrap_k
from ._common import _LIMITS, _SOLVED, _UNREACHABLE, _k_clip, _k_max, _k_min, _k_phase
from .frames import _k_fk
from .geometry import _LIMIT_ROUNDING, ABAD_LIMIT, THETA_MAX, THETA_MIN, TYRE_THICKNESS
from .linkage import _closed_form, _constants, _kconst
from .radial_roots import _k_lower_bound, _k_radial_extremum, _k_radial_newton
from .rim import _k_plane


@lru_cache(maxsize=32)
def _arc_table(R: float, seed: bool, nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """``|c(theta, alpha)|^2`` and its theta-derivative on a theta grid, as a matrix for all alpha at once.

    For an arc ``c = ctr + e v`` (``v = ref - ctr``, made unit for the three-arc rim; ``rim._k_plane``),
    ``|c|^2 = A + |e|^2 V + 2 Re(W e)`` with ``A = |ctr|^2``, ``V = |v|^2``, ``W = conj(ctr) v``: functions
    of theta alone, tabulated once per geometry. Returns ``grid`` (K,) and ``table`` (9, 2K) such that
    the target's coefficient row ``[u, u |e|^2, 2 u Re e, -2 u Im e, l, l |e|^2, 2 l Re e, -2 l Im e, -r^2]``
    (u = 1 on the upper rim, l = 1 - u; built in :func:`_k_ik_radial`) ``@ table`` is ``[f(grid), f'(grid)]``,
    ``f = |c|^2 - r^2``.
    """
    grid = np.linspace(THETA_MIN, THETA_MAX, nodes)
    coef = _arc_terms(grid, R, seed)
    table = np.zeros((9, 2 * nodes))
    for kind in range(2):
        for row in range(4):
            table[4 * kind + row, :nodes] = coef[kind, row]
            table[4 * kind + row, nodes:] = coef[kind, row + 4]
    table[8, :nodes] = 1.0
    grid.setflags(write=False)
    table.setflags(write=False)
    return grid, table


def _arc_terms(theta: np.ndarray, R: float, seed: bool) -> np.ndarray:
    """(2 arc kinds, 8, ...): A, V, Re W, Im W and their theta-derivatives (see :func:`_arc_table`)."""
    pts, der = _closed_form(theta, _constants(R), R + TYRE_THICKNESS, True, full=seed)
    assert der is not None
    rows = []
    for ctr_name, ref_name in ((("U", "J"), ("O_r", "G")) if seed else (("U", "F"), ("L", "G"))):
        ctr, dctr = pts[ctr_name], der[ctr_name]
        v, dv = pts[ref_name] - ctr, der[ref_name] - dctr
        if seed:
            nv = np.abs(v)
            dnv = (np.conj(v) * dv).real / nv
            v, dv = v / nv, (dv - v * dnv / nv) / nv
        W, dW = np.conj(ctr) * v, np.conj(dctr) * v + np.conj(ctr) * dv
        rows.append([np.abs(ctr) ** 2, np.abs(v) ** 2, W.real, W.imag,
                     2 * (np.conj(ctr) * dctr).real, 2 * (np.conj(v) * dv).real, dW.real, dW.imag])
    return np.array(rows)


#: Nodes of the theta grid that brackets the roots of the radial equation (8.9 deg cells).
_RADIAL_NODES = 17
#: Sub-cells per cell of the fine coefficient table that refines the Newton start (0.14 deg).
_RADIAL_SUB = 64


@lru_cache(maxsize=16)
def _radial_table(R: float, seed: bool):
    """The radial IK's tables: :func:`_arc_table` on a coarse and a fine grid, and curvature bounds.

    Returns ``grid`` (K,), ``table`` (9, 2K) (coarse: brackets every root of every target with one small
    matrix product), ``m2`` (2, 3, K - 1): bounds of ``|A''|, |V''|, |W''|`` in each cell (finite
    differences of the exact first derivatives on 256 sub-intervals per cell, times 1.25), so
    ``|f''| <= m2[k, 0, j] + |e|^2 m2[k, 1, j] + 2 |e| m2[k, 2, j]`` in cell j for arc kind k; and ``fine``
    (Kf,), ``fine_rows`` (2 Kf, 9) (the fine table transposed: rows are gathered per root to refine its
    start).
    """
    grid, table = _arc_table(R, seed, _RADIAL_NODES)
    k = grid.size
    per = 256
    fine = np.linspace(THETA_MIN, THETA_MAX, (k - 1) * per + 1)
    d = _arc_terms(fine, R, seed)[:, 4:]
    d2 = np.abs(np.diff(d, axis=-1)) / (fine[1] - fine[0])  # (2, 4, fine intervals): A'', V'', Re W'', Im W''
    d2 = d2.reshape(2, 4, k - 1, per).max(axis=-1)
    m2 = 1.25 * np.stack([d2[:, 0], d2[:, 1], np.hypot(d2[:, 2], d2[:, 3])], 1)  # (2, 3, cells)
    fine, fine_table = _arc_table(R, seed, (k - 1) * _RADIAL_SUB + 1)
    fine_rows = np.ascontiguousarray(fine_table.T)
    for arr in (m2, fine_rows):
        arr.setflags(write=False)
    return grid, table, m2, fine, fine_rows


#: Most roots of one target kept by the radial kernel (16 cells, two per split cell, the ends, doubles).
_RADIAL_CAP = 64


@kernel
def _k_radial_brackets(grid, f, g, m2, kind, ee, ea, ftol, upper, right, e, seed, K, KC, r2, max_iter, jobs, xth):
    """The roots' brackets on the grid for one target (``f``, ``g``: f and f' at the nodes).

    Into ``jobs`` (rows ``(lo, hi, flo, fhi, glo, ghi, curvature bound, start guess)``): every cell where f
    changes sign, then the two halves of every cell split at an extremum where f reaches 0
    (:func:`_k_radial_extremum`); into ``xth``: the roots found without Newton (an end of [17, 160] deg with
    ``|f| <= ftol``, double roots at an extremum). Returns (brackets, roots without Newton, split cells,
    iterations)."""
    K_ = grid.shape[0]
    h = grid[1] - grid[0]
    nj = 0
    for k in range(K_ - 1):
        if (f[k] > 0) != (f[k + 1] > 0):
            M = m2[kind, 0, k] + ee * m2[kind, 1, k] + 2.0 * ea * m2[kind, 2, k]
            jobs[nj, 0], jobs[nj, 1], jobs[nj, 2], jobs[nj, 3] = grid[k], grid[k + 1], f[k], f[k + 1]
            jobs[nj, 4], jobs[nj, 5], jobs[nj, 6], jobs[nj, 7] = g[k], g[k + 1], M, math.nan
            nj += 1
    its = 0
    nx = 0
    for end in range(2):
        col, inward, cell = (0, 1.0, 0) if end == 0 else (K_ - 1, -1.0, K_ - 2)
        # An end of [17, 160] deg with |f| <= ftol is a root within rounding (issue 15; see _ik_radial).
        near = abs(f[col]) <= ftol
        same_side = (inward * g[col] > 0) == (f[col] > 0)
        change = (f[cell] > 0) != (f[cell + 1] > 0)
        if near and (not change or same_side):
            xth[nx] = grid[col]
            nx += 1
    split_lo = np.empty((K_, 8))
    split_hi = np.empty((K_, 8))
    ns = 0
    for k in range(K_ - 1):
        if ((g[k] > 0) != (g[k + 1] > 0)) and ((f[k] > 0) == (f[k + 1] > 0)):  # extremum, no sign change
            sig = 1.0 if f[k] > 0 else -1.0
            Fa, Fb, Ga, Gb = sig * f[k], sig * f[k + 1], sig * g[k], sig * g[k + 1]
            M = m2[kind, 0, k] + ee * m2[kind, 1, k] + 2.0 * ea * m2[kind, 2, k]
            # |f| falls into the cell from both ends and the curvature bound allows it to reach 0
            if Ga < 0 and Gb > 0 and _k_lower_bound(Fa, Fb, Ga, Gb, h, M) <= ftol:
                th_e, f_e, g_e, status, k_e, its_e = _k_radial_extremum(
                    grid[k], grid[k + 1], f[k], f[k + 1], g[k], g[k + 1], M, upper, right, e, seed, K, KC, r2,
                    ftol, max_iter)
                its += its_e
                if status == 2:
                    xth[nx] = th_e
                    nx += 1
                elif status == 1:
                    # start both roots from the parabola f_s + f'_s d + k d^2 / 2 through the split point
                    sq = math.sqrt(_k_max(g_e * g_e - 2 * k_e * f_e, 0.0))
                    dd1, dd2 = (-g_e - sq) / k_e, (-g_e + sq) / k_e
                    row = split_lo[ns]
                    row[0], row[1], row[2], row[3] = grid[k], th_e, f[k], f_e
                    row[4], row[5], row[6], row[7] = g[k], g_e, M, th_e + _k_min(dd1, dd2)
                    row = split_hi[ns]
                    row[0], row[1], row[2], row[3] = th_e, grid[k + 1], f_e, f[k + 1]
                    row[4], row[5], row[6], row[7] = g_e, g[k + 1], M, th_e + _k_max(dd1, dd2)
                    ns += 1
    for half in (split_lo, split_hi):  # element by element: a row assignment compiles numba's shape-error text
        for i in range(ns):
            for c in range(8):
                jobs[nj, c] = half[i, c]
            nj += 1
    return nj, nx, ns, its


@kernel
def _k_radial_roots(jobs, nj, xth, nx, ns, coef, fine, fine_rows, upper, right, e, seed, K, KC, r2, max_iter, rth,
                    rz):
    """The roots of one target into ``rth`` (theta) and ``rz`` (its contact point before the beta rotation):
    :func:`_k_radial_newton` on every bracket of :func:`_k_radial_brackets`, then the roots found without
    Newton (contact point from the closed form); sorted by theta and deduplicated (1e-10 rad) when there are
    such roots or split cells. Returns (roots, iterations)."""
    its = 0
    nr = 0
    for j in range(nj):
        root, zr, its_n, conv = _k_radial_newton(jobs[j, 0], jobs[j, 1], jobs[j, 2], jobs[j, 3], jobs[j, 4],
                                                 jobs[j, 5], jobs[j, 7], coef, fine, fine_rows, upper, right, e,
                                                 seed, K, KC, r2, jobs[j, 6], max_iter)
        its += its_n
        if conv and nr < _RADIAL_CAP:
            rth[nr], rz[nr] = root, zr
            nr += 1
    for i in range(nx):  # roots without a Newton evaluation: the contact point from the closed form
        if nr < _RADIAL_CAP:
            y, _dy = _k_plane(xth[i], upper, right, e, seed, K, KC, False, True)
            rth[nr], rz[nr] = xth[i], y
            nr += 1
    if nx > 0 or ns > 0:  # stable sort by theta, then one root found twice is listed once
        for i in range(1, nr):
            tv, zv = rth[i], rz[i]
            j = i - 1
            while j >= 0 and rth[j] > tv:
                rth[j + 1], rz[j + 1] = rth[j], rz[j]
                j -= 1
            rth[j + 1], rz[j + 1] = tv, zv
        keep = 1 if nr > 0 else 0
        prev = rth[0] if nr > 0 else 0.0
        for i in range(1, nr):
            cur = rth[i]
            if not (abs(cur - prev) <= 1e-10):
                rth[keep], rz[keep] = cur, rz[i]
                keep += 1
            prev = cur
        nr = keep
    return nr, its


@kernel
def _k_radial_pick(rth, rz, nr, tau, gamma1, gamma2, two, q0, use_q0, limits, q, sols):
    """The solutions of one target into ``sols`` (S, 3) (NaN-padded, as many as fit) and the answer into ``q``.

    Each root gives ``(theta, arg(tau conj(i c)), gamma1)`` on the branch ``y_L <= 0`` and, if ``two``,
    ``(theta, arg(conj(tau) conj(i c)), gamma2)`` on ``y_L > 0``, listed in that order. The answer: the
    first usable one (finite; with ``limits`` gamma inside the ABAD limits within rounding, clipped onto
    them), or with ``use_q0`` the usable one nearest ``q0`` (wrapped angle differences), its beta (and,
    without limits, gamma) shifted by multiples of 2 pi to lie within pi of ``q0``'s. Without a usable one
    ``q`` is the first solution. Returns (answer index or -1, solutions).
    """
    nsol = nr * (2 if two else 1)
    S = sols.shape[0]
    for i in range(S):
        sols[i, 0], sols[i, 1], sols[i, 2] = math.nan, math.nan, math.nan
    best = -1
    best_d2 = math.inf
    sq0 = np.empty(3)
    for i in range(nsol):
        r = i if i < nr else i - nr
        ccz = rz[r].conjugate() * -1j
        sq0[0] = rth[r]
        if i < nr:
            sq0[1], sq0[2] = _k_phase(tau * ccz), gamma1
        else:
            sq0[1], sq0[2] = _k_phase(tau.conjugate() * ccz), gamma2
        usable = sq0[0] == sq0[0]
        if limits:  # the ABAD joint's URDF limits; within rounding of a limit counts as on it
            usable = usable and abs(sq0[2]) <= ABAD_LIMIT + _LIMIT_ROUNDING
            if usable:
                sq0[2] = _k_clip(sq0[2], -ABAD_LIMIT, ABAD_LIMIT)
        if i < S:
            sols[i, 0], sols[i, 1], sols[i, 2] = sq0[0], sq0[1], sq0[2]
        if i == 0 or (usable and not use_q0 and best < 0):
            q[0], q[1], q[2] = sq0[0], sq0[1], sq0[2]  # the first: kept for the out-of-limits answer
        if usable:
            if not use_q0:
                if best < 0:
                    best = i
            else:
                dist = (sq0[0] - q0[0]) ** 2
                w1 = wrap_k(sq0[1] - q0[1])
                w2 = wrap_k(sq0[2] - q0[2])
                dist += w1 * w1 + w2 * w2
                if dist < best_d2 or best < 0:
                    best, best_d2 = i, dist
                    q[0], q[1], q[2] = sq0[0], q0[1] + w1, (q0[2] + w2 if not limits else sq0[2])
    return best, nsol


@kernel(entry=True)
def _k_ik_radial(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows, tol,
                 max_iter, q0, use_q0, limits, q, sols):
    """The radial IK for one target (:func:`_ik_radial` states the math) into ``q`` (3,) and ``sols``
    (S, 3) (NaN-padded, as many as fit): the out-of-plane part in closed form, f and f' on the grid from the
    table, :func:`_k_radial_brackets`, :func:`_k_radial_roots`, :func:`_k_radial_pick`; the answer checked
    by the FK. Returns (iterations, error, reason, roots, solutions)."""
    K_ = grid.shape[0]
    d0, d1, d2 = tgt[0] - o0, tgt[1] - o1, tgt[2] - o2
    x_L = -d0
    m = complex(s * d1, d2)
    yabs = math.sqrt(_k_max(m.real * m.real + m.imag * m.imag - a * a, 0.0))
    r2 = x_L * x_L + yabs * yabs
    ftol = 2.0 * math.sqrt(r2) * tol
    coef = np.zeros(9)
    base = 0 if upper else 4
    ee = e.real * e.real + e.imag * e.imag
    coef[base] = 1.0
    coef[base + 1] = ee
    coef[base + 2] = 2.0 * e.real
    coef[base + 3] = -2.0 * e.imag
    coef[8] = -r2
    f = np.empty(K_)
    g = np.empty(K_)
    for k in range(K_):
        fk, gk = 0.0, 0.0
        for j in range(9):
            fk += coef[j] * table[j, k]
            gk += coef[j] * table[j, K_ + k]
        f[k], g[k] = fk, gk
    jobs = np.empty((3 * K_, 8))
    xth = np.empty(K_ + 2)
    nj, nx, ns, its = _k_radial_brackets(grid, f, g, m2, 0 if upper else 1, ee, math.sqrt(ee), ftol, upper, right,
                                         e, seed, K, KC, r2, max_iter, jobs, xth)
    rth = np.empty(_RADIAL_CAP)
    rz = np.empty(_RADIAL_CAP, dtype=np.complex128)
    nr, its_r = _k_radial_roots(jobs, nj, xth, nx, ns, coef, fine, fine_rows, upper, right, e, seed, K, KC, r2,
                                max_iter, rth, rz)
    its += its_r
    # solutions: branch y_L <= 0 by increasing theta, then branch y_L > 0
    tau = complex(x_L, -yabs)  # exp(i (beta + pi/2)) c = tau on the branch y_L <= 0
    gamma1 = _k_phase(m * complex(a, yabs))
    gamma2 = _k_phase(m * complex(a, -yabs))
    best, nsol = _k_radial_pick(rth, rz, nr, tau, gamma1, gamma2, yabs > 0, q0, use_q0, limits, q, sols)
    if best >= 0:
        reason = _SOLVED
    elif nr > 0:  # reachable only outside the ABAD limits: q is the first solution, for the error message
        reason = _LIMITS
    else:  # no root: the grid node of smallest |f|, as the point reached
        kb = 0
        for k in range(1, K_):
            if abs(f[k]) < abs(f[kb]):
                kb = k
        cz, _dz = _k_plane(grid[kb], upper, right, e, seed, K, KC, False, True)
        q[0], q[1], q[2] = grid[kb], _k_phase(tau * cz.conjugate() * -1j), gamma1
        reason = _UNREACHABLE
    p = np.empty(3)
    _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, p, p)
    err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)
    if reason == _SOLVED and not (err <= tol):
        reason = _UNREACHABLE  # (does not happen: each root is checked against tol by the FK)
    return its, err, reason, nr, nsol


@batch_kernel(rows="tgt upper right e a q0 q sols its err reason nsol", min_parallel=256)
def _k_ik_radial_batch(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows, tol,
                       max_iter, q0, use_q0, limits, q, sols, its, err, reason, nsol):
    """:func:`_k_ik_radial` over targets (n, 3) (q0 (n, 3) or (1, 3) unused) into q, sols, its, err, reason,
    nsol (solutions found per target, possibly more than sols holds)."""
    for i in range(tgt.shape[0]):
        iq0 = i if use_q0 else i - i  # (same integer type as i)
        its[i], err[i], reason[i], _nr, nsol[i] = _k_ik_radial(
            tgt[i], upper[i], right[i], e[i], a[i], seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows,
            tol, max_iter, q0[iq0], use_q0, limits, q[i], sols[i])


def _ik_radial(target, ctx, tol, max_iter, q0, limits=True):
    """The radial IK: gamma and beta in closed form, theta from the 1-D equation ``|c(theta, alpha)| = r``.

    Not in the seed, which iterates Gauss-Newton on all three unknowns with a forward-difference Jacobian
    (seed 2.2-2.3). This uses the structure of the map q -> contact point:

    * For fixed (alpha, w) the contact point is a fixed point of one rim link; in the leg plane {L} it is
      ``exp(i (beta + pi/2)) c(theta, alpha)`` (:func:`rim_point`; ``c`` depends on theta alone), at
      lateral coordinate w.
    * gamma rotates the module about z_M, the robot's x axis through the module origin o, so the target's
      coordinate along that axis and its distance from it do not depend on gamma. With ``d = target - o``
      and ``a = d_wheel + s w`` (s = +1 left, -1 right), the contact point in {M} before the ABAD rotation
      is ``(a, y_L, -+x_L)``, so ``x_L = -d_x`` and ``a^2 + y_L^2 = d_y^2 + d_z^2``: ``y_L = -+sqrt(d_y^2 +
      d_z^2 - a^2)`` (two branches; clipped at 0 if negative: then the FK check decides), and
      ``gamma = arg((s d_y + i d_z) / (a + i y_L))``.
    * beta rotates the leg plane about the motor axis O, so ``r = |x_L + i y_L|`` must equal ``|c|``, which
      depends on theta alone. The equation solved is ``f(theta) = |c(theta, alpha)|^2 - r^2 = 0`` on
      [17 deg, 160 deg], with the exact ``f' = 2 Re(conj(c) dc/dtheta)`` (the closed form's forward-mode
      derivatives, as in :func:`~legkin.wheel_leg.jacobian`). Then ``beta = arg((x_L + i y_L) / c) - pi/2``.

    Roots: f and f' on a 17-node grid come from tabulated theta-coefficients (:func:`_arc_table`: one small matrix
    product for the batch). Every cell where f changes sign holds a root, found by
    :func:`.radial_roots._k_radial_newton` (usually one evaluation of the closed form, from a start refined on a
    fine table). A cell where f keeps its sign while f' changes sign holds an extremum of f: unless a curvature
    bound shows that f stays above ``2 r tol`` in it, :func:`.radial_roots._k_radial_extremum` decides whether f
    reaches 0 there (then the cell is split into two brackets, or the extremum taken as a double root if ``|f| <= 2
    r tol`` at it). An end of the range with ``|f| <= 2 r tol`` is a root too. This finds every root if each cell
    holds at most one extremum of f. For the default geometry ``|c|^2`` has at most one extremum in theta for any
    alpha, both rims (checked on 1441 alpha x 20001 theta). At alpha = +-163 deg the contact point is the crank
    hinge B, ``|c| = R`` for every theta: f is rounding noise, every theta solves the IK and the grid reports many
    roots.

    Returns ``(q, iterations, error, converged, solutions, reason)``; ``solutions`` (n, S, 3), NaN-padded:
    for each root by increasing theta the branch ``y_L <= 0``, then the same roots on the branch ``y_L > 0``
    (absent when ``y_L = 0``). The answer is the first solution in that order whose gamma is inside the ABAD
    joint's URDF limits ``[-pi/2, pi/2]`` (``limits=False``: the first), or with ``q0`` the usable solution
    nearest ``q0``. It is checked with the forward kinematics (:func:`_k_fk`): converged means
    ``|fk(q) - target| <= tol``. ``reason`` per target: 0 solved, 1 no root (out of reach),
    2 every root outside the ABAD limits. A target without a root gets, as its (unconverged) q, the grid
    node of smallest ``|f|`` with beta, gamma from the branch ``y_L <= 0``; one reachable only outside the
    limits, its first solution.
    """
    max_iter = 60 if max_iter is None else max_iter
    n = target.shape[0]
    grid, table, m2, fine, fine_rows = _radial_table(ctx.geo.R, ctx.seed)
    K, KC = _kconst(ctx.c.R, ctx.geo.R + TYRE_THICKNESS)
    upper, right, e, a = ctx.items((n,))
    tgt = as_rows(target, 3)
    q0a = _NO_Q0 if q0 is None else as_rows(q0, 3)
    o = ctx.origin
    q = np.empty((n, 3))
    its, reason, nsol = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    err = np.empty(n)
    cap = _RADIAL_SOLS
    sols = np.empty((n, cap, 3))
    args = (ctx.seed, K, KC, ctx.s, float(o[0]), float(o[1]), float(o[2]), grid, table, m2, fine, fine_rows, tol,
            max_iter)
    _k_ik_radial_batch(tgt, upper, right, e, a, *args, q0a, q0 is not None, bool(limits), q, sols, its, err,
                       reason, nsol)
    S = int(nsol.max()) if n else 0
    if S > cap:  # a target with more solutions than the first pass kept: solve those again, keeping all
        big = np.flatnonzero(nsol > cap)
        wide = np.full((n, S, 3), np.nan)
        wide[:, :cap] = sols
        qb, sb = np.empty((big.size, 3)), np.empty((big.size, S, 3))
        tmp = [np.empty(big.size, dtype=np.int64) for _ in range(3)]
        _k_ik_radial_batch(tgt[big], upper[big], right[big], e[big], a[big], *args,
                           q0a if q0 is None else q0a[big], q0 is not None, bool(limits), qb, sb, tmp[0],
                           np.empty(big.size), tmp[1], tmp[2])
        wide[big] = sb
        sols = wide
    return q, its, err, reason == _SOLVED, sols[:, :S], reason


#: Solutions per target kept by the first pass of the radial batch (more: that target is solved again).
_RADIAL_SOLS = 8
_NO_Q0 = np.zeros((1, 3))
