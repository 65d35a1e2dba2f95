"""The kinematic contract of the robots :mod:`legkin.legs` serves (its registry entries, ``legs/spec.py``), on the
public API of :class:`legkin.legs.Leg`: one :class:`~legkin._contract.Case` per leg, for the generic test that every
registered model signs (tests/test_contract.py). A shared package's ``contract(name)`` takes the model's name."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._batch import as_input
from .._contract import Case, Contract
from ..errors import UnreachableError

__all__ = ["contract"]


def contract(name: str) -> Contract:
    """The contract of the robot ``name``: one case per leg measured from its model (a 3-DOF :class:`Leg`: foot
    position; a 6-DOF :class:`Leg6`: foot pose, flattened).

    Args:
        name: a registry name whose package is :mod:`legkin.legs` (:func:`legkin.list_models`).

    Returns:
        a :class:`~legkin._contract.Contract` whose cases are named by the legs (e.g. ``"FL"``).
    """
    from ..robot import load
    from .extract import from_model

    legs = from_model(load(name).model)
    return Contract(tuple(_case(leg) if leg.dof == 3 else _case6(leg) for leg in legs.values()))


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


def _flat(T: np.ndarray) -> np.ndarray:
    """A pose (..., 4, 4) as the vector (..., 12): the position (m), then the rotation matrix row by row."""
    T = np.asarray(T, dtype=float)
    return np.concatenate([T[..., :3, 3], T[..., :3, :3].reshape(T.shape[:-2] + (9,))], axis=-1)


def _pose(x: Any) -> np.ndarray:
    """The inverse of :func:`_flat`: a vector (..., 12) as a homogeneous transform (..., 4, 4)."""
    x = np.asarray(x, dtype=float)
    T = np.zeros(x.shape[:-1] + (4, 4))
    T[..., :3, 3] = x[..., :3]
    T[..., :3, :3] = x[..., 3:].reshape(x.shape[:-1] + (3, 3))
    T[..., 3, 3] = 1.0
    return T


def _case6(leg: Any) -> Case:
    """The contract case of one :class:`legkin.legs.Leg6` (joints (6,); the foot pose flattened to (12,) by
    :func:`_flat`, so that the generic test compares poses entry by entry, m and unitless rotation entries).

    Its Jacobian is the derivative of that vector: the linear rows of ``leg.jacobian`` (LOCAL_WORLD_ALIGNED), and
    for each joint the rotation's derivative ``[w_i]x R`` from the angular rows, which central differences of
    ``fk`` then check.
    """
    lo = np.maximum(np.asarray(leg.lower, dtype=float), -math.pi)  # a continuous joint: one turn
    hi = np.minimum(np.asarray(leg.upper, dtype=float), math.pi)

    def fk(q: Any, return_mask: bool = False) -> Any:
        x = _flat(leg.fk(q))
        return (x, np.isfinite(x).all(axis=-1)) if return_mask else x

    def ik(x: Any, return_mask: bool = False) -> Any:
        pose = _pose(as_input(x, "target", (12,)))  # the flattened form's own input check (shape, NaN, complex)
        try:
            return leg.ik(pose, return_mask=return_mask)
        except UnreachableError as exc:  # its data in the case's flattened form, as the generic test reads it
            exc.target = _flat(exc.target)
            exc.closest = None if exc.closest is None else _flat(exc.closest)
            raise

    def jacobian(q: Any) -> np.ndarray:
        J, R = np.asarray(leg.jacobian(q)), np.asarray(leg.fk(q))[..., :3, :3]
        w = np.moveaxis(J[..., 3:, :], -1, -2)  # (..., 6, 3): the angular velocity per joint
        skew = np.zeros(w.shape + (3,))
        skew[..., 0, 1], skew[..., 0, 2], skew[..., 1, 2] = -w[..., 2], w[..., 1], -w[..., 0]
        skew = skew - np.swapaxes(skew, -1, -2)
        dR = (skew @ R[..., None, :, :]).reshape(w.shape[:-1] + (9,))  # (..., 6, 9)
        return np.concatenate([J[..., :3, :], np.swapaxes(dR, -1, -2)], axis=-2)

    def sample(rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(lo, hi, (n, 6))

    def within_limits(q: np.ndarray) -> np.ndarray:
        return np.asarray(leg.within_limits(q))

    far = _flat(np.stack([np.eye(4)] * 2))
    far[:, :3] = [[10.0, 0.0, 0.0], [0.0, 0.0, -10.0]]  # 10 m from the root: beyond any leg's reach
    return Case(name=leg.name, nq=6, nx=12, fk=fk, ik=ik, jacobian=jacobian, of=fk, jacobian_of="fk",
                sample=sample, within_limits=within_limits, unreachable=far)
