"""The quadruped's cases of the generic contract test (:mod:`legkin._contract`): one per leg, default geometry.

Tolerances, measured (2026-12-01, 8,000 in-limit samples, on the quadruped's former closed form; the same rows
on :class:`legkin.legs.Leg`, 2026-12-04: ``legkin check quadruped``'s IK round trip, 6e-16 m): ``fk(ik(x))``
reproduces ``x`` to 2.2e-16 m on targets made from in-limit joints (a branch repaired into the limits to at most
``legkin.legs`` ``REACH_TOL`` = 1e-12 m), so ``round_trip_tol`` is 1e-12; the Jacobian against central differences
with step 1e-6 rad: 1.4e-10 m/rad at most (the rounding of the differences, ~eps |p| / h), bound 1e-9.
"""

from __future__ import annotations

import numpy as np

from .._contract import Case, Contract
from .configuration import sample_joints
from .constants import L1, LEGS, X34, Y12
from .kinematics import fk, hip_position, ik, jacobian, within_limits

__all__ = ["contract"]


def _unreachable(leg: str) -> np.ndarray:
    """Targets of ``leg`` no joint values reach: beyond full stretch, inside the abduction cylinder, too close
    to the hip (|L1 - L2| away in the leg plane, a hair less), and a huge finite one."""
    h = hip_position(leg)
    sy = 1.0 if leg[0] == "L" else -1.0
    inner = abs(L1 - X34) - 1e-3
    return np.array([
        h + [0.0, 0.0, -(L1 + X34 + 0.01)],
        h + [0.0, sy * 0.5 * Y12, 0.0],
        h + [inner, sy * Y12, 0.0],
        [1e300, 0.0, 0.0],
    ])


def _case(leg: str) -> Case:
    return Case(
        name=leg,
        nq=3,
        nx=3,
        fk=lambda q, return_mask=False: fk(q, leg, return_mask=return_mask),
        ik=lambda x, return_mask=False: ik(x, leg, return_mask=return_mask),
        jacobian=lambda q: jacobian(q, leg),
        of=lambda q: fk(q, leg),
        jacobian_of="fk",
        sample=sample_joints,
        within_limits=lambda q: np.asarray(within_limits(q, 0.0)),
        unreachable=_unreachable(leg),
        round_trip_tol=1e-12,
        step=1e-6,
        jacobian_tol=1e-9,
    )


def contract() -> Contract:
    """One :class:`~legkin._contract.Case` per leg (``LF``, ``LH``, ``RF``, ``RH``), default geometry."""
    return Contract(cases=tuple(_case(leg) for leg in LEGS))


