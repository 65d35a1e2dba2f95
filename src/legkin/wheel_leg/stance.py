"""The stance IK (issue 12): the joints (theta, beta, gamma) that put the ground contact point of a leg
(:func:`~legkin.wheel_leg.ground.ground_contact`) on a target, as one compiled per-target kernel.

How every solution is found (:func:`_k_stance_all`, one target):

* the lateral coordinate w of the contact is one of -T/2, T/2, 0 (the rule of ``ground_contact``); for each, the
  target's distance from the module axis gives the leg-plane height y_L (two branches, ``rr >= -1e-15``) and
  gamma in closed form (as the radial IK); the (w, branch) pair is kept only if the ground normal at that gamma
  gives the same w by the rule and a nonzero in-plane part ``n_plane``;
* the support point of a circle (centre c_k(theta), radius rho_k) toward ``-n_plane`` is
  ``rot(beta) c_k(theta) - rho_k n_plane``, so the target needs ``|c_k(theta)| = |Z_k|``,
  ``Z_k = (-x_target, y_L) + rho_k n_plane`` (leg plane). The circles: the offset arcs about U_L, L_L, L_R, U_R
  (rho = R + r) and the fillets and caps about F_L, G, F_R, H_L, H_R (rho = r). Conjugate centres (left/right
  halves) have the same |c_k|: five functions |c|^2(theta) (U, L, F, G, H), tabulated on a 2001-node grid over
  [17, 160] deg (:func:`_centre_table`). Each sign change of ``|c|^2 - |Z|^2`` on the grid is bracketed and
  solved by Newton's method safeguarded by bisection (the theta-derivative of the closed form) to full
  precision (an ill-conditioned root, near wheel mode: by plain bisection); a grid end with
  ``| |c|^2 - |Z|^2 | <= 1e-15`` is a root too. Next to a fold of a row (an interior extremum of its grid values,
  a boundary of its monotone runs) the curve can cross the level and come back between two nodes that do not
  change sign: where the level is that close to the fold's node (:func:`_k_fold_roots`), the true extremum is
  found (bisection on the sign of the theta-derivative) and the two roots on either side of it solved, or the
  extremum itself taken where it touches the level to 1e-15. beta follows from the angle of ``Z_k / c_k``;
* each candidate is kept only if ``ground_contact`` at it reproduces the target to :data:`VERIFY_TOL` (the
  circle must really carry the lowest point), then sorted by (|gamma|, theta) (stable) and de-duplicated
  (max-norm 1e-9, angles wrapped; the first is kept).

A root is missed only where one grid cell holds more than one extremum of a row (none does: the rows are smooth
and their folds 100s of cells apart).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, Literal, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input, check_flag
from .._kernels import as_rows, batch_kernel, kernel
from .._rotations import wrap_k
from ..errors import InvalidInputError, UnreachableError
from ._common import Leg
from .geometry import (
    _DEFAULT_GEOMETRY,
    ABAD_LIMIT,
    THETA_MAX,
    THETA_MIN,
    TYRE_THICKNESS,
    Geometry,
    _geometry,
    _leg,
    abad_limit_error,
)
from .ground import _ZERO, _k_ground, _k_normal_leg, _leg_consts, _normals
from .linkage import _IF, _IG, _IH, _IL, _IU, _k_closed, _kconst, linkage_points
from .tyre import _thickness

__all__ = ["stance_ik", "stance_ik_all", "VERIFY_TOL"]

_GRID = 2001
#: A candidate whose ground contact is farther than this from the target is not a solution (m).
VERIFY_TOL = 1e-9
#: Two solutions closer than this (max-norm, rad, angles wrapped) are one.
_SAME = 1e-9
#: Most roots per |c|^2 row and (w, branch) pair, and most verified solutions per target (never reached:
#: a target has at most a few dozen candidates; reaching it is the status _OVERFLOW).
_CAP_ROOTS = 64
CAP = 64
_OVERFLOW = 3
_NEWTON_MAX = 80
#: A root whose |d |c|^2 / d theta| is below this times |Z|^2 is ill-conditioned: solved by plain bisection.
_ILL = 1e-2
_BISECT = 56
#: The pre-check of a candidate (:func:`_k_candidate`): its support height within this of the tyre's lowest (m).
_PREFILTER = 1e-7

#: The nine support circles in the order of the search: (|c|^2 row, closed-form point, conjugated, offset arc).
_ROWS_PT = np.array([_IU, _IL, _IF, _IG, _IH], dtype=np.int64)  # rows U, L, F, G, H of the table
_ROW_BIG = np.array([True, True, False, False, False])
_C_ROW = np.array([0, 1, 1, 0, 2, 3, 2, 4, 4], dtype=np.int64)  # U_L, L_L, L_R, U_R, F_L, G, F_R, H_L, H_R
_C_CONJ = np.array([False, False, True, True, False, False, True, False, True])
_WS = np.array([-1.0, 1.0, 0.0])  # w / (T/2), in the order of the search


@lru_cache(maxsize=8)
def _centre_table(geo: Geometry) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """theta grid (M,), the five |c(theta)|^2 rows (5, M) of the support circles' centres U, L, F, G, H, and
    each row's maximal monotone runs on the grid: boundaries RUNS (5, Q) (node indices, first 0, last M - 1)
    and their counts NRUN (5,). A sign change of ``row - z2`` is in at most one cell of a monotone run (rounding
    is monotone), found by bisection over its nodes: the cells of a linear scan, in the same order."""
    th = np.linspace(THETA_MIN, THETA_MAX, _GRID)
    pts = linkage_points(th, -np.pi / 2, geometry=geo)
    tab = np.stack([pts[name][:, 0] ** 2 + pts[name][:, 1] ** 2 for name in ("U_L", "L_L", "F_L", "G", "H_L")])
    bounds = []
    for row in tab:
        b, direction = [0], 0
        for j in range(1, row.size):
            step = np.sign(row[j] - row[j - 1])
            if step != 0 and direction != 0 and step != direction:
                b.append(j - 1)
                direction = step
            elif direction == 0:
                direction = step
        b.append(row.size - 1)
        bounds.append(b)
    nrun = np.array([len(b) for b in bounds], dtype=np.int64)
    runs = np.zeros((5, nrun.max()), dtype=np.int64)
    for k, b in enumerate(bounds):
        runs[k, : len(b)] = b
    for a in (th, tab, runs, nrun):
        a.setflags(write=False)
    return th, tab, runs, nrun


@kernel
def _k_centre(theta, row, K, KC):
    """Centre of |c|^2 row ``row`` at theta (left half, pre-rotation plane) and its theta-derivative."""
    pts, der = _k_closed(theta, K, KC, True)
    j = _ROWS_PT[row]
    return pts[j], der[j]


@kernel(inline=True)
def _k_root(row, z2, lo, hi, flo, fhi, K, KC):
    """The root of ``|c_row(theta)|^2 - z2`` in the grid cell [lo, hi] (values flo, fhi of opposite signs):
    Newton's method from the secant point, a bisection step whenever Newton would leave the bracket or does not
    halve the step (the safeguard of ``rtsafe``), until the step is a few ulps (rounding noise)."""
    x = lo - flo * (hi - lo) / (fhi - flo)
    if not lo <= x <= hi:
        x = 0.5 * (lo + hi)
    neg_lo = flo < 0.0
    dx_old = dx = hi - lo
    for _ in range(_NEWTON_MAX):
        c, dc = _k_centre(x, row, K, KC)
        f = abs(c) ** 2 - z2
        if f == 0.0:
            return x, 2.0 * (c.conjugate() * dc).real
        if (f < 0.0) == neg_lo:
            lo = x
        else:
            hi = x
        df = 2.0 * (c.conjugate() * dc).real
        xn = x - f / df if df != 0.0 else math.nan
        if not (lo <= xn <= hi) or abs(2.0 * f) > abs(dx_old * df):
            dx_old, dx = dx, 0.5 * (hi - lo)
            xn = lo + dx
        else:
            dx_old, dx = dx, x - xn
        if abs(xn - x) <= 4e-16 * abs(x) or hi - lo <= 4e-16 * abs(x):
            return xn, df
        x = xn
    return x, 0.0


@kernel(inline=True)
def _k_bisect(row, z2, lo, hi, flo, K, KC):
    """The root of ``|c_row(theta)|^2 - z2`` in [lo, hi] by :data:`_BISECT` bisection steps (to the last bit):
    for the ill-conditioned roots (:func:`_k_root`'s derivative small, near wheel mode, where every centre
    nears O), whose position within rounding depends on the path: the path of a plain bisection."""
    neg_lo = flo < 0.0
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        pts, _der = _k_closed(mid, K, KC, False)
        if (abs(pts[_ROWS_PT[row]]) ** 2 - z2 < 0.0) == neg_lo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@kernel(inline=True)
def _k_solve_cell(row, z2, lo, hi, flo, fhi, K, KC):
    """The root of ``|c_row(theta)|^2 - z2`` bracketed by [lo, hi] (values flo, fhi of opposite signs): Newton
    (:func:`_k_root`), or plain bisection (:func:`_k_bisect`) where the root is ill-conditioned."""
    x, df = _k_root(row, z2, lo, hi, flo, fhi, K, KC)
    if not abs(df) >= _ILL * z2:
        x = _k_bisect(row, z2, lo, hi, flo, K, KC)
    return x


@kernel
def _k_extremum(row, lo, hi, K, KC):
    """The extremum of ``|c_row(theta)|^2`` in [lo, hi] (the theta-derivative changes sign there; else the middle)
    by bisection on the derivative's sign: (theta, |c_row|^2 there)."""
    c, dc = _k_centre(lo, row, K, KC)
    neg_lo = (c.conjugate() * dc).real < 0.0
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        c, dc = _k_centre(mid, row, K, KC)
        if ((c.conjugate() * dc).real < 0.0) == neg_lo:
            lo = mid
        else:
            hi = mid
    x = 0.5 * (lo + hi)
    c, dc = _k_centre(x, row, K, KC)
    return x, abs(c) ** 2


