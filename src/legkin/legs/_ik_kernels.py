"""Closed-form inverse kinematics kernels of an HAA-HFE-KFE leg (every branch, the branch inside the limits)
and the damped Newton polish on the exact forward map (see :mod:`legkin.legs.kinematics`), scalar and batch."""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_kernel, kernel, prange
from ._fk_kernels import _finite_k, _fk3_k, _jac3_t
from ._layout import (
    _ARC,
    _BAD_INPUT,
    _CD,
    _D,
    _E1,
    _E2,
    _E3,
    _H,
    _HI,
    _IDEAL,
    _IN_CYLINDER,
    _INV_TWO_PI,
    _JOINT_LIMIT,
    _K,
    _KN,
    _L,
    _LN,
    _LO,
    _NAN,
    _NARROW,
    _O,
    _PK,
    _PL,
    _POLISH_DONE,
    _REF,
    _S3,
    _SD,
    _SLACK,
    _TOO_FAR,
    _TOO_NEAR,
    _TWO_PI,
    _UNREACHABLE,
    _WHOLE,
    CANDIDATE_SLACK,
    IK_TOL,
    LIMIT_SLACK,
    LIMIT_TOL,
    POLISH_DAMPING,
    POLISH_STEPS,
    REACH_TOL,
    WELL_CONDITIONED,
)

_LAM2_MAX = POLISH_DAMPING * POLISH_DAMPING
_HALF_PI = 0.5 * math.pi


@kernel(inline=True)
def _atan2_k(y, x):
    """``atan2(y, x)`` (rad, in ``[-pi, pi]``) from one ``atan`` of a ratio of magnitude <= 1: ``atan(y / x)``, plus
    ``+-pi`` (the sign of ``y``) when ``x < 0``, or ``+-pi/2 - atan(x / y)`` when ``|y| > |x|``. glibc's ``atan2``
    costs ~17 ns, its ``atan`` on [-1, 1] ~4 ns and a division ~1 ns: the closed-form IK's three angles (q1, q2
    and the knee's ``beta``) took half of a batch ``ik``'s time. Within 1-2 ulp of ``math.atan2`` (the ratio's
    rounding, then the sum with the rounded ``pi`` or ``pi/2``); signed zeros, infinities and NaN as
    ``math.atan2`` (``x`` zero or infinite and ``|y| <= |x|``: ``math.atan2`` itself)."""
    ax, ay = abs(x), abs(y)
    if ay <= ax:
        if not 0.0 < ax < math.inf:
            return math.atan2(y, x)
        a = math.atan(y / x)
        return a + math.copysign(math.pi, y) if x < 0.0 else a
    return math.copysign(_HALF_PI, y) - math.atan(x / y)


