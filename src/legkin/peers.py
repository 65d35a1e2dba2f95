"""Peer IK libraries on the quadruped leg, beside the quadruped bench's Pinocchio CLIK, ikpy and TRAC-IK rows.

:func:`add_quadruped_peers` appends one :class:`legkin.bench.Method` per peer to the quadruped's
:class:`legkin.bench.ModelBench`: roboticstoolbox-python ``ik_LM``, mink, pin-pink and pytorch-kinematics.
Each gets the same position-only targets (Pinocchio FK of ``LF_FOOT``) and the same scoring as the Pinocchio
CLIK rows (it reuses that row's inputs and score function: the foot position Pinocchio gives at the returned
leg joints vs the target; solved = within ``SOLVE_TOL`` and inside the joint limits), solves the same prefix
of targets, and starts from the same ``q0``. A peer that is not installed, or cannot be set up, is a skipped
row with the reason.
"""

from __future__ import annotations

import warnings
from typing import Any, Callable

import numpy as np

from ._benchkit import missing

__all__ = ["add_quadruped_peers", "PEER_TOL", "PEER_MAX_ITER"]

LEG = "LF"
#: Position tolerance (m) every peer is asked for: the quadruped CLIK's.
PEER_TOL = 1e-10
#: Iteration cap of the differential-IK loops (mink, pink) and of pytorch-kinematics.
PEER_MAX_ITER = 200
#: The damping given to mink and pink (their QP's Levenberg-Marquardt term), as CLIK's.
PEER_DAMPING = 1e-12
#: mink's and pink's integration step (s): a full step of the QP's velocity.
PEER_DT = 1.0


def _reference(bench):
    """The Pinocchio CLIK row of the quadruped bench: its targets, score function and target count."""
    return next(m for m in bench.methods if m.name.startswith("pinocchio CLIK") and m.skip is None)


def _robot():
    from .robot import load

    robot = load("quadruped")
    iq = robot.idx_q(f"{LEG}_HAA")
    return robot, iq


# ------------------------------------------------------------------------------------------- roboticstoolbox
def _rtb():
    import roboticstoolbox as rtb

    robot, iq = _robot()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # roboticstoolbox warns that Robot.URDF is superseded by URDF_read + Robot
        rob = rtb.Robot.URDF(str(robot.urdf_path))
    ets = rob.ets(start="base", end=f"{LEG}_FOOT")
    q0 = robot.q0[iq : iq + 3].copy()
    # ik_LM's tol bounds E = 1/2 e^T We e: 1/2 PEER_TOL^2 is |e| <= PEER_TOL on the masked (position) rows
    tol = 0.5 * PEER_TOL**2
    mask = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    tep = np.eye(4)

    def run(p):
        out = np.full((len(p), 3), np.nan)
        iters = np.zeros(len(p))
        for k, target in enumerate(p):
            tep[:3, 3] = target
            sol = ets.ik_LM(tep, q0=q0, mask=mask, tol=tol, joint_limits=True)
            out[k] = sol.q
            iters[k] = sol.iterations
        return out, iters

    note = (f"roboticstoolbox ik_LM: Robot.URDF, ets(base..{LEG}_FOOT).ik_LM(T, q0, mask=[1,1,1,0,0,0], "
            f"tol={tol:g} (on 1/2 |e|^2, i.e. |e| <= {PEER_TOL:g} m), joint_limits=True), defaults otherwise "
            "(ilimit 30 iterations per search, up to slimit 100 searches from random joints inside the limits, "
            "Chan's damping); the answer is kept whatever `success` says; iters = total over the searches")
    return run, note