@kernel(inline=True)
def _k_fold_roots(row, z2, TH, TAB, RUNS, NRUN, K, KC, roots, m):
    """Append to ``roots[row]`` (m so far) the roots next to each interior fold of the row (node b, a boundary of
    its monotone runs) that the nodes b - 1, b, b + 1 do not bracket: where the level is within the neighbours'
    differences of the fold's node (a parabola through the nodes dips below its lowest node by at most a quarter
    of them), the extremum between b - 1 and b + 1 decides: beyond the level, a root on each side of it; at the
    level (to 1e-15, a double root), the extremum itself. Returns the new count."""
    for q in range(1, NRUN[row] - 1):
        b = RUNS[row, q]
        f0, f1, f2 = TAB[row, b - 1] - z2, TAB[row, b] - z2, TAB[row, b + 1] - z2
        if (f0 < 0.0) != (f1 < 0.0) or (f2 < 0.0) != (f1 < 0.0):
            continue  # a sign change in a cell next to the fold: bracketed by the scan of the runs
        if abs(f1) > max(abs(f0 - f1), abs(f2 - f1)):
            continue  # the curve cannot reach the level between these nodes
        x, fx = _k_extremum(row, TH[b - 1], TH[b + 1], K, KC)
        fx -= z2
        if abs(fx) <= 1e-15:
            if m < _CAP_ROOTS:
                roots[row, m] = x
            m += 1
        elif (fx < 0.0) != (f1 < 0.0):
            for lo, hi, flo, fhi in ((TH[b - 1], x, f0, fx), (x, TH[b + 1], fx, f2)):
                if m < _CAP_ROOTS:
                    roots[row, m] = _k_solve_cell(row, z2, lo, hi, flo, fhi, K, KC)
                m += 1
    return m


