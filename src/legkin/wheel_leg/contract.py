"""The wheel-leg's cases of the generic kinematic contract (:mod:`legkin._contract`, tests/test_contract.py).

One case per leg on the continuous rim, plus leg FL on the seed's three-arc rim. Each binds the contact FK
(:func:`~legkin.wheel_leg.fk`), the default IK (:func:`~legkin.wheel_leg.ik`, radial) and the contact Jacobian
(:func:`~legkin.wheel_leg.jacobian`) at one fixed rim point (alpha, w).

Tolerances (measured): the round trip is the IK's own tolerance, 1e-12 m (every radial answer is checked
with the FK against it). The Jacobian against central differences with h = 1e-6: truncation ~h^2 |p'''| plus
rounding ~eps |p| / h, measured ~1.3e-10 (the check rows use 1e-8); 1e-8 here too.
"""

from __future__ import annotations

import numpy as np

from .._contract import Case, Contract
from .configuration import sample_q_in_limits, within_limits
from .frames import fk, jacobian
from .geometry import LEGS
from .inverse import ik

#: The rim point of every case: an upper-rim point off the toe, a little off the mid-plane.
ALPHA, W = 0.7, 0.005
STEP = 1e-6


def _case(leg: str, rim: str) -> Case:
    def f(q, return_mask=False):
        return fk(q, leg, alpha=ALPHA, w=W, rim=rim, return_mask=return_mask)

    def inv(x, return_mask=False):
        return ik(x, leg, alpha=ALPHA, w=W, rim=rim, return_mask=return_mask)

    def jac(q):
        return jacobian(q, leg, alpha=ALPHA, w=W, rim=rim)

    def sample(rng: np.random.Generator, n: int) -> np.ndarray:
        return sample_q_in_limits(n, rng, margin=10 * STEP)  # the central differences stay inside theta's domain

    unreachable = np.array([[0.3, 0.2, -0.6], [5.0, 5.0, 5.0], [0.255, 0.12, 0.057166]])
    return Case(
        name=leg if rim == "continuous" else f"{leg} rim={rim}",
        nq=3, nx=3, fk=f, ik=inv, jacobian=jac, of=lambda q: f(q), jacobian_of="fk",
        sample=sample, within_limits=within_limits, unreachable=unreachable,
        round_trip_tol=1e-12, step=STEP, jacobian_tol=1e-8,
    )


def contract() -> Contract:
    """The wheel-leg's contract: legs FL, FR, RR, RL on the continuous rim, FL on the three-arc rim."""
    return Contract(cases=tuple(_case(leg, "continuous") for leg in LEGS) + (_case("FL", "three_arc"),))
