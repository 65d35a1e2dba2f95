"""The loop-closure equations of the legs as kernels: platform centre, seed eqs (98), (102) (IK of a leg),
Appendix D eqs (103)-(105) (the actuation Jacobian A_u), and the motor planes' determinant.

Per leg K (``c_K = cos eta_K``, ``s_K = sin eta_K``), with E = (x, y, z) the platform centre:

* eq (98): ``cos q_K2 = (c_K z - s_K y) / (d s_alpha)``, ``q_K2 = acos(.) in (0, pi)`` (home mode);
* eq (102): ``(s_K1, c_K1) = [[1 - c_alpha, s2 s_alpha], [-s2 s_alpha, 1 - c_alpha]] (x, -(c_K y + s_K z)) / d~``,
  ``q_K1 = atan2(s_K1, c_K1)``, ``d~ = d ((1 - c_alpha)^2 + (s2 s_alpha)^2)`` (the seed's determinant of (101) is
  wrong, see :func:`legkin.tripod.ik`);
* ``q_K3 = q_K2`` and ``q_K4 = q_K1`` (the constant-velocity branch).

Kernels take the geometry as the float vector of :mod:`legkin.tripod.geometry` (``Geometry._vector``) and an
assembly mode as (home flag, side e of E, signs s of sin q_K2).
"""

from __future__ import annotations

import numpy as np

from .._kernels import OK, batch_kernel, kernel
from ._common import BOUNDARY_TOL, DET_GUARD, GAIN_GUARD, SINGULAR_TOL, ST_FAIL, ST_NONFINITE
from .geometry import G_CA, G_CE, G_D, G_DSA, G_K, G_K2, G_ML, G_OPC, G_SA, G_SE, G_TH, G_W
from .platform import _k_one_plus_cc


@kernel
def _k_centre(cy, sy, cz, sz, G, home, e):  # type: ignore[no-untyped-def]
    """Platform centre E = e L b / |b| (:func:`legkin.tripod.platform_position` in the home mode, e = -1):
    (x, y, z, 1 + c_y c_z); NaN where 1 + c_y c_z <= SINGULAR_TOL."""
    nb2 = _k_one_plus_cc(cy, sy, cz, sz)
    lead = G[G_ML] if home else -e * G[G_ML]
    scale = lead / np.sqrt(2.0 * nb2) if nb2 > SINGULAR_TOL else np.nan
    return nb2 * scale, sz * cy * scale, -sy * scale, nb2


@kernel
def _k_leg(K, x, y, z, G, home, s):  # type: ignore[no-untyped-def]
    """Seed eqs (98), (102) for leg K at E = (x, y, z): (q1, q2, cos q2, sin q2, sin q1 (unnormalised), cos q1).
    ``s``: the sign of sin q_K2 (ignored in the home mode)."""
    ce, se = G[G_CE + K], G[G_SE + K]
    c2 = (ce * z - se * y) / G[G_DSA]  # eq (98)
    q2 = np.arccos(c2)  # NaN where |c2| > 1
    if not home:
        q2 = s * q2
    s2 = np.sin(q2)
    w = -(ce * y + se * z)
    s2sa = s2 * G[G_SA]
    det = G[G_D] * (G[G_K2] + s2sa * s2sa)
    sn = (G[G_K] * x + s2sa * w) / det
    cn = (-s2sa * x + G[G_K] * w) / det
    return np.arctan2(sn, cn), q2, c2, s2, sn, cn  # eq (102)


@kernel
def _k_inside(c2a, c2b, c2c, nb2):  # type: ignore[no-untyped-def]
    """The IK's success test: not singular (1 + c_y c_z > SINGULAR_TOL) and every leg 1 - |cos q_K2| > BOUNDARY_TOL
    (False on NaN)."""
    return (nb2 > SINGULAR_TOL) and (1.0 - abs(c2a) > BOUNDARY_TOL) and (1.0 - abs(c2b) > BOUNDARY_TOL) and (
        1.0 - abs(c2c) > BOUNDARY_TOL
    )


