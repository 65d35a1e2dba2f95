"""Validation of :mod:`legkin.tripod` against Pinocchio, for alpha in {pi/3 (default), pi/4, pi/2}."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._checkkit import CheckResult, classify_failures, compare, per_sample, pinocchio_frames, robustness_row
from .._rotations import rotation_angle as _rot_err
from .._rotations import wrap
from ..errors import LoopClosureError
from ..robot import load
from . import kinematics as at
from ._common import BOUNDARY_TOL, HOME_MODE, SINGULAR_TOL
from .configuration import MOTOR_COLUMNS, sample_workspace
from .inverse import _run

TOL = 1e-12
#: The parameter sets checked: the default (alpha = pi/3) and alpha = pi/4, pi/2 (generated into the cache).
ALPHAS = (("pi/3", math.pi / 3), ("pi/4", math.pi / 4), ("pi/2", math.pi / 2))
#: A_u from Pinocchio (:func:`_pin_actuation_jacobian`) is an SVD null space N of the constraint Jacobian, mapped to
#: (alpha_y, alpha_z) by the 2x2 matrix G and inverted: A_u = N[actuated] G^-1. Its difference from the analytic
#: A_u, relative to max(1, |A_u|), is bounded by eps x the amplification s_1 / s_10 (the SVD's gap: N's error) +
#: cond(G) (the inverse's) + 1 / cos^2 alpha_y (G's rows divide by cos alpha_y and cos^2 alpha_y: the
#: parametrization's singularity at alpha_y = +-pi/2) + 1 / (1 + c_y c_z) (the flip, where |A_u| grows like it),
#: times a constant of the floating-point operations: the row reports error / (eps x amplification) against
#: AMP_CONSTANT. scripts/tripod_conditioning_sweep.py measured it over 20 seeds x 10^3, 10^4, 10^5 samples at each
#: alpha: median ~0.15, largest 24.8 at alpha = pi/2, 37.8 at pi/4 and 41.7 at pi/3 (near the flip, where the
#: errors reach 2.4e-9 with |A_u| ~ 1 / (1 + c_y c_z)). AMP_CONSTANT keeps a margin of 2.4. Every sample's
#: amplification exceeds ~86 (the SVD's gap), so no sample has a bound below 1e-12: a fixed tolerance of 1e-12
#: on any subset fails by chance (it did: 3.3e-12 at 20,000 samples, alpha = pi/2, |A_u| = 1563; 1.6e-12 at
#: alpha = pi/4 where the amplification is below 225).
AMP_CONSTANT = 100.0
#: Central differences of ik (4th order at H and H/2, Richardson-combined to 6th order): truncation
#: ~ H^6 |q^(7)|, roundoff ~ 1e-16 / H;
#: used on samples with min |sin q_K2| > 0.1, |cos alpha_y| > 0.1 and 1 + c_y c_z > 0.1, where the derivatives of
#: ik stay moderate (relative error measured <= 3e-10 at 10,000 samples).
H = 1e-4
TOL_FD = 1e-9
#: ... and |det M| > FD_DET (the actuation singularity: ik refuses |det M| < DET_GUARD = 1e-6 and A_u ~ 1 / det M):
#: a sample 2e-4 rad from the curve det M = 0 had a difference point refused there (NaN: the row failed at
#: alpha = pi/4, seed 13, 10^4 samples; scripts/check_sweep.py).
FD_DET = 1e-2
#: fk vs solve_loops: the configuration solve_loops closes (residual ~1e-15, A_q1 and B_q1 held) is only as
#: accurate as 1e-15 x gain, gain = 1 / sigma_min(constraint Jacobian on the free joints), which is large near
#: bifurcations of the legs' branches (measured: 1.75e-12 rad at gain 3.9e4, alpha = pi/4, seed 2; error / gain
#: <= 1.4e-16 over seeds 0, 2, 5, 7). Samples with gain > GAIN_MAX report error / gain against TOL_GAIN.
GAIN_MAX = 1e3
TOL_GAIN = 1e-15
#: fk vs solve_loops: samples (loop solving is slower) and the solver tolerance (tighter than the default
#: 1e-12, which would limit the comparison to ~1e-12 x conditioning).
SOLVE_SAMPLES = 200
#: Near the platform singularity 1 + c_y c_z = 0 (tilt -> pi) fk and ik are ill-conditioned: the orientation
#: error of fk(ik(u)) grows like 1e-16 / (1 + c_y c_z) (measured 3.8e-10 at 1 + c_y c_z = 7e-7, alpha = pi/4);
#: samples with 1 + c_y c_z <= NEAR_FLIP get rows of their own (the ik rows with TOL_FLIP, valid down to
#: 1 + c_y c_z ~ 1e-7; the fk rows with FK_CONSTANT).
NEAR_FLIP = 1e-2
TOL_FLIP = 1e-8
#: fk(ik(u)) round trip: fk solves ik(x) = u by Gauss-Newton, so its answer is off by the solve's gain
#: |A_u^+| = 1 / sigma_min(A_u) times the rounding of the residual ik(x) - u, ~eps (|u| + |A_u| |x|) with |u|,
#: |x| <= pi; near the flip ik and platform_rotation themselves lose accuracy like eps / (1 + c_y c_z) (measured
#: 3.8e-10 at 1 + c_y c_z = 7e-7). The row reports the rotation error / (eps x amplification), amplification
#: = (1 + 1 / sigma_min(A_u)) (1 + sigma_max(A_u)) + 1 / (1 + c_y c_z), against FK_CONSTANT. A fixed 1e-12 failed
#: by chance: 1.41e-12 at alpha = pi/4, seed 19, 10^5 samples, where det M = 8e-5, 1 / sigma_min = 261 and
#: sigma_max = 1.5 (error / (eps x amplification) = 9.7 there). scripts/tripod_conditioning_sweep.py --row fk
#: measured the ratio over 20 seeds x 10^3, 10^4, 10^5 samples at each alpha: largest 10.6 (pi/3), 12.1 (pi/4),
#: 7.8 (pi/2) far from the flip, 0.84 near it (pi/4); FK_CONSTANT keeps a margin of 2.5.
FK_CONSTANT = 30.0
#: The inconsistency |ik(fk(u)) - u| of consistent motors is the rounding of ik's motors at fk's answer,
#: ~eps (1 + |A_u|) (|A_u| = sigma_max reaches ~500 near a leg's boundary, where a fixed 1e-12 keeps a margin of
#: only ~4); the row reports inconsistency / (eps (1 + sigma_max(A_u))) against INCONSISTENCY_CONSTANT (measured
#: as FK_CONSTANT: largest 2.4, 2.2, 2.6 at pi/3, pi/4, pi/2; a margin of 3).
INCONSISTENCY_CONSTANT = 8.0
SOLVE_TOL = 1e-14


def sample_near_boundary(n: int, rng: np.random.Generator, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Orientations with some leg at 1 - |cos q_K2| in [1e-10, 1e-3] (close to the workspace boundary)."""
    ch = math.cos(alpha / 2)
    ays: list[np.ndarray] = []
    azs: list[np.ndarray] = []
    while sum(a.shape[0] for a in ays) < n:
        phi = rng.uniform(-np.pi, np.pi, 2 * n)
        k = rng.integers(0, 3, 2 * n)
        s = np.abs(np.sin(phi - np.asarray(at.ETA)[k]))
        gap = 10 ** rng.uniform(-10, -3, 2 * n)  # target 1 - |cos q_K2|
        arg = (1.0 - gap) * ch / s
        good = arg < 1.0
        theta = 2 * np.arcsin(np.minimum(arg, 1.0))
        r = np.stack([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)], axis=-1)
        ay, az = at.orientation_from_axis(r)
        _, ok = at.ik(np.stack([ay, az], axis=-1), geometry=at.Geometry(alpha=alpha), return_mask=True)
        ok &= good
        ays.append(ay[ok])
        azs.append(az[ok])
    return np.concatenate(ays)[:n], np.concatenate(azs)[:n]


