"""``legkin bench ROBOT`` for an external quadruped: one leg's closed-form IK vs Pinocchio CLIK and peers.

:func:`build` (found by :mod:`legkin.bench` for every robot of :data:`legkin.legs.ERD_ROBOTS`) benches the leg
:data:`LEG` (else the robot's first leg) of ``legkin.load(name)`` (fixed base: world = root frame).

Targets: Pinocchio's foot frame for the leg's three joints drawn uniformly inside the URDF limits (the other
joints at the standing pose ``robot.q0``), so every target is reachable inside the limits. Every method's
answer is scored the same way: Pinocchio's foot at the returned joints against the target; solved = error
<= :data:`legkin._benchkit.SOLVE_TOL` and the joints inside the limits; reached = the error alone. Peers
(ikpy, roboticstoolbox ``ik_LM``) are optional: a row says why it is skipped when one is not installed or
cannot be set up. They read the robot's URDF without its visual/collision/gazebo elements (their loaders try
to resolve the ``package://`` meshes), with the chain from the URDF's root link to the foot link.
"""

from __future__ import annotations

import os
import tempfile
import warnings
import xml.etree.ElementTree as ET
from typing import Any, Callable

import numpy as np

from .._benchkit import SOLVE_TOL, Method, MethodResult, ModelBench, missing, sizes
from ._benchframe import _LegFrame

__all__ = ["build", "LEG", "CLIK_MAX_ITER", "CLIK_DAMPING", "PEER_TOL", "stripped_urdf", "urdf_chain"]

#: The benched leg when the robot has one of this name (else its first leg).
LEG = "FL"
#: Pinocchio CLIK: iteration cap, damping (m^2) of the damped Newton steps and stopping error (m).
CLIK_MAX_ITER = 100
CLIK_DAMPING = 1e-12
#: The stopping error (m) given to the iterative methods: a tenth of the solved tolerance.
PEER_TOL = 0.1 * SOLVE_TOL


def _sizes(n: int | None, quick: bool) -> tuple[int, int, int]:
    """(batch targets, single-call targets, iterative-solver targets); CLIK gets 10x the iterative count."""
    return sizes(n, quick, full=(20_000, 5_000, 200), small=(1_000, 200, 10))


def stripped_urdf(urdf) -> str:
    """A temporary copy of ``urdf`` without visual, collision and gazebo elements; returns its path (the caller
    deletes it)."""
    tree = ET.parse(urdf)
    root = tree.getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    for g in root.findall("gazebo"):
        root.remove(g)
    fd, path = tempfile.mkstemp(suffix=".urdf", prefix="legkin_legs_")
    os.close(fd)
    tree.write(path)
    return path


def urdf_chain(urdf, frame: str) -> tuple[str, str, list[str]]:
    """``(root link, end link, [link, joint, link, ..., end link])`` from the URDF's root link to the link
    ``frame`` (or to the child link of the joint ``frame``)."""
    root = ET.parse(urdf).getroot()
    parent: dict[str, tuple[str, str]] = {}  # child link -> (joint, parent link)
    child_of_joint: dict[str, str] = {}
    for j in root.findall("joint"):
        c, p = j.find("child"), j.find("parent")
        if c is None or p is None:
            continue
        parent[str(c.get("link"))] = (str(j.get("name")), str(p.get("link")))
        child_of_joint[str(j.get("name"))] = str(c.get("link"))
    links = {str(link.get("name")) for link in root.findall("link")}
    end = frame if frame in links else child_of_joint.get(frame)
    if end is None:
        raise ValueError(f"no link or joint {frame!r} in {urdf}")
    path = [end]
    while path[-1] in parent:
        joint, up = parent[path[-1]]
        path += [joint, up]
    path.reverse()
    return path[0], end, path


class _Foot(_LegFrame):
    """The foot position (m); error: the distance to the target."""

    shape = (3,)

    def _value(self, placement: Any) -> np.ndarray:
        return placement.translation

    def _error(self, got: np.ndarray, targets: np.ndarray) -> np.ndarray:
        return np.linalg.norm(got - targets, axis=-1)


def _legkin_methods(leg, targets: np.ndarray, foot: _Foot, n_batch: int, n_single: int) -> list[Method]:
    """``Leg.ik`` as one batch and as single calls (compiled / loaded from numba's cache before timing)."""
    from ..errors import LegkinError

    leg.ik(targets[:2])
    leg.ik(targets[0])  # compiled / loaded from numba's cache before timing

    def batch(p):
        return leg.ik(p)

    def single(p):
        out = np.full((len(p), 3), np.nan)
        ik = leg.ik
        for k in range(len(p)):
            try:
                out[k] = ik(p[k])
            except LegkinError:
                pass
        return out

    return [
        Method(f"legkin Leg.ik batch (closed form; {n_batch} at once)", targets, batch, foot.score, repeats=5),
        Method("legkin Leg.ik single calls (Python loop)", targets, single, foot.score, max_targets=n_single,
               repeats=3),
    ]


