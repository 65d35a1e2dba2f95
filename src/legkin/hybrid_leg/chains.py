"""The closed sub-chain's rod-length equations as compiled kernels (seed 003, eqs 2-16).

Each motor chain closes when ``|A_i - S_i(theta_i)| = L`` (the lever tip ``S_i`` of eqs 7, 14, the rod of
eqs 8, 15 and the platform point ``A_i = c + R_P a_i`` of eqs 9, 16). The kernels here are the building blocks
of every other module: the platform rotation, the closed form of each chain, the lever tips, the rod residuals
and their derivatives, and the sign of det N that defines the assembly modes.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, kernel
from .._rotations import wrap_k
from ._options import ST_INPUT, ST_REACH
from .geometry import ATTACH, BETA, CENTER, K_TOL, LEVER, LL_ORIGIN, MOTOR_POS, ROD_LENGTH

# the geometry as plain floats (numba freezes them into the kernels)
CX, CY, CZ = float(CENTER[0]), float(CENTER[1]), float(CENTER[2])
LX, LZ = float(LEVER[0]), float(LEVER[2])
PX0, PY0, PZ0 = (float(v) for v in MOTOR_POS[0])
PX1, PY1, PZ1 = (float(v) for v in MOTOR_POS[1])
AX0, AY0, AZ0 = (float(v) for v in ATTACH[0])
AX1, AY1, AZ1 = (float(v) for v in ATTACH[1])
OX, OZ = float(LL_ORIGIN[0]), float(LL_ORIGIN[2])
L = ROD_LENGTH


@kernel(entry=True)
def rot_k(r, p, m):
    """m (3, 3) = Rx(r) Ry(p), the universal centre (seed eq 2 with the universal joint)."""
    rot_cs_k(math.cos(r), math.sin(r), math.cos(p), math.sin(p), m)


@kernel
def rot_cs_k(cr, sr, cp, sp, m):
    """:func:`rot_k` from the cosines and sines of roll and pitch."""
    m[0, 0], m[0, 1], m[0, 2] = cp, 0.0, sp
    m[1, 0], m[1, 1], m[1, 2] = sr * sp, cr, -sr * cp
    m[2, 0], m[2, 1], m[2, 2] = -cr * sp, sr, cr * cp


@kernel(entry=True)
def rotation_error_k(m):
    """max |R^T R - I| of m (3, 3); inf if m has a non-finite entry or det m < 0 (not a rotation)."""
    err = 0.0
    for i in range(3):
        for j in range(3):
            if not math.isfinite(m[i, j]):
                return math.inf
            v = m[0, i] * m[0, j] + m[1, i] * m[1, j] + m[2, i] * m[2, j] - (1.0 if i == j else 0.0)
            err = max(err, abs(v))
    det = (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]) - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
           + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]))
    return err if det >= 0.0 else math.inf


@kernel(inline=True)
def is_rotation_k(m):
    """m is a rotation within 1e-9 (|R^T R - I| <= 1e-9, det >= 0), as the wrappers require."""
    return rotation_error_k(m) <= 1e-9


@kernel
def arm_k(m, i):
    """``m a_i``: chain i's platform point relative to the centre (eqs 9, 16), rotated by m (3, 3) (three numbers)."""
    if i == 0:
        ax, ay, az = AX0, AY0, AZ0
    else:
        ax, ay, az = AX1, AY1, AZ1
    return (m[0, 0] * ax + m[0, 1] * ay + m[0, 2] * az, m[1, 0] * ax + m[1, 1] * ay + m[1, 2] * az,
            m[2, 0] * ax + m[2, 1] * ay + m[2, 2] * az)


