"""Hybrid leg: closed-form ``ik`` (batch and scalar) vs a Pinocchio closed-loop iterative IK, same targets.

Targets: Pinocchio's ``FCS`` frame at closed configurations (``configuration.closed_configuration``) of
random platform poses of the neutral assembly mode (``configuration.sample_workspace``, motor Jacobian
sigma_min >= 1e-2) and theta_LL uniform on the extension side [-0.3, delta] (the ``ll_branch`` ik tries first).
Every answer (three motor angles) is scored the same way: the foot that those motors give in the neutral
assembly mode (:func:`legkin.hybrid_leg.fk`, validated against Pinocchio) vs the target.
"""

from __future__ import annotations

from typing import Callable, Iterator

import numpy as np

from .._benchkit import (
    SOLVE_TOL,
    Method,
    MethodResult,
    ModelBench,
    Score,
    levenberg_marquardt_rows,
    pinocchio_positions,
    scalar_loop,
    sizes,
)
from .._single_call import SingleCall
from ..robot import Robot, load
from . import kinematics as ah
from .configuration import LL_RANGE, closed_configuration, sample_workspace

TOL = 1e-12
MAX_ITER = 100


def _sizes(n: int | None, quick: bool) -> tuple[int, int, int]:
    """(batch targets, scalar-loop targets, iterative-solver targets)."""
    return sizes(n, quick, full=(20_000, 2_000, 200), small=(1_000, 100, 10))


#: The single-call inputs: a platform pose of the neutral assembly mode and an extension-motor angle.
SINGLE_POSE = (0.1, 0.2)
SINGLE_THETA0 = 1.0


def single_calls() -> list[SingleCall]:
    """One single call per public function of :mod:`legkin.hybrid_leg`, inputs bound.

    Inputs: the motors of the platform pose :data:`SINGLE_POSE` (roll, pitch) on branch (1, 1), theta0 =
    :data:`SINGLE_THETA0`, the foot they give as the IK target. Yardsticks: Pinocchio ``forwardKinematics`` +
    ``updateFramePlacement`` on the quadruped (``quadruped_fk``) for the closed forms; ``Robot.solve_loops`` on
    the hybrid leg (``solve_loops``, ``iterative=True``) for the functions that solve the closed sub-chain's
    forward kinematics (the degree-8 polynomial and Newton): platform_orientation, platform_poses, fk and
    jacobian. ik_all is a closed form (16 branches, each checked by the root-isolation certificate of
    :mod:`._ik_certify`, the forward kinematics only where that cannot settle): quadruped_fk.
    """
    roll, pitch = SINGLE_POSE
    t0 = SINGLE_THETA0
    rot = ah.platform_rotation(roll, pitch)
    t1, t2 = (float(v) for v in ah.motor_angles(roll, pitch))
    tll = float(ah.ll_angle(t0))
    q = np.array([t1, t2, t0])
    p = ah.fk(q)
    cf, it = "quadruped_fk", "solve_loops"
    return [
        SingleCall("ll_angle", lambda: ah.ll_angle(t0), cf),
        SingleCall("extension_motor_angle", lambda: ah.extension_motor_angle(tll), cf),
        SingleCall("platform_rotation", lambda: ah.platform_rotation(roll, pitch), cf),
        SingleCall("rod_spans", lambda: ah.rod_spans(t1, t2, roll, pitch), cf),
        SingleCall("motor_angles", lambda: ah.motor_angles(roll, pitch), cf),
        SingleCall("motor_angles_from_rotation", lambda: ah.motor_angles_from_rotation(rot), cf),
        SingleCall("motor_jacobian", lambda: ah.motor_jacobian(roll, pitch), cf),
        SingleCall("sphere_joint_angles", lambda: ah.sphere_joint_angles(rot), cf),
        SingleCall("spherical_free_axis", lambda: ah.spherical_free_axis(rot), cf),
        SingleCall("assembly_mode", lambda: ah.assembly_mode(roll, pitch), cf),
        SingleCall("foot_position_from_platform", lambda: ah.foot_position_from_platform(roll, pitch, tll), cf),
        SingleCall("foot_platform_ik", lambda: ah.foot_platform_ik(p), cf),
        SingleCall("ik", lambda: ah.ik(p), cf),
        SingleCall("platform_orientation", lambda: ah.platform_orientation(t1, t2), it, iterative=True),
        SingleCall("platform_poses", lambda: ah.platform_poses(t1, t2), it, iterative=True),
        SingleCall("fk", lambda: ah.fk(q), it, iterative=True),
        SingleCall("jacobian", lambda: ah.jacobian(q), it, iterative=True),
        SingleCall("ik_all", lambda: ah.ik_all(p), cf),
        SingleCall("ik_branches", lambda: ah.ik_branches(p), cf),
    ]


def _targets(robot: Robot, n: int, rng: np.random.Generator) -> np.ndarray:
    """Pinocchio's FCS at ``n`` closed configurations: neutral-mode platform poses, theta_LL in [-0.3, delta]."""
    roll, pitch = sample_workspace(n, rng)
    theta_ll = rng.uniform(LL_RANGE[0], ah.LL_DELTA, n)
    qs = closed_configuration(robot, np.stack([roll, pitch], -1), theta_ll)
    targets, _ = pinocchio_positions(robot.model, robot.data, robot.frame_id("FCS"), qs)
    return targets  # type: ignore[no-any-return]


