"""A cheap certificate that the forward kinematics returns a closed-form IK candidate (the IK's mode check).

The forward kinematics of motors (theta1, theta2) in mode (b1, b2), s returns, of the poses within the limits in
that mode, the one nearest R_P = I (:func:`.forward.fk_select_k`). The IK candidate (roll_c, pitch_c) closes both
rods by construction and lies in that mode, so the forward kinematics returns it unless another pose of that mode
lies nearer R_P = I: one with |roll| <= |(roll_c, pitch_c)| = r_c. Every pose is a real root t = tan(roll / 2) of
the degree-8 polynomial of the rods (:func:`.polynomial.roll_poly_k`), so :func:`certify_k` isolates the real roots
in |t| <= tan(r_c / 2) by subdividing the polynomial's Bernstein form on that interval (an interval whose Bernstein
coefficients share a sign holds no root; one where they are monotone holds at most one, found by safeguarded
Newton), and classifies each root: the candidate itself, or a pose outside the limits, farther from R_P = I, or
clearly in another mode. Anything else (a nearer pose of the mode, a root it cannot isolate, parallel rod
equations, a label within rounding of changing) leaves the verdict to the full forward kinematics.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from .chains import chain_k, ref_of, rod_system_rates_k, rot_k, sgn_k, tips_k
from .geometry import K_TOL, PLATFORM_LIMIT
from .polynomial import quadratics_at_k, roll_poly_k

__all__ = ["certify_k", "CERTIFY_WORK"]

# ----------------------------------------------------------------------------- the Bernstein form (degree 8)
_N = 8
_BINOM = np.array([[math.comb(i, j) for j in range(_N + 1)] for i in range(_N + 1)], dtype=np.float64)
_BERN = np.array([[_BINOM[i, j] / _BINOM[_N, j] if j <= i else 0.0 for j in range(_N + 1)] for i in range(_N + 1)])


@kernel(inline=True)  # small and hot: inlined
def bernstein_k(c, lo, hi, b, d):
    """Bernstein coefficients b (9,) on [lo, hi] of the degree-8 polynomial c (9,) (ascending); d (9,) work."""
    for k in range(_N + 1):
        d[k] = c[k]
    for i in range(_N):  # Taylor shift: coefficients of c(lo + x)
        for j in range(_N - 1, i - 1, -1):
            d[j] += lo * d[j + 1]
    f = 1.0
    w = hi - lo
    for k in range(_N + 1):
        d[k] *= f
        f *= w
    for i in range(_N + 1):
        s = 0.0
        for j in range(i + 1):
            s += _BERN[i, j] * d[j]
        b[i] = s


@kernel(inline=True)  # small and hot: inlined
def _split_k(b, left, right, w):
    """de Casteljau at the midpoint: the Bernstein coefficients of both halves; w (9,) work."""
    for i in range(_N + 1):
        w[i] = b[i]
    left[0], right[_N] = w[0], w[_N]
    for r in range(1, _N + 1):
        for i in range(_N + 1 - r):
            w[i] = 0.5 * (w[i] + w[i + 1])
        left[r], right[_N - r] = w[0], w[_N - r]


@kernel(inline=True)  # small and hot: inlined
def _signs_k(b, eps):
    """+1 / -1 where every entry of b exceeds eps / is below -eps, else 0."""
    pos = True
    neg = True
    for i in range(b.shape[0]):
        pos = pos and b[i] > eps
        neg = neg and b[i] < -eps
    return 1 if pos else (-1 if neg else 0)


@kernel(inline=True)  # small and hot: inlined
def _slope_k(b, eps):
    """The sign of the polynomial's slope where its Bernstein coefficients b are strictly monotone, else 0."""
    up = True
    down = True
    for i in range(_N):
        dd = b[i + 1] - b[i]
        up = up and dd > eps
        down = down and dd < -eps
    return 1 if up else (-1 if down else 0)


@kernel(inline=True)  # small and hot: inlined
def _horner_k(c, t):
    """(c(t), c'(t)) of the polynomial c (9,) (ascending)."""
    p = c[_N]
    dp = 0.0
    for k in range(_N - 1, -1, -1):
        dp = dp * t + p
        p = p * t + c[k]
    return p, dp


