"""The ground model of a robot with legs (:func:`ground_model`, found by :func:`legkin.mjcf.ground.ground_model`):
a sphere per point foot at its foot frame (the quadrupeds), four spheres at the corners of a flat foot's sole (the
humanoids, :func:`sole_spheres`); legkin's leg FK for where they touch the ground and its leg IK to hold them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..mjcf.ground import Foot, FootGround, sphere_radius
from .extract import from_model

__all__ = ["ground_model", "supports", "UNSUPPORTED", "HELD_TILT", "STRAIGHT_LEGS", "NOT_THE_ROBOT", "NO_SQUAT",
           "SQUAT_START", "sole_spheres", "SOLE_RADIUS", "SOLE_BAND", "DEFAULT_SOLE"]

#: Radius (m) of the four corner spheres of a sole measured from a mesh (:func:`sole_spheres`): g1's URDF uses
#: 5 mm spheres at its sole corners, kept for every humanoid.
SOLE_RADIUS = 0.005
#: A foot mesh's sole: its vertices within this height (m) of the lowest one (talos's collision mesh: the
#: rectangle of those within 3 mm is 0.208 x 0.124 m, the whole mesh 0.221 x 0.134 m).
SOLE_BAND = 0.003
#: The sole (x min, x max, y min, y max, z) in the foot frame (m) of a 6-DOF leg without any foot shape in its
#: URDF (simple_humanoid: "FIXME: fill missing data: sole", no visual, its foot frame the ankle centre): talos's sole
#: measured from its collision mesh (:data:`SOLE_BAND`), 0.107 m below its ankle (talos's sole frame). Talos's legs
#: have simple_humanoid's proportions (thigh, shank, hip spacing: 0.348, 0.293, 0.170 m against 0.3535, 0.300,
#: 0.180 m); on straight legs simple_humanoid's centre of mass is 0.035 m ahead of its ankles, 0.064 m inside the
#: sole's toe, and its feet (0.124 m wide) are 0.056 m apart.
DEFAULT_SOLE = (-0.1095, 0.0987, -0.0620, 0.0621, -0.107)


#: The robots of :mod:`legkin.legs` without a ground model, and why (none).
UNSUPPORTED: dict[str, str] = {}

#: A biped on two point feet (bolt) cannot stand: the line between its feet is its only support. Its scenarios
#: hold its base's roll and pitch by a torque of this many times its toppling stiffness m g h per radian
#: (:attr:`legkin.mjcf.ground.GroundModel.held_tilt`; bolt: 100 x 8.00 N m / rad).
HELD_TILT = 100.0

#: The robots that stand on straight legs (every leg joint at 0: soles level, feet under the hips) instead of their
#: reference pose, and why (:attr:`legkin.mjcf.ground.FootGround.stance`).
STRAIGHT_LEGS = {
    "simple_humanoid": "its SRDF half_sitting lies outside its URDF limits (ankle pitch -0.419 rad, range [0, 2.618]);"
                       " a level sole needs ankle pitch = -(hip pitch + knee) (hip roll, yaw 0), so with both "
                       "ankles' pitch >= 0 and the right knee >= 0 the right foot is under its hip only on a straight "
                       "leg",
}

#: URDF collision shapes (Pinocchio names) that are not the robot's, left out of its ground export:
#: simple_humanoid's BODY carries example-robot-data's test shapes for Pinocchio's ``<collision_checking>`` (a capsule
#: of radius 1 m and length 1 m around the base, 0.76 m above the floor, and a box mesh).
NOT_THE_ROBOT = {"simple_humanoid": ("BODY_0", "BODY_1")}

#: The robots of :mod:`legkin.legs` whose ground model has no ``squat`` scenario, and why.
NO_SQUAT = {
    "romeo": "5 cm below its half_sitting its feet are reachable only outside its joint limits (by 1.5e-3 rad)",
    "simple_humanoid": "its base 1 mm below its straight-leg stance, its right foot is reachable only outside its "
                       "URDF limits (by 0.060 rad; 5 cm: 0.43 rad; Leg6.ik over its 8 solutions)",
}
#: How far (m) below its reference pose a robot whose reference pose has straight knees (g1, no SRDF) starts the
#: squat (:attr:`legkin.mjcf.ground.GroundModel.squat_start`): from straight knees g1's feet slid 14 mm.
SQUAT_START = 0.02


def supports(name: str) -> bool:
    """Whether the ground model serves the robot ``name``.

    Args:
        name: a registry name of :mod:`legkin.legs`.

    Returns:
        True for the quadrupeds (:data:`legkin.legs.ERD_ROBOTS`: four point feet) and the humanoids (flat feet) but
        :data:`UNSUPPORTED` (docs/mujoco.md).
    """
    from .erd import ERD_ALL

    return name in ERD_ALL and name not in UNSUPPORTED


def _y_up(path: str) -> bool:
    """Whether a mesh is a Collada file declaring ``<up_axis>Y_UP</up_axis>`` (icub's)."""
    file = Path(path)
    if file.suffix.lower() != ".dae" or not file.is_file():
        return False
    with file.open("rb") as f:
        return b"<up_axis>Y_UP</up_axis>" in f.read(4096)


def _mesh_points(robot: Any, joint: int, frame: Any) -> np.ndarray | None:
    """The vertices (n, 3) of the first mesh on ``joint`` (collision shapes first, then visuals) in ``frame``'s
    coordinates (m), or None. A Y-up Collada mesh is turned back by -90 deg about x: Pinocchio's loader (assimp)
    turns it Z-up, where the URDF's origin expects the file's own axes (icub's feet: loaded, their sole is
    0.06 m long and 0.157 m wide, turned back 0.157 m long, and the centre of mass of half_sitting is above it)."""
    for geometry in (robot.collision_model, robot.visual_model):
        for g in geometry.geometryObjects:
            if g.parentJoint == joint and hasattr(g.geometry, "vertices"):
                pts = np.asarray(g.geometry.vertices()) * np.asarray(g.meshScale).ravel()
                if _y_up(g.meshPath):
                    pts = pts[:, [0, 2, 1]] * np.array([1.0, 1.0, -1.0])  # (x, y, z) -> (x, z, -y)
                pts = pts @ g.placement.rotation.T + g.placement.translation  # in the joint frame
                return (pts - frame.placement.translation) @ frame.placement.rotation
    return None


def sole_spheres(robot: Any, foot_frame: str) -> list[tuple[np.ndarray, float]]:
    """The contact spheres of a flat foot: ``[(centre in the foot frame (m), radius (m))]``.

    The URDF's collision spheres on the foot's body when it has at least three (g1: four 5 mm spheres); otherwise
    four :data:`SOLE_RADIUS` spheres inside the corners of the sole rectangle, their bottoms on the sole: the sole
    is the x-y box of a foot mesh's vertices within :data:`SOLE_BAND` of its lowest one (the collision mesh, else
    the visual one: talos, romeo, icub, alexander), else :data:`DEFAULT_SOLE` (simple_humanoid).

    Args:
        robot: a loaded robot (``legkin.load(name, floating=True)``).
        foot_frame: the leg's foot frame (:attr:`legkin.legs.Leg6.foot_frame`).

    Returns:
        the spheres, at least three.
    """
    model = robot.model
    frame = model.frames[model.getFrameId(foot_frame)]
    spheres = [(frame.placement.actInv(g.placement).translation, float(g.geometry.radius))
               for g in robot.collision_model.geometryObjects
               if g.parentJoint == frame.parentJoint and type(g.geometry).__name__ == "Sphere"]
    if len(spheres) >= 3:
        return spheres
    pts = _mesh_points(robot, frame.parentJoint, frame)
    if pts is None:
        x0, x1, y0, y1, z = DEFAULT_SOLE
    else:
        z = float(pts[:, 2].min())
        sole = pts[pts[:, 2] < z + SOLE_BAND]
        (x0, y0), (x1, y1) = sole[:, :2].min(axis=0), sole[:, :2].max(axis=0)
    r = SOLE_RADIUS
    return [(np.array([x, y, z + r]), r) for x in (x0 + r, x1 - r) for y in (y0 + r, y1 - r)]


def ground_model(robot: Any) -> FootGround:
    """Feet of the legs :func:`legkin.legs.from_model` finds in ``robot.model`` (a floating robot).

    Args:
        robot: ``legkin.load(name, floating=True)``.

    Returns:
        a :class:`~legkin.mjcf.ground.FootGround`: a 3-DOF leg's foot sphere of the URDF's collision radius
        (:func:`~legkin.mjcf.ground.sphere_radius`), a 6-DOF leg's sole spheres (:func:`sole_spheres`);
        :meth:`legkin.legs.Leg.fk` / :meth:`legkin.legs.Leg6.fk` and their ``ik``.
    """
    legs = from_model(robot.model)
    feet = []
    for name, leg in legs.items():
        idx = tuple(leg.idx_q)
        if len(idx) == 3:
            feet.append(Foot(name, leg.foot_frame, sphere_radius(robot, leg.foot_frame), idx))
            continue
        feet += [Foot(name, leg.foot_frame, r, idx, (float(c[0]), float(c[1]), float(c[2])), f"sole{k}")
                 for k, (c, r) in enumerate(sole_spheres(robot, leg.foot_frame))]

    def fk(name: str, q_leg: np.ndarray) -> np.ndarray:
        out = np.asarray(legs[name].fk(q_leg), dtype=float)
        if out.shape == (3,):  # a 3-DOF leg: the foot position
            pose = np.eye(4)
            pose[:3, 3] = out
            return pose
        return out

    def ik(name: str, pose: np.ndarray, q_near: np.ndarray) -> np.ndarray:
        target = pose if len(legs[name].idx_q) == 6 else pose[:3, 3]
        return np.asarray(legs[name].ik(target, q_near=q_near), dtype=float)

    out = FootGround(robot, feet, fk, ik)
    out.no_squat = NO_SQUAT.get(robot.name)
    out.collision_skip |= frozenset(NOT_THE_ROBOT.get(robot.name, ()))
    if len(legs) == 2 and all(len(leg.idx_q) == 3 for leg in legs.values()):  # two point feet
        out.held_tilt = HELD_TILT * out.toppling()
    if robot.name in STRAIGHT_LEGS:
        out.stance = {i: 0.0 for leg in legs.values() for i in leg.idx_q}
    if not robot.spec.reference_pose:  # g1 (no SRDF): q0 has straight knees, where d q / d height is unbounded
        out.squat_start = SQUAT_START
    return out
