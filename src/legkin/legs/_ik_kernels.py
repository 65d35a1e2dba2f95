"""Closed-form inverse kinematics kernels of an HAA-HFE-KFE leg (every branch, the branch inside the limits)
and the damped Newton polish on the exact forward map (see :mod:`legkin.legs.kinematics`), scalar and batch."""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_kernel, kernel
from ._fk_kernels import _finite3, _fk3_k, _jac3_k
from ._layout import (
    _BAD_INPUT,
    _D,
    _E1,
    _E2,
    _E3,
    _H,
    _HI,
    _IN_CYLINDER,
    _JOINT_LIMIT,
    _K,
    _KN,
    _L,
    _LN,
    _LO,
    _NAN,
    _O,
    _PK,
    _PL,
    _POLISH_DONE,
    _S3,
    _SLACK,
    _TOO_FAR,
    _TOO_NEAR,
    _TWO_PI,
    _UNREACHABLE,
    LIMIT_SLACK,
    LIMIT_TOL,
    POLISH_DAMPING,
    POLISH_STEPS,
    REACH_TOL,
)


@kernel
def _polish_k(p, g, q, jac, fixed) -> float:
    """At most :data:`POLISH_STEPS` damped Newton steps on the exact forward map while the foot error exceeds
    :data:`POLISH_BELOW`, each kept only if it reduces the error: ``e = p - fk(q)``,
    ``dq = J^T (J J^T + lambda^2 I)^-1 e`` (``lambda`` = :data:`POLISH_DAMPING`).

    The closed form is exact for the ideal structure (a1 perpendicular to a2 = +-a3); URDF angles written
    with 11 digits (``rpy="0 1.57079632679 0"``) leave axes ~5e-12 off, i.e. ~1e-12 m at the foot, and near the
    fold of the knee (|w| -> 0 when |k| = |l|) the law of cosines loses digits: the steps remove both.
    ``fixed`` (bits 1, 2, 4 for q1, q2, q3): joints held where they are (their Jacobian columns zeroed).
    Returns the final foot error ``|e|`` (m).
    """
    fx, fy, fz = _fk3_k(q[0], q[1], q[2], g)
    ex, ey, ez = p[0] - fx, p[1] - fy, p[2] - fz
    err = ex * ex + ey * ey + ez * ez
    lam2 = POLISH_DAMPING * POLISH_DAMPING
    for _ in range(POLISH_STEPS):
        if err <= _POLISH_DONE:
            break
        _jac3_k(q[0], q[1], q[2], g, jac)
        for j in range(3):
            if fixed & (1 << j):
                jac[0, j] = jac[1, j] = jac[2, j] = 0.0
        # A = J J^T + lam^2 I (symmetric positive definite), solve A y = e by the adjugate, dq = J^T y
        a00 = jac[0, 0] ** 2 + jac[0, 1] ** 2 + jac[0, 2] ** 2 + lam2
        a11 = jac[1, 0] ** 2 + jac[1, 1] ** 2 + jac[1, 2] ** 2 + lam2
        a22 = jac[2, 0] ** 2 + jac[2, 1] ** 2 + jac[2, 2] ** 2 + lam2
        a01 = jac[0, 0] * jac[1, 0] + jac[0, 1] * jac[1, 1] + jac[0, 2] * jac[1, 2]
        a02 = jac[0, 0] * jac[2, 0] + jac[0, 1] * jac[2, 1] + jac[0, 2] * jac[2, 2]
        a12 = jac[1, 0] * jac[2, 0] + jac[1, 1] * jac[2, 1] + jac[1, 2] * jac[2, 2]
        c00, c11, c22 = a11 * a22 - a12 * a12, a00 * a22 - a02 * a02, a00 * a11 - a01 * a01
        c01, c02, c12 = a02 * a12 - a01 * a22, a01 * a12 - a02 * a11, a01 * a02 - a00 * a12
        det = a00 * c00 + a01 * c01 + a02 * c02
        if not det > 0.0:
            break
        yx = (c00 * ex + c01 * ey + c02 * ez) / det
        yy = (c01 * ex + c11 * ey + c12 * ez) / det
        yz = (c02 * ex + c12 * ey + c22 * ez) / det
        n0 = q[0] + jac[0, 0] * yx + jac[1, 0] * yy + jac[2, 0] * yz
        n1 = q[1] + jac[0, 1] * yx + jac[1, 1] * yy + jac[2, 1] * yz
        n2 = q[2] + jac[0, 2] * yx + jac[1, 2] * yy + jac[2, 2] * yz
        fx, fy, fz = _fk3_k(n0, n1, n2, g)
        nx, ny, nz = p[0] - fx, p[1] - fy, p[2] - fz
        new = nx * nx + ny * ny + nz * nz
        if not new < err:
            break
        q[0], q[1], q[2] = n0, n1, n2
        ex, ey, ez, err = nx, ny, nz, new
    return math.sqrt(err)


