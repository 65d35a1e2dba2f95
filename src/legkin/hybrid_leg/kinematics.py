"""Closed-form kinematics of the hybrid leg: a 2-RSS + centre platform, its extension joint and foot (seed 003).

The public API, re-exported from the modules that implement it (each kernel beside its seed equations):

* :mod:`.geometry`: :class:`Geometry` (``center``, ``starting_value``), the fixed constants, tolerances, limits;
* :mod:`.extension`: eq 19 (:func:`ll_angle`, :func:`extension_motor_angle`);
* :mod:`.platform`: the motor chains of a platform pose (eqs 2-16): :func:`motor_angles`, their Jacobian, the
  assembly mode, rod spans; :mod:`.rotation`: the closed forms of a rotation matrix (either centre): motor angles,
  spherical joints, the spherical centre's free axis;
* :mod:`.forward`: the closed sub-chain's forward kinematics (:func:`platform_orientation`, :func:`platform_poses`;
  the degree-8 polynomial of :mod:`.polynomial`);
* :mod:`.foot`: the foot (eqs 17, 18, 20), the leg's forward kinematics :func:`fk` and :func:`jacobian`;
* :mod:`.foot_inverse`: the foot IK :func:`ik`, :func:`ik_all` (every branch; :func:`ik_branches` with their modes),
  :func:`foot_platform_ik`.

Assembly modes: :func:`fk`, :func:`jacobian`, :func:`platform_orientation` and :func:`ik` take ``branch`` and
``assembly`` (:func:`assembly_mode`), by default ``(1, 1)`` and ``+1``, the mode of the SRDF reference pose
``neutral``; the IK-only branches ``ll_branch``, ``roll_branch`` are searched in :data:`FOOT_IK_ORDER`
(docs/hybrid_leg.md, "IK contract").

Every function takes arrays with leading batch dimensions. A single input (the core shape exactly) returns plain
arrays and raises on failure; a batch returns NaN where an item fails, and ``return_mask=True`` also returns the
boolean mask of successes.
"""

from __future__ import annotations

from .extension import extension_motor_angle, ll_angle
from .foot import fk, foot_position_from_platform, jacobian
from .foot_inverse import FootIKSolutions, foot_platform_ik, ik, ik_all, ik_branches
from .forward import PlatformPoses, platform_orientation, platform_poses
from .geometry import (
    ARC_RADIUS,
    ATTACH,
    BETA,
    BOUNDARY_TOL,
    CENTER,
    CLIP_FOOT_TOL,
    FK_GAIN_MAX,
    FOOT_IK_BRANCHES,
    FOOT_IK_ORDER,
    FOOT_X,
    IK_K_TOL,
    K_TOL,
    LEVER,
    LL_DELTA,
    LL_LIMIT,
    LL_ORIGIN,
    LL_TOL,
    MOTOR_BRANCHES,
    MOTOR_LIMIT,
    MOTOR_POS,
    MOTOR_YAW,
    PITCH_SPLIT,
    PLATFORM_LIMIT,
    RATIO,
    RHO_TOL,
    ROD_LENGTH,
    SCREW_LEAD,
    Geometry,
)
from .platform import assembly_mode, motor_angles, motor_jacobian, platform_rotation, rod_spans
from .rotation import motor_angles_from_rotation, sphere_joint_angles, spherical_free_axis

__all__ = [
    # the API of docs/api.md
    "Geometry", "fk", "ik", "ik_all", "jacobian", "ik_branches", "FootIKSolutions",
    # the closed sub-chain, the extension joint, the foot
    "ll_angle", "extension_motor_angle", "platform_rotation", "rod_spans", "motor_angles",
    "motor_angles_from_rotation", "motor_jacobian", "sphere_joint_angles", "spherical_free_axis", "assembly_mode",
    "platform_orientation", "platform_poses", "PlatformPoses", "foot_position_from_platform", "foot_platform_ik",
    # constants
    "CENTER", "BETA", "MOTOR_POS", "MOTOR_YAW", "LEVER", "ROD_LENGTH", "ATTACH", "LL_ORIGIN", "FOOT_X", "SCREW_LEAD",
    "ARC_RADIUS", "RATIO", "MOTOR_BRANCHES", "FOOT_IK_BRANCHES", "LL_DELTA", "K_TOL", "IK_K_TOL", "CLIP_FOOT_TOL",
    "BOUNDARY_TOL", "LL_TOL", "RHO_TOL", "PLATFORM_LIMIT", "LL_LIMIT", "MOTOR_LIMIT", "FK_GAIN_MAX", "PITCH_SPLIT",
    "FOOT_IK_ORDER",
]