@kernel(inline=True)
def _k_arc_low(c, p1, p2, d, R):
    """Lowest height ``Re(conj(p) d)`` over the arc of radius R about c from p1 to p2 (counter-clockwise)."""
    a1 = math.atan2((p1 - c).imag, (p1 - c).real)
    span = (math.atan2((p2 - c).imag, (p2 - c).real) - a1) % (2.0 * math.pi)
    if (math.atan2(-d.imag, -d.real) - a1) % (2.0 * math.pi) <= span:
        return (c.conjugate() * d).real - R
    return min((p1.conjugate() * d).real, (p2.conjugate() * d).real)


@kernel(inline=True)
def _k_pitch_low(pts, d, R):
    """Lowest height along the unit direction d (pre-rotation plane) of the pitch curve (the four rim arcs of
    radius R, H_L -> F_L -> G -> F_R -> H_R): the tyre's lowest height is this minus r (the tyre is the pitch
    curve swept by a disk of radius r)."""
    UL, LL, FL, G, HL = pts[_IU], pts[_IL], pts[_IF], pts[_IG], pts[_IH]
    h = _k_arc_low(UL, HL, FL, d, R)
    h = min(h, _k_arc_low(LL, FL, G, d, R))
    h = min(h, _k_arc_low(LL.conjugate(), G, FL.conjugate(), d, R))
    return min(h, _k_arc_low(UL.conjugate(), FL.conjugate(), HL.conjugate(), d, R))