@kernel
def _polish_k(px, py, pz, g, q0, q1, q2, fixed):
    """At most :data:`POLISH_STEPS` damped Newton steps on the exact forward map while the foot error exceeds
    :data:`POLISH_BELOW`, each kept only if it reduces the error: ``e = p - fk(q)``,
    ``dq = J^T (J J^T + lambda^2 I)^-1 e``, ``lambda`` from :data:`POLISH_DAMPING`, divided by 10 after a kept
    step and multiplied by 10 after a refused one, up to :data:`POLISH_DAMPING` (Levenberg-Marquardt): with a fixed
    ``lambda``, a direction whose singular value ``sigma << lambda`` gains only ``sigma^2 / lambda^2`` a step (hyq
    near its HAA cylinder, sigma 7e-9: 2.4e-12 m left after the steps).

    The closed form is exact for the ideal structure (a1 perpendicular to a2 = +-a3); URDF angles written
    with 11 digits (``rpy="0 1.57079632679 0"``) leave axes ~5e-12 off, i.e. ~1e-12 m at the foot, and near the
    fold of the knee (|w| -> 0 when |k| = |l|) the law of cosines loses digits: the steps remove both.
    ``fixed`` (bits 1, 2, 4 for q1, q2, q3): joints held where they are (their Jacobian columns zeroed).
    Scalars in (the target ``(px, py, pz)``), scalars out: returns the polished ``(q1, q2, q3)`` and the final foot
    error ``|e|`` (m).
    """
    fx, fy, fz = _fk3_k(q0, q1, q2, g)
    ex, ey, ez = px - fx, py - fy, pz - fz
    err = ex * ex + ey * ey + ez * ez
    lam2 = POLISH_DAMPING * POLISH_DAMPING
    f0, f1, f2 = (fixed & 1) == 0, (fixed & 2) == 0, (fixed & 4) == 0
    for _ in range(POLISH_STEPS):
        if err <= _POLISH_DONE:
            break
        j00, j01, j02, j10, j11, j12, j20, j21, j22 = _jac3_t(q0, q1, q2, g)
        if not f0:
            j00 = j10 = j20 = 0.0
        if not f1:
            j01 = j11 = j21 = 0.0
        if not f2:
            j02 = j12 = j22 = 0.0
        # A = J J^T + lam^2 I (symmetric positive definite), solve A y = e by the adjugate, dq = J^T y
        a00 = j00 * j00 + j01 * j01 + j02 * j02 + lam2
        a11 = j10 * j10 + j11 * j11 + j12 * j12 + lam2
        a22 = j20 * j20 + j21 * j21 + j22 * j22 + lam2
        a01 = j00 * j10 + j01 * j11 + j02 * j12
        a02 = j00 * j20 + j01 * j21 + j02 * j22
        a12 = j10 * j20 + j11 * j21 + j12 * j22
        c00, c11, c22 = a11 * a22 - a12 * a12, a00 * a22 - a02 * a02, a00 * a11 - a01 * a01
        c01, c02, c12 = a02 * a12 - a01 * a22, a01 * a12 - a02 * a11, a01 * a02 - a00 * a12
        det = a00 * c00 + a01 * c01 + a02 * c02
        if not det > 0.0:
            break
        yx = (c00 * ex + c01 * ey + c02 * ez) / det
        yy = (c01 * ex + c11 * ey + c12 * ez) / det
        yz = (c02 * ex + c12 * ey + c22 * ez) / det
        n0 = q0 + j00 * yx + j10 * yy + j20 * yz
        n1 = q1 + j01 * yx + j11 * yy + j21 * yz
        n2 = q2 + j02 * yx + j12 * yy + j22 * yz
        fx, fy, fz = _fk3_k(n0, n1, n2, g)
        nx, ny, nz = px - fx, py - fy, pz - fz
        new = nx * nx + ny * ny + nz * nz
        if not new < err:  # refused: more damping (Levenberg-Marquardt), up to POLISH_DAMPING again
            if lam2 >= _LAM2_MAX:
                break
            lam2 = min(lam2 * 100.0, _LAM2_MAX)
            continue
        q0, q1, q2 = n0, n1, n2
        ex, ey, ez, err = nx, ny, nz, new
        lam2 *= 0.01  # kept: less damping, so that a direction of singular value << lambda converges too
    return q0, q1, q2, math.sqrt(err)


@kernel
def _settle_k(px, py, pz, g, q0, q1, q2):
    """A closed-form branch that is not well-conditioned on the exact ideal structure (see
    :data:`WELL_CONDITIONED`: the callers return those as they are, without a call) polished
    (:func:`_polish_k`); if its foot error stays above :data:`REACH_TOL` (near a
    fold of the ideal structure, where Newton stalls) it is restarted off the fold, each joint moved by
    ``+-eta = +-4 sqrt(|e| / min(|k|, |l|))`` in turn, keeping the best. Returns ``(q1, q2, q3, |e|)``."""
    q0, q1, q2, res = _polish_k(px, py, pz, g, q0, q1, q2, 0)
    if res <= REACH_TOL:
        return q0, q1, q2, res
    eta = 4.0 * math.sqrt(res / min(g[_KN], g[_LN]))
    b0, b1, b2 = q0, q1, q2
    for jr in range(6):
        step = eta if jr % 2 == 0 else -eta
        d0 = step if jr < 2 else 0.0
        d1 = step if jr // 2 == 1 else 0.0
        d2 = step if jr > 3 else 0.0
        t0, t1, t2, rt = _polish_k(px, py, pz, g, b0 + d0, b1 + d1, b2 + d2, 0)
        if rt < res:
            q0, q1, q2, res = t0, t1, t2, rt
        if res <= REACH_TOL:
            break
    return q0, q1, q2, res


