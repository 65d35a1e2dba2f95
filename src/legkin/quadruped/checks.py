"""Validation of :mod:`legkin.quadruped` against Pinocchio (and yourdfpy as a third opinion)."""

from __future__ import annotations

import math

import numpy as np

from .. import load
from . import kinematics as aq
from ..validation import (
    CheckResult,
    classify_failures,
    compare,
    per_sample,
    pinocchio_frames,
    robustness_row,
    sample_within_limits,
)

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


# ---------------------------------------------------------------- the IK contract row
#: Contract tolerance: every solved answer reproduces its target to this (m) with the default foot_position.
CONTRACT_TOL = 1e-9


def made_joints(n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` joint vectors inside the limits, biased to the hard places: uniform (60 %), with joints snapped
    exactly onto a limit (20 %), and with the foot rho in [1e-10, 1e-3] m from the abduction cylinder (20 %)."""
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    q = rng.uniform(lo, hi, (n, 3))
    kind = rng.uniform(size=n)
    snap = (kind < 0.2)[:, None] & (rng.uniform(size=(n, 3)) < 0.5)
    q = np.where(snap, np.where(rng.uniform(size=(n, 3)) < 0.5, lo, hi), q)
    near = np.nonzero(kind > 0.8)[0]
    if len(near):
        qn = q[near]
        vx, vz = aq._knee_vector(qn[:, 2], 0.0)
        rho = 10 ** rng.uniform(-10, -3, len(near)) * rng.choice([-1.0, 1.0], len(near))
        r = np.hypot(vx, vz)
        q2 = aq._wrap(np.arctan2(rho, np.sqrt(r * r - rho * rho)) - np.arctan2(vz, vx))
        keep = (q2 >= lo[1]) & (q2 <= hi[1])
        qn[keep, 1] = q2[keep]
        q[near] = qn
    return q


def random_targets(n: int, rng: np.random.Generator, legs: np.ndarray) -> np.ndarray:
    """``n`` foot targets in and around the workspace of ``legs[i]``: a box of +-0.8 m about the hip (50 %),
    points a hair (1e-15 .. 1e-3 m) inside / outside the abduction cylinder, full stretch and the inner
    radius |L1 - L2| (30 %), and FK of joints just outside the limits (by 1e-12 .. 1e-2 rad, 20 %)."""
    hips = np.stack([aq.hip_position(leg) for leg in aq.LEGS])[np.searchsorted(aq.LEGS, legs)]
    sy = np.where(np.char.startswith(legs.astype(str), "L"), 1.0, -1.0)
    p = hips + rng.uniform(-0.8, 0.8, (n, 3))
    kind = rng.uniform(size=n)
    l1, l2 = math.hypot(aq.X23, aq.Z23), aq.X34
    hair = 10 ** rng.uniform(-15, -3, n) * rng.choice([-1.0, 1.0], n)
    # near the boundary surfaces: pick rho (distance from the cylinder's tangent plane) and r (in-plane reach)
    radius = np.where(kind < 0.6, l1 + l2 + hair, np.abs(l1 - l2) + hair)
    angle = rng.uniform(-np.pi, np.pi, n)
    rho = np.where(kind < 0.6, np.abs(radius * np.sin(angle)), 10 ** rng.uniform(-12, -3, n))
    dx = np.where(kind < 0.6, radius * np.cos(angle), np.sqrt(np.maximum(radius**2 - rho**2, 0.0)) * np.sign(np.cos(angle)))
    axis = np.sqrt(aq.Y12**2 + rho**2)
    axis = np.where(kind < 0.45, aq.Y12 + hair, axis)  # some straddle the cylinder itself
    tilt = rng.uniform(-np.pi, np.pi, n)
    surf = hips + np.stack([dx, sy * axis * np.cos(tilt), axis * np.sin(tilt)], axis=-1)
    boundary = (kind >= 0.5) & (kind < 0.8)
    p[boundary] = surf[boundary]
    outside = np.nonzero(kind >= 0.8)[0]
    if len(outside):
        lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
        q = rng.uniform(lo, hi, (len(outside), 3))
        j = rng.integers(0, 3, len(outside))
        over = 10 ** rng.uniform(-12, -2, len(outside))
        side = rng.uniform(size=len(outside)) < 0.5
        q[np.arange(len(outside)), j] = np.where(side, lo[j] - over, hi[j] + over)
        for leg in aq.LEGS:
            sel = legs[outside] == leg
            p[outside[sel]] = aq.foot_position(q[sel], leg)
    return p


def ik_robustness(n: int, rng: np.random.Generator, *, classify: int | None = 2000) -> CheckResult:
    """The IK contract row of the quadruped legs (see :func:`legkin.validation.robustness_row`).

    Half the targets are ``foot_position`` of in-limit joints (:func:`made_joints`, each must be solved), the
    rest :func:`random_targets`; legs are drawn at random. ``foot_ik`` runs once per leg as a batch with
    default options; for the solved targets the error is |foot_position(q) - p| (m), and an answer outside
    the URDF limits (no slack) counts as not reproduced (error inf). Up to ``classify`` unsolved targets
    (None: all) are classified by single calls.
    """
    n_made = n // 2
    legs = np.asarray(aq.LEGS)[rng.integers(0, 4, n)]
    made = np.zeros(n, dtype=bool)
    made[:n_made] = True
    p = np.empty((n, 3))
    q_made = made_joints(n_made, rng)
    for leg in aq.LEGS:
        sel = np.nonzero(legs[:n_made] == leg)[0]
        p[sel] = aq.foot_position(q_made[sel], leg)
    p[n_made:] = random_targets(n - n_made, rng, legs[n_made:])
    solved = np.zeros(n, dtype=bool)
    error = np.full(n, np.nan)
    exceptions = 0
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    for leg in aq.LEGS:
        sel = np.nonzero(legs == leg)[0]
        try:
            q, ok = aq.foot_ik(p[sel], leg, return_mask=True)
        except Exception:  # noqa: BLE001 - a foreign (or any) exception from a batch call is a defect
            exceptions += 1
            continue
        err = np.linalg.norm(aq.foot_position(np.where(ok[:, None], q, 0.0), leg) - p[sel], axis=-1)
        inside = np.all((q >= lo) & (q <= hi), axis=-1)
        error[sel] = np.where(inside, err, np.inf)
        solved[sel] = ok
    unsolved = np.nonzero(~solved)[0]
    if classify is not None and len(unsolved) > classify:
        unsolved = np.sort(rng.choice(unsolved, classify, replace=False))
    reasons, foreign = classify_failures(lambda i: aq.foot_ik(p[i], str(legs[i])), unsolved)
    return robustness_row(
        "quadruped", made=made, solved=solved, error=error, reasons=reasons, classified=len(unsolved),
        exceptions=exceptions + foreign, tolerance=CONTRACT_TOL,
    )
