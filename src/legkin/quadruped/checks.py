"""Validation of :mod:`legkin.quadruped` against Pinocchio (and yourdfpy as a third opinion)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._checkkit import (
    CheckResult,
    classify_failures,
    compare,
    per_sample,
    pinocchio_frames,
    robustness_row,
    sample_within_limits,
)
from .._rotations import wrap
from ..robot import load
from . import kinematics as aq
from .configuration import leg_slice, made_joints, near_singular_joints, pinocchio_configuration, random_targets, rho
from .constants import L1

TOL = 1e-12
#: Abduction-singularity band: below this distance rho (m) of the foot from the abduction cylinder
#: the two abduction branches nearly merge and the joint solution is ill-conditioned (error ~ 1.6e-16 m / rho).
RHO_NEAR = 1e-3
#: Tolerance of the near-singular rows, for rho down to ~1e-7 m (measured: 9e-12 rad at rho = 1.9e-6 m).
TOL_NEAR = 1e-9
YOURDFPY_SAMPLES = 1000
#: ``legkin check``'s worker group (:func:`legkin.validation._group_key`): these checks run :mod:`legkin.legs` on
#: POPI (:func:`_generic_leg_rows`), so they share a process with the external robots and the legs kernels compile
#: once on a first run (6-8 s of CPU when the two groups ran in separate processes).
KERNEL_GROUP = "legs"


def run(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    robot = load("quadruped")
    qs = sample_within_limits(robot, samples, rng)
    frames = [f"{leg}_FOOT" for leg in aq.LEGS]
    pos, _, jac = pinocchio_frames(robot, qs, frames, jacobians=True)
    rows: list[CheckResult] = []
    for k, leg in enumerate(aq.LEGS):
        cols = leg_slice(robot, leg)
        q = qs[:, cols]
        rows.append(compare(f"{leg} foot position vs oMf", per_sample(aq.fk(q, leg) - pos[:, k]), TOL))
        jerr = np.abs(aq.jacobian(q, leg) - jac[:, k, :3, cols]).max(axis=(-1, -2))
        rows.append(compare(f"{leg} foot Jacobian vs getFrameJacobian", jerr, TOL))
        # IK round trip: q in limits -> Pinocchio FK -> ik (branch nearest the sample).
        q_sing = near_singular_joints(max(samples // 20, 50), leg, rng)
        pos_n = pinocchio_frames(robot, pinocchio_configuration(robot, {leg: q_sing}), [f"{leg}_FOOT"])[0][:, 0]
        q_all = np.concatenate([q, q_sing])
        p_all = np.concatenate([pos[:, k], pos_n])
        q_ik = aq.ik(p_all, leg, q_near=q_all)
        jerr = np.abs(wrap(q_ik - q_all)).max(axis=-1)
        near = rho(p_all, leg) < RHO_NEAR
        rows.append(compare(f"{leg} IK round trip, joints (rho >= 1 mm)", jerr[~near], TOL))
        rows.append(compare(f"{leg} IK round trip, joints (rho < 1 mm, near-singular)", jerr[near], TOL_NEAR))
        rows.append(compare(f"{leg} IK round trip, foot position", per_sample(aq.fk(q_ik, leg) - p_all), TOL))
        rows += _textbook_rows(leg, p_all, near)
    rows += _geometry_rows(samples, rng)
    rows.append(_yourdfpy_row(robot, qs[: min(samples, YOURDFPY_SAMPLES)], pos, frames))
    rows += _generic_leg_rows(samples, rng)
    return rows


def _textbook_rows(leg: str, p: np.ndarray, near: np.ndarray) -> list[CheckResult]:
    """Seed 002's textbook IK (:mod:`legkin.quadruped.textbook`) vs :func:`~legkin.quadruped.ik_all`'s branch
    (s_u, k) = (-1, -1) on the Pinocchio feet ``p`` (max joint difference, rad), split like the IK rows at
    rho = 1 mm: the seed's ``acos(a / sqrt(x_f^2 + z_f^2))`` loses digits as the foot nears the abduction
    cylinder (measured: 1.1e-11 rad at rho = 6e-6 m, error * rho <= 1e-16 m rad)."""
    fz = aq.DEFAULT_GEOMETRY.foot_z
    theta = aq.textbook_ik(aq.textbook_frame(p, leg), aq.Y12, L1, float(np.hypot(aq.X34, fz)))
    err = np.abs(wrap(aq.textbook_to_joints(theta, leg) - aq.ik_all(p, leg)[:, 0])).max(axis=-1)
    err = np.where(np.isnan(err), np.inf, err)  # the seed's acos/asin out of range: a failure of the row
    name = f"{leg} seed 002 textbook IK = ik_all branch (s_u, k) = (-1, -1), joints"
    return [
        compare(f"{name} (rho >= 1 mm)", err[~near], TOL),
        compare(f"{name} (rho < 1 mm, near-singular)", err[near], TOL_NEAR),
    ]


#: Prefix of the rows of the generic leg (:mod:`legkin.legs`, measured from POPI's model).
GENERIC_PREFIX = "legs.Leg: "


def _generic_leg_rows(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """POPI through the code path of any URDF quadruped: :func:`legkin.legs.checks.run` on its model (the four
    legs found and measured by :func:`legkin.legs.from_model`), rows prefixed :data:`GENERIC_PREFIX`."""
    from dataclasses import replace

    from ..legs import checks as leg_checks

    return [replace(r, name=GENERIC_PREFIX + r.name) for r in leg_checks.run("quadruped", samples, rng)]


#: The non-default geometry of the geometry rows: POPI's own URDF value of foot_z (m).
FOOT_Z = -0.015


def _geometry_rows(samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """``fk``/``jacobian``/``ik`` with ``geometry=robot.geometry`` of ``load("quadruped", foot_z=FOOT_Z)``
    against that model's Pinocchio frames (every leg, ``samples`` configurations in all)."""
    robot = load("quadruped", foot_z=FOOT_Z)
    geometry = robot.geometry
    qs = sample_within_limits(robot, samples, rng)
    frames = [f"{leg}_FOOT" for leg in aq.LEGS]
    pos, _, jac = pinocchio_frames(robot, qs, frames, jacobians=True)
    ferr, jerr, ierr = [], [], []
    for k, leg in enumerate(aq.LEGS):
        cols = leg_slice(robot, leg)
        q = qs[:, cols]
        ferr.append(per_sample(aq.fk(q, leg, geometry=geometry) - pos[:, k]))
        jerr.append(np.abs(aq.jacobian(q, leg, geometry=geometry) - jac[:, k, :3, cols]).max(axis=(-1, -2)))
        q_ik = aq.ik(pos[:, k], leg, q_near=q, geometry=geometry)
        ierr.append(per_sample(aq.fk(q_ik, leg, geometry=geometry) - pos[:, k]))
    tag = f"foot_z = {FOOT_Z:g} (robot.geometry)"
    return [
        compare(f"feet, {tag}: position vs oMf", np.concatenate(ferr), TOL),
        compare(f"feet, {tag}: Jacobian vs getFrameJacobian", np.concatenate(jerr), TOL),
        compare(f"feet, {tag}: IK round trip, foot position", np.concatenate(ierr), TOL),
    ]


