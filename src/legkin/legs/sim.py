"""The ground model of a robot with legs (:func:`ground_model`, found by :func:`legkin.mjcf.ground.ground_model`):
a sphere per foot at its foot frame, legkin's leg FK for where it touches the ground and its leg IK to hold it."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..mjcf.ground import Foot, FootGround, sphere_radius
from .extract import from_model

__all__ = ["ground_model", "supports"]


def supports(name: str) -> bool:
    """Whether the foot-sphere ground model serves the robot ``name``.

    Args:
        name: a registry name of :mod:`legkin.legs`.

    Returns:
        True for the quadrupeds (:data:`legkin.legs.ERD_ROBOTS`: four point feet); the bipeds (flat feet, or
        bolt's point feet, which cannot stand) have no ground model yet.
    """
    from .erd import ERD_ROBOTS

    return name in ERD_ROBOTS


def ground_model(robot: Any) -> FootGround:
    """Feet of the legs :func:`legkin.legs.from_model` finds in ``robot.model`` (a floating robot).

    Args:
        robot: ``legkin.load(name, floating=True)``.

    Returns:
        a :class:`~legkin.mjcf.ground.FootGround`: foot spheres of the URDF's collision radius
        (:func:`~legkin.mjcf.ground.sphere_radius`), :meth:`legkin.legs.Leg.fk` and :meth:`legkin.legs.Leg.ik`.
    """
    legs = from_model(robot.model)
    feet = [Foot(name, leg.foot_frame, sphere_radius(robot, leg.foot_frame), tuple(leg.idx_q))
            for name, leg in legs.items()]

    def fk(name: str, q_leg: np.ndarray) -> np.ndarray:
        return np.asarray(legs[name].fk(q_leg), dtype=float)

    def ik(name: str, p: np.ndarray, q_near: np.ndarray) -> np.ndarray:
        return np.asarray(legs[name].ik(p, q_near=q_near), dtype=float)

    return FootGround(robot, feet, fk, ik)
