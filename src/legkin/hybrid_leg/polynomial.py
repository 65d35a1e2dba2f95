"""Every platform pose of given motor angles, in closed form (seed 003, eqs 1-16 with both motors given).

The closed sub-chain's forward kinematics. With the lever tips S_i known (motor angles given), rod i closes iff
``|A_i - S_i| = L``, ``A_i = c + R a_i``, i.e. ``w_i . R a_i = kappa_i`` with ``w_i = c - S_i`` and
``kappa_i = (L^2 - |w_i|^2 - |a_i|^2) / 2``. With ``R = Rx(roll) Ry(pitch)`` and ``q = Rx(roll)^T w`` that is,
per rod::

    alpha_i cos(pitch) + beta_i sin(pitch) + gamma_i = 0,
    alpha = w_x a_x + a_z q_z,  beta = w_x a_z - a_x q_z,  gamma = a_y q_y - kappa,
    q_y = cos(roll) w_y + sin(roll) w_z,  q_z = -sin(roll) w_y + cos(roll) w_z,

two linear equations in (cos pitch, sin pitch): Cramer gives ``cos = C / D``, ``sin = S / D``, and
``cos^2 + sin^2 = 1`` is ``C^2 + S^2 - D^2 = 0``, a trigonometric polynomial of degree 4 in roll. With
``t = tan(roll / 2)`` (times ``(1 + t^2)^4``) it is a polynomial of degree 8 (:func:`roll_poly_k`): up to 8 poses;
roll in the joint limits is ``|t| <= 1``. Its roots (:func:`roots_k`, Aberth-Ehrlich), each polished by Newton's
method on the rod equations (:func:`rod_newton_k`), give every pose (:func:`solutions_k`).
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from .._rotations import wrap_k
from .chains import (
    AX0,
    AX1,
    AY0,
    AY1,
    AZ0,
    AZ1,
    CX,
    CY,
    CZ,
    L,
    chain_k,
    lever_tips_k,
    rod_rate_k,
    rod_system_k,
    rot_k,
    sgn_k,
)
from .geometry import BOUNDARY_TOL, K_TOL, LIMIT_TOL, PLATFORM_LIMIT

_TWO_PI = 2.0 * math.pi

#: Offsets (rad) of the extra starting poses on either side of a near-singular solution (along the null vector of
#: N), from which Newton runs with the forward-singularity barrier: near det N = 0 two poses of opposite modes are
#: close together, and the plain Newton iteration from the roots may find only one of them.
FOLD_OFFSETS = (1e-9, 1e-7, 1e-5, 1e-3)


@kernel
def roll_poly_k(tip, poly, al, be, ga):
    """The degree-8 polynomial poly (9,) in t = tan(roll / 2) and the per-rod quadratics al, be, ga (2, 3)."""
    for i in range(2):
        if i == 0:
            ax, ay, az = AX0, AY0, AZ0
        else:
            ax, ay, az = AX1, AY1, AZ1
        wx, wy, wz = CX - tip[i, 0], CY - tip[i, 1], CZ - tip[i, 2]
        kap = 0.5 * (L * L - (wx * wx + wy * wy + wz * wz) - (ax * ax + ay * ay + az * az))
        qz0, qz1, qz2 = wz * 1.0, -wy * 2.0, wz * -1.0  # -wy T_S + wz T_C
        qy0, qy1, qy2 = wy * 1.0, wz * 2.0, wy * -1.0  # wy T_C + wz T_S
        al[i, 0] = wx * ax + az * qz0
        al[i, 1] = az * qz1
        al[i, 2] = wx * ax + az * qz2
        be[i, 0] = wx * az - ax * qz0
        be[i, 1] = -ax * qz1
        be[i, 2] = wx * az - ax * qz2
        ga[i, 0] = ay * qy0 - kap
        ga[i, 1] = ay * qy1
        ga[i, 2] = ay * qy2 - kap
    # det = al0 be1 - al1 be0, cc = be0 ga1 - be1 ga0, ss = al1 ga0 - al0 ga1 (degree 4); poly = cc^2 + ss^2 - det^2
    w = np.empty((3, 5))
    for k in range(5):
        w[0, k] = _rows_conv_k(al, 0, be, 1, 3, k) - _rows_conv_k(al, 1, be, 0, 3, k)
        w[1, k] = _rows_conv_k(be, 0, ga, 1, 3, k) - _rows_conv_k(be, 1, ga, 0, 3, k)
        w[2, k] = _rows_conv_k(al, 1, ga, 0, 3, k) - _rows_conv_k(al, 0, ga, 1, 3, k)
    for k in range(9):
        poly[k] = _rows_conv_k(w, 1, w, 1, 5, k) + _rows_conv_k(w, 2, w, 2, 5, k) - _rows_conv_k(w, 0, w, 0, 5, k)


@kernel(inline=True)
def _rows_conv_k(a, ra, b, rb, n, k):
    """Coefficient k of the product of the polynomials a[ra], b[rb] (n ascending coefficients each), summed over
    ascending i (rows indexed in place: no array views)."""
    s = 0.0
    for i in range(n):
        j = k - i
        if 0 <= j < n:
            s += a[ra, i] * b[rb, j]
    return s


@kernel(inline=True)
def roots_k(c, z):
    """Complex roots z (8,) of the polynomial c (9,) (ascending), NaN-padded: Aberth-Ehrlich iteration.

    Leading coefficients at the rounding level of the largest one lower the degree (roots beyond ~1e15: roll at
    pi, outside the platform limits); trailing ones at that level are roots at 0, taken exactly (mirror-symmetric
    motors make roll = 0 a double root, and the iteration started around the other roots would stall a few 1e-3
    away from it: seen at (roll, pitch) = (2.2e-16, 0.7768)). A non-finite polynomial has no roots. Returns the
    number of roots.
    """
    for j in range(8):
        z[j] = complex(math.nan, math.nan)
    cmax = 0.0
    for j in range(9):
        if not math.isfinite(c[j]):
            return 0
        cmax = max(cmax, abs(c[j]))
    floor = 1e-15 * cmax
    n = 8
    while n > 0 and abs(c[n]) <= floor:
        n -= 1
    if n == 0:
        return 0
    lo = 0
    while lo < n and abs(c[lo]) <= floor:
        z[lo] = complex(0.0, 0.0)
        lo += 1
    if lo == n:
        return n
    nz = roots_aberth_k(c[lo : n + 1], n - lo, z[lo:])
    return lo + nz


@kernel
def roots_aberth_k(c, n, z):
    """Aberth-Ehrlich iteration for the n roots z[:n] of c[:n + 1] (ascending, c[n] and c[0] nonzero)."""
    lead = c[n]
    # starting points on a circle: the geometric mean of the roots' moduli, at most Fujiwara's bound
    rad = 0.0
    for k in range(n):
        v = (abs(c[k] / lead) / (2.0 if k == 0 else 1.0)) ** (1.0 / (n - k))
        if v > rad:
            rad = v
    rad = 2.0 * rad
    if not (rad > 0.0 and math.isfinite(rad)):
        rad = 1.0
    g0 = abs(c[0] / lead) ** (1.0 / n)
    if g0 > 0.0 and g0 < rad:
        rad = g0
    zr = np.empty(8)
    zi = np.empty(8)
    for j in range(n):
        ang = _TWO_PI * j / n + 0.4
        zr[j], zi[j] = rad * math.cos(ang), rad * math.sin(ang)
    done = np.zeros(8, dtype=np.bool_)
    prev = np.full(8, math.inf)
    for _ in range(100):
        ndone = 0
        for j in range(n):
            if done[j]:
                ndone += 1
                continue
            xr, xi = zr[j], zi[j]
            pr, pi_ = c[n], 0.0
            dr, di = 0.0, 0.0
            for k in range(n - 1, -1, -1):
                dr, di = dr * xr - di * xi + pr, dr * xi + di * xr + pi_
                pr, pi_ = pr * xr - pi_ * xi + c[k], pr * xi + pi_ * xr
            if pr == 0.0 and pi_ == 0.0:
                done[j] = True
                continue
            # ratio = p / p'
            dd = dr * dr + di * di
            rr, ri = (pr * dr + pi_ * di) / dd, (pi_ * dr - pr * di) / dd
            sr, si = 0.0, 0.0
            for k in range(n):
                if k != j:
                    er, ei = xr - zr[k], xi - zi[k]
                    e2 = er * er + ei * ei
                    sr += er / e2
                    si -= ei / e2
            # w = ratio / (1 - ratio s)
            qr, qi = 1.0 - (rr * sr - ri * si), -(rr * si + ri * sr)
            q2 = qr * qr + qi * qi
            wr, wi = (rr * qr + ri * qi) / q2, (ri * qr - rr * qi) / q2
            if not (math.isfinite(wr) and math.isfinite(wi)):
                wr, wi = rr, ri
            zr[j], zi[j] = xr - wr, xi - wi
            # converged (cubically: the last correction leaves rounding only), or stalled at the rounding floor
            # of a (near-)multiple root, where the convergence is linear
            aw = math.hypot(wr, wi)
            az = math.hypot(xr, xi)
            if aw <= 1e-12 * az or (aw <= 1e-6 * az and aw >= 0.5 * prev[j]):
                done[j] = True
            prev[j] = aw
        if ndone == n:
            break
    for j in range(n):
        z[j] = complex(zr[j], zi[j])
    return n



@kernel
def rod_newton_k(x, tip, max_iter, keep_sign):
    """Damped Newton on both rod equations from x (2,) (in place; as in the numpy version of issue 15): each
    accepted step decreases max|g|; with keep_sign it also keeps the sign of det N of the start. Returns the
    rod-length error (m), inf where not finite."""
    g = np.empty(2)
    nm = np.empty((2, 2))
    gt = np.empty(2)
    nt = np.empty((2, 2))
    cur = rod_system_k(x[0], x[1], tip, g, nm)
    sign = sgn_k(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])
    act = math.isfinite(cur)
    for it in range(max_iter):
        if it == 8 and not (cur <= 1e-4 * L):
            act = False
        if not act:
            break
        det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
        s0 = -((nm[1, 1] * g[0] - nm[0, 1] * g[1]) / det)
        s1 = -((nm[0, 0] * g[1] - nm[1, 0] * g[0]) / det)
        fin = math.isfinite(s0) and math.isfinite(s1)
        if fin:
            s0 = min(max(s0, -0.3), 0.3)
            s1 = min(max(s1, -0.3), 0.3)
        else:
            s0 = 0.0
            s1 = 0.0
        smax = max(abs(s0), abs(s1))
        fin = fin and smax > 1e-16 * (1.0 + max(abs(x[0]), abs(x[1])))
        lam = 1.0
        acc = False
        if fin:
            for _ in range(16):
                xt0 = x[0] + lam * s0
                xt1 = x[1] + lam * s1
                ct = rod_system_k(xt0, xt1, tip, gt, nt)
                ok = ct < cur
                if keep_sign:
                    ok = ok and sgn_k(nt[0, 0] * nt[1, 1] - nt[0, 1] * nt[1, 0]) == sign
                if ok:
                    acc = True
                    x[0], x[1], cur = xt0, xt1, ct
                    g[0], g[1] = gt[0], gt[1]
                    nm[0, 0], nm[0, 1], nm[1, 0], nm[1, 1] = nt[0, 0], nt[0, 1], nt[1, 0], nt[1, 1]
                    break
                lam *= 0.5
        if not acc or smax * lam <= 1e-16:
            act = False
    gm = max(abs(g[0]), abs(g[1]))
    err = gm * 2.0 / (L + math.sqrt(max(2.0 * gm + L * L, 0.0)))
    return err if math.isfinite(err) else math.inf


@kernel(inline=True)
def null_k(nm, v):
    """Singular values (s_max, s_min) of N (2, 2) and the right singular vector v (2,) of s_min."""
    a = nm[0, 0] * nm[0, 0] + nm[1, 0] * nm[1, 0]
    b = nm[0, 0] * nm[0, 1] + nm[1, 0] * nm[1, 1]
    c = nm[0, 1] * nm[0, 1] + nm[1, 1] * nm[1, 1]
    h = math.sqrt(0.25 * (a - c) ** 2 + b * b)
    lmax = 0.5 * (a + c) + h
    smax = math.sqrt(lmax)
    det = abs(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])
    smin = det / smax if smax > 0.0 else 0.0
    lmin = smin * smin
    # eigenvector of N^T N for lmin: (b, lmin - a) or (lmin - c, b), the better conditioned
    v0, v1 = b, lmin - a
    u0, u1 = lmin - c, b
    if u0 * u0 + u1 * u1 > v0 * v0 + v1 * v1:
        v0, v1 = u0, u1
    nv = math.hypot(v0, v1)
    if nv > 0.0:
        v[0], v[1] = v0 / nv, v1 / nv
    elif a <= c:
        v[0], v[1] = 1.0, 0.0
    else:
        v[0], v[1] = 0.0, 1.0
    return smax, smin


@kernel(inline=True)
def quadratics_at_k(al, be, ga, t):
    """The per-rod quadratics al, be, ga (2, 3) of :func:`roll_poly_k` at t = tan(roll / 2): (a_0, a_1, b_0, b_1,
    g_0, g_1), rod i's equation in pitch being ``a_i cos(pitch) + b_i sin(pitch) = g_i`` (times (1 + t^2))."""
    return ((al[0, 2] * t + al[0, 1]) * t + al[0, 0], (al[1, 2] * t + al[1, 1]) * t + al[1, 0],
            (be[0, 2] * t + be[0, 1]) * t + be[0, 0], (be[1, 2] * t + be[1, 1]) * t + be[1, 0],
            (ga[0, 2] * t + ga[0, 1]) * t + ga[0, 0], (ga[1, 2] * t + ga[1, 1]) * t + ga[1, 0])


