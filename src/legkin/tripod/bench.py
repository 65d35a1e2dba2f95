"""Tripod: analytic ``fk`` / ``ik`` vs Pinocchio-only iterations on the closed-loop model, same targets.

Targets: platform orientations (alpha_y, alpha_z) uniform over the workspace (``configuration.sample_workspace``);
their motor angles come from :func:`legkin.tripod.ik`. Scored the same way for every method:
the platform rotation reached (from the answer's orientation, or Pinocchio's ``platform`` frame for a
joint configuration) against the target, and Pinocchio's loop residual at the joint configuration.
"""

from __future__ import annotations

import numpy as np

from .. import _benchkit
from .._benchkit import SOLVE_TOL, Method, MethodResult, ModelBench, Score, rotation_error, sizes
from ..errors import LoopClosureError
from ..robot import load
from . import kinematics as at
from .configuration import MOTOR_COLUMNS, sample_workspace

#: The tolerance every iterative method is given (fk's step tolerance, solve_loops' residual tolerance).
TOL = 1e-12
MAX_ITER = 100


def _sizes(n: int | None, quick: bool) -> tuple[int, int, int]:
    """(batch targets, scalar-loop targets, iterative-solver targets)."""
    return sizes(n, quick, full=(20_000, 2_000, 200), small=(1_000, 100, 10))


