"""Forward kinematics of the tripod as kernels: the platform orientation from the three motor angles.

The closed-form start (the motor planes' intersection, not in the seed), the 3 x 2 least-squares Gauss-Newton
step in closed form, and the per-target iteration with early exit (:func:`_k_fk`); see :func:`legkin.tripod.fk`.

Start. Eliminating s_K2 from the two rows of eq (101) leaves one linear equation per motor,
``s_K1 x - c_K1 (c_K y + s_K z) = d (1 - c_alpha)``: E lies on three planes with unit normals
``n_K = (s_K1, -c_K1 c_K, -c_K1 s_K)``, the rows of M. Their intersection is
``E = d (1 - c_alpha) M^-1 (1, 1, 1)`` with ``M^-1 = [n_B x n_C, n_C x n_A, n_A x n_B] / det M``; for
``(J, K) = (K+1, K+2)`` the cross product is ``n_J x n_K = (c_J1 c_K1 sin(eta_K - eta_J),
s_J1 c_K1 s_K - c_J1 s_K1 s_J, c_J1 s_K1 c_J - s_J1 c_K1 c_K)``. Pushed onto the sphere |E| = L (eq 64a), E gives
the platform axis ``r = R e_x = 2 (e_x . e) e - e_x`` (e = E / |E|: E is on the bisector, see
:func:`legkin.tripod.platform_position`), i.e. ``r = (2 E_x^2 - |E|^2, 2 E_x E_y, 2 E_x E_z) / |E|^2`` (invariant
under E -> -E and scaling, so only the direction of ``adj(M) (1, 1, 1)`` is needed), and
``(alpha_y, alpha_z) = (-asin(r_z), atan2(r_y, r_x))`` as in :func:`legkin.tripod.orientation_from_axis`.
fk refuses ``|det M| < DET_GUARD`` before iterating, so nearly parallel planes never need a least-squares
intersection.

Step. ``-pinv(A) r`` for ``A = [a1 a2]`` (3 x 2) without an SVD: with ``n = a1 x a2``, ``|n|^2 = det(A^T A)``
(Lagrange's identity) and the normal equations solved by Cramer's rule, ``x = ((r x a2) . n, (a1 x r) . n) / |n|^2``.
Written with cross products, no entry of ``A^T A`` is formed, so the error grows like cond(A), not cond(A)^2.
Where ``sigma_2 <= STEP_RCOND sigma_1`` (i.e. ``|n|^2 <= STEP_RCOND^2 |A|_F^4``: ``alpha_y`` at +-pi/2 makes the
second column vanish), the rank-1 pseudo-inverse ``A^T r / |A|_F^2`` is used, as ``np.linalg.pinv`` with that
rcond would (``0`` for ``A = 0``).
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_kernel, kernel
from .._rotations import wrap_k
from ._common import (
    DET_GUARD,
    GAIN_GUARD,
    ST_GAIN,
    ST_INCONSISTENT,
    ST_LEFT,
    ST_NONFINITE,
    ST_NOT_CONVERGED,
    ST_OUTSIDE,
    ST_SINGULAR_PLANES,
)
from .closure import _k_inside, _k_jac, _k_plane_cross, _k_plane_dot, _k_pose
from .geometry import G_K

#: Relative singular-value cut-off of the Gauss-Newton step (that of ``np.linalg.pinv(A_u, rcond=1e-12)``).
STEP_RCOND = 1e-12
#: fk's consistency test accepts ``inconsistency <= max_inconsistency + ROUNDING_FLOOR |A_u|_F``: a pose stored in
#: floats (|u| <= pi, ulp <= 4.4e-16) reproduces its own motors only to ~ulp |A_u|, which exceeds 1e-9 rad
#: where |A_u| is huge (a leg within ~1e-5 of its boundary sin q_K2 = 0 next to the flip: |A_u| ~ 1e9).
#: Elsewhere (|A_u| <= ~1e3) the allowance is below 3e-12 rad.
ROUNDING_FLOOR = 4.0 * math.pi * 2.0**-52


@kernel(entry=True)
def _k_initial_guess(qa, qb, qc, G):  # type: ignore[no-untyped-def]
    """Closed-form start of fk from the motors (the motor planes' adjugate intersection, see the module docstring):
    (alpha_y, alpha_z, det M). With ``1 - c_alpha = 0`` (E = 0) the start is the home direction."""
    s = (np.sin(qa), np.sin(qb), np.sin(qc))
    c = (np.cos(qa), np.cos(qb), np.cos(qc))
    det3 = 0.0
    ex = 0.0
    ey = 0.0
    ez = 0.0
    for K in range(3):
        x, y, z = _k_plane_cross(K, s, c, G)
        det3 += _k_plane_dot(K, s, c, G, x, y, z)
        ex += x
        ey += y
        ez += z
    if G[G_K] == 0.0:
        ex, ey, ez = -1.0, 0.0, 0.0
    ee = ex * ex + ey * ey + ez * ez
    t = ex + ex
    ay = -np.arcsin(min(max(t * ez / ee, -1.0), 1.0))
    az = np.arctan2(t * ey, t * ex - ee)
    return ay, az, det3 / 3.0


@kernel(inline=True)
def _k_rank1(a1, a2, r, f):  # type: ignore[no-untyped-def]
    """The rank-1 step's pieces for A = [a1 a2] of squared Frobenius norm ``f``: ``(a1 . r, a2 . r, fs)`` with
    ``fs = f`` (1 where f is not > 0), so that ``A^+ r ~ A^T r / fs`` where ``sigma_2 <= STEP_RCOND sigma_1``."""
    fs = f if f > 0 else 1.0
    u0 = 0.0
    u1 = 0.0
    for K in range(3):
        u0 += a1[K] * r[K]
        u1 += a2[K] * r[K]
    return u0, u1, fs


@kernel(inline=True)
def _k_cross(u, v):  # type: ignore[no-untyped-def]
    """``u x v`` for (3,) arrays, as three numbers."""
    return u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]


@kernel(inline=True)
def _k_normal(a1, a2):  # type: ignore[no-untyped-def]
    """For A = [a1 a2]: the normal ``n = a1 x a2`` of its range (three numbers), ``|n|^2`` and ``|A|_F^2``."""
    n0, n1, n2 = _k_cross(a1, a2)
    f = 0.0
    for K in range(3):
        f += a1[K] * a1[K] + a2[K] * a2[K]
    return n0, n1, n2, n0 * n0 + n1 * n1 + n2 * n2, f


@kernel
def _k_gn_step(a1, a2, r):  # type: ignore[no-untyped-def]
    """``-pinv([a1 a2]) r`` in closed form (the module docstring, "Step") for (3,) columns: (s0, s1) =
    ``((a2 x r) . n, (r x a1) . n) / |n|^2``, n = a1 x a2."""
    n0, n1, n2, nn, f = _k_normal(a1, a2)
    b0, b1, b2 = _k_cross(a2, r)
    c0, c1, c2 = _k_cross(r, a1)
    s0, s1 = (b0 * n0 + b1 * n1 + b2 * n2) / nn, (c0 * n0 + c1 * n1 + c2 * n2) / nn
    if nn <= (STEP_RCOND * STEP_RCOND) * f * f:
        u0, u1, fs = _k_rank1(a1, a2, r, f)
        s0, s1 = -u0 / fs, -u1 / fs
    return s0, s1


@kernel(inline=True)
def _k_normal_residual(a1, a2, r):  # type: ignore[no-untyped-def]
    """|r - A A^+ r| and |A|_F for A = [a1 a2] (the part of r off the range of A: rank 2 ``|r . n| / |n|``,
    n = a1 x a2; rank-1 projection where ``sigma_2 <= STEP_RCOND sigma_1``)."""
    n0, n1, n2, nn, f = _k_normal(a1, a2)
    out = abs(r[0] * n0 + r[1] * n1 + r[2] * n2) / np.sqrt(nn)
    if not nn > (STEP_RCOND * STEP_RCOND) * f * f:
        u0, u1, fs = _k_rank1(a1, a2, r, f)
        pp = 0.0
        for K in range(3):
            p = r[K] - (a1[K] * u0 + a2[K] * u1) / fs
            pp += p * p
        out = np.sqrt(pp)
    return out, np.sqrt(f)


@kernel(inline=True)
def _k_shrunk(ay, az, f):  # type: ignore[no-untyped-def]
    """The orientation of tilt (1 - f) theta in the direction of (ay, az) (towards home)."""
    cy = np.cos(ay)
    r0, r1, r2 = np.cos(az) * cy, np.sin(az) * cy, -np.sin(ay)
    theta = np.arccos(min(max(r0, -1.0), 1.0)) * (1.0 - f)
    side = np.hypot(r1, r2)
    side = side if side > 0 else 1.0
    st = np.sin(theta) / side
    return -np.arcsin(min(max(r2 * st, -1.0), 1.0)), np.arctan2(r1 * st, np.cos(theta))


@kernel
def _k_fk_report(ay, az, qm, G, home, e, s, a1, a2, q1, c2, s2, sn, cn, r, last):  # type: ignore[no-untyped-def]
    """The reported pose (alpha_y in [-pi/2, pi/2]), its inconsistency, ik's success test and the rounding floor.
    ``last`` = (alpha_y, alpha_z, 1 + c_y c_z) of the pose q1, c2, ... were last evaluated at: reused when the
    reported pose is that one (the usual exit: converged without a further step)."""
    if np.cos(ay) < 0:
        ay, az = math.pi - ay, az + math.pi
    ay, az = wrap_k(ay), wrap_k(az)
    if ay == last[0] and az == last[1] and ay != 0.0 and az != 0.0:  # (not at a signed zero: same bits)
        nb2 = last[2]
    else:
        nb2 = _k_pose(np.cos(ay), np.sin(ay), np.cos(az), np.sin(az), G, home, e, s, q1, c2, s2, sn, cn)
    for K in range(3):
        r[K] = wrap_k(q1[K] - qm[K])
    inc, norm_a = _k_normal_residual(a1, a2, r)
    return ay, az, inc, _k_inside(c2[0], c2[1], c2[2], nb2), ROUNDING_FLOOR * norm_a


@kernel(entry=True)
def _k_fk(qa, qb, qc, G, home, e, s, tol, max_iter, max_inc, out):  # type: ignore[no-untyped-def]
    """fk of one motor triple in one assembly mode: writes (alpha_y, alpha_z, inconsistency) into ``out`` (3,)
    and returns the status (0 ok, else the ST_ codes of :mod:`legkin.tripod._common`; :data:`ST_NONFINITE` for
    NaN / inf motors).

    Gauss-Newton from the motor planes' intersection, kept inside the workspace (a step that
    lands outside is halved, a start outside is pulled in towards home); early exit per target.
    See :func:`legkin.tripod.fk`.
    """
    if not (np.isfinite(qa) and np.isfinite(qb) and np.isfinite(qc)):
        out[0] = out[1] = out[2] = np.nan
        return ST_NONFINITE
    qm = np.empty(3)
    qm[0], qm[1], qm[2] = qa, qb, qc
    scratch = np.empty((8, 3))
    q1, c2, s2, sn, cn, r, a1, a2 = (scratch[0], scratch[1], scratch[2], scratch[3], scratch[4], scratch[5],
                                     scratch[6], scratch[7])
    ay, az, det = _k_initial_guess(qa, qb, qc, G)
    if not abs(det) >= DET_GUARD:
        out[0] = out[1] = out[2] = np.nan
        return ST_SINGULAR_PLANES
    y0, z0 = ay, az
    converged = False
    active = True
    rn_prev = np.inf
    py = pz = np.nan
    tries = 0
    a1[:] = np.nan
    a2[:] = np.nan
    last = (np.nan, np.nan, np.nan)
    for _ in range(max_iter):
        cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
        nb2 = _k_pose(cy, sy, cz, sz, G, home, e, s, q1, c2, s2, sn, cn)
        last = (ay, az, nb2)
        rr = 0.0
        for K in range(3):
            r[K] = wrap_k(q1[K] - qm[K])
            rr += r[K] * r[K]
        rn = np.sqrt(rr)
        good = _k_inside(c2[0], c2[1], c2[2], nb2) and np.isfinite(rn)
        if active and not converged and not good:
            tries += 1
            if tries > 6:
                active = False
            elif np.isfinite(py):  # halve the step from the last iterate inside
                ay, az = 0.5 * (py + ay), 0.5 * (pz + az)
            else:  # pull the start in
                ay, az = _k_shrunk(y0, z0, 10.0 ** (-14.0 + 2.0 * tries))
        work = active and not converged and good
        _k_jac(cy, sy, cz, sz, c2, s2, nb2, G, home, e, a1, a2)
        stalled = rn >= rn_prev  # no progress: at the (least-squares) minimum to rounding
        if work:
            rn_prev = rn
        f = 0.0
        for K in range(3):
            f += a1[K] * a1[K] + a2[K] * a2[K]
        at_floor = rn <= ROUNDING_FLOOR * np.sqrt(f)
        s0, s1 = _k_gn_step(a1, a2, r)
        motor_step = 0.0
        for K in range(3):
            v = abs(a1[K] * s0 + a2[K] * s1)
            if not v <= motor_step:  # NaN propagates, as np.maximum
                motor_step = v
        big = abs(s0)
        if not abs(s1) <= big:
            big = abs(s1)
        small = (big <= tol) or (motor_step <= tol) or stalled or at_floor
        if work:
            py, pz = ay, az
            if not at_floor:
                ay, az = ay + s0, az + s1
            if small:
                converged = True
        if converged or not active:
            break
    if not np.isfinite(py):
        active = False
    ry, rz, inc, inside, floor = _k_fk_report(ay, az, qm, G, home, e, s, a1, a2, q1, c2, s2, sn, cn, r, last)
    if converged and not inside:  # the last (tiny) step left the workspace: report the iterate before it
        last = (np.nan, np.nan, np.nan)  # q1, c2, ... now hold the reported pose's, not py's
        by, bz, binc, binside, bfloor = _k_fk_report(py, pz, qm, G, home, e, s, a1, a2, q1, c2, s2, sn, cn, r, last)
        if binside:
            ry, rz, inc, inside, floor = by, bz, binc, binside, bfloor
    out[0], out[1], out[2] = ry, rz, inc
    consistent = inc <= max_inc + floor
    tame = floor <= ROUNDING_FLOOR * GAIN_GUARD
    if not active:
        return ST_LEFT
    if not converged:
        return ST_NOT_CONVERGED
    if not inside:
        return ST_OUTSIDE
    if not tame:
        return ST_GAIN
    if not consistent:
        return ST_INCONSISTENT
    return OK


def _fk_loop(qm, G, homes, es, ss, tol, max_iter, max_inc, out, status):  # type: ignore[no-untyped-def]
    """fk over motors (n, 3) in the modes given (homes (m,), es (m,), ss (m, 3)): out (n, m, 3), status (n, m);
    NaN where an item fails."""
    n, m = qm.shape[0], homes.shape[0]
    for i in range(n):
        for j in range(m):
            st = _k_fk(qm[i, 0], qm[i, 1], qm[i, 2], G, homes[j], es[j], ss[j], tol, max_iter, max_inc, out[i, j])
            status[i, j] = st
            if st != OK:
                out[i, j, 0] = out[i, j, 1] = out[i, j, 2] = np.nan

FK_LOOP = batch_kernel(rows="qm out status", min_parallel=256)(_fk_loop)
