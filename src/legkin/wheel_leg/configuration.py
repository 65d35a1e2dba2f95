"""Helpers the rest of the package (checks, bench, clips, contract) and users need: closed Pinocchio
configurations from the analytic angles, joint names, samplers of in-limit joints and of targets, the contact
point in its rim link's frame and the iterative IK's geometric start."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .frames import _context, fk
from .geometry import ABAD_LIMIT, LEGS, THETA0, THETA_MAX, THETA_MIN, Geometry, _geometry
from .ik_iterative import starts
from .linkage import PASSIVE_JOINTS, linkage_points, passive_angles
from .rim import rim_point, rim_point_seed, rim_segment

__all__ = [
    "SEGMENT_LINKS",
    "PHI_LIMIT",
    "leg_joint_names",
    "configuration",
    "uniform_configuration",
    "sample_leg_q",
    "sample_q_in_limits",
    "within_limits",
    "sample_targets",
    "local_contact_point",
    "ik_start",
]

#: Rim link of each segment of :func:`~legkin.wheel_leg.rim_point` (index = :func:`rim_segment`) and the
#: hinge point where that link's frame sits.
SEGMENT_LINKS = (("rim_upper_L", "B_L"), ("rim_lower_L", "F_L"), ("rim_lower_R", "F_R"), ("rim_upper_R", "B_R"))
#: The URDF limit of the motor joints ``<leg>_phi_L``, ``<leg>_phi_R`` (rad): [-4 pi, 4 pi].
PHI_LIMIT = 4.0 * np.pi


def leg_joint_names(leg: str) -> list[str]:
    """The tree joints of one leg in the URDF: ``<leg>_abad`` and the 10 of :data:`PASSIVE_JOINTS`."""
    return [f"{leg}_abad"] + [f"{leg}_{j}" for j in PASSIVE_JOINTS]


def configuration(robot: Any, leg_q: ArrayLike) -> np.ndarray:
    """Configurations (..., nq) closing every loop, from per-leg (theta, beta, gamma) of shape (..., 4, 3).

    Every tree joint from :func:`~legkin.wheel_leg.passive_angles` (the closed form of the linkage); the ABAD
    joint is gamma; anything else (a free-flyer base) keeps its value in ``robot.q0``. The geometry is the
    robot's (``robot.params``).
    """
    leg_q = np.asarray(leg_q, dtype=float)
    geo = Geometry.from_params(robot.params)
    q = np.broadcast_to(robot.q0, leg_q.shape[:-2] + (robot.model.nq,)).copy()
    for k, leg in enumerate(LEGS):
        ang = passive_angles(leg_q[..., k, 0], leg_q[..., k, 1], geometry=geo)
        for j, v in ang.items():
            q[..., robot.idx_q(f"{leg}_{j}")] = v
        q[..., robot.idx_q(f"{leg}_abad")] = leg_q[..., k, 2]
    return q


def uniform_configuration(robot: Any, theta: ArrayLike, beta: ArrayLike = 0.0, gamma: ArrayLike = 0.0) -> np.ndarray:
    """Configurations (..., nq) with every leg at the same (theta, beta, gamma) (broadcast together)."""
    theta, beta, gamma = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (theta, beta, gamma)))
    leg_q = np.stack([theta, beta, gamma], -1)[..., None, :]
    return configuration(robot, np.broadcast_to(leg_q, theta.shape + (4, 3)))


def sample_leg_q(n: int, rng: np.random.Generator, gamma_range: float = 0.6) -> np.ndarray:
    """(n, 3) random (theta, beta, gamma): theta over [17, 160] deg, beta in [-pi, pi], |gamma| <= gamma_range."""
    return np.stack(
        [rng.uniform(THETA_MIN, THETA_MAX, n), rng.uniform(-np.pi, np.pi, n),
         rng.uniform(-gamma_range, gamma_range, n)], -1,
    )  # fmt: skip


def sample_q_in_limits(n: int, rng: np.random.Generator, margin: float = 0.0) -> np.ndarray:
    """(n, 3) random (theta, beta, gamma) inside the URDF limits, ``margin`` (rad) inside theta's domain and
    the ABAD limits (e.g. a finite-difference step): theta, beta over [-pi, pi], gamma uniform."""
    return np.stack(
        [rng.uniform(THETA_MIN + margin, THETA_MAX - margin, n), rng.uniform(-np.pi, np.pi, n),
         rng.uniform(-ABAD_LIMIT + margin, ABAD_LIMIT - margin, n)], -1,
    )  # fmt: skip


def within_limits(q: ArrayLike, tol: float = 1e-12) -> np.ndarray:
    """Mask (...) of (theta, beta, gamma) (..., 3) inside the URDF limits (to ``tol``): theta in
    [17, 160] deg, gamma in the ABAD limits, both motor angles ``beta -+ (theta - theta0)`` in +-4 pi."""
    q = np.asarray(q, dtype=float)
    theta, beta, gamma = q[..., 0], q[..., 1], q[..., 2]
    with np.errstate(invalid="ignore"):
        ok = (theta >= THETA_MIN - tol) & (theta <= THETA_MAX + tol) & (np.abs(gamma) <= ABAD_LIMIT + tol)
        for phi in (beta + (theta - THETA0), beta - (theta - THETA0)):
            ok &= np.abs(phi) <= PHI_LIMIT + tol
    return ok


def sample_targets(n: int, rng: np.random.Generator, leg: str, *, geometry: Geometry | None = None,
                   rim: str = "continuous") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``n`` reachable targets of ``leg``: (target (n, 3), alpha (n,), w (n,), q (n, 3)), the contact point
    :func:`~legkin.wheel_leg.fk` of in-limit joints (:func:`sample_q_in_limits`) at random rim points."""
    geo = _geometry(geometry)
    q = sample_q_in_limits(n, rng)
    alpha = rng.uniform(-np.pi, np.pi, n)
    w = rng.uniform(-geo.T / 2, geo.T / 2, n)
    return fk(q, leg, alpha=alpha, w=w, rim=rim, geometry=geo), alpha, w, q  # type: ignore[call-overload]