def _yourdfpy_row(robot: Any, qs: np.ndarray, pos: np.ndarray, frames: list[str]) -> CheckResult:
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
#: Contract tolerance: every solved answer reproduces its target to this (m) with the default fk.
CONTRACT_TOL = 1e-9


def ik_robustness(n: int, rng: np.random.Generator, *, classify: int | None = 2000) -> CheckResult:
    """The IK contract row of the quadruped legs (see :func:`legkin.validation.robustness_row`).

    Half the targets are ``fk`` of in-limit joints (:func:`made_joints`, each must be solved), the
    rest :func:`random_targets`; legs are drawn at random. ``ik`` runs once per leg as a batch with
    default options; for the solved targets the error is |fk(q) - p| (m), and an answer outside
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
        p[sel] = aq.fk(q_made[sel], leg)
    p[n_made:] = random_targets(n - n_made, rng, legs[n_made:])
    solved = np.zeros(n, dtype=bool)
    error = np.full(n, np.nan)
    exceptions = 0
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    for leg in aq.LEGS:
        sel = np.nonzero(legs == leg)[0]
        try:
            q, ok = aq.ik(p[sel], leg, return_mask=True)
        except Exception:  # noqa: BLE001 - a foreign (or any) exception from a batch call is a defect
            exceptions += 1
            continue
        err = np.linalg.norm(aq.fk(np.where(ok[:, None], q, 0.0), leg) - p[sel], axis=-1)
        inside = np.all((q >= lo) & (q <= hi), axis=-1)
        error[sel] = np.where(inside, err, np.inf)
        solved[sel] = ok
    unsolved = np.nonzero(~solved)[0]
    if classify is not None and len(unsolved) > classify:
        unsolved = np.sort(rng.choice(unsolved, classify, replace=False))
    reasons, foreign = classify_failures(lambda i: aq.ik(p[i], str(legs[i])), unsolved)
    return robustness_row(
        "quadruped", made=made, solved=solved, error=error, reasons=reasons, classified=len(unsolved),
        exceptions=exceptions + foreign, tolerance=CONTRACT_TOL,
    )
