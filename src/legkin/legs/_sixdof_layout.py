"""Constants of the 6-DOF legs (:mod:`legkin.legs.sixdof`): tolerances, the layout of the geometry array
:attr:`Leg6.params` the kernels read, the structure codes and the kernels' status codes."""

from __future__ import annotations

from ._layout import _BAD_INPUT, _JOINT_LIMIT, _UNREACHABLE, IK_TOL

__all__ = ["_BAD_INPUT", "_JOINT_LIMIT", "_UNREACHABLE", "IK_TOL"]

#: Two joint axes closer than this (m) count as intersecting; a unit-axis cross product below it, as parallel (rad).
#: URDF angles written with 4-6 digits (icub: ``rpy="... 1.5708 ..."``) leave axes up to ~2e-5 m / rad off the
#: ideal; the closed form then lands that close and the Newton polish (:data:`POLISH_STEPS6`) finishes the job.
AXIS_TOL = 1e-4
# IK_TOL (default ``tol`` of Leg6.ik / Leg6.ik_all, 1e-7, derived in ._layout): a pose is solved when the polished
# answer reproduces it to this (m and rad, the norm of the 6-vector position error, rotation error); Leg's default.
#: A solution up to this far outside the URDF limits (rad) is clipped onto them and kept if it still reproduces the
#: target to ``tol``: a target rounded to float32 next to a limit (near a stretched knee its solution moves by up to
#: ~sqrt(1e-7) rad) is then solved at the nearest in-limit pose.
LIMIT_SLACK6 = 1e-4
#: Damped Newton steps (at most) of the polish on the exact forward map.
POLISH_STEPS6 = 12
#: Damping of the polish steps (m): bounds a step near a singularity.
POLISH_DAMPING6 = 1e-9
#: Pose error (m and rad) below which the polish stops (the closed form of an exact structure lands at ~1e-15).
POLISH_BELOW6 = 1e-13
#: Rows of :meth:`Leg6.ik_all` by structure: the closed form of a spherical hip has at most 8 solutions; the
#: one-dimensional search of three parallel axes keeps at most 16 (a 6R chain has at most 16).
_NSOL = 8
_NSOL_SEARCH = 16
#: Grid of the one-dimensional search by structure (points over a full turn of the searched joint): each cell between
#: two grid points is settled by a curvature bound or bisected (see :mod:`._search_kernels`), so the grid sets the
#: speed more than the completeness. g1 (offset hip): 60 points (42 us a target; 90 took 50 us; the sampled
#: configuration among ik_all's rows on every one of 10^6 random in-limit samples per leg at 60 points, docs/legs.md);
#: alexander keeps 360.
SEARCH_GRID = {"6R-three-parallel": 360, "6R-offset-hip": 60}
#: A dip of the search residual to within this (m) of zero without a sign change is kept as a tangential root (the
#: polish then decides).
TANGENT_TOL = 1e-9

#: Structure codes (params[_KIND]).
HIP_SPHERICAL = 1.0
THREE_PARALLEL = 2.0
OFFSET_HIP = 3.0

# ---------------------------------------------------------------- layout of the geometry array (Leg6.params)
_AX = 0  # the six unit axes a_j at the neutral configuration (root frame), 3 each
_OR = 18  # a point o_j of each axis (the joint's origin), 3 each
_M0 = 36  # the foot pose at the neutral configuration: rotation (9, row-major), then position (3)
_HIP = 48  # the hip centre c (the point nearest axes 1-3)
_ANK = 51  # the ankle centre a (the point nearest axes 5, 6)
_LO6, _HI6 = 54, 60  # the URDF limits (6 each)
_KIND = 66  # the structure code
_NSOLS = 67  # the rows of ik_all
_GRID = 68  # the grid points of the one-dimensional search (0: none)
_QREF = 69  # the default reference q_ref (6): the single call's fast path reads it here
_NP6 = 75
