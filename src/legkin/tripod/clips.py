"""Tripod clips: the platform sweeps the boundary of its reachable set, every frame from the closed-form IK."""

from __future__ import annotations

import numpy as np

from . import kinematics as at
from .configuration import closed_configuration, robot_configuration

#: How far inside the legs' singular curves sin q_K2 = 0 the sweep stays (rad of tilt).
MARGIN = 0.05
#: Largest tilt of the sweep (rad): the boundary touches the platform singularity 1 + c_y c_z = 0 (tilt pi) in
#: six directions for the default geometry; the platform centre swings round fast there, so the clip cuts the
#: corners at pi - 0.3 rad (163 deg).
TILT_CAP = np.pi - 0.3


def _geometry(robot) -> at.Geometry:
    return at.Geometry.from_params(robot.params)


def boundary_path(robot, dense: int = 2001) -> tuple[np.ndarray, np.ndarray]:
    """(alpha_y, alpha_z) of a closed path just inside the workspace boundary, ``dense`` points.

    The boundary in tilt coordinates is ``theta = tilt_max(phi)`` (:func:`legkin.tripod.workspace`,
    axis ``R e_x = (cos theta, sin theta cos phi, sin theta sin phi)``); the path is
    ``theta = min(tilt_max - MARGIN, TILT_CAP)``, mapped to (alpha_y, alpha_z) by ``orientation_from_axis``.
    """
    geo = _geometry(robot)
    ws = at.workspace(geometry=geo, n=3, m=dense)
    theta = np.minimum(ws.tilt_max - MARGIN, TILT_CAP)
    phi = ws.phi
    axis = np.stack([np.cos(theta), np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi)], axis=-1)
    return at.orientation_from_axis(axis)


def workspace_boundary(robot, frames: int = 150) -> list[np.ndarray]:
    """The platform sweeps once round (just inside) the boundary of its reachable (alpha_y, alpha_z) set.

    The path of :func:`boundary_path` is resampled at equal steps of joint-space arc length, so the legs move
    at an even pace (the tilt direction turns fast where the boundary bends). Every frame is ``ik`` (eqs 98,
    102) of the analytic module: the loops are closed to rounding.
    """
    geo = _geometry(robot)
    ay, az = boundary_path(robot)
    q = closed_configuration(ay, az, geometry=geo)  # (dense, 12); raises nothing for a batch: NaN if a point failed
    if not np.all(np.isfinite(q)):
        raise RuntimeError("tripod workspace_boundary: the boundary path left the workspace")  # pragma: no cover
    step = np.linalg.norm(np.angle(np.exp(1j * np.diff(q, axis=0))), axis=-1)  # wrapped joint steps
    s = np.concatenate([[0.0], np.cumsum(step)])
    pick = np.searchsorted(s, np.linspace(0.0, s[-1], frames, endpoint=False))
    q_frames = closed_configuration(ay[pick], az[pick], geometry=geo)
    return list(robot_configuration(robot, q_frames))


ANIMATIONS = {"workspace_boundary": workspace_boundary}
