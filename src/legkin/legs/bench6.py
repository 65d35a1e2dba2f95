"""``legkin bench talos`` (any robot with 6-DOF legs): one leg's IK (:class:`~legkin.legs.Leg6`) vs EAIK and
Pinocchio CLIK.

Targets: Pinocchio's foot frame (4x4, root frame) for the leg's six joints drawn uniformly inside the URDF limits
(the other joints at ``robot.q0``, fixed base). Every answer is scored the same way: Pinocchio's foot at the
returned joints against the target, error = max(|position error| (m), rotation error (rad)); solved = error
<= :data:`legkin._benchkit.SOLVE_TOL` and the joints inside the limits.

Peers: EAIK (``pip install eaik``, the ``bench`` extra): ``HPRobot(H, P)`` from the leg's measured axes and
offsets (its tool frame turned by the foot frame's neutral rotation), ``IK(T)`` returns every solution without
limits; the row times that call alone and scores the non-least-squares solution inside the limits nearest
mid-limit (picked outside the timing). Pinocchio CLIK: damped Newton on the SE(3) log error, six joints, from mid-limit.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .._benchkit import SOLVE_TOL, Method, MethodResult, ModelBench, Score, missing, rotation_error, sizes
from ._benchframe import _LegFrame

__all__ = ["build6", "CLIK_MAX_ITER", "CLIK_DAMPING"]

CLIK_MAX_ITER = 100
CLIK_DAMPING = 1e-12


class _Pose(_LegFrame):
    """The foot pose (4x4); error: max(|position error| (m), rotation error (rad))."""

    shape = (4, 4)

    def _value(self, placement: Any) -> np.ndarray:
        return placement.homogeneous

    def _error(self, got: np.ndarray, targets: np.ndarray) -> np.ndarray:
        pos = np.linalg.norm(got[:, :3, 3] - targets[:, :3, 3], axis=-1)
        return np.maximum(pos, rotation_error(targets[:, :3, :3], got[:, :3, :3]))


def _nearest_inside(rows: np.ndarray, lo: np.ndarray, hi: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """The row of joint solutions ``rows`` (K, 6) (NaN rows ignored), each angle moved to its 2 pi representative
    nearest ``ref``, that lies inside ``[lo, hi]`` nearest ``ref`` (rad); NaN if none does."""
    shifted = rows + 2 * np.pi * np.round((ref - rows) / (2 * np.pi))
    cost = np.where(np.all((shifted >= lo) & (shifted <= hi), axis=-1), np.sum((shifted - ref) ** 2, axis=-1), np.inf)
    k = int(np.argmin(np.nan_to_num(cost, nan=np.inf)))
    return shifted[k] if np.isfinite(cost[k]) else np.full(rows.shape[-1], np.nan)


def _legkin(leg, targets: np.ndarray, pose: _Pose, n_batch: int, n_single: int) -> list[Method]:
    from ..errors import LegkinError

    leg.ik(targets[:2])
    leg.ik(targets[0])
    leg.ik_all(targets[0])

    def single(fn: Callable) -> Callable:
        def run(t):  # timed: the calls alone (a refused target gives None)
            out: list[np.ndarray | None] = []
            for k in range(len(t)):
                try:
                    out.append(fn(t[k]))
                except LegkinError:
                    out.append(None)
            return out
        return run

    def score(t, sols) -> Score:  # untimed: ik's answer, or ik_all's solution inside the limits nearest q_ref
        q = np.full((len(sols), 6), np.nan)
        for k, sol in enumerate(sols):
            if sol is not None:
                q[k] = sol if sol.ndim == 1 else _nearest_inside(sol, leg.lower, leg.upper, leg.q_ref)
        return pose.score(t[:len(sols)], q)

    return [
        Method(f"legkin Leg6.ik batch ({leg.structure}; {n_batch} at once)", targets, leg.ik, pose.score, repeats=3),
        Method("legkin Leg6.ik single calls (Python loop)", targets, single(leg.ik), score,
               max_targets=n_single, repeats=3),
        Method("legkin Leg6.ik_all single calls (every solution; the nearest in-limit one picked untimed)", targets,
               single(leg.ik_all), score, max_targets=n_single, repeats=3),
    ]


def _eaik(leg, targets: np.ndarray, pose: _Pose, n_single: int) -> Method:
    name = "EAIK IK single calls (every solution; the nearest in-limit one picked untimed)"
    why = missing("eaik")
    if why is not None:
        return Method(name, skip=why)
    from eaik.IK_HP import HPRobot

    r0 = leg.foot_pose[:3, :3]
    offsets = np.vstack([leg.origins[0], np.diff(leg.origins, axis=0), leg.foot_pose[:3, 3] - leg.origins[5]])
    robot = HPRobot(np.array(leg.axes), offsets)
    if not robot.hasKnownDecomposition():
        return Method(name, skip=f"EAIK: no known decomposition for {leg.structure} ({robot.getKinematicFamily()})")
    lo, hi, ref = leg.lower, leg.upper, leg.q_ref

    def run(t):  # timed: EAIK's call alone (every solution, as legkin's ik_all)
        out = []
        for k in range(len(t)):
            tk = t[k].copy()
            tk[:3, :3] = tk[:3, :3] @ r0.T  # EAIK's tool frame is the foot frame turned back to the root axes
            out.append(robot.IK(tk))
        return out

    def score(t, sols) -> Score:  # untimed: the non-least-squares solution inside the limits nearest mid-limit
        q = np.full((len(sols), 6), np.nan)
        for k, sol in enumerate(sols):
            exact = [qs for qs, ls in zip(sol.Q, sol.is_LS) if not ls]
            if exact:
                q[k] = _nearest_inside(np.array(exact), lo, hi, ref)
        return pose.score(t[:len(sols)], q)

    return Method(name, targets, run, score, max_targets=n_single, repeats=3)


def _clik(pose: _Pose) -> Callable:
    import pinocchio as pin

    model, data, fid, iq, iv, leg = pose.model, pose.data, pose.fid, pose.iq, pose.iv, pose.leg

    def clik(t):
        q = np.full((len(t), 6), np.nan)
        iters = np.zeros(len(t))
        for k in range(len(t)):
            target = pin.SE3(t[k])
            qk = pose.q_base.copy()
            qk[iq] = leg.q_ref
            for it in range(CLIK_MAX_ITER + 1):
                pin.forwardKinematics(model, data, qk)
                m = pin.updateFramePlacement(model, data, fid)
                e = pin.log6(m.actInv(target)).vector  # LOCAL error
                if np.linalg.norm(e) <= 0.1 * SOLVE_TOL or it == CLIK_MAX_ITER:
                    break
                jac = pin.computeFrameJacobian(model, data, qk, fid, pin.LOCAL)[:, iv]
                dq = jac.T @ np.linalg.solve(jac @ jac.T + CLIK_DAMPING * np.eye(6), e)
                qk[iq] = np.clip(qk[iq] + dq, leg.lower, leg.upper)
            q[k], iters[k] = qk[iq], it
        return q, iters

    return clik


def build6(robot, leg_name: str, n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    """The bench of ``robot``'s 6-DOF leg ``leg_name`` (see the module docstring)."""
    n_batch, n_single, n_iter = sizes(n, quick, full=(5_000, 1_000, 100), small=(500, 100, 10))
    leg = robot.geometry[leg_name]
    pose = _Pose(robot.model, leg, np.array(robot.q0, dtype=float))
    targets = pose(rng.uniform(leg.lower, leg.upper, (n_batch, 6)))
    methods = _legkin(leg, targets, pose, n_batch, n_single)
    methods.append(_eaik(leg, targets, pose, n_single))
    methods.append(Method("pinocchio CLIK (damped Newton on SE(3), 6 leg joints)", targets, _clik(pose),
                          pose.score_iter, max_targets=n_iter, repeats=1))
    notes = [
        f"{robot.name} leg {leg_name} ({', '.join(leg.joint_names)} -> {leg.foot_frame}; {leg.structure}), fixed "
        f"base; {n_batch} targets from joints uniform in the URDF limits; single calls and EAIK solve the first "
        f"{n_single}, CLIK the first {n_iter}",
        "err = max(|position error| m, rotation error rad) of Pinocchio's foot at the answer; solved also needs "
        "the joints inside the URDF limits",
    ]
    return ModelBench(methods=methods, units={"ik": "m|rad"}, tolerance=f"pose error <= {SOLVE_TOL:g} and joints "
                      "inside the URDF limits", notes=notes, summary=_summary)


def _summary(results: list[MethodResult]) -> list[str]:
    single = next(r for r in results if "Leg6.ik single" in r.name)
    lines = []
    for r in results:
        if r is not single:
            lines.append(f"{r.name.split(' (')[0]}: {r.time_per_target_s / single.time_per_target_s:,.2f}x the time "
                         f"of a single Leg6.ik call per target")
    return lines