def _clik(foot: _Foot) -> Callable:
    """Pinocchio CLIK: damped Newton ``dq = J^T (J J^T + lambda I)^-1 e`` on the leg's three joints from
    mid-limit, clipped into the limits; returns ``(joints, iterations)``."""
    import pinocchio as pin

    model, data, fid, iq, iv = foot.model, foot.data, foot.fid, foot.iq, foot.iv
    lower, upper, q_ref, q_base = foot.lower, foot.upper, foot.q_ref, foot.q_base

    def clik(p):
        q = np.full((len(p), 3), np.nan)
        iters = np.zeros(len(p))
        eye = CLIK_DAMPING * np.eye(3)
        for k in range(len(p)):
            qk = q_base.copy()
            qk[iq] = q_ref
            for it in range(CLIK_MAX_ITER + 1):
                pin.forwardKinematics(model, data, qk)
                e = p[k] - pin.updateFramePlacement(model, data, fid).translation
                if np.linalg.norm(e) <= PEER_TOL or it == CLIK_MAX_ITER:
                    break
                jac = pin.computeFrameJacobian(model, data, qk, fid, pin.LOCAL_WORLD_ALIGNED)[:3, iv]
                qk[iq] = np.clip(qk[iq] + jac.T @ np.linalg.solve(jac @ jac.T + eye, e), lower, upper)
            q[k], iters[k] = qk[iq], it
        return q, iters

    return clik


def _notes(name: str, leg_name: str, leg, n_batch: int, n_single: int, n_clik: int, n_iter: int) -> list[str]:
    return [
        f"{name} leg {leg_name} ({', '.join(leg.joint_names)} -> {leg.foot_frame}), fixed base; targets: "
        f"Pinocchio's {leg.foot_frame} for {n_batch} joint vectors uniform in the URDF limits (other joints at q0); "
        f"single calls solve the first {n_single}, CLIK the first {n_clik}, the peers the first {n_iter}",
        "err = |Pinocchio foot at the answer - target| (m); solved also needs the joints inside the URDF limits, "
        "reached does not",
        f"pinocchio CLIK: from mid-limit, damping {CLIK_DAMPING:g}, stop at |e| <= {PEER_TOL:g} m or "
        f"{CLIK_MAX_ITER} iterations, each step clipped into the limits",
    ]


def _summary(results: list[MethodResult]) -> list[str]:
    b = next(r for r in results if "batch" in r.name)
    s = next(r for r in results if "single" in r.name)
    lines = []
    for r in results:
        if r is b or r is s:
            continue
        lines.append(f"batch Leg.ik is {r.time_per_target_s / b.time_per_target_s:,.0f}x and a single call "
                     f"{r.time_per_target_s / s.time_per_target_s:,.1f}x faster than {r.name.split(' (')[0]}")
    return lines


def build(name: str, n: int | None, rng: np.random.Generator, quick: bool) -> ModelBench:
    """The bench of robot ``name``'s leg :data:`LEG` (or first leg).

    Rows: ``Leg.ik`` as one batch and as single calls, Pinocchio CLIK (damped Newton
    ``dq = J^T (J J^T + lambda I)^-1 e`` on the leg's three joints from mid-limit, clipped into the limits,
    <= :data:`CLIK_MAX_ITER` iterations), ikpy and roboticstoolbox ``ik_LM`` (position only) when installed.
    """
    from ..robot import load

    n_batch, n_single, n_iter = _sizes(n, quick)
    n_clik = min(n_batch, 10 * n_iter)
    robot = load(name)
    legs = robot.geometry
    leg_name = LEG if LEG in legs else next(iter(legs))
    leg = legs[leg_name]
    if leg.dof == 6:
        from .bench6 import build6

        return build6(robot, leg_name, n, rng, quick)
    foot = _Foot(robot.model, leg, np.array(robot.q0, dtype=float))
    q_true = rng.uniform(leg.lower, leg.upper, (n_batch, 3))
    targets = foot(q_true)
    methods = _legkin_methods(leg, targets, foot, n_batch, n_single)
    methods.append(Method("pinocchio CLIK (damped Newton, 3 leg joints)", targets, _clik(foot), foot.score_iter,
                          max_targets=n_clik, repeats=1 if quick else 3))
    methods += _peers(name, leg, targets, n_iter, foot.score_iter, quick)
    return ModelBench(
        methods=methods,
        units={"ik": "m"},
        tolerance=f"foot error <= {SOLVE_TOL:g} m and joints inside the URDF limits",
        notes=_notes(name, leg_name, leg, n_batch, n_single, n_clik, n_iter),
        summary=_summary,
    )


