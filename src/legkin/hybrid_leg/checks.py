"""Validation of :mod:`legkin.hybrid_leg` against Pinocchio (closed loops, mobility, Jacobians)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checkkit import CheckResult, compare, per_sample, pinocchio_frames
from .._rotations import rot_x, rot_y, rot_z
from ..robot import load
from . import kinematics as ah
from .configuration import (
    ACTUATED,
    LL_RANGE,
    PASSIVE_U,
    SIGMA_MIN,
    closed_configuration,
    sample_near_forward_singularity,
    sample_workspace,
)
from .configuration import sigma_min as _sigma_min
from .geometry import LL0, H

TOL = 1e-12
#: Samples for the iterative Pinocchio loop solver and the mobility SVDs (costly per sample).
SOLVE_SAMPLES = 200
#: Near the forward singularity the FK error scales as eps / sigma_min: that row reports
#: error * sigma_min, measured <= 6.0e-15 over 140,000 samples; tolerance:
TOL_SCALED = 1e-13
#: ik: condition number (see :func:`foot_ik_condition`) above which a sample is near-singular.
KAPPA_NEAR = 100.0
#: Tolerance of error / kappa for those (measured <= 1.7e-15 over 20,000 samples placed near alpha = 0).
TOL_KAPPA = 1e-14
#: jacobian: sigma_min(dtheta/dx) at least this for the 1e-12 row.
SIGMA_JAC = 0.3
#: Tolerance of error x sigma_min^3 below SIGMA_JAC (measured <= 3.1e-15 at 10,000 samples).
TOL_SIGMA3 = 1e-14
#: Samples of the foot-Jacobian rows (one pseudo-inverse per sample).
JAC_SAMPLES = 10_000



def foot_ik_condition(pos: np.ndarray, theta_ll: np.ndarray, roll: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """Condition number of ik at a sample: ``max(1, sigma_max(dtheta/dx)) * max(1 / alpha, |u| / rho)``.

    ``alpha = |theta_LL - LL_DELTA|`` (the LL branches merge at 0), ``u = p - CENTER``, ``rho`` = distance of
    the foot from the roll axis (x through the LCS centre; roll is undetermined at 0), and
    ``sigma_max(dtheta/dx)`` amplifies platform-angle errors into motor angles (infinite on the reach boundary).
    """
    u = pos - ah.CENTER
    rho = np.hypot(u[..., 1], u[..., 2])
    with np.errstate(divide="ignore"):
        geo = np.maximum(1.0 / np.abs(theta_ll - ah.LL_DELTA), np.linalg.norm(u, axis=-1) / rho)
    jac = ah.motor_jacobian(roll, pitch)
    return np.maximum(np.linalg.svd(jac, compute_uv=False)[..., 0], 1.0) * geo


def _residuals(robot, qs: np.ndarray) -> np.ndarray:
    return np.array([np.linalg.norm(robot.constraint_residual(q)) for q in qs])


def _closed_loop_jacobian(robot, q: np.ndarray, frame: str) -> np.ndarray:
    """d(frame position)/d(MCS1, MCS2, LL) of the closed mechanism: passive velocities from J_c v = 0.

    ``v_p = -pinv(J_c,p) J_c,a v_a``; the rod spins lie in the null space of ``J_c,p`` and do not move the
    frame, so the minimum-norm choice is as good as any.
    """
    jc = robot.constraint_jacobian(q)
    jf = robot.frame_jacobian(q, frame)[:3]
    act = [robot.idx_v(n) for n in ACTUATED]
    pas = [i for i in range(robot.model.nv) if i not in act]
    vp = -np.linalg.pinv(jc[:, pas], rcond=1e-12) @ jc[:, act]
    return jf[:, act] + jf[:, pas] @ vp


def platform_dof(robot, q: np.ndarray, locked=ACTUATED, tol: float = 1e-9) -> tuple[int, np.ndarray]:
    """Rank of the platform angular-velocity map on the closed-loop motions with ``locked`` held.

    Returns the rank and the free axis (the leading left singular vector; NaN for rank 0).
    """
    jc = robot.constraint_jacobian(q)
    free = np.ones(robot.model.nv, dtype=bool)
    for name in locked:
        free[robot.idx_v(name)] = False
    _, s, vt = np.linalg.svd(jc[:, free])
    rank = int(np.sum(s > tol * s[0]))
    null = vt[rank:].T
    jp = robot.frame_jacobian(q, "P")[3:, free] @ null
    u, sp, _ = np.linalg.svd(jp)
    r = int(np.sum(sp > tol))
    axis = u[:, 0] if r else np.full(3, np.nan)
    return r, axis * np.sign(axis[2]) if r else axis


@dataclass
class _Workspace:
    """The samples the rows share: platform poses of the neutral mode, their motors and FK, LL angles, closed
    configurations and the Pinocchio feet."""

    roll: np.ndarray
    pitch: np.ndarray
    th: np.ndarray
    x: np.ndarray
    tll: np.ndarray
    qs: np.ndarray
    pos: np.ndarray
    theta0: np.ndarray


def run(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """The ``legkin check hybrid_leg`` rows (without the IK-contract row, :func:`ik_robustness`)."""
    robot = load("hybrid_leg")
    n = int(samples)
    ns = min(n, SOLVE_SAMPLES)
    rows = _motor_rows(robot, n, rng)
    roll, pitch = sample_workspace(n, rng)
    th = ah.motor_angles(roll, pitch)
    x = ah.platform_orientation(th[:, 0], th[:, 1])
    rows += _orientation_rows(roll, pitch, x, n, rng)
    tll = rng.uniform(*LL_RANGE, n)
    qs = closed_configuration(robot, np.stack([roll, pitch], -1), tll)
    pos = pinocchio_frames(robot, qs, ["FCS"])[0][:, 0]
    w = _Workspace(roll, pitch, th, x, tll, qs, pos, np.asarray(ah.extension_motor_angle(tll)))
    rows += _solve_loops_rows(robot, w, ns, rng)
    rows += _foot_rows(w)
    rows += _ik_rows(robot, w, ns)
    rows += _jacobian_rows(robot, w, n)
    rows += _mobility_rows(robot, roll[:ns], pitch[:ns], rng)
    return rows


def _motor_rows(robot, n: int, rng: np.random.Generator) -> list[CheckResult]:  # noqa: ANN001
    rows: list[CheckResult] = []
    # -- motor_angles -> Pinocchio: loops closed, platform as asked (all four motor branches)
    r0 = rng.uniform(-1.0, 1.0, 4 * n)
    p0 = rng.uniform(-1.0, 1.1, 4 * n)
    res_all, rot_err = [], []
    for b in ah.MOTOR_BRANCHES:
        th, ok = ah.motor_angles(r0, p0, b, return_mask=True)
        idx = np.flatnonzero(ok)[: n // 4 + 1]
        qs = closed_configuration(robot, np.stack([r0[idx], p0[idx]], -1), np.zeros(len(idx)), b)
        res_all.append(_residuals(robot, qs))
        _, rot = pinocchio_frames(robot, qs, ["P"])
        rot_err.append(np.abs(rot[:, 0] - ah.platform_rotation(r0[idx], p0[idx])).max(axis=(-1, -2)))
    rows.append(compare("motor_angles (4 branches) -> Pinocchio loop residual (m)", np.concatenate(res_all), TOL))
    rows.append(compare("motor_angles (4 branches) -> Pinocchio platform rotation", np.concatenate(rot_err), TOL))
    return rows


def _orientation_rows(roll: np.ndarray, pitch: np.ndarray, x: np.ndarray, n: int,
                      rng: np.random.Generator) -> list[CheckResult]:
    rows: list[CheckResult] = []
    # -- platform_orientation: round trip through motor_angles, well-conditioned and near-singular
    rows.append(
        compare(f"platform_orientation(motor_angles(x)) = x, sigma_min >= {SIGMA_MIN:g}",
                np.abs(x - np.stack([roll, pitch], -1)).max(-1), TOL)
    )
    rn, pn = sample_near_forward_singularity(max(n // 10, 20), rng)
    thn = ah.motor_angles(rn, pn)
    xn = ah.platform_orientation(thn[:, 0], thn[:, 1])
    scaled = np.abs(xn - np.stack([rn, pn], -1)).max(-1) * _sigma_min(rn, pn)
    rows.append(compare("platform_orientation near forward singularity: error x sigma_min", scaled, TOL_SCALED))
    return rows


def _solve_loops_rows(robot, w: _Workspace, ns: int, rng: np.random.Generator) -> list[CheckResult]:  # noqa: ANN001
    rows: list[CheckResult] = []
    roll, pitch, th, x, qs = w.roll, w.pitch, w.th, w.x, w.qs
    # -- platform_orientation vs Robot.solve_loops with the motors held
    pas = [robot.idx_q(j) for j in PASSIVE_U]
    err = np.empty(ns)
    # start the solver near the sample's assembly: passive joints perturbed by N(0, 0.1 sigma_min) rad (the
    # other assembly mode is ~sigma_min away near the forward singularity, and the solver would find it)
    scale = 0.1 * _sigma_min(roll[:ns], pitch[:ns])
    other_mode = np.zeros(ns, dtype=bool)
    for k in range(ns):
        q_init = qs[k].copy()
        q_init[pas] += rng.normal(0.0, scale[k], len(pas))
        q = robot.solve_loops(q_init, fixed=list(ACTUATED), tol=1e-15, max_iter=50)
        x_solver = q[[robot.idx_q("LCS_x"), robot.idx_q("LCS_y")]]
        err[k] = np.abs(x_solver - x[k]).max()
        if err[k] > 1e-6:
            # The forward kinematics of the closed chain is multi-valued: the solver may close the loops in
            # another assembly mode, a different platform pose whose motor angles (on some motor branch) are
            # the held ones. Such samples are counted, not compared; anything else stays an error.
            th_other = np.stack([ah.motor_angles(x_solver[0], x_solver[1], b, return_mask=True)[0]
                                 for b in ah.MOTOR_BRANCHES])
            other_mode[k] = bool(np.any(np.abs(th_other - th[k]).max(-1) < 1e-9))
    rows.append(compare(
        f"platform_orientation vs Robot.solve_loops (motors held, {ns} samples; {int(other_mode.sum())} "
        "closed in another assembly mode, skipped)", err[~other_mode], TOL))
    return rows


def _foot_rows(w: _Workspace) -> list[CheckResult]:
    rows: list[CheckResult] = []
    roll, pitch, th, tll, pos, theta0 = w.roll, w.pitch, w.th, w.tll, w.pos, w.theta0
    # -- foot position (Newton FK + eq 19 + eqs 17-20) vs Pinocchio FCS
    rows.append(compare("foot_position_from_platform vs Pinocchio FCS (m)",
                        per_sample(ah.foot_position_from_platform(roll, pitch, tll) - pos), TOL))
    rows.append(compare("fk(theta1, theta2, theta0) vs Pinocchio FCS (m)",
                        per_sample(ah.fk(np.column_stack([th, theta0])) - pos), TOL))
    return rows


def _ik_rows(robot, w: _Workspace, ns: int) -> list[CheckResult]:  # noqa: ANN001
    rows: list[CheckResult] = []
    roll, pitch, th, tll, pos, theta0 = w.roll, w.pitch, w.th, w.tll, w.pos, w.theta0
    # -- ik: default branch round trip, and every branch closes in Pinocchio at the target.
    # Its conditioning: kappa = max(1, sigma_max(dtheta/dx)) * max(1 / alpha, |u| / rho), alpha = |theta_LL -
    # LL_DELTA| (the two LL branches merge at alpha = 0: acos near 1) and rho = distance of the foot from the
    # roll axis (roll undetermined at rho = 0): error ~ eps * kappa. Samples with kappa > KAPPA_NEAR are in
    # a separate row reporting error / kappa.
    kappa = foot_ik_condition(pos, tll, roll, pitch)
    well = kappa <= KAPPA_NEAR
    default = tll <= ah.LL_DELTA  # samples on the default LL branch (the others are in the all-branch rows)
    sol = ah.ik(pos[default])
    jerr = np.maximum(np.abs(sol[:, :2] - th[default]).max(-1), np.abs(ah.ll_angle(sol[:, 2]) - tll[default]))
    wd = well[default]
    rows.append(compare(f"ik round trip (default branch, kappa <= {KAPPA_NEAR:g}): theta1, theta2, theta_LL",
                        jerr[wd], TOL))
    rows.append(compare(f"ik round trip (default branch, kappa > {KAPPA_NEAR:g}): error / kappa",
                        jerr[~wd] / kappa[default][~wd], TOL_KAPPA))
    allb, okb = ah.ik_all(pos[:ns], return_mask=True)
    truth = np.concatenate([th[:ns], theta0[:ns, None]], -1)[:, None, :]
    # theta0 compared as theta_LL (x RATIO): one LL radian is 134.6 motor radians
    diff = (np.abs(allb - truth) * np.array([1.0, 1.0, ah.RATIO])).max(-1)
    found = np.min(np.where(okb, diff, np.inf), axis=-1) / np.maximum(kappa[:ns] / KAPPA_NEAR, 1.0)
    rows.append(compare(f"ik_all: the branches contain the sample ({ns} samples; / (kappa/{KAPPA_NEAR:g}) if larger)",
                        found, TOL))
    res_b, foot_b = [], []
    for j, (llb, rb, b1, b2) in enumerate(ah.FOOT_IK_BRANCHES):
        idx = np.flatnonzero(okb[:, j])
        if not len(idx):
            continue
        plat = ah.foot_platform_ik(pos[idx], ll_branch=llb, roll_branch=rb)
        qb = closed_configuration(robot, plat[:, 1:], plat[:, 0], (b1, b2))
        mot = np.stack([qb[:, robot.idx_q("MCS1")], qb[:, robot.idx_q("MCS2")]], -1)
        res_b.append(np.maximum(_residuals(robot, qb), np.abs(mot - allb[idx, j, :2]).max(-1)))
        foot_b.append(per_sample(pinocchio_frames(robot, qb, ["FCS"])[0][:, 0] - pos[idx]))
    rows.append(compare("ik_all every branch -> Pinocchio loop residual (m)", np.concatenate(res_b), TOL))
    rows.append(compare("ik_all every branch -> Pinocchio FCS at the target (m)", np.concatenate(foot_b), TOL))
    return rows


def _jacobian_rows(robot, w: _Workspace, n: int) -> list[CheckResult]:  # noqa: ANN001
    rows: list[CheckResult] = []
    roll, pitch, th, qs, theta0 = w.roll, w.pitch, w.th, w.qs, w.theta0
    # -- foot Jacobian vs Pinocchio's closed-loop Jacobian. Given motor angles, the platform comes from the
    # FK (error ~ eps / sigma_min) and the Jacobian's sensitivity grows as 1 / sigma_min^2: error ~ 1 / sigma^3.
    nj = min(n, JAC_SAMPLES)
    ja = ah.jacobian(np.column_stack([th[:nj], theta0[:nj]]))
    jerr = np.empty(nj)
    for k in range(nj):
        jp = _closed_loop_jacobian(robot, qs[k], "FCS")
        jp[:, 2] *= -ah.RATIO  # dtheta_LL/dtheta0 (eq 19)
        jerr[k] = np.abs(ja[k] - jp).max()
    smin = _sigma_min(roll[:nj], pitch[:nj])
    wj = smin >= SIGMA_JAC
    rows.append(compare(f"jacobian vs Pinocchio closed-loop Jacobian, sigma_min >= {SIGMA_JAC:g} (m/rad)",
                        jerr[wj], TOL))
    rows.append(compare(f"jacobian vs Pinocchio closed-loop Jacobian, sigma_min < {SIGMA_JAC:g}: error x sigma_min^3",
                        jerr[~wj] * smin[~wj] ** 3, TOL_SIGMA3))
    return rows


def _values(a: np.ndarray) -> str:
    return ", ".join(str(int(v)) for v in sorted(set(a.tolist())))


def _mobility_rows(robot, roll, pitch, rng) -> list[CheckResult]:
    rows = []
    ns = len(roll)
    qs = closed_configuration(robot, np.stack([roll, pitch], -1), np.zeros(ns))
    mob = np.array([robot.mobility(q, locked=ACTUATED) for q in qs])
    dof = np.array([platform_dof(robot, q)[0] for q in qs])
    rows.append(compare(f"universal: Robot.mobility, MCS1+MCS2+LL locked = 2 rod spins (measured {_values(mob)})",
                        mob - 2, 0.0))
    rows.append(compare(f"universal: uncontrolled platform DOF = 0 (measured {_values(dof)})", dof, 0.0))

    sph = load("hybrid_leg", center="spherical")
    ang = np.stack([roll, pitch, rng.uniform(-0.2, 0.2, ns)], -1)
    rot = rot_x(ang[:, 0]) @ rot_y(ang[:, 1]) @ rot_z(ang[:, 2])
    ok = ah.motor_angles_from_rotation(rot, return_mask=True)[1]
    ang, rot = ang[ok], rot[ok]
    qs = closed_configuration(sph, ang, np.zeros(len(ang)))
    rows.append(compare("spherical: motor_angles_from_rotation -> Pinocchio loop residual (m)", _residuals(sph, qs),
                        TOL))
    mob = np.array([sph.mobility(q, locked=ACTUATED) for q in qs])
    meas = [platform_dof(sph, q) for q in qs]
    dof = np.array([m[0] for m in meas])
    axes = np.array([m[1] for m in meas])
    rows.append(compare(f"spherical: Robot.mobility, MCS1+MCS2+LL locked = 2 rod spins + 1 (measured {_values(mob)})",
                        mob - 3, 0.0))
    rows.append(compare(f"spherical: uncontrolled platform DOF = 1 (measured {_values(dof)})", dof - 1, 0.0))
    axis_a = ah.spherical_free_axis(rot)
    rows.append(compare("spherical: free axis, Pinocchio null space vs (R a1 x d1) x (R a2 x d2)",
                        per_sample(axes - axis_a), TOL))
    return rows


# ---------------------------------------------------------------- the IK contract row
def _aspect_poses(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` (roll, pitch) uniform in the neutral aspect (branch (1, 1), assembly mode +1, pitch < PITCH_SPLIT)."""
    out_r, out_p, got = [], [], 0
    while got < n:
        r = rng.uniform(-1.3, 1.3, 3 * n + 16)
        p = rng.uniform(-0.62, 0.98, 3 * n + 16)
        mode, ok = ah.assembly_mode(r, p, return_mask=True)
        keep = ok & (mode == 1) & (p < ah.PITCH_SPLIT)
        out_r.append(r[keep])
        out_p.append(p[keep])
        got += int(keep.sum())
    return np.concatenate(out_r)[:n], np.concatenate(out_p)[:n]


