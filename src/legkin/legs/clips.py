"""Clips of the external robots (``legkin view go2 --animate feet_circles``, ``legkin view g1 --animate squat``),
driven by :meth:`Leg.ik` and :meth:`Leg6.ik`."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ANIMATIONS", "feet_circles", "squat", "squat_depth", "circle_points", "FRAMES", "RADIUS", "LIMIT_MARGIN",
           "SQUAT_DEPTH", "DEPTH_STEPS"]

#: Frames of one turn and the circles' radius (m).
FRAMES = 60
RADIUS = 0.03
#: A standing pose outside the limits is moved this fraction of each limit range inside them.
LIMIT_MARGIN = 0.1
#: How far (m) the pelvis goes down in :func:`squat` at most (less where the legs cannot: :func:`squat_depth`).
SQUAT_DEPTH = 0.08
#: :func:`squat_depth` tries the depths ``SQUAT_DEPTH k / DEPTH_STEPS``, k = 1 .. DEPTH_STEPS.
DEPTH_STEPS = 16


def circle_points(start, frames: int = FRAMES, radius: float = RADIUS) -> np.ndarray:
    """(frames, 3): a vertical circle in the root's x-z plane through ``start`` (frame 0), centred ``radius``
    above it, one turn forward-up-back-down: ``start + radius (sin t, 0, 1 - cos t)``, ``t = 2 pi k / frames``."""
    t = np.linspace(0.0, 2.0 * np.pi, frames, endpoint=False)
    return np.asarray(start, dtype=float) + radius * np.stack([np.sin(t), np.zeros_like(t), 1.0 - np.cos(t)], -1)


def feet_circles(robot: Any, frames: int = FRAMES, radius: float = RADIUS) -> list[np.ndarray]:
    """Every foot traces :func:`circle_points` from its standing position (``robot.q0``), all legs together.

    The feet are the legs of ``robot.geometry`` (:func:`legkin.legs.from_model` of ``robot.model``), their
    standing positions :meth:`Leg.fk` of ``robot.q0``'s leg joints (the root frame; with a free flyer, the base
    stays where ``q0`` puts it). Each frame's leg joints are ``Leg.ik(p, q_near=previous frame's)``, starting
    from ``q0``; every other coordinate keeps its ``q0`` value. A leg whose ``q0`` joints lie outside its URDF
    limits (none of the nine: laikago, which has no SRDF, gets legkin's standing pose,
    :func:`legkin.legs.erd.standing_pose`) starts from them moved :data:`LIMIT_MARGIN` of each limit range
    inside the limits.

    Raises:
        UnreachableError, JointLimitError: a circle point out of a leg's reach or limits (then ``radius`` is too
            large for that robot).
    """
    q0 = np.array(robot.q0, dtype=float)
    qs = np.tile(q0, (frames, 1))
    for leg in robot.geometry.values():
        cols = list(leg.idx_q)
        q = _start(leg, q0)
        for k, p in enumerate(circle_points(leg.fk(q), frames, radius)):
            q = leg.ik(p, q_near=q)
            qs[k, cols] = q
    return list(qs)


def _start(leg, q0: np.ndarray) -> np.ndarray:
    """The leg's joints of ``q0``, moved :data:`LIMIT_MARGIN` of each limit range inside the limits if outside."""
    q = q0[list(leg.idx_q)]
    if not leg.within_limits(q):
        margin = LIMIT_MARGIN * (leg.upper - leg.lower)
        q = np.clip(q, leg.lower + margin, leg.upper - margin)
    return q


def _floor_offset(robot: Any, q: np.ndarray) -> float:
    """How far (m) to raise a floating base at ``q`` so that the lowest foot frame is on the floor (z = 0)."""
    import pinocchio as pin

    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return -min(float(data.oMf[robot.model.getFrameId(leg.foot_frame)].translation[2])
                for leg in robot.geometry.values())


def _soles(robot: Any, q0: np.ndarray) -> list[tuple[Any, np.ndarray, np.ndarray]]:
    """Each leg, its joints at the start of the squat and its foot's pose there (root frame)."""
    out = []
    for leg in robot.geometry.values():
        q = _start(leg, q0)
        out.append((leg, q, leg.fk(q)))
    return out


def _raised(leg: Any, start: np.ndarray, dz: float) -> np.ndarray:
    target = start.copy()
    if leg.dof == 6:
        target[2, 3] += dz
    else:
        target[2] += dz
    return target


def squat_depth(robot: Any, depth: float = SQUAT_DEPTH) -> float:
    """The squat depth the legs can do (m): the largest of ``depth k / DEPTH_STEPS`` (k = 1 .. DEPTH_STEPS) down to
    which every foot raised by each smaller step still has an in-limit solution (:meth:`Leg6.ik`, continued from the
    previous step); 0 if none (a robot whose standing pose already has a knee on its limit).

    Args:
        robot: a :class:`~legkin.Robot` with legs (``robot.geometry``).
        depth: the wanted depth (m).

    Returns:
        The depth (m), at most ``depth``.
    """
    from ..errors import LegkinError

    soles = _soles(robot, np.array(robot.q0, dtype=float))
    best = 0.0
    qs = [q for _, q, _ in soles]
    for k in range(1, DEPTH_STEPS + 1):
        dz = depth * k / DEPTH_STEPS
        try:
            qs = [leg.ik(_raised(leg, start, dz), q_near=q) for (leg, _, start), q in zip(soles, qs)]
        except LegkinError:
            break
        best = dz
    return best


def squat(robot: Any, frames: int = FRAMES, depth: float | None = None) -> list[np.ndarray]:
    """The pelvis goes ``depth`` down and back up (``dz = depth (1 - cos t) / 2``, one period) with every foot
    flat and fixed on the floor: each foot's target in the root frame is its pose (6-DOF legs: the 4x4 pose,
    3-DOF legs: the position) at ``robot.q0`` raised by ``dz``, solved by ``ik(target, q_near=previous frame's)``.
    With a free flyer (``legkin.load(name, floating=True)``, ``legkin view --floating``) the base is first raised
    so that the lowest foot is on the floor, then goes down by ``dz``: the feet stay where they are in the world;
    on a fixed base the feet rise instead.

    ``depth`` (m): None for :func:`squat_depth` (:data:`SQUAT_DEPTH`, or less where the legs cannot: romeo's and
    simple_humanoid's standing poses are near their limits).

    Raises:
        UnreachableError, JointLimitError: a target out of a leg's reach or limits (a given ``depth`` too large).
    """
    q0 = np.array(robot.q0, dtype=float)
    depth = squat_depth(robot) if depth is None else depth
    soles = _soles(robot, q0)
    for leg, q, _ in soles:  # the legs' start (moved inside the limits where robot.q0 is not)
        q0[list(leg.idx_q)] = q
    qs = np.tile(q0, (frames, 1))
    dz = 0.5 * depth * (1.0 - np.cos(np.linspace(0.0, 2.0 * np.pi, frames, endpoint=False)))
    if robot.model.njoints > 1 and robot.model.joints[1].shortname() == "JointModelFreeFlyer":
        qs[:, 2] += _floor_offset(robot, q0) - dz
    for leg, q, start in soles:
        for k in range(frames):
            q = leg.ik(_raised(leg, start, dz[k]), q_near=q)
            qs[k, list(leg.idx_q)] = q
    return list(qs)


ANIMATIONS = {"feet_circles": feet_circles, "squat": squat}