@kernel(inline=True)
def _root_k(c, a, b, fa):
    """The root of c in [a, b] where c is monotone and changes sign (fa = c(a)): Newton, bisection-safeguarded."""
    x = 0.5 * (a + b)
    for _ in range(80):
        f, df = _horner_k(c, x)
        if f == 0.0:
            return x
        if (f > 0.0) == (fa > 0.0):
            a = x
        else:
            b = x
        xn = x - f / df
        if not (a < xn < b):
            xn = 0.5 * (a + b)
        if abs(xn - x) <= 1e-16 * (1.0 + abs(x)) or b - a <= 1e-16 * (1.0 + abs(x)):
            return xn
        x = xn
    return x


# ----------------------------------------------------------------------------- what a root is to the candidate
#: Verdicts of :func:`classify_k`.
UNKNOWN = -1
NOT_NEARER = 0
SELF = 1
#: A root whose (roll, pitch) lies within this (rad) of the candidate's is the candidate itself.
SELF_TOL = 1e-8
#: Margin (rad) of a pose's distance from R_P = I and from the platform limits: a pose beyond a limit, or farther
#: from R_P = I than the candidate, by more than this is not nearer; one within this of a limit is left to the
#: forward kinematics (and so is a candidate within it of a limit).
NORM_MARGIN = 1e-6
#: A chain whose reach ratio |k| lies within this of 1 is on its reach boundary (labelled with both branches).
BOUNDARY_MARGIN = 1e-6
#: Relative margins of det N (the assembly mode's sign) and of the rods' Cramer determinant (one pitch per roll).
DET_MARGIN = 1e-9
CRAMER_MARGIN = 1e-4


@kernel
def classify_k(t, tip, dtip, al, be, ga, pose, b1, b2, s, rc, work):
    """What the pose at the root t = tan(roll / 2) is to the candidate pose (3,) (theta_LL, roll, pitch) of mode
    (b1, b2), s at distance rc from R_P = I: SELF, NOT_NEARER (outside the limits, farther, or in another mode) or
    UNKNOWN (possibly a nearer pose of the mode: the forward kinematics decides). work (21,)."""
    a0, a1, c0, c1, g0, g1 = quadratics_at_k(al, be, ga, t)
    det = a0 * c1 - a1 * c0
    if not (abs(det) > CRAMER_MARGIN * (abs(a0 * c1) + abs(a1 * c0))):
        return UNKNOWN  # parallel rod equations: more than one pitch at this roll
    roll = 2.0 * math.atan(t)
    pitch = math.atan2((a1 * g0 - a0 * g1) / det, (c0 * g1 - c1 * g0) / det)
    if max(abs(roll - pose[1]), abs(pitch - pose[2])) <= SELF_TOL:
        return SELF
    if abs(pitch) > PLATFORM_LIMIT + NORM_MARGIN or math.hypot(roll, pitch) > rc + NORM_MARGIN:
        return NOT_NEARER
    if abs(pitch) > PLATFORM_LIMIT - NORM_MARGIN or abs(roll) > PLATFORM_LIMIT - NORM_MARGIN:
        return UNKNOWN
    rot = work[0:9].reshape((3, 3))
    th, kk, g, dd = work[9:11], work[11:13], work[13:15], work[15:17]
    nm = work[17:21].reshape((2, 2))
    rot_k(roll, pitch, rot)
    chain_k(rot, 0, 1.0, K_TOL, th, kk)
    chain_k(rot, 1, 1.0, K_TOL, th, kk)
    rod_system_rates_k(roll, pitch, tip, dtip, g, nm, dd)
    for i in range(2):
        if not (abs(abs(kk[i]) - 1.0) > BOUNDARY_MARGIN):
            continue  # on (or near) the chain's reach boundary: labelled with both branches
        if -(1.0 if i == 0 else -1.0) * sgn_k(dd[i]) != (b1 if i == 0 else b2):
            return NOT_NEARER
    dn = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
    if not (abs(dn) > DET_MARGIN * (abs(nm[0, 0] * nm[1, 1]) + abs(nm[0, 1] * nm[1, 0]))):
        return UNKNOWN
    if sgn_k(dn) * ref_of(b1, b2) != s:
        return NOT_NEARER
    return UNKNOWN


