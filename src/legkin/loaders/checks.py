"""``legkin check PATH``: the rows that check a robot from a file (:func:`check_rows`).

Samples: motor values reachable by construction (:func:`reachable_motors`): from ``q0``, a random motor step
(uniform in +-0.1 rad for a revolute motor, +-0.01 m for a prismatic one), the passive joints moved by the
minimum-norm velocity solution, then the loops closed again with every joint free; its motors are the
sample. ``closed_fk`` must solve it from ``q0`` (the IK contract's "every target the FK makes is solved").
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .._checkkit import CheckResult, compare
from ..closing import CLOSED_TOL, close_loops, loop_errors
from ..errors import LegkinError, LoopClosureError, UnreachableError
from ..mjcf.roundtrip import mjcf_round_trip_error
from .robot import FileRobot

__all__ = ["check_rows", "reachable_motors", "determined_frames", "jacobian_fd_error",
           "SPREAD"]

#: Motor step of the samples: rad for a revolute motor, m for a prismatic one.
SPREAD = {"revolute": 0.1, "prismatic": 0.01}
#: Central-difference step (rad or m) and the Jacobian row's tolerance (truncation ~h^2, round-off ~eps/h).
FD_STEP, TOL_JACOBIAN = 1e-6, 1e-6


def _spread(robot: FileRobot) -> np.ndarray:
    kinds = [robot.model.joints[robot.joint_id(a)].shortname() for a in robot.actuated]
    return np.array([SPREAD["prismatic"] if "JointModelP" in k else SPREAD["revolute"] for k in kinds])


def reachable_motors(robot: FileRobot, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """``n`` motor vectors reachable from ``robot.q0`` and the closed configurations that make them."""
    iq, iv = robot._motor_index()
    jc = robot.constraint_jacobian(robot.q0)
    passive = np.ones(robot.model.nv, dtype=bool)
    passive[iv] = False
    pp = np.linalg.pinv(jc[:, passive], rcond=1e-10) @ jc[:, iv]
    motors: list[np.ndarray] = []
    qs: list[np.ndarray] = []
    spread = _spread(robot)
    while len(motors) < n:
        dm = rng.uniform(-1.0, 1.0, len(iv)) * spread
        dq = np.zeros(robot.model.nv)
        dq[iv], dq[passive] = dm, -pp @ dm
        try:
            q, _ = close_loops(robot._loopset, pin.integrate(robot.model, robot.q0, dq),
                               np.ones(robot.model.nv, dtype=bool), homotopy=False, diagnose_failure=False)
        except LoopClosureError:
            continue
        motors.append(q[iq])
        qs.append(q)
    return np.array(motors), np.array(qs)


def determined_frames(robot: FileRobot, q: np.ndarray, tol: float = 1e-9) -> list[str]:
    """The frames whose twist the motors determine at ``q``: unmoved by the idle motions (the null space of the
    passive loop Jacobian ``J_p``; a frame on a rod spinning between two ball joints turns with it), in model order.
    """
    _, _, _, passive = robot._compiled()
    jp = robot.constraint_jacobian(q)[:, passive]
    _, s, vt = np.linalg.svd(jp)
    rank = int(np.sum(s > tol * max(s[0], 1e-300))) if s.size else 0
    idle = vt[rank:].T
    out = []
    for f in robot.model.frames:
        jf = robot.frame_jacobian(q, f.name)[:, passive]
        if idle.size == 0 or np.max(np.abs(jf @ idle)) <= tol:
            out.append(f.name)
    return out


def _central(robot: FileRobot, q: np.ndarray, frame: str, h: float) -> np.ndarray:
    """Central differences of ``frame``'s placement through ``closed_fk`` (step ``h`` on each motor), 6 x n."""
    iq, _ = robot._motor_index()
    num = np.zeros((6, len(iq)))
    for i in range(len(iq)):
        e = np.zeros(len(iq))
        e[i] = h
        ma = robot.frame_placement(robot.closed_fk(q[iq] + e, q), frame)
        mb = robot.frame_placement(robot.closed_fk(q[iq] - e, q), frame)
        num[:3, i] = (ma.translation - mb.translation) / (2 * h)
        num[3:, i] = pin.log3(ma.rotation @ mb.rotation.T) / (2 * h)
    return num


