"""Hybrid-leg clips: the leg extends and its platform tilts in roll and pitch, every frame in closed form."""

from __future__ import annotations

import math

import numpy as np

from . import kinematics as ah
from .configuration import closed_configuration
from .geometry import Geometry

#: Roll and pitch amplitudes of the clip (rad): inside the reachable set and clear of the parallel
#: singularity of motor branch (+1, +1) (see ``hybrid_leg_workspace.png``).
ROLL_AMPLITUDE = math.radians(30.0)
PITCH_AMPLITUDE = math.radians(20.0)
#: Extension-motor travel (rad): 4 turns, LL from 0 to -0.187 rad (the SRDF pose ``extended``).
EXTENSION = 8.0 * math.pi
BRANCH = (1, 1)


def tilt_path(frames: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """(roll, pitch) of the clip: a figure of eight ``roll = A sin 2 pi t``, ``pitch = B sin 4 pi t``, t in [0, 1)."""
    t = np.arange(frames + 1) / frames
    return ROLL_AMPLITUDE * np.sin(2.0 * math.pi * t), PITCH_AMPLITUDE * np.sin(4.0 * math.pi * t)


def configurations(robot, roll, pitch, theta_ll, branch=BRANCH) -> np.ndarray:
    """Configurations (n, nq) closing both loops: universal centre at (roll, pitch), LL at ``theta_ll``.

    Built by :func:`legkin.hybrid_leg.configuration.closed_configuration` (motors and lever-tip spherical joints in
    closed form). For the spherical-centre model, its third centre joint ``LCS_z`` keeps its ``q0`` value.
    """
    angles = [np.ravel(roll), np.ravel(pitch)]
    if robot.model.existJointName("LCS_z"):
        angles.append(np.full(angles[0].shape, robot.q0[robot.idx_q("LCS_z")]))
    qs = closed_configuration(robot, np.stack(angles, axis=-1), np.ravel(theta_ll), branch)
    if not np.all(np.isfinite(qs)):
        raise RuntimeError("hybrid_leg clip: a pose of the path is out of the motors' reach")  # pragma: no cover
    return qs


def extend_and_tilt(robot, frames: int = 120) -> list[np.ndarray]:
    """The extension motor turns 4 times out and back while the platform draws a figure of eight in (roll, pitch).

    ``theta0(t) = 8 pi (1 - cos 2 pi t) / 2`` drives LL by eq 19 (:func:`~legkin.hybrid_leg.ll_angle`),
    ``(roll, pitch)`` follows :func:`tilt_path` on motor branch (+1, +1); the clip loops seamlessly.
    """
    roll, pitch = tilt_path(frames)
    roll, pitch = roll[:-1], pitch[:-1]
    t = np.arange(frames) / frames
    theta0 = EXTENSION * 0.5 * (1.0 - np.cos(2.0 * math.pi * t))
    theta_ll = ah.ll_angle(theta0, geometry=Geometry.from_params(robot.params))
    return list(configurations(robot, roll, pitch, theta_ll))


ANIMATIONS = {"extend_and_tilt": extend_and_tilt}
