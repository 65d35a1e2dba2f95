"""Quadruped foot IK: legkin's closed form (batch and scalar) vs Pinocchio CLIK, ikpy and TRAC-IK.

Targets: Pinocchio's forward kinematics of the ``LF_FOOT`` frame for joint vectors of leg LF drawn uniformly
inside its joint limits (other legs at ``q0``), so every target is reachable inside the limits. Every
method's answer is scored the same way: Pinocchio's foot position at the returned joints (taken mod 2 pi
into the limits) against the target; solved = error <= SOLVE_TOL and joints inside the limits.

The floor of the batch closed form is its transcendental calls alone (:func:`transcendental_floor`: per
target the 2 sqrt, 1 acos and 2 atan2 calls one branch of an HAA-HFE-KFE leg's closed form needs, in the same
compiled ``prange`` loop shape; ``ik`` is :meth:`legkin.legs.Leg.ik`, which computes four branches), not ``fk``
(which needs no inverse trig). :func:`single_calls` gives the single-call table (one entry per public function
of :mod:`legkin.quadruped`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .._benchkit import (
    SOLVE_TOL,
    Method,
    MethodResult,
    ModelBench,
    Score,
    missing,
    pinocchio_positions,
    quiet_stdout,
    sizes,
)
from .._single_call import SingleCall
from ..errors import UnreachableError
from ..robot import load
from . import kinematics as aq
from .configuration import leg_slice, pinocchio_configuration, sample_joints

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


#: The single-call inputs: leg LF at the SRDF ``standing`` pose (q0), its foot as the IK target.
SINGLE_Q = np.array([0.0, 0.75, 1.5])


def single_calls() -> list[SingleCall]:
    """One single call per public function of :mod:`legkin.quadruped`, inputs bound (leg LF, q0).

    Yardsticks: Pinocchio ``forwardKinematics`` + ``updateFramePlacement`` on the 12-DOF quadruped
    (``quadruped_fk``; issue 16's yardstick for ``fk``, ``jacobian`` and ``ik`` alike).
    """
    q = SINGLE_Q.copy()
    p = aq.fk(q, LEG)
    q_near = q + 0.01
    pf = aq.textbook_frame(p, LEG)
    a, b, c = aq.Y12, math.hypot(aq.X23, aq.Z23), aq.X34
    theta = aq.textbook_ik(pf, a, b, c)
    batch = np.stack([p] * 8)
    geometry = aq.Geometry(foot_z=-0.015)
    fk, jac, ik, ik_all, wl = aq.fk, aq.jacobian, aq.ik, aq.ik_all, aq.within_limits
    hp, tf, ti, tj = aq.hip_position, aq.textbook_frame, aq.textbook_ik, aq.textbook_to_joints
    legs = aq.legs
    return [
        SingleCall("fk", lambda: fk(q, LEG), "quadruped_fk"),
        SingleCall("fk (geometry)", lambda: fk(q, LEG, geometry=geometry), "quadruped_fk"),
        SingleCall("jacobian", lambda: jac(q, LEG), "quadruped_fk"),
        SingleCall("ik", lambda: ik(p, LEG), "quadruped_fk"),
        SingleCall("ik (q_near)", lambda: ik(p, LEG, q_near=q_near), "quadruped_fk"),
        SingleCall("ik, batch of 8", lambda: ik(batch, LEG), "quadruped_fk"),
        SingleCall("ik_all", lambda: ik_all(p, LEG), "quadruped_fk"),
        SingleCall("within_limits", lambda: wl(q), "quadruped_fk"),
        SingleCall("legs", lambda: legs(), "quadruped_fk"),
        SingleCall("hip_position", lambda: hp(LEG), "quadruped_fk"),
        SingleCall("textbook_frame", lambda: tf(p, LEG), "quadruped_fk"),
        SingleCall("textbook_ik", lambda: ti(pf, a, b, c), "quadruped_fk"),
        SingleCall("textbook_to_joints", lambda: tj(theta, LEG), "quadruped_fk"),
    ]


_FLOOR = None


def transcendental_floor() -> Callable[[np.ndarray, np.ndarray], None]:
    """The compiled floor loop ``floor(p, out)``: per target row of ``p`` (n, 3), the transcendental calls of
    one branch of the leg's closed form alone (2 sqrt, 1 acos, 2 atan2, on the target's coordinates), written to ``out``
    (n, 3); a ``prange`` loop like the batch kernels (numba's thread count), compiled on first use."""
    global _FLOOR
    if _FLOOR is None:
        import numba

        @numba.njit(cache=True, error_model="numpy", parallel=True)
        def floor(p, out):
            for i in numba.prange(p.shape[0]):
                x, y, z = p[i, 0], p[i, 1], p[i, 2]
                out[i, 0] = np.arctan2(x, y) + np.sqrt(abs(x))
                out[i, 1] = np.arctan2(y, z) + np.sqrt(abs(y))
                out[i, 2] = np.arccos(min(max(z, -1.0), 1.0))

        _FLOOR = floor
    return _FLOOR


@dataclass
class _Setup:
    """What every method of the bench shares: the model, leg LF's frame and columns, the targets, the score."""

    robot: Any
    fid: int
    cols: slice
    q0_leg: np.ndarray
    targets: np.ndarray
    target_rot: np.ndarray

    def joints_score(self, p: np.ndarray, out: Any) -> Score:
        """Pinocchio's foot at the returned joints (mod 2 pi into the limits) vs the target."""
        qs, iters = out if isinstance(out, tuple) else (out, None)
        qs = np.asarray(qs, dtype=float)
        inside = np.all(np.isfinite(qs), axis=-1)
        qw = np.where(inside[:, None], _into_limits(np.nan_to_num(qs)), np.nan)
        inside &= aq.within_limits(np.nan_to_num(qw, nan=1e9))
        robot = self.robot
        pos, _ = pinocchio_positions(robot.model, robot.data, self.fid, pinocchio_configuration(robot, {LEG: qs}))
        err = np.linalg.norm(pos - p, axis=-1)
        fk = None if iters is None else iters + 1
        reached = err <= SOLVE_TOL
        return Score(error=err, solved=reached & inside, iterations=iters, fk_evals=fk, reached=reached)


def _legkin_methods(s: _Setup, q_gen: np.ndarray, n_batch: int, n_scalar: int) -> list[Method]:
    """legkin's batch (numba's threads and 1 thread), batch FK, the floor and the scalar loop."""
    targets = s.targets

    def fk_score(q: np.ndarray, pos: np.ndarray) -> Score:
        err = np.linalg.norm(pos - targets[: len(q)], axis=-1)
        return Score(error=err, solved=err <= SOLVE_TOL)

    floor_loop = transcendental_floor()

    def floor_run(p: np.ndarray) -> np.ndarray:
        out = np.empty_like(p)
        floor_loop(p, out)
        return out

    def floor_score(p: np.ndarray, out: Any) -> Score:  # no answer to score: time only
        return Score(error=np.full(len(p), np.nan), solved=np.zeros(len(p), dtype=bool))

    def batch_ik(p: np.ndarray) -> np.ndarray:
        return aq.ik(p, LEG)

    def batch_ik_one_thread(p: np.ndarray) -> np.ndarray:  # the same call on one numba thread (restored after)
        import numba

        before = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            return aq.ik(p, LEG)
        finally:
            numba.set_num_threads(before)

    def scalar_ik(p: np.ndarray) -> np.ndarray:
        out = np.full((len(p), 3), np.nan)
        for i, pi in enumerate(p):
            try:
                out[i] = aq.ik(pi, LEG)
            except UnreachableError:
                pass
        return out

    score = s.joints_score
    return [
        Method(f"legkin batch closed form (ik, {n_batch} at once)", targets, batch_ik, score, repeats=7),
        Method("legkin batch closed form, 1 thread (numba.set_num_threads(1))", targets, batch_ik_one_thread,
               score, repeats=7),
        Method("legkin batch FK (fk)", q_gen, lambda q: aq.fk(q, LEG), fk_score, repeats=7),
        Method("floor: ik's transcendental calls alone (2 sqrt, acos, 2 atan2)", targets, floor_run,
               floor_score, group="floor", repeats=7),
        Method("legkin scalar closed form, Python loop", targets, scalar_ik, score, max_targets=n_scalar,
               repeats=3),
    ]


def _clik_methods(s: _Setup, n_iter: int) -> list[Method]:
    """Pinocchio's examples/inverse-kinematics.py on the foot position, DT = 0.1 and DT = 1."""
    import pinocchio as pin

    robot = s.robot
    model, data, fid, cols = robot.model, robot.data, s.fid, s.cols
    damp_eye = CLIK_DAMP * np.eye(3)

    def clik(dt: float) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
        def run(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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
                out[k] = q[cols]
                iters[k] = i
            return out, iters

        return run

    return [
        Method("pinocchio CLIK (example settings, DT=0.1)", s.targets, clik(CLIK_DT), s.joints_score,
               max_targets=n_iter, repeats=3),
        Method("pinocchio CLIK, full Gauss-Newton step (DT=1)", s.targets, clik(1.0), s.joints_score,
               max_targets=n_iter, repeats=3),
    ]


def _ikpy_method(s: _Setup, n_iter: int) -> Method:
    reason = missing("ikpy")
    if reason:
        return Method("ikpy (scipy least_squares)", skip=reason)
    import ikpy.chain

    urdf = str(s.robot.urdf_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = ikpy.chain.Chain.from_urdf_file(urdf, base_elements=["base", f"{LEG}_HAA"])
    mask = [link.joint_type != "fixed" for link in chain.links]
    chain = ikpy.chain.Chain.from_urdf_file(urdf, base_elements=["base", f"{LEG}_HAA"], active_links_mask=mask)
    active = np.flatnonzero(mask)
    init = np.zeros(len(chain.links))
    init[active] = s.q0_leg

    def ikpy_run(p: np.ndarray) -> np.ndarray:
        out = np.empty((len(p), 3))
        for k, target in enumerate(p):
            out[k] = chain.inverse_kinematics(target, initial_position=init)[active]
        return out

    return Method("ikpy (scipy least_squares)", s.targets, ikpy_run, s.joints_score, max_targets=n_iter, repeats=3)


def _tracik_method(s: _Setup, n_iter: int) -> Method:
    reason = missing("pytracik", "trac_ik")
    if reason:
        return Method("TRAC-IK (pytracik)", skip=reason)
    from trac_ik import TracIK

    with quiet_stdout():  # KDL prints a warning about the root link's inertia
        tracik = TracIK("base", f"{LEG}_FOOT", str(s.robot.urdf_path), epsilon=TRACIK_EPS)
    pose = np.concatenate([s.targets, s.target_rot.reshape(len(s.targets), 9)], axis=1)

    def tracik_run(pr: np.ndarray) -> np.ndarray:
        out = np.full((len(pr), 3), np.nan)
        for k, row in enumerate(pr):
            q = tracik.ik(row[:3], row[3:].reshape(3, 3), seed_jnt_values=s.q0_leg)
            if q is not None:
                out[k] = q
        return out

    return Method("TRAC-IK (pytracik, full pose)", pose, tracik_run,
                  lambda pr, out: s.joints_score(pr[:, :3], out), max_targets=n_iter, repeats=3)


def _notes(n_batch: int, n_scalar: int, n_iter: int) -> list[str]:
    return [
        f"targets: Pinocchio FK of {LEG}_FOOT for {n_batch} joint vectors of leg {LEG} uniform in its limits "
        f"(the other legs at q0); slow methods solve the first {n_scalar} (scalar loop) or {n_iter} (iterative) "
        "of the same targets",
        "floor: a compiled prange loop making, per target, the transcendental calls of one closed-form branch "
        "(2 sqrt, 1 acos, 2 atan2) and nothing else; no answer to score (time only); threads: "
        "numba's setting (numba.set_num_threads / NUMBA_NUM_THREADS), the same for the batch rows",
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


def _summary(results: list[MethodResult]) -> list[str]:
    import numba

    by = {r.name: r for r in results}
    batch = next(r for r in results if "batch closed form" in r.name)
    fk = next(r for r in results if "batch FK" in r.name)
    floor = next(r for r in results if r.group == "floor")
    one = next(r for r in results if "1 thread" in r.name)
    lines = [
        f"batch closed form: {1.0 / batch.time_per_target_s / 1e6:.2f} M targets/s on "
        f"{numba.get_num_threads()} thread(s); IK/floor = {batch.time_per_target_s / floor.time_per_target_s:.1f}"
        f" (floor = its transcendental calls alone); IK/FK = {batch.time_per_target_s / fk.time_per_target_s:.1f}; "
        f"{numba.get_num_threads()} threads vs 1: {one.time_per_target_s / batch.time_per_target_s:.2f}x faster"
    ]
    for r in by.values():
        if r is batch or r is fk or r is floor or r is one:
            continue
        speedup = r.time_per_target_s / batch.time_per_target_s
        lines.append(f"batch closed form is {speedup:,.0f}x faster than {r.name}")
    return lines


def build(n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    """The quadruped's bench rows (see the module docstring): ``n`` batch targets (None: the default sizes)."""
    n_batch, n_scalar, n_iter = _sizes(n, quick)
    robot = load("quadruped")
    fid = robot.frame_id(f"{LEG}_FOOT")
    cols = leg_slice(robot, LEG)
    q_gen = sample_joints(rng, n_batch)
    full = pinocchio_configuration(robot, {LEG: q_gen})
    targets, target_rot = pinocchio_positions(robot.model, robot.data, fid, full)
    s = _Setup(robot, fid, cols, robot.q0[cols].copy(), targets, target_rot)
    methods = [
        *_legkin_methods(s, q_gen, n_batch, n_scalar),
        *_clik_methods(s, n_iter),
        _ikpy_method(s, n_iter),
        _tracik_method(s, n_iter),
    ]
    return ModelBench(
        methods=methods,
        units={"ik": "m", "floor": "- (time only)"},
        tolerance=f"position error <= {SOLVE_TOL:g} m and joints inside the limits",
        notes=_notes(n_batch, n_scalar, n_iter),
        summary=_summary,
    )
