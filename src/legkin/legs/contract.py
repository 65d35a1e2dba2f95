"""The kinematic contract of the robots :mod:`legkin.legs` serves (its registry entries, ``legs/spec.py``), on the
public API of :class:`legkin.legs.Leg`: one :class:`~legkin._contract.Case` per leg, for the generic test that every
registered model signs (tests/test_contract.py). A shared package's ``contract(name)`` takes the model's name."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._contract import Case, Contract

__all__ = ["contract"]


def contract(name: str) -> Contract:
    """The contract of the robot ``name``: one case per leg measured from its model.

    Args:
        name: a registry name whose package is :mod:`legkin.legs` (:func:`legkin.list_models`).

    Returns:
        a :class:`~legkin._contract.Contract` whose cases are named by the legs (e.g. ``"FL"``).
    """
    from ..robot import load
    from .extract import from_model

    legs = from_model(load(name).model)
    return Contract(tuple(_case(leg) for leg in legs.values()))


def _case(leg: Any) -> Case:
    """The contract case of one :class:`legkin.legs.Leg` (joints (3,), foot position (3,) in m)."""
    lo = np.maximum(np.asarray(leg.lower, dtype=float), -math.pi)  # a continuous joint: one turn
    hi = np.minimum(np.asarray(leg.upper, dtype=float), math.pi)

    def fk(q: Any, return_mask: bool = False) -> Any:
        x = leg.fk(q)
        return (x, np.isfinite(x).all(axis=-1)) if return_mask else x

    def sample(rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(lo, hi, (n, 3))

    def within_limits(q: np.ndarray) -> np.ndarray:
        return np.asarray(leg.within_limits(q))

    reach = sum(float(np.linalg.norm(v)) for v in (leg.hip_offset, leg.thigh, leg.shank)) + abs(leg.lateral_offset)
    far = np.asarray(leg.origin, dtype=float) + (reach + 1.0) * np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    return Case(name=leg.name, nq=3, nx=3, fk=fk, ik=leg.ik, jacobian=leg.jacobian, of=leg.fk, jacobian_of="fk",
                sample=sample, within_limits=within_limits, unreachable=far)
