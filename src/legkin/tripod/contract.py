"""The tripod's cases of the generic kinematic contract (:mod:`legkin._contract`): one per assembly mode.

A case's joints are the three motors (q_A1, q_B1, q_C1) and its target the orientation (alpha_y, alpha_z):
``fk`` and ``ik`` of that mode, and the Jacobian of ``ik`` (A_u; ``fk`` is a least-squares solve of three motors
for two unknowns, so its derivative is not a function of independent inputs).
"""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np

from .._contract import Case, Contract
from ._common import HOME_MODE, MODES
from .configuration import sample_workspace, within_limits
from .forward import fk
from .inverse import ik, jacobian

#: Targets no configuration reaches in any mode (default geometry): tilts 0.3 rad beyond the boundary
#: (:func:`legkin.tripod.workspace`, tilt_max = 2 pi / 3 in these directions), and the platform singularity.
UNREACHABLE = np.array([[0.347, -2.465], [0.747, 3.0], [-0.347, 2.465], [0.0, np.pi]])
#: |fk(ik(x)) - x| measured over 16 modes x 200 samples: max 2.6e-13 rad (alpha_z is ill-conditioned near c_y = 0).
ROUND_TRIP_TOL = 1e-12


def _sample(rng: np.random.Generator, n: int, mode: str) -> np.ndarray:
    """``n`` in-limit motor triples of ``mode``: ik's motors of orientations uniform over the workspace (kept where
    that mode's ik, and fk, solve them)."""
    out: list[np.ndarray] = []
    total = 0
    while total < n:
        ay, az = sample_workspace(max(n, 16), rng)
        q, ok = ik(np.stack([ay, az], axis=-1), mode=mode, return_mask=True)
        q = q[ok]
        q = q[fk(q, mode=mode, return_mask=True)[1]]
        out.append(q)
        total += len(q)
    return np.concatenate(out)[:n]


def _case(mode: str) -> Case:
    bound_ik = partial(ik, mode=mode)
    bound_jacobian: Any = partial(jacobian, mode=mode)
    return Case(
        name=f"mode {mode}" + (" (home)" if mode == HOME_MODE else ""),
        nq=3,
        nx=2,
        fk=partial(fk, mode=mode),
        ik=bound_ik,
        jacobian=bound_jacobian,
        of=bound_ik,
        jacobian_of="ik",
        sample=partial(_sample, mode=mode),
        within_limits=within_limits,
        unreachable=UNREACHABLE,
        round_trip_tol=ROUND_TRIP_TOL,
        step=1e-6,
        jacobian_tol=1e-6,
    )


def contract() -> Contract:
    """One :class:`~legkin._contract.Case` per assembly mode (:data:`legkin.tripod.MODES`, home first)."""
    return Contract(cases=tuple(_case(m) for m in (HOME_MODE, *[m for m in MODES if m != HOME_MODE])))