@kernel
def _residual_k(p, g, q) -> float:
    """``|p - fk(q)|`` on the exact forward map."""
    fx, fy, fz = _fk3_k(q[0], q[1], q[2], g)
    return math.sqrt((p[0] - fx) ** 2 + (p[1] - fy) ** 2 + (p[2] - fz) ** 2)


@kernel
def _near_k(a, r):
    """The representative ``a + 2 pi n`` nearest ``r``."""
    return a + _TWO_PI * math.floor((r - a) / _TWO_PI + 0.5)


@kernel(entry=True)
def _ik_all_k(p, g, ref, out, info) -> int:
    """Every branch (rows in :data:`BRANCHES` order, NaN rows for absent ones) of the target ``p``.

    ``r^2 = y^2 + z^2``, ``u3 = s_a sqrt(r^2 - d^2)``, ``q1 = atan2(z, y) - atan2(u3, d)``;
    ``w = (u3, x1) - h``, ``cos beta = (|w|^2 - |k|^2 - |l|^2) / (2 |k||l|)``, ``beta = s_k acos(.)``,
    ``q3 = s3 (beta - phi_l + phi_k)``, ``q2 = atan2(w) - atan2(k + Rot(s3 q3) l)``. Each branch is then
    polished on the exact forward map (:func:`_polish_k`) and each angle moved to its
    2 pi representative nearest ``ref``. ``info`` (2,): on failure the miss (m) and its reason.
    """
    for b in range(4):
        for j in range(3):
            out[b, j] = _NAN
    if not _finite3(p):
        return _BAD_INPUT
    px, py, pz = p[0] - g[_O], p[1] - g[_O + 1], p[2] - g[_O + 2]
    x1 = px * g[_E1] + py * g[_E1 + 1] + pz * g[_E1 + 2]
    y = px * g[_E2] + py * g[_E2 + 1] + pz * g[_E2 + 2]
    z = px * g[_E3] + py * g[_E3 + 1] + pz * g[_E3 + 2]
    d = g[_D]
    ad = abs(d)
    r = math.hypot(y, z)
    slack = g[_SLACK]
    cyl = ad - r
    if cyl > slack:
        info[0], info[1] = cyl, _IN_CYLINDER
        return _UNREACHABLE
    disc = (r - ad) * (r + ad)
    t = math.sqrt(disc) if disc > 0.0 else 0.0
    phi = math.atan2(z, y)
    kn, ln = g[_KN], g[_LN]
    s3 = g[_S3]
    best, why = math.inf, 0.0
    if cyl > REACH_TOL:
        best, why = cyl, _IN_CYLINDER
    found = 0
    qb = np.empty(3)
    qt = np.empty(3)
    jac = np.empty((3, 3))
    for ia in range(2):
        u3 = t if ia == 1 else -t
        q1 = phi - math.atan2(u3, d)
        wx, wy = u3 - g[_H], x1 - g[_H + 1]
        wn = math.hypot(wx, wy)
        far = wn - (kn + ln)
        near = abs(kn - ln) - wn
        miss = far if far > near else near
        if miss > slack:
            if miss < best:
                best, why = miss, (_TOO_FAR if far > near else _TOO_NEAR)
            continue
        # within the slack of the ideal structure's boundary: kept only if the exact foot error is <= REACH_TOL
        check = cyl > REACH_TOL or miss > REACH_TOL
        c = (wn * wn - kn * kn - ln * ln) / (2.0 * kn * ln)
        c = 1.0 if c > 1.0 else (-1.0 if c < -1.0 else c)
        acb = math.acos(c)
        for ik in range(2):
            beta = acb if ik == 1 else -acb
            a = beta - g[_PL] + g[_PK]  # = s3 q3
            ca, sa = math.cos(a), math.sin(a)
            vx = g[_K] + ca * g[_L] - sa * g[_L + 1]
            vy = g[_K + 1] + sa * g[_L] + ca * g[_L + 1]
            q2 = math.atan2(wy, wx) - math.atan2(vy, vx)
            b = 2 * ia + ik
            qb[0], qb[1], qb[2] = q1, q2, s3 * a
            res = _polish_k(p, g, qb, jac, 0)
            if res > REACH_TOL:  # near a fold of the ideal structure: restart off it (Newton stalls on a fold)
                eta = 4.0 * math.sqrt(res / min(kn, ln))
                q0, q1b, q2b = qb[0], qb[1], qb[2]
                for jr in range(6):
                    qt[0], qt[1], qt[2] = q0, q1b, q2b
                    qt[jr // 2] += eta if jr % 2 == 0 else -eta
                    rt = _polish_k(p, g, qt, jac, 0)
                    if rt < res:
                        res = rt
                        qb[0], qb[1], qb[2] = qt[0], qt[1], qt[2]
                    if res <= REACH_TOL:
                        break
            # a branch clamped onto the ideal structure's boundary is kept only if it reaches the target
            if check and res > REACH_TOL:
                if cyl <= REACH_TOL and res < best:
                    best, why = res, (_TOO_FAR if far > near else _TOO_NEAR)
                continue
            out[b, 0] = _near_k(qb[0], ref[0])
            out[b, 1] = _near_k(qb[1], ref[1])
            out[b, 2] = _near_k(qb[2], ref[2])
            found += 1
    if found == 0:
        info[0], info[1] = best, why
        return _UNREACHABLE
    return OK


@kernel(inline=True)
def _in_limits_k(a, r, lo, hi):
    """The representative ``a + 2 pi n`` inside ``[lo, hi]`` (slack :data:`LIMIT_TOL`, then clipped) nearest ``r``;
    NaN if none. Also returns the distance to the limits of the nearest representative (0 when inside)."""
    rc = lo if r < lo else (hi if r > hi else r)
    base = _near_k(a, rc)
    best, dist, miss = _NAN, math.inf, math.inf
    for n in range(-1, 2):
        x = base + _TWO_PI * n
        out_by = lo - x if x < lo else (x - hi if x > hi else 0.0)
        if out_by < miss:
            miss = out_by
        if out_by <= LIMIT_TOL:
            x = lo if x < lo else (hi if x > hi else x)
            if abs(x - r) < dist:
                best, dist = x, abs(x - r)
    return best, miss


@kernel
def _repair_k(p, g, q, ref, jac) -> bool:
    """A branch ``q`` (3,) at most :data:`LIMIT_SLACK` outside the limits, moved into them (rare path): each angle
    at its representative nearest ``ref`` clipped onto the limits, the joints left alone re-solved by
    :func:`_polish_k` with the clipped ones fixed (a joint the steps push outside is clipped and fixed in turn, as
    when a target is made with two joints on their limits); kept (True, ``q`` overwritten) if it reproduces ``p``
    within :data:`REACH_TOL`. Near the abduction singularity (foot on the cylinder ``r = |d|``) a branch's q1 errs
    by up to ~1e-8 rad along the singular direction while its foot is exact: a target made with q1 on its limit
    then comes back outside it, and the other joints absorb the clip."""
    fixed = 0
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
        res = _polish_k(p, g, q, jac, fixed)
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


@kernel(entry=True)
def _ik_k(p, g, ref, out, info) -> int:
    """The branch of :func:`_ik_all_k` inside the limits nearest ``ref`` (least sum of squared joint differences;
    ties to the earlier branch). ``info``: the miss (m) and reason, or the least limit violation (rad) and the
    number of geometric branches."""
    qa = np.empty((4, 3))
    status = _ik_all_k(p, g, ref, qa, info)
    for j in range(3):
        out[j] = _NAN
    if status != OK:
        return status
    best, viol, nb = math.inf, math.inf, 0
    for b in range(4):
        if not np.isfinite(qa[b, 0]):
            continue
        nb += 1
        x0, m0 = _in_limits_k(qa[b, 0], ref[0], g[_LO], g[_HI])
        x1, m1 = _in_limits_k(qa[b, 1], ref[1], g[_LO + 1], g[_HI + 1])
        x2, m2 = _in_limits_k(qa[b, 2], ref[2], g[_LO + 2], g[_HI + 2])
        m = max(m0, max(m1, m2))
        if m < viol:
            viol = m
        if m > LIMIT_SLACK:
            continue
        if m > 0.0:  # a hair outside the limits: moved into them, the free joints re-solved (rare path)
            qr = np.empty(3)  # the rare path allocates its own scratch
            qr[0], qr[1], qr[2] = qa[b, 0], qa[b, 1], qa[b, 2]
            if _repair_k(p, g, qr, ref, np.empty((3, 3))):
                x0, x1, x2 = qr[0], qr[1], qr[2]
            elif not (np.isfinite(x0) and np.isfinite(x1) and np.isfinite(x2)):
                continue  # (within LIMIT_TOL: the clipped angles, the foot within LIMIT_TOL x the reach)
        cost = (x0 - ref[0]) ** 2 + (x1 - ref[1]) ** 2 + (x2 - ref[2]) ** 2
        if cost < best:
            best = cost
            out[0], out[1], out[2] = x0, x1, x2
    if best == math.inf:
        info[0], info[1] = viol, nb
        return _JOINT_LIMIT
    return OK


@batch_kernel(rows="p ref out status info", min_parallel=4096)
def _ik_all_batch(p, g, ref, out, status, info) -> None:
    # ref: one row for all targets (m = 1) or one per target; ``i - i`` keeps the index type of i
    n, m = p.shape[0], ref.shape[0]
    for i in range(n):
        status[i] = _ik_all_k(p[i], g, ref[i if m > 1 else i - i], out[i], info[i])


@batch_kernel(rows="p ref out status info", min_parallel=4096)
def _ik_batch(p, g, ref, out, status, info) -> None:
    n, m = p.shape[0], ref.shape[0]
    for i in range(n):
        status[i] = _ik_k(p[i], g, ref[i if m > 1 else i - i], out[i], info[i])
