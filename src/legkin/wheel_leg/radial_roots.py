"""The 1-D root finding of the radial IK on ``f(theta) = |c(theta, alpha)|^2 - r^2`` (not in the seed): the
linkage evaluation, a curvature lower bound, cubic Hermite starts, the extremum test and the safeguarded Newton.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from ._common import _k_clip, _k_max
from .geometry import THETA_MIN
from .rim import _k_plane

_EPS = float(np.finfo(float).eps)


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


@kernel(inline=True)
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


@kernel(inline=True)
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
    ``coef`` (9,), the target's coefficient row of ``_arc_table``) does not change sign there, bisection on the
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
