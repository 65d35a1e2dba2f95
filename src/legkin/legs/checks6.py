"""``legkin check`` rows of a robot with 6-DOF legs (:class:`~legkin.legs.Leg6`) against Pinocchio.

Every sample draws each leg's six joints uniformly in their URDF limits (the other joints, and the floating base
if any, at the neutral configuration: the world frame is then the root frame). Rows, merged over the legs:

* ``feet FK vs oMf``: max |Leg6.fk(q) - oMf[foot]| over the 4x4 entries;
* ``feet Jacobian vs getFrameJacobian``: max |Leg6.jacobian(q) - J| over the 6x6 block (LOCAL_WORLD_ALIGNED, the
  leg's six columns);
* for legs with an IK (``6R-spherical-hip``, ``6R-three-parallel``): ``IK round trip`` (max entry of Pinocchio's foot at
  ``Leg6.ik(T)`` minus ``T``; unsolved or outside the limits counts as infinite), ``IK all solutions``
  (the same for every row of ``ik_all``), ``sampled q among ik_all``: the distance (rad, max over the joints, mod
  2 pi) from the sampled configuration to the nearest row, times the least singular value ``sigma_min`` of the foot
  Jacobian at the sampled configuration (see :data:`C_AMONG`).
"""

from __future__ import annotations

import numpy as np

from .._checkkit import CheckResult, compare
from ._reference import pinocchio_poses

__all__ = ["rows6", "TOL6", "C_AMONG"]

#: Tolerance of the FK, Jacobian and round-trip rows (m, rad per 4x4 entry). Measured over seeds 0-19 at 10^3-10^5
#: samples (``scripts/check_sweep.py``, docs/legs.md): FK and Jacobian <= 3.1e-15 (icub; ~7e-16 elsewhere); round
#: trips <= 6.2e-15 on the closed forms, 1.6e-14 on alexander, 9.7e-14 on g1: every answer is polished until its pose
#: error (a norm) is below ``POLISH_BELOW6`` = 1e-13, a tenth of this tolerance, which the Newton steps reach unless
#: the closed form or the search lost the digits first (talos at seed 12, 10^5 samples, before the subproblems' fix).
TOL6 = 1e-12
#: The sampled configuration ``q`` is among ik_all's rows when its distance ``gap`` (rad) to the nearest row obeys
#: ``gap * sigma_min(J(q)) <= C_AMONG * TOL6``. The pose fixes the joints only through the Jacobian: two configurations
#: whose foot poses differ by ``dx`` (a 6-vector, m and rad) are ``|dx| / sigma_min`` apart to first order, and a
#: second order term (a fold, where two solutions merge) only brings them closer; a row that passes the ``IK all
#: solutions`` row reproduces the pose to ``TOL6`` per 4x4 entry, i.e. ``|dx| <= sqrt(3 + 9/2) TOL6 = 2.74 TOL6``
#: (position: 3 entries; rotation: ``|w| = |dR|_F / sqrt 2``, 9 entries). So ``C_AMONG = 3`` is a bound from the
#: conditioning, not a fit: no sample can fail by chance while the IK rows pass, and a missing branch fails (the
#: nearest other row is ~0.1-3 rad away: ``gap * sigma_min`` ~1e-6 or more unless ``sigma_min < 1e-11``). Measured
#: over seeds 0-19 at 10^3-10^5 samples (``scripts/check_sweep.py``, docs/legs.md): ``gap * sigma_min`` <= 4.6e-15
#: (g1), 2.7e-15 (icub), 1e-15 on the others, at most 0.15 % of the tolerance (before the subproblems' fix, 5.0e-12 on
#: talos: a closed-form row 2.4e-11 off its pose near a singular one, ``sigma_min`` = 1.7e-7).
C_AMONG = 3.0


def _with(model, legs: dict, qleg: np.ndarray) -> np.ndarray:
    """Neutral configurations (N, nq) with each leg's joints from ``qleg`` (N, L, 6)."""
    import pinocchio as pin

    qs = np.tile(pin.neutral(model), (len(qleg), 1))
    for k, leg in enumerate(legs.values()):
        qs[:, list(leg.idx_q)] = qleg[:, k]
    return qs


