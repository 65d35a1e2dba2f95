"""The quadruped leg's constants: POPI's link offsets and joint limits (seed 004), the branch order and a slack.

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
    "BRANCHES",
    "LIMIT_TOL",
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

#: Branch order of :func:`legkin.quadruped.ik_all`: (s_u, k) with s_u = -1 foot below the hip plane, k the
#: knee sign (the sign of acos K in q3).
BRANCHES = ((-1, -1), (-1, 1), (1, -1), (1, 1))

#: Default slack (rad) of :func:`legkin.quadruped.within_limits`.
LIMIT_TOL = 1e-9

#: Angle of the thigh offset: atan(|z23| / |x23|) = 0.1174 rad, the seed-002 servo zero offset.
KNEE_OFFSET = math.atan2(-Z23, -X23)

# ----------------------------------------------------------------------------- constants seen by the kernels
# numba freezes module globals into the compiled code: plain floats and tuples of floats (seed 002's kernels in
# :mod:`legkin.quadruped.textbook`; the samplers of :mod:`legkin.quadruped.configuration`).
PI = math.pi
L1 = math.hypot(X23, Z23)  # |t23|, the thigh
SX = (1.0, -1.0, 1.0, -1.0)  # per leg index (LEGS order): front / hind
SY = (1.0, 1.0, -1.0, -1.0)  # left / right

# Kernel status code (OK = 0, legkin._kernels.OK).
BAD_INPUT = 3  # a NaN/inf entry in the first array argument