@kernel
def _k_candidate(theta, Z, u, rho_k, row, conj, gamma, K, KC, t, n, gargs, cand, nc):
    """Verify the candidate of circle (row, conj, radius rho_k) at root theta (Z: its |Z| point, u: the unit
    in-plane normal, leg plane); append it to cand (nc so far); the new count. A candidate whose support height
    is not the tyre's lowest (the pitch curve's minus r, to 1e-7 m: the circle does not carry the lowest point)
    is dropped before the full check by ``ground_contact``'s kernel."""
    pts, _der = _k_closed(theta, K, KC, False)
    c = pts[_ROWS_PT[row]]
    if conj:
        c = c.conjugate()
    w = Z / c
    beta = wrap_k(math.atan2(w.imag, w.real) - 0.5 * math.pi)
    d = complex(math.cos(beta + 0.5 * math.pi), -math.sin(beta + 0.5 * math.pi)) * u
    if abs((c.conjugate() * d).real - rho_k - (_k_pitch_low(pts, d, K[0]) - gargs[0])) > _PREFILTER:
        return nc
    q = np.empty(3)
    q[0], q[1], q[2] = theta, beta, gamma
    P, J, info = np.empty(3), np.empty(9), np.empty(4)
    rho, KK, KKC, sl, dwheel, halfT, o0, o1, o2, RLM, R0 = gargs
    if _k_ground(q, n, rho, KK, KKC, sl, dwheel, halfT, o0, o1, o2, RLM, R0, P, J, info, False) != 0:
        return nc
    e = math.sqrt((P[0] - t[0]) ** 2 + (P[1] - t[1]) ** 2 + (P[2] - t[2]) ** 2)
    if not e <= VERIFY_TOL:
        return nc
    if nc >= cand.shape[0]:
        return nc + 1
    cand[nc, 0], cand[nc, 1], cand[nc, 2] = theta, beta, gamma
    return nc + 1


