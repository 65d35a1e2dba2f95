"""``legkin check`` rows of the measured legs of a quadruped (example-robot-data or legkin's own) vs Pinocchio.

Rows (merged over the robot's four legs; every sample draws all twelve leg joints uniformly in their URDF
limits, the floating base, if any, at its neutral pose, so that the world frame is the root frame):

* ``feet FK vs oMf``: |Leg.fk(q) - oMf[foot].translation| (m);
* ``feet Jacobian vs getFrameJacobian``: max |Leg.jacobian(q) - J| over the 3x3 block, J = the
  LOCAL_WORLD_ALIGNED translational rows of the leg's three columns;
* ``IK round trip``: |FK_pinocchio(Leg.ik(p)) - p| for p = the sampled feet; a target left unsolved or solved
  outside the URDF limits counts as an infinite error; the row name carries the count solved;
* ``IK all branches``: |FK_pinocchio(q_b) - p| for every branch q_b of Leg.ik_all(p) (the name carries the count).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._checkkit import CheckResult, compare
from ._reference import pinocchio_poses

__all__ = ["run", "TOL", "load_model", "sample_legs", "pinocchio_poses", "pinocchio_feet"]

#: Tolerance (m, or m/rad for the Jacobian) of every row.
TOL = 1e-12


def load_model(robot_name: str):
    """The Pinocchio model of ``robot_name``: an example-robot-data robot (:data:`legkin.legs.ERD_ALL`), else a
    legkin model (``legkin.load(robot_name).model``)."""
    from .erd import ERD_ALL, load_erd

    if robot_name in ERD_ALL:
        return load_erd(robot_name)[0]
    from ..robot import load

    return load(robot_name).model


def sample_legs(model, legs: dict, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` configurations: the neutral one with every leg joint drawn uniformly in its URDF limits."""
    import pinocchio as pin

    qs = np.tile(pin.neutral(model), (n, 1))
    for leg in legs.values():
        for j, i in enumerate(leg.idx_q):
            qs[:, i] = rng.uniform(leg.lower[j], leg.upper[j], n)
    return qs


def pinocchio_feet(model: Any, legs: dict, qs: np.ndarray, jacobians: bool = False) -> Any:
    """Pinocchio's feet (N, L, 3) in the world frame (m), and with ``jacobians`` the (N, L, 3, 3)
    LOCAL_WORLD_ALIGNED translational rows of each leg's three columns (:func:`pinocchio_poses`)."""
    poses, jac = pinocchio_poses(model, legs, qs, jacobians)
    pos = poses[..., :3, 3]
    return (pos, jac[..., :3, :]) if jacobians else pos


def _with_legs(model, legs: dict, q0: np.ndarray, qleg: np.ndarray) -> np.ndarray:
    """Configurations ``q0`` (N, nq) with each leg's joints set from ``qleg`` (N, L, 3)."""
    qs = q0.copy()
    for k, leg in enumerate(legs.values()):
        qs[:, list(leg.idx_q)] = qleg[:, k]
    return qs


def run(robot_name: str, samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """The check rows of ``robot_name`` (see the module docstring) on ``samples`` random configurations."""
    from .extract import from_model

    model = load_model(robot_name)
    legs = from_model(model)
    if any(leg.dof == 6 for leg in legs.values()):
        from .checks6 import rows6

        return rows6(model, legs, samples, rng)
    nl = len(legs)
    qs = sample_legs(model, legs, samples, rng)
    pos, jac = pinocchio_feet(model, legs, qs, jacobians=True)
    qleg = np.stack([qs[:, list(leg.idx_q)] for leg in legs.values()], axis=1)  # (N, L, 3)
    fk = np.stack([leg.fk(qleg[:, k]) for k, leg in enumerate(legs.values())], axis=1)
    jk = np.stack([leg.jacobian(qleg[:, k]) for k, leg in enumerate(legs.values())], axis=1)
    rows = [
        compare(f"{nl} feet: FK vs oMf", np.linalg.norm(fk - pos, axis=-1), TOL),
        compare(f"{nl} feet: Jacobian vs getFrameJacobian (LWA, leg columns)", np.abs(jk - jac).max(axis=(-1, -2)),
                TOL),
    ]
    # IK round trip: the default branch (inside the limits, nearest mid-limit), checked by Pinocchio.
    q_ik = np.empty_like(qleg)
    ok = np.empty((samples, nl), dtype=bool)
    for k, leg in enumerate(legs.values()):
        q_ik[:, k], ok[:, k] = leg.ik(pos[:, k], return_mask=True)
        ok[:, k] &= np.all((q_ik[:, k] >= leg.lower) & (q_ik[:, k] <= leg.upper), axis=-1)
    back = pinocchio_feet(model, legs, _with_legs(model, legs, qs, np.where(ok[..., None], q_ik, 0.0)))
    err = np.where(ok, np.linalg.norm(back - pos, axis=-1), np.inf)
    rows.append(compare(f"IK round trip, Pinocchio FK of ik(p) ({int(ok.sum())}/{ok.size} solved in limits)", err, TOL))
    # Every branch of ik_all.
    q_all = np.empty((samples, nl, 4, 3))
    mask = np.empty((samples, nl, 4), dtype=bool)
    for k, leg in enumerate(legs.values()):
        q_all[:, k], mask[:, k] = leg.ik_all(pos[:, k], return_mask=True)
    errs = []
    for b in range(4):
        qb = np.where(mask[:, :, b, None], q_all[:, :, b], 0.0)
        back = pinocchio_feet(model, legs, _with_legs(model, legs, qs, qb))
        errs.append(np.linalg.norm(back - pos, axis=-1)[mask[:, :, b]])
    name = f"IK all branches, Pinocchio FK of ik_all(p) ({int(mask.sum())} branches)"
    rows.append(compare(name, np.concatenate(errs), TOL))
    return rows