@kernel
def _target_k(px, py, pz, g):
    """The target in the abduction frame: ``x1 = p'.e1``, ``t = sqrt(t2)`` and ``t2 = max(y^2 + z^2 - d^2, 0)``
    (0 inside the cylinder), ``(y, z)``, ``cyl = |d| - r`` (> 0: inside the abduction cylinder), with ``p' = p -
    o1``, and whether the leg has the exact ideal structure with ``t >= WELL_CONDITIONED r`` (away from the
    abduction singularity: see :data:`WELL_CONDITIONED`). ``t2`` from ``r^2`` directly, not from ``r`` (``r``
    is off the path to the angles: one square root fewer in a row's chain of dependent operations)."""
    px, py, pz = px - g[_O], py - g[_O + 1], pz - g[_O + 2]
    x1 = px * g[_E1] + py * g[_E1 + 1] + pz * g[_E1 + 2]
    y = px * g[_E2] + py * g[_E2 + 1] + pz * g[_E2 + 2]
    z = px * g[_E3] + py * g[_E3 + 1] + pz * g[_E3 + 2]
    ad = abs(g[_D])
    r2 = y * y + z * z
    r = math.sqrt(r2)  # (hypot costs ~7x a sqrt; no overflow at leg scales)
    t2 = max(r2 - ad * ad, 0.0)
    t = math.sqrt(t2)
    return x1, t, t2, (y, z), ad - r, g[_IDEAL] > 0.0 and t >= WELL_CONDITIONED * r


@kernel(inline=True)
def _abduction_vec_k(g, ia, t, yz):
    """Abduction branch ``ia`` (0: ``s_a = -1``, 1: ``+1``): ``u3 = s_a t`` and the vector ``(c, s)`` whose angle is
    ``q1 = atan2(z, y) - atan2(u3, d)`` (the angle from ``(d, u3)`` to ``(y, z)``): ``c = d y + u3 z``,
    ``s = d z - u3 y``."""
    u3 = t if ia == 1 else -t
    d, y, z = g[_D], yz[0], yz[1]
    return u3, d * y + u3 * z, d * z - u3 * y


@kernel
def _abduction_k(g, ia, t, yz):
    """Abduction branch ``ia``: ``u3`` and ``q1`` (one ``atan2`` of :func:`_abduction_vec_k`'s vector)."""
    u3, c, s = _abduction_vec_k(g, ia, t, yz)
    return u3, _atan2_k(s, c)


@kernel(inline=True)
def _on_arc_k(g, c, s) -> bool:
    """Whether the angle of the vector ``(c, s)`` lies on the HAA limits' arc widened by :data:`ARC_SLACK`
    (:data:`_ARC`): by the signs of cross products with the arc's ends, no angle computed. The zero vector passes."""
    kind = g[_ARC + 4]
    if kind == _WHOLE:
        return True
    after_a = g[_ARC] * s - g[_ARC + 1] * c  # e_a x v
    before_b = c * g[_ARC + 3] - s * g[_ARC + 2]  # v x e_b
    if kind == _NARROW:
        return after_a >= 0.0 and before_b >= 0.0
    return after_a >= 0.0 or before_b >= 0.0


@kernel
def _pitch_k(g, x1, u3, t2):
    """The pitch-plane vector ``w = (u3, x1) - h``, its miss of the knee's reach ``max(|w| - |k| - |l|,
    | |k| - |l| | - |w|)`` (m, <= 0 inside), whether it is beyond full stretch, the knee's
    ``cs = (cos beta, |sin beta|)`` with ``cos beta = (|w|^2 - |k|^2 - |l|^2) / (2 |k||l|)`` (clipped to [-1, 1])
    and ``acos(cos beta) = atan2(|sin beta|, cos beta)``, and whether ``|w| >= WELL_CONDITIONED (|k| + |l|)``
    (away from the knee's fold). With ``h_X = 0``, ``|w|^2 = t2 + w_Y^2`` (``u3^2 = t2``: no square root between
    the target and ``cos beta``)."""
    kn, ln = g[_KN], g[_LN]
    wx, wy = u3 - g[_H], x1 - g[_H + 1]
    w2 = (t2 if g[_H] == 0.0 else wx * wx) + wy * wy
    wn = math.sqrt(w2)
    far = wn - (kn + ln)
    near = abs(kn - ln) - wn
    c = (w2 - kn * kn - ln * ln) / (2.0 * kn * ln)
    c = 1.0 if c > 1.0 else (-1.0 if c < -1.0 else c)
    sb = math.sqrt((1.0 - c) * (1.0 + c))
    clean = wn >= WELL_CONDITIONED * (kn + ln)
    return wx, wy, (far if far > near else near), far > near, (c, sb), _atan2_k(sb, c), clean


@kernel
def _knee_k(g, ik, acb):
    """Knee branch ``ik`` (0: ``s_k = -1``, 1: ``+1``): ``q3 = s3 a`` with ``a = beta - phi_l + phi_k``,
    ``beta = s_k acb``."""
    return g[_S3] * ((acb if ik == 1 else -acb) - g[_PL] + g[_PK])