def jacobian_fd_error(robot: FileRobot, q: np.ndarray, frame: str) -> float:
    """Largest entry of ``closed_jacobian(q, frame)`` minus central differences of ``closed_fk`` (m, rad), the
    differences Richardson-extrapolated, ``(4 D(h) - D(2h)) / 3`` (truncation O(h^4)): near a singularity the
    passive joints move ~1/sigma_min per motor radian, and a plain central difference's O(h^2) truncation grows
    with its cube (measured, robot_delta: 7 of 100 reachable samples off by 1.3e-6 to 2.6e-3 at h = 1e-6)."""
    num = (4.0 * _central(robot, q, frame, FD_STEP) - _central(robot, q, frame, 2 * FD_STEP)) / 3.0
    return float(np.max(np.abs(robot.closed_jacobian(q, frame) - num)))


def _fk_rows(robot: FileRobot, motors: np.ndarray) -> list[CheckResult]:
    iq, _ = robot._motor_index()
    held: list[float] = []
    closed: list[float] = []
    unsolved = 0
    for m in motors:
        try:
            q = robot.closed_fk(m)
        except LoopClosureError:
            unsolved += 1
            continue
        held.append(float(np.max(np.abs(q[iq] - m))))
        closed.append(max(e.worst for e in loop_errors(robot.model, robot.data, robot.loops, q)))
    n = len(motors)
    return [compare("closed_fk motors held (rad, m)", held, 1e-12),
            compare("closed_fk loops closed (frames, m, rad)", closed, CLOSED_TOL),
            CheckResult("closed_fk unsolved fraction", n, unsolved / n, unsolved / n, 0.01, unsolved / n <= 0.01)]


def _ik_row(robot: FileRobot, qs: np.ndarray, frame: str) -> CheckResult:
    errs: list[float] = []
    for q in qs:
        target = robot.frame_placement(q, frame)
        try:
            qi = robot.closed_ik(frame, target)
        except UnreachableError:
            errs.append(np.nan)
            continue
        errs.append(float(np.linalg.norm(pin.log6(target.actInv(robot.frame_placement(qi, frame))).vector)))
    return compare(f"closed_ik {frame} round trip (m, rad)", errs, CLOSED_TOL)


def check_rows(robot: FileRobot, samples: int, rng: np.random.Generator, frame: str | None = None) -> list[CheckResult]:
    """The rows of ``legkin check PATH``: ``q0`` closed, ``closed_fk`` (motors held, loops, unsolved
    fraction), ``closed_jacobian`` vs central differences, ``closed_ik`` round trip, MJCF round trip.

    Args:
        robot: a robot from a file.
        samples: motor samples of the ``closed_fk`` rows (a tenth of them, at least 3, for the Jacobian and IK).
        rng: the random generator.
        frame: the frame of the Jacobian and IK rows (default: the model's last frame that the motors determine,
            :func:`determined_frames`).
    """

    if isinstance(robot.closing, LegkinError):
        return [CheckResult(f"q0 closed from neutral: {robot.closing}", 0, np.nan, np.nan, CLOSED_TOL, False)]
    frame = frame or determined_frames(robot, robot.q0)[-1]
    rows = [compare("q0 loops closed (frames, m, rad)",
                    [e.worst for e in loop_errors(robot.model, robot.data, robot.loops, robot.q0)], CLOSED_TOL)]
    motors, qs = reachable_motors(robot, samples, rng)
    rows += _fk_rows(robot, motors)
    few = qs[: max(3, samples // 10)]
    rows.append(compare(f"closed_jacobian {frame} vs central differences",
                        [jacobian_fd_error(robot, q, frame) for q in few], TOL_JACOBIAN))
    rows.append(_ik_row(robot, few, frame))
    rows.append(compare("MJCF round trip: loops at q0 (m, rad)", [mjcf_round_trip_error(robot)], CLOSED_TOL))
    return rows
