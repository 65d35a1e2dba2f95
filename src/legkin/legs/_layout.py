"""Constants of the leg kinematics (:mod:`legkin.legs.kinematics`): tolerances, the branch order, the layout of
the geometry array :attr:`Leg.params` the kernels read, and the kernels' status codes."""

from __future__ import annotations

import math

#: |a1 . a2| (HAA vs HFE axis) above this is "not perpendicular" (rad, ~ the angle's deviation).
PERPENDICULAR_TOL = 1e-9
#: |a2 x a3| (HFE vs KFE axis) above this is "not parallel".
PARALLEL_TOL = 1e-9
#: The closed form's own reach slack (m): a branch is polished until its foot is this close.
REACH_TOL = 1e-12
#: Default ``tol`` of :meth:`Leg.ik` / :meth:`Leg.ik_all` (m) and of :class:`~legkin.legs.Leg6`'s pose error (m and
#: rad): a target up to this far outside the reachable set is solved at its nearest reachable point. Why 1e-7: a
#: target rounded to float32 (a simulator's, a sensor's) moves each coordinate in [0.5, 1) m by up to 2^-25 m, so a
#: foot within 1 m of the root by up to sqrt(3) 2^-25 = 5.2e-8 m, and near a stretched knee or a joint limit that
#: lands outside the reachable set; a float32 rotation matrix (entries rounded by <= 2^-25) is turned by at most
#: 3 2^-25 / sqrt(2) = 6.3e-8 rad, so a float32 4x4 pose is off by <= 8.2e-8 (m and rad combined) < 1e-7. Targets
#: farther out are refused (UnreachableError); pass a smaller ``tol`` (down to the solvers' 1e-12) for a tighter
#: check of exact float64 targets.
IK_TOL = 1e-7
#: A joint angle up to this far (rad) outside the URDF limits is clipped onto the limit when re-solving the other
#: joints (LIMIT_SLACK) does not reach the target (the foot then moves by at most LIMIT_TOL x the leg's reach).
LIMIT_TOL = 1e-10
#: A branch up to this far (rad) outside the limits is moved into them and its other joints re-solved (kept if it
#: still reaches the target within REACH_TOL): near the abduction singularity a branch's q1 errs by up to ~1e-8 rad.
LIMIT_SLACK = 1e-7
#: A closed-form branch (before its polish) up to this far (rad) outside the limits is a candidate of the limits-first
#: :meth:`Leg.ik` (the polish moves an angle by ~1e-15 rad, up to ~1e-8 near the abduction singularity).
CANDIDATE_SLACK = LIMIT_SLACK + 1e-6
#: How far (rad) beyond the HAA limits the arc test of the limits-first IK (:data:`_ARC`) still keeps a branch: more
#: than CANDIDATE_SLACK, so that the exact test on the angle, not the rounding of a cross product, decides there.
ARC_SLACK = CANDIDATE_SLACK + 1e-6
#: Damped Newton steps (at most) polishing each closed-form branch on the exact forward map (see _polish_k).
POLISH_STEPS = 24
#: Damping (m) of the polishing steps: bounds a step to ~|e| / (2 lambda) rad near a singularity.
POLISH_DAMPING = 1e-7
#: On a leg with the exact ideal structure (:data:`_IDEAL`), a closed-form branch is returned unpolished (no
#: forward-map evaluation) when it is this far from the singular sets: ``t >= WELL_CONDITIONED r`` (abduction:
#: ``t = |u3|``, ``r`` the target's distance to the HAA axis) and ``|w| >= WELL_CONDITIONED (|k| + |l|)`` (knee
#: fold), and not on the reach boundary. Measured there: foot error <= 7.6e-16 m < POLISH_BELOW on the 12 legs of
#: POPI, go2 and solo12 (200000 joint vectors uniform in [-3.2, 3.2]^3 each, every branch; at 1e-2: 1.7e-15 m).
WELL_CONDITIONED = 3e-2
#: Foot error (m) below which a branch is not polished (a few ulps of a 1 m reach).
POLISH_BELOW = 1e-15
_POLISH_DONE = POLISH_BELOW**2
#: Branch order of :meth:`Leg.ik_all`: ``(s_a, s_k)``, the abduction sign (sign of ``u3``, the foot's
#: coordinate along ``e3 = a1 x a2`` in the abduction frame) and the knee sign (sign of ``beta``).
BRANCHES = ((-1, -1), (-1, 1), (1, -1), (1, 1))

# ---------------------------------------------------------------- layout of the geometry array (Leg.params)
_O, _E1, _E2, _E3 = 0, 3, 6, 9  # o1, e1, e2, e3 (3 each)
_D = 12  # lateral offset d
_H, _K, _L = 13, 15, 17  # h, k, l in pitch-plane coordinates (X, Y)
_S3 = 19  # knee axis sign
_KN, _LN, _PK, _PL = 20, 21, 22, 23  # |k|, |l|, phi_k, phi_l
_LO, _HI = 24, 27  # lower, upper limits (3 each)
_A1, _A2, _A3 = 30, 33, 36  # the measured unit axes a1, a2, a3 (exact forward map)
_V21, _V32, _V3F = 39, 42, 45  # o2 - o1, o3 - o2, f - o3
_SLACK = 48  # reach slack of the ideal structure: REACH_TOL + its deviation bound (see Leg.from_geometry)
_IDEAL = 49  # 1.0 if the measured axes are exactly (in floats) the ideal structure: a1 . a2 = 0 and a2 x a3 = 0
_CD, _SD = 50, 51  # cos, sin (phi_k - phi_l): the knee's offset angle (the hip pitch without trigonometric calls)
#: The HAA limits as an arc of the circle, widened by ARC_SLACK: cos, sin of its start and end, and its kind
#: (_WHOLE, _NARROW: shorter than pi, _WIDE: from pi to 2 pi); the limits-first IK drops an abduction branch whose
#: q1 lies off the arc before computing the angle (two cross products instead of an atan2).
_ARC = 52
_REF = 57  # q_ref (3): the default reference of Leg.ik / Leg.ik_all (a single call passes no reference array)
_NPARAMS = 60
_WHOLE, _NARROW, _WIDE = 0.0, 1.0, 2.0

_TWO_PI = 2.0 * math.pi
_INV_TWO_PI = 1.0 / _TWO_PI  # (a product: a division costs ~20 cycles of latency in the branch choice)
_NAN = math.nan

# kernel status codes (OK = 0)
_UNREACHABLE = 1
_JOINT_LIMIT = 2
_BAD_INPUT = 3
# reasons of _UNREACHABLE (info[1])
_IN_CYLINDER = 1.0
_TOO_FAR = 2.0
_TOO_NEAR = 3.0
