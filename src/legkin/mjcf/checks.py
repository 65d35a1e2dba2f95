"""The ``legkin check`` rows of the MuJoCo models against Pinocchio (:func:`check_rows`)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
import pinocchio as pin

from .._batch import check_integer, check_number
from ..errors import LoopClosureError
from ._base import _mujoco
from .mechanism import MujocoMechanism, load_mujoco

if TYPE_CHECKING:  # pragma: no cover
    from .._checkkit import CheckResult
    from ..robot import Robot

#: Tolerances of the rows of :func:`check_rows`.
TOL_PLACEMENT = 1e-12
TOL_EQUALITY = 1e-12
TOL_GRAVITY = 1e-4
TOL_CLIP = 1e-3


# ------------------------------------------------------------------------------------------ the checks
def independent_actuated(robot: "Robot", q: np.ndarray | None = None) -> list[str]:
    """The actuated joints that, held, each remove one degree of freedom at ``q`` (default ``q0``).

    All of them for most mechanisms; fewer for a redundantly actuated one (the tripod: three actuators on
    a two-DOF platform), whose remaining actuated joints follow from the loops.
    """
    q = robot.q0 if q is None else q
    held: list[str] = []
    dof = robot.mobility(q)
    for name in robot.actuated_joints:
        m = robot.mobility(q, locked=held + [name])
        if m < dof:
            held.append(name)
            dof = m
    return held


def closed_configurations(robot: "Robot", n: int, rng: np.random.Generator) -> list[np.ndarray]:
    """``q0`` and ``n`` closed configurations from random actuated values in their limits.

    The independent actuated joints (:func:`independent_actuated`) are drawn uniformly in their limits
    (within pi of ``q0``) and held while :meth:`legkin.Robot.solve_loops` closes the loops from ``q0``; a
    draw that does not close is pulled towards ``q0`` (halfway, a quarter, ...) and solved again. A model
    without loops gets every 1-DOF joint drawn in its limits.
    """
    model = robot.model
    out = [robot.q0.copy()]
    names = independent_actuated(robot) if robot.loops else [
        nm for nm in robot.joint_names if model.joints[robot.joint_id(nm)].nq == 1
    ]
    idx = [robot.idx_q(nm) for nm in names]
    lo, hi = model.lowerPositionLimit[idx], model.upperPositionLimit[idx]
    lo, hi = np.maximum(lo, robot.q0[idx] - math.pi), np.minimum(hi, robot.q0[idx] + math.pi)
    attempts = 0
    while len(out) < n + 1:
        attempts += 1
        if attempts > 20 * (n + 1):
            raise LoopClosureError(f"{robot.name}: only {len(out) - 1} of {n} random configurations closed")
        draw = rng.uniform(lo, hi)
        if not robot.loops:
            q = robot.q0.copy()
            q[idx] = draw
            out.append(q)
            continue
        for t in (1.0, 0.5, 0.25, 0.125, 0.0625):
            vals = robot.q0[idx] + t * (draw - robot.q0[idx])
            try:
                out.append(robot.solve_loops(fixed=dict(zip(names, vals)), tol=1e-13, max_iter=100))
                break
            except LoopClosureError:
                continue
    return out


def placement_errors(mech: MujocoMechanism, qs: Sequence[np.ndarray]) -> np.ndarray:
    """Per configuration, the largest distance between a MuJoCo body (site) position after
    ``mj_kinematics`` and its Pinocchio joint (frame) placement, in m."""
    mujoco = _mujoco()
    robot = mech.robot
    data = robot.model.createData()
    bodies = np.array(mech.body_ids[1:])
    fids = [int(f) for f, _ in mech.sites]
    sids = np.array([s for _, s in mech.sites], dtype=int)
    out = np.empty(len(qs))
    for k, q in enumerate(qs):
        mech.data.qpos[:] = mech.qpos(q)
        mujoco.mj_kinematics(mech.model, mech.data)
        pin.framesForwardKinematics(robot.model, data, q)
        pj = np.array([data.oMi[i].translation for i in range(1, robot.model.njoints)])
        pf = np.array([data.oMf[f].translation for f in fids])
        eb = np.linalg.norm(mech.data.xpos[bodies] - pj, axis=1)
        es = np.linalg.norm(mech.data.site_xpos[sids] - pf, axis=1)
        out[k] = max(eb.max(initial=0.0), es.max(initial=0.0))
    return out


def equality_errors(mech: MujocoMechanism, qs: Sequence[np.ndarray]) -> np.ndarray:
    """Per configuration, the largest ``|efc_pos|`` of MuJoCo's equality rows after ``mj_forward``."""
    rows = sum(3 if lp.type == "point" else 6 for lp in mech.robot.loops)
    out = np.empty(len(qs))
    for k, q in enumerate(qs):
        mech.set_configuration(q)
        r = mech.equality_residuals()
        out[k] = np.max(np.abs(r), initial=0.0) if r.size == rows else np.nan  # a row missing: a failure
    return out