def local_contact_point(alpha: ArrayLike, w: ArrayLike, geometry: Geometry | None = None,
                        rim: str = "continuous") -> tuple[np.ndarray, np.ndarray]:
    """The contact point in its rim link's frame and the segment index (:data:`SEGMENT_LINKS`).

    Fixed in the link, so computed from the closed form at the wheel-mode reference (where every link frame is
    parallel to {L} and sits at its parent hinge). ``rim="three_arc"``: only its upper-rim arcs
    (``|alpha| > psi_FG``) are fixed in a link (the toe arc about O_r is in none).
    """
    geo = _geometry(geometry)
    alpha = np.asarray(alpha, dtype=float)
    th0 = np.full(alpha.shape, THETA0)
    fn = rim_point if rim == "continuous" else rim_point_seed
    p = fn(th0, 0.0, alpha, w, geometry=geo)
    pts = linkage_points(th0, geometry=geo)
    seg = rim_segment(alpha) if rim == "continuous" else np.where(alpha > 0, 3, 0)
    origin = np.zeros_like(p)
    for k, (_, pt) in enumerate(SEGMENT_LINKS):
        origin[seg == k] = pts[pt][seg == k]
    return p - origin, seg


def ik_start(target: ArrayLike, leg: str, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: str = "continuous",
             geometry: Geometry | None = None) -> np.ndarray:
    """The first geometric start (n, 3) of the iterative IK methods for targets (n, 3) (gamma exact, theta
    from the 64-node grid, beta from the direction; :func:`legkin.wheel_leg.ik_iterative._k_starts`)."""
    target = np.asarray(target, dtype=float).reshape(-1, 3)
    n = target.shape[0]
    alpha = np.broadcast_to(np.asarray(alpha, dtype=float), (n,))
    w = np.broadcast_to(np.asarray(w, dtype=float), (n,))
    ctx = _context(alpha, w, leg, rim, _geometry(geometry), None)
    return starts(target, ctx, 1)[0]