@kernel
def _hip_k(g, ik, wx, wy, cs):
    """Hip pitch of knee branch ``ik``: ``q2 = atan2(w) - atan2(v)`` (one ``atan2``: the angle from ``v`` to ``w``)
    with ``v = k + Rot(a) l``; ``cos a`` and ``sin a`` from ``cs = (cos beta, |sin beta|)`` of :func:`_pitch_k`
    (``sin beta`` of sign ``s_k``) and the stored ``cos, sin (phi_k - phi_l)`` (no trigonometric call)."""
    c, sb = cs
    if ik == 0:
        sb = -sb
    ca = c * g[_CD] - sb * g[_SD]
    sa = sb * g[_CD] + c * g[_SD]
    vx = g[_K] + ca * g[_L] - sa * g[_L + 1]
    vy = g[_K + 1] + sa * g[_L] + ca * g[_L + 1]
    return _atan2_k(vx * wy - vy * wx, vx * wx + vy * wy)


@kernel
def _near_k(a, r):
    """The representative ``a + 2 pi n`` nearest ``r``: ``a`` itself when ``|r - a| < pi`` (a compare off the
    critical path: the common case of an angle from ``atan2`` and a reference inside the limits)."""
    d = r - a
    if abs(d) < math.pi:
        return a
    return a + _TWO_PI * np.floor(d * _INV_TWO_PI + 0.5)  # (np.floor: a float, math.floor rounds through an int)


@kernel
def _ik_all_core(px, py, pz, g, r0, r1, r2, tol, out, flip):
    """Every branch (rows in :data:`BRANCHES` order, NaN rows for absent ones) of the target ``p = (px, py, pz)``
    into ``out`` (4, 3) (branch ``b`` into row ``b ^ flip``: 0, or a caller's own order, as the quadruped's seed
    order), each angle nearest the reference ``(r0, r1, r2)`` (scalars: a call passing arrays costs
    their reference counts, a third of the kernel's time).

    ``r^2 = y^2 + z^2``, ``u3 = s_a sqrt(r^2 - d^2)``, ``q1 = atan2(z, y) - atan2(u3, d)``;
    ``w = (u3, x1) - h``, ``cos beta = (|w|^2 - |k|^2 - |l|^2) / (2 |k||l|)``, ``beta = s_k acos(.)``,
    ``q3 = s3 (beta - phi_l + phi_k)``, ``q2 = atan2(w) - atan2(k + Rot(s3 q3) l)``. Each branch is then
    polished on the exact forward map (:func:`_settle_k`) and each angle moved to its 2 pi representative
    nearest ``ref``. A target up to ``tol`` (m) outside the reachable set is solved at its nearest reachable point
    (the clamped closed form, polished); a branch clamped onto its reach is dropped when the other abduction branch
    reaches the target exactly (:func:`_drop_projected_k`). Returns ``(status, miss, reason)``: on failure the
    miss (m) and its reason.
    """
    for b in range(4):
        out[b, 0] = out[b, 1] = out[b, 2] = _NAN
    if not (_finite_k(px, py, pz) and _finite_k(r0, r1, r2)):
        return _BAD_INPUT, 0.0, 0.0
    x, t, t2, yz, cyl, clean_a = _target_k(px, py, pz, g)
    slack = g[_SLACK] - REACH_TOL + tol  # the ideal structure's deviation bound, plus tol
    if cyl > slack:
        return _UNREACHABLE, cyl, _IN_CYLINDER
    best, why = math.inf, 0.0
    if cyl > tol:
        best, why = cyl, _IN_CYLINDER
    found = 0
    pitched, far, clean_w = False, False, False  # the pitch-plane quantities computed (for one abduction branch)
    wx = wy = miss = acb = 0.0
    cs = (0.0, 0.0)
    projected, exact = 0, False  # bits of the abduction branches written clamped onto their reach; one exact
    for ia in range(2):
        u3, q1 = _abduction_k(g, ia, t, yz)
        if not pitched or g[_H] != 0.0:  # h_X = 0: |w|, so the knee, is the same on both abduction branches
            wx, wy, miss, far, cs, acb, clean_w = _pitch_k(g, x, u3, t2)
            pitched = True
        wx = u3 - g[_H]
        reason = _TOO_FAR if far else _TOO_NEAR
        if miss > slack:
            if miss < best:
                best, why = miss, reason
            continue
        # within the slack of the ideal structure's boundary: kept only if the exact foot error is <= tol
        check = cyl > tol or miss > tol
        for ik in range(2):
            j1, j2, j3 = q1, _hip_k(g, ik, wx, wy, cs), _knee_k(g, ik, acb)
            if not (clean_a and clean_w and not check):  # (a call with arrays costs their reference counts)
                j1, j2, j3, res = _settle_k(px, py, pz, g, j1, j2, j3)
                if check and res > tol:  # clamped onto the ideal structure's boundary, and missing the target
                    if cyl <= tol and res < best:
                        best, why = res, reason
                    continue
            b = (2 * ia + ik) ^ flip
            out[b, 0], out[b, 1], out[b, 2] = _near_k(j1, r0), _near_k(j2, r1), _near_k(j3, r2)
            found += 1
            if miss > g[_SLACK]:
                projected |= 1 << ia
            else:
                exact = True
    if exact and projected:  # an exact branch beats a clamped one (h_X != 0: the branches' reaches differ)
        found -= _drop_projected_k(out, projected, flip)
    if found == 0:
        return _UNREACHABLE, best, why
    return OK, 0.0, 0.0


