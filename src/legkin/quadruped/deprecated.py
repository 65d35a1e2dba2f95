"""The names of legkin 0.1, kept for one release: each warns (``DeprecationWarning``) and calls the new one.

| 0.1 | 0.2 |
| --- | --- |
| ``foot_position(q, leg, foot_z=...)`` | ``fk(q, leg, geometry=Geometry(foot_z=...))`` |
| ``foot_jacobian(q, leg, foot_z=...)`` | ``jacobian(q, leg, geometry=...)`` |
| ``foot_ik(p, leg, q_ref, foot_z=..., return_mask=...)`` | ``ik(p, leg, q_near=..., geometry=..., return_mask=...)`` |
| ``foot_ik_all(p, leg, foot_z=..., return_mask=...)`` | ``ik_all(p, leg, geometry=..., return_mask=...)`` |
"""

from __future__ import annotations

from typing import Literal, overload

import numpy as np
import numpy.typing as npt

from ._common import deprecated, legacy_geometry
from .closed_form import ik_all
from .forward import fk, jacobian
from .geometry import Geometry
from .inverse import ik

__all__ = ["foot_position", "foot_jacobian", "foot_ik", "foot_ik_all"]


def foot_position(
    q: npt.ArrayLike, leg: str, *, foot_z: float | None = None, geometry: Geometry | None = None
) -> np.ndarray:
    """Deprecated alias of :func:`~legkin.quadruped.fk` (``foot_z=``: ``geometry=Geometry(foot_z=...)``)."""
    deprecated("foot_position", "fk")
    return fk(q, leg, geometry=legacy_geometry(foot_z, geometry))


def foot_jacobian(
    q: npt.ArrayLike, leg: str, *, foot_z: float | None = None, geometry: Geometry | None = None
) -> np.ndarray:
    """Deprecated alias of :func:`~legkin.quadruped.jacobian`."""
    deprecated("foot_jacobian", "jacobian")
    return jacobian(q, leg, geometry=legacy_geometry(foot_z, geometry))


@overload
def foot_ik(
    p: npt.ArrayLike, leg: str, q_ref: npt.ArrayLike | None = None, *, foot_z: float | None = None,
    geometry: Geometry | None = None, return_mask: Literal[False] = False,
) -> np.ndarray: ...
@overload
def foot_ik(
    p: npt.ArrayLike, leg: str, q_ref: npt.ArrayLike | None = None, *, foot_z: float | None = None,
    geometry: Geometry | None = None, return_mask: Literal[True],
) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def foot_ik(
    p: npt.ArrayLike, leg: str, q_ref: npt.ArrayLike | None = None, *, foot_z: float | None = None,
    geometry: Geometry | None = None, return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...


def foot_ik(
    p: npt.ArrayLike, leg: str, q_ref: npt.ArrayLike | None = None, *, foot_z: float | None = None,
    geometry: Geometry | None = None, return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Deprecated alias of :func:`~legkin.quadruped.ik` (``q_ref``: ``q_near=``)."""
    deprecated("foot_ik", "ik (q_ref -> q_near=)")
    g = legacy_geometry(foot_z, geometry)
    return ik(p, leg, q_near=q_ref, geometry=g, return_mask=return_mask)


@overload
def foot_ik_all(
    p: npt.ArrayLike, leg: str, *, foot_z: float | None = None, geometry: Geometry | None = None,
    return_mask: Literal[False] = False,
) -> np.ndarray: ...
@overload
def foot_ik_all(
    p: npt.ArrayLike, leg: str, *, foot_z: float | None = None, geometry: Geometry | None = None,
    return_mask: Literal[True],
) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def foot_ik_all(
    p: npt.ArrayLike, leg: str, *, foot_z: float | None = None, geometry: Geometry | None = None,
    return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...


def foot_ik_all(
    p: npt.ArrayLike, leg: str, *, foot_z: float | None = None, geometry: Geometry | None = None,
    return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Deprecated alias of :func:`~legkin.quadruped.ik_all`."""
    deprecated("foot_ik_all", "ik_all")
    return ik_all(p, leg, geometry=legacy_geometry(foot_z, geometry), return_mask=return_mask)
