"""Helpers the rest of the package (checks, bench, clips, contract) and users share: the leg's joint names,
a Pinocchio configuration from leg angles, and samplers of in-limit joints and of foot targets.

The samplers draw from a ``numpy.random.Generator``; nothing here is a kinematic function of its own (they
call :func:`~legkin.quadruped.fk`).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import numpy.typing as npt

from .._rotations import wrap
from ._common import leg_index
from .constants import JOINT_LIMITS, L1, LEGS, X23, X34, Y12, Z23
from .kinematics import fk, hip_position, within_limits

__all__ = [
    "JOINTS",
    "joint_names",
    "leg_slice",
    "pinocchio_configuration",
    "sample_joints",
    "near_singular_joints",
    "made_joints",
    "random_targets",
    "rho",
    "knee_vector",
]

#: The joint names of a leg, in the order of ``q``: (``<LEG>_HAA``, ``<LEG>_HFE``, ``<LEG>_KFE``).
JOINTS = ("HAA", "HFE", "KFE")


def joint_names(leg: str) -> tuple[str, str, str]:
    """The URDF joint names of ``leg``'s ``q`` (q1, q2, q3), e.g. ``("LF_HAA", "LF_HFE", "LF_KFE")``."""
    leg_index(leg)
    return f"{leg}_HAA", f"{leg}_HFE", f"{leg}_KFE"


def leg_slice(robot: Any, leg: str) -> slice:
    """The slice of ``robot``'s configuration vector (a :class:`legkin.Robot`) holding ``leg``'s ``q``."""
    iq = int(robot.idx_q(joint_names(leg)[0]))
    return slice(iq, iq + 3)


def pinocchio_configuration(
    robot: Any, legs: Mapping[str, npt.ArrayLike], base: npt.ArrayLike | None = None
) -> np.ndarray:
    """A Pinocchio configuration (..., nq) of ``robot`` with the legs' angles ``{leg: q (..., 3)}`` set.

    The other coordinates are ``base`` (default ``robot.q0``, the SRDF ``standing`` pose); the leading shapes
    of the leg angles broadcast. The quadruped has no loops: every such configuration is closed.
    """
    qs = {leg: np.asarray(q, dtype=float) for leg, q in legs.items()}
    batch = np.broadcast_shapes(*(q.shape[:-1] for q in qs.values())) if qs else ()
    q0 = np.asarray(robot.q0 if base is None else base, dtype=float)
    out = np.array(np.broadcast_to(q0, batch + q0.shape[-1:]))
    for leg, q in qs.items():
        out[..., leg_slice(robot, leg)] = q
    return out


