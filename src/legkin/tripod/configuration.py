"""Public helpers the rest of the package (checks, bench, clips, figures, contract) and users need: closed
Pinocchio configurations from orientations, samplers of reachable orientations and of in-limit motors,
joint-name lists."""

from __future__ import annotations

from typing import Any

import numpy as np

from ._common import HOME_MODE, LEGS
from .geometry import Geometry
from .inverse import ik_joints

__all__ = [
    "JOINT_NAMES", "MOTOR_NAMES", "MOTOR_COLUMNS", "closed_configuration", "robot_configuration",
    "sample_workspace", "sample_motors", "within_limits",
]

#: Every joint, in the order of :func:`legkin.tripod.ik_joints` (and of the Pinocchio model's q).
JOINT_NAMES = tuple(f"{leg}_q{j}" for leg in LEGS for j in range(1, 5))
#: The actuated joints (the motors of :func:`legkin.tripod.ik` / :func:`legkin.tripod.fk`), and their columns in
#: :data:`JOINT_NAMES`.
MOTOR_NAMES = tuple(f"{leg}_q1" for leg in LEGS)
MOTOR_COLUMNS = (0, 4, 8)
#: The URDF limits of every joint (rad).
LOWER, UPPER = -np.pi, np.pi


def closed_configuration(alpha_y: Any, alpha_z: Any, *, mode: str = HOME_MODE,
                         geometry: Geometry | None = None) -> np.ndarray:
    """The closed configuration (..., 12) (order :data:`JOINT_NAMES`) of the orientations (alpha_y, alpha_z)
    (broadcast together), NaN rows where ik fails: :func:`legkin.tripod.ik_joints` of the stacked target."""
    ay, az = np.broadcast_arrays(np.asarray(alpha_y, dtype=float), np.asarray(alpha_z, dtype=float))
    return ik_joints(np.stack([ay, az], axis=-1), mode=mode, geometry=geometry)


def robot_configuration(robot: Any, joints: np.ndarray) -> np.ndarray:
    """Joint values (..., 12) in :data:`JOINT_NAMES` order as configurations (..., robot.model.nq) of ``robot``
    (placed by joint name; other coordinates from ``robot.q0``)."""
    joints = np.asarray(joints, dtype=float)
    qs = np.broadcast_to(robot.q0, joints.shape[:-1] + (robot.model.nq,)).copy()
    for j, name in enumerate(JOINT_NAMES):
        qs[..., robot.idx_q(name)] = joints[..., j]
    return qs


def within_limits(q: np.ndarray) -> np.ndarray:
    """True where every joint of q (..., k) is inside the URDF limits [-pi, pi]."""
    q = np.asarray(q, dtype=float)
    return np.all((q >= LOWER) & (q <= UPPER), axis=-1)


def sample_workspace(n: int, rng: np.random.Generator, geometry: Geometry | None = None,
                     margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``n`` orientations (alpha_y, alpha_z) uniform in [-pi/2, pi/2] x [-pi, pi], kept where :func:`ik` succeeds
    (home mode) and every leg has ``1 - |cos q_K2| > margin``."""
    ays, azs, total = [], [], 0
    while total < n:
        ay = rng.uniform(-np.pi / 2, np.pi / 2, 2 * n)
        az = rng.uniform(-np.pi, np.pi, 2 * n)
        q, ok = ik_joints(np.stack([ay, az], axis=-1), geometry=geometry, return_mask=True)
        if margin > 0:
            ok &= np.all(1.0 - np.abs(np.cos(q[..., [1, 5, 9]])) > margin, axis=-1)
        ays.append(ay[ok])
        azs.append(az[ok])
        total += int(ok.sum())
    return np.concatenate(ays)[:n], np.concatenate(azs)[:n]


def sample_motors(rng: np.random.Generator, n: int, geometry: Geometry | None = None) -> np.ndarray:
    """``n`` in-limit motor triples (n, 3) whose :func:`fk` is defined: the motors of :func:`sample_workspace`
    orientations (ik's motors lie in (-pi, pi], inside the limits)."""
    ay, az = sample_workspace(n, rng, geometry)
    return closed_configuration(ay, az, geometry=geometry)[:, list(MOTOR_COLUMNS)]
