"""Validation of :mod:`legkin.analytic.quadruped` against Pinocchio (and yourdfpy as a third opinion)."""

from __future__ import annotations

import numpy as np

from .. import load
from ..analytic import quadruped as aq
from ..validation import CheckResult, compare, per_sample, pinocchio_frames, sample_within_limits

TOL = 1e-12
#: Abduction-singularity band: below this distance rho (m) of the foot from the abduction cylinder
#: the two abduction branches nearly merge and the joint solution is ill-conditioned (error ~ 1.6e-16 m / rho).
RHO_NEAR = 1e-3
#: Tolerance of the near-singular rows, for rho down to ~1e-7 m (measured: 9e-12 rad at rho = 1.9e-6 m).
TOL_NEAR = 1e-9
YOURDFPY_SAMPLES = 1000


def _rho(p: np.ndarray, leg: str) -> np.ndarray:
    d = p - aq.hip_position(leg)
    return np.sqrt(np.maximum(d[..., 1] ** 2 + d[..., 2] ** 2 - aq.Y12**2, 0.0))


def near_singular_joints(n: int, leg: str, rng: np.random.Generator) -> np.ndarray:
    """Joint vectors inside the limits whose foot lies rho in [1e-6, 1e-3] m from the abduction cylinder.

    Built by choosing q1, q3 in the limits and q2 with u_z = rho (the foot's height in the hip-rotated frame).
    """
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    out = []
    while sum(len(o) for o in out) < n:
        q = rng.uniform(lo, hi, (2 * n, 3))
        vx, vz = aq._knee_vector(q[:, 2], 0.0)
        rho = 10 ** rng.uniform(-6, -3, 2 * n) * rng.choice([-1.0, 1.0], 2 * n)
        r = np.hypot(vx, vz)
        q[:, 1] = np.arctan2(rho, np.sqrt(r * r - rho * rho)) - np.arctan2(vz, vx)
        q[:, 1] = aq._wrap(q[:, 1])
        out.append(q[aq.within_limits(q, 0.0)])
    return np.concatenate(out)[:n]


def run(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    robot = load("quadruped")
    qs = sample_within_limits(robot, samples, rng)
    frames = [f"{leg}_FOOT" for leg in aq.LEGS]
    pos, _, jac = pinocchio_frames(robot, qs, frames, jacobians=True)
    rows: list[CheckResult] = []
    for k, leg in enumerate(aq.LEGS):
        iq = robot.idx_q(f"{leg}_HAA")
        q = qs[:, iq : iq + 3]
        rows.append(compare(f"{leg} foot position vs oMf", per_sample(aq.foot_position(q, leg) - pos[:, k]), TOL))
        jerr = np.abs(aq.foot_jacobian(q, leg) - jac[:, k, :3, iq : iq + 3]).max(axis=(-1, -2))
        rows.append(compare(f"{leg} foot Jacobian vs getFrameJacobian", jerr, TOL))
        # IK round trip: q in limits -> Pinocchio FK -> foot_ik (branch nearest the sample).
        q_near = near_singular_joints(max(samples // 20, 50), leg, rng)
        qn = np.tile(robot.q0, (len(q_near), 1))
        qn[:, iq : iq + 3] = q_near
        pos_n = pinocchio_frames(robot, qn, [f"{leg}_FOOT"])[0][:, 0]
        q_all = np.concatenate([q, q_near])
        p_all = np.concatenate([pos[:, k], pos_n])
        q_ik = aq.foot_ik(p_all, leg, q_ref=q_all)
        jerr = np.abs(aq._wrap(q_ik - q_all)).max(axis=-1)
        near = _rho(p_all, leg) < RHO_NEAR
        rows.append(compare(f"{leg} IK round trip, joints (rho >= 1 mm)", jerr[~near], TOL))
        rows.append(compare(f"{leg} IK round trip, joints (rho < 1 mm, near-singular)", jerr[near], TOL_NEAR))
        rows.append(compare(f"{leg} IK round trip, foot position", per_sample(aq.foot_position(q_ik, leg) - p_all), TOL))
    rows.append(_yourdfpy_row(robot, qs[: min(samples, YOURDFPY_SAMPLES)], pos, frames))
    return rows


def _yourdfpy_row(robot, qs: np.ndarray, pos: np.ndarray, frames: list[str]) -> CheckResult:
    """Third opinion: yourdfpy's forward kinematics of the same URDF vs Pinocchio."""
    import yourdfpy

    urdf = yourdfpy.URDF.load(
        str(robot.urdf_path), load_meshes=False, build_collision_scene_graph=False, load_collision_meshes=False
    )
    index = [robot.idx_q(name) for name in urdf.actuated_joint_names]
    err = np.empty((len(qs), len(frames)))
    for i, q in enumerate(qs):
        urdf.update_cfg(q[index])
        for k, f in enumerate(frames):
            err[i, k] = np.linalg.norm(urdf.get_transform(f, "base")[:3, 3] - pos[i, k])
    return compare("feet: yourdfpy FK vs Pinocchio", err, TOL)