def hold_under_gravity(mech: MujocoMechanism, seconds: float = 2.0) -> dict[str, np.ndarray]:
    """Simulate ``seconds`` from ``q0`` with the actuators holding it.

    Returns:
        ``{"loop": (steps, loops) loop residuals (m, rad), "joint": (steps,) largest |q - q0| over the
        actuated joints (rad or m), "time": (steps,)}``; NaN from the first step whose state is not finite
        or that MuJoCo warned about (unstable acceleration).
    """
    mujoco = _mujoco()
    mech.set_configuration(mech.robot.q0)
    steps = int(round(seconds / mech.model.opt.timestep))
    loops = np.full((steps, len(mech.loop_sites)), np.nan)
    joint = np.full(steps, np.nan)
    ref = mech.data.qpos.copy()
    adr = mech.model.jnt_qposadr[mech.model.actuator_trnid[:, 0]]
    warned0 = int(mech.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number)
    for k in range(steps):
        mujoco.mj_step(mech.model, mech.data)
        bad = int(mech.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number) > warned0
        if bad or not np.all(np.isfinite(mech.data.qpos)):
            break
        loops[k] = mech.loop_residuals()
        joint[k] = np.max(np.abs(mech.data.qpos[adr] - ref[adr]), initial=0.0)
    return {"loop": loops, "joint": joint, "time": np.arange(1, steps + 1) * mech.model.opt.timestep}


def passive_joints(robot: "Robot", q: np.ndarray) -> tuple[list[str], list[str]]:
    """The 1-DOF joints that are not actuated: ``(driven by the loops, idle)``.

    Idle joints (their column of the loop Jacobian is zero at ``q``, e.g. a rod's spin about its own axis
    between two spherical joints) are left free by the loops: neither MuJoCo nor Pinocchio fixes them.
    """
    jac = robot.constraint_jacobian(q) if robot.loops else np.zeros((0, robot.model.nv))
    scale = max(float(np.abs(jac).max(initial=0.0)), 1e-300)
    driven: list[str] = []
    idle: list[str] = []
    for name in robot.joint_names:
        j = robot.model.joints[robot.joint_id(name)]
        if j.nv != 1 or name in robot.actuated_joints:
            continue
        col = jac[:, j.idx_v]
        (driven if np.abs(col).max(initial=0.0) > 1e-9 * scale else idle).append(name)
    return driven, idle


def drive_clip(mech: MujocoMechanism, qs: Sequence[np.ndarray], frame_time: float = 0.02) -> dict[str, Any]:
    """Drive the actuators through the clip ``qs`` and compare the passive joints with Pinocchio.

    The simulation starts at rest at ``qs[0]``; the actuator targets go linearly from one frame's actuated
    values to the next in ``frame_time`` seconds. At the end of each frame, Pinocchio's loop solver closes
    the loops from MuJoCo's configuration with the actuated joints held at MuJoCo's values (the angles
    MuJoCo reached, not the commanded ones: the comparison is about the loops, not about tracking; only the
    independent ones, :func:`independent_actuated`, for a redundantly actuated mechanism).

    Returns:
        ``{"passive": (frames-1, passive) |q_mujoco - q_pinocchio| of the loop-driven passive joints,
        "tracking": (frames-1, actuated) |q_mujoco - q_clip| of the actuated joints, "loop": (frames-1, loops)
        loop residuals, "passive_joints": names}``; NaN rows where the state is not finite or a solve failed.
    """
    mujoco = _mujoco()
    robot = mech.robot
    qs = [robot.check_q(q) for q in qs]
    driven, _ = passive_joints(robot, qs[0])
    held = independent_actuated(robot, qs[0])
    pidx = np.array([robot.idx_q(n) for n in driven], dtype=int)
    aidx = np.array(mech.actuator_q, dtype=int)
    steps = max(1, int(round(frame_time / mech.model.opt.timestep)))
    mech.set_configuration(qs[0])
    n = len(qs) - 1
    passive = np.full((n, pidx.size), np.nan)
    tracking = np.full((n, aidx.size), np.nan)
    loops = np.full((n, len(mech.loop_sites)), np.nan)
    for k in range(n):
        c0, c1 = mech.ctrl(qs[k]), mech.ctrl(qs[k + 1])
        for s in range(steps):
            a = (s + 1) / steps
            mech.data.ctrl[:] = (1 - a) * c0 + a * c1
            mujoco.mj_step(mech.model, mech.data)
        if not np.all(np.isfinite(mech.data.qpos)):
            break
        q_mj = mech.q(mech.data.qpos)
        loops[k] = mech.loop_residuals()
        tracking[k] = np.abs(q_mj[aidx] - qs[k + 1][aidx])
        try:
            q_pin = robot.solve_loops(q_mj, fixed=held, tol=1e-13, max_iter=50)
        except LoopClosureError:
            continue
        passive[k] = np.abs(q_mj[pidx] - q_pin[pidx])
    return {"passive": passive, "tracking": tracking, "loop": loops, "passive_joints": driven}


