"""Wheel-leg (Corgi, seed 001) kinematics: closed-form leg linkage, rim contact point, contact Jacobian, IK.

Conventions (metres, radians at every API, theta included):

* Robot frame {R}: x front, y left, z up. Legs ``"FL"``, ``"FR"``, ``"RR"``, ``"RL"`` = indices 0-3 of the
  design notes (left: 0, 3; right: 1, 2). Module origin ``(+-L_body/2, +-W_body/2, d_abad)``.
* Module frame {M}: ``R_R^M(gamma) = R0 Rz(gamma)`` with ``R0`` = (x_M, y_M, z_M) = (+y_R, +z_R, +x_R) on the left,
  (-y_R, +z_R, -x_R) on the right, so z_M = +x_R (left) / -x_R (right) as in "Coord definitions".
* Leg frame {L}: origin ``(d_wheel, 0, 0)`` in {M}; the seed's ``T_L^M`` (left: x_L = -z_M, y_L = y_M,
  z_L = x_M; right: x_L = z_M, y_L = y_M, z_L = -x_M). At gamma = 0 every leg has x_L = -x_R, y_L = +z_R,
  z_L = +y_R, so +w points outward on left legs and inward on right legs, gamma > 0 swings the foot
  outward on both sides, and beta > 0 moves the foot backward.
* Leg plane: complex numbers ``x + i y`` in {L}; the closed form is written for the left half with the
  leg axis along +x and rotated by ``exp(i (beta + pi/2))``; right-half points are the complex conjugates
  before that rotation. Leg-frame points are returned as ``(x, y, w)``.
* Motors: ``phi_L = beta + (theta - theta0)``, ``phi_R = beta - (theta - theta0)``, theta0 = 17 deg;
  theta in [17 deg, 160 deg].
* Rim parameter alpha: 0 at the toe G, alpha > 0 towards the right half (counter-clockwise in {L}),
  alpha in [-pi, pi]; alpha = +-pi are the rim tips H_R / H_L (which meet only in wheel mode).

Files: :mod:`.geometry` (constants, :class:`Geometry`), :mod:`.linkage` (closed form), :mod:`.rim` (rim
contact points in {L}), :mod:`.frames` (frames, :func:`fk`, :func:`jacobian`), :mod:`.inverse` (:func:`ik`,
:func:`ik_all`), :mod:`.ik_radial`, :mod:`.ik_iterative`, :mod:`.tyre` (the tyre surface), :mod:`.ground`
(:func:`ground_contact`, :func:`stance_ik`). This module re-exports the public API.

A single input returns plain arrays and raises on failure; a batch (leading dimensions) returns NaN where
an item fails, and ``return_mask=True`` also returns the mask of successes.
"""

from __future__ import annotations

from .frames import fk, jacobian, leg_frame_to_robot, module_origin
from .geometry import (
    ABAD_LIMIT,
    LEGS,
    PSI_FG,
    THETA0,
    THETA_MAX,
    THETA_MIN,
    TYRE_THICKNESS,
    Geometry,
)
from .ground import GroundContact, ground_contact
from .inverse import IKInfo, IKOptions, ik, ik_all
from .linkage import (
    PASSIVE_JOINTS,
    POINTS,
    linkage_constants,
    linkage_points,
    motor_angles,
    passive_angles,
    theta_beta,
)
from .rim import rim_jump_seed, rim_point, rim_point_seed, rim_segment
from .stance import stance_ik, stance_ik_all
from .tyre import TyrePieces, tyre_length, tyre_pieces, tyre_point

__all__ = [
    "LEGS",
    "THETA0",
    "THETA_MIN",
    "THETA_MAX",
    "PSI_FG",
    "TYRE_THICKNESS",
    "ABAD_LIMIT",
    "Geometry",
    "linkage_constants",
    "POINTS",
    "PASSIVE_JOINTS",
    "linkage_points",
    "passive_angles",
    "motor_angles",
    "theta_beta",
    "rim_point",
    "rim_point_seed",
    "rim_jump_seed",
    "rim_segment",
    "fk",
    "jacobian",
    "leg_frame_to_robot",
    "module_origin",
    "ik",
    "ik_all",
    "IKOptions",
    "IKInfo",
    "tyre_point",
    "tyre_pieces",
    "tyre_length",
    "TyrePieces",
    "ground_contact",
    "GroundContact",
    "stance_ik",
    "stance_ik_all",
]
