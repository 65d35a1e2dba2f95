"""What a mechanism tells the ground simulation (:class:`GroundModel`): its contact geometry, where legkin predicts
it touches flat ground, and the IK that holds those contacts while the base moves.

A mechanism package provides it by one rule: a module ``<package>.sim`` with ``ground_model(robot) ->
GroundModel`` (:func:`ground_model` finds it; ``legkin.legs.sim`` serves every robot with legs, the wheel-leg has
its own). The framework never imports a mechanism: it only calls these methods.

Frames: the *base frame* is the robot's root body with the base level at the origin (a floating robot's free joint
at identity); ``q`` is always the full configuration of the floating robot, of which only the joints below the
free joint are read.
"""

from __future__ import annotations

import importlib
import importlib.util
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np
import pinocchio as pin

from ..errors import InvalidParameterError

if TYPE_CHECKING:  # pragma: no cover
    from ..robot import Robot

__all__ = ["ContactGeom", "GroundModel", "FootGround", "Foot", "ground_model", "has_ground_model"]


#: The damping of :attr:`GroundModel.held_tilt`, in seconds (damping / stiffness).
HELD_TILT_DAMPING = 0.02


@dataclass(frozen=True)
class ContactGeom:
    """One collision primitive of the export.

    Attributes:
        name: geom name.
        joint: Pinocchio joint index of the body carrying it.
        kind: ``"sphere"``, ``"cylinder"`` (MuJoCo types).
        size: MuJoCo ``size`` (m): ``(radius,)`` or ``(radius, half length)``.
        placement: pose in that joint's frame (a cylinder's axis is the placement's z).
    """

    name: str
    joint: int
    kind: str
    size: tuple[float, ...]
    placement: pin.SE3


