"""The foot IK as compiled kernels (seed 003: eqs 17-20 inverted, then eqs 3-16 per chain and eq 19 inverted).

Per closed-form branch (ll_branch, roll_branch, motor branch): the LL arc gives theta_LL, the foot direction gives
roll and pitch (:func:`platform_pose_k`), the chains give the motors (:func:`ik_candidate_k`). The mode-checked IK
(:func:`foot_ik_k`) keeps the first candidate (or the one nearest ``q_near``) that is inside the limits, in the mode
asked for, outside the forward-singularity band and reproduced by the forward kinematics; :func:`ik_all_k` labels
all 16 branches.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import OK, batch_kernel, kernel
from .._rotations import wrap_k
from ._ik_certify import CERTIFY_WORK, certify_k
from ._options import ST_ASSEMBLE, ST_INPUT, ST_REACH
from .chains import OX, OZ, chain_k, ref_of, rod_system_rates_cs_k, rot_cs_k, sgn_k, tips_k
from .extension import theta0_k
from .foot import gain_cs_k
from .forward import fk_select_k
from .geometry import (
    CLIP_FOOT_TOL,
    FK_GAIN_MAX,
    FOOT_IK_BRANCHES,
    FOOT_X,
    IK_K_TOL,
    LIMIT_TOL,
    LL0,
    LL_DELTA,
    LL_TOL,
    PITCH_SPLIT,
    PLATFORM_LIMIT,
    RATIO,
    RHO_TOL,
    H,
)

#: FOOT_IK_BRANCHES as a (16, 4) float array (ll_branch, roll_branch, b1, b2), for the kernels.
BRANCHES = np.array(FOOT_IK_BRANCHES, dtype=np.float64)


@kernel(entry=True)
def platform_pose_k(ux, uy, uz, llb, rb, pose, info):
    """(theta_LL, roll, pitch) (3,) placing the foot at u = p - CENTER, wrapped, for one (ll_branch, roll_branch).

    1. LL arc: ``|u|^2 = LL0^2 + h^2 - 2 h LL0 cos(theta_LL - delta)``, ``theta_LL = delta + ll_branch acos(kk)``;
    2. ``u = Rx(roll) v``, ``v = Ry(pitch) f``, ``v_y = 0``: ``v_z = +-|(u_y, u_z)|``,
       ``roll = atan2(-u_y / v_z, u_z / v_z)``, ``pitch = atan2(f_z, f_x) - atan2(v_z, u_x)``.

    info (3,) = (kk, LL arc reached (1/0), rho = distance from the roll axis).
    """
    r2 = ux * ux + uy * uy + uz * uz
    kk = (LL0 * LL0 + H * H - r2) / (2.0 * H * LL0)
    reach = math.isfinite(kk) and abs(kk) <= 1.0 + LL_TOL
    kc = min(max(kk if reach else 1.0, -1.0), 1.0)
    tll = LL_DELTA + llb * math.acos(kc)
    fx = OX + FOOT_X * math.cos(tll)
    fz = OZ - FOOT_X * math.sin(tll)
    rho = math.hypot(uy, uz)
    sg = (1.0 if uz >= 0.0 else -1.0) * rb
    vz = sg * rho
    if rho <= RHO_TOL:
        roll = 0.0 if rb > 0 else math.pi
    else:
        roll = math.atan2(-uy * sg, uz * sg)
    pitch = math.atan2(fz, fx) - math.atan2(vz, ux)
    pose[0], pose[1], pose[2] = wrap_k(tll), wrap_k(roll), wrap_k(pitch)
    info[0], info[1], info[2] = kk, 1.0 if reach else 0.0, rho


@batch_kernel(rows="u pose info", min_parallel=64)
def platform_pose_b(u, llb, rb, pose, info):
    for j in range(u.shape[0]):
        platform_pose_k(u[j, 0], u[j, 1], u[j, 2], llb, rb, pose[j], info[j])


@kernel(inline=True)  # hot, per candidate: inlined
def candidate_pose_k(ux, uy, uz, llb, rb, pose, arc, rot, trig):
    """The platform pose (3,) of one (ll_branch, roll_branch) (:func:`platform_pose_k`, arc (3,) its info), roll
    and pitch clipped to the platform limits within rounding, its rotation rot (3, 3) and trig (6,) = (cos, sin)
    of roll, pitch and theta_LL. Returns inside the limits."""
    platform_pose_k(ux, uy, uz, llb, rb, pose, arc)
    x1, x2 = pose[1], pose[2]
    near1 = abs(x1) <= PLATFORM_LIMIT + LIMIT_TOL
    near2 = abs(x2) <= PLATFORM_LIMIT + LIMIT_TOL
    if near1:  # rounding at a limit
        x1 = min(max(x1, -PLATFORM_LIMIT), PLATFORM_LIMIT)
    if near2:
        x2 = min(max(x2, -PLATFORM_LIMIT), PLATFORM_LIMIT)
    pose[1], pose[2] = x1, x2
    trig[0], trig[1], trig[2], trig[3] = math.cos(x1), math.sin(x1), math.cos(x2), math.sin(x2)
    trig[4], trig[5] = math.cos(pose[0]), math.sin(pose[0])
    rot_cs_k(trig[0], trig[1], trig[2], trig[3], rot)
    return near1 and near2


@kernel(inline=True)  # hot, per candidate: inlined
def candidate_motors_k(ux, uy, uz, sv, pose, arc, trig, inlim, b1, b2, th, kx, ok, motors, info, tip, dtip, g, nm,
                       dd):
    """The rest of one candidate (:func:`ik_candidate_k`) from its pose (3,), arc (3,) and trig (6,)
    (:func:`candidate_pose_k`) and the chains' motor angles th (2,), reach ratios kx (2,) and reach ok on
    branch (b1, b2); tip, dtip (2, 3), g, dd (2,), nm (2, 2) are work arrays. Returns the candidate exists."""
    kk, reach, rho = arc[0], arc[1] == 1.0, arc[2]
    x0 = pose[0]
    exists = reach and ok
    gain = math.inf
    mode = 0.0
    if exists:
        tips_k(th[0], th[1], tip, dtip)
        rod_system_rates_cs_k(trig[0], trig[1], trig[2], trig[3], tip, dtip, g, nm, dd)
        # a chain clipped at its reach boundary (|k| up to 1 + IK_K_TOL) leaves its rod off by g: the FK pose of
        # these motor angles moves by ~N^-1 g and the foot by at most |u| sqrt(2) times that
        det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
        s0 = (nm[1, 1] * g[0] - nm[0, 1] * g[1]) / det
        s1 = (nm[0, 0] * g[1] - nm[1, 0] * g[0]) / det
        shift = math.sqrt(s0 * s0 + s1 * s1) * math.sqrt(2.0) * math.sqrt(ux * ux + uy * uy + uz * uz)
        clipped = min(abs(abs(kx[0]) - 1.0), abs(abs(kx[1]) - 1.0)) <= IK_K_TOL
        exists = (not clipped) or shift <= CLIP_FOOT_TOL
        if exists:
            mode = sgn_k(det) * ref_of(b1, b2)
            gain = gain_cs_k(trig[0], trig[1], trig[2], trig[3], trig[4], trig[5], nm, dd)
    if exists:
        motors[0], motors[1], motors[2] = th[0], th[1], theta0_k(x0, sv)
    else:
        motors[0], motors[1], motors[2] = math.nan, math.nan, math.nan
    info[0] = 1.0 if exists else 0.0
    info[1] = 1.0 if inlim else 0.0
    info[2], info[3], info[4] = mode, gain, kk
    info[5] = 1.0 if reach else 0.0
    info[6] = 0.0 if rho > 0.0 else 1.0
    return exists


@kernel
def ik_candidate_k(ux, uy, uz, sv, llb, rb, b1, b2, pose, motors, info):
    """One (ll_branch, roll_branch, motor branch) closed-form candidate for the target u = p - CENTER.

    pose (3,) = (theta_LL, roll, pitch) (:func:`platform_pose_k`, clipped to the platform limits within rounding),
    motors (3,) = (theta1, theta2, theta0) (the chains with IK_K_TOL, eq 19 inverted), NaN where the candidate does
    not exist; info (7,) = (exists, inlim, mode, gain, kk, reach, axis) as floats. Returns OK if the candidate
    exists, else ST_REACH.
    """
    arc = np.empty(3)
    rot = np.empty((3, 3))
    trig = np.empty(6)
    inlim = candidate_pose_k(ux, uy, uz, llb, rb, pose, arc, rot, trig)
    th = np.empty(2)
    kx = np.empty(2)
    ok1 = chain_k(rot, 0, b1, IK_K_TOL, th, kx)
    ok2 = chain_k(rot, 1, b2, IK_K_TOL, th, kx)
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    g = np.empty(2)
    nm = np.empty((2, 2))
    dd = np.empty(2)
    exists = candidate_motors_k(ux, uy, uz, sv, pose, arc, trig, inlim, b1, b2, th, kx, ok1 and ok2, motors, info,
                                tip, dtip, g, nm, dd)
    return OK if exists else ST_REACH


@kernel(inline=True)
def reproduced_k(pose, motors, b1, b2, s, work):
    """The forward kinematics of the candidate's motors in mode (b1, b2), s returns its pose. The neutral aspect
    (branch (1, 1), mode +1, pitch < PITCH_SPLIT) is one-to-one and nearer R_P = I than the other region of that
    mode: there the forward kinematics returns exactly these poses; elsewhere the certificate of
    :func:`._ik_certify.certify_k` (no nearer pose of the mode among the rods' polynomial roots) decides, and
    where it cannot, the forward kinematics is asked. work: (CERTIFY_WORK,)."""
    if b1 == 1.0 and b2 == 1.0 and s == 1.0 and pose[2] < PITCH_SPLIT:
        return True
    if certify_k(pose, motors, b1, b2, s, work):
        return True
    xf = np.empty(2)
    if fk_select_k(motors[0], motors[1], b1, b2, s, 1e-12, 50, xf) != OK:
        return False
    return max(abs(xf[0] - pose[1]), abs(xf[1] - pose[2])) <= 1e-7


@kernel(inline=True)
def accepted_k(pose, motors, info, b1, b2, s, work):
    """The mode-checked IK keeps the candidate: inside the limits, in mode (b1, b2), s, off the forward-singularity
    band, and reproduced by the forward kinematics (:func:`reproduced_k`)."""
    if not (info[0] == 1.0 and info[1] == 1.0 and info[2] == s and info[3] < FK_GAIN_MAX):
        return False
    return reproduced_k(pose, motors, b1, b2, s, work)


@kernel(inline=True)
def _joint_distance(motors, near):
    """Distance in the joints (MCS1, MCS2, LL): wrapped motor differences and the LL difference (RATIO dtheta0)."""
    d0 = wrap_k(motors[0] - near[0])
    d1 = wrap_k(motors[1] - near[1])
    d2 = RATIO * (motors[2] - near[2])
    return math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@kernel(inline=True)
def foot_ik_k(ux, uy, uz, sv, combos, b1, b2, s, limits_only, axis_ok, near, motors, pose):
    """The mode-checked foot IK of one target u = p - CENTER: the first candidate, in the order combos (k, 2) of
    (ll_branch, roll_branch), that :func:`accepted_k` keeps (limits_only: that reaches the LL arc inside the joint
    limits, as the default :func:`foot_platform_ik`; not axis_ok: off the roll axis); with ``near`` (3,) finite,
    the kept candidate nearest it in the joints instead. motors (3,), pose (3,); returns OK or ST_ASSEMBLE (NaN)."""
    info = np.empty(7)
    if not (math.isfinite(ux) and math.isfinite(uy) and math.isfinite(uz)):
        motors[:] = math.nan
        pose[:] = math.nan
        return ST_INPUT
    use_near = math.isfinite(near[0]) and math.isfinite(near[1]) and math.isfinite(near[2])
    best = math.inf
    bm = np.empty(3)
    bp = np.empty(3)
    work = np.empty(CERTIFY_WORK)
    for c in range(combos.shape[0]):
        ik_candidate_k(ux, uy, uz, sv, combos[c, 0], combos[c, 1], b1, b2, pose, motors, info)
        if limits_only:
            acc = info[5] == 1.0 and info[1] == 1.0
        else:
            acc = accepted_k(pose, motors, info, b1, b2, s, work)
        if acc and (axis_ok or info[6] == 0.0):
            if not use_near:
                return OK
            d = _joint_distance(motors, near)
            if d < best:
                best = d
                for k in range(3):  # element by element: an array assignment compiles numba's shape-error text
                    bm[k], bp[k] = motors[k], pose[k]
    if best < math.inf:
        for k in range(3):
            motors[k], pose[k] = bm[k], bp[k]
        return OK
    motors[:] = math.nan
    pose[:] = math.nan
    return ST_ASSEMBLE


@batch_kernel(rows="u near motors pose ok", min_parallel=64)
def foot_ik_b(u, sv, combos, b1, b2, s, limits_only, axis_ok, near, motors, pose, ok):
    for j in range(u.shape[0]):
        ok[j] = foot_ik_k(u[j, 0], u[j, 1], u[j, 2], sv, combos, b1, b2, s, limits_only, axis_ok, near[j],
                          motors[j], pose[j]) == OK


@kernel(entry=True)
def ik_all_k(ux, uy, uz, sv, fk_in_band, motors, pose, info, fk):
    """Every closed-form branch (BRANCHES order) of one target u = p - CENTER: motors (16, 3), pose (16, 3), info
    (16, 7) (:func:`ik_candidate_k`) and fk (16,): the branch exists inside the limits in a mode (+-1) and the
    forward kinematics of its motors in that mode returns its pose (judged in the forward-singularity band only
    with fk_in_band; False there otherwise). The four motor branches of one (ll_branch, roll_branch) share its
    platform pose and the chains' equations (BRANCHES lists them together, chain 1's branch +1 first)."""
    arc = np.empty(3)
    rot = np.empty((3, 3))
    trig = np.empty(6)
    th2 = np.empty((2, 2))  # [branch index, chain]: the motor angles on branch +1 (index 0) and -1
    kx2 = np.empty((2, 2))
    ok2 = np.empty((2, 2), dtype=np.bool_)
    th = np.empty(2)
    kx = np.empty(2)
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    g = np.empty(2)
    nm = np.empty((2, 2))
    dd = np.empty(2)
    work = np.empty(CERTIFY_WORK)
    for c in range(0, BRANCHES.shape[0], 4):
        inlim = candidate_pose_k(ux, uy, uz, BRANCHES[c, 0], BRANCHES[c, 1], pose[c], arc, rot, trig)
        for q in range(2):
            for i in range(2):
                ok2[q, i] = chain_k(rot, i, 1.0 - 2.0 * q, IK_K_TOL, th2[q], kx2[q])
        for j in range(c, c + 4):
            b1, b2 = BRANCHES[j, 2], BRANCHES[j, 3]
            q1, q2 = (0 if b1 > 0.0 else 1), (0 if b2 > 0.0 else 1)
            th[0], th[1], kx[0], kx[1] = th2[q1, 0], th2[q2, 1], kx2[q1, 0], kx2[q2, 1]
            pose[j, 0], pose[j, 1], pose[j, 2] = pose[c, 0], pose[c, 1], pose[c, 2]
            candidate_motors_k(ux, uy, uz, sv, pose[j], arc, trig, inlim, b1, b2, th, kx, ok2[q1, 0] and ok2[q2, 1],
                               motors[j], info[j], tip, dtip, g, nm, dd)
            live = info[j, 0] == 1.0 and info[j, 1] == 1.0 and info[j, 2] != 0.0
            live = live and (fk_in_band or info[j, 3] < FK_GAIN_MAX)
            fk[j] = live and reproduced_k(pose[j], motors[j], b1, b2, info[j, 2], work)


@kernel(entry=True, inline=True)  # entry: ik_all's single call (the 1-row batch loop costs ~0.6 us)
def ik_all_out_k(ux, uy, uz, sv, motors, pose, mask, asm, within, valid):
    """:func:`ik_all` of one target: motors, pose (16, 3) (NaN where the branch does not exist), mask (exists),
    asm (assembly mode, int), within (inside the limits, and exists), valid (fk reproduces it, off the band).
    Returns the target is finite (a non-finite one has no branch)."""
    info = np.empty((16, 7))
    fk = np.empty(16, dtype=np.bool_)
    ik_all_k(ux, uy, uz, sv, False, motors, pose, info, fk)
    for j in range(16):
        mask[j] = info[j, 0] == 1.0
        if not mask[j]:
            pose[j, 0], pose[j, 1], pose[j, 2] = math.nan, math.nan, math.nan
        asm[j] = int(info[j, 2])
        within[j] = info[j, 1] == 1.0 and mask[j]
        valid[j] = fk[j] and info[j, 3] < FK_GAIN_MAX
    return math.isfinite(ux) and math.isfinite(uy) and math.isfinite(uz)


@batch_kernel(rows="u motors pose mask asm within valid", min_parallel=32)
def ik_all_b(u, sv, motors, pose, mask, asm, within, valid):
    for j in range(u.shape[0]):
        ik_all_out_k(u[j, 0], u[j, 1], u[j, 2], sv, motors[j], pose[j], mask[j], asm[j], within[j], valid[j])
