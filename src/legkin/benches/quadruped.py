"""Quadruped foot IK: legkin's closed form (batch and scalar) vs Pinocchio CLIK, ikpy and TRAC-IK.

Targets: Pinocchio's forward kinematics of the ``LF_FOOT`` frame for joint vectors of leg LF drawn uniformly
inside its joint limits (other legs at ``q0``), so every target is reachable inside the limits. Every
method's answer is scored the same way: Pinocchio's foot position at the returned joints (taken mod 2 pi
into the limits) against the target; solved = error <= SOLVE_TOL and joints inside the limits.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .. import load
from ..analytic import quadruped as aq
from ..bench import Method, MethodResult, ModelBench, Score
from ..errors import UnreachableError
from . import SOLVE_TOL, missing, pinocchio_positions, quiet_stdout, sizes

LEG = "LF"
#: CLIK settings of Pinocchio's examples/inverse-kinematics.py, with the issue's tolerance 1e-10.
CLIK_EPS, CLIK_IT_MAX, CLIK_DT, CLIK_DAMP = 1e-10, 1000, 1e-1, 1e-12
#: TRAC-IK's Cartesian tolerance, set to the CLIK tolerance (its default is 1e-5).
TRACIK_EPS = 1e-10


def _sizes(n: int | None, quick: bool) -> tuple[int, int, int]:
    """(batch targets, scalar-loop targets, iterative-solver targets)."""
    return sizes(n, quick, full=(100_000, 5_000, 300), small=(2_000, 200, 10))


def _into_limits(q: np.ndarray) -> np.ndarray:
    """Angles shifted by multiples of 2 pi to start at the lower limit (same pose, comparable to the limits)."""
    lo = aq.JOINT_LIMITS[:, 0]
    return lo + np.mod(q - lo, 2.0 * math.pi)


def build(n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    n_batch, n_scalar, n_iter = _sizes(n, quick)
    robot = load("quadruped")
    model, data = robot.model, robot.data
    fid = robot.frame_id(f"{LEG}_FOOT")
    iq = robot.idx_q(f"{LEG}_HAA")
    q0_leg = robot.q0[iq : iq + 3].copy()

    q_gen = rng.uniform(aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1], (n_batch, 3))
    full = np.tile(robot.q0, (n_batch, 1))
    full[:, iq : iq + 3] = q_gen
    targets, target_rot = pinocchio_positions(model, data, fid, full)

    def joints_score(p: np.ndarray, out) -> Score:
        qs, iters = out if isinstance(out, tuple) else (out, None)
        qs = np.asarray(qs, dtype=float)
        inside = np.all(np.isfinite(qs), axis=-1)
        qw = np.where(inside[:, None], _into_limits(np.nan_to_num(qs)), np.nan)
        inside &= aq.within_limits(np.nan_to_num(qw, nan=1e9))
        f = np.tile(robot.q0, (len(qs), 1))
        f[:, iq : iq + 3] = qs
        pos, _ = pinocchio_positions(model, data, fid, f)
        err = np.linalg.norm(pos - p, axis=-1)
        fk = None if iters is None else iters + 1
        reached = err <= SOLVE_TOL
        return Score(error=err, solved=reached & inside, iterations=iters, fk_evals=fk, reached=reached)

    def fk_score(q: np.ndarray, pos: np.ndarray) -> Score:
        err = np.linalg.norm(pos - targets[: len(q)], axis=-1)
        return Score(error=err, solved=err <= SOLVE_TOL)

    # ---------------------------------------------------------------- legkin
    def batch_ik(p):
        return aq.foot_ik(p, LEG)

    def scalar_ik(p):
        out = np.full((len(p), 3), np.nan)
        for i, pi in enumerate(p):
            try:
                out[i] = aq.foot_ik(pi, LEG)
            except UnreachableError:
                pass
        return out

    # ---------------------------------------------------------------- Pinocchio CLIK
    import pinocchio as pin

    damp_eye = CLIK_DAMP * np.eye(3)

    def clik(dt: float):
        def run(p):
            out = np.full((len(p), 3), np.nan)
            iters = np.zeros(len(p))
            for k, target in enumerate(p):
                q = robot.q0.copy()
                i = 0
                while True:
                    pin.framesForwardKinematics(model, data, q)
                    err = data.oMf[fid].translation - target
                    if np.linalg.norm(err) < CLIK_EPS or i >= CLIK_IT_MAX:
                        break
                    J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)[:3, :]
                    v = -J.T.dot(np.linalg.solve(J.dot(J.T) + damp_eye, err))
                    q = pin.integrate(model, q, v * dt)
                    i += 1
                out[k] = q[iq : iq + 3]
                iters[k] = i
            return out, iters

        return run

    methods = [
        Method(f"legkin batch closed form (foot_ik, {n_batch} at once)", targets, batch_ik, joints_score, repeats=7),
        Method("legkin batch FK (foot_position), the floor", q_gen, lambda q: aq.foot_position(q, LEG), fk_score,
               repeats=7),
        Method("legkin scalar closed form, Python loop", targets, scalar_ik, joints_score, max_targets=n_scalar,
               repeats=3),
        Method("pinocchio CLIK (example settings, DT=0.1)", targets, clik(CLIK_DT), joints_score,
               max_targets=n_iter, repeats=3),
        Method("pinocchio CLIK, full Gauss-Newton step (DT=1)", targets, clik(1.0), joints_score,
               max_targets=n_iter, repeats=3),
    ]

    # ---------------------------------------------------------------- ikpy
    reason = missing("ikpy")
    if reason:
        methods.append(Method("ikpy (scipy least_squares)", skip=reason))
    else:
        import ikpy.chain

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            chain = ikpy.chain.Chain.from_urdf_file(str(robot.urdf_path), base_elements=["base", f"{LEG}_HAA"])
        mask = [link.joint_type != "fixed" for link in chain.links]
        chain = ikpy.chain.Chain.from_urdf_file(
            str(robot.urdf_path), base_elements=["base", f"{LEG}_HAA"], active_links_mask=mask
        )
        active = np.flatnonzero(mask)
        init = np.zeros(len(chain.links))
        init[active] = q0_leg

        def ikpy_run(p):
            out = np.empty((len(p), 3))
            for k, target in enumerate(p):
                out[k] = chain.inverse_kinematics(target, initial_position=init)[active]
            return out

        methods.append(Method("ikpy (scipy least_squares)", targets, ikpy_run, joints_score, max_targets=n_iter,
                              repeats=3))

    # ---------------------------------------------------------------- TRAC-IK
    reason = missing("pytracik", "trac_ik")
    if reason:
        methods.append(Method("TRAC-IK (pytracik)", skip=reason))
    else:
        from trac_ik import TracIK

        with quiet_stdout():  # KDL prints a warning about the root link's inertia
            tracik = TracIK("base", f"{LEG}_FOOT", str(robot.urdf_path), epsilon=TRACIK_EPS)
        pose = np.concatenate([targets, target_rot.reshape(len(targets), 9)], axis=1)

        def tracik_run(pr):
            out = np.full((len(pr), 3), np.nan)
            for k, row in enumerate(pr):
                q = tracik.ik(row[:3], row[3:].reshape(3, 3), seed_jnt_values=q0_leg)
                if q is not None:
                    out[k] = q
            return out

        methods.append(Method("TRAC-IK (pytracik, full pose)", pose, tracik_run,
                              lambda pr, out: joints_score(pr[:, :3], out), max_targets=n_iter, repeats=3))

    notes = [
        f"targets: Pinocchio FK of {LEG}_FOOT for {n_batch} joint vectors of leg {LEG} uniform in its limits "
        f"(the other legs at q0); slow methods solve the first {n_scalar} (scalar loop) or {n_iter} (iterative) "
        "of the same targets",
        "errors: Pinocchio FK of the returned joints vs the target; FK/solve = mean forward-kinematics "
        "evaluations per target; reached = error <= "
        f"{SOLVE_TOL:g} m; solved = reached with the joints inside the limits (angles mod 2 pi)",
        f"pinocchio CLIK: Pinocchio's examples/inverse-kinematics.py on the foot position: framesForwardKinematics, "
        f"computeFrameJacobian (LOCAL_WORLD_ALIGNED), v = -J^T (J J^T + {CLIK_DAMP:g} I)^-1 e, integrate(q, v DT), "
        f"stop at |e| < {CLIK_EPS:g} m or {CLIK_IT_MAX} iterations, start q0; joint limits are not enforced",
        "ikpy: Chain.from_urdf_file(base..LF_FOOT) with its active joints, inverse_kinematics(target, "
        "initial_position=q0) with the defaults (bounded scipy least_squares; its `tol` sets ftol/xtol and "
        "does not change the result, scipy's gtol=1e-8 stops it first)",
        f"TRAC-IK: TracIK(base, LF_FOOT, epsilon={TRACIK_EPS:g}), default timeout 5 ms and solve type Speed, seed q0; "
        "pytracik exposes no per-axis tolerance bounds, so it is given the full target pose (position and the "
        "foot orientation of the generating joints): an easier, fully determined problem; it runs KDL and an "
        "SQP solver in two threads",
    ]

    def summary(results: list[MethodResult]) -> list[str]:
        by = {r.name: r for r in results}
        batch = next(r for r in results if "batch closed form" in r.name)
        fk = next(r for r in results if "batch FK" in r.name)
        lines = [
            f"batch closed form: {1.0 / batch.time_per_target_s / 1e6:.2f} M targets/s on one core; "
            f"IK/FK = {batch.time_per_target_s / fk.time_per_target_s:.1f} (target <= 3)"
        ]
        for r in by.values():
            if r is batch or r is fk:
                continue
            speedup = r.time_per_target_s / batch.time_per_target_s
            lines.append(f"batch closed form is {speedup:,.0f}x faster than {r.name}")
        return lines

    return ModelBench(
        methods=methods,
        units={"ik": "m"},
        tolerance=f"position error <= {SOLVE_TOL:g} m and joints inside the limits",
        notes=notes,
        summary=summary,
    )
