"""The study's compiled kernels: the conditioning of a Jacobian, the twist of a rotation, and the known-answer
planar 2-link leg (:mod:`legkin.study.targets`). Each is a scalar kernel beside its formula and a compiled batch
loop over it (CONTRIBUTING.md, "one implementation, compiled")."""

from __future__ import annotations

import math

from .._kernels import batch_kernel, kernel

__all__ = ["COND_CAP"]

#: Largest condition number the Gram-matrix eigenvalues resolve: kappa^2 = lambda_max / lambda_min loses
#: log10(kappa^2) digits of lambda_min's 16, so kappa above 1e6 (lambda ratio 1e12) is reported as COND_CAP
#: (counted as singular by any threshold below it, in the top bin of the histogram).
COND_CAP = 1.0e6


@kernel(inline=True)
def _k_sym3_eig_extremes(a00, a01, a02, a11, a12, a22):  # type: ignore[no-untyped-def]
    """Smallest and largest eigenvalue of the symmetric 3 x 3 matrix [[a00, a01, a02], [., a11, a12], [., ., a22]]:
    the trigonometric closed form of the characteristic cubic (Smith 1961): with q = tr/3, p = sqrt(|A - qI|_F^2/6),
    B = (A - qI)/p, r = det(B)/2, phi = acos(r)/3: eigenvalues q + 2p cos(phi + 2 pi k/3), k = 0 (largest), 1
    (smallest)."""
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    q = (a00 + a11 + a22) / 3.0
    b00, b11, b22 = a00 - q, a11 - q, a22 - q
    p2 = b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * p1
    if p2 <= 0.0:
        return q, q
    p = math.sqrt(p2 / 6.0)
    det = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02) + a02 * (a01 * a12 - b11 * a02)
    r = det / (2.0 * p * p * p)
    r = min(max(r, -1.0), 1.0)
    phi = math.acos(r) / 3.0
    top = q + 2.0 * p * math.cos(phi)
    low = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    return max(low, 0.0), top


@kernel
def _k_gram_extremes(J, m, k):  # type: ignore[no-untyped-def]
    """Smallest and largest eigenvalue (sigma_min^2, sigma_max^2) of the Gram matrix G = J^T J of the m x k matrix J
    (row-major, k in 1..3): 2 x 2 in closed form (lambda = t/2 -+ sqrt(t^2/4 - det)), 3 x 3 by
    :func:`_k_sym3_eig_extremes`. NaN when J has a NaN."""
    g00 = g01 = g02 = g11 = g12 = g22 = 0.0
    for r in range(m):
        a = J[r * k]
        b = J[r * k + 1] if k > 1 else 0.0
        c = J[r * k + 2] if k > 2 else 0.0
        g00 += a * a
        g01 += a * b
        g02 += a * c
        g11 += b * b
        g12 += b * c
        g22 += c * c
    if k == 1:
        return g00, g00
    if k == 2:
        half = 0.5 * (g00 + g11)
        disc = math.sqrt(max(half * half - (g00 * g11 - g01 * g01), 0.0))
        return max(half - disc, 0.0), half + disc
    return _k_sym3_eig_extremes(g00, g01, g02, g11, g12, g22)


def _stats_loop(J, m, k, ok, eps, step, top_bin, bins):  # type: ignore[no-untyped-def]
    """The histogram bin of log10 kappa (kappa = sqrt(lambda_max / lambda_min), :func:`_k_gram_extremes`) of each
    row of J (n, m * k) into bins (n,): floor(log10 kappa / step), capped at top_bin - 1, top_bin where kappa >=
    COND_CAP, top_bin + 1 where the row is not reached (ok False) or J is not finite. Returns the number of reached
    rows with 1/kappa <= eps (lambda_min <= eps^2 lambda_max)."""
    singular = 0
    cap2 = COND_CAP * COND_CAP
    for i in range(J.shape[0]):
        if not ok[i]:  # unreached: no Jacobian to condition
            bins[i] = top_bin + 1
            continue
        low, top = _k_gram_extremes(J[i], m, k)
        if not (top == top and low == low):
            bins[i] = top_bin + 1
            continue
        if low <= eps * eps * top:
            singular += 1
        if low * cap2 <= top:
            bins[i] = top_bin
        else:
            bins[i] = min(int(0.5 * math.log10(top / low) / step), top_bin - 1)
    return singular


STATS = batch_kernel(rows="J ok bins", min_parallel=16384)(_stats_loop)


@kernel
def _k_twist_x(R):  # type: ignore[no-untyped-def]
    """Twist of the rotation R (row-major 3 x 3) about the body x axis, |psi| in [0, pi] (rad): the swing-twist
    decomposition R = R_swing Rx(psi), R_swing about an axis perpendicular to x; from R's unit quaternion
    (w, x, y, z), psi = 2 atan2(x, w) = 2 atan2(R_21 - R_12, 1 + tr R). Zero for a constant-velocity (zero-torsion)
    rotation."""
    return abs(2.0 * math.atan2(R[7] - R[5], 1.0 + R[0] + R[4] + R[8]))


def _twist_loop(R, out):  # type: ignore[no-untyped-def]
    """|twist| of each rotation R (n, 9) into out (n,) (:func:`_k_twist_x`)."""
    for i in range(R.shape[0]):
        out[i] = _k_twist_x(R[i])


TWIST = batch_kernel(rows="R out", min_parallel=16384)(_twist_loop)


@kernel
def _k_planar_ik(x, y, l1, l2, q):  # type: ignore[no-untyped-def]
    """IK of the planar 2-link leg (elbow branch q2 >= 0): ``cos q2 = (x^2 + y^2 - l1^2 - l2^2) / (2 l1 l2)``,
    ``q1 = atan2(y, x) - atan2(l2 sin q2, l1 + l2 cos q2)``. Returns False outside the annulus |l1 - l2| <= r <=
    l1 + l2 (q untouched)."""
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    if not (-1.0 <= c2 <= 1.0):
        return False
    s2 = math.sqrt(1.0 - c2 * c2)
    q[1] = math.atan2(s2, c2)
    q[0] = math.atan2(y, x) - math.atan2(l2 * s2, l1 + l2 * c2)
    return True


@kernel
def _k_planar_jacobian(q1, q2, l1, l2, J):  # type: ignore[no-untyped-def]
    """Jacobian d(x, y)/d(q1, q2) of ``(x, y) = (l1 c1 + l2 c12, l1 s1 + l2 s12)``, row-major 2 x 2 (m/rad)."""
    s1, c1, s12, c12 = math.sin(q1), math.cos(q1), math.sin(q1 + q2), math.cos(q1 + q2)
    J[0], J[1] = -l1 * s1 - l2 * s12, -l2 * s12
    J[2], J[3] = l1 * c1 + l2 * c12, l2 * c12


def _planar_loop(target, l1, l2, q, J, ok):  # type: ignore[no-untyped-def]
    """IK and Jacobian of the planar 2-link leg over targets (n, 2): q (n, 2), J (n, 4), ok (n,) (NaN rows where
    unreachable); returns the number solved."""
    count = 0
    for i in range(target.shape[0]):
        ok[i] = _k_planar_ik(target[i, 0], target[i, 1], l1, l2, q[i])
        if ok[i]:
            _k_planar_jacobian(q[i, 0], q[i, 1], l1, l2, J[i])
            count += 1
        else:
            for j in range(2):
                q[i, j] = math.nan
            for j in range(4):
                J[i, j] = math.nan
    return count


PLANAR = batch_kernel(rows="target q J ok", min_parallel=16384)(_planar_loop)