def _aspect_boundary(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` poses on the edge of the neutral aspect (reach boundary |k| = 1, or just inside det N = 0), found by
    bisection along random directions from R_P = I on "reachable on branch (1, 1) and in mode +1"."""
    d = rng.normal(size=(n, 2))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    lo, hi = np.zeros(n), np.full(n, 2.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        mode, ok = ah.assembly_mode(mid * d[:, 0], mid * d[:, 1], return_mask=True)
        inside = ok & (mode == 1)
        lo, hi = np.where(inside, mid, lo), np.where(inside, hi, mid)
    return lo * d[:, 0], lo * d[:, 1]


def _fk_made(roll, pitch, tll):
    """Foot targets made by the default ``fk`` from the in-limit joints of poses (roll, pitch, theta_LL)
    of the neutral mode; returns the targets and the mask of those the FK produced."""
    th, ok = ah.motor_angles(roll, pitch, return_mask=True)
    th = np.where(ok[:, None], th, 0.0)
    p, made = ah.fk(np.column_stack([th, ah.extension_motor_angle(tll)]), return_mask=True)
    return p, made & ok


def ik_robustness_targets(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` foot targets (n, 3) and the mask of those made by the default FK from in-limit joints.

    About half made: poses uniform in the neutral aspect with theta_LL uniform in the LL limits [-pi, pi]; poses
    on the aspect's edge (reach boundary, and the forward-singularity side, where the FK refuses the band); the
    LL arc's ends (theta_LL = LL_DELTA - pi: 3.14042 m from the centre, and theta_LL = LL_DELTA: 0.14042 m, where
    the LL branches meet) and LL at its limits +-pi; feet on the roll axis (pitch = atan2(f_z, f_x)); random motor
    angles over the neutral aspect's motor range. The rest (made = False): uniform in a ball of 3.3 m around the
    centre (the arc reaches 3.14 m), FK-made targets moved by 1e-10 to 0.1 m, points on the roll axis, at the LL
    arc's ends +- 1e-15..1e-9 relative, and the centre itself.
    """
    n = int(n)
    n_made = n // 2
    k = [int(n_made * f) for f in (0.4, 0.1, 0.1, 0.1, 0.1)]
    k.append(n_made - sum(k))
    parts_p, parts_m = [], []

    def add(p, made):
        parts_p.append(p)
        parts_m.append(made)

    r, pch = _aspect_poses(k[0], rng)
    add(*_fk_made(r, pch, rng.uniform(-ah.LL_LIMIT, ah.LL_LIMIT, k[0])))
    r, pch = _aspect_boundary(k[1], rng)
    add(*_fk_made(r, pch, rng.uniform(-ah.LL_LIMIT, ah.LL_LIMIT, k[1])))
    r, pch = _aspect_poses(k[2], rng)  # LL arc ends and LL limits
    ends = np.array([ah.LL_DELTA - np.pi, ah.LL_DELTA, np.pi, -np.pi])
    add(*_fk_made(r, pch, ends[rng.integers(0, 4, k[2])]))
    r, pch = _aspect_boundary(k[3], rng)  # both at once
    add(*_fk_made(r, pch, ends[rng.integers(0, 4, k[3])]))
    # feet on the roll axis: pitch = atan2(f_z, f_x) puts R_P f on the x axis for any roll
    tll = rng.uniform(-0.6, 0.6, 4 * k[4] + 16)
    f = ah.LL_ORIGIN[[0, 2]][None] + ah.FOOT_X * np.stack([np.cos(tll), -np.sin(tll)], -1)
    pa = np.arctan2(f[:, 1], f[:, 0])
    ra = rng.uniform(-1.2, 1.2, len(tll))
    mode, ok = ah.assembly_mode(ra, pa, return_mask=True)
    sel = np.flatnonzero(ok & (mode == 1))[: k[4]]
    add(*_fk_made(ra[sel], pa[sel], tll[sel]))
    # random motor angles over the motor range of the neutral aspect (most assemble there)
    th = rng.uniform([-1.6, -2.7], [2.7, 1.6], (3 * k[5] + 16, 2))
    t0 = ah.extension_motor_angle(rng.uniform(-ah.LL_LIMIT, ah.LL_LIMIT, len(th)))
    p, made = ah.fk(np.column_stack([th, t0]), return_mask=True)
    sel = np.flatnonzero(made)[: k[5]]
    add(p[sel], made[sel])

    made_p = np.concatenate([q[m] for q, m in zip(parts_p, parts_m)])
    while len(made_p) < n_made:  # the edge samples on the forward-singularity side are refused by the FK: top up
        r, pch = _aspect_poses(n_made - len(made_p), rng)
        p, ok = _fk_made(r, pch, rng.uniform(-ah.LL_LIMIT, ah.LL_LIMIT, len(r)))
        made_p = np.concatenate([made_p, p[ok]])
    m = n - len(made_p)
    k = [int(m * f) for f in (0.4, 0.4, 0.08, 0.08)]
    k.append(m - sum(k))
    out = [made_p]
    v = rng.normal(size=(k[0], 3))
    v *= (3.3 * rng.uniform(0, 1, (k[0], 1)) ** (1 / 3)) / np.linalg.norm(v, axis=-1, keepdims=True)
    out.append(ah.CENTER + v)
    base = made_p[rng.integers(0, max(len(made_p), 1), k[1])] if len(made_p) else np.tile(ah.CENTER, (k[1], 1))
    v = rng.normal(size=(k[1], 3))
    v *= 10.0 ** rng.uniform(-10, -1, (k[1], 1)) / np.linalg.norm(v, axis=-1, keepdims=True)
    out.append(base + v)
    out.append(ah.CENTER + np.stack([rng.uniform(-3.3, 3.3, k[2]), np.zeros(k[2]), np.zeros(k[2])], -1))
    v = rng.normal(size=(k[3], 3))
    radius = np.where(rng.uniform(size=k[3]) < 0.5, LL0 + H, LL0 - H)
    radius *= 1.0 + rng.choice([-1.0, 1.0], k[3]) * 10.0 ** rng.uniform(-15, -9, k[3])
    out.append(ah.CENTER + v * (radius / np.linalg.norm(v, axis=-1))[:, None])
    out.append(np.tile(ah.CENTER, (k[4], 1)))
    targets = np.concatenate(out)
    made = np.zeros(len(targets), dtype=bool)
    made[: len(made_p)] = True
    return targets, made


def ik_robustness(n: int, rng: np.random.Generator, *, classify: int | None = 2000) -> CheckResult:
    """The IK contract row of the hybrid leg: default ``ik`` on ``n`` targets in and around the workspace.

    Targets from :func:`ik_robustness_targets` (about half made by the default ``fk`` from in-limit
    joints). The default batch IK runs on all; each solved answer is scored by ``|fk(ik(x)) - x|``
    (default options); up to ``classify`` unsolved targets (None: all; FK-made ones first) are classified by the
    error a single ``ik`` call raises (:func:`legkin.validation.classify_failures`).
    """
    from .._checkkit import classify_failures, robustness_row

    targets, made = ik_robustness_targets(n, rng)
    exceptions = 0
    try:
        sol, solved = ah.ik(targets, return_mask=True)
    except Exception:  # noqa: BLE001 - a foreign exception from the batch call is a defect, counted
        exceptions += 1
        sol, solved = np.full(targets.shape, np.nan), np.zeros(len(targets), dtype=bool)
    error = np.full(len(targets), np.inf)
    if solved.any():
        try:
            back, ok = ah.fk(sol[solved], return_mask=True)
            error[solved] = np.where(ok, np.linalg.norm(back - targets[solved], axis=-1), np.inf)
        except Exception:  # noqa: BLE001
            exceptions += 1
    unsolved = np.flatnonzero(~solved)
    order = np.concatenate([unsolved[made[unsolved]], rng.permutation(unsolved[~made[unsolved]])])
    idx = order if classify is None else order[: int(classify)]
    reasons, exc = classify_failures(lambda i: ah.ik(targets[i]), idx)
    return robustness_row("hybrid_leg", made=made, solved=solved, error=error, reasons=reasons,
                          classified=len(idx), exceptions=exceptions + exc)