def _pin_rot_and_residual(robot, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's platform rotation and loop-residual norm at each finite joint configuration (NaN elsewhere)."""
    rot = np.full((len(qs), 3, 3), np.nan)
    res = np.full(len(qs), np.nan)
    for i, q in enumerate(qs):
        if np.all(np.isfinite(q)):
            rot[i] = robot.frame_placement(q, "platform").rotation
            res[i] = np.linalg.norm(robot.constraint_residual(q))
    return rot, res


def _joints_scorer(robot, r_true: np.ndarray):
    """Score of a joint answer (``qs`` or ``(qs, iterations)``): rotation error and loop residual."""

    def joints_score(rows, out) -> Score:
        qs, iters = out if isinstance(out, tuple) else (out, None)
        k = len(rows)
        rot, res = _pin_rot_and_residual(robot, qs)
        err = rotation_error(rot, r_true[:k])
        ok = (err <= SOLVE_TOL) & (res <= SOLVE_TOL)
        return Score(error=err, solved=ok, orientation=res, iterations=iters)

    return joints_score


def _fk_methods(robot, motors: np.ndarray, r_true: np.ndarray, n_batch: int, n_scalar: int,
                n_iter: int) -> list[Method]:
    """fk: motors -> orientation (batch, scalar loop, ``Robot.solve_loops``)."""
    model = robot.model
    joints_score = _joints_scorer(robot, r_true)

    def fk_batch(m):
        return at.fk(m, tol=TOL)

    def fk_scalar(m):
        return _benchkit.scalar_loop(lambda row: at.fk(row, tol=TOL), m, 2)

    def fk_score(m, u) -> Score:
        k = len(m)
        err = rotation_error(at.platform_rotation(np.nan_to_num(u[:, 0]), np.nan_to_num(u[:, 1])), r_true[:k])
        err = np.where(np.all(np.isfinite(u), axis=-1), err, np.nan)
        return Score(error=err, solved=err <= SOLVE_TOL)

    def solve_loops_run(m):
        qs = np.full((len(m), model.nq), np.nan)
        iters = np.full(len(m), np.nan)
        for i, (a, b, c) in enumerate(m):
            try:
                q, info = robot.solve_loops(
                    fixed={"A_q1": a, "B_q1": b, "C_q1": c}, tol=TOL, max_iter=MAX_ITER, return_info=True
                )
            except LoopClosureError as exc:
                iters[i] = exc.iterations
                continue
            qs[i], iters[i] = q, info.iterations
        return qs, iters

    return [
        Method(f"legkin batch fk (Gauss-Newton, analytic A_u; {n_batch} at once)", motors, fk_batch, fk_score,
               group="fk", repeats=5),
        Method("legkin scalar fk, Python loop", motors, fk_scalar, fk_score, group="fk", max_targets=n_scalar,
               repeats=3),
        Method("pinocchio Robot.solve_loops (motors held, start q0)", motors, solve_loops_run, joints_score,
               group="fk", max_targets=n_iter, repeats=3),
    ]


def _pin_inverse(robot):
    """Pinocchio-only inverse: Levenberg-Marquardt on [loop residual; log3(R_target^T R_platform)], every joint
    free; returns ``(qs, iterations, fk evaluations)``."""
    import pinocchio as pin

    model = robot.model
    fid = robot.frame_id("platform")
    loopset = robot._loopset
    ldata = loopset.data
    free = np.ones(model.nv, dtype=bool)

    def problems(u):
        for a, b in u:
            r_t = at.platform_rotation(a, b)

            def residual_and_jacobian(q, r_t=r_t):
                r, jac = loopset.residual_and_jacobian(q)  # forward kinematics + joint Jacobians in ldata
                pin.updateFramePlacement(model, ldata, fid)
                r_err = r_t.T @ ldata.oMf[fid].rotation
                e = pin.log3(r_err)
                j_rot = pin.Jlog3(r_err) @ pin.getFrameJacobian(model, ldata, fid, pin.LOCAL)[3:]
                return np.concatenate([r, e]), np.vstack([jac, j_rot])

            yield residual_and_jacobian, robot.q0.copy()

    def pin_inverse(u):
        return _benchkit.levenberg_marquardt_rows(model, problems(u), len(u), free, TOL, MAX_ITER)

    return pin_inverse


def _ik_methods(robot, orient: np.ndarray, r_true: np.ndarray, n_batch: int, n_scalar: int,
                n_iter: int) -> list[Method]:
    """ik: orientation -> joints (batch closed form, scalar loop, Pinocchio-only inverse)."""
    joints_score = _joints_scorer(robot, r_true)

    def ik_batch(u):
        return at.ik_joints(u)

    def ik_scalar(u):
        return _benchkit.scalar_loop(at.ik_joints, u, 12)

    pin_inverse = _pin_inverse(robot)

    def pin_inverse_score(rows, out) -> Score:
        s = joints_score(rows, out[:2])
        s.fk_evals = out[2]
        return s

    def ik_score(rows, qs) -> Score:
        return joints_score(rows, qs)

    return [
        Method(f"legkin batch ik (closed form; {n_batch} at once)", orient, ik_batch, ik_score, group="ik",
               repeats=5),
        Method("legkin scalar ik, Python loop", orient, ik_scalar, ik_score, group="ik", max_targets=n_scalar,
               repeats=3),
        Method("pinocchio-only inverse (loops + platform rotation, LM, start q0)", orient, pin_inverse,
               pin_inverse_score, group="ik", max_targets=n_iter, repeats=3),
    ]


def _notes(n_batch: int, n_scalar: int, n_iter: int) -> list[str]:
    return [
        f"targets: {n_batch} platform orientations uniform over the workspace (alpha_y in [-pi/2, pi/2], alpha_z in "
        f"[-pi, pi], kept where ik succeeds), motors = ik(target); slow methods use the first {n_scalar} (loops) "
        f"or {n_iter} (Pinocchio) of the same targets",
        "err = geodesic angle between the platform rotation reached and the target's; loop |r| = norm of "
        "Pinocchio's stacked loop residual at the joints returned (fk returns no joints: '-')",
        f"every iterative method is given tolerance {TOL:g} (fk: step; Pinocchio: residual norm) and at most "
        f"{MAX_ITER} iterations (fk's own cap is 30)",
        "Robot.solve_loops: Levenberg-Marquardt on Pinocchio's FrameAnchor constraint residuals/Jacobians "
        "with the three motors held; it may close the loops in another assembly mode (a different platform pose): "
        "that counts as not solved",
        "pinocchio-only inverse: the same Levenberg-Marquardt on [loop residual; log3(R_target^T R_platform)] "
        "with getFrameJacobian(LOCAL) and Jlog3, every joint free",
    ]


def _summary(results: list[MethodResult]) -> list[str]:
    lines = []
    for g, batch_key, pin_key in (("fk", "batch fk", "solve_loops"), ("ik", "batch ik", "pinocchio-only")):
        b = next(r for r in results if batch_key in r.name)
        p = next(r for r in results if pin_key in r.name)
        s = next(r for r in results if r.group == g and "scalar" in r.name)
        lines.append(
            f"{g}: batch is {p.time_per_target_s / b.time_per_target_s:,.0f}x and the scalar call "
            f"{p.time_per_target_s / s.time_per_target_s:,.1f}x faster than {p.name.split(' (')[0]} (target >= 10x"
            f"{' for fk' if g == 'fk' else ''})"
        )
    return lines


def build(n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    n_batch, n_scalar, n_iter = _sizes(n, quick)
    robot = load("tripod")
    ay, az = sample_workspace(n_batch, rng)
    r_true = at.platform_rotation(ay, az)
    orient = np.stack([ay, az], axis=-1)
    motors = at.ik(orient)
    methods = _fk_methods(robot, motors, r_true, n_batch, n_scalar, n_iter) + _ik_methods(
        robot, orient, r_true, n_batch, n_scalar, n_iter
    )
    tolerance = f"rotation error <= {SOLVE_TOL:g} rad (and loop |r| <= {SOLVE_TOL:g} for joint answers)"
    return ModelBench(methods=methods, units={"fk": "rad", "ik": "rad"}, tolerance=tolerance,
                      notes=_notes(n_batch, n_scalar, n_iter), summary=_summary, secondary="loop |r|")


def single_calls() -> list:
    """One single call per public function of :mod:`legkin.tripod` (issue 16), inputs bound: a pose inside
    the workspace and its motors. Closed forms are compared with the quadruped's forward kinematics, ``fk``
    (iterative) with ``Robot.solve_loops`` on the tripod."""
    from .._single_call import SingleCall

    ay, az = 0.3, -0.4
    target = np.array([ay, az])
    q = at.ik_joints(target)
    motors = q[list(MOTOR_COLUMNS)]
    leg = np.array([float(q[0]), float(q[1]), float(q[2]) + 0.1, float(q[3]) - 0.2])
    leg_cv = np.array([float(q[4]), float(q[5])])
    axis = at.platform_axis(ay, az)
    closed = [
        ("leg_transform", lambda: at.leg_transform(leg, "A")),
        ("leg_transform_cv", lambda: at.leg_transform_cv(leg_cv, "B")),
        ("alpha_x", lambda: at.alpha_x(ay, az)),
        ("platform_rotation", lambda: at.platform_rotation(ay, az)),
        ("platform_position", lambda: at.platform_position(ay, az)),
        ("platform_axis", lambda: at.platform_axis(ay, az)),
        ("orientation_from_axis", lambda: at.orientation_from_axis(axis)),
        ("ik", lambda: at.ik(target)),
        ("ik_all", lambda: at.ik_all(target)),
        ("ik_joints", lambda: at.ik_joints(target)),
        ("jacobian", lambda: at.jacobian(target)),
        ("workspace", lambda: at.workspace(n=2, m=2)),
    ]
    calls = [SingleCall(name, call, "quadruped_fk") for name, call in closed]
    calls.insert(11, SingleCall("fk", lambda: at.fk(motors), "solve_loops", iterative=True))
    return calls
