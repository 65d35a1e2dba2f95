"""The radial IK (``method="radial"``): gamma and beta in closed form, theta from a bracketed 1-D Newton."""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .._kernels import as_rows, kernel, prange
from ._common import _LIMITS, _SOLVED, _UNREACHABLE, _k_clip, _k_max, _k_min, _k_phase, _loop
from .frames import _k_fk
from .geometry import _LIMIT_ROUNDING, ABAD_LIMIT, FOOT_OFFSET, THETA_MAX, THETA_MIN
from .linkage import _closed_form, _constants, _kconst
from .rim import _k_plane, _Sel


@lru_cache(maxsize=32)
def _arc_table(R: float, seed: bool, nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """``|c(theta, alpha)|^2`` and its theta-derivative on a theta grid, as a matrix for all alpha at once.

    For an arc ``c = ctr + e v`` (``v = ref - ctr``, made unit for the seed rim; :func:`_plane`),
    ``|c|^2 = A + |e|^2 V + 2 Re(W e)`` with ``A = |ctr|^2``, ``V = |v|^2``, ``W = conj(ctr) v``: functions
    of theta alone, tabulated once per geometry. Returns ``grid`` (K,) and ``table`` (9, 2K) such that
    :func:`_arc_coefficients` ``@ table`` is ``[f(grid), f'(grid)]``, ``f = |c|^2 - r^2``.
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
    pts, der = _closed_form(theta, _constants(R), R + FOOT_OFFSET, True, full=seed)
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


def _arc_coefficients(sel: _Sel, r2) -> np.ndarray:
    """(n, 9) rows ``[u, u |e|^2, 2 u Re e, -2 u Im e, l, l |e|^2, 2 l Re e, -2 l Im e, -r^2]`` (u = 1 on the
    upper rim, l = 1 - u) that turn :func:`_arc_table`'s table into ``f, f'`` for each item."""
    e = sel.e
    ee = e.real * e.real + e.imag * e.imag
    coef = np.empty(e.shape + (9,))
    for base, on in ((0, sel.upper), (4, ~sel.upper)):
        w8 = on.astype(float)
        coef[..., base] = w8
        coef[..., base + 1] = w8 * ee
        coef[..., base + 2] = w8 * 2.0 * e.real
        coef[..., base + 3] = w8 * -2.0 * e.imag
    coef[..., 8] = -r2
    return coef



# ---------------------------------------------------------------- radial IK (method="radial")
#: Nodes of the theta grid that brackets the roots of the radial equation (8.9 deg cells).
_RADIAL_NODES = 17
#: Sub-cells per cell of the fine coefficient table that refines the Newton start (0.14 deg).
_RADIAL_SUB = 64
_EPS = float(np.finfo(float).eps)


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


@kernel
def _k_f_and_slope(theta, upper, right, e, seed, K, KC, r2):
    """``f = |c(theta)|^2 - r2`` and ``f' = 2 Re(conj(c) dc/dtheta)``, ``c`` the contact point in the leg plane
    (right halves unconjugated: same modulus), and ``c, dc``: the radial IK's only linkage evaluation."""
    y, dy = _k_plane(theta, upper, right, e, seed, K, KC, True, False)
    return y.real * y.real + y.imag * y.imag - r2, 2.0 * (y.real * dy.real + y.imag * dy.imag), y, dy




@kernel
def _k_lower_bound(Fa, Fb, Ga, Gb, h, M):
    """Lower bound of f on a cell of width h from its ends (f oriented positive there: Fa, Fb > 0; slopes
    Ga, Gb) and a bound M of |f''|: the larger of the Taylor bounds from the two ends,
    ``Fa + Ga t - M t^2/2`` and ``Fb - Gb (h - t) - M (h - t)^2/2``, at the t where they cross."""
    tc = _k_clip((Fa - Fb + Gb * h + M * h * h / 2) / (Gb - Ga + M * h), 0.0, h)
    if not math.isfinite(tc):
        tc = 0.5 * h
    return _k_max(Fa + Ga * tc - M * tc * tc / 2, Fb - Gb * (h - tc) - M * (h - tc) ** 2 / 2)


@kernel
def _k_hermite_root(h, flo, fhi, glo, ghi):
    """Root (offset from the lower end, in [0, h]) of the cubic Hermite model of f on a bracket of width h
    (values flo, fhi of opposite signs, slopes glo, ghi): four Newton steps on the cubic from the regula
    falsi point, clipped to the bracket."""
    df = fhi - flo
    c2 = (3 * df / h - 2 * glo - ghi) / h
    c3 = (glo + ghi - 2 * df / h) / (h * h)
    t = _k_clip(-flo / df, 0.0, 1.0) * h
    for _ in range(4):
        t = _k_clip(t - (flo + t * (glo + t * (c2 + t * c3))) / (glo + t * (2 * c2 + 3 * t * c3)), 0.0, h)
    return t


@kernel
def _k_radial_extremum(lo, hi, flo, fhi, glo, ghi, M, upper, right, e, seed, K, KC, r2, ftol, max_iter):
    """Decide whether f (of one sign at both ends of [lo, hi]) reaches 0 near the extremum inside.

    Regula falsi (Illinois) on f' from the extremum of the cubic Hermite model, until: f changes sign at
    the new point (two roots: split the bracket there), ``|f| <= 4 eps r^2`` (a double root at rounding
    level), :func:`_k_lower_bound` on the shrunk bracket is above ftol (no root), or the bracket is 1e-11
    wide (the extremum: a double root if ``|f| <= ftol`` there, else none). Returns (theta, f and f'
    there, status: 1 split / 2 double root / 0 none, f'' estimated by the secant of f' over the last
    bracket, iterations).
    """
    sig = 1.0 if flo > 0 else -1.0
    Fa, Fb, Ga, Gb = sig * flo, sig * fhi, sig * glo, sig * ghi  # oriented: Fa, Fb > 0, Ga < 0 < Gb
    h = hi - lo
    c2 = (3 * (Fb - Fa) / h - 2 * Ga - Gb) / h  # extremum of the cubic model p'(t) = 0
    c3 = (Ga + Gb - 2 * (Fb - Fa) / h) / (h * h)
    disc = math.sqrt(_k_max(c2 * c2 - 3 * c3 * Ga, 0.0))
    t0 = -Ga / (c2 + disc)  # the root of Ga + 2 c2 t + 3 c3 t^2 between the slopes' sign change
    th = lo + t0 if (t0 > 0 and t0 < h) else lo - Ga * h / (Gb - Ga)
    ga, gb = Ga, Gb  # Illinois-modified slopes
    f_out, g_out = math.nan, math.nan
    status = 0
    its = 0
    kept = 0  # +1: the upper end was kept last time, -1: the lower end
    for _ in range(max_iter):
        t = th
        f, g, _y, _dy = _k_f_and_slope(t, upper, right, e, seed, K, KC, r2)
        its += 1
        F, G = sig * f, sig * g
        f_out, g_out = f, g
        split = F < 0
        double = (not split) and F <= 4 * _EPS * r2  # at rounding level: a double root
        if G < 0:  # t replaces the lower end
            lo, Fa, Ga = t, F, G
            ga = G
            if kept == 1:
                gb = 0.5 * gb
            kept = 1
        else:
            hi, Fb, Gb = t, F, G
            if kept == -1:
                ga = 0.5 * ga
            gb = G
            kept = -1
        none = _k_lower_bound(Fa, Fb, Ga, Gb, hi - lo, M) > ftol
        narrow = (hi - lo <= 1e-11) or G == 0  # the extremum found: a double root if within tolerance
        if (not split) and narrow and F <= ftol:
            double = True
        status = 1 if split else (2 if double else 0)
        if split or double or none or narrow:
            th = t
            break
        nxt = (lo * gb - hi * ga) / (gb - ga)
        th = nxt if (nxt > lo and nxt < hi) else 0.5 * (lo + hi)
    curv = sig * (Gb - Ga) / (hi - lo)
    return th, f_out, g_out, status, curv, its


@kernel
def _k_fine_f(fine_rows, i, coef):
    """f (f' for rows kf + i) from the fine table at node i: ``fine_rows[i] . coef``."""
    acc = 0.0
    for j in range(9):
        acc += fine_rows[i, j] * coef[j]
    return acc


@kernel
def _k_radial_newton(lo, hi, flo, fhi, glo, ghi, guess, coef, fine, fine_rows, upper, right, e, seed, K, KC, r2,
                     mb, max_iter):
    """Safeguarded Newton on ``f(theta) = |c(theta)|^2 - r2`` in a bracket [lo, hi] where f changes sign.

    Start (no linkage evaluation): the root of the cubic Hermite model of f on the bracket
    (:func:`_k_hermite_root`) picks a sub-cell of the fine table (0.14 deg); if f (from the table and
    ``coef`` (9,), the target's :func:`_arc_coefficients`) does not change sign there, bisection on the
    table's nodes inside the bracket finds one; the start is then the root of the cubic model on that
    sub-cell, which becomes the bracket (if the table's signs do not bracket the root, e.g. a root at a
    node, the start on the whole bracket is kept). ``guess`` (NaN: none) overrides the start (the
    parabola start of the brackets split at an extremum). Each step ``-f/f'`` stays inside the
    (shrinking) bracket, else bisects. Stops when the predicted radius error after the step,
    ``|f''| step^2 / (4 r)`` with ``mb`` bounding ``|f''|``, is below one ulp of r, when
    ``|f| <= 4 eps r^2``, or when the bracket is ~eps wide.

    Returns (theta, c(theta) (complex, conjugated on right halves: the contact point before the beta
    rotation, from the last evaluation's Taylor step ``c + (theta - t) dc``, at rounding level since
    the last step is), iterations, converged).
    """
    kf = fine.shape[0]
    hf = fine[1] - fine[0]
    start = lo + _k_hermite_root(hi - lo, flo, fhi, glo, ghi)
    x = (start - THETA_MIN) / hf
    i_lo = int(x) if math.isfinite(x) else 0
    i_lo = min(max(i_lo, 0), kf - 2)
    i_hi = i_lo + 1
    f_lo, f_hi = _k_fine_f(fine_rows, i_lo, coef), _k_fine_f(fine_rows, i_hi, coef)
    ok = ((f_lo > 0) != (f_hi > 0)) and fine[i_lo] >= lo and fine[i_hi] <= hi
    if not ok and guess != guess:  # bisection on the table's nodes inside the bracket
        b_lo = min(max(int(math.ceil((lo - THETA_MIN) / hf - 1e-6)), 0), kf - 1)
        b_hi = min(max(int(math.floor((hi - THETA_MIN) / hf + 1e-6)), 0), kf - 1)
        b_p = _k_fine_f(fine_rows, b_lo, coef) > 0
        ok = (b_p != (_k_fine_f(fine_rows, b_hi, coef) > 0)) and b_lo < b_hi
        if ok:
            while b_hi - b_lo > 1:
                mid = (b_lo + b_hi) // 2
                if (_k_fine_f(fine_rows, mid, coef) > 0) == b_p:
                    b_lo = mid
                else:
                    b_hi = mid
        i_lo, i_hi = b_lo, b_hi
        f_lo, f_hi = _k_fine_f(fine_rows, b_lo, coef), _k_fine_f(fine_rows, b_hi, coef)
    if ok:  # the cubic model on the sub-cell
        lo, hi, flo, fhi = fine[i_lo], fine[i_hi], f_lo, f_hi
        glo, ghi = _k_fine_f(fine_rows, kf + i_lo, coef), _k_fine_f(fine_rows, kf + i_hi, coef)
        start = lo + _k_hermite_root(hi - lo, flo, fhi, glo, ghi)
    if guess == guess:
        start = guess
    th = start if (start > lo and start < hi) else 0.5 * (lo + hi)
    root = math.nan
    z = complex(math.nan, math.nan)
    its = 0
    conv = False
    pos_lo = flo > 0
    tol_step = 4 * _EPS * r2 / mb  # step^2 below this: the Newton update is at rounding level
    tol_f = 4 * _EPS * r2
    for _ in range(max_iter):
        t = th
        f, g, y, dy = _k_f_and_slope(t, upper, right, e, seed, K, KC, r2)
        its += 1
        if (f > 0) == pos_lo:
            lo = t
        else:
            hi = t
        step = f / g
        new = t - step
        newton = new > lo and new < hi
        if not newton:
            new = 0.5 * (lo + hi)
        small = abs(f) <= tol_f
        done = small or (newton and step * step <= tol_step) or (hi - lo <= 4 * _EPS * hi)
        if small:
            new = t
        root, z = new, y + (new - t) * dy
        conv = done
        th = new
        if done:
            break
    if right:
        z = z.conjugate()
    return root, z, its, conv


#: Most roots of one target kept by the radial kernel (16 cells, two per split cell, the ends, doubles).
_RADIAL_CAP = 64




@kernel
def _k_ik_radial(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows, tol,
                 max_iter, q0, use_q0, limits, q, sols):
    """The radial IK for one target (:func:`_ik_radial` states the math) into ``q`` (3,) and ``sols``
    (S, 3) (NaN-padded, as many as fit). Returns (iterations, error, reason, roots, solutions)."""
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
    kind = 0 if upper else 1
    ea = math.sqrt(ee)
    f = np.empty(K_)
    g = np.empty(K_)
    for k in range(K_):
        fk, gk = 0.0, 0.0
        for j in range(9):
            fk += coef[j] * table[j, k]
            gk += coef[j] * table[j, K_ + k]
        f[k], g[k] = fk, gk
    h = grid[1] - grid[0]
    # brackets: (lo, hi, flo, fhi, glo, ghi, curvature bound, start guess)
    jobs = np.empty((3 * K_, 8))
    nj = 0
    for k in range(K_ - 1):
        if (f[k] > 0) != (f[k + 1] > 0):
            M = m2[kind, 0, k] + ee * m2[kind, 1, k] + 2.0 * ea * m2[kind, 2, k]
            jobs[nj, 0], jobs[nj, 1], jobs[nj, 2], jobs[nj, 3] = grid[k], grid[k + 1], f[k], f[k + 1]
            jobs[nj, 4], jobs[nj, 5], jobs[nj, 6], jobs[nj, 7] = g[k], g[k + 1], M, math.nan
            nj += 1
    its = 0
    rth = np.empty(_RADIAL_CAP)
    rz = np.empty(_RADIAL_CAP, dtype=np.complex128)
    nx = 0  # roots found without Newton (ends of the range, double roots)
    xth = np.empty(K_ + 2)
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
    for i in range(ns):
        jobs[nj] = split_lo[i]
        nj += 1
    for i in range(ns):
        jobs[nj] = split_hi[i]
        nj += 1
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
    # solutions: branch y_L <= 0 by increasing theta, then branch y_L > 0
    tau = complex(x_L, -yabs)  # exp(i (beta + pi/2)) c = tau on the branch y_L <= 0
    gamma1 = _k_phase(m * complex(a, yabs))
    gamma2 = _k_phase(m * complex(a, -yabs))
    nsol = nr * (2 if yabs > 0 else 1)
    S = sols.shape[0]
    for i in range(S):
        sols[i, 0], sols[i, 1], sols[i, 2] = math.nan, math.nan, math.nan
    best = -1
    best_d2 = math.inf
    sq0 = np.empty(3)
    sel = np.empty(3)
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
        if i == 0:
            sel[0], sel[1], sel[2] = sq0[0], sq0[1], sq0[2]  # kept for the out-of-limits answer
        if usable:
            if not use_q0:
                if best < 0:
                    best = i
                    q[0], q[1], q[2] = sq0[0], sq0[1], sq0[2]
            else:
                dist = (sq0[0] - q0[0]) ** 2
                w1 = _k_phase(complex(math.cos(sq0[1] - q0[1]), math.sin(sq0[1] - q0[1])))
                w2 = _k_phase(complex(math.cos(sq0[2] - q0[2]), math.sin(sq0[2] - q0[2])))
                dist += w1 * w1 + w2 * w2
                if dist < best_d2 or best < 0:
                    best, best_d2 = i, dist
                    q[0], q[1], q[2] = sq0[0], q0[1] + w1, (q0[2] + w2 if not limits else sq0[2])
    if best >= 0:
        reason = _SOLVED
    elif nr > 0:  # reachable only outside the ABAD limits: the first solution, for the error message
        q[0], q[1], q[2] = sel[0], sel[1], sel[2]
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


@_loop(256)
def _k_ik_radial_batch(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows, tol,
                       max_iter, q0, use_q0, limits, q, sols, its, err, reason, nsol):
    """:func:`_k_ik_radial` over targets (n, 3) (q0 (n, 3) or (1, 3) unused) into q, sols, its, err, reason,
    nsol (solutions found per target, possibly more than sols holds)."""
    for i in prange(tgt.shape[0]):
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
      derivatives, as in :func:`contact_jacobian`). Then ``beta = arg((x_L + i y_L) / c) - pi/2``.

    Roots: f and f' on a 17-node grid come from tabulated theta-coefficients (:func:`_arc_table`: one
    small matrix product for the batch). Every cell where f changes sign holds a root, found by
    :func:`_radial_newton` (usually one evaluation of the closed form, from a start refined on a fine
    table). A cell where f keeps its sign while f' changes sign holds an extremum of f: unless a
    curvature bound shows that f stays above ``2 r tol`` in it, :func:`_radial_extremum` decides whether f
    reaches 0 there (then the cell is split into two brackets, or the extremum taken as a double root if
    ``|f| <= 2 r tol`` at it). An end of the range with ``|f| <= 2 r tol`` is a root too. This finds every
    root if each cell holds at most one extremum of f. For the default geometry ``|c|^2`` has at most one
    extremum in theta for any alpha, both rims (checked on 1441 alpha x 20001 theta). At alpha = +-163 deg
    the contact point is the crank hinge B, ``|c| = R`` for every theta: f is rounding noise, every theta
    solves the IK and the grid reports many roots.

    Returns ``(q, iterations, error, converged, solutions, reason)``; ``solutions`` (n, S, 3), NaN-padded:
    for each root by increasing theta the branch ``y_L <= 0``, then the same roots on the branch ``y_L > 0``
    (absent when ``y_L = 0``). The answer is the first solution in that order whose gamma is inside the ABAD
    joint's URDF limits ``[-pi/2, pi/2]`` (``limits=False``: the first), or with ``q0`` the usable solution
    nearest ``q0``. It is checked with the forward kinematics (:func:`_k_fk`): converged means
    ``|contact_point(q) - target| <= tol``. ``reason`` per target: 0 solved, 1 no root (out of reach),
    2 every root outside the ABAD limits. A target without a root gets, as its (unconverged) q, the grid
    node of smallest ``|f|`` with beta, gamma from the branch ``y_L <= 0``; one reachable only outside the
    limits, its first solution.
    """
    max_iter = 60 if max_iter is None else max_iter
    n = target.shape[0]
    grid, table, m2, fine, fine_rows = _radial_table(ctx.geo.R, ctx.seed)
    K, KC = _kconst(ctx.c.R, ctx.geo.R + FOOT_OFFSET)
    sel = ctx.sel

    def items(x, dtype):
        return np.ascontiguousarray(np.broadcast_to(x, (n,)), dtype=dtype)

    upper, right, e = items(sel.upper, np.bool_), items(sel.right, np.bool_), items(sel.e, np.complex128)
    a = items(ctx.geo.d_wheel + ctx.s * ctx.w, np.float64)
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