@kernel
def _k_branch(t, n, yl, gamma, Zb, u, TH, TAB, RUNS, NRUN, K, KC, gargs, rho_big, rho_small, roots, nroot, cand, nc):
    """Every verified candidate of one (w, branch) pair (Zb = (-x, y_L), u the unit in-plane normal)."""
    M = TH.shape[0]
    z2s = np.empty(5)
    for row in range(5):  # the roots of each |c|^2 row (shared by the conjugate circles)
        Z = Zb + (rho_big if _ROW_BIG[row] else rho_small) * u
        z2 = abs(Z) ** 2
        z2s[row] = z2
        m = 0
        for q in range(NRUN[row] - 1):
            a, b = RUNS[row, q], RUNS[row, q + 1]
            fa = TAB[row, a] - z2
            if (fa < 0.0) == (TAB[row, b] - z2 < 0.0):
                continue
            while b - a > 1:  # the one cell of this run with the sign change
                mid = (a + b) // 2
                if (TAB[row, mid] - z2 < 0.0) == (fa < 0.0):
                    a = mid
                else:
                    b = mid
            if m < _CAP_ROOTS:
                roots[row, m] = _k_solve_cell(row, z2, TH[a], TH[b], TAB[row, a] - z2, TAB[row, b] - z2, K, KC)
            m += 1
        nroot[row] = _k_fold_roots(row, z2, TH, TAB, RUNS, NRUN, K, KC, roots, m)
    for k in range(9):
        row = _C_ROW[k]
        rho_k = rho_big if _ROW_BIG[row] else rho_small
        Z = Zb + rho_k * u
        for m in range(min(nroot[row], _CAP_ROOTS)):
            nc = _k_candidate(roots[row, m], Z, u, rho_k, row, _C_CONJ[k], gamma, K, KC, t, n, gargs, cand, nc)
        if nroot[row] > _CAP_ROOTS:
            nc = cand.shape[0] + 1
    for end in (0, M - 1):  # a root on a bound of [17, 160] deg without a sign change in the end cell
        for k in range(9):
            row = _C_ROW[k]
            if abs(TAB[row, end] - z2s[row]) <= 1e-15:
                rho_k = rho_big if _ROW_BIG[row] else rho_small
                nc = _k_candidate(TH[end], Zb + rho_k * u, u, rho_k, row, _C_CONJ[k], gamma, K, KC, t, n, gargs,
                                  cand, nc)
    return nc


@kernel(entry=True)
def _k_stance_all(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, out):
    """Every solution of one target t (3,) for the unit normal n (3,) into out (CAP, 3), sorted by (|gamma|,
    theta), de-duplicated; ``limits``: only |gamma| <= ABAD_LIMIT. Returns the count (-1: more than CAP)."""
    rho, _K, _KC, sl, dwheel, halfT, o0, o1, o2, RLM, R0 = gargs
    R = K[0]
    d0, d1, d2 = t[0] - o0, t[1] - o1, t[2] - o2
    if not (math.isfinite(d0) and math.isfinite(d1) and math.isfinite(d2)):
        return 0
    cand = np.empty((4 * CAP, 3))
    roots = np.empty((5, _CAP_ROOTS))
    nroot = np.zeros(5, dtype=np.int64)
    nc = 0
    for iw in range(3):
        w = _WS[iw] * halfT
        a = dwheel + sl * w
        rr = d1 * d1 + d2 * d2 - a * a
        if rr < -1e-15:
            continue
        for sign in (-1.0, 1.0):
            yl = sign * math.sqrt(max(rr, 0.0))
            g = complex(sl * d1, d2) / complex(a, yl)
            gamma = math.atan2(g.imag, g.real)
            nl0, nl1, nl2 = _k_normal_leg(gamma, n, RLM, R0)
            w_rule = -halfT if nl2 > _ZERO else (halfT if nl2 < -_ZERO else 0.0)
            nzv = complex(nl0, nl1)
            mag = abs(nzv)
            if w_rule != w or not mag > _ZERO:
                continue
            nc = _k_branch(t, n, yl, gamma, complex(-d0, yl), nzv / mag, TH, TAB, RUNS, NRUN, K, KC, gargs,
                           R + rho, rho, roots, nroot, cand, nc)
    if nc > cand.shape[0]:
        return -1
    # sort by (|gamma|, theta), stable (insertion sort: a few candidates), then de-duplicate
    for i in range(1, nc):
        x0, x1, x2 = cand[i, 0], cand[i, 1], cand[i, 2]
        j = i - 1
        while j >= 0 and (abs(cand[j, 2]) > abs(x2) or (abs(cand[j, 2]) == abs(x2) and cand[j, 0] > x0)):
            cand[j + 1, 0], cand[j + 1, 1], cand[j + 1, 2] = cand[j, 0], cand[j, 1], cand[j, 2]
            j -= 1
        cand[j + 1, 0], cand[j + 1, 1], cand[j + 1, 2] = x0, x1, x2
    m = 0
    for i in range(nc):
        if limits and not abs(cand[i, 2]) <= ABAD_LIMIT + 1e-12:
            continue
        new = True
        for j in range(m):
            dd = max(abs(cand[i, 0] - out[j, 0]), abs(wrap_k(cand[i, 1] - out[j, 1])),
                     abs(wrap_k(cand[i, 2] - out[j, 2])))
            if not dd > _SAME:
                new = False
                break
        if new:
            if m >= out.shape[0]:
                return -1
            out[m, 0], out[m, 1], out[m, 2] = cand[i, 0], cand[i, 1], cand[i, 2]
            m += 1
    return m