class GroundModel(ABC):
    """The ground-contact facts of one mechanism (module docstring).

    Attributes:
        robot: the floating robot (``legkin.load(name, floating=True)``).
        collision_skip: URDF collision geoms *not* exported (replaced by :meth:`geoms`, e.g. the wheel-leg's rim
            meshes, which MuJoCo would convexify).
        rolling_radius: the radius (m) of a rolling wheel in the reference pose, or None (legs).
        squat_pose: the SRDF pose the ``squat`` scenario starts from (None: the reference pose).
        squat_start: how far (m) below that pose the squat starts (the contacts held by :meth:`hold`).
        stand_angle: the ``stand`` scenario's wheels turned by this angle (rad, :meth:`roll`) from the pose (the
            wheel-leg: half the angle between two tyre cylinders, where MuJoCo's tyre is farthest from legkin's).
        line_half_width: half the length (m) of a line contact across the base's y axis (a tyre lying flat: its
            centre of pressure anywhere on it is legkin's contact); 0 for point contacts.
        rolls_sideways: whether a contact rolls about the base x axis too (a sphere) or only about y (a tyre).
        timestep: the export's time step (s) for this mechanism, or None (the ground default, 1 ms).
        no_squat: why the ``squat`` scenario cannot run on this robot, or None.
        fixed_base: a fixed mechanism (its registry spec not floating: the hybrid leg), whose floor is put under its
            contacts and whose scenario is ``press``.
        held_tilt: the stiffness (N m / rad) of a torque on the base that holds its roll and pitch at 0 in the
            scenarios (a biped on two point feet, bolt: its only support is the line between its feet), with
            :data:`HELD_TILT_DAMPING` times as much damping (N m s / rad); a torque, no force: the base's height and
            its contacts are the contacts' alone. 0: none.
    """

    robot: "Robot"
    collision_skip: frozenset[str] = frozenset()
    rolling_radius: float | None = None
    squat_pose: str | None = None
    squat_start: float = 0.0
    stand_angle: float = 0.0
    line_half_width: float = 0.0
    rolls_sideways: bool = True
    timestep: float | None = None
    no_squat: str | None = None
    fixed_base: bool = False
    held_tilt: float = 0.0

    @abstractmethod
    def geoms(self) -> list[ContactGeom]:
        """The contact geometry legkin predicts contacts for (feet, tyres)."""

    @abstractmethod
    def contacts(self, q: np.ndarray) -> np.ndarray:
        """(k, 3) legkin's predicted lowest points (m, base frame) of the contact geometry at ``q`` (level base)."""

    @abstractmethod
    def hold(self, q: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """A configuration near ``q`` whose contact points (:meth:`contacts`) are ``targets`` (k, 3), base frame.

        Raises:
            LegkinError: a target out of reach (the mechanism's IK error).
        """

    @abstractmethod
    def contact_frames(self, q: np.ndarray) -> list[tuple[tuple[str, ...], float]]:
        """Per contact of :meth:`contacts`, the frames of the bodies carrying it (two for a tyre fillet about a
        hinge, which two links carry half each) and the radius (m) of the circle or sphere touching the ground
        there (its rolling radius)."""

    def rolled(self, rho: float, a: np.ndarray) -> np.ndarray:
        """How far (m, base frame) a contact of rolling radius ``rho`` rolls when its body turns by the rotation
        vector ``a`` (rad): ``rho (a_y, -a_x, 0)`` for a sphere; a tyre (:attr:`rolls_sideways` False) rolls only
        about its axis (base y), ``rho (a_y, 0, 0)``."""
        return np.array([rho * a[1], -rho * a[0] if self.rolls_sideways else 0.0, 0.0])

    def rolling(self, q_ref: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(k, 3) how far each contact rolls on the ground (no slip) from ``q_ref`` to ``q`` (:meth:`rolled` of the
        mean rotation vector of its bodies, :meth:`contact_frames`; Pinocchio FK, level base)."""
        model = self.robot.model
        datas = []
        for x in (q_ref, q):
            data = model.createData()
            pin.framesForwardKinematics(model, data, x)
            datas.append(data)
        frames = self.contact_frames(q_ref)
        out = np.zeros((len(frames), 3))
        for k, (names, rho) in enumerate(frames):
            fids = [model.getFrameId(n) for n in names]
            a = np.mean([pin.log3(datas[1].oMf[f].rotation @ datas[0].oMf[f].rotation.T) for f in fids], axis=0)
            out[k] = self.rolled(rho, a)
        return out

    def hold_rolling(self, q_ref: np.ndarray, targets: np.ndarray, iterations: int = 4) -> np.ndarray:
        """:meth:`hold` with each target moved by the rolling (:meth:`rolling`) from ``q_ref`` to the answer: the
        contacts roll without slipping (a fixed point, ``iterations`` rounds)."""
        q = np.array(q_ref, dtype=float)
        for _ in range(iterations):
            q = self.hold(q, np.asarray(targets, dtype=float) + self.rolling(q_ref, q))
        return q

    def static_torques(self, q: np.ndarray) -> np.ndarray | None:
        """(nv,) joint torques (N m) holding ``q`` standing, the weight shared equally by the contacts, or None
        (not known: the integral term of the scenarios finds them)."""
        return None

    def roll(self, q: np.ndarray, angle: float) -> np.ndarray:
        """``q`` with every wheel turned forward by ``angle`` (rad): only for mechanisms with wheels."""
        raise InvalidParameterError(f"{self.robot.name} has no wheels to roll")

    def pose(self, q: np.ndarray) -> np.ndarray:
        """The configuration the scenarios and the keyframes use for the pose ``q`` (default ``q`` itself; flat
        feet: levelled, :meth:`FootGround.pose`)."""
        return q

    def stiffness(self) -> dict[str, float]:
        """The smallest position gain (N m / rad) of some actuated joints in the ground export (default none; flat
        feet: :meth:`FootGround.stiffness`)."""
        return {}

    def standing_height(self, q: np.ndarray) -> float:
        """Base height (m) that puts the lowest predicted contact on the floor z = 0 (level base)."""
        return float(-np.min(self.contacts(q)[:, 2]))


@dataclass(frozen=True)
class Foot:
    """A contact sphere of ``radius`` (m) centred at ``offset`` (m) in ``frame``, moved by the joints ``idx_q`` of
    ``leg``: a point foot (one per leg, at the foot frame) or one corner of a flat foot's sole (several per leg,
    :func:`legkin.legs.sim.sole_spheres`). Its geom is ``<leg>_<label>_contact``."""

    leg: str
    frame: str
    radius: float
    idx_q: tuple[int, ...]
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    label: str = "foot"


#: Smallest position gain of a flat-footed leg's joints, in units of the robot's toppling stiffness m g h
#: (:meth:`FootGround.stiffness`).
STIFFNESS = 2.0
#: A flat foot within this (|R - R_level|, max entry) of level is left as it is (:meth:`FootGround.pose`): 1e-9
#: tilts a 0.2 m sole by 2e-10 m.
_LEVEL_TOL = 1e-9


def _level(rotation: np.ndarray) -> np.ndarray:
    """The rotation about z nearest ``rotation`` in yaw (its x axis projected on the floor)."""
    yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
    return np.array(pin.rpy.rpyToMatrix(0.0, 0.0, yaw))


class FootGround(GroundModel):
    """Feet as contact spheres (:class:`Foot`); legkin's leg ``fk(leg, q_leg)`` (the foot frame's 4x4 pose) and
    ``ik(leg, pose, q_near)`` (base frame). A leg with several spheres has a flat foot: its sole is held level.

    The predicted contact of a sphere is its centre minus ``radius`` along z; :meth:`hold` runs the leg IK on the
    foot pose that puts the sphere centres on ``target + radius z`` (a flat foot keeping its orientation).

    Attributes:
        stance: joint values (rad, by index in ``q``) that every pose takes before its soles are levelled
            (:meth:`pose`): a robot whose reference pose lies outside its joint limits stands in another one
            (simple_humanoid: straight legs, :data:`legkin.legs.sim.STRAIGHT_LEGS`); empty for the others.
    """

    def __init__(self, robot: "Robot", feet: Sequence[Foot], fk: Callable[[str, np.ndarray], np.ndarray],
                 ik: Callable[[str, np.ndarray, np.ndarray], np.ndarray]) -> None:
        self.robot, self.feet, self._fk, self._ik = robot, list(feet), fk, ik
        self.stance: dict[int, float] = {}
        self.legs = {f.leg: [g for g in self.feet if g.leg == f.leg] for f in self.feet}
        model = robot.model
        flat = {model.frames[model.getFrameId(f[0].frame)].parentJoint for f in self.legs.values() if len(f) > 1}
        self.collision_skip = frozenset(  # the foot frames' shapes, and every shape of a flat foot's body
            g.name for g in robot.collision_model.geometryObjects
            if model.frames[g.parentFrame].name in {f.frame for f in self.feet} or g.parentJoint in flat
        )

    def geoms(self) -> list[ContactGeom]:
        """One sphere per :class:`Foot`, at its offset in its frame."""
        model = self.robot.model
        out = []
        for f in self.feet:
            frame = model.frames[model.getFrameId(f.frame)]
            out.append(ContactGeom(f"{f.leg}_{f.label}_contact", frame.parentJoint, "sphere", (f.radius,),
                                   frame.placement * pin.SE3(np.eye(3), np.array(f.offset))))
        return out

    def _points(self, q: np.ndarray) -> np.ndarray:
        """(k, 3) the sphere centres (legkin's leg FK), base frame."""
        poses = {leg: self._fk(leg, q[list(f[0].idx_q)]) for leg, f in self.legs.items()}
        return np.array([poses[f.leg][:3, :3] @ np.array(f.offset) + poses[f.leg][:3, 3] for f in self.feet])

    def contacts(self, q: np.ndarray) -> np.ndarray:
        """The lowest point of each contact sphere (legkin's leg FK), base frame."""
        return self._points(q) - np.array([[0.0, 0.0, f.radius] for f in self.feet])

    def contact_frames(self, q: np.ndarray) -> list[tuple[tuple[str, ...], float]]:
        """Each sphere's frame and radius."""
        return [((f.frame,), f.radius) for f in self.feet]

    def static_torques(self, q: np.ndarray) -> np.ndarray:
        """``g(q) - sum_k J_k^T f_k``: gravity and vertical forces ``f_k`` at the sphere centres carrying the weight
        with no moment about the centre of mass (the least-norm solution of the three balance equations;
        Pinocchio, level base); the base rows are not used."""
        model = self.robot.model
        data = model.createData()
        tau = np.array(pin.computeGeneralizedGravity(model, data, q))
        com = np.array(pin.centerOfMass(model, data, q))
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        weight = -float(model.gravity.linear[2]) * sum(i.mass for i in model.inertias)
        fids = [model.getFrameId(f.frame) for f in self.feet]
        arms = [data.oMf[i].rotation @ np.array(f.offset) for i, f in zip(fids, self.feet)]
        xy = np.array([data.oMf[i].translation[:2] + a[:2] for i, a in zip(fids, arms)])
        balance = np.vstack([np.ones(len(fids)), xy.T])
        forces = np.linalg.lstsq(balance, weight * np.array([1.0, com[0], com[1]]), rcond=None)[0]
        for fid, arm, fz in zip(fids, arms, forces):
            jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            point = jac[:3] - pin.skew(arm) @ jac[3:]  # the velocity of the sphere centre
            tau -= point.T @ np.array([0.0, 0.0, fz])
        return tau

    def _solve(self, q: np.ndarray, leg: str, rotation: np.ndarray, position: np.ndarray) -> np.ndarray:
        """``q`` with ``leg``'s joints from its IK (nearest ``q``) putting its foot frame at (rotation, position)."""
        idx = list(self.legs[leg][0].idx_q)
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = rotation, position
        out = np.array(q, dtype=float)
        out[idx] = self._ik(leg, pose, out[idx])
        return out

    def hold(self, q: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Leg IK (nearest to ``q``) putting each sphere's lowest point on its target, a flat foot keeping its
        orientation (the foot frame's position: the mean over its spheres, exact when they move rigidly)."""
        out = np.array(q, dtype=float)
        centres = np.asarray(targets, dtype=float) + np.array([[0.0, 0.0, f.radius] for f in self.feet])
        for leg, feet in self.legs.items():
            rotation = self._fk(leg, q[list(feet[0].idx_q)])[:3, :3]
            rows = [k for k, f in enumerate(self.feet) if f.leg == leg]
            position = np.mean([centres[k] - rotation @ np.array(self.feet[k].offset) for k in rows], axis=0)
            out = self._solve(out, leg, rotation, position)
        return out

    def stiffness(self) -> dict[str, float]:
        """:data:`STIFFNESS` ``m g h`` for every joint of a leg on a flat foot: ``m`` the robot's mass, ``h`` its
        centre of mass's height above the soles in the reference pose. The robot standing on its soles is an
        inverted pendulum that an ankle softer than ``m g h`` lets topple (g1's 98.7 N m / rad from its foot's
        inertia, for m g h = 230 N m / rad: it fell forwards 0.04 rad in 2 s)."""
        model = self.robot.model
        joints = [model.idx_qs.tolist().index(i) for f in self.legs.values() if len(f) > 1 for i in f[0].idx_q]
        return {model.names[j]: STIFFNESS * self.toppling() for j in joints}

    def toppling(self) -> float:
        """The robot's toppling stiffness ``m g h`` (N m / rad): its weight times its centre of mass's height above
        the floor in the reference pose (:meth:`pose`, level base)."""
        model, q = self.robot.model, self.pose(self.robot.q0)
        height = float(pin.centerOfMass(model, model.createData(), q)[2]) + self.standing_height(q)
        return -float(model.gravity.linear[2]) * sum(i.mass for i in model.inertias) * height

    def pose(self, q: np.ndarray) -> np.ndarray:
        """``q`` with the :attr:`stance` joints set, then every flat foot levelled (its yaw and position kept; leg IK
        nearest ``q``): an SRDF pose whose soles are not level with the base (icub's half_sitting: pitched
        0.063 rad) would land on an edge."""
        out = np.array(q, dtype=float)
        out[list(self.stance)] = list(self.stance.values())
        for leg, feet in self.legs.items():
            pose = self._fk(leg, out[list(feet[0].idx_q)])
            if len(feet) > 1 and np.abs(pose[:3, :3] - _level(pose[:3, :3])).max() > _LEVEL_TOL:
                out = self._solve(out, leg, _level(pose[:3, :3]), pose[:3, 3])
        return out


def sphere_radius(robot: "Robot", frame: str, default: float = 0.02) -> float:
    """The radius (m) of the URDF collision shape at a foot ``frame``.

    A sphere: its radius. A mesh (e.g. go2's convex foot): the distance from the frame origin to the mesh's
    farthest vertex along the shank (the direction from the parent joint to the frame), so the sphere's bottom is
    the mesh's with the shank vertical. No collision shape: ``default``.
    """
    model = robot.model
    fid = model.getFrameId(frame)
    for g in robot.collision_model.geometryObjects:
        if g.parentFrame != fid:
            continue
        kind = type(g.geometry).__name__
        if kind == "Sphere":
            return float(g.geometry.radius)
        if hasattr(g.geometry, "vertices"):
            pts = np.asarray(g.geometry.vertices()) * np.asarray(g.meshScale).ravel()
            pts = pts @ g.placement.rotation.T + g.placement.translation  # in the joint frame
            origin = model.frames[fid].placement.translation
            axis = origin / max(float(np.linalg.norm(origin)), 1e-12)
            return float(np.max((pts - origin) @ axis))
    return default


def has_ground_model(robot: "Robot | str") -> bool:
    """Whether the package of a robot (or registered model name) provides a ``sim`` module (:func:`ground_model`)
    that serves it: a shared package's ``sim.supports(name)`` says which of its models it serves (legkin.legs: all
    but its ``sim.UNSUPPORTED``)."""
    from .._registry import get_spec

    spec = get_spec(robot) if isinstance(robot, str) else robot.spec
    if importlib.util.find_spec(f"{spec.package}.sim") is None:
        return False
    supports = getattr(importlib.import_module(f"{spec.package}.sim"), "supports", None)
    return supports is None or bool(supports(spec.name))


def ground_model(robot: "Robot") -> GroundModel:
    """The :class:`GroundModel` of a floating robot (or a fixed mechanism), from its package's ``sim`` module.

    Raises:
        InvalidParameterError: the robot is not loaded as its registry spec says (floating; fixed for a fixed
            mechanism, the hybrid leg), or its package has no ground model.
    """
    if robot.floating != robot.spec.floating:  # a fixed mechanism (the hybrid leg) presses on the floor fixed
        raise InvalidParameterError(
            f"{robot.name}: the ground simulation needs legkin.load(name, floating={robot.spec.floating})")
    if not has_ground_model(robot):
        found = importlib.util.find_spec(f"{robot.spec.package}.sim") is not None
        why = getattr(importlib.import_module(f"{robot.spec.package}.sim"), "UNSUPPORTED", {}) if found else {}
        raise InvalidParameterError(f"{robot.name} has no ground model ({robot.spec.package}.sim"
                                    f"{': ' + why[robot.spec.name] if robot.spec.name in why else ''})")
    module = importlib.import_module(f"{robot.spec.package}.sim")
    return module.ground_model(robot)