def sample_near_flip(n: int, rng: np.random.Generator, alpha: float):
    """Reachable orientations with tilt pi - delta, delta in [1e-3, 3e-2] (1 + c_y c_z ~ delta^2 / 2 >= 5e-7)."""
    phi = rng.uniform(-np.pi, np.pi, 20 * n)
    theta = np.pi - 10 ** rng.uniform(-3, -1.5, 20 * n)
    r = np.stack([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)], axis=-1)
    ay, az = at.orientation_from_axis(r)
    _, ok = at.ik(np.stack([ay, az], axis=-1), geometry=at.Geometry(alpha=alpha), return_mask=True)
    return ay[ok][:n], az[ok][:n]


def _pin_actuation_jacobian(robot, q: np.ndarray) -> tuple[np.ndarray, float]:
    """d(q_A1, q_B1, q_C1)/d(alpha_y, alpha_z) from Pinocchio alone, and the amplification of its rounding errors
    (``s_1 / s_10 + cond(G) + 1 / cos^2 alpha_y``, see :data:`AMP_CONSTANT`).

    The closed-loop velocities span the null space N (12 x 2) of the stacked constraint Jacobian; the
    platform's angular velocity is w = J_platform[3:] N; the platform axis r = R e_x moves as dr = w x r, and
    (alpha_y, alpha_z) = (-asin r3, atan2(r2, r1)) (definition, eq 5) moves as G = d(alpha)/dr . dr.
    Then A_u = N[actuated] G^-1.
    """
    jac = robot.constraint_jacobian(q)
    _, s, vt = np.linalg.svd(jac)
    null = vt[-2:].T
    jf = robot.frame_jacobian(q, "platform")
    r = robot.data.oMf[robot.frame_id("platform")].rotation[:, 0]
    dr = np.cross(jf[3:].T, r).T @ null  # (w x r) for each null vector
    rho2 = r[0] ** 2 + r[1] ** 2
    g = np.stack([-dr[2] / math.sqrt(rho2), (r[0] * dr[1] - r[1] * dr[0]) / rho2])
    act = [robot.idx_v(j) for j in robot.actuated_joints]
    amplification = s[0] / s[-3] + np.linalg.cond(g) + 1.0 / rho2
    return null[act] @ np.linalg.inv(g), float(amplification)