def _ik_rows(model, legs: dict, qleg: np.ndarray, poses: np.ndarray) -> list[CheckResult]:
    closed = [k for k, leg in enumerate(legs.values()) if leg.n_solutions > 0]
    if not closed:
        return []
    items = list(legs.values())
    q_ik = np.zeros_like(qleg)
    ok = np.ones(qleg.shape[:2], dtype=bool)
    rows = max(leg.n_solutions for leg in items)
    q_all = np.zeros(qleg.shape[:1] + (len(items), rows, 6))
    mask = np.zeros(qleg.shape[:1] + (len(items), rows), dtype=bool)
    among = []
    for k in closed:
        leg = items[k]
        q_ik[:, k], ok[:, k] = leg.ik(poses[:, k], return_mask=True)
        ok[:, k] &= np.asarray(leg.within_limits(np.nan_to_num(q_ik[:, k])))
        q_all[:, k, :leg.n_solutions], mask[:, k, :leg.n_solutions] = leg.ik_all(poses[:, k], return_mask=True)
        gap = np.abs(np.angle(np.exp(1j * (q_all[:, k] - qleg[:, k, None])))).max(axis=-1)
        gap = np.nanmin(np.where(mask[:, k], gap, np.inf), axis=-1)
        among.append(gap * np.linalg.svd(leg.jacobian(qleg[:, k]), compute_uv=False)[:, -1])  # see C_AMONG
    back, _ = pinocchio_poses(model, legs, _with(model, legs, np.where(ok[..., None], q_ik, 0.0)), False)
    err = np.where(ok, np.abs(back - poses).max(axis=(-1, -2)), np.inf)[:, closed]
    errs = []
    for b in range(rows):
        qb = np.where(mask[:, :, b, None], q_all[:, :, b], 0.0)
        back_b, _ = pinocchio_poses(model, legs, _with(model, legs, qb), False)
        errs.append(np.abs(back_b - poses).max(axis=(-1, -2))[:, closed][mask[:, closed, b]])
    n_closed = len(closed)
    return [
        compare(f"{n_closed} feet: IK round trip, Pinocchio FK of ik(T) ({int(ok[:, closed].sum())}/{err.size} "
                f"solved in limits)", err, TOL6),
        compare(f"{n_closed} feet: IK all solutions, Pinocchio FK of ik_all(T) ({int(mask.sum())} solutions)",
                np.concatenate(errs), TOL6),
        compare(f"{n_closed} feet: the sampled q among ik_all(T) (q distance x sigma_min(J), m)", np.concatenate(among),
                C_AMONG * TOL6),
    ]


def rows6(model, legs: dict, samples: int, rng: np.random.Generator) -> list[CheckResult]:
    """The check rows (see the module docstring) of the 6-DOF ``legs`` of ``model`` on ``samples`` configurations."""
    qleg = np.stack([rng.uniform(leg.lower, leg.upper, (samples, 6)) for leg in legs.values()], axis=1)
    poses, jac = pinocchio_poses(model, legs, _with(model, legs, qleg), True)
    fk = np.stack([leg.fk(qleg[:, k]) for k, leg in enumerate(legs.values())], axis=1)
    jk = np.stack([leg.jacobian(qleg[:, k]) for k, leg in enumerate(legs.values())], axis=1)
    structures = sorted({leg.structure for leg in legs.values()})
    nl = len(legs)
    return [
        compare(f"{nl} feet ({', '.join(structures)}): FK vs oMf (4x4)", np.abs(fk - poses).max(axis=(-1, -2)), TOL6),
        compare(f"{nl} feet: Jacobian vs getFrameJacobian (LWA, 6x6)", np.abs(jk - jac).max(axis=(-1, -2)), TOL6),
        *_ik_rows(model, legs, qleg, poses),
    ]