def _peers(name: str, leg, targets: np.ndarray, n_iter: int, score: Callable, quick: bool) -> list[Method]:
    """The ikpy and roboticstoolbox rows (set up here, untimed), or skipped rows saying why."""
    from .erd import ERD_ROBOTS, erd_files

    ikpy_name = "ikpy inverse_kinematics (position)"
    rtb_name = "roboticstoolbox ik_LM (position mask)"
    if name not in ERD_ROBOTS:
        why = f"{name} is not an example-robot-data robot (no URDF file for the peers)"
        return [Method(ikpy_name, skip=why), Method(rtb_name, skip=why)]
    repeats = 1 if quick else 3
    out: list[Method] = []
    path = stripped_urdf(erd_files(name)[0])
    try:
        base, end, chain_names = urdf_chain(path, leg.foot_frame)
        reason = missing("ikpy")
        if reason:
            out.append(Method(ikpy_name, skip=reason))
        else:
            try:
                out.append(_ikpy(ikpy_name, path, chain_names, leg, targets, n_iter, score, repeats))
            except Exception as exc:  # noqa: BLE001 - a peer that cannot be set up is a skipped row
                out.append(Method(ikpy_name, skip=f"cannot set up: {type(exc).__name__}: {exc}"))
        reason = missing("roboticstoolbox-python", "roboticstoolbox")
        if reason:
            out.append(Method(rtb_name, skip=reason))
        else:
            try:
                out.append(_rtb(rtb_name, path, base, end, leg, targets, n_iter, score, repeats))
            except Exception as exc:  # noqa: BLE001
                out.append(Method(rtb_name, skip=f"cannot set up: {type(exc).__name__}: {exc}"))
    finally:
        os.unlink(path)
    return out


def _ikpy(label, path, chain_names, leg, targets, n_iter, score, repeats) -> Method:
    import ikpy.chain

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = ikpy.chain.Chain.from_urdf_file(path, base_elements=list(chain_names))
        names = [link.name for link in chain.links]
        mask = [link.joint_type != "fixed" for link in chain.links]
        chain = ikpy.chain.Chain.from_urdf_file(path, base_elements=list(chain_names), active_links_mask=mask)
    active = [i for i, nm in enumerate(names) if nm in leg.joint_names]
    if [names[i] for i in active] != list(leg.joint_names) or chain.links[-1].name != chain_names[-2]:
        raise ValueError(f"ikpy's chain {names} is not the leg's ({leg.joint_names} -> {chain_names[-1]})")
    init = np.zeros(len(chain.links))
    init[active] = leg.q_ref

    def run(p):
        q = np.full((len(p), 3), np.nan)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for k in range(len(p)):
                q[k] = chain.inverse_kinematics(p[k], initial_position=init)[active]
        return q, None

    return Method(label, targets, run, score, max_targets=n_iter, repeats=repeats,
                  note="Chain.from_urdf_file (root link to foot), from mid-limit, position only, ikpy defaults")


def _rtb(label, path, base, end, leg, targets, n_iter, score, repeats) -> Method:
    import roboticstoolbox as rtb

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rob = rtb.Robot.URDF(path)
    ets = rob.ets(start=base, end=end)
    if ets.n != 3:
        raise ValueError(f"the ETS {base} -> {end} has {ets.n} joints, not 3")
    tol = 0.5 * PEER_TOL**2  # ik_LM's tol bounds 1/2 |e|^2 on the masked rows
    wmask = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    q0 = np.array(leg.q_ref)

    def run(p):
        q = np.full((len(p), 3), np.nan)
        iters = np.zeros(len(p))
        tep = np.eye(4)
        for k in range(len(p)):
            tep[:3, 3] = p[k]
            sol: Any = ets.ik_LM(tep, q0=q0, mask=wmask, tol=tol, joint_limits=True)
            q[k], iters[k] = sol.q, sol.iterations
        return q, iters

    return Method(label, targets, run, score, max_targets=n_iter, repeats=repeats,
                  note=f"Robot.URDF, ets({base}..{end}).ik_LM(mask=[1,1,1,0,0,0], tol=1/2 {PEER_TOL:g}^2, "
                  "joint_limits=True, q0=mid-limit), defaults otherwise")


def single_calls(name: str) -> list:
    """One single call per public function of :class:`~legkin.legs.Leg` for robot ``name``'s leg :data:`LEG`,
    inputs bound (the standing pose and its foot), against Pinocchio's FK + frame (and frame Jacobian) of
    that leg's foot on the same model (``legkin bench <name>``'s single-call table)."""
    from .._single_call import SingleCall
    from ..robot import load

    robot = load(name)
    legs = robot.geometry
    leg = legs[LEG if LEG in legs else next(iter(legs))]
    q = np.array(robot.q0[list(leg.idx_q)], dtype=float)
    q = np.clip(q, leg.lower, leg.upper)
    p = leg.fk(q)
    return [
        SingleCall("Leg.fk", lambda: leg.fk(q), "fk"),
        SingleCall("Leg.jacobian", lambda: leg.jacobian(q), "jacobian"),
        SingleCall("Leg.ik", lambda: leg.ik(p), "fk"),
        SingleCall("Leg.ik_all", lambda: leg.ik_all(p), "fk"),
    ]