@kernel
def _k_jac_home(K, cy, sy, cz, sz, s2, n, G):  # type: ignore[no-untyped-def]
    """Seed eqs (103)-(105), row K of A_u (home mode): (A_K1, A_K2), the expressions of
    :func:`legkin.tripod.jacobian`'s docstring evaluated in the same order (repeated sub-expressions computed once)."""
    ck, sk = G[G_CE + K], G[G_SE + K]
    cpc = cy + cz
    ck_cpc, sk_cpc = ck * cpc, sk * cpc
    ck_sy, sk_sy, ck_cy = ck * sy, sk * sy, ck * cy
    ck_sy_sz, sk_sy_sz = ck_sy * sz, sk_sy * sz
    f = G[G_TH] * (ck_sy + sk * cy * sz)  # eq (105)
    m = G[G_OPC] * (s2 * s2) + 1 - G[G_CA]
    t = ck_cy * sz - sk_sy
    p = n * n + t * t
    den = 2 * s2 * (n * n) * m
    mf = -f
    a1 = mf * (ck_cpc - sk_sy_sz + (ck_cy - sk_sy_sz) * n) / den - (ck_sy_sz + sk_cpc) / p
    a2 = mf * cy * (sk_cpc + ck_sy_sz + sk * cz * n) / den + cy * (ck_cpc - sk_sy_sz) / p
    return a1, a2


@kernel
def _k_jac_general(K, cy, sy, cz, sz, c2, s2, n, G, e):  # type: ignore[no-untyped-def]
    """Row K of A_u in any assembly mode, by the chain rule through the mode's IK (:func:`_k_leg`).

    With ``E = e L b / sqrt(2 n)`` (n = 1 + c_y c_z): ``dE = e L (2 n)^(-1/2) (db - b dn / (2 n))``;
    ``d cos q2 = (c_K dz - s_K dy) / (d s_alpha)``, ``d sin q2 = -cos q2 d cos q2 / sin q2`` (either sign of
    sin q2); ``q1 = atan2(P, Q)`` with ``P = k x + sigma w``, ``Q = -sigma x + k w``, ``sigma = s_alpha sin q2``,
    ``w = -(c_K y + s_K z)``, ``k = 1 - c_alpha``: ``dq1 = (Q dP - P dQ) / (P^2 + Q^2)``. In the home mode it
    equals eqs (103)-(105) (:func:`_k_jac_home`) to rounding.
    """
    ce, se, k, sa = G[G_CE + K], G[G_SE + K], G[G_K], G[G_SA]
    lead = -e * G[G_ML] / np.sqrt(2.0 * n)
    bx, by, bz = n, sz * cy, -sy
    x, y, z = lead * bx, lead * by, lead * bz
    w = -(ce * y + se * z)
    sig = sa * s2
    p_, q_ = k * x + sig * w, -sig * x + k * w
    pq = p_ * p_ + q_ * q_
    out0 = 0.0
    out1 = 0.0
    for col in range(2):
        if col == 0:
            dn, dbx, dby, dbz = -sy * cz, -sy * cz, -sz * sy, -cy
        else:
            dn, dbx, dby, dbz = -cy * sz, -cy * sz, cz * cy, 0.0 * cy
        h = dn / (2.0 * n)
        dx, dy, dz = lead * (dbx - bx * h), lead * (dby - by * h), lead * (dbz - bz * h)
        dc2 = (ce * dz - se * dy) / G[G_DSA]
        dsig = sa * (-c2 * dc2 / s2)
        dw = -(ce * dy + se * dz)
        dp = k * dx + sig * dw + w * dsig
        dq = -sig * dx - x * dsig + k * dw
        v = (q_ * dp - p_ * dq) / pq
        if col == 0:
            out0 = v
        else:
            out1 = v
    return out0, out1


@kernel
def _k_pose(cy, sy, cz, sz, G, home, e, s, q1, c2, s2, sn, cn):  # type: ignore[no-untyped-def]
    """IK at the trig of u: fills q1, c2, s2, sn, cn (3,) per leg; returns 1 + c_y c_z."""
    x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, home, e)
    for K in range(3):
        q1[K], _q2, c2[K], s2[K], sn[K], cn[K] = _k_leg(K, x, y, z, G, home, s[K])
    return nb2


