"""Clips of the external quadrupeds (``legkin view go2 --animate feet_circles``), driven by :meth:`Leg.ik`."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ANIMATIONS", "feet_circles", "circle_points", "FRAMES", "RADIUS", "LIMIT_MARGIN"]

#: Frames of one turn and the circles' radius (m).
FRAMES = 60
RADIUS = 0.03
#: A standing pose outside the limits is moved this fraction of each limit range inside them.
LIMIT_MARGIN = 0.1


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
        q = q0[cols]
        if not leg.within_limits(q):
            margin = LIMIT_MARGIN * (leg.upper - leg.lower)
            q = np.clip(q, leg.lower + margin, leg.upper - margin)
        for k, p in enumerate(circle_points(leg.fk(q), frames, radius)):
            q = leg.ik(p, q_near=q)
            qs[k, cols] = q
    return list(qs)


ANIMATIONS = {"feet_circles": feet_circles}