# ------------------------------------------------------------------------------------------- mink
def _differential_peer(setup: str, limits: str, iq: int, start: Callable[[], Any], task: Any,
                       pose: Callable[[np.ndarray], Any], foot: Callable[[Any], np.ndarray],
                       velocity: Callable[[Any], np.ndarray]) -> tuple[Callable[[np.ndarray], Any], str]:
    """mink's and pink's method: per target, ``conf = start()``, ``task.set_target(pose(target))``, then
    ``conf.integrate_inplace(velocity(conf), PEER_DT)`` until ``|foot(conf) - target| < PEER_TOL`` (m) or
    PEER_MAX_ITER steps.

    Args:
        setup: the note's first part (the peer, its model and task).
        limits: the limits its ``solve_ik`` takes, for the note.
        iq: the leg's first joint in the configuration ``conf.q``.
        start: the configuration at the start of one target's solve (q0).
        task: the peer's foot task.
        pose: the task's target pose (an SE3 of the peer's) of a foot target (m).
        foot: the foot position (3,) of a configuration (m).
        velocity: the joint velocity (rad/s) the peer's QP asks of a configuration.

    Returns:
        ``(run, note)``: ``run(p)`` of (n, 3) foot targets (m) returns ``(q (n, 3) the leg's joints (rad),
        iterations (n,))``.
    """
    def run(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out = np.full((len(p), 3), np.nan)
        iters = np.zeros(len(p))
        for k, target in enumerate(p):
            conf = start()
            task.set_target(pose(target))
            i = 0
            while True:
                err = foot(conf) - target
                if np.linalg.norm(err) < PEER_TOL or i >= PEER_MAX_ITER:
                    break
                conf.integrate_inplace(velocity(conf), PEER_DT)
                i += 1
            out[k] = conf.q[iq : iq + 3]
            iters[k] = i
        return out, iters

    note = (f"{setup}, loop solve_ik(daqp, damping {PEER_DAMPING:g}, {limits}) + integrate_inplace with dt = "
            f"{PEER_DT:g} (a full step), until |e| < {PEER_TOL:g} m or {PEER_MAX_ITER} iterations")
    return run, note


def _mink():
    import mink
    import mujoco

    robot, iq = _robot()
    xml = robot.urdf_path.read_text()
    head = '<robot name="quadruped">'
    if head not in xml:
        raise RuntimeError("unexpected URDF header")
    # keep the fixed-joint foot links as bodies (MuJoCo fuses them into the shank by default)
    xml = xml.replace(head, head + '<mujoco><compiler fusestatic="false" discardvisual="true"/></mujoco>', 1)
    model = mujoco.MjModel.from_xml_string(xml)
    names = [model.joint(i).name for i in range(model.njnt)]
    if names != list(robot.model.names[1:]):
        raise RuntimeError(f"MuJoCo joint order {names} differs from Pinocchio's")
    q0 = robot.q0.copy()
    conf = mink.Configuration(model, q0)
    task = mink.FrameTask(f"{LEG}_FOOT", "body", position_cost=1.0, orientation_cost=0.0)
    limits = [mink.ConfigurationLimit(model)]

    def start():
        conf.update(q0)
        return conf

    return _differential_peer(
        f"mink: the URDF in MuJoCo (fusestatic off), from q0, FrameTask({LEG}_FOOT, position_cost 1, "
        "orientation_cost 0)", "ConfigurationLimit", iq, start, task, mink.SE3.from_translation,
        lambda c: c.get_transform_frame_to_world(f"{LEG}_FOOT", "body").translation(),
        lambda c: mink.solve_ik(c, [task], PEER_DT, "daqp", damping=PEER_DAMPING, limits=limits))


# ------------------------------------------------------------------------------------------- pink
def _pink():
    import pink
    import pinocchio as pin
    from pink.tasks import FrameTask

    robot, iq = _robot()
    model = robot.model
    data = model.createData()
    q0 = robot.q0.copy()
    task = FrameTask(f"{LEG}_FOOT", position_cost=1.0, orientation_cost=0.0)
    eye = np.eye(3)
    return _differential_peer(
        f"pink: Configuration(model, data, q0), FrameTask({LEG}_FOOT, position_cost 1, orientation_cost 0)",
        "its default configuration and velocity limits", iq, lambda: pink.Configuration(model, data, q0), task,
        lambda t: pin.SE3(eye, t), lambda c: c.get_transform_frame_to_world(f"{LEG}_FOOT").translation,
        lambda c: pink.solve_ik(c, [task], PEER_DT, solver="daqp", damping=PEER_DAMPING, safety_break=False))


# ------------------------------------------------------------------------------------------- pytorch-kinematics
def _pytorch_kinematics():
    import pytorch_kinematics as pk
    import torch

    robot, iq = _robot()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = pk.build_serial_chain_from_urdf(robot.urdf_path.read_bytes(), f"{LEG}_FOOT", "base")
    chain = chain.to(dtype=torch.float64)  # float32 cannot reach 1e-10 m
    lo, hi = chain.get_joint_limits()
    limits = torch.tensor(np.stack([lo, hi], axis=-1), dtype=torch.float64)
    q0 = torch.tensor(robot.q0[iq : iq + 3], dtype=torch.float64)[None]
    ik = pk.PseudoInverseIK(
        chain,
        pos_tolerance=PEER_TOL,
        rot_tolerance=float("inf"),
        retry_configs=q0,
        joint_limits=limits,
        max_iterations=PEER_MAX_ITER,
        orientation_weight=0.0,
        early_stopping_any_converged=True,
    )

    def run(p):
        goal = pk.Transform3d(pos=torch.as_tensor(p, dtype=torch.float64), dtype=torch.float64)
        sol = ik.solve(goal)
        return sol.solutions[:, 0].numpy().copy(), np.full(len(p), float(sol.iterations))

    note = (f"pytorch-kinematics: build_serial_chain_from_urdf(base..{LEG}_FOOT) in float64, PseudoInverseIK("
            f"retry_configs=[q0], pos_tolerance {PEER_TOL:g}, orientation_weight 0, max_iterations "
            f"{PEER_MAX_ITER}, joint_limits, early_stopping_any_converged), defaults otherwise (lr 1, "
            "LM damping 0.1 |e|^2, 2 pi wrapping and clamped refinement into the limits); all targets in one "
            f"batched solve on the CPU ({torch.get_num_threads()} torch threads); iters = the batch's; its URDF "
            "parser builds the joint origins in float32 (pytorch_kinematics.urdf._convert_transform) before the "
            "cast to float64, so its leg model is ~1e-8 m off the URDF: answers that meet its own 1e-10 m land "
            "~1e-8 m from the target by Pinocchio's FK and are not solved")
    return run, note


#: (row name, distribution, module, setup)
PEERS = [
    ("roboticstoolbox ik_LM (position mask)", "roboticstoolbox-python", "roboticstoolbox", _rtb),
    ("mink (MuJoCo, daqp)", "mink", "mink", _mink),
    ("pink (pin-pink, daqp)", "pin-pink", "pink", _pink),
    ("pytorch-kinematics PseudoInverseIK (batch)", "pytorch-kinematics", "pytorch_kinematics", _pytorch_kinematics),
]


def add_quadruped_peers(bench) -> None:
    """Append the peer rows (or their skip reasons) and their notes to the quadruped ``ModelBench``."""
    from ._benchkit import Method

    try:
        ref = _reference(bench)
    except StopIteration:
        return
    for name, dist, module, setup in PEERS:
        reason = missing(dist, module)
        if reason is None and dist == "pytorch-kinematics":
            reason = missing("torch")
        if reason:
            bench.methods.append(Method(name, skip=reason))
            continue
        try:
            run, note = setup()
        except Exception as exc:  # noqa: BLE001 - a peer that cannot be set up is a skipped row
            bench.methods.append(Method(name, skip=f"{dist} could not be set up: {type(exc).__name__}: {exc}"))
            continue
        bench.methods.append(Method(name, ref.inputs, run, ref.score, max_targets=ref.max_targets, repeats=3))
        bench.notes.append(note)