@kernel
def _drop_projected_k(out, bits, flip) -> int:
    """NaN the rows of the abduction branches in ``bits`` (bit ``ia``): a target that one abduction branch reaches
    exactly is not solved by the other's nearest reachable point (with ``h_X != 0`` their reaches differ, and a
    target on one's boundary lies up to ``tol`` outside the other's). Returns the number of rows cleared."""
    n = 0
    for ia in range(2):
        if bits & (1 << ia):
            for ik in range(2):
                b = (2 * ia + ik) ^ flip
                if out[b, 0] == out[b, 0]:
                    n += 1
                out[b, 0] = out[b, 1] = out[b, 2] = _NAN
    return n


@kernel(inline=True)
def _within_k(a, r, lo, hi, tol):
    """The representative ``a + 2 pi n`` inside ``[lo, hi]`` (slack ``tol``, then clipped) nearest ``r``; NaN if
    none. Also returns the distance to the limits of the nearest representative (0 when inside) and whether the
    one returned was clipped. Limits narrower than 2 pi - 2 ``tol`` hold one representative at most: ``a`` itself
    when it lies inside (returned as it is), none when ``a`` lies in a gap between the window ``[lo - tol, hi +
    tol]`` and its copy 2 pi away (NaN and the distance to the nearer copy, no ``floor``)."""
    if hi - lo < _TWO_PI - 2.0 * tol:
        if a >= lo and a <= hi:
            return a, 0.0, False
        if a > hi + tol and a < lo - tol + _TWO_PI:
            return _NAN, min(a - hi, lo + _TWO_PI - a), False
        if a < lo - tol and a > hi + tol - _TWO_PI:
            return _NAN, min(lo - a, a + _TWO_PI - hi), False
    rc = lo if r < lo else (hi if r > hi else r)
    base = _near_k(a, rc)
    best, dist, miss, clipped = _NAN, math.inf, math.inf, False
    for n in range(-1, 2):
        x = base + _TWO_PI * n
        out_by = lo - x if x < lo else (x - hi if x > hi else 0.0)
        if out_by < miss:
            miss = out_by
        if out_by <= tol:
            x = lo if x < lo else (hi if x > hi else x)
            if abs(x - r) < dist:
                best, dist, clipped = x, abs(x - r), out_by > 0.0
    return best, miss, clipped


@kernel(inline=True)
def _in_limits_k(a, r, lo, hi):
    """:func:`_within_k` with the slack :data:`LIMIT_TOL`: the representative and the distance."""
    x, miss, _clipped = _within_k(a, r, lo, hi, LIMIT_TOL)
    return x, miss


@kernel
def _repair_k(px, py, pz, g, q, r0, r1, r2) -> bool:
    """A branch ``q`` (3,) at most :data:`LIMIT_SLACK` outside the limits, moved into them (rare path): each angle
    at its representative nearest ``ref = (r0, r1, r2)`` clipped onto the limits, the joints left alone re-solved by
    :func:`_polish_k` with the clipped ones fixed (a joint the steps push outside is clipped and fixed in turn, as
    when a target is made with two joints on their limits); kept (True, ``q`` overwritten) if it reproduces ``p``
    within :data:`REACH_TOL`. Near the abduction singularity (foot on the cylinder ``r = |d|``) a branch's q1 errs
    by up to ~1e-8 rad along the singular direction while its foot is exact: a target made with q1 on its limit
    then comes back outside it, and the other joints absorb the clip."""
    fixed, ref = 0, (r0, r1, r2)
    for j in range(3):
        lo, hi = g[_LO + j], g[_HI + j]
        x = _near_k(q[j], lo if ref[j] < lo else (hi if ref[j] > hi else ref[j]))
        for n in range(-1, 2):
            y = x + _TWO_PI * n
            if y >= lo - LIMIT_SLACK and y <= hi + LIMIT_SLACK:
                x = y
        if x < lo or x > hi:
            x = lo if x < lo else hi
            fixed |= 1 << j
        q[j] = x
    for _ in range(3):  # a free joint the steps push outside its limits is clipped and fixed in turn
        q[0], q[1], q[2], res = _polish_k(px, py, pz, g, q[0], q[1], q[2], fixed)
        inside = True
        for j in range(3):
            lo, hi = g[_LO + j], g[_HI + j]
            if q[j] < lo or q[j] > hi:
                q[j] = lo if q[j] < lo else hi
                fixed |= 1 << j
                inside = False
        if inside:
            return res <= REACH_TOL
    return False