#: Most seeds per motor pair: 8 roots (x3 where the rod equations are parallel), and the fold seeds of each.
MAX_SEEDS = 24
MAX_SOL = MAX_SEEDS * (1 + 2 * len(FOLD_OFFSETS))
_FOLD = np.array(FOLD_OFFSETS)


@kernel
def seeds_k(tip, x0, imag):
    """Starting poses x0 (k, 2) for Newton from the roots of the degree-8 polynomial of the lever tips tip (2, 3): the
    roots with |roll| <= ~pi/2 (and nearly real complex pairs, imag (k,) their imaginary part), the pitch of each
    from the two rod equations (linear in cos, sin pitch), and where those equations are (nearly) parallel the two
    pitches that close the better-conditioned one. Returns k."""
    poly = np.empty(9)
    al = np.empty((2, 3))
    be = np.empty((2, 3))
    ga = np.empty((2, 3))
    roll_poly_k(tip, poly, al, be, ga)
    z = np.empty(8, dtype=np.complex128)
    nr = roots_k(poly, z)
    m = 0
    nbad = 0
    bad = np.empty((8, 4))  # roll, base, c, imag of the seeds whose rod equations are (nearly) parallel
    for j in range(nr):
        zr, zi = z[j].real, z[j].imag
        if not (math.isfinite(zr) and math.isfinite(zi)):
            continue
        if not (abs(zi) <= 1e-2 * (1.0 + abs(z[j])) and abs(zr) <= 1.0 + 1e-3):
            continue
        t = zr
        a0, a1, b0, b1, g0, g1 = quadratics_at_k(al, be, ga, t)
        det = a0 * b1 - a1 * b0
        cp = (b0 * g1 - b1 * g0) / det
        sp = (a1 * g0 - a0 * g1) / det
        roll = 2.0 * math.atan(t)
        pitch = math.atan2(sp, cp)
        x0[m, 0] = roll if math.isfinite(roll) else 0.0
        x0[m, 1] = pitch if math.isfinite(pitch) else 0.0
        imag[m] = abs(zi)
        m += 1
        if not (abs(det) > 1e-6 * (abs(a0 * b1) + abs(a1 * b0))):
            if math.hypot(a1, b1) > math.hypot(a0, b0):
                ak, bk, gk = a1, b1, g1
            else:
                ak, bk, gk = a0, b0, g0
            bad[nbad, 0] = roll
            bad[nbad, 1] = math.atan2(bk, ak)
            kc = -gk / math.hypot(ak, bk)
            bad[nbad, 2] = math.acos(min(max(kc, -1.0), 1.0)) if not math.isnan(kc) else math.nan
            bad[nbad, 3] = abs(zi)
            nbad += 1
    for sgn in (1.0, -1.0):
        for j in range(nbad):
            r_, p_ = bad[j, 0], bad[j, 1] + sgn * bad[j, 2]
            x0[m, 0] = r_ if math.isfinite(r_) else 0.0
            x0[m, 1] = p_ if math.isfinite(p_) else 0.0
            imag[m] = bad[j, 3]
            m += 1
    return m