@kernel
def chain_k(m, i, bi, tol, theta, kout):
    """Chain i's rod-length equation (seed eqs 3-9, 10-16) for the platform rotation m (3, 3), branch bi.

    ``A cos(phi) + B sin(phi) = C`` with ``w = p_i - A_i``, ``A = l_x w_x``, ``B = l_x w_y``,
    ``C = (L^2 - |w|^2 - l_x^2 - l_z^2 - 2 l_z w_z) / 2``; ``phi = atan2(B, A) - sigma_i b_i acos(k)``,
    ``k = C / sqrt(A^2 + B^2)``. Writes theta[i] (wrapped; NaN when unreachable) and kout[i]; returns reachable.
    """
    if i == 0:
        px, py, pz, sg, yaw = PX0, PY0, PZ0, 1.0, BETA
    else:
        px, py, pz, sg, yaw = PX1, PY1, PZ1, -1.0, -BETA
    rx, ry, rz = arm_k(m, i)
    wx, wy, wz = px - (CX + rx), py - (CY + ry), pz - (CZ + rz)
    a = LX * wx
    b = LX * wy
    c = 0.5 * (L * L - (wx * wx + wy * wy + wz * wz) - LX * LX - LZ * LZ - 2.0 * LZ * wz)
    k = c / math.hypot(a, b)
    kout[i] = k
    if not (math.isfinite(k) and abs(k) <= 1.0 + tol):
        theta[i] = math.nan
        return False
    kc = min(max(k, -1.0), 1.0)
    theta[i] = wrap_k(math.atan2(b, a) - sg * bi * math.acos(kc) - yaw)
    return True


@kernel(entry=True)
def chains_k(m, b1, b2, tol, theta, kout):
    """Both chains (:func:`motor_angles_from_rotation`); returns _OK or ST_REACH (theta NaN then)."""
    ok1 = chain_k(m, 0, b1, tol, theta, kout)
    ok2 = chain_k(m, 1, b2, tol, theta, kout)
    if ok1 and ok2:
        return OK
    theta[0] = math.nan
    theta[1] = math.nan
    return ST_REACH


@kernel(entry=True)
def motor_angles_k(r, p, b1, b2, theta, kout):
    """:func:`motor_angles`: the chains at R_P = Rx(r) Ry(p)."""
    if not (math.isfinite(r) and math.isfinite(p)):
        theta[0] = math.nan
        theta[1] = math.nan
        return ST_INPUT
    m = np.empty((3, 3))
    rot_k(r, p, m)
    return chains_k(m, b1, b2, K_TOL, theta, kout)


@kernel
def tips_k(t1, t2, tip, dtip):
    """Lever tips S_i (2, 3) and dS_i/dtheta_i (seed eqs 7, 14) for motor angles t1, t2."""
    for i in range(2):
        if i == 0:
            phi, px, py, pz = t1 + BETA, PX0, PY0, PZ0
        else:
            phi, px, py, pz = t2 - BETA, PX1, PY1, PZ1
        c, s = math.cos(phi), math.sin(phi)
        tip[i, 0] = LX * c + px
        tip[i, 1] = LX * s + py
        tip[i, 2] = LZ + pz
        dtip[i, 0] = -LX * s
        dtip[i, 1] = LX * c
        dtip[i, 2] = 0.0


@kernel(inline=True)
def lever_tips_k(t1, t2):
    """:func:`tips_k` into new arrays: (tip (2, 3), dtip (2, 3))."""
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    tips_k(t1, t2, tip, dtip)
    return tip, dtip


@kernel
def rod_system_k(x0, x1, tip, g, nm):
    """Rod equations g_i = (|A_i - S_i|^2 - L^2) / 2 (2,) and N (2, 2) (N_ik = d_i . dA_i/dx_k) at (x0, x1).

    Returns max |g_i| (NaN if not finite)."""
    return rod_system_cs_k(math.cos(x0), math.sin(x0), math.cos(x1), math.sin(x1), tip, g, nm)


@kernel(inline=True)
def rod_arm_k(i, cr, sr, cp, sp):
    """``R_P a_i`` (m), chain i's platform attachment rotated by ``R_P = Rx(roll) Ry(pitch)`` given by the
    cosines and sines of roll and pitch (eqs 9, 16 less the centre c)."""
    if i == 0:
        ax, ay, az = AX0, AY0, AZ0
    else:
        ax, ay, az = AX1, AY1, AZ1
    return (cp * ax + sp * az, sr * sp * ax + cr * ay - sr * cp * az, -cr * sp * ax + sr * ay + cr * cp * az)


