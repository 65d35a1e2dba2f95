"""The hybrid leg's kinematic contract (:mod:`legkin._contract`): one case per assembly mode (motor branch (b1, b2)
and assembly +-1), each with :func:`~legkin.hybrid_leg.fk`, :func:`~legkin.hybrid_leg.ik` and
:func:`~legkin.hybrid_leg.jacobian` bound to that mode; the first, branch (1, 1), assembly +1, is the mode of the SRDF
reference pose, the one fk and ik default to.

Measured (20,000 samples per mode, seed 1, sigma >= 0.3): ``|fk(ik(x)) - x|`` <= 3.1e-15 m in the default mode, at
most 2.1e-13 m over the eight (branch (1, -1), assembly -1); the Jacobian against central differences (h = 1e-6)
<= 9.4e-10 m/rad in the default mode, at most 2.2e-9 over the eight. The samples are well-conditioned platform poses
(sigma_min(dtheta/d(roll, pitch)) >= 0.3, :data:`SIGMA_CONTRACT`): towards the forward singularity the FK's third
derivative grows as 1 / sigma^5 and central differences lose their digits (2.9e-7 at sigma >= 0.1, 1.8e-2 at sigma
>= 0.01); there the Jacobian is checked against Pinocchio's closed-loop Jacobian instead (``legkin check
hybrid_leg``: error x sigma^3 row). The default mode samples the neutral workspace
(:func:`.configuration.sample_joints`), the others every pose of the mode within the limits that the mode's fk
returns (:func:`.configuration.sample_mode_joints`).
"""

from __future__ import annotations

import numpy as np

from .._contract import Case, Contract
from .configuration import sample_joints, sample_mode_joints, within_limits
from .foot import fk, jacobian
from .foot_inverse import ik
from .geometry import CENTER, MOTOR_BRANCHES

__all__ = ["contract", "SIGMA_CONTRACT"]

#: sigma_min(dtheta/d(roll, pitch)) of the contract's samples.
SIGMA_CONTRACT = 0.3

#: Targets no motor angles reach: beyond the LL arc's outer end (3.14 m), inside its inner end (0.14 m), on the
#: roll axis beyond the arc, and the LCS centre itself.
UNREACHABLE = np.array([CENTER + [0.0, 0.0, -3.5], CENTER + [0.0, 0.0, -0.1], CENTER + [4.0, 0.0, 0.0], CENTER])


def _sample(rng: np.random.Generator, n: int) -> np.ndarray:
    return sample_joints(rng, n, sigma=SIGMA_CONTRACT)


def _case(branch: tuple[int, int], assembly: int) -> Case:
    """The case of one mode: fk, ik and jacobian bound to it."""
    b, s = branch, assembly
    if b == (1, 1) and s == 1:
        sample = _sample
    else:
        def sample(rng: np.random.Generator, n: int) -> np.ndarray:
            return sample_mode_joints(rng, n, b, s, sigma=SIGMA_CONTRACT)
    return Case(
        name=f"branch ({b[0]}, {b[1]}), assembly {s:+d}",
        nq=3,
        nx=3,
        fk=lambda q, return_mask=False: fk(q, branch=b, assembly=s, return_mask=return_mask),
        ik=lambda x, return_mask=False: ik(x, branch=b, assembly=s, return_mask=return_mask),
        jacobian=lambda q: jacobian(q, branch=b, assembly=s),
        of=lambda q: fk(q, branch=b, assembly=s),
        jacobian_of="fk",
        sample=sample,
        within_limits=within_limits,
        unreachable=UNREACHABLE,
        round_trip_tol=1e-12,
        step=1e-6,
        jacobian_tol=1e-8,
    )


def contract() -> Contract:
    """The cases of the generic contract test (tests/test_contract.py): the default mode first, then the other
    seven."""
    modes = [((1, 1), 1)] + [(b, s) for b in MOTOR_BRANCHES for s in (1, -1) if (b, s) != ((1, 1), 1)]
    return Contract(cases=tuple(_case(b, s) for b, s in modes))