@kernel(inline=True)
def _k_jac(cy, sy, cz, sz, c2, s2, nb2, G, home, e, a1, a2):  # type: ignore[no-untyped-def]
    """Both columns of A_u (3,) each, in place."""
    for K in range(3):
        if home:
            a1[K], a2[K] = _k_jac_home(K, cy, sy, cz, sz, s2[K], nb2, G)
        else:
            a1[K], a2[K] = _k_jac_general(K, cy, sy, cz, sz, c2[K], s2[K], nb2, G, e)


@kernel(inline=True)
def _k_plane_cross(K, s, c, G):  # type: ignore[no-untyped-def]
    """``n_J x n_L`` (J, L = K + 1, K + 2 mod 3) of the motor planes' normals ``n_K = (s_K1, -c_K1 c_K,
    -c_K1 s_K)``, from the sin / cos tuples of the three motors: a column of the adjugate of M (the same
    products serve det M and fk's start, :func:`legkin.tripod.forward_kernels._k_initial_guess`)."""
    J, L = (K + 1) % 3, (K + 2) % 3
    p, q = c[J] * s[L], s[J] * c[L]
    x = c[J] * c[L] * G[G_W + K]
    y = q * G[G_SE + L] - p * G[G_SE + J]
    z = p * G[G_CE + J] - q * G[G_CE + L]
    return x, y, z


@kernel(inline=True)
def _k_plane_dot(K, s, c, G, x, y, z):  # type: ignore[no-untyped-def]
    """``n_K . (x, y, z)``: with (x, y, z) = :func:`_k_plane_cross` (K) the triple product det M."""
    return s[K] * x - c[K] * (G[G_CE + K] * y + G[G_SE + K] * z)


@kernel(inline=True)
def _k_det_planes(sa_, sb_, sc_, ca_, cb_, cc_, G):  # type: ignore[no-untyped-def]
    """det M of the motor planes' unit normals ``n_K = (s_K1, -c_K1 c_K, -c_K1 s_K)`` from sin / cos of the three
    motors: the triple product ``n_A . (n_B x n_C)`` (the mean of its three cyclic forms)."""
    s = (sa_, sb_, sc_)
    c = (ca_, cb_, cc_)
    tot = 0.0
    for K in range(3):
        x, y, z = _k_plane_cross(K, s, c, G)
        tot += _k_plane_dot(K, s, c, G, x, y, z)
    return tot / 3.0


@kernel(entry=True)
def _k_ik(ay, az, G, home, e, s, q, aux):  # type: ignore[no-untyped-def]
    """ik of one orientation in one assembly mode (seed eqs (98), (102)): writes the 12 joints into ``q`` (NaN
    unless ok) and (cos q_A2, cos q_B2, cos q_C2, 1 + c_y c_z, det M, |A_u|_F) into ``aux`` (6,); the motor gain
    |A_u|_F is the cheap bound sqrt(3/2) / (min |sin q_K2| sqrt(1 + c_y c_z)) (1.3 for sqrt(3/2), measured to
    hold), exact where that bound exceeds GAIN_GUARD. Returns OK, ST_FAIL or ST_NONFINITE."""
    if not (np.isfinite(ay) and np.isfinite(az)):
        q[:] = np.nan
        aux[:] = np.nan
        return ST_NONFINITE
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, home, e)
    q1a, q2a, c2a, s2a, sna, cna = _k_leg(0, x, y, z, G, home, s[0])
    q1b, q2b, c2b, s2b, snb, cnb = _k_leg(1, x, y, z, G, home, s[1])
    q1c, q2c, c2c, s2c, snc, cnc = _k_leg(2, x, y, z, G, home, s[2])
    det = _k_det_planes(sna, snb, snc, cna, cnb, cnc, G)
    inside = _k_inside(c2a, c2b, c2c, nb2)
    n = nb2 if inside else 1.0
    m = abs(s2a)
    for v in (abs(s2b), abs(s2c)):
        if not v >= m:  # NaN propagates, as np.minimum
            m = v
    gain = 1.3 / (m * np.sqrt(n))
    if gain > GAIN_GUARD:
        tot = 0.0
        for K in range(3):
            c2k = c2a if K == 0 else (c2b if K == 1 else c2c)
            s2k = s2a if K == 0 else (s2b if K == 1 else s2c)
            if home:
                j1, j2 = _k_jac_home(K, cy, sy, cz, sz, s2k, n, G)
            else:
                j1, j2 = _k_jac_general(K, cy, sy, cz, sz, c2k, s2k, n, G, e)
            tot += j1 * j1 + j2 * j2
        gain = np.sqrt(tot)
    aux[0], aux[1], aux[2], aux[3], aux[4], aux[5] = c2a, c2b, c2c, nb2, det, gain
    if inside and abs(det) >= DET_GUARD and gain <= GAIN_GUARD:
        _k_write(q, q1a, q2a, q1b, q2b, q1c, q2c)
        return OK
    q[:] = np.nan
    return ST_FAIL