@kernel
def polish_k(tip, x0, imag, nseed, tol, max_iter, x, err):
    """Newton on the rod equations from each seed x0[:nseed] into x, err (rod-length error, m); near the forward
    singularity also from both sides of each near-singular solution (or unconverged nearly real root), along the
    null vector of N, with the det N barrier. Returns the number of poses in x."""
    m = nseed
    g = np.empty(2)
    nm = np.empty((2, 2))
    v = np.empty(2)
    for j in range(nseed):
        x[j, 0], x[j, 1] = x0[j, 0], x0[j, 1]
        err[j] = rod_newton_k(x[j], tip, max_iter, False)
    # near the forward singularity: seeds on both sides of each near-singular solution (or unconverged nearly
    # real root), along the null vector of N, Newton with the det N barrier
    near = np.empty((MAX_SEEDS, 4))
    nnear = 0
    for j in range(nseed):
        if err[j] <= 1e-6:
            y0, y1 = x[j, 0], x[j, 1]
        else:
            y0, y1 = x0[j, 0], x0[j, 1]
        rod_system_k(y0, y1, tip, g, nm)
        for q in range(2):
            for r in range(2):
                if not math.isfinite(nm[q, r]):
                    nm[q, r] = 0.0
        smax, smin = null_k(nm, v)
        if err[j] <= tol:
            isnear = smin < 1e-3 * max(smax, 1e-300)
        else:
            isnear = imag[j] <= 1e-4
        if isnear:
            near[nnear, 0], near[nnear, 1], near[nnear, 2], near[nnear, 3] = y0, y1, v[0], v[1]
            nnear += 1
    for h in _FOLD:
        for sgn in (1.0, -1.0):
            for j in range(nnear):
                x[m, 0] = near[j, 0] + sgn * h * near[j, 2]
                x[m, 1] = near[j, 1] + sgn * h * near[j, 3]
                err[m] = rod_newton_k(x[m], tip, max_iter, True)
                m += 1
    return m


