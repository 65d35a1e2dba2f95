"""The quadruped leg's constants: POPI's link offsets and joint limits (seed 004), and the IK's tolerances.

The link offsets are the values of POPI's xacro (``quadruped.urdf.xacro``), constants of the model: only
``foot_z`` is an xacro argument (see :class:`legkin.quadruped.Geometry`). Base frame: x forward, y left,
z up; metres, radians. Legs ``"LF"``, ``"LH"``, ``"RF"``, ``"RH"``; ``sx = +1`` front / ``-1`` hind,
``sy = +1`` left / ``-1`` right.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "LEGS",
    "X01",
    "Y01",
    "Z01",
    "Y12",
    "X23",
    "Z23",
    "X34",
    "JOINT_LIMITS",
    "REACH_TOL",
    "BRANCHES",
    "LIMIT_TOL",
    "LIMIT_SLACK",
    "CLIP_TOL",
    "KNEE_OFFSET",
]

LEGS = ("LF", "LH", "RF", "RH")

# Seed 004 offsets (m), POPI's xacro values: base_aile, aile_epaule, epaule_coude, coude_pied.
X01, Y01, Z01 = 0.3305, 0.175, -0.051
Y12 = 0.1077
X23, Z23 = -0.35192, -0.041509
X34 = 0.29604

#: Joint limits (POPI's), rows q1, q2, q3: (lower, upper) in rad.
JOINT_LIMITS = np.array([[-0.4, 0.4], [0.0, math.pi], [0.26, 1.92]])
JOINT_LIMITS.setflags(write=False)

#: Distance (m) by which a target may lie outside the reachable set and still be solved (on the boundary).
REACH_TOL = 1e-12

#: Branch order of :func:`legkin.quadruped.ik_all`: (s_u, k) with s_u = -1 foot below the hip plane, k the
#: knee sign.
BRANCHES = ((-1, -1), (-1, 1), (1, -1), (1, 1))

#: Default slack (rad) of :func:`legkin.quadruped.within_limits`, and of the representative choice of q2
#: near +-pi.
LIMIT_TOL = 1e-9
#: A branch of :func:`legkin.quadruped.ik` up to this far (rad) outside :data:`JOINT_LIMITS` is a candidate:
#: targets made at a limit come back a rounding error outside it, and near the abduction singularity
#: (rho -> 0) the joints err by up to ~rho / y12 <= 1.4e-8 rad along the singular direction (the foot itself
#: stays exact). Such a branch is clipped into the limits and the other joints re-solved (Gauss-Newton on the
#: foot position); it is kept only if the result is inside the limits and reproduces the target within
#: :data:`CLIP_TOL`.
LIMIT_SLACK = 1e-7
#: Largest foot error (m) of a branch clipped into the limits.
CLIP_TOL = 1e-12

#: Angle of the thigh offset: atan(|z23| / |x23|) = 0.1174 rad, the seed-002 servo zero offset.
KNEE_OFFSET = math.atan2(-Z23, -X23)

# ----------------------------------------------------------------------------- constants seen by the kernels
# numba freezes module globals into the compiled code: plain floats and tuples of floats.
PI = math.pi
TWO_PI = 2.0 * math.pi
Y12_SQ = Y12**2
L1 = math.hypot(X23, Z23)  # |t23|, the thigh
ALPHA = math.atan2(Z23, X23)  # direction of t23 in the thigh's x-z plane
LO = (float(JOINT_LIMITS[0, 0]), float(JOINT_LIMITS[1, 0]), float(JOINT_LIMITS[2, 0]))
HI = (float(JOINT_LIMITS[0, 1]), float(JOINT_LIMITS[1, 1]), float(JOINT_LIMITS[2, 1]))
SX = (1.0, -1.0, 1.0, -1.0)  # per leg index (LEGS order): front / hind
SY = (1.0, 1.0, -1.0, -1.0)  # left / right
SU = (-1.0, -1.0, 1.0, 1.0)  # BRANCHES, s_u column
KS = (-1.0, 1.0, -1.0, 1.0)  # BRANCHES, k column
#: Rank cut of the Gauss-Newton steps of the clip repair (numpy ``pinv``'s ``rcond``).
RCOND = 1e-10

# Kernel status codes (OK = 0, legkin._kernels.OK).
UNREACHABLE = 1
JOINT_LIMIT = 2
BAD_INPUT = 3  # a NaN/inf entry in the first array argument
BAD_REF = 4  # a NaN/inf entry in q_near