@kernel(entry=True, inline=True)
def _k_stance(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, near, has_near, q):
    """:func:`stance_ik` for one target into q (3,): 0 solved, 1 unreachable, 2 solutions only outside the
    limits, 3 overflow (more than CAP solutions)."""
    sols = np.empty((CAP, 3))
    m = _k_stance_all(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, False, sols)
    if m < 0:
        return _OVERFLOW
    if m == 0:
        return 1
    best, bd = -1, math.inf
    for i in range(m):
        if limits and not abs(sols[i, 2]) <= ABAD_LIMIT + 1e-12:
            continue
        if not has_near:
            best = i
            break
        dd = max(abs(sols[i, 0] - near[0]), abs(wrap_k(sols[i, 1] - near[1])), abs(wrap_k(sols[i, 2] - near[2])))
        if dd < bd:
            best, bd = i, dd
    if best < 0:
        return 2
    q[0], q[1], q[2] = sols[best, 0], sols[best, 1], sols[best, 2]
    return 0


@batch_kernel(rows="t n out count", min_parallel=4)
def _k_stance_all_batch(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, out, count):
    for i in range(t.shape[0]):
        count[i] = _k_stance_all(t[i], n[i], TH, TAB, RUNS, NRUN, K, KC, gargs, limits, out[i])


@batch_kernel(rows="t n near q status", min_parallel=4)
def _k_stance_batch(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, near, has_near, q, status):
    for i in range(t.shape[0]):
        status[i] = _k_stance(t[i], n[i], TH, TAB, RUNS, NRUN, K, KC, gargs, limits, near[i], has_near, q[i])


@lru_cache(maxsize=64, typed=True)  # typed: leg=1 must not admit leg=True or 1.0 (issue 25)
def _args(leg, r, geometry) -> tuple[Any, ...]:
    """(TH, TAB, RUNS, NRUN, K, KC, ground-kernel args) of (leg, r, geometry), validated; cached."""
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rho = _thickness(r, geo)
    _leg(leg)
    sl, o, RLM, R0 = _leg_consts(leg, geo)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    TH, TAB, RUNS, NRUN = _centre_table(geo)
    gargs = (rho, K, KC, sl, geo.d_wheel, geo.T / 2, float(o[0]), float(o[1]), float(o[2]), RLM, R0)
    return TH, TAB, RUNS, NRUN, K, KC, gargs


def _consts(leg, r, geometry) -> tuple[Any, ...]:
    try:
        return _args(leg, r, geometry)
    except TypeError:  # unhashable: the checks below give the legkin error
        geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
        _thickness(r, geo)
        _leg(leg)
        raise


_Z = (0.0, 0.0, 1.0)
_Z_ARRAY = np.array(_Z)  # writeable, like the batch rows: one compiled version of the kernels (never written)
_NO_NEAR = np.zeros((1, 3))  # writeable, like the batch rows (one compiled version; never written)