@kernel(inline=True)
def rod_rate_k(i, cr, sr, cp, sp, tip, dtip):
    """``D_i = (A_i - tip_i) . dtip_i``, the rate of rod i's residual per motor radian (m^2/rad), from the
    cosines and sines of roll and pitch."""
    rx, ry, rz = rod_arm_k(i, cr, sr, cp, sp)
    return ((CX + rx - tip[i, 0]) * dtip[i, 0] + (CY + ry - tip[i, 1]) * dtip[i, 1]
            + (CZ + rz - tip[i, 2]) * dtip[i, 2])


@kernel
def rod_system_cs_k(cr, sr, cp, sp, tip, g, nm):
    """:func:`rod_system_k` from the cosines and sines of roll and pitch."""
    worst = 0.0
    for i in range(2):
        rx, ry, rz = rod_arm_k(i, cr, sr, cp, sp)
        d0, d1, d2 = CX + rx - tip[i, 0], CY + ry - tip[i, 1], CZ + rz - tip[i, 2]
        g[i] = 0.5 * ((d0 * d0 + d1 * d1 + d2 * d2) - L * L)
        nm[i, 0] = -d1 * rz + d2 * ry
        nm[i, 1] = d0 * (cr * rz - sr * ry) + (d1 * sr - d2 * cr) * rx
        a = abs(g[i])
        if not (a <= worst):
            worst = a if math.isfinite(a) or math.isnan(worst) else math.nan
    return worst if math.isfinite(worst) else math.nan


@kernel
def sgn_k(v):
    return 1.0 if v > 0.0 else (-1.0 if v < 0.0 else (0.0 if v == 0.0 else math.nan))


@kernel
def rod_rates_k(r, p, tip, dtip, nm, dd):
    """The rod system's Jacobian ``N = dg/d(roll, pitch)`` (into nm) and ``D_i = (c_i - tip_i) . dtip_i``, the
    rate of rod i's residual per motor radian (into dd), at the pose (r, p) closed by the lever tips tip."""
    g = np.empty(2)
    rod_system_rates_k(r, p, tip, dtip, g, nm, dd)


@kernel
def rod_system_rates_k(r, p, tip, dtip, g, nm, dd):
    """:func:`rod_system_k` (g, nm) and the rates dd of :func:`rod_rates_k` at once (no work arrays)."""
    rod_system_rates_cs_k(math.cos(r), math.sin(r), math.cos(p), math.sin(p), tip, dtip, g, nm, dd)


@kernel
def rod_system_rates_cs_k(cr, sr, cp, sp, tip, dtip, g, nm, dd):
    """:func:`rod_system_rates_k` from the cosines and sines of roll and pitch."""
    rod_system_cs_k(cr, sr, cp, sp, tip, g, nm)
    for i in range(2):
        dd[i] = rod_rate_k(i, cr, sr, cp, sp, tip, dtip)


@kernel(entry=True)
def ref_sign_k(b1, b2):
    """Sign of det N at the neutral pose R_P = I on motor branch (b1, b2) (the reference of assembly +1)."""
    rot = np.eye(3)
    th = np.empty(2)
    kk = np.empty(2)
    chains_k(rot, b1, b2, K_TOL, th, kk)
    tip, dtip = lever_tips_k(th[0], th[1])
    g = np.empty(2)
    nm = np.empty((2, 2))
    rod_system_k(0.0, 0.0, tip, g, nm)
    return sgn_k(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0])


REF = np.array([[ref_sign_k(-1.0, -1.0), ref_sign_k(-1.0, 1.0)], [ref_sign_k(1.0, -1.0), ref_sign_k(1.0, 1.0)]])


@kernel
def ref_of(b1, b2):
    return REF[1 if b1 > 0 else 0, 1 if b2 > 0 else 0]

