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
    """

    robot: "Robot"
    collision_skip: frozenset[str] = frozenset()
    rolling_radius: float | None = None
    squat_pose: str | None = None
    squat_start: float = 0.0
    stand_angle: float = 0.0
    line_half_width: float = 0.0
    rolls_sideways: bool = True

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

    def standing_height(self, q: np.ndarray) -> float:
        """Base height (m) that puts the lowest predicted contact on the floor z = 0 (level base)."""
        return float(-np.min(self.contacts(q)[:, 2]))


@dataclass(frozen=True)
class Foot:
    """A foot: a sphere of ``radius`` (m) centred on ``frame``, moved by the three joints ``idx_q`` of ``leg``."""

    leg: str
    frame: str
    radius: float
    idx_q: tuple[int, ...]


class FootGround(GroundModel):
    """Feet as spheres at the foot frames; legkin's leg ``fk(leg, q_leg)`` and ``ik(leg, p, q_near)`` (base frame).

    The predicted contact of a foot is its centre minus ``radius`` along z; :meth:`hold` runs the leg IK on the
    foot centres ``target + radius z``.
    """

    def __init__(self, robot: "Robot", feet: Sequence[Foot], fk: Callable[[str, np.ndarray], np.ndarray],
                 ik: Callable[[str, np.ndarray, np.ndarray], np.ndarray]) -> None:
        self.robot, self.feet, self._fk, self._ik = robot, list(feet), fk, ik
        self.collision_skip = frozenset(
            g.name for g in robot.collision_model.geometryObjects
            if robot.model.frames[g.parentFrame].name in {f.frame for f in self.feet}
        )

    def geoms(self) -> list[ContactGeom]:
        """One sphere per foot, at its frame."""
        model = self.robot.model
        out = []
        for f in self.feet:
            frame = model.frames[model.getFrameId(f.frame)]
            out.append(ContactGeom(f"{f.leg}_foot_contact", frame.parentJoint, "sphere", (f.radius,), frame.placement))
        return out

    def contacts(self, q: np.ndarray) -> np.ndarray:
        """The lowest point of each foot sphere (legkin's leg FK), base frame."""
        down = np.array([0.0, 0.0, 1.0])
        return np.array([self._fk(f.leg, q[list(f.idx_q)]) - f.radius * down for f in self.feet])

    def contact_frames(self, q: np.ndarray) -> list[tuple[tuple[str, ...], float]]:
        """Each foot frame and sphere radius."""
        return [((f.frame,), f.radius) for f in self.feet]

    def static_torques(self, q: np.ndarray) -> np.ndarray:
        """``g(q) - sum_k J_k^T f_k``: gravity and vertical foot forces ``f_k`` carrying the weight with no moment
        about the centre of mass (the least-norm solution of the three balance equations; Pinocchio, level
        base); the base rows are not used."""
        model = self.robot.model
        data = model.createData()
        tau = np.array(pin.computeGeneralizedGravity(model, data, q))
        com = np.array(pin.centerOfMass(model, data, q))
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        weight = -float(model.gravity.linear[2]) * sum(i.mass for i in model.inertias)
        fids = [model.getFrameId(f.frame) for f in self.feet]
        xy = np.array([data.oMf[i].translation[:2] for i in fids])
        balance = np.vstack([np.ones(len(fids)), xy.T])
        forces = np.linalg.lstsq(balance, weight * np.array([1.0, com[0], com[1]]), rcond=None)[0]
        for fid, fz in zip(fids, forces):
            jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
            tau -= jac.T @ np.array([0.0, 0.0, fz])
        return tau

    def hold(self, q: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Leg IK (nearest to ``q``) putting each foot's lowest point on its target."""
        out = np.array(q, dtype=float)
        for f, t in zip(self.feet, np.asarray(targets, dtype=float)):
            idx = list(f.idx_q)
            out[idx] = self._ik(f.leg, t + np.array([0.0, 0.0, f.radius]), out[idx])
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
    that serves it: a shared package's ``sim.supports(name)`` says which of its models it serves (legkin.legs: the
    quadrupeds; the humanoids' flat feet have no ground model yet)."""
    from .._registry import get_spec

    spec = get_spec(robot) if isinstance(robot, str) else robot.spec
    if importlib.util.find_spec(f"{spec.package}.sim") is None:
        return False
    supports = getattr(importlib.import_module(f"{spec.package}.sim"), "supports", None)
    return supports is None or bool(supports(spec.name))


def ground_model(robot: "Robot") -> GroundModel:
    """The :class:`GroundModel` of a floating robot, from its package's ``sim`` module.

    Raises:
        InvalidParameterError: the robot is not floating, or its package has no ground model.
    """
    if not robot.floating:
        raise InvalidParameterError(f"{robot.name}: the ground simulation needs legkin.load(name, floating=True)")
    if not has_ground_model(robot):
        raise InvalidParameterError(f"{robot.name} has no ground model ({robot.spec.package}.sim)")
    module = importlib.import_module(f"{robot.spec.package}.sim")
    return module.ground_model(robot)
