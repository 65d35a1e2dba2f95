"""The kinematic contract every mechanism signs, in one form the generic test (tests/test_contract.py) runs.

Each mechanism package ``legkin.<name>`` has a module ``contract`` with ``contract() -> Contract``: one
:class:`Case` per variant of its kinematics (a leg, an assembly mode or branch), each binding its forward
kinematics, its IK and a Jacobian to plain callables. The test written once over the registry checks, for
every case of every mechanism:

* FK then IK round trip: on ``sample(rng, n)`` (in-limit joint values), every target ``fk(q)`` is solved by
  the default IK (mask all True), ``fk(ik(x)) == x`` to ``round_trip_tol`` and the answers are in limits;
* ``jacobian(u)`` against central differences of ``of(u)`` (``of`` is ``fk`` or ``ik``: what the
  Jacobian differentiates);
* a single call equals the same row of a batch call (bit for bit) for ``fk``, ``ik`` and ``jacobian``;
* a batch with unreachable targets gives NaN rows and a False mask; the single call raises a legkin error;
* NaN, inf, complex and wrong-shaped inputs raise :class:`~legkin.errors.InvalidInputError` (a ValueError);
* the mechanism's ``legkin check`` rows pass, among them a Jacobian against Pinocchio.

A new mechanism inherits all of this by writing its ``contract()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

__all__ = ["Case", "Contract"]


@dataclass(frozen=True)
class Case:
    """One variant of a mechanism's kinematics, bound to callables of one array argument.

    Attributes:
        name: e.g. ``"LF"`` or ``"mode -+++"``.
        nq, nx: sizes of a joint vector and of a target.
        fk: ``fk(q, return_mask=False)``: (nq,) -> (nx,) or (n, nq) -> (n, nx) (every option bound).
        ik: ``ik(x, return_mask=False)``: the default IK, (nx,) -> (nq,) or (n, nx) -> (n, nq).
        jacobian: ``jacobian(u)``: the derivative of ``of`` at ``u``, (m,) -> (k, m), batched likewise.
        of: the function ``jacobian`` differentiates (``fk`` or ``ik``; single input -> single output).
        jacobian_of: ``"fk"`` or ``"ik"``: which of the two ``of`` is (the argument sampled for the
            finite differences is then ``q`` or ``fk(q)``).
        sample: ``sample(rng, n) -> (n, nq)``: joint values inside the URDF limits whose ``fk`` is defined.
        within_limits: ``within_limits(q) -> (n,) bool``: the URDF joint limits, for IK answers.
        unreachable: (k, nx) targets that no joint values reach.
        round_trip_tol: bound on ``|fk(ik(x)) - x|`` (m or rad).
        step: central-difference step.
        jacobian_tol: bound on the difference to central differences (absolute, per entry).
    """

    name: str
    nq: int
    nx: int
    fk: Callable[..., Any]
    ik: Callable[..., Any]
    jacobian: Callable[[np.ndarray], np.ndarray]
    of: Callable[[np.ndarray], np.ndarray]
    jacobian_of: str
    sample: Callable[[np.random.Generator, int], np.ndarray]
    within_limits: Callable[[np.ndarray], np.ndarray]
    unreachable: np.ndarray
    round_trip_tol: float = 1e-12
    step: float = 1e-6
    jacobian_tol: float = 1e-6


@dataclass(frozen=True)
class Contract:
    """A mechanism's cases (see the module docstring)."""

    cases: tuple[Case, ...]
