"""Validation of :mod:`legkin.wheel_leg` against Pinocchio (closed loops, frames, contact Jacobian)."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .._checkkit import CheckResult, compare, per_sample, pinocchio_frames
from .._rotations import wrap
from ..robot import load
from . import kinematics as wl
from . import tyre_checks
from ._differences import derivative
from .configuration import SEGMENT_LINKS, configuration, leg_joint_names, local_contact_point, sample_leg_q

TOL = 1e-12
#: Loop solver: passive angles after solve_loops (its own stopping tolerance is 1e-12 on the residual).
TOL_SOLVE = 1e-10
#: Residual tolerance asked of solve_loops (its default, 1e-12, leaves hinge points ~2e-12 off).
SOLVE_TOL = 1e-14
#: Central differences with h = 1e-6: truncation ~h^2 |p'''| plus rounding ~eps |p| / h (measured ~1.3e-10).
TOL_FD = 1e-8
FD_STEP = 1e-6
#: Row sizes of the costlier comparisons (loop solving, constrained Jacobians, mobility).
SOLVE_SAMPLES = 200
JACOBIAN_SAMPLES = 2000
MOBILITY_SAMPLES = 50
GAMMA_RANGE = 0.6

#: Hinge frames of one leg compared with :func:`linkage_points` (frame suffix -> point name).
FRAME_POINTS = {
    "A_L": "A_L", "A_R": "A_R", "B_L": "B_L", "B_R": "B_R", "C_L": "C_L", "C_R": "C_R",
    "C_L_cut": "C_L", "C_R_cut": "C_R", "D_L": "D_L", "D_R": "D_R", "E": "E", "E_cut": "E",
    "F_L": "F_L", "F_R": "F_R", "G": "G", "G_cut": "G", "H_L": "H_L", "H_R": "H_R",
    "U_L": "U_L", "U_R": "U_R", "L_L": "L_L", "L_R": "L_R", "leg": "O",
}  # fmt: skip


class _Samples(NamedTuple):
    """The configurations and contact points every section of :func:`run` compares."""

    robot: Any
    geo: wl.Geometry
    n: int
    leg_q: np.ndarray  # (n, 4, 3) (theta, beta, gamma) per leg
    qs: np.ndarray  # (n, nq) closed configurations
    legs: np.ndarray  # (n,) the leg of each contact sample
    alpha: np.ndarray
    w: np.ndarray
    q3: np.ndarray  # (n, 3) that leg's joints
    local: np.ndarray  # (n, 3) contact point in its rim link
    seg: np.ndarray  # (n,) its rim segment
    seg_frames: list[str]
    idx: np.ndarray  # (n,) index into seg_frames
    pin_p: np.ndarray  # (n, 3) Pinocchio's contact point
    ana: np.ndarray  # (n, 3) fk's


def _assembly_rows(robot, geo, leg_q, qs) -> tuple[list[CheckResult], np.ndarray, list[str]]:
    """Loop residual of the closed-form configurations; linkage_points vs the hinge frames."""
    n = len(qs)
    res = np.array([np.abs(robot.constraint_residual(q)).max() for q in qs])
    rows = [compare("closed-form configuration: loop residual (16 loops, theta 17-160 deg)", res, TOL)]
    frames = [f"{leg}_{f}" for leg in wl.LEGS for f in FRAME_POINTS]
    pos = pinocchio_frames(robot, qs, frames)[0].reshape(n, 4, len(FRAME_POINTS), 3)
    err = np.zeros((n, 4, len(FRAME_POINTS)))
    for k, leg in enumerate(wl.LEGS):
        pts = wl.linkage_points(leg_q[:, k, 0], leg_q[:, k, 1], geometry=geo)
        for m, pt in enumerate(FRAME_POINTS.values()):
            ana = wl.leg_frame_to_robot(pts[pt], leg_q[:, k, 2], leg, geometry=geo)
            err[:, k, m] = per_sample(ana - pos[:, k, m])
    rows.append(compare("linkage_points vs hinge frames oMf (23 frames x 4 legs)", err.max(axis=(1, 2)), TOL))
    return rows, pos, frames


def _loop_solver_rows(robot, qs, pos, frames, rng) -> list[CheckResult]:
    """solve_loops from the motors alone (passive joints perturbed) against the closed form."""
    ns = min(len(qs), SOLVE_SAMPLES)
    fixed = [f"{leg}_{j}" for leg in wl.LEGS for j in ("abad", "phi_L", "phi_R")]
    passive = [f"{leg}_hinge_{h}_{s}" for leg in wl.LEGS for h in "ABDF" for s in "LR"]
    ip = np.array([robot.idx_q(j) for j in passive])
    ang_err, frame_err, iters = np.zeros(ns), np.zeros(ns), np.zeros(ns, dtype=int)
    for i in range(ns):
        q_init = qs[i].copy()
        q_init[ip] += rng.uniform(-0.05, 0.05, ip.size)
        q_sol, info = robot.solve_loops(q_init, fixed, tol=SOLVE_TOL, return_info=True)
        iters[i] = info.iterations
        ang_err[i] = np.abs(wrap(q_sol[ip] - qs[i][ip])).max()
        p_sol = pinocchio_frames(robot, q_sol[None], frames)[0].reshape(4, len(FRAME_POINTS), 3)
        frame_err[i] = per_sample(p_sol - pos[i]).max()
    return [
        compare(f"solve_loops from motors (passive +-0.05 rad off) vs passive_angles, "
                f"{ns} samples, tol {SOLVE_TOL:g}, <= {iters.max()} iterations", ang_err, TOL_SOLVE),
        compare(f"solve_loops: hinge frames vs linkage_points, {ns} samples", frame_err, TOL),
    ]


def _mobility_rows(robot, qs) -> list[CheckResult]:
    nm = min(len(qs), MOBILITY_SAMPLES)
    mob_err = np.zeros(nm)
    for i in range(nm):
        k = i % 4
        others = [j for leg in wl.LEGS if leg != wl.LEGS[k] for j in leg_joint_names(leg)]
        m_leg = robot.mobility(qs[i], locked=others + [f"{wl.LEGS[k]}_abad"])
        m_all = robot.mobility(qs[i])
        mob_err[i] = abs(m_leg - 2) + abs(m_all - 12)
    return [compare(f"mobility: 2 per leg linkage (ABAD locked), 12 for the robot, {nm} samples", mob_err, 0.0)]


def _contact_samples(robot, geo, leg_q, qs, rng) -> tuple[_Samples, np.ndarray, np.ndarray]:
    """Random contact points (leg, alpha, w) of the sampled configurations: Pinocchio's (rim link placement
    times the constant local point) and fk's. Also returns the rim frames' placements (fpos, frot)."""
    n = len(qs)
    legs = rng.integers(0, 4, n)
    alpha = rng.uniform(-np.pi, np.pi, n)
    w = rng.uniform(-geo.T / 2, geo.T / 2, n)
    q3 = leg_q[np.arange(n), legs]
    local, seg = local_contact_point(alpha, w, geo)
    seg_frames = [f"{leg}_{lk}" for leg in wl.LEGS for lk, _ in SEGMENT_LINKS]
    fpos, frot = pinocchio_frames(robot, qs, seg_frames)
    idx = legs * 4 + seg
    pin_p = fpos[np.arange(n), idx] + np.einsum("nij,nj->ni", frot[np.arange(n), idx], local)
    ana = np.empty((n, 3))
    for k, leg in enumerate(wl.LEGS):
        m = legs == k
        ana[m] = wl.fk(q3[m], leg, alpha=alpha[m], w=w[m], geometry=geo)
    s = _Samples(robot, geo, n, leg_q, qs, legs, alpha, w, q3, local, seg, seg_frames, idx, pin_p, ana)
    return s, fpos, frot


def _contact_rows(s: _Samples, fpos, frot) -> list[CheckResult]:
    rows = [compare("fk (contact point) vs rim link oMf * local point (alpha over the whole rim)",
                    per_sample(s.ana - s.pin_p), TOL)]
    # three-arc rim: its upper-rim arcs are fixed in the upper rims (the toe arc about O_r is in no link)
    up = np.abs(s.alpha) > wl.PSI_FG
    local_s, seg_s = local_contact_point(s.alpha[up], s.w[up], s.geo, rim="three_arc")
    idx_s = s.legs[up] * 4 + seg_s
    rows_s = np.arange(up.sum())
    pin_s = fpos[up][rows_s, idx_s] + np.einsum("nij,nj->ni", frot[up][rows_s, idx_s], local_s)
    ana_s = np.empty((up.sum(), 3))
    for k, leg in enumerate(wl.LEGS):
        m = s.legs[up] == k
        ana_s[m] = wl.fk(s.q3[up][m], leg, alpha=s.alpha[up][m], w=s.w[up][m], rim="three_arc", geometry=s.geo)
    rows.append(compare("fk(rim='three_arc'), upper-rim arcs |alpha| > psi_FG vs upper rim oMf",
                        per_sample(ana_s - pin_s), TOL))
    return rows


def _jacobian_rows(s: _Samples) -> list[CheckResult]:
    """jacobian against central differences of fk, and against Pinocchio's closed-loop Jacobian."""
    jac = np.empty((s.n, 3, 3))
    for k, leg in enumerate(wl.LEGS):
        m = s.legs == k
        jac[m] = wl.jacobian(s.q3[m], leg, alpha=s.alpha[m], w=s.w[m], geometry=s.geo)
    fd = np.empty_like(jac)
    one_sided = np.zeros(s.n, dtype=bool)
    for k, leg in enumerate(wl.LEGS):
        m = np.flatnonzero(s.legs == k)

        def contact(q: np.ndarray, rows: np.ndarray, leg: str = leg, m: np.ndarray = m) -> tuple[np.ndarray, None]:
            return wl.fk(q, leg, alpha=s.alpha[m[rows]], w=s.w[m[rows]], geometry=s.geo), None

        for c in range(3):
            lower, upper = (wl.THETA_MIN, wl.THETA_MAX) if c == 0 else (-np.inf, np.inf)
            fd[m, :, c], fitted = derivative(contact, s.q3[m], c, FD_STEP, lower, upper, (s.ana[m], None))
            one_sided[m] |= fitted
    rows = [compare(f"jacobian vs central differences (h = {FD_STEP:g}; {one_sided.sum()} within h of theta's "
                    "limits: one-sided, second order)", np.abs(jac - fd).max(axis=(1, 2)), TOL_FD)]
    nj = min(s.n, JACOBIAN_SAMPLES)
    jerr = np.array([np.abs(_pinocchio_jacobian(s, i) - jac[i]).max() for i in range(nj)])
    rows.append(compare(f"jacobian vs Pinocchio closed-loop Jacobian (constraint null space), {nj} samples",
                        jerr, TOL))
    return rows