@kernel
def _accept_k(px, py, pz, g, j1, j2, j3, r0, r1, r2):
    """A polished branch ``(j1, j2, j3)`` of the target ``(px, py, pz)`` put inside the limits: each angle at its
    representative inside them nearest ``(r0, r1, r2)``; a branch up to :data:`LIMIT_SLACK` outside is moved into
    them by :func:`_repair_k` (rare path), failing that one up to :data:`LIMIT_TOL` outside is kept clipped onto
    them. Returns ``(ok, violation, x1, x2, x3)``: whether it is kept, by how much (rad) it was outside, and the
    angles kept."""
    x0, m0 = _in_limits_k(j1, r0, g[_LO], g[_HI])
    x1, m1 = _in_limits_k(j2, r1, g[_LO + 1], g[_HI + 1])
    x2, m2 = _in_limits_k(j3, r2, g[_LO + 2], g[_HI + 2])
    m = max(m0, max(m1, m2))
    if m > LIMIT_SLACK:
        return False, m, x0, x1, x2
    if m > 0.0:  # a hair outside the limits: moved into them, the free joints re-solved (rare path)
        qr = np.empty(3)  # the rare path allocates its own scratch
        qr[0], qr[1], qr[2] = j1, j2, j3
        if _repair_k(px, py, pz, g, qr, r0, r1, r2):
            return True, m, qr[0], qr[1], qr[2]
        if not (np.isfinite(x0) and np.isfinite(x1) and np.isfinite(x2)):
            return False, m, x0, x1, x2
    return True, m, x0, x1, x2


@kernel
def _ik_every_k(px, py, pz, g, r0, r1, r2, tol):
    """:func:`_ik_core`'s complete path: every branch of :func:`_ik_all_core` (all polished) put inside the limits
    by :func:`_accept_k`, the one nearest ``ref = (r0, r1, r2)`` kept (least sum of squared joint differences; ties
    to the earlier branch). Returns ``(status, info0, info1, q1, q2, q3)``: the miss (m) and reason, or the least
    limit violation (rad) and the number of geometric branches; the angles (NaN unless solved)."""
    qa = np.empty((4, 3))  # the rare path allocates
    status, i0, i1 = _ik_all_core(px, py, pz, g, r0, r1, r2, tol, qa, 0)
    if status != OK:
        return status, i0, i1, _NAN, _NAN, _NAN
    best, viol, nb = math.inf, math.inf, 0
    y0 = y1 = y2 = _NAN
    for b in range(4):
        if not np.isfinite(qa[b, 0]):
            continue
        nb += 1
        ok, m, x0, x1, x2 = _accept_k(px, py, pz, g, qa[b, 0], qa[b, 1], qa[b, 2], r0, r1, r2)
        viol = min(viol, m)
        cost = (x0 - r0) ** 2 + (x1 - r1) ** 2 + (x2 - r2) ** 2
        if ok and cost < best:
            best, y0, y1, y2 = cost, x0, x1, x2
    if best == math.inf:
        return _JOINT_LIMIT, viol, float(nb), _NAN, _NAN, _NAN
    return OK, 0.0, 0.0, y0, y1, y2