def actuation_jacobian_errors(robot, geo: at.Geometry, q: np.ndarray, ay: np.ndarray,
                              az: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per sample, the relative error of :func:`legkin.tripod.jacobian` against Pinocchio's actuation Jacobian
    (max entry difference / max(1, max |A_u|)) and the amplification of Pinocchio's rounding errors there.

    Args:
        robot: the tripod model (Pinocchio) for ``geo``.
        geo: the geometry.
        q: (n, 12) joint configurations of the orientations.
        ay: (n,) alpha_y (rad).
        az: (n,) alpha_z (rad).

    Returns:
        ``(error, amplification)``, two (n,) arrays (dimensionless).
    """
    a_an = at.jacobian(np.stack([ay, az], axis=-1), geometry=geo)
    err, amp = np.empty(len(q)), 1.0 / (1.0 + np.cos(ay) * np.cos(az))  # the flip: |A_u| ~ 1 / (1 + c_y c_z)
    for i, qi in enumerate(q):
        a_pin, pin_amp = _pin_actuation_jacobian(robot, qi)
        amp[i] += pin_amp
        err[i] = np.abs(a_pin - a_an[i]).max() / max(1.0, np.abs(a_an[i]).max())
    return err, amp


def _fd_actuation_jacobian(ay, az, alpha):
    geo = at.Geometry(alpha=alpha)

    def motors(y, z):
        return at.ik(np.stack(np.broadcast_arrays(y, z), axis=-1), geometry=geo)

    def d4(h, dy, dz):
        f = lambda k: motors(ay + k * h * dy, az + k * h * dz)  # noqa: E731
        return (8 * (f(1) - f(-1)) - (f(2) - f(-2))) / (12 * h)

    cols = []
    for dy, dz in ((1.0, 0.0), (0.0, 1.0)):
        cols.append((16 * d4(H / 2, dy, dz) - d4(H, dy, dz)) / 15)  # Richardson: 6th order
    return np.stack(cols, axis=-1)


def _is_cv_branch(q: np.ndarray) -> bool:
    q2 = q[[1, 5, 9]]
    return bool(
        np.all(np.abs(wrap(q[[2, 6, 10]] - q2)) < 1e-9)
        and np.all(np.abs(wrap(q[[3, 7, 11]] - q[[0, 4, 8]])) < 1e-9)
        and np.all(np.sin(q2) > 0)
    )


def _open_chain_rows(robot, geo: at.Geometry, pre: str, samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """Open chains (every joint random) and eq (10) on the CV branch (q3 = q2, q4 = q1) against Pinocchio."""
    rows: list[CheckResult] = []
    qs = rng.uniform(-np.pi, np.pi, (samples, 12))
    pos, rot = pinocchio_frames(robot, qs, [f"{k}_ee" for k in at.LEGS])
    perr, rerr, cverr = [], [], []
    for k, leg in enumerate(at.LEGS):
        t = at.leg_transform(qs[:, 4 * k : 4 * k + 4], leg, geometry=geo)
        perr.append(per_sample(t[:, :3, 3] - pos[:, k]))
        rerr.append(_rot_err(t[:, :3, :3], rot[:, k]))
    rows.append(compare(pre + "leg_transform vs oMf K_ee, open chains, position (m)", perr, TOL))
    rows.append(compare(pre + "leg_transform vs oMf K_ee, open chains, rotation (rad)", rerr, TOL))
    # --- eq (10) on the CV branch (q3 = q2, q4 = q1)
    qcv = qs.copy()
    for k in range(3):
        qcv[:, 4 * k + 2] = qcv[:, 4 * k + 1]
        qcv[:, 4 * k + 3] = qcv[:, 4 * k]
    pos, rot = pinocchio_frames(robot, qcv, [f"{k}_ee" for k in at.LEGS])
    for k, leg in enumerate(at.LEGS):
        t = at.leg_transform_cv(qcv[:, 4 * k : 4 * k + 2], leg, geometry=geo)
        cverr.append(np.maximum(per_sample(t[:, :3, 3] - pos[:, k]), _rot_err(t[:, :3, :3], rot[:, k])))
    rows.append(compare(pre + "eq (10) leg_transform_cv vs oMf K_ee, q3=q2, q4=q1 (m | rad)", cverr, TOL))
    return rows


def _ik_rows(robot, geo: at.Geometry, alpha: float, pre: str, samples: int,
             rng: np.random.Generator) -> tuple[list[CheckResult], np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """ik -> Pinocchio (loop residual, platform pose), inside the workspace and near its boundary.

    Returns:
        The rows, and the joints ``q``, the orientations ``ay``, ``az`` and the mask ``far`` (from the flip)
        of the workspace samples.
    """
    rows: list[CheckResult] = []
    ay, az = sample_workspace(samples, rng, geo)
    fy, fz = sample_near_flip(max(samples // 10, 50), rng, alpha)
    if len(fy):  # the workspace reaches the platform singularity only for alpha <= pi/3 (default eta)
        ay, az = np.concatenate([ay, fy]), np.concatenate([az, fz])
    far = 1 + np.cos(ay) * np.cos(az) > NEAR_FLIP
    q = at.ik_joints(np.stack([ay, az], axis=-1), geometry=geo)
    res = np.array([np.linalg.norm(robot.constraint_residual(qi)) for qi in q])
    pos, rot = pinocchio_frames(robot, q, ["platform"])
    rot_e = _rot_err(at.platform_rotation(ay, az), rot[:, 0])
    pos_e = per_sample(at.platform_position(ay, az, geometry=geo) - pos[:, 0])
    flip_tags = (f"1 + c_y c_z > {NEAR_FLIP:g}", f"1 + c_y c_z <= {NEAR_FLIP:g}")
    for sel, tag_, tol in ((far, flip_tags[0], TOL), (~far, flip_tags[1], TOL_FLIP)):
        if not sel.any():
            continue
        rows.append(compare(pre + f"ik -> loop residual |r| (Pinocchio) ({tag_})", res[sel], tol))
        rows.append(compare(pre + f"ik -> platform rotation vs platform_rotation (rad) ({tag_})", rot_e[sel], tol))
        rows.append(compare(pre + f"ik -> platform position vs platform_position (m) ({tag_})", pos_e[sel], tol))
    by, bz = sample_near_boundary(max(samples // 10, 50), rng, alpha)
    qb = at.ik_joints(np.stack([by, bz], axis=-1), geometry=geo)
    resb = np.array([np.linalg.norm(robot.constraint_residual(qi)) for qi in qb])
    farb = 1 + np.cos(by) * np.cos(bz) > NEAR_FLIP  # boundary samples can be near the flip too
    for sel, tag_, tol in ((farb, flip_tags[0], TOL), (~farb, flip_tags[1], TOL_FLIP)):
        if sel.any():
            rows.append(compare(pre + f"ik -> loop residual, near boundary (1-|cos q2| in [1e-10, 1e-3]) ({tag_})",
                                resb[sel], tol))
    return rows, q, ay, az, far


def _jacobian_rows(robot, geo: at.Geometry, alpha: float, pre: str, q: np.ndarray, ay: np.ndarray, az: np.ndarray,
                   far: np.ndarray) -> list[CheckResult]:
    """The actuation Jacobian A_u against Pinocchio's closed-loop null space and against finite differences."""
    rows: list[CheckResult] = []
    err, amp = actuation_jacobian_errors(robot, geo, q, ay, az)
    eps = float(np.finfo(float).eps)
    rows.append(compare(pre + "A_u (jacobian) vs Pinocchio closed-loop null space, rel. error / (eps x amplification)",
                        err / (eps * amp), AMP_CONSTANT))
    s2 = np.abs(np.sin(q[:, [1, 5, 9]])).min(axis=-1)
    fd_ok = (s2 > 0.1) & (np.abs(np.cos(ay)) > 0.1) & (1 + np.cos(ay) * np.cos(az) > 0.1)
    fd_ok &= np.abs(_home_det(ay, az, geo._vector)) > FD_DET  # the differences' points stay clear of ik's DET_GUARD
    a_fd = _fd_actuation_jacobian(ay[fd_ok], az[fd_ok], alpha)
    a_an = at.jacobian(np.stack([ay[fd_ok], az[fd_ok]], axis=-1), geometry=geo)
    scale = np.maximum(1.0, np.abs(a_an).max(axis=(-1, -2)))
    rows.append(compare(pre + f"A_u vs Richardson central differences of ik, rel. (h={H:g})",
                        np.abs(a_fd - a_an).max(axis=(-1, -2)) / scale, TOL_FD))
    return rows


def fk_round_trip_errors(geo: at.Geometry, q: np.ndarray, ay: np.ndarray, az: np.ndarray,
                         far: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per sample, the platform rotation error of ``fk(ik(u))`` and its amplification bound (:data:`FK_CONSTANT`),
    the inconsistency of the consistent motors and its amplification (:data:`INCONSISTENCY_CONSTANT`).

    Args:
        geo: the geometry.
        q: (n, 12) joint configurations of the orientations (from :func:`legkin.tripod.ik_joints`).
        ay: (n,) alpha_y (rad).
        az: (n,) alpha_z (rad).
        far: (n,) the samples with 1 + c_y c_z > :data:`NEAR_FLIP` (the others may be inconsistent up to 1e-6 rad).

    Returns:
        ``(error, amplification, inconsistency, inconsistency_amplification)``, four (n,) arrays: the rotation
        angle (rad, NaN where fk failed) and the inconsistency (rad), and their amplifications (dimensionless).
    """
    # near the flip the motors' rounding noise is amplified (|A_u| ~ 1 / (1 + c_y c_z)): measured
    # inconsistency up to 5e-9 rad there, so those samples accept up to 1e-6 (the default is 1e-9)
    u, u_ok, u_info = at.fk(q[:, list(MOTOR_COLUMNS)], geometry=geo, return_mask=True, return_info=True,
                            max_inconsistency=1e-6)
    inconsistency = u_info.inconsistency
    u_ok[far & (inconsistency > 1e-9)] = False
    error = _rot_err(at.platform_rotation(np.nan_to_num(u[:, 0]), np.nan_to_num(u[:, 1])),
                     at.platform_rotation(ay, az))
    error[~u_ok] = np.nan  # a failure counts against the row
    sv = np.linalg.svd(at.jacobian(np.stack([ay, az], axis=-1), geometry=geo), compute_uv=False)
    amp = (1.0 + 1.0 / sv[:, -1]) * (1.0 + sv[:, 0]) + 1.0 / (1.0 + np.cos(ay) * np.cos(az))
    return error, amp, inconsistency, 1.0 + sv[:, 0]


def _fk_rows(geo: at.Geometry, pre: str, q: np.ndarray, ay: np.ndarray, az: np.ndarray,
             far: np.ndarray) -> list[CheckResult]:
    """fk(ik(u)) round trip and the inconsistency of consistent motors, each per sample against its conditioning
    bound (:data:`FK_CONSTANT`, :data:`INCONSISTENCY_CONSTANT`)."""
    rows: list[CheckResult] = []
    error, amp, inconsistency, inc_amp = fk_round_trip_errors(geo, q, ay, az, far)
    eps = float(np.finfo(float).eps)
    for sel, tag_ in ((far, f"1 + c_y c_z > {NEAR_FLIP:g}"), (~far, f"1 + c_y c_z <= {NEAR_FLIP:g}")):
        if sel.any():
            rows.append(compare(pre + f"fk(ik(u)) round trip, platform rotation / (eps x amplification) ({tag_})",
                                error[sel] / (eps * amp[sel]), FK_CONSTANT))
    rows.append(compare(pre + "fk(ik(u)) inconsistency of consistent motors / (eps x (1 + |A_u|)) "
                        f"(1 + c_y c_z > {NEAR_FLIP:g})", inconsistency[far] / (eps * inc_amp[far]),
                        INCONSISTENCY_CONSTANT))
    return rows


def _solve_loops_rows(robot, geo: at.Geometry, pre: str, q: np.ndarray, ay: np.ndarray, az: np.ndarray,
                      samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """fk against ``Robot.solve_loops`` with A_q1 and B_q1 held, started 0.15 rad away (samples far from the flip)."""
    rows: list[CheckResult] = []
    m = min(samples, SOLVE_SAMPLES)
    delta = rng.normal(0.0, 0.15, (m, 2))
    q_start, ok = at.ik_joints(np.stack([ay[:m] + delta[:, 0], az[:m] + delta[:, 1]], axis=-1), geometry=geo,
                               return_mask=True)
    err_list: list[float] = []
    gain_list: list[float] = []
    other, failed = 0, 0
    held_free = np.ones(robot.model.nv, dtype=bool)
    held_free[[robot.idx_v("A_q1"), robot.idx_v("B_q1")]] = False
    for i in np.flatnonzero(ok).tolist():
        try:
            qs_i = robot.solve_loops(q_start[i], {"A_q1": q[i, 0], "B_q1": q[i, 4]}, tol=SOLVE_TOL)
        except LoopClosureError:
            failed += 1  # a local minimum of |r| that does not close (reported, see docs/tripod.md)
            continue
        if not _is_cv_branch(qs_i):
            other += 1  # another assembly mode of the legs: outside fk's model (q3=q2, q4=q1, q2 in (0, pi))
            continue
        uf = at.fk(qs_i[list(MOTOR_COLUMNS)], geometry=geo)
        rot_pin = robot.frame_placement(qs_i, "platform").rotation
        err_list.append(float(_rot_err(at.platform_rotation(uf[0], uf[1]), rot_pin)))
        # The closed configuration's own error (its residual <= SOLVE_TOL) is amplified by 1 / sigma_min of the
        # constraint Jacobian on the free joints: near a bifurcation of the legs' branches it is large
        jac_free = robot.constraint_jacobian(qs_i)[:, held_free]
        gain_list.append(float(1.0 / np.linalg.svd(jac_free, compute_uv=False)[-1]))
    errs, gain = np.asarray(err_list, dtype=float), np.asarray(gain_list, dtype=float)
    well = gain <= GAIN_MAX
    head = pre + f"fk vs solve_loops (A_q1, B_q1 held, start 0.15 rad away; {other} of {int(ok.sum())} " \
        f"landed on another assembly mode, {failed} did not close; both skipped)"
    if well.any():
        rows.append(compare(head + f", loop gain <= {GAIN_MAX:g}", errs[well], TOL))
    if (~well).any():
        rows.append(compare(head + f", loop gain > {GAIN_MAX:g}: error / gain", errs[~well] / gain[~well], TOL_GAIN))
    return rows


def _run_alpha(tag: str, alpha: float, samples: int, rng: np.random.Generator) -> list[CheckResult]:
    robot = load("tripod") if tag == "pi/3" else load("tripod", alpha=alpha)
    geo = at.Geometry(alpha=alpha)
    pre = f"[alpha={tag}] "
    rows = _open_chain_rows(robot, geo, pre, samples, rng)
    ik_rows, q, ay, az, far = _ik_rows(robot, geo, alpha, pre, samples, rng)
    rows += ik_rows
    rows += _jacobian_rows(robot, geo, alpha, pre, q, ay, az, far)
    rows += _fk_rows(geo, pre, q, ay, az, far)
    q, ay, az = q[far], ay[far], az[far]
    rows += _solve_loops_rows(robot, geo, pre, q, ay, az, samples, rng)
    # --- mobility
    mob = [robot.mobility(qi) for qi in q[: min(samples, 1000)]]
    rows.append(compare(pre + "Robot.mobility - 2 at random workspace poses", np.asarray(mob) - 2, 0.0))
    # --- named poses
    rows.append(compare(pre + "SRDF poses: loop residual |r|",
                        [np.linalg.norm(robot.constraint_residual(p)) for p in robot.poses.values()], TOL))
    return rows


def run(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    rows: list[CheckResult] = []
    for tag, alpha in ALPHAS:
        rows += _run_alpha(tag, alpha, samples, rng)
    return rows


# ---------------------------------------------------------------- the IK contract row
#: Contract tolerance (rad): every solved orientation is reproduced by the default fk to this.
CONTRACT_TOL = 1e-9


def pose_error(ay, az, y, z) -> np.ndarray:
    """How far the pose (y, z) is from (ay, az) (rad): the smaller of the parameter distance (modulo 2 pi and
    the equivalence (pi - alpha_y, alpha_z + pi)) and the rotation angle between the platform rotations.

    Each measure is ill-conditioned at one singular set of the parametrisation, the other is not: alpha_z is
    undefined at c_y = 0 (same rotation for every alpha_z), and R(u) folds a circle of rotations onto the flip
    point 1 + c_y c_z = 0 (the parameters are well determined there)."""
    d1 = np.hypot(wrap(y - ay), wrap(z - az))
    d2 = np.hypot(wrap(np.pi - y - ay), wrap(z + np.pi - az))
    with np.errstate(invalid="ignore"):
        rot = _rot_err(at.platform_rotation(ay, az), at.platform_rotation(np.nan_to_num(y), np.nan_to_num(z)))
    return np.minimum(np.minimum(d1, d2), np.where(np.isfinite(y) & np.isfinite(z), rot, np.inf))


def made_targets(n: int, rng: np.random.Generator, alpha: float = at.ALPHA) -> tuple[np.ndarray, np.ndarray]:
    """``n`` orientations made by the default :func:`fk` from in-limit joints of a closed configuration.

    Motors q_A1, q_B1 uniform in the joint limits [-pi, pi]; E on both motor planes and the sphere |E| = L (a
    line cut by a sphere: zero or two points, see :mod:`legkin.tripod.forward_kernels`); for the points
    in the home mode's half (E_x < 0, sin q_A2, sin q_B2 > 0) that leg C reaches, q_C1 from leg C on its home
    branch (eqs 98, 102 at E); the target is ``fk(q_A1, q_B1, q_C1)`` with default options, kept where fk
    solves it.
    """
    geo = at.Geometry(alpha=alpha)
    ce, se = np.cos(np.asarray(geo.eta)), np.sin(np.asarray(geo.eta))
    d, k, sa = geo.d, 1.0 - math.cos(alpha), math.sin(alpha)
    dk, big_l, dsa = d * k, geo.length, d * sa
    ys, zs, total = [], [], 0
    while total < n:
        m = max(2 * n, 1000) * 4
        q = rng.uniform(-np.pi, np.pi, (m, 2))
        s, c = np.sin(q), np.cos(q)
        na = np.stack([s[:, 0], -c[:, 0] * ce[0], -c[:, 0] * se[0]], axis=-1)
        nb = np.stack([s[:, 1], -c[:, 1] * ce[1], -c[:, 1] * se[1]], axis=-1)
        cab = np.sum(na * nb, axis=-1)
        v = np.cross(na, nb)
        vv = np.sum(v * v, axis=-1)
        p0 = dk * (na + nb) / (1.0 + cab)[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.sqrt(big_l**2 - np.sum(p0 * p0, axis=-1)) / np.sqrt(vv)
        keep = np.isfinite(t) & (vv > 1e-12)
        for sign in (-1.0, 1.0):
            e = p0 + (sign * t)[:, None] * v
            h1, h2 = -e[:, 0] / d, -(ce[:2, None] * e[:, 1] + se[:2, None] * e[:, 2]).T / d
            s2sa = c * h1[:, None] + s * h2  # sin q_K2 sin(alpha) of legs A and B at E
            # q_C1 from E on leg C's home branch (eqs 98, 102; straight from E, not through the orientation)
            c2 = (ce[2] * e[:, 2] - se[2] * e[:, 1]) / dsa
            home = keep & (e[:, 0] < 0) & np.all(s2sa > 0, axis=-1) & (np.abs(c2) < 1.0)
            e, c2 = e[home], c2[home]
            sc = np.sqrt(1.0 - c2 * c2) * sa
            w = -(ce[2] * e[:, 1] + se[2] * e[:, 2])
            qc = np.arctan2(k * e[:, 0] + sc * w, -sc * e[:, 0] + k * w)
            qa = q[home]
            u, solved = at.fk(np.stack([qa[:, 0], qa[:, 1], qc], axis=-1), geometry=geo, return_mask=True)
            ys.append(u[solved, 0])
            zs.append(u[solved, 1])
            total += int(solved.sum())
    return np.concatenate(ys)[:n], np.concatenate(zs)[:n]


def _home_det(y: Any, z: Any, G: np.ndarray) -> np.ndarray:
    """det M of the home mode's motor planes at (alpha_y, alpha_z) (ik's kernel, also where its guards refuse the
    pose), NaN outside the workspace."""
    ay, az = np.broadcast_arrays(np.asarray(y, dtype=float), np.asarray(z, dtype=float))
    aux = _run(ay, az, G, HOME_MODE)[1][..., 0, :]
    inside = (aux[..., 3] > SINGULAR_TOL) & np.all(1.0 - np.abs(aux[..., :3]) > BOUNDARY_TOL, axis=-1)
    return np.where(inside, aux[..., 4], np.nan)


def _det_curve_points(rng: np.random.Generator, alpha: float, grid: int = 121) -> np.ndarray:
    """Points (alpha_y, alpha_z) on the actuation-singular curves det M = 0 of the home mode's motors: bisection
    between grid neighbours where det M changes sign, along alpha_y (random alpha_z) and along alpha_z (random
    alpha_y; at alpha = pi/2 det M vanishes on the lines alpha_z = +-pi/2)."""
    G = at.Geometry(alpha=alpha)._vector

    def det_of(y, z):
        return _home_det(y, z, G)

    out = []
    for along_y in (True, False):
        line = np.linspace(-np.pi / 2, np.pi / 2, grid) if along_y else np.linspace(-np.pi, np.pi, 2 * grid)
        other = rng.uniform(-np.pi, np.pi, grid) if along_y else rng.uniform(-np.pi / 2, np.pi / 2, grid)
        g1, g2 = np.meshgrid(line, other, indexing="ij")

        def det_on(v, w, along_y=along_y):
            return det_of(v, w) if along_y else det_of(w, v)

        dm = det_on(g1, g2)
        i, j = np.nonzero(np.sign(dm[1:]) * np.sign(dm[:-1]) < 0)
        lo, hi, w = line[i], line[i + 1], other[j]
        flo = det_on(lo, w)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = det_on(mid, w)
            left = np.sign(fm) == np.sign(flo)
            lo, flo, hi = np.where(left, mid, lo), np.where(left, fm, flo), np.where(left, hi, mid)
        v = 0.5 * (lo + hi)
        out.append(np.stack([v, w] if along_y else [w, v], axis=-1))
    return np.concatenate(out)


def random_orientations(n: int, rng: np.random.Generator, alpha: float = at.ALPHA) -> tuple[np.ndarray, np.ndarray]:
    """``n`` orientations in and around the workspace: uniform over a box a little larger than the principal
    range (40 %), any representation (|alpha_y|, |alpha_z| up to 20 rad, 10 %), near the flip
    (1 + c_y c_z log-uniform in [1e-14, 1e-2], 15 %), a hair inside or outside a leg's boundary
    (|1 - |cos q_K2|| log-uniform in [1e-15, 1e-3], 25 %), and near the actuation-singular curves det M = 0
    (offsets log-uniform in [1e-12, 1e-2] rad, 10 %)."""
    ay = rng.uniform(-np.pi / 2 - 0.3, np.pi / 2 + 0.3, n)
    az = rng.uniform(-np.pi - 0.3, np.pi + 0.3, n)
    kind = rng.uniform(size=n)
    far = (kind >= 0.4) & (kind < 0.5)
    ay[far], az[far] = rng.uniform(-20, 20, far.sum()), rng.uniform(-20, 20, far.sum())
    phi = rng.uniform(-np.pi, np.pi, n)
    flip = (kind >= 0.5) & (kind < 0.65)
    theta = np.arccos(np.clip(10 ** rng.uniform(-14, -2, n) - 1.0, -1.0, 1.0))
    bnd = (kind >= 0.65) & (kind < 0.9)
    k = rng.integers(0, 3, n)
    sk = np.abs(np.sin(phi - np.asarray(at.ETA)[k]))
    gap = 10 ** rng.uniform(-15, -3, n) * rng.choice([-1.0, 1.0], n)
    with np.errstate(divide="ignore", invalid="ignore"):
        arg = (1.0 - gap) * math.cos(alpha / 2) / sk
    theta = np.where(bnd, 2.0 * np.arcsin(np.clip(arg, -1.0, 1.0)), theta)
    sel = flip | bnd
    r = np.stack([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)], axis=-1)[sel]
    ay[sel], az[sel] = at.orientation_from_axis(r)
    det = np.nonzero(kind >= 0.9)[0]
    pts = _det_curve_points(rng, alpha)
    if len(det) and len(pts):
        base = pts[rng.integers(0, len(pts), len(det))]
        off = 10 ** rng.uniform(-12, -2, (len(det), 1)) * rng.normal(size=(len(det), 2))
        ay[det], az[det] = (base + off).T
    return ay, az


def ik_robustness(n: int, rng: np.random.Generator, *, classify: int | None = 2000) -> CheckResult:
    """The IK contract row of the tripod (default geometry; see :func:`legkin.validation.robustness_row`).

    Half the targets are :func:`made_targets` (fk of in-limit motors, each must be solved), the rest
    :func:`random_orientations`. The default batch ``ik`` solves them; for the solved ones the error is
    :func:`pose_error` between the target and the default ``fk`` of the answer's motors (an answer whose
    joints leave the URDF limits [-pi, pi], or that fk does not solve, counts as not reproduced). Up to
    ``classify`` unsolved targets (None: all) are classified by single calls.
    """
    n_made = n // 2
    my, mz = made_targets(n_made, rng)
    ry, rz = random_orientations(n - n_made, rng)
    ay, az = np.concatenate([my, ry]), np.concatenate([mz, rz])
    made = np.arange(n) < n_made
    exceptions = 0
    y, z, ok = np.full(n, np.nan), np.full(n, np.nan), np.zeros(n, dtype=bool)
    try:
        q, solved = at.ik_joints(np.stack([ay, az], axis=-1), return_mask=True)
        u, ok[solved] = at.fk(q[solved][:, list(MOTOR_COLUMNS)], return_mask=True)
        y[solved], z[solved] = u[:, 0], u[:, 1]
    except Exception:  # noqa: BLE001 - a foreign (or any) exception from a batch call is a defect
        exceptions += 1
        q, solved = np.full((n, 12), np.nan), np.zeros(n, dtype=bool)
    inside = np.all((q >= -np.pi) & (q <= np.pi), axis=-1)
    error = np.where(solved & ok & inside, pose_error(ay, az, y, z), np.inf)
    unsolved = np.nonzero(~solved)[0]
    if classify is not None and len(unsolved) > classify:
        unsolved = np.sort(rng.choice(unsolved, classify, replace=False))
    reasons, foreign = classify_failures(lambda i: at.ik(np.array([ay[i], az[i]])), unsolved)
    return robustness_row(
        "tripod", made=made, solved=solved, error=error, reasons=reasons, classified=len(unsolved),
        exceptions=exceptions + foreign, tolerance=CONTRACT_TOL,
    )
