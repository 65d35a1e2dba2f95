"""Wheel-leg clips: all four legs transform from wheel mode to leg mode and back, every frame in closed form."""

from __future__ import annotations

import math

import numpy as np

from . import kinematics as wl


def leg_configurations(robot, theta: np.ndarray, beta: np.ndarray | float = 0.0, gamma: np.ndarray | float = 0.0):
    """Configurations (n, nq) with every leg at (theta, beta, gamma) (each (n,) or scalar), loops closed.

    Every tree joint of a leg comes from :func:`legkin.wheel_leg.passive_angles` (the closed form of
    the linkage); the ABAD joint is gamma; anything else (a free-flyer base) keeps its value in ``robot.q0``.
    """
    geo = wl.Geometry.from_params(robot.params)
    theta = np.asarray(theta, dtype=float)
    beta, gamma = np.broadcast_to(beta, theta.shape), np.broadcast_to(gamma, theta.shape)
    qs = np.tile(robot.q0, theta.shape + (1,))
    angles = wl.passive_angles(theta, beta, geometry=geo)
    for leg in wl.LEGS:
        for joint, value in angles.items():
            qs[..., robot.idx_q(f"{leg}_{joint}")] = value
        qs[..., robot.idx_q(f"{leg}_abad")] = gamma
    return qs


def transform(robot, frames: int = 90) -> list[np.ndarray]:
    """Wheel mode (theta = 17 deg) to leg mode (theta = 160 deg) and back, beta = 0, all four legs.

    ``theta(t) = 17 deg + (160 deg - 17 deg) (1 - cos 2 pi t) / 2`` over one period (eased at both ends),
    so the clip loops seamlessly.
    """
    t = np.arange(frames) / frames
    theta = wl.THETA_MIN + (wl.THETA_MAX - wl.THETA_MIN) * 0.5 * (1.0 - np.cos(2.0 * math.pi * t))
    return list(leg_configurations(robot, theta))


ANIMATIONS = {"transform": transform}