@kernel(inline=True)
def _k_write(q, q1a, q2a, q1b, q2b, q1c, q2c):  # type: ignore[no-untyped-def]
    """The solution into ``q``: every joint (12,) (q_K3 = q_K2, q_K4 = q_K1) or the motors (3,)."""
    if q.shape[0] == 12:
        q[0], q[1], q[2], q[3] = q1a, q2a, q2a, q1a
        q[4], q[5], q[6], q[7] = q1b, q2b, q2b, q1b
        q[8], q[9], q[10], q[11] = q1c, q2c, q2c, q1c
    else:
        q[0], q[1], q[2] = q1a, q1b, q1c


@kernel(entry=True)
def _k_ik_all(ay, az, G, q, ok):  # type: ignore[no-untyped-def]
    """ik of one orientation in every assembly mode at once (:data:`legkin.tripod.MODES` order): writes each
    mode's joints into ``q[j]`` ((16, 12) every joint or (16, 3) the motors; NaN unless ok) and its success
    into ``ok[j]``; returns OK if some mode solves it, else ST_FAIL (ST_NONFINITE for NaN / inf).

    The 16 modes share their work: the platform centre once per side of E (``E = -+L b / |b|``), seed eqs (98),
    (102) once per (side, leg, sign of sin q_K2) -- 12 leg solutions instead of 48 -- and each mode combines
    three of them with its own det M, gain and guards. Every step is :func:`_k_ik`'s, in the same order, so mode
    j's answer is bit-identical to ``_k_ik`` in that mode (the home mode ``j = 0`` uses eqs (103)-(105) for
    the exact gain, as there).
    """
    if not (np.isfinite(ay) and np.isfinite(az)):
        q[:, :] = np.nan
        ok[:] = False
        return ST_NONFINITE
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    # legs[side, K, i] = (q1, q2, c2, s2, sn, cn) with side 0: E_x < 0 (e = -1), i = 0: sin q_K2 > 0
    legs = np.empty((2, 3, 2, 6))
    nbs = np.empty(2)
    for side in range(2):
        e = -1.0 if side == 0 else 1.0
        x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, False, e)
        nbs[side] = nb2
        for K in range(3):
            for i in range(2):
                sg = 1.0 if i == 0 else -1.0
                (legs[side, K, i, 0], legs[side, K, i, 1], legs[side, K, i, 2], legs[side, K, i, 3],
                 legs[side, K, i, 4], legs[side, K, i, 5]) = _k_leg(K, x, y, z, G, False, sg)
    found = False
    for j in range(16):
        side, ia, ib, ic = j // 8, (j // 4) % 2, (j // 2) % 2, j % 2
        la, lb, lc = legs[side, 0, ia], legs[side, 1, ib], legs[side, 2, ic]
        nb2 = nbs[side]
        det = _k_det_planes(la[4], lb[4], lc[4], la[5], lb[5], lc[5], G)
        inside = _k_inside(la[2], lb[2], lc[2], nb2)
        n = nb2 if inside else 1.0
        m = abs(la[3])
        for v in (abs(lb[3]), abs(lc[3])):
            if not v >= m:  # NaN propagates, as np.minimum
                m = v
        gain = 1.3 / (m * np.sqrt(n))
        if gain > GAIN_GUARD:
            e = -1.0 if side == 0 else 1.0
            tot = 0.0
            for K in range(3):
                lk = la if K == 0 else (lb if K == 1 else lc)
                if j == 0:
                    j1, j2 = _k_jac_home(K, cy, sy, cz, sz, lk[3], n, G)
                else:
                    j1, j2 = _k_jac_general(K, cy, sy, cz, sz, lk[2], lk[3], n, G, e)
                tot += j1 * j1 + j2 * j2
            gain = np.sqrt(tot)
        if inside and abs(det) >= DET_GUARD and gain <= GAIN_GUARD:
            _k_write(q[j], la[0], la[1], lb[0], lb[1], lc[0], lc[1])
            ok[j] = True
            found = True
        else:
            q[j, :] = np.nan
            ok[j] = False
    return OK if found else ST_FAIL


