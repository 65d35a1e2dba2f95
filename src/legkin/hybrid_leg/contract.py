"""The hybrid leg's kinematic contract (:mod:`legkin._contract`): one case, the assembly mode of the SRDF reference
pose (motor branch (1, 1), assembly +1), the mode :func:`~legkin.hybrid_leg.fk` and :func:`~legkin.hybrid_leg.ik`
default to.

Measured (20,000 samples each, seed 1): ``|fk(ik(x)) - x|`` <= 3.1e-15 m; the Jacobian against central differences
(h = 1e-6) <= 9.4e-10 m/rad. The samples are well-conditioned platform poses (sigma_min(dtheta/d(roll, pitch)) >=
0.3, :data:`SIGMA_CONTRACT`): towards the forward singularity the FK's third derivative grows as 1 / sigma^5 and
central differences lose their digits (2.9e-7 at sigma >= 0.1, 1.8e-2 at sigma >= 0.01); there the Jacobian is
checked against Pinocchio's closed-loop Jacobian instead (``legkin check hybrid_leg``: error x sigma^3 row).
"""

from __future__ import annotations

import numpy as np

from .._contract import Case, Contract
from .configuration import sample_joints, within_limits
from .foot import fk, jacobian
from .foot_inverse import ik
from .geometry import CENTER

__all__ = ["contract", "SIGMA_CONTRACT"]

#: sigma_min(dtheta/d(roll, pitch)) of the contract's samples.
SIGMA_CONTRACT = 0.3

#: Targets no motor angles reach: beyond the LL arc's outer end (3.14 m), inside its inner end (0.14 m), on the
#: roll axis beyond the arc, and the LCS centre itself.
UNREACHABLE = np.array([CENTER + [0.0, 0.0, -3.5], CENTER + [0.0, 0.0, -0.1], CENTER + [4.0, 0.0, 0.0], CENTER])


def _sample(rng: np.random.Generator, n: int) -> np.ndarray:
    return sample_joints(rng, n, sigma=SIGMA_CONTRACT)


def contract() -> Contract:
    """The cases of the generic contract test (tests/test_contract.py)."""
    case = Case(
        name="branch (1, 1), assembly +1",
        nq=3,
        nx=3,
        fk=lambda q, return_mask=False: fk(q, return_mask=return_mask),
        ik=lambda x, return_mask=False: ik(x, return_mask=return_mask),
        jacobian=lambda q: jacobian(q),
        of=lambda q: fk(q),
        jacobian_of="fk",
        sample=_sample,
        within_limits=within_limits,
        unreachable=UNREACHABLE,
        round_trip_tol=1e-12,
        step=1e-6,
        jacobian_tol=1e-8,
    )
    return Contract(cases=(case,))
