"""The hybrid leg on the ground (:func:`ground_model`, found by :func:`legkin.mjcf.ground.ground_model`): a fixed
mechanism, so not a robot that stands; its foot presses on a floor put under it (the ``press`` scenario of
:mod:`legkin.mjcf.scenarios`).

Contact geometry: the URDF's foot sphere (radius 0.018 m at the foot frame FCS), alone (:class:`HybridGround`).
Predicted contact: :func:`.fk` of the motor angles (theta1, theta2 and theta0 from LL by
:func:`.extension_motor_angle`) minus the radius along z; holding it: :func:`.foot_platform_ik` (theta_LL, roll,
pitch) closed by :func:`.configuration.closed_configuration`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..mjcf.ground import ContactGeom, GroundModel, sphere_radius

__all__ = ["ground_model", "HybridGround", "FOOT_FRAME"]

#: The foot frame, whose URDF collision sphere is the contact.
FOOT_FRAME = "FCS"


class HybridGround(GroundModel):
    """The hybrid leg's foot on a floor (module docstring).

    Args:
        robot: ``legkin.load("hybrid_leg")`` (fixed base).
    """

    def __init__(self, robot: Any) -> None:
        self.robot = robot
        self.fixed_base = True
        self.radius = sphere_radius(robot, FOOT_FRAME)
        self.no_squat = "a fixed mechanism: its foot presses on the floor (scenario press)"
        # only the foot meets the floor: the motor housings and levers hang 0.17 m below the foot in CCS, where a
        # floor under the foot would cut through them (38 contacts, 0.15 m deep, measured)
        self.collision_skip = frozenset(g.name for g in robot.collision_model.geometryObjects)

    def geoms(self) -> list[ContactGeom]:
        """The foot sphere at FCS."""
        model = self.robot.model
        frame = model.frames[model.getFrameId(FOOT_FRAME)]
        return [ContactGeom("foot_contact", frame.parentJoint, "sphere", (self.radius,), frame.placement)]

    def motors(self, q: np.ndarray) -> np.ndarray:
        """(theta1, theta2, theta0) (rad) of a configuration ``q``."""
        from .kinematics import extension_motor_angle

        r = self.robot
        return np.array([q[r.idx_q("MCS1")], q[r.idx_q("MCS2")],
                         float(extension_motor_angle(q[r.idx_q("LL")], geometry=r.geometry))])

    def contacts(self, q: np.ndarray) -> np.ndarray:
        """(1, 3) the foot sphere's lowest point (legkin's :func:`.fk`), base frame (m)."""
        from .kinematics import fk

        return (np.asarray(fk(self.motors(q), geometry=self.robot.geometry)) - [0.0, 0.0, self.radius])[None, :]

    def contact_frames(self, q: np.ndarray) -> list[tuple[tuple[str, ...], float]]:
        """The foot frame and its sphere's radius."""
        return [((FOOT_FRAME,), self.radius)]

    def hold(self, q: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """The closed configuration whose foot sphere's lowest point is ``targets[0]`` (:func:`.foot_platform_ik`,
        its first branch inside the limits)."""
        from .configuration import closed_configuration
        from .kinematics import foot_platform_ik

        centre = np.asarray(targets, dtype=float)[0] + [0.0, 0.0, self.radius]
        ll, roll, pitch = np.asarray(foot_platform_ik(centre, geometry=self.robot.geometry), dtype=float)
        return closed_configuration(self.robot, np.array([[roll, pitch]]), np.array([ll]))[0]


def ground_model(robot: Any) -> HybridGround:
    """The :class:`HybridGround` of ``legkin.load("hybrid_leg")``.

    Args:
        robot: the hybrid leg, fixed base.

    Returns:
        its ground model.
    """
    return HybridGround(robot)
