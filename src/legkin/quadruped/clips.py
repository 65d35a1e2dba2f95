"""Quadruped clips: every foot traces a circle, solved by the closed-form IK at each frame."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import kinematics as aq
from .configuration import leg_slice


def foot_circles(robot: Any, frames: int = 90, radius: float = 0.06) -> list[np.ndarray]:
    """Feet trace vertical circles (radius 6 cm) around their standing positions, legs half a turn apart."""
    t = np.linspace(0.0, 2.0 * np.pi, frames, endpoint=False)
    qs = np.tile(robot.q0, (frames, 1))
    for k, leg in enumerate(aq.LEGS):
        cols = leg_slice(robot, leg)
        q_stand = robot.q0[cols]
        centre = aq.fk(q_stand, leg, geometry=robot.geometry)
        phase = t + (np.pi if k in (1, 2) else 0.0)  # trot-like: LF/RH together, LH/RF together
        p = centre + radius * np.stack([np.cos(phase), np.zeros_like(t), np.sin(phase)], axis=-1)
        qs[:, cols] = aq.ik(p, leg, q_near=q_stand, geometry=robot.geometry)
    return list(qs)


ANIMATIONS = {"foot_circles": foot_circles}
