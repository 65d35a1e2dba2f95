"""What the quadruped's wrappers share: the leg look-up, the geometry check and the array fast path (private)."""

from __future__ import annotations

import numpy as np

from .._batch import as_input
from ..errors import InvalidParameterError
from .constants import LEGS
from .geometry import Geometry

LEG_INDEX = {leg: i for i, leg in enumerate(LEGS)}
F64 = np.dtype(np.float64)
S3 = (3,)


def leg_index(leg: object) -> int:
    """The index of ``leg`` in :data:`LEGS` (a dict look-up), or InvalidParameterError naming the legs."""
    try:
        return LEG_INDEX[leg]  # type: ignore[index]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"leg must be one of {', '.join(LEGS)}, got {leg!r}") from None


def foot_z_of(geometry: object) -> float:
    """``geometry.foot_z`` of a :class:`Geometry` (``None``: the default, 0.0)."""
    if geometry is None:
        return 0.0
    if isinstance(geometry, Geometry):
        return geometry.foot_z
    raise InvalidParameterError(f"geometry must be a legkin.quadruped.Geometry or None, got {geometry!r}")


def rows(x: object, name: str) -> np.ndarray:
    """``x`` as a float64 array (..., 3): a float64 ndarray of that shape as it is (its finiteness is the
    kernel's to test), anything else through :func:`as_input` (shape and type errors raised there)."""
    if type(x) is np.ndarray and x.dtype is F64 and x.ndim >= 1 and x.shape[-1] == 3:
        return x
    return as_input(x, name, S3, allow_nan=True)


def raise_bad(x: object, name: str) -> None:
    """Raise the error of :func:`as_input` for an array a kernel found NaN/inf in."""
    as_input(x, name, S3)
    raise AssertionError(f"{name}: a kernel reported a non-finite entry that as_input accepts")  # pragma: no cover