@kernel
def label_k(tip, dtip, x, err, m, tol, xs, bl, sdet):
    """The poses x[:m] within the joint limits that close both rods within tol, into xs, with their motor branch
    bl (0 on a chain's reach boundary) and sign of det N sdet. Returns their number."""
    g = np.empty(2)
    nm = np.empty((2, 2))
    kk = np.empty(2)
    th = np.empty(2)
    rot = np.empty((3, 3))
    out = 0
    for j in range(m):
        r_, p_ = wrap_k(x[j, 0]), wrap_k(x[j, 1])
        if not (err[j] <= tol and abs(r_) <= PLATFORM_LIMIT + LIMIT_TOL and abs(p_) <= PLATFORM_LIMIT + LIMIT_TOL):
            continue
        r_ = min(max(r_, -PLATFORM_LIMIT), PLATFORM_LIMIT)
        p_ = min(max(p_, -PLATFORM_LIMIT), PLATFORM_LIMIT)
        rot_k(r_, p_, rot)
        chain_k(rot, 0, 1.0, K_TOL, th, kk)
        chain_k(rot, 1, 1.0, K_TOL, th, kk)
        rod_system_k(r_, p_, tip, g, nm)
        xs[out, 0], xs[out, 1] = r_, p_
        cr, sr, cp, sp = math.cos(r_), math.sin(r_), math.cos(p_), math.sin(p_)
        for i in range(2):
            sg = 1.0 if i == 0 else -1.0
            dd = rod_rate_k(i, cr, sr, cp, sp, tip, dtip)
            bl[out, i] = 0.0 if abs(abs(kk[i]) - 1.0) <= BOUNDARY_TOL else -sg * sgn_k(dd)
        sdet[out] = sgn_k(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])
        out += 1
    return out



@kernel(inline=True)
def solutions_k(t1, t2, tol, max_iter, xs, bl, sdet):
    """Every platform pose within the joint limits closing both rods for motors (t1, t2): xs (m, 2), motor
    branch bl (m, 2) (0 on a chain's reach boundary), sign det N sdet (m,). Returns m (duplicates possible).

    The roots of the degree-8 polynomial in tan(roll / 2) with |roll| <= ~pi/2 (and nearly real complex pairs),
    their pitch from the two rod equations (linear in cos, sin pitch), each polished by Newton; near the forward
    singularity, extra Newton runs from both sides of each near-singular solution with the det N barrier.
    """
    tip, dtip = lever_tips_k(t1, t2)
    x0 = np.empty((MAX_SOL, 2))
    imag = np.empty(MAX_SOL)
    nseed = seeds_k(tip, x0, imag)
    x = np.empty((MAX_SOL, 2))
    err = np.empty(MAX_SOL)
    m = polish_k(tip, x0, imag, nseed, tol, max_iter, x, err)
    return label_k(tip, dtip, x, err, m, tol, xs, bl, sdet)
