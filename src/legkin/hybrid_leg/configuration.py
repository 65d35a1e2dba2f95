"""Configurations and samples of the hybrid leg, shared by its checks, bench, figures and clips (and users):
closed Pinocchio configurations from analytic angles, samplers of in-limit joints and of foot targets, the joint
names."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .._rotations import rot_x, rot_y, rot_z
from .extension import extension_motor_angle, ll_angle
from .foot import fk
from .forward import platform_orientation
from .geometry import LL_LIMIT, MOTOR_LIMIT, Geometry
from .platform import assembly_mode, motor_angles, motor_jacobian
from .rotation import motor_angles_from_rotation, sphere_joint_angles

__all__ = [
    "ACTUATED", "PASSIVE_U", "LL_RANGE", "SIGMA_MIN", "sigma_min", "neutral_mode", "sample_workspace",
    "sample_near_forward_singularity", "closed_configuration", "sample_joints", "sample_mode_joints", "within_limits",
    "sample_targets",
]

#: The actuated joints (the motors MCS1, MCS2 and the LL joint driven by theta0 through eq 19).
ACTUATED = ("MCS1", "MCS2", "LL")
#: The passive joints of the universal-centre model (centre, lever-tip spherical joints).
PASSIVE_U = ("LCS_x", "LCS_y", "Sph_1_1_z", "Sph_1_1_y", "Sph_1_1_x", "Sph_2_1_z", "Sph_2_1_y", "Sph_2_1_x")
#: LL samples: theta_LL uniform in this range (rad), i.e. theta0 from -16.8 to +40 motor radians (-2.7 to
#: +6.4 revolutions with starting_value 0).
LL_RANGE = (-0.3, 0.125)
#: Well-conditioned workspace: sigma_min(dtheta/d(roll, pitch)) at least this (rad/rad).
SIGMA_MIN = 1e-2


def sigma_min(roll: np.ndarray, pitch: np.ndarray, branch: Sequence[int] = (1, 1)) -> np.ndarray:
    """Smallest singular value of d(theta1, theta2)/d(roll, pitch) (NaN where out of reach)."""
    jac, ok = motor_jacobian(roll, pitch, branch, return_mask=True)
    s = np.full(np.shape(roll), np.nan)
    s[ok] = np.linalg.svd(jac[ok], compute_uv=False)[..., -1]
    return s


def neutral_mode(roll: np.ndarray, pitch: np.ndarray, branch: Sequence[int] = (1, 1)) -> np.ndarray:
    """Reachable, and same sign of det dtheta/dx as at R_P = I (the neutral assembly mode)."""
    jac, ok = motor_jacobian(roll, pitch, branch, return_mask=True)
    j0 = motor_jacobian(0.0, 0.0, branch)
    det = np.linalg.det(np.where(ok[..., None, None], jac, np.eye(2)))
    return ok & (np.sign(det) == np.sign(np.linalg.det(j0)))  # type: ignore[no-any-return]


def sample_workspace(n: int, rng: np.random.Generator, sigma: float = SIGMA_MIN) -> tuple[np.ndarray, np.ndarray]:
    """``n`` (roll, pitch) pairs of the neutral assembly mode with sigma_min(dtheta/dx) >= ``sigma``.

    Rejection sampling in |roll| <= 1, pitch in [-1, 1.1] rad (the neutral mode's component lies inside it:
    pitch from about -34 to +55 deg, roll up to about +-57 deg).
    """
    out_r, out_p, got = [], [], 0
    while got < n:
        r = rng.uniform(-1.0, 1.0, 4 * n)
        p = rng.uniform(-1.0, 1.1, 4 * n)
        keep = neutral_mode(r, p)
        keep[keep] &= sigma_min(r[keep], p[keep]) >= sigma
        out_r.append(r[keep])
        out_p.append(p[keep])
        got += int(keep.sum())
    return np.concatenate(out_r)[:n], np.concatenate(out_p)[:n]


def sample_near_forward_singularity(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(roll, pitch) just inside the forward-singularity curve (det N = 0) bounding the neutral mode.

    For roll in [-0.9, 0.9], the pitch where det dtheta/dx changes sign between 0 and 1.1 rad is found by
    bisection; samples sit 10^U(-7, -2) rad inside it.
    """
    roll = rng.uniform(-0.9, 0.9, n)
    lo, hi = np.zeros(n), np.full(n, 1.1)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        inside = neutral_mode(roll, mid)
        lo = np.where(inside, mid, lo)
        hi = np.where(inside, hi, mid)
    return roll, lo - 10.0 ** rng.uniform(-7, -2, n)