def _clip_frames(robot: "Robot") -> tuple[str | None, list[np.ndarray]]:
    """The first clip of the model (name, configurations), or ``(None, [])``."""
    from ..clips import available, frames
    clips = available(robot.name)
    if not clips:
        return None, []
    name = sorted(clips)[0]
    return name, [np.asarray(q, dtype=float) for q in frames(robot, name)]


def _round_trip_row(robot, qs) -> "CheckResult":
    """legkin's MJCF export read back by Pinocchio's MJCF parser: its loops at ``q0`` and ``qs`` (m/rad)."""
    from .._checkkit import compare
    from ..closing import CLOSED_TOL
    from .roundtrip import mjcf_round_trip_error

    error = mjcf_round_trip_error(robot, qs)
    name = f"MJCF round trip (Pinocchio's parser): {len(robot.loops)} loops at {len(qs)} configurations (m/rad)"
    return compare(name, [error], CLOSED_TOL)


def check_rows(
    name: str,
    samples: int = 10,
    rng: np.random.Generator | None = None,
    *,
    seconds: float = 2.0,
    frame_time: float = 0.02,
    mech: MujocoMechanism | None = None,
) -> list["CheckResult"]:
    """The ``legkin check`` rows of the MuJoCo model of ``name`` against Pinocchio.

    1. at ``q0`` and ``samples`` random closed configurations (:func:`closed_configurations`), MuJoCo's body
       and site positions (``mj_kinematics``) equal Pinocchio's joint and frame placements (1e-12 m);
    2. MuJoCo's equality residuals there (``efc_pos`` after ``mj_forward``) are 0 (1e-12; models with loops);
       and the MJCF round trip: Pinocchio's MJCF parser reads the export back with the same loops, closed at
       those configurations (1e-10 m and rad; :func:`legkin.mjcf.roundtrip.mjcf_round_trip_error`);
    3. 2 s under gravity from ``q0`` with the actuators holding it: a finite state, every loop residual
       under 1e-4 (m, rad); for a model without loops, the state stays finite (its actuated joints' largest
       drift from ``q0`` is the row's error, tolerance 0.05 rad);
    4. driving the actuators along the model's first clip: the loop-driven passive joints equal Pinocchio's
       loop solution at MuJoCo's actuated angles within 1e-3 rad (models with passive joints).

    Args:
        name: a registered model.
        samples: random closed configurations of rows 1-2 (an integer >= 0).
        rng: random generator (default ``numpy.random.default_rng(0)``).
        seconds: simulated time of row 3.
        frame_time: seconds per clip frame in row 4.
        mech: a :class:`MujocoMechanism` to check instead of ``load_mujoco(name)`` (e.g. an edited MJCF).

    Raises:
        LegkinError: MuJoCo is not installed (:func:`unavailable_reason` says so without raising).
        UnknownModelError: ``name`` is not registered.
    """
    from .._checkkit import compare

    _mujoco()
    samples = check_integer(samples, "samples", 0)
    seconds = check_number(seconds, "seconds", 0.0, low_open=True)
    frame_time = check_number(frame_time, "frame_time", 0.0, low_open=True)
    rng = np.random.default_rng(0) if rng is None else rng
    mech = load_mujoco(name) if mech is None else mech
    robot = mech.robot
    qs = closed_configurations(robot, samples, rng)
    rows = [compare(
        f"MuJoCo body/site positions = Pinocchio joint/frame placements (q0 + {samples} closed configurations, m)",
        placement_errors(mech, qs), TOL_PLACEMENT,
    )]
    if robot.loops:
        rows.append(compare(
            f"MuJoCo equality residuals efc_pos at closed configurations ({len(robot.loops)} loops, m/rad)",
            equality_errors(mech, qs), TOL_EQUALITY,
        ))
    if robot.loops:
        rows.append(_round_trip_row(robot, qs))
    hold = hold_under_gravity(mech, seconds)
    if robot.loops:
        rows.append(compare(
            f"MuJoCo {seconds:g} s under gravity, actuators holding q0: loop residuals (m/rad)",
            hold["loop"], TOL_GRAVITY,
        ))
    else:
        rows.append(compare(
            f"MuJoCo {seconds:g} s under gravity, actuators holding q0: finite, joint drift from q0 (rad)",
            hold["joint"], 0.05,
        ))
    driven, _ = passive_joints(robot, robot.q0)
    if driven:
        clip, frames = _clip_frames(robot)
        if clip is not None:
            res = drive_clip(mech, frames, frame_time)
            rows.append(compare(
                f"MuJoCo clip {clip!r} ({len(frames)} frames x {frame_time:g} s): {len(driven)} passive joints = "
                "Pinocchio's loop solution at MuJoCo's actuated angles (rad)",
                res["passive"], TOL_CLIP,
            ))
    return rows