@kernel
def _no_candidate_k(g, x, t, t2, cyl, tol, slack, clean_a):
    """The verdict on a target none of whose branches is a candidate of the limits-first :func:`_ik_core`, when it
    is beyond doubt (a workspace study's common case; otherwise ``(OK, 0, 0)``: the complete path decides):

    * out of reach: inside the abduction cylinder, or beyond the knee's reach on both abduction branches, each by
      more than ``slack`` (the cases :func:`_ik_all_core` skips without a polish). Returns ``(_UNREACHABLE, miss,
      reason)`` with :func:`_ik_all_core`'s data (the least miss, m, and its reason);
    * reachable only outside the limits: on the exact ideal structure, away from the singular sets
      (:data:`WELL_CONDITIONED`: the closed form is the answer, no polish moves it) and inside the reach by ``tol``,
      every branch was dropped for a joint more than :data:`CANDIDATE_SLACK` (> :data:`LIMIT_SLACK`) outside its
      limits, which :func:`_accept_k` rejects too. Returns ``(_JOINT_LIMIT, nan, 4)`` (the least violation is
      measured by the single call's error, from :meth:`Leg.ik_all`)."""
    if cyl > slack:
        return _UNREACHABLE, cyl, _IN_CYLINDER
    best, why = math.inf, 0.0
    if cyl > tol:
        best, why = cyl, _IN_CYLINDER
    clean = clean_a and cyl <= tol
    for ia in range(1 if g[_H] == 0.0 else 2):  # h_X = 0: the knee's miss is the same on both abduction branches
        _wx, _wy, miss, far, _cs, _acb, clean_w = _pitch_k(g, x, t if ia == 1 else -t, t2)
        clean = clean and clean_w and miss <= tol
        if not miss > slack:
            best = -1.0  # this branch is within the reach: not out of reach
        elif miss < best:
            best, why = miss, (_TOO_FAR if far else _TOO_NEAR)
    if best >= 0.0:
        return _UNREACHABLE, best, why
    if clean:
        return _JOINT_LIMIT, _NAN, 4.0
    return OK, 0.0, 0.0


@kernel
def _ik_core(px, py, pz, g, r0, r1, r2, tol):
    """The branch of :func:`_ik_all_core` inside the limits nearest ``ref = (r0, r1, r2)``, limits first, for the
    target ``(px, py, pz)`` (scalars, as every kernel on the common path: a call passing arrays costs their
    reference counts).

    The fast path computes the closed form of each branch with scalars only, joint by joint in the order q1, q3,
    q2, and drops a branch as soon as a joint's representative nearest ``ref`` is more than
    :data:`CANDIDATE_SLACK` outside the limits or its partial cost ``sum (x_j - ref_j)^2`` exceeds the best's;
    only the best candidate is polished (:func:`_settle_k`, unless well-conditioned) and put inside the limits
    (:func:`_accept_k`). When it fails (no candidate, a branch off the ideal structure's reach, a polish leaving
    the limits) the complete path :func:`_ik_every_k` decides (every branch polished; the failure's data). Ties go
    to the earlier branch (costs of the closed-form angles before the polish). Returns ``(status, info0, info1, q1,
    q2, q3)`` as :func:`_ik_every_k`."""
    if not (_finite_k(px, py, pz) and _finite_k(r0, r1, r2)):
        return _BAD_INPUT, 0.0, 0.0, _NAN, _NAN, _NAN
    x, t, t2, yz, cyl, clean_a = _target_k(px, py, pz, g)
    slack = g[_SLACK] - REACH_TOL + tol
    best, c1, c2, c3, check, clean, inside, clamped = math.inf, 0.0, 0.0, 0.0, False, False, False, False
    y0 = y1 = y2 = 0.0
    pitched, clean_w = False, False  # the pitch-plane quantities computed (for one abduction branch)
    wx = wy = miss = acb = 0.0
    cs = (0.0, 0.0)
    for ia in range(2 if cyl <= slack else 0):
        u3, vc, vs = _abduction_vec_k(g, ia, t, yz)
        if not _on_arc_k(g, vc, vs):  # q1 off the limits (by more than ARC_SLACK): no atan2
            continue
        q1 = _atan2_k(vs, vc)
        x0, m0, k0 = _within_k(q1, r0, g[_LO], g[_HI], CANDIDATE_SLACK)
        cost0 = (x0 - r0) ** 2
        if m0 > CANDIDATE_SLACK or not cost0 < best:
            continue
        if not pitched or g[_H] != 0.0:  # h_X = 0: |w|, so the knee, is the same on both abduction branches
            wx, wy, miss, far, cs, acb, clean_w = _pitch_k(g, x, u3, t2)
            pitched = True
        wx = u3 - g[_H]
        if miss > slack:
            continue
        for ik in range(2):
            q3 = _knee_k(g, ik, acb)
            x2, m2, k2 = _within_k(q3, r2, g[_LO + 2], g[_HI + 2], CANDIDATE_SLACK)
            cost = cost0 + (x2 - r2) ** 2
            if m2 > CANDIDATE_SLACK or not cost < best:
                continue
            q2 = _hip_k(g, ik, wx, wy, cs)
            x1, m1, k1 = _within_k(q2, r1, g[_LO + 1], g[_HI + 1], CANDIDATE_SLACK)
            cost += (x1 - r1) ** 2
            if m1 <= CANDIDATE_SLACK and cost < best:
                best, c1, c2, c3, y0, y1, y2 = cost, q1, q2, q3, x0, x1, x2
                clamped = miss > g[_SLACK]
                check = cyl > tol or miss > tol
                clean = clean_a and clean_w and not check
                inside = m0 == 0.0 and m1 == 0.0 and m2 == 0.0 and not (k0 or k1 or k2)
    if clamped and g[_H] != 0.0:  # clamped onto its reach: the other abduction branch may reach exactly
        return _ik_every_k(px, py, pz, g, r0, r1, r2, tol)
    if clean and inside:  # well-conditioned, strictly inside the limits: the representatives found are the answer
        return OK, 0.0, 0.0, y0, y1, y2
    if best == math.inf:  # no candidate: decided here when it is clear (_no_candidate_k), else the complete path
        status, i0, i1 = _no_candidate_k(g, x, t, t2, cyl, tol, slack, clean_a)
        if status != OK:
            return status, i0, i1, _NAN, _NAN, _NAN
    else:
        j1, j2, j3, res = (c1, c2, c3, 0.0) if clean else _settle_k(px, py, pz, g, c1, c2, c3)
        if res <= tol or not check:
            ok, _m, x0, x1, x2 = _accept_k(px, py, pz, g, j1, j2, j3, r0, r1, r2)
            if ok:
                return OK, 0.0, 0.0, x0, x1, x2
    return _ik_every_k(px, py, pz, g, r0, r1, r2, tol)


