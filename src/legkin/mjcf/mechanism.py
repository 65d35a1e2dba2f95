"""A legkin mechanism loaded in MuJoCo (:func:`load_mujoco`), with the maps between ``qpos`` and ``q``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..errors import LegkinError
from ._base import DEFAULTS, _mujoco, _options, _robot
from .writer import _build_xml, _joint, _qpos

if TYPE_CHECKING:  # pragma: no cover
    from ..robot import Robot


# ------------------------------------------------------------------------------------------ loaded model
@dataclass
class MujocoMechanism:
    """A legkin mechanism loaded in MuJoCo, with the maps between its ``qpos`` and Pinocchio's ``q``.

    Attributes:
        robot: the legkin robot (Pinocchio model).
        xml: the MJCF text.
        model, data: MuJoCo's ``MjModel`` and ``MjData``.
        body_ids: MuJoCo body id of each Pinocchio joint (index 0: the world).
        sites: ``(Pinocchio frame id, MuJoCo site id)`` of every frame exported as a site.
        loop_sites: ``(site1, site2)`` ids of each loop closure, in ``robot.loops`` order.
        actuator_q: index in ``q`` of each actuator's joint (actuators in ``robot.actuated_joints`` order).
    """

    robot: "Robot"
    xml: str
    model: Any
    data: Any
    joints: list = field(repr=False)
    body_ids: list[int] = field(repr=False)
    sites: list[tuple[int, int]] = field(repr=False)
    loop_sites: list[tuple[int, int]] = field(repr=False)
    actuator_q: list[int] = field(repr=False)

    def qpos(self, q) -> np.ndarray:
        """MuJoCo ``qpos`` of the Pinocchio configuration ``q``."""
        q = self.robot.check_q(q)
        qpos = np.empty(self.model.nq)
        qpos[self._qposadr] = _qpos(self.joints, q)
        return qpos

    def q(self, qpos) -> np.ndarray:
        """Pinocchio configuration of the MuJoCo ``qpos``."""
        x = np.asarray(qpos, dtype=float)[self._qposadr]
        out = np.empty(self.robot.model.nq)
        k = 0
        for j in self.joints[1:]:
            if j.kind == "hinge_rub":
                out[j.idx_q : j.idx_q + 2] = math.cos(x[k]), math.sin(x[k])
                k += 1
            elif j.kind == "free":
                out[j.idx_q : j.idx_q + 7] = [*x[k : k + 3], *x[k + 4 : k + 7], x[k + 3]]
                k += 7
            elif j.kind == "ball":
                out[j.idx_q : j.idx_q + 4] = [*x[k + 1 : k + 4], x[k]]
                k += 4
            else:
                out[j.idx_q : j.idx_q + j.nq] = x[k : k + j.nq]
                k += j.nq
        return out

    def ctrl(self, q) -> np.ndarray:
        """Actuator targets holding the actuated joints at their values in ``q``."""
        return np.asarray(q, dtype=float)[self.actuator_q]

    def set_configuration(self, q, forward: bool = True) -> None:
        """``qpos`` from ``q``, zero velocity, ``ctrl`` holding it; then ``mj_forward`` (or only kinematics)."""
        mujoco = _mujoco()
        self.data.qpos[:] = self.qpos(q)
        self.data.qvel[:] = 0.0
        self.data.ctrl[:] = self.ctrl(q)
        (mujoco.mj_forward if forward else mujoco.mj_kinematics)(self.model, self.data)

    def loop_residuals(self) -> np.ndarray:
        """Per loop, the distance between its two sites (point) or ``sqrt(|dp|^2 + angle^2)`` (frame), in m
        and rad, at the current ``data`` (after ``mj_kinematics``)."""
        d = self.data
        out = np.empty(len(self.loop_sites))
        for k, ((s1, s2), lp) in enumerate(zip(self.loop_sites, self.robot.loops)):
            dp = float(np.linalg.norm(d.site_xpos[s1] - d.site_xpos[s2]))
            if lp.type == "frame":
                r = d.site_xmat[s1].reshape(3, 3).T @ d.site_xmat[s2].reshape(3, 3)
                s = 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
                angle = math.atan2(float(np.linalg.norm(s)), 0.5 * (np.trace(r) - 1.0))
                dp = math.hypot(dp, angle)
            out[k] = dp
        return out

    def equality_residuals(self) -> np.ndarray:
        """MuJoCo's own equality rows of ``efc_pos`` (after ``mj_forward``)."""
        mujoco = _mujoco()
        n = self.data.nefc
        kind = np.asarray(self.data.efc_type[:n])
        return np.asarray(self.data.efc_pos[:n])[kind == mujoco.mjtConstraint.mjCNSTR_EQUALITY].copy()

    def __post_init__(self) -> None:
        self._qposadr = np.concatenate([
            np.arange(self.model.jnt_qposadr[self._jid(j.name)], self.model.jnt_qposadr[self._jid(j.name)] + n)
            for j in self.joints[1:]
            for n in [{"free": 7, "ball": 4, "hinge_rub": 1}.get(j.kind, j.nq)]
        ]).astype(int) if len(self.joints) > 1 else np.zeros(0, dtype=int)

    def _jid(self, name: str) -> int:
        mujoco = _mujoco()
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)


def load_mujoco(robot_or_name: "Robot | str", *, xml: str | None = None, **params: Any) -> MujocoMechanism:
    """Compile :func:`to_mjcf` (or the given ``xml``, e.g. an edited copy) in MuJoCo.

    Raises:
        LegkinError: MuJoCo is not installed, or refused the model (its message included).
    """
    mujoco = _mujoco()
    opts = {k: v for k, v in params.items() if k in DEFAULTS}
    robot = _robot(robot_or_name, {k: v for k, v in params.items() if k not in DEFAULTS})
    if xml is None:
        xml = _build_xml(robot, _options(opts))
    try:
        mj_model = mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        raise LegkinError(f"MuJoCo refused the MJCF of {robot.name!r}: {exc}") from None
    model = robot.model
    joints = [None] + [_joint(model, i) for i in range(1, model.njoints)]

    def oid(kind, name):
        return mujoco.mj_name2id(mj_model, kind, name)

    bodies = [0]
    for i in range(1, model.njoints):
        jid = oid(mujoco.mjtObj.mjOBJ_JOINT, model.names[i])
        if jid < 0:
            raise LegkinError(f"the MJCF has no joint {model.names[i]!r}")
        bodies.append(int(mj_model.jnt_bodyid[jid]))
    sites = []
    for fid, f in enumerate(model.frames):
        sid = oid(mujoco.mjtObj.mjOBJ_SITE, f.name)
        if sid >= 0 and f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME):
            sites.append((fid, sid))
    loop_sites = [
        (oid(mujoco.mjtObj.mjOBJ_SITE, lp.frame1), oid(mujoco.mjtObj.mjOBJ_SITE, lp.frame2)) for lp in robot.loops
    ]
    act_q = []
    for k, name in enumerate(robot.actuated_joints):
        aid = oid(mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        if aid != k:
            raise LegkinError(f"the MJCF's actuator {k} is not on joint {name!r}")
        act_q.append(robot.idx_q(name))
    return MujocoMechanism(robot, xml, mj_model, mujoco.MjData(mj_model), joints, bodies, sites, loop_sites, act_q)
