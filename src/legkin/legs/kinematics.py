"""Closed-form kinematics of an HAA-HFE-KFE leg measured from any URDF (issue 13).

The leg, in the model's root frame at the neutral configuration (every length measured, nothing assumed):

* ``o1, a1``: origin and unit axis of the abduction joint (HAA), ``o2, a2``: the hip pitch joint (HFE),
  ``o3, a3``: the knee (KFE), ``f``: the foot frame's origin. The structure: ``a1 . a2 = 0`` and
  ``a3 = s3 a2`` with ``s3 = +-1`` (parallel pitch axes, same or opposite sense).
* The abduction frame ``(e1, e2, e3) = (a1, a2, a1 x a2)`` (right-handed, orthonormal).
* The product of exponentials about the neutral configuration (exact for a chain of revolute joints)::

      p(q) = o1 + R(a1, q1) [ (o2 - o1) + R(a2, q2) ( (o3 - o2) + R(a3, q3) (f - o3) ) ]

  ``R(a2, .)`` and ``R(a3, .)`` leave the ``e2`` components unchanged, so the foot lies at the fixed
  **lateral offset** ``d = e2 . (f - o1)`` along the pitch axis. In the pitch-plane coordinates
  ``(X, Y) = (v . e3, v . e1)`` (``R(e2, t)`` is the plane rotation ``Rot(t)`` there) with the measured
  offsets ``h = (o2 - o1)``, ``k = (o3 - o2)`` (thigh), ``l = (f - o3)`` (shank)::

      (u3, u1) = h + Rot(q2) [ k + Rot(s3 q3) l ]                                   (pitch plane)
      p = o1 + u1 e1 + (cos q1 d - sin q1 u3) e2 + (sin q1 d + cos q1 u3) e3        (abduction)

  The HAA axis need not pass through the HFE origin (``h`` is any vector) and the thigh and shank may have
  any offset angles ``phi_k = atan2(k_Y, k_X)``, ``phi_l = atan2(l_Y, l_X)``.

Inverse kinematics, with ``p' = p - o1`` and ``(x1, y, z) = (p'.e1, p'.e2, p'.e3)``:

1. abduction: ``r^2 = y^2 + z^2``; ``u3 = s_a sqrt(r^2 - d^2)`` (abduction branch ``s_a = +-1``, out of reach
   if ``r < |d|``: inside the abduction cylinder), ``q1 = atan2(z, y) - atan2(u3, d)``;
2. knee: ``w = (u3, x1) - h``; ``cos(beta) = (|w|^2 - |k|^2 - |l|^2) / (2 |k| |l|)``, ``beta = s_k acos(.)``
   (knee branch ``s_k = +-1``, out of reach if ``|w| > |k| + |l|`` or ``|w| < | |k| - |l| |``);
   ``beta = s3 q3 + phi_l - phi_k`` so ``q3 = s3 (beta - phi_l + phi_k)``;
3. hip pitch: ``v = k + Rot(s3 q3) l``; ``q2 = atan2(w_Y, w_X) - atan2(v_Y, v_X)``.

The forward map and Jacobian kernels use the measured axes exactly (the product of exponentials above, as
Pinocchio); each closed-form branch is polished by at most :data:`POLISH_STEPS` damped Newton steps on it when
its foot error exceeds :data:`POLISH_BELOW` (axes a few 1e-12 rad off the ideal structure, the knee's fold).
Each angle is then moved by a multiple of 2 pi: in :meth:`Leg.ik_all` to the representative nearest the
reference configuration, in :meth:`Leg.ik` to the representative inside the URDF limits nearest ``q_near``.

Implementation (issue 16, :mod:`legkin._kernels`): each function is one compiled scalar kernel; a batch is a
compiled loop over it. The leg's geometry reaches the kernels as one float64 array (:attr:`Leg.params`).
Single/batch contract of :mod:`legkin._batch`: a single input (3,) returns a plain array and raises a legkin
error on failure; a batch (..., 3) returns NaN rows where an item fails (``return_mask=True`` adds the mask).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._batch import as_input, check_flag, finish
from .._kernels import OK, SERIAL_BELOW, as_rows, batch_kernel, kernel, prange
from ..errors import InvalidInputError, InvalidParameterError, JointLimitError, UnreachableError

__all__ = [
    "Leg",
    "LegStructureError",
    "BRANCHES",
    "PERPENDICULAR_TOL",
    "PARALLEL_TOL",
    "REACH_TOL",
    "LIMIT_TOL",
]


class LegStructureError(InvalidParameterError):
    """A kinematic chain that is not an HAA-HFE-KFE leg (the message names the deviation)."""


#: |a1 . a2| (HAA vs HFE axis) above this is "not perpendicular" (rad, ~ the angle's deviation).
PERPENDICULAR_TOL = 1e-9
#: |a2 x a3| (HFE vs KFE axis) above this is "not parallel".
PARALLEL_TOL = 1e-9
#: A target up to this far (m) outside the reachable set is solved on its boundary.
REACH_TOL = 1e-12
#: A joint angle up to this far (rad) outside the URDF limits is clipped onto the limit (the foot then moves by
#: at most LIMIT_TOL x the leg's reach, < 1e-10 m).
LIMIT_TOL = 1e-10
#: Damped Newton steps (at most) polishing each closed-form branch on the exact forward map (see _polish_k).
POLISH_STEPS = 8
#: Damping (m) of the polishing steps: bounds a step to ~|e| / (2 lambda) rad near a singularity.
POLISH_DAMPING = 1e-7
#: Foot error (m) below which a branch is not polished (a few ulps of a 1 m reach).
POLISH_BELOW = 1e-15
_POLISH_DONE = POLISH_BELOW**2
#: Branch order of :meth:`Leg.ik_all`: ``(s_a, s_k)``, the abduction sign (sign of ``u3``, the foot's
#: coordinate along ``e3 = a1 x a2`` in the abduction frame) and the knee sign (sign of ``beta``).
BRANCHES = ((-1, -1), (-1, 1), (1, -1), (1, 1))

# ---------------------------------------------------------------- layout of the geometry array (Leg.params)
_O, _E1, _E2, _E3 = 0, 3, 6, 9  # o1, e1, e2, e3 (3 each)
_D = 12  # lateral offset d
_H, _K, _L = 13, 15, 17  # h, k, l in pitch-plane coordinates (X, Y)
_S3 = 19  # knee axis sign
_KN, _LN, _PK, _PL = 20, 21, 22, 23  # |k|, |l|, phi_k, phi_l
_LO, _HI = 24, 27  # lower, upper limits (3 each)
_A1, _A2, _A3 = 30, 33, 36  # the measured unit axes a1, a2, a3 (exact forward map)
_V21, _V32, _V3F = 39, 42, 45  # o2 - o1, o3 - o2, f - o3
_SLACK = 48  # reach slack of the ideal structure: REACH_TOL + its deviation bound (see Leg.from_geometry)
_NPARAMS = 49

_TWO_PI = 2.0 * math.pi
_NAN = math.nan

# kernel status codes (OK = 0)
_UNREACHABLE = 1
_JOINT_LIMIT = 2
_BAD_INPUT = 3
# reasons of _UNREACHABLE (info[1])
_IN_CYLINDER = 1.0
_TOO_FAR = 2.0
_TOO_NEAR = 3.0

_S3SHAPE = (3,)
_F64 = np.dtype(np.float64)


# ---------------------------------------------------------------- kernels
@kernel
def _finite3(x) -> bool:
    return np.isfinite(x[0]) and np.isfinite(x[1]) and np.isfinite(x[2])


@kernel
def _rot_k(g, ia, c, s, vx, vy, vz):
    """Rodrigues: ``R(a, t) v = cos t v + sin t (a x v) + (1 - cos t) (a . v) a`` with ``a = g[ia:ia + 3]``."""
    ax, ay, az = g[ia], g[ia + 1], g[ia + 2]
    k = (1.0 - c) * (ax * vx + ay * vy + az * vz)
    return (
        c * vx + s * (ay * vz - az * vy) + k * ax,
        c * vy + s * (az * vx - ax * vz) + k * ay,
        c * vz + s * (ax * vy - ay * vx) + k * az,
    )


@kernel
def _cross_k(g, ia, vx, vy, vz):
    """``a x v`` with ``a = g[ia:ia + 3]``."""
    ax, ay, az = g[ia], g[ia + 1], g[ia + 2]
    return ay * vz - az * vy, az * vx - ax * vz, ax * vy - ay * vx


@kernel
def _fk3_k(q0, q1, q2, g):
    """The product of exponentials with the measured axes and origins (what Pinocchio computes)::

        t3 = R(a3, q3) (f - o3),  t2 = R(a2, q2) [(o3 - o2) + t3],  p = o1 + R(a1, q1) [(o2 - o1) + t2]
    """
    c, s = math.cos(q2), math.sin(q2)
    t3x, t3y, t3z = _rot_k(g, _A3, c, s, g[_V3F], g[_V3F + 1], g[_V3F + 2])
    c, s = math.cos(q1), math.sin(q1)
    t2x, t2y, t2z = _rot_k(g, _A2, c, s, g[_V32] + t3x, g[_V32 + 1] + t3y, g[_V32 + 2] + t3z)
    c, s = math.cos(q0), math.sin(q0)
    px, py, pz = _rot_k(g, _A1, c, s, g[_V21] + t2x, g[_V21 + 1] + t2y, g[_V21 + 2] + t2z)
    return g[_O] + px, g[_O + 1] + py, g[_O + 2] + pz


@kernel
def _fk_k(q, g, out) -> int:
    """Foot position: :func:`_fk3_k`,
    ``p = o1 + R(a1, q1) [(o2 - o1) + R(a2, q2) ((o3 - o2) + R(a3, q3) (f - o3))]``."""
    if not _finite3(q):
        return _BAD_INPUT
    out[0], out[1], out[2] = _fk3_k(q[0], q[1], q[2], g)
    return OK


@kernel
def _jac3_k(q0, q1, q2, g, out) -> None:
    """Columns ``a1 x R1 v1``, ``R1 (a2 x t2)``, ``R1 R2 (a3 x t3)`` (each joint: its spatial axis crossed with
    the lever from its origin to the foot), with ``R_j = R(a_j, q_j)`` and ``t3, t2, v1`` of :func:`_fk3_k`."""
    c3, s3 = math.cos(q2), math.sin(q2)
    c2, s2 = math.cos(q1), math.sin(q1)
    c1, s1 = math.cos(q0), math.sin(q0)
    t3x, t3y, t3z = _rot_k(g, _A3, c3, s3, g[_V3F], g[_V3F + 1], g[_V3F + 2])
    t2x, t2y, t2z = _rot_k(g, _A2, c2, s2, g[_V32] + t3x, g[_V32 + 1] + t3y, g[_V32 + 2] + t3z)
    # column 1: a1 x R1 v1 = R1 (a1 x v1)
    x, y, z = _cross_k(g, _A1, g[_V21] + t2x, g[_V21 + 1] + t2y, g[_V21 + 2] + t2z)
    out[0, 0], out[1, 0], out[2, 0] = _rot_k(g, _A1, c1, s1, x, y, z)
    x, y, z = _cross_k(g, _A2, t2x, t2y, t2z)
    out[0, 1], out[1, 1], out[2, 1] = _rot_k(g, _A1, c1, s1, x, y, z)
    x, y, z = _cross_k(g, _A3, t3x, t3y, t3z)
    x, y, z = _rot_k(g, _A2, c2, s2, x, y, z)
    out[0, 2], out[1, 2], out[2, 2] = _rot_k(g, _A1, c1, s1, x, y, z)


@kernel
def _jacobian_k(q, g, out) -> int:
    """Foot Jacobian ``dp/dq`` (3, 3): :func:`_jac3_k`."""
    if not _finite3(q):
        return _BAD_INPUT
    _jac3_k(q[0], q[1], q[2], g, out)
    return OK


@kernel
def _polish_k(p, g, q, jac) -> float:
    """At most :data:`POLISH_STEPS` damped Newton steps on the exact forward map while the foot error exceeds
    :data:`POLISH_BELOW`, each kept only if it reduces the error: ``e = p - fk(q)``,
    ``dq = J^T (J J^T + lambda^2 I)^-1 e`` (``lambda`` = :data:`POLISH_DAMPING`).

    The closed form is exact for the ideal structure (a1 perpendicular to a2 = +-a3); URDF angles written
    with 11 digits (``rpy="0 1.57079632679 0"``) leave axes ~5e-12 off, i.e. ~1e-12 m at the foot, and near the
    fold of the knee (|w| -> 0 when |k| = |l|) the law of cosines loses digits: the steps remove both.
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