@kernel(entry=True)
def _ik_all_k(p, g, flip, out) -> int:
    """:func:`_ik_all_core` of one target with the default ``tol`` and reference (:data:`_REF`: a single call,
    one argument fewer for numba), rows in the order ``flip`` gives: its status."""
    return _ik_all_core(p[0], p[1], p[2], g, g[_REF], g[_REF + 1], g[_REF + 2], IK_TOL, out, flip)[0]


@kernel(entry=True)
def _ik_all_near_k(p, g, ref, flip, out) -> int:
    """:func:`_ik_all_k` with the reference ``ref`` (3,)."""
    return _ik_all_core(p[0], p[1], p[2], g, ref[0], ref[1], ref[2], IK_TOL, out, flip)[0]


@kernel(entry=True)
def _ik_k(p, g, out) -> int:
    """:func:`_ik_core` of one target with the default ``tol`` and reference (:data:`_REF`) into ``out``: its
    status."""
    s, _a, _b, out[0], out[1], out[2] = _ik_core(p[0], p[1], p[2], g, g[_REF], g[_REF + 1], g[_REF + 2], IK_TOL)
    return s


@kernel(entry=True)
def _ik_near_k(p, g, ref, out) -> int:
    """:func:`_ik_k` with the reference ``ref`` (3,)."""
    s, _a, _b, out[0], out[1], out[2] = _ik_core(p[0], p[1], p[2], g, ref[0], ref[1], ref[2], IK_TOL)
    return s


@batch_kernel(rows="p ref out status info", min_parallel=512, parfor=True)
def _ik_all_batch(p, g, ref, tol, out, status, info) -> int:
    """:func:`_ik_all_core` over rows; returns the number of targets that failed (status != OK)."""
    # ref: one row for all targets (m = 1) or one per target; ``i - i`` keeps the index type of i
    n, m, bad = p.shape[0], ref.shape[0], 0
    for i in prange(n):
        j = i if m > 1 else i - i
        s, a, b = _ik_all_core(p[i, 0], p[i, 1], p[i, 2], g, ref[j, 0], ref[j, 1], ref[j, 2], tol, out[i], 0)
        status[i], info[i, 0], info[i, 1] = s, a, b
        bad += s != OK
    return bad


@batch_kernel(rows="p ref out status info", min_parallel=1024, parfor=True)
def _ik_batch(p, g, ref, tol, out, status, info) -> int:
    """:func:`_ik_core` over rows; returns the number of targets that failed (status != OK), NaN rows in ``out``.
    ``status`` and ``info`` with no row: not recorded (a caller that needs neither allocates neither)."""
    n, m, bad = p.shape[0], ref.shape[0], 0
    record = status.shape[0] == n
    for i in prange(n):
        j = i if m > 1 else i - i
        s, a, b, out[i, 0], out[i, 1], out[i, 2] = _ik_core(p[i, 0], p[i, 1], p[i, 2], g, ref[j, 0], ref[j, 1],
                                                            ref[j, 2], tol)
        if record:
            status[i], info[i, 0], info[i, 1] = s, a, b
        bad += s != OK
    return bad