@kernel(entry=True)
def _k_actuation_jacobian(ay, az, G, home, e, s, a, aux):  # type: ignore[no-untyped-def]
    """A_u (3, 2) of one orientation in one mode into ``a`` (NaN unless inside the workspace), (cos q_K2 (3),
    1 + c_y c_z) into ``aux``; returns OK, ST_FAIL or ST_NONFINITE (see :func:`legkin.tripod.jacobian`)."""
    if not (np.isfinite(ay) and np.isfinite(az)):
        a[:, :] = np.nan
        aux[:] = np.nan
        return ST_NONFINITE
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, home, e)
    for K in range(3):
        _q1, _q2, c2, s2, _sn, _cn = _k_leg(K, x, y, z, G, home, s[K])
        aux[K] = c2
        if home:
            a[K, 0], a[K, 1] = _k_jac_home(K, cy, sy, cz, sz, s2, nb2, G)
        else:
            a[K, 0], a[K, 1] = _k_jac_general(K, cy, sy, cz, sz, c2, s2, nb2, G, e)
    aux[3] = nb2
    if _k_inside(aux[0], aux[1], aux[2], nb2):
        return OK
    a[:, :] = np.nan
    return ST_FAIL


def _ik_loop(ay, az, G, homes, es, ss, q, aux, status):  # type: ignore[no-untyped-def]
    """ik over orientations (n,) in the modes given (homes (m,), es (m,), ss (m, 3)): q (n, m, 12), aux (n, m, 6),
    status (n, m)."""
    n, m = ay.shape[0], homes.shape[0]
    for i in range(n):
        for j in range(m):
            status[i, j] = _k_ik(ay[i], az[i], G, homes[j], es[j], ss[j], q[i, j], aux[i, j])


def _ik_all_loop(ay, az, G, q, ok, status):  # type: ignore[no-untyped-def]
    """ik in every mode over orientations (n,): q (n, 16, 12 or 3), ok (n, 16), status (n,)."""
    for i in range(ay.shape[0]):
        status[i] = _k_ik_all(ay[i], az[i], G, q[i], ok[i])


def _jacobian_loop(ay, az, G, home, e, s, a, aux, status):  # type: ignore[no-untyped-def]
    """A_u over orientations (n,): a (n, 3, 2), aux (n, 4), status (n,)."""
    for i in range(ay.shape[0]):
        status[i] = _k_actuation_jacobian(ay[i], az[i], G, home, e, s, a[i], aux[i])


IK_LOOP = batch_kernel(rows="ay az q aux status", min_parallel=1024)(_ik_loop)
IK_ALL_LOOP = batch_kernel(rows="ay az q ok status", min_parallel=256)(_ik_all_loop)
JACOBIAN_LOOP = batch_kernel(rows="ay az a aux status", min_parallel=4096)(_jacobian_loop)