def _pinocchio_jacobian(s: _Samples, i: int) -> np.ndarray:
    """d(contact point) / d(theta, beta, gamma) of sample i by Pinocchio: the rim link's frame Jacobian at the
    point, the passive joint rates from the constraint Jacobian's null space."""
    import pinocchio as pin

    robot = s.robot
    model, data = robot.model, robot.data
    leg = wl.LEGS[s.legs[i]]
    q = s.qs[i]
    fid = robot.frame_id(f"{leg}_{SEGMENT_LINKS[s.seg[i]][0]}")
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J6 = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
    r = data.oMf[fid].rotation @ s.local[i]
    Jp = J6[:3] - np.cross(r, J6[3:].T).T  # velocity of the point: v + w x r
    Jc = robot.constraint_jacobian(q)
    iv = [robot.idx_v(f"{leg}_{j}") for j in ("phi_L", "phi_R", "abad")]
    pv = [robot.idx_v(f"{leg}_hinge_{h}_{side}") for h in "ABDF" for side in "LR"]
    # independent velocities (phi_L, phi_R, abad) per unit (theta, beta, gamma) rates
    S_ind = np.array([[1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    S_pas = -np.linalg.pinv(Jc[:, pv], rcond=1e-10) @ (Jc[:, iv] @ S_ind)
    return Jp[:, iv] @ S_ind + Jp[:, pv] @ S_pas


def _ik_round_trip_rows(s: _Samples, method: str, rim: str) -> list[CheckResult]:
    """ik on fk-made targets: the answer reproduces the target; radial: the sampled q is among the solutions."""
    n = s.n
    errs = np.full(n, np.nan)
    its = np.zeros(n, dtype=int)
    ok_all = np.zeros(n, dtype=bool)
    found = np.full(n, np.nan)
    for k, leg in enumerate(wl.LEGS):
        m = s.legs == k
        kw = {"alpha": s.alpha[m], "w": s.w[m], "rim": rim, "geometry": s.geo}
        target = wl.fk(s.q3[m], leg, **kw) if rim == "three_arc" else s.ana[m]
        qk, ok, ik_info = wl.ik(target, leg, method=method, return_mask=True, return_info=True,  # type: ignore[call-overload]
                                **kw)  # (method, rim: names of the Literal types, as str)
        reached = wl.fk(np.where(ok[:, None], qk, s.q3[m]), leg, **kw)
        errs[m] = np.where(ok, per_sample(reached - target), np.nan)
        its[m], ok_all[m] = ik_info.iterations, ok
        if method == "radial":
            assert ik_info.solutions is not None
            sigma = np.linalg.svd(wl.jacobian(s.q3[m], leg, **kw), compute_uv=False)[:, -1]
            found[m] = solution_distance(ik_info.solutions, s.q3[m]) * sigma
    name = (f"ik(method='{method}', rim='{rim}') round trip: {ok_all.sum()}/{n} converged in [17, 160] deg, "
            f"iterations mean {its.mean():.2f} max {its.max()}")
    if method == "gauss_newton_fd":
        # The baseline is measured, not required to succeed: the row covers the converged targets.
        return [compare(name + " (converged targets)", errs[ok_all], TOL)]
    rows = [compare(name, errs, TOL)]
    if method == "radial":
        # Every root found: the sampled q is one of info.solutions. Its distance in q is scaled by the
        # smallest singular value of the contact Jacobian at the sample (near folds theta is
        # ill-conditioned: a position error e moves the root by ~e / sigma_min), giving metres.
        rows.append(compare(f"ik(method='radial', rim='{rim}'): sampled q among info.solutions "
                            "(q distance x sigma_min(J), m)", found, TOL))
    return rows


def _ik_vs_pinocchio_row(s: _Samples) -> CheckResult:
    """Radial IK on Pinocchio's contact points (rim link oMf times the local point), the answers scored by
    Pinocchio on the configuration closing every loop."""
    n = s.n
    q_rad = s.leg_q.copy()
    ok_rad = np.zeros(n, dtype=bool)
    for k, leg in enumerate(wl.LEGS):
        rows_k = np.flatnonzero(s.legs == k)
        qk, ok_rad[rows_k] = wl.ik(s.pin_p[rows_k], leg, alpha=s.alpha[rows_k], w=s.w[rows_k], method="radial",
                                   geometry=s.geo, return_mask=True)
        q_rad[rows_k[ok_rad[rows_k]], k] = qk[ok_rad[rows_k]]
    fpos_r, frot_r = pinocchio_frames(s.robot, configuration(s.robot, q_rad), s.seg_frames)
    pin_r = fpos_r[np.arange(n), s.idx] + np.einsum("nij,nj->ni", frot_r[np.arange(n), s.idx], s.local)
    return compare(f"ik(method='radial') vs Pinocchio: target = rim link oMf * local point, answer's contact "
                   f"point by Pinocchio (closed configuration), {ok_rad.sum()}/{n} solved",
                   np.where(ok_rad, per_sample(pin_r - s.pin_p), np.nan), TOL)


def run(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """The check rows: closed form, loop solver, mobility, contact point, Jacobian and IK against Pinocchio."""
    robot = load("wheel_leg")
    geo = wl.Geometry.from_params(robot.params)
    leg_q = sample_leg_q(4 * samples, rng).reshape(samples, 4, 3)
    qs = configuration(robot, leg_q)
    rows, pos, frames = _assembly_rows(robot, geo, leg_q, qs)
    rows += _loop_solver_rows(robot, qs, pos, frames, rng)
    rows += _mobility_rows(robot, qs)
    s, fpos, frot = _contact_samples(robot, geo, leg_q, qs, rng)
    rows += _contact_rows(s, fpos, frot)
    rows += _jacobian_rows(s)
    for method in ("damped", "gauss_newton_fd", "radial"):
        for rim in ("continuous", "three_arc"):
            rows += _ik_round_trip_rows(s, method, rim)
    rows.append(_ik_vs_pinocchio_row(s))
    rows += tyre_checks.run(samples, rng)
    return rows


def solution_distance(solutions: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Distance (max-norm, angles wrapped) from each q (n, 3) to the nearest of its solutions (n, S, 3)."""
    d = solutions - q[:, None, :]
    d[..., 1:] = wrap(d[..., 1:])
    d = np.abs(d).max(axis=-1)
    return np.min(np.where(np.isnan(d), np.inf, d), axis=1)


def ik_robustness(n: int, rng: np.random.Generator, *, classify: int | None = 2000) -> CheckResult:
    """The IK contract row: the default :func:`wl.ik` on ``n`` random targets in and around the workspace.

    Half the targets (``made``) are :func:`wl.fk` of random joints inside the URDF limits (theta over
    [17, 160] deg, beta over the circle, gamma over [-pi/2, pi/2], 10 % of them on a limit) at random rim
    points (alpha, w); a quarter are such targets pushed off by up to 5 cm in a random direction; a quarter are
    uniform in a 0.8 m box around the module origin. Legs in turn. Each solved answer is scored by the
    default :func:`wl.fk`; up to ``classify`` unsolved targets are classified by single calls.
    """
    from .._checkkit import classify_failures, robustness_row

    legs = np.arange(n) % 4
    m_made, m_push = n // 2, n // 4
    kind = np.zeros(n, dtype=int)
    kind[m_made:m_made + m_push], kind[m_made + m_push:] = 1, 2
    q = np.stack([rng.uniform(wl.THETA_MIN, wl.THETA_MAX, n), rng.uniform(-np.pi, np.pi, n),
                  rng.uniform(-wl.ABAD_LIMIT, wl.ABAD_LIMIT, n)], -1)
    on_limit = rng.random(n) < 0.1
    q[on_limit, 2] = rng.choice([-wl.ABAD_LIMIT, wl.ABAD_LIMIT], on_limit.sum())
    alpha, w = rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.02, 0.02, n)
    target = np.empty((n, 3))
    solved = np.zeros(n, dtype=bool)
    error = np.full(n, np.nan)
    exceptions = 0
    for k, leg in enumerate(wl.LEGS):
        m = np.flatnonzero(legs == k)
        t = wl.fk(q[m], leg, alpha=alpha[m], w=w[m])
        push = kind[m] == 1
        d = rng.normal(size=(push.sum(), 3))
        t[push] += d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(0.0, 0.05, (push.sum(), 1))
        box = kind[m] == 2
        t[box] = wl.module_origin(leg) + rng.uniform(-0.4, 0.4, (box.sum(), 3))
        target[m] = t
        try:
            qs, ok = wl.ik(t, leg, alpha=alpha[m], w=w[m], return_mask=True)
        except Exception:  # noqa: BLE001 - a foreign exception from the batch is a defect, counted
            exceptions += 1
            continue
        solved[m] = ok
        error[m[ok]] = per_sample(wl.fk(qs[ok], leg, alpha=alpha[m[ok]], w=w[m[ok]]) - t[ok])
    unsolved = np.flatnonzero(~solved)
    pick = unsolved if classify is None else unsolved[: max(int(classify), 0)]
    reasons, single_exc = classify_failures(
        lambda i: wl.ik(target[i], wl.LEGS[legs[i]], alpha=alpha[i], w=w[i]), pick)
    return robustness_row("wheel_leg", made=kind == 0, solved=solved, error=error, reasons=reasons,
                          classified=len(pick), exceptions=exceptions + single_exc)