@kernel
def _ik_all_k(p, g, ref, out, info) -> int:
    """Every branch (rows in :data:`BRANCHES` order, NaN rows for absent ones) of the target ``p``.

    ``r^2 = y^2 + z^2``, ``u3 = s_a sqrt(r^2 - d^2)``, ``q1 = atan2(z, y) - atan2(u3, d)``;
    ``w = (u3, x1) - h``, ``cos beta = (|w|^2 - |k|^2 - |l|^2) / (2 |k||l|)``, ``beta = s_k acos(.)``,
    ``q3 = s3 (beta - phi_l + phi_k)``, ``q2 = atan2(w) - atan2(k + Rot(s3 q3) l)``. Each angle is moved to
    Each branch is then polished on the exact forward map (:func:`_polish_k`) and each angle moved to its
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
            res = _polish_k(p, g, qb, jac)
            if res > REACH_TOL:  # near a fold of the ideal structure: restart off it (Newton stalls on a fold)
                eta = 4.0 * math.sqrt(res / min(kn, ln))
                q0, q1b, q2b = qb[0], qb[1], qb[2]
                for jr in range(6):
                    qt[0], qt[1], qt[2] = q0, q1b, q2b
                    qt[jr // 2] += eta if jr % 2 == 0 else -eta
                    rt = _polish_k(p, g, qt, jac)
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


@kernel
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
        if not (np.isfinite(x0) and np.isfinite(x1) and np.isfinite(x2)):
            continue
        cost = (x0 - ref[0]) ** 2 + (x1 - ref[1]) ** 2 + (x2 - ref[2]) ** 2
        if cost < best:
            best = cost
            out[0], out[1], out[2] = x0, x1, x2
    if best == math.inf:
        info[0], info[1] = viol, nb
        return _JOINT_LIMIT
    return OK


@batch_kernel
def _fk_batch(q, g, out) -> int:
    n, bad = q.shape[0], 0
    if n < SERIAL_BELOW:
        for i in range(n):
            bad += _fk_k(q[i], g, out[i]) != OK
    else:
        for i in prange(n):
            bad += _fk_k(q[i], g, out[i]) != OK
    return bad


@batch_kernel
def _jacobian_batch(q, g, out) -> int:
    n, bad = q.shape[0], 0
    if n < SERIAL_BELOW:
        for i in range(n):
            bad += _jacobian_k(q[i], g, out[i]) != OK
    else:
        for i in prange(n):
            bad += _jacobian_k(q[i], g, out[i]) != OK
    return bad


@batch_kernel
def _ik_all_batch(p, g, ref, out, status, info) -> None:
    # ref: one row for all targets (m = 1) or one per target; ``i - i`` keeps the index type of prange's i
    n, m = p.shape[0], ref.shape[0]
    if n < SERIAL_BELOW:
        for i in range(n):
            status[i] = _ik_all_k(p[i], g, ref[i if m > 1 else i - i], out[i], info[i])
    else:
        for i in prange(n):
            status[i] = _ik_all_k(p[i], g, ref[i if m > 1 else i - i], out[i], info[i])


@batch_kernel
def _ik_batch(p, g, ref, out, status, info) -> None:
    n, m = p.shape[0], ref.shape[0]
    if n < SERIAL_BELOW:
        for i in range(n):
            status[i] = _ik_k(p[i], g, ref[i if m > 1 else i - i], out[i], info[i])
    else:
        for i in prange(n):
            status[i] = _ik_k(p[i], g, ref[i if m > 1 else i - i], out[i], info[i])


# ---------------------------------------------------------------- geometry helpers (Python)
def _never() -> Exception:  # pragma: no cover - a batch call never raises
    raise AssertionError("finish() asked a batch call for its error")


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    n = float(np.linalg.norm(v))
    if not n > 1e-12 or not math.isfinite(n):
        raise LegStructureError(f"{what} has no direction (norm {n:g})")
    return np.asarray(v, dtype=float) / n


def _signed_angle(u: np.ndarray, v: np.ndarray, n: np.ndarray) -> float:
    """Angle (rad) from ``u`` to ``v`` about the unit axis ``n``."""
    return math.atan2(float(n @ np.cross(u, v)), float(u @ v))


def _axis_label(a: np.ndarray) -> str:
    """``"+x"``, ``"-y"``, ... for an axis along a root axis (to 1e-9), else the rounded vector."""
    i = int(np.argmax(np.abs(a)))
    if abs(abs(a[i]) - 1.0) <= 1e-9:
        return f"{'+' if a[i] > 0 else '-'}{'xyz'[i]}"
    return "(" + ", ".join(f"{c:+.4f}" for c in a) + ")"


def _frozen(a) -> np.ndarray:
    arr = np.array(a, dtype=float)
    arr.flags.writeable = False
    return arr


# ---------------------------------------------------------------- the leg
@dataclass(frozen=True, eq=False)
class Leg:
    """One HAA-HFE-KFE leg, measured in the model's root frame at the neutral configuration.

    Build one with :func:`legkin.legs.from_model` / :func:`legkin.legs.from_urdf` (or :meth:`from_geometry`).

    Attributes:
        name: the leg's name (the common prefix of its joint names, e.g. ``"FL"``, ``"lf"``).
        joint_names: its three joints in model order (HAA, HFE, KFE).
        foot_frame: the frame whose origin is the foot.
        lower, upper: the URDF limits (rad) of the three joints.
        origin: HAA origin ``o1`` (m, root frame).
        axes: (3, 3) rows: the unit joint axes ``a1, a2, a3`` at the neutral configuration (root frame).
        hfe_origin, kfe_origin, foot_origin: ``o2``, ``o3`` and the foot ``f`` at the neutral configuration.
        frame: (3, 3) rows ``e1, e2, e3``: the abduction frame ``(a1, a2, a1 x a2)``.
        lateral_offset: ``d = e2 . (f - o1)`` (m), the foot's fixed offset along the pitch axis.
        hip_offset, thigh, shank: ``h = o2 - o1``, ``k = o3 - o2``, ``l = f - o3`` in pitch-plane coordinates
            ``(X, Y) = (v . e3, v . e1)`` (m).
        knee_sign: ``s3``, +1 if the KFE axis has the HFE axis's sense, -1 if opposite.
        q_ref: the default reference of :meth:`ik` / :meth:`ik_all` (mid-limit; 0 where a limit is infinite).
        idx_q, idx_v: the joints' indices in the source model's configuration / velocity vectors (-1 if none).
        params: the float64 geometry array the kernels read.
    """

    name: str
    joint_names: tuple[str, str, str]
    foot_frame: str
    lower: np.ndarray
    upper: np.ndarray
    origin: np.ndarray
    axes: np.ndarray
    hfe_origin: np.ndarray
    kfe_origin: np.ndarray
    foot_origin: np.ndarray
    frame: np.ndarray
    lateral_offset: float
    hip_offset: np.ndarray
    thigh: np.ndarray
    shank: np.ndarray
    knee_sign: float
    q_ref: np.ndarray
    idx_q: tuple[int, int, int] = (-1, -1, -1)
    idx_v: tuple[int, int, int] = (-1, -1, -1)
    params: np.ndarray = field(default=None, repr=False)  # type: ignore[arg-type]  # always set by from_geometry

    # ------------------------------------------------------------ construction
    @classmethod
    def from_geometry(
        cls,
        name: str,
        joint_names: tuple[str, str, str],
        foot_frame: str,
        origins,
        axes,
        foot,
        lower,
        upper,
        *,
        idx_q: tuple[int, int, int] = (-1, -1, -1),
        idx_v: tuple[int, int, int] = (-1, -1, -1),
    ) -> Leg:
        """A leg from its joint origins (3, 3), unit axes (3, 3) and foot (3,) at the neutral configuration.

        Checks the structure: ``|a1 . a2| <= PERPENDICULAR_TOL`` (the HAA axis perpendicular to the HFE axis),
        ``|a2 x a3| <= PARALLEL_TOL`` (parallel pitch axes), nonzero thigh ``k`` and shank ``l`` in the pitch
        plane. Then ``e2 = a2``, ``e1`` = ``a1`` made exactly orthogonal to ``e2``, ``e3 = e1 x e2``,
        ``s3 = sign(a2 . a3)``, ``d = e2 . (f - o1)``, and ``h, k, l`` as pitch-plane coordinates.

        Raises:
            LegStructureError: the deviation, named (e.g. "HFE axis is 0.3 deg off parallel to KFE axis").
        """
        o = np.asarray(origins, dtype=float).reshape(3, 3)
        ax = np.asarray(axes, dtype=float).reshape(3, 3)
        f = np.asarray(foot, dtype=float).reshape(3)
        j1, j2, j3 = joint_names
        if not (np.isfinite(o).all() and np.isfinite(ax).all() and np.isfinite(f).all()):
            raise LegStructureError(f"leg {name}: non-finite joint origins, axes or foot position")
        a1 = _unit(ax[0], f"leg {name}: HAA axis ({j1})")
        a2 = _unit(ax[1], f"leg {name}: HFE axis ({j2})")
        a3 = _unit(ax[2], f"leg {name}: KFE axis ({j3})")
        dot12 = float(a1 @ a2)
        if abs(dot12) > PERPENDICULAR_TOL:
            off = math.degrees(math.asin(min(1.0, abs(dot12))))
            raise LegStructureError(
                f"leg {name}: HAA axis ({j1}, {a1.round(6).tolist()}) is {off:.3g} deg off perpendicular to the "
                f"HFE axis ({j2}, {a2.round(6).tolist()}); an HAA-HFE-KFE leg needs |a1 . a2| <= {PERPENDICULAR_TOL:g}"
            )
        cross23 = float(np.linalg.norm(np.cross(a2, a3)))
        if cross23 > PARALLEL_TOL:
            off = math.degrees(math.atan2(cross23, abs(float(a2 @ a3))))
            raise LegStructureError(
                f"leg {name}: HFE axis ({j2}, {a2.round(6).tolist()}) is {off:.3g} deg off parallel to the KFE axis "
                f"({j3}, {a3.round(6).tolist()}); an HAA-HFE-KFE leg needs |a2 x a3| <= {PARALLEL_TOL:g}"
            )
        e2 = a2
        e1 = _unit(a1 - (a1 @ e2) * e2, f"leg {name}: HAA axis")
        e3 = np.cross(e1, e2)
        s3 = 1.0 if float(a2 @ a3) > 0 else -1.0

        def plane(v):
            return np.array([float(v @ e3), float(v @ e1)])

        h, k, l = plane(o[1] - o[0]), plane(o[2] - o[1]), plane(f - o[2])
        kn, ln = float(np.hypot(*k)), float(np.hypot(*l))
        if kn <= 1e-9:
            raise LegStructureError(
                f"leg {name}: the KFE axis ({j3}) passes through the HFE axis ({j2}): thigh length {kn:.3g} m"
            )
        if ln <= 1e-9:
            raise LegStructureError(
                f"leg {name}: the foot ({foot_frame}) lies on the KFE axis ({j3}): shank length {ln:.3g} m"
            )
        d = float(e2 @ (f - o[0]))
        lo = np.asarray(lower, dtype=float).reshape(3)
        hi = np.asarray(upper, dtype=float).reshape(3)
        if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo > hi):
            raise LegStructureError(f"leg {name}: bad joint limits lower={lo.tolist()}, upper={hi.tolist()}")
        mid = np.where(np.isfinite(lo) & np.isfinite(hi), 0.5 * (lo + hi), np.clip(0.0, lo, hi))
        g = np.zeros(_NPARAMS)
        g[_O:_O + 3], g[_E1:_E1 + 3], g[_E2:_E2 + 3], g[_E3:_E3 + 3] = o[0], e1, e2, e3
        g[_D] = d
        g[_H:_H + 2], g[_K:_K + 2], g[_L:_L + 2] = h, k, l
        g[_S3] = s3
        g[_KN], g[_LN] = kn, ln
        g[_PK], g[_PL] = math.atan2(k[1], k[0]), math.atan2(l[1], l[0])
        g[_LO:_LO + 3], g[_HI:_HI + 3] = lo, hi
        g[_A1:_A1 + 3], g[_A2:_A2 + 3], g[_A3:_A3 + 3] = a1, a2, a3
        g[_V21:_V21 + 3], g[_V32:_V32 + 3], g[_V3F:_V3F + 3] = o[1] - o[0], o[2] - o[1], f - o[2]
        # The ideal structure (e1 perpendicular to e2 = +-a3) differs from the measured one by at most the axis
        # deviations (rad) times the lever arms: its reach boundaries get that much slack (then exact check).
        lever = float(np.linalg.norm(o[1] - o[0]) + np.linalg.norm(o[2] - o[1]) + np.linalg.norm(f - o[2]))
        g[_SLACK] = REACH_TOL + 4.0 * (abs(dot12) + cross23 + 1e-15) * lever
        return cls(
            name=str(name), joint_names=(str(j1), str(j2), str(j3)), foot_frame=str(foot_frame),
            lower=_frozen(lo), upper=_frozen(hi), origin=_frozen(o[0]), axes=_frozen(np.stack([a1, a2, a3])),
            hfe_origin=_frozen(o[1]), kfe_origin=_frozen(o[2]), foot_origin=_frozen(f),
            frame=_frozen(np.stack([e1, e2, e3])), lateral_offset=d, hip_offset=_frozen(h), thigh=_frozen(k),
            shank=_frozen(l), knee_sign=s3, q_ref=_frozen(mid), idx_q=(int(idx_q[0]), int(idx_q[1]), int(idx_q[2])),
            idx_v=(int(idx_v[0]), int(idx_v[1]), int(idx_v[2])), params=_frozen(g),
        )

    # ------------------------------------------------------------ derived numbers
    @property
    def thigh_length(self) -> float:
        """``|k|`` (m): HFE axis to KFE axis in the pitch plane."""
        return float(self.params[_KN])

    @property
    def shank_length(self) -> float:
        """``|l|`` (m): KFE axis to the foot in the pitch plane."""
        return float(self.params[_LN])

    @property
    def axis_labels(self) -> tuple[str, str, str]:
        """The joint axes in the root frame as ``"+x"``, ``"-y"``, ... (a vector when not along a root axis)."""
        return tuple(_axis_label(a) for a in self.axes)  # type: ignore[return-value]

    @property
    def knee_offset_angles(self) -> tuple[float, float]:
        """``(thigh_zero, knee_zero)`` (rad): the angle about ``a2`` from the root's down direction (-z, projected
        on the pitch plane) to the thigh ``k`` at q2 = 0, and the angle about ``a3`` from the thigh ``k`` to the
        shank ``l`` at q3 = 0 (0 for a straight leg; the zero offset of the knee)."""
        e1, e2, e3 = self.frame
        k = self.thigh[0] * e3 + self.thigh[1] * e1
        l = self.shank[0] * e3 + self.shank[1] * e1
        down = np.array([0.0, 0.0, -1.0])
        down = down - (down @ e2) * e2
        thigh_zero = _signed_angle(down, k, e2) if np.linalg.norm(down) > 1e-9 else float("nan")
        return thigh_zero, _signed_angle(k, l, self.axes[2])

    @property
    def axis_deviation(self) -> tuple[float, float]:
        """``(|a1 . a2|, |a2 x a3|)``: how far (rad) the measured axes are from perpendicular / parallel."""
        a1, a2, a3 = self.axes
        return abs(float(a1 @ a2)), float(np.linalg.norm(np.cross(a2, a3)))

    @property
    def reach(self) -> tuple[float, float]:
        """``(| |k| - |l| |, |k| + |l|)``: the knee's inner and outer reach (m) in the pitch plane."""
        return abs(self.thigh_length - self.shank_length), self.thigh_length + self.shank_length

    def summary(self) -> dict:
        """The extracted geometry as plain numbers (for tables)."""
        tz, kz = self.knee_offset_angles
        return {
            "leg": self.name, "joints": list(self.joint_names), "foot": self.foot_frame,
            "axes": list(self.axis_labels), "knee_sign": self.knee_sign,
            "haa_origin": self.origin.tolist(), "lateral_offset": self.lateral_offset,
            "hip_offset": self.hip_offset.tolist(), "thigh": self.thigh.tolist(), "shank": self.shank.tolist(),
            "thigh_length": self.thigh_length, "shank_length": self.shank_length,
            "thigh_zero_deg": math.degrees(tz), "knee_zero_deg": math.degrees(kz),
            "lower": self.lower.tolist(), "upper": self.upper.tolist(),
        }

    def __repr__(self) -> str:
        return (
            f"Leg({self.name!r}, joints={self.joint_names}, foot={self.foot_frame!r}, axes={self.axis_labels}, "
            f"d={self.lateral_offset:.4f} m, thigh={self.thigh_length:.4f} m, shank={self.shank_length:.4f} m)"
        )

    # ------------------------------------------------------------ kinematics
    def fk(self, q) -> np.ndarray:
        """Foot position (m, root frame) of the joint values ``q`` (3,) or (..., 3).

        ``p = o1 + u1 e1 + (cos q1 d - sin q1 u3) e2 + (sin q1 d + cos q1 u3) e3`` with
        ``(u3, u1) = h + Rot(q2) [k + Rot(s3 q3) l]`` (see the module docstring).

        Raises:
            InvalidInputError: ``q`` not a finite real array (..., 3).
        """
        if q.__class__ is np.ndarray and q.shape == _S3SHAPE and q.dtype is _F64:  # a single call, fast
            out = np.empty(3)
            if _fk_k(q, self.params, out) == OK:
                return out
        arr = as_input(q, "q", _S3SHAPE)
        if arr.ndim == 1:
            out = np.empty(3)
            _fk_k(arr, self.params, out)
            return out
        rows = as_rows(arr, 3)
        out = np.empty_like(rows)
        _fk_batch(rows, self.params, out)
        return out.reshape(arr.shape)

    def jacobian(self, q) -> np.ndarray:
        """``dp/dq`` (3, 3) or (..., 3, 3): column j is the foot velocity (root frame) per unit rate of joint j.

        ``dp/dq1 = e1 x (p - o1)``; with ``perp(X, Y) = (-Y, X)`` and the pitch-plane vectors
        ``w = Rot(q2) v``, ``g = Rot(q2) s3 perp(Rot(s3 q3) l)``: ``d(u3, u1)/dq2 = perp(w)``,
        ``d(u3, u1)/dq3 = g``, each mapped to the root frame by ``(X, Y) -> Y e1 - sin q1 X e2 + cos q1 X e3``.
        Equal to Pinocchio's LOCAL_WORLD_ALIGNED translational rows of the leg's columns (fixed base).

        Raises:
            InvalidInputError: ``q`` not a finite real array (..., 3).
        """
        if q.__class__ is np.ndarray and q.shape == _S3SHAPE and q.dtype is _F64:  # a single call, fast
            out = np.empty((3, 3))
            if _jacobian_k(q, self.params, out) == OK:
                return out
        arr = as_input(q, "q", _S3SHAPE)
        if arr.ndim == 1:
            out = np.empty((3, 3))
            _jacobian_k(arr, self.params, out)
            return out
        rows = as_rows(arr, 3)
        out = np.empty((rows.shape[0], 3, 3))
        _jacobian_batch(rows, self.params, out)
        return out.reshape(arr.shape + (3,))

    def _prepare(self, p, q_near):
        """Checked target rows and reference rows (m = 1 or n), the batch shape and whether it is a single call."""
        arr = as_input(p, "p", _S3SHAPE)
        if q_near is None:
            ref = self.q_ref.reshape(1, 3)
            batch = arr.shape[:-1]
        else:
            r = as_input(q_near, "q_near", _S3SHAPE)
            try:
                batch = np.broadcast_shapes(arr.shape[:-1], r.shape[:-1])
            except ValueError:
                raise InvalidInputError(
                    f"p (shape {arr.shape}) and q_near (shape {r.shape}) do not broadcast together; expected "
                    f"q_near of shape (3,) or the shape of p"
                ) from None
            if r.ndim == 1:
                ref = np.ascontiguousarray(r.reshape(1, 3))
            else:
                ref = as_rows(np.broadcast_to(r, batch + _S3SHAPE), 3)
            if arr.shape[:-1] != batch:
                arr = np.broadcast_to(arr, batch + _S3SHAPE)
        return as_rows(arr, 3), ref, batch, len(batch) == 0

    def _error(self, status: int, info: np.ndarray, p: np.ndarray):
        tgt = [float(x) for x in p]
        if status == _UNREACHABLE:
            miss, why = float(info[0]), info[1]
            lo, hi = self.reach
            if why == _IN_CYLINDER:
                text = (f"it lies {miss:.6g} m inside the abduction cylinder "
                        f"(radius |d| = {abs(self.lateral_offset):.6g} m about the HAA axis)")
            elif why == _TOO_FAR:
                text = f"it lies {miss:.6g} m beyond the leg's full stretch (|k| + |l| = {hi:.6g} m in the pitch plane)"
            else:
                text = f"it lies {miss:.6g} m inside the knee's inner reach (| |k| - |l| | = {lo:.6g} m)"
            return UnreachableError(f"target {tgt} is out of reach of leg {self.name} by {miss:.6g} m: {text}",
                                    target=p)
        if status == _JOINT_LIMIT:
            branches = self.ik_all(p)[0]
            return JointLimitError(
                f"target {tgt} of leg {self.name} is reachable only outside the joint limits "
                f"[{self.lower.tolist()}, {self.upper.tolist()}] (by {float(info[0]):.6g} rad at least); "
                f"branches {np.round(branches, 6).tolist()}",
                target=p,
            )
        return InvalidInputError(f"p must be finite, got {tgt}")  # pragma: no cover - as_input caught it

    def ik_all(self, p, *, q_near=None) -> tuple[np.ndarray, np.ndarray]:
        """Every IK branch of the target(s) ``p`` (m, root frame), joint limits ignored.

        Branches in :data:`BRANCHES` order ``(s_a, s_k)``: ``u3 = s_a sqrt(y^2 + z^2 - d^2)`` (abduction) and
        ``beta = s_k acos((|w|^2 - |k|^2 - |l|^2) / (2 |k||l|))`` (knee); each angle is the 2 pi representative
        nearest ``q_near`` (default :attr:`q_ref`, the mid-limit configuration). Coincident branches (on the
        singular sets ``u3 = 0`` or ``beta in {0, pi}``) appear twice.

        Args:
            p: targets (3,) or (..., 3).
            q_near: reference joint values (3,) or broadcastable with ``p``.

        Returns:
            ``(q_all, mask)``: (4, 3) or (..., 4, 3) with NaN rows for absent branches, and the (4,) or (..., 4)
            boolean mask of the branches that exist.

        Raises:
            UnreachableError: a single target with no branch (the message says by how much it misses).
            InvalidInputError: ``p`` or ``q_near`` not finite real arrays (..., 3), or not broadcastable.
        """
        rows, ref, batch, single = self._prepare(p, q_near)
        n = rows.shape[0]
        out = np.empty((n, 4, 3))
        status = np.empty(n, dtype=np.int64)
        info = np.zeros((n, 2))
        _ik_all_batch(rows, self.params, ref, out, status, info)
        if single and status[0] != OK:
            raise self._error(int(status[0]), info[0], rows[0])
        mask = np.isfinite(out[..., 0])
        return out.reshape(batch + (4, 3)), mask.reshape(batch + (4,))

    def ik(self, p, *, q_near=None, return_mask: bool = False):
        """Joint values placing the foot at ``p``: the branch inside the URDF limits nearest ``q_near``.

        For each branch of :meth:`ik_all`, each joint takes its 2 pi representative inside ``[lower, upper]``
        nearest ``q_near`` (an angle up to :data:`LIMIT_TOL` outside is clipped onto the limit); among the branches
        inside the limits the one with the least ``|q - q_near|^2`` wins (ties: the earlier branch).

        Args:
            p: targets (3,) or (..., 3), m, root frame.
            q_near: reference (3,) or broadcastable with ``p``; default :attr:`q_ref` (mid-limit).
            return_mask: also return the boolean mask of the solved targets.

        Returns:
            ``q`` (3,) or (..., 3) (NaN rows for unsolved batch items), and the mask if asked.

        Raises:
            UnreachableError: a single target out of reach (the message says by how much, and why).
            JointLimitError: a single target reachable only outside the joint limits.
            InvalidInputError: ``p`` / ``q_near`` not finite real arrays (..., 3), or not broadcastable.
            InvalidParameterError: ``return_mask`` not a bool.
        """
        if return_mask is not False and return_mask is not True:
            return_mask = check_flag(return_mask, "return_mask")
        if q_near is None and p.__class__ is np.ndarray and p.shape == _S3SHAPE and p.dtype is _F64:  # fast
            out = np.empty(3)
            info = np.zeros(2)
            st = _ik_k(p, self.params, self.q_ref, out, info)
            if st == OK:
                return (out, np.array(True)) if return_mask else out
            if st != _BAD_INPUT:
                raise self._error(st, info, p.copy())
        rows, ref, batch, single = self._prepare(p, q_near)
        n = rows.shape[0]
        out = np.empty((n, 3))
        status = np.empty(n, dtype=np.int64)
        info = np.zeros((n, 2))
        _ik_batch(rows, self.params, ref, out, status, info)
        ok = status == OK
        if single:
            return finish(out[0], ok[0], True, return_mask, lambda: self._error(int(status[0]), info[0], rows[0]))
        return finish(out.reshape(batch + (3,)), ok.reshape(batch), False, return_mask, _never)

    def within_limits(self, q, tol: float = 0.0) -> np.ndarray | bool:
        """Whether the joint values ``q`` (3,) or (..., 3) lie inside the URDF limits (widened by ``tol`` rad)."""
        arr = as_input(q, "q", _S3SHAPE)
        inside = np.all((arr >= self.lower - tol) & (arr <= self.upper + tol), axis=-1)
        return bool(inside) if arr.ndim == 1 else inside