def _targets(target, normal):
    t = as_input(target, "target", (3,))
    if normal is _Z:  # the default normal: no checks, one row for all
        rows = as_rows(t, 3)
        return rows, np.tile(_Z_ARRAY, (rows.shape[0], 1)), t.shape[:-1]
    n = _normals(normal)
    try:
        shape = np.broadcast_shapes(t.shape[:-1], n.shape[:-1])
    except ValueError as exc:
        raise InvalidInputError(f"inputs do not broadcast together: target{t.shape}, normal{n.shape}") from exc
    return (as_rows(np.broadcast_to(t, shape + (3,)), 3), as_rows(np.broadcast_to(n, shape + (3,)), 3), shape)


def _plain(x: object) -> bool:
    """A finite (3,) float64 array (the single-call fast path; anything else takes the full checks)."""
    return (type(x) is np.ndarray and x.shape == (3,) and x.dtype == np.float64  # type: ignore[attr-defined]
            and math.isfinite(x[0]) and math.isfinite(x[1]) and math.isfinite(x[2]))  # type: ignore[index]


def _overflow() -> RuntimeError:
    return RuntimeError(f"more than {CAP} stance IK solutions for one target (not expected: please report)")


@overload
def stance_ik_all(target: ArrayLike, leg: Leg, *, normal: ArrayLike = ..., r: float = ..., limits: bool = ...,
                  geometry: Geometry | None = ..., return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def stance_ik_all(target: ArrayLike, leg: Leg, *, normal: ArrayLike = ..., r: float = ..., limits: bool = ...,
                  geometry: Geometry | None = ..., return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def stance_ik_all(target: ArrayLike, leg: Leg, *, normal: ArrayLike = _Z, r: float = TYRE_THICKNESS,
                  limits: bool = False, geometry: Geometry | None = None,
                  return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Every (theta, beta, gamma) whose ground contact (:func:`~legkin.wheel_leg.ground_contact`) is ``target``,
    (..., S, 3), NaN-padded (S >= 1).

    The search is the module docstring's (:mod:`legkin.wheel_leg.stance`). Sorted by |gamma|, then theta.
    ``limits=True``: only |gamma| <= ABAD_LIMIT (theta is always in [17, 160] deg).

    Args:
        target: (..., 3) ground-contact points in {R} (m).
        leg: "FL", "FR", "RR", "RL" or 0-3.
        normal: the ground normal (3,) in {R}.
        r: tyre thickness (m).
        limits: keep only solutions inside the ABAD limits.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).
        return_mask: also return the mask (..., S) of the rows that are solutions.

    Returns:
        (..., S, 3) every (theta, beta, gamma) (rad), NaN rows padding a batch to the largest count S; then the
        mask, if asked.

    Raises:
        InvalidInputError: NaN/inf/complex/wrong shapes, a zero normal.
        InvalidParameterError: unknown leg, r out of range, geometry not a Geometry.
    """
    TH, TAB, RUNS, NRUN, K, KC, gargs = _consts(leg, r, geometry)
    if normal is _Z and _plain(target) and type(limits) is bool and type(return_mask) is bool:  # the kernel directly
        one = np.full((CAP, 3), np.nan)
        k = _k_stance_all(target, _Z_ARRAY, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, one)
        if k < 0:
            raise _overflow()
        sols = one[: max(1, k)].copy()
        return (sols, np.arange(len(sols)) < k) if return_mask is True else sols
    limits = check_flag(limits, "limits")
    return_mask = check_flag(return_mask, "return_mask")
    t, n, shape = _targets(target, normal)
    m = t.shape[0]
    out, count = np.full((m, CAP, 3), np.nan), np.empty(m, dtype=np.int64)
    _k_stance_all_batch(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, out, count)
    if np.any(count < 0):
        raise _overflow()
    S = max(1, int(count.max(initial=0)))
    sols = np.ascontiguousarray(out[:, :S]).reshape(shape + (S, 3))
    return (sols, (np.arange(S) < count[:, None]).reshape(shape + (S,))) if return_mask else sols


@overload
def stance_ik(target: ArrayLike, leg: Leg, *, normal: ArrayLike = ..., q_near: ArrayLike | None = ..., r: float = ...,
              limits: bool = ..., geometry: Geometry | None = ...,
              return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def stance_ik(target: ArrayLike, leg: Leg, *, normal: ArrayLike = ..., q_near: ArrayLike | None = ..., r: float = ...,
              limits: bool = ..., geometry: Geometry | None = ...,
              return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def stance_ik(target: ArrayLike, leg: Leg, *, normal: ArrayLike = _Z, q_near: ArrayLike | None = None,
              r: float = TYRE_THICKNESS, limits: bool = True, geometry: Geometry | None = None,
              return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """(theta, beta, gamma) placing the ground contact point (:func:`~legkin.wheel_leg.ground_contact`) of
    ``leg`` at ``target`` (robot frame).

    The solutions are :func:`stance_ik_all`'s; with ``limits=True`` (default) only those inside the joint limits
    (theta in [17, 160] deg always; |gamma| <= ABAD_LIMIT). Default: the first (smallest |gamma|, then theta);
    with ``q_near`` (3,) or (..., 3): the nearest to it (max-norm, beta and gamma wrapped; the first on a tie).

    Raises (single target): UnreachableError (no solution), JointLimitError (solutions only outside the limits),
    InvalidInputError (bad input). A batch gives NaN and mask False instead.

    Args:
        target: (..., 3) ground-contact points in {R} (m).
        leg: "FL", "FR", "RR", "RL" or 0-3.
        normal: the ground normal (3,) in {R} (any nonzero length).
        q_near: (..., 3) the configuration to stay near (rad).
        r: tyre thickness (m).
        limits: keep only answers inside the ABAD limits.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).
        return_mask: also return the mask of solved targets (batch).

    Returns:
        (..., 3) (theta, beta, gamma) (rad), NaN where a batch item is not solved; then the mask, if asked.
    """
    TH, TAB, RUNS, NRUN, K, KC, gargs = _consts(leg, r, geometry)
    if (normal is _Z and type(limits) is bool and return_mask is False and _plain(target)
            and (q_near is None or _plain(q_near))):  # one target: the kernel directly
        q = np.empty(3)
        has_near = q_near is not None
        status = _k_stance(target, _Z_ARRAY, TH, TAB, RUNS, NRUN, K, KC, gargs, limits,
                           q_near if has_near else _NO_NEAR[0], has_near, q)
        if status == 0:
            return q
        t = np.asarray(target)[None]
    else:
        limits = check_flag(limits, "limits")
        return_mask = check_flag(return_mask, "return_mask")
        t, n, shape = _targets(target, normal)
        m = t.shape[0]
        if q_near is None:
            near, has_near = np.zeros((m, 3)), False
        else:
            near = as_rows(np.broadcast_to(as_input(q_near, "q_near", (3,)), shape + (3,)), 3)
            has_near = True
        q, st = np.full((m, 3), np.nan), np.empty(m, dtype=np.int64)
        _k_stance_batch(t, n, TH, TAB, RUNS, NRUN, K, KC, gargs, limits, near, has_near, q, st)
        if np.any(st == _OVERFLOW):
            raise _overflow()
        q[st != 0] = np.nan
        if shape != ():
            q = q.reshape(shape + (3,))
            return (q, (st == 0).reshape(shape)) if return_mask else q
        status = int(st[0])
        if status == 0:
            return (q[0], np.asarray(True)) if return_mask else q[0]
    if status == 2:
        raise abad_limit_error(f"target {t[0].tolist()} is reached only with |gamma| > ABAD_LIMIT = pi/2 "
                               "(joint <leg>_abad)", leg, t[0], math.nan)
    if status == _OVERFLOW:
        raise _overflow()
    raise UnreachableError(f"no configuration puts the ground contact of {leg} at {t[0].tolist()}", target=t[0])
