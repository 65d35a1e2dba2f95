"""Wheel-leg clips: all four legs transform from wheel mode to leg mode and back, every frame in closed form."""

from __future__ import annotations

import math

import numpy as np

from . import kinematics as wl
from .configuration import uniform_configuration


def transform(robot, frames: int = 90) -> list[np.ndarray]:
    """Wheel mode (theta = 17 deg) to leg mode (theta = 160 deg) and back, beta = 0, all four legs.

    ``theta(t) = 17 deg + (160 deg - 17 deg) (1 - cos 2 pi t) / 2`` over one period (eased at both ends),
    so the clip loops seamlessly.
    """
    t = np.arange(frames) / frames
    theta = wl.THETA_MIN + (wl.THETA_MAX - wl.THETA_MIN) * 0.5 * (1.0 - np.cos(2.0 * math.pi * t))
    return list(uniform_configuration(robot, theta))


ANIMATIONS = {"transform": transform}