def _score_motors(p: np.ndarray, motors: np.ndarray, residual: np.ndarray | None = None,
                  iters: np.ndarray | None = None, evals: np.ndarray | None = None) -> Score:
    """The foot of the motors (theta1, theta2, theta0) in the neutral assembly mode (fk) vs the target."""
    motors = np.asarray(motors, dtype=float)
    ok_in = np.all(np.isfinite(motors), axis=-1)
    foot = np.full((len(p), 3), np.nan)
    if ok_in.any():
        foot[ok_in] = ah.fk(motors[ok_in])
    err = np.linalg.norm(foot - p, axis=-1)
    solved = err <= SOLVE_TOL
    if residual is not None:
        solved &= residual <= SOLVE_TOL
    return Score(error=err, solved=solved, orientation=residual, iterations=iters, fk_evals=evals)


def _scalar_ik(p: np.ndarray) -> np.ndarray:
    """ik one target at a time (a Python loop of single calls), NaN where it raises."""
    return scalar_loop(ah.ik, p, 3)


def _pinocchio_ik(robot: Robot) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Pinocchio's closed-loop IK: the Levenberg-Marquardt of Robot.solve_loops on [loop closures; FCS - target],
    every joint free, from q0 (the loop rows from the public ``constraint_residual`` / ``constraint_jacobian``, the
    foot rows from ``forwardKinematics`` + ``getFrameJacobian`` in ``robot.data``)."""
    import pinocchio as pin

    model, data = robot.model, robot.data
    fid = robot.frame_id("FCS")
    free = np.ones(model.nv, dtype=bool)

    def problems(p: np.ndarray) -> Iterator[tuple[Callable, np.ndarray]]:
        for target in p:

            def residual_and_jacobian(q: np.ndarray, target: np.ndarray = target) -> tuple[np.ndarray, np.ndarray]:
                r, jc = robot.constraint_residual(q), robot.constraint_jacobian(q)
                pin.computeJointJacobians(model, data, q)  # also the forward kinematics
                pin.updateFramePlacement(model, data, fid)
                jf = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
                return np.concatenate([r, data.oMf[fid].translation - target]), np.vstack([jc, jf])

            yield residual_and_jacobian, robot.q0.copy()

    def solve(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return levenberg_marquardt_rows(model, problems(p), len(p), free, TOL, MAX_ITER)

    return solve


def _pinocchio_score(robot: Robot) -> Callable[[np.ndarray, tuple[np.ndarray, ...]], Score]:
    """Scores Pinocchio's configurations as the closed forms' motors, with their loop residual."""
    i_m = [robot.idx_q(j) for j in ("MCS1", "MCS2", "LL")]

    def score(p: np.ndarray, out: tuple[np.ndarray, ...]) -> Score:
        qs, iters, evals = out
        motors = np.column_stack([qs[:, i_m[0]], qs[:, i_m[1]], ah.extension_motor_angle(qs[:, i_m[2]])])
        res = np.array([np.linalg.norm(robot.constraint_residual(q)) if np.all(np.isfinite(q)) else np.nan
                        for q in qs])
        return _score_motors(p, motors, res, iters, evals)

    return score


def _notes(n_batch: int, n_scalar: int, n_iter: int) -> list[str]:
    return [
        f"targets: Pinocchio FCS of {n_batch} closed configurations, platform poses of the neutral assembly mode "
        "(sigma_min(dtheta/dx) >= 1e-2), theta_LL uniform in [-0.3, delta] (the ll_branch ik tries first); the "
        f"scalar loop solves the first {n_scalar}, Pinocchio the first {n_iter}",
        "err = foot of the answer's motors (theta1, theta2, theta0) in the neutral assembly mode (fk) vs "
        "target (m); loop |r| = Pinocchio loop residual of the Pinocchio answer; a Pinocchio answer closing the "
        "loops in another assembly mode lands elsewhere and counts as not solved",
        f"pinocchio closed-loop IK: the Levenberg-Marquardt of Robot.solve_loops on [2 rod closures; FCS - target] "
        f"(Robot.constraint_residual and constraint_jacobian, getFrameJacobian LOCAL_WORLD_ALIGNED), every joint "
        f"free, tolerance {TOL:g}, at most {MAX_ITER} iterations; theta0 from theta_LL by eq 19",
    ]


def _summary(results: list[MethodResult]) -> list[str]:
    b = next(r for r in results if "batch" in r.name)
    s = next(r for r in results if "scalar" in r.name)
    p = next(r for r in results if "pinocchio" in r.name)
    return [
        f"batch ik is {p.time_per_target_s / b.time_per_target_s:,.0f}x and the scalar call "
        f"{p.time_per_target_s / s.time_per_target_s:,.1f}x faster than the Pinocchio closed-loop IK"
    ]


def build(n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    """The ``legkin bench`` rows: batch and scalar ``ik`` vs Pinocchio's closed-loop IK on the same targets."""
    n_batch, n_scalar, n_iter = _sizes(n, quick)
    robot = load("hybrid_leg")
    targets = _targets(robot, n_batch, rng)
    methods = [
        Method(f"legkin batch closed form (ik; {n_batch} at once)", targets, ah.ik,
               lambda p, m: _score_motors(p, m), repeats=5),
        Method("legkin scalar closed form, Python loop", targets, _scalar_ik, lambda p, m: _score_motors(p, m),
               max_targets=n_scalar, repeats=3),
        Method("pinocchio closed-loop IK (LM on loops + foot, start q0)", targets, _pinocchio_ik(robot),
               _pinocchio_score(robot), max_targets=n_iter, repeats=3),
    ]
    tolerance = f"foot error <= {SOLVE_TOL:g} m (and loop |r| <= {SOLVE_TOL:g} for Pinocchio's configuration)"
    return ModelBench(methods=methods, units={"ik": "m"}, tolerance=tolerance, notes=_notes(n_batch, n_scalar, n_iter),
                      summary=_summary, secondary="loop |r|")