def sample_joints(rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` joint vectors (n, 3) uniform inside :data:`JOINT_LIMITS`."""
    return rng.uniform(JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1], (n, 3))


def rho(p: npt.ArrayLike, leg: str) -> np.ndarray:
    """Distance (m) of foot targets (..., 3) from the abduction cylinder's tangent plane (0 inside it):
    ``rho^2 = d_y^2 + d_z^2 - y12^2`` with ``d = p - h``; the abduction singularity is rho = 0."""
    d = np.asarray(p, dtype=float) - hip_position(leg)
    return np.sqrt(np.maximum(d[..., 1] ** 2 + d[..., 2] ** 2 - Y12**2, 0.0))


def knee_vector(q3: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Seed 004's knee-to-foot vector in the thigh's x-z plane, ``v = t23 + R_y(q3) t34`` (foot_z = 0), for
    knee angles ``q3`` (rad, any shape): ``(v_x, v_z)`` in metres (a sampler's helper, not a kinematic function)."""
    q3 = np.asarray(q3, dtype=float)
    return X23 + X34 * np.cos(q3), Z23 - X34 * np.sin(q3)


def _q2_at_rho(q3: np.ndarray, signed_rho: np.ndarray) -> np.ndarray:
    """q2 putting the foot (foot_z = 0) ``signed_rho`` from the abduction cylinder (u_z = rho) for knee ``q3``."""
    vx, vz = knee_vector(q3)
    r = np.hypot(vx, vz)
    return wrap(np.arctan2(signed_rho, np.sqrt(r * r - signed_rho * signed_rho)) - np.arctan2(vz, vx))


def near_singular_joints(n: int, leg: str, rng: np.random.Generator) -> np.ndarray:
    """Joint vectors (n, 3) inside the limits whose foot lies rho in [1e-6, 1e-3] m from the abduction cylinder.

    Built by choosing q1, q3 in the limits and q2 with u_z = rho (the foot's height in the hip-rotated frame).
    """
    leg_index(leg)
    out: list[np.ndarray] = []
    while sum(len(o) for o in out) < n:
        q = sample_joints(rng, 2 * n)
        signed = 10 ** rng.uniform(-6, -3, 2 * n) * rng.choice([-1.0, 1.0], 2 * n)
        q[:, 1] = _q2_at_rho(q[:, 2], signed)
        out.append(q[within_limits(q, 0.0)])
    return np.concatenate(out)[:n]


def made_joints(n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` joint vectors inside the limits, biased to the hard places: uniform (60 %), with joints snapped
    exactly onto a limit (20 %), and with the foot rho in [1e-10, 1e-3] m from the abduction cylinder (20 %)."""
    lo, hi = JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1]
    q = rng.uniform(lo, hi, (n, 3))
    kind = rng.uniform(size=n)
    snap = (kind < 0.2)[:, None] & (rng.uniform(size=(n, 3)) < 0.5)
    q = np.where(snap, np.where(rng.uniform(size=(n, 3)) < 0.5, lo, hi), q)
    near = np.nonzero(kind > 0.8)[0]
    if len(near):
        qn = q[near]
        signed = 10 ** rng.uniform(-10, -3, len(near)) * rng.choice([-1.0, 1.0], len(near))
        q2 = _q2_at_rho(qn[:, 2], signed)
        keep = (q2 >= lo[1]) & (q2 <= hi[1])
        qn[keep, 1] = q2[keep]
        q[near] = qn
    return q


def random_targets(n: int, rng: np.random.Generator, legs: np.ndarray) -> np.ndarray:
    """``n`` foot targets in and around the workspace of ``legs[i]``: a box of +-0.8 m about the hip (50 %),
    points a hair (1e-15 .. 1e-3 m) inside / outside the abduction cylinder, full stretch and the inner
    radius |L1 - L2| (30 %), and FK of joints just outside the limits (by 1e-12 .. 1e-2 rad, 20 %)."""
    hips = np.stack([hip_position(leg) for leg in LEGS])[np.searchsorted(LEGS, legs)]
    sy = np.where(np.char.startswith(legs.astype(str), "L"), 1.0, -1.0)
    p = hips + rng.uniform(-0.8, 0.8, (n, 3))
    kind = rng.uniform(size=n)
    l1, l2 = L1, X34
    hair = 10 ** rng.uniform(-15, -3, n) * rng.choice([-1.0, 1.0], n)
    # near the boundary surfaces: pick rho (distance from the cylinder's tangent plane) and r (in-plane reach)
    radius = np.where(kind < 0.6, l1 + l2 + hair, np.abs(l1 - l2) + hair)
    angle = rng.uniform(-np.pi, np.pi, n)
    rh = np.where(kind < 0.6, np.abs(radius * np.sin(angle)), 10 ** rng.uniform(-12, -3, n))
    inner_dx = np.sqrt(np.maximum(radius**2 - rh**2, 0.0)) * np.sign(np.cos(angle))
    dx = np.where(kind < 0.6, radius * np.cos(angle), inner_dx)
    axis = np.sqrt(Y12**2 + rh**2)
    axis = np.where(kind < 0.45, Y12 + hair, axis)  # some straddle the cylinder itself
    tilt = rng.uniform(-np.pi, np.pi, n)
    surf = hips + np.stack([dx, sy * axis * np.cos(tilt), axis * np.sin(tilt)], axis=-1)
    boundary = (kind >= 0.5) & (kind < 0.8)
    p[boundary] = surf[boundary]
    outside = np.nonzero(kind >= 0.8)[0]
    if len(outside):
        lo, hi = JOINT_LIMITS[:, 0], JOINT_LIMITS[:, 1]
        q = rng.uniform(lo, hi, (len(outside), 3))
        j = rng.integers(0, 3, len(outside))
        over = 10 ** rng.uniform(-12, -2, len(outside))
        side = rng.uniform(size=len(outside)) < 0.5
        q[np.arange(len(outside)), j] = np.where(side, lo[j] - over, hi[j] + over)
        for leg in LEGS:
            sel = legs[outside] == leg
            p[outside[sel]] = fk(q[sel], leg)
    return p