def closed_configuration(robot: Any, angles: np.ndarray, theta_ll: np.ndarray,
                         branch: Sequence[int] = (1, 1)) -> np.ndarray:
    """Analytic configurations (n, nq) closing both loops.

    Args:
        robot: a loaded ``hybrid_leg`` (either centre).
        angles: centre joint angles (n, 2) (roll, pitch) for the universal centre, (n, 3) (x, y, z) for the
            spherical one (R_P = Rx Ry Rz).
        theta_ll: LL angles (n,).
        branch: the motor branch (b1, b2).
    """
    rot = rot_x(angles[:, 0]) @ rot_y(angles[:, 1])
    if angles.shape[1] == 3:
        rot = rot @ rot_z(angles[:, 2])
    theta = motor_angles_from_rotation(rot, branch)
    sph = sphere_joint_angles(rot, branch)
    qs = np.tile(robot.q0, (len(angles), 1))
    for k, axis in enumerate("xyz"[: angles.shape[1]]):
        qs[:, robot.idx_q(f"LCS_{axis}")] = angles[:, k]
    for i in (1, 2):
        qs[:, robot.idx_q(f"MCS{i}")] = theta[:, i - 1]
        for k, axis in enumerate("zyx"):
            qs[:, robot.idx_q(f"Sph_{i}_1_{axis}")] = sph[:, i - 1, k]
    qs[:, robot.idx_q("LL")] = theta_ll
    return qs


def sample_joints(rng: np.random.Generator, n: int, *, sigma: float = SIGMA_MIN,
                  geometry: Geometry | None = None) -> np.ndarray:
    """``n`` motor angle triples q = (theta1, theta2, theta0) (n, 3) inside the URDF limits whose :func:`fk` (default
    mode) is defined: platform poses from :func:`sample_workspace` (sigma_min(dtheta/dx) >= ``sigma``), theta_LL
    uniform in :data:`LL_RANGE`."""
    roll, pitch = sample_workspace(n, rng, sigma)
    th = motor_angles(roll, pitch)
    t0 = extension_motor_angle(rng.uniform(*LL_RANGE, n), geometry=geometry)
    return np.column_stack([th, t0])


def sample_mode_joints(rng: np.random.Generator, n: int, branch: Sequence[int], assembly: int, *,
                       sigma: float = SIGMA_MIN, geometry: Geometry | None = None) -> np.ndarray:
    """``n`` motor angle triples q (n, 3) inside the URDF limits whose :func:`fk` in the mode ``branch``,
    ``assembly`` is defined and returns a platform pose with sigma_min(dtheta/dx) >= ``sigma`` on that branch.

    Rejection sampling: platform poses uniform in the joint limits (|roll|, |pitch| <= pi/2) in that mode, their
    motor angles on ``branch``, kept where the forward kinematics of the mode returns that pose (it returns the
    pose of the mode nearest R_P = I) outside the forward-singularity band; theta_LL uniform in :data:`LL_RANGE`.
    """
    out, got = [], 0
    for _ in range(1000):
        m = 8 * n
        r, p = rng.uniform(-np.pi / 2, np.pi / 2, m), rng.uniform(-np.pi / 2, np.pi / 2, m)
        th, ok = motor_angles(r, p, branch, return_mask=True)
        ok &= assembly_mode(np.where(ok, r, 0.0), np.where(ok, p, 0.0), branch, return_mask=True)[0] == assembly
        ok[ok] &= sigma_min(r[ok], p[ok], branch) >= sigma
        r, p, th = r[ok], p[ok], th[ok]
        x, back = platform_orientation(th[:, 0], th[:, 1], branch, assembly=assembly, return_mask=True)
        keep = back & (np.abs(x - np.stack([r, p], -1)).max(-1, initial=0.0) <= 1e-9)
        q = np.column_stack([th[keep], extension_motor_angle(rng.uniform(*LL_RANGE, int(keep.sum())),
                                                             geometry=geometry)])
        defined = fk(q, branch=branch, assembly=assembly, geometry=geometry, return_mask=True)[1]
        out.append(q[defined])
        got += int(defined.sum())
        if got >= n:
            break
    return np.concatenate(out)[:n]


def within_limits(q: np.ndarray, *, geometry: Geometry | None = None, tol: float = 1e-12) -> np.ndarray:
    """Motor angles q (..., 3) inside the URDF limits: MCS1, MCS2 in [-pi, pi], LL (eq 19 of theta0) in [-pi, pi]."""
    q = np.asarray(q, dtype=float)
    tll = ll_angle(q[..., 2], geometry=geometry)
    return ((np.abs(q[..., 0]) <= MOTOR_LIMIT + tol) & (np.abs(q[..., 1]) <= MOTOR_LIMIT + tol)  # type: ignore
            & (np.abs(tll) <= LL_LIMIT + tol))


def sample_targets(rng: np.random.Generator, n: int, *, sigma: float = SIGMA_MIN,
                   geometry: Geometry | None = None) -> np.ndarray:
    """``n`` foot targets (n, 3) made by the default :func:`fk` from :func:`sample_joints`."""
    return fk(sample_joints(rng, n, sigma=sigma, geometry=geometry), geometry=geometry)  # type: ignore[no-any-return]