# ----------------------------------------------------------------------------- root isolation by subdivision
#: Deepest subdivision of the root interval (widths down to 2^-MAX_DEPTH of it).
MAX_DEPTH = 14
_S = MAX_DEPTH + 2  # stack entries
_STACK = 78
#: Length of certify_k's work array.
CERTIFY_WORK = _STACK + _S * (_N + 4)
#: Bernstein coefficients within ZERO_TOL (relative to the largest on the whole interval) of zero count as zero;
#: their successive differences within SLOPE_TOL (likewise relative) count as no slope.
ZERO_TOL = 1e-9
SLOPE_TOL = 1e-13


@kernel
def certify_k(pose, motors, b1, b2, s, work):
    """True if the forward kinematics of the candidate's motors (3,) in mode (b1, b2), s surely returns the
    candidate's pose (3,) (theta_LL, roll, pitch); False if it cannot tell (then ask the forward kinematics).
    work: (CERTIFY_WORK,) float64."""
    r, p = pose[1], pose[2]
    if not (abs(r) < PLATFORM_LIMIT - NORM_MARGIN and abs(p) < PLATFORM_LIMIT - NORM_MARGIN):
        return False
    rc = math.hypot(r, p)
    tmax = math.tan(0.5 * min(rc + NORM_MARGIN, PLATFORM_LIMIT + NORM_MARGIN))
    tip, dtip = work[0:6].reshape((2, 3)), work[6:12].reshape((2, 3))
    al, be, ga = work[12:18].reshape((2, 3)), work[18:24].reshape((2, 3)), work[24:30].reshape((2, 3))
    poly, left, right, tmp = work[30:39], work[39:48], work[48:57], work[57:66]
    cwork = work[57:_STACK]  # classify_k's work (after tmp's last use in a step)
    tips_k(motors[0], motors[1], tip, dtip)
    roll_poly_k(tip, poly, al, be, ga)
    for k in range(_N + 1):
        if not math.isfinite(poly[k]):
            return False
    # depth-first subdivision; a stack of Bernstein coefficients with their interval and depth
    stack = work[_STACK:_STACK + _S * (_N + 1)].reshape((_S, _N + 1))
    lo = work[_STACK + _S * (_N + 1):_STACK + _S * (_N + 2)]
    hi = work[_STACK + _S * (_N + 2):_STACK + _S * (_N + 3)]
    depth = work[_STACK + _S * (_N + 3):_STACK + _S * (_N + 4)]
    bernstein_k(poly, -tmax, tmax, stack[0], tmp)
    scale = 0.0
    for i in range(_N + 1):
        scale = max(scale, abs(stack[0, i]))
    if not (scale > 0.0):
        return False
    eps, seps = ZERO_TOL * scale, SLOPE_TOL * scale
    lo[0], hi[0], depth[0] = -tmax, tmax, 0.0
    top = 1
    found_self = False
    while top > 0:
        top -= 1
        b = stack[top]
        a, c, dpt = lo[top], hi[top], depth[top]
        if _signs_k(b, eps) != 0:
            continue  # no root
        if _slope_k(b, seps) != 0:  # monotone: at most one root
            verdict = NOT_NEARER
            fa, fc = b[0], b[_N]
            if (fa > 0.0) != (fc > 0.0) or fa == 0.0 or fc == 0.0:
                t = a if fa == 0.0 else (c if fc == 0.0 else _root_k(poly, a, c, fa))
                verdict = classify_k(t, tip, dtip, al, be, ga, pose, b1, b2, s, rc, cwork)
            elif min(abs(fa), abs(fc)) <= eps:  # a root just outside: look at the nearer end
                t = a if abs(fa) <= abs(fc) else c
                verdict = classify_k(t, tip, dtip, al, be, ga, pose, b1, b2, s, rc, cwork)
            if verdict == UNKNOWN:
                return False
            found_self = found_self or verdict == SELF
            continue
        if dpt >= MAX_DEPTH:
            return False
        _split_k(b, left, right, tmp)
        m = 0.5 * (a + c)
        for i in range(_N + 1):  # (element copies: an array assignment compiles numba's shape-error formatting)
            stack[top, i], stack[top + 1, i] = right[i], left[i]
        lo[top], hi[top], depth[top] = m, c, dpt + 1.0
        lo[top + 1], hi[top + 1], depth[top + 1] = a, m, dpt + 1.0
        top += 2
    return found_self
