"""Rotation and angle helpers, one module with one wrap convention for all of legkin.

Convention: an angle is wrapped to ``(-pi, pi]`` (``wrap(pi) == pi``, ``wrap(-pi) == pi``), by
``pi - ((pi - a) mod 2 pi)`` with the floor modulo (numpy's ``np.mod``, Python's ``%`` on floats, numba's
``%``): within one rounding of pi of ``a`` for |a| <= pi, and the same bits in numpy and in a kernel.

Kernels (numba, for use inside other kernels): :func:`wrap_k`, :func:`rot_k`. Numpy (checks, benches,
figures): :func:`wrap`, :func:`rot_x`, :func:`rot_y`, :func:`rot_z`, :func:`rotation_angle`.
"""

from __future__ import annotations

import math

import numpy as np

from ._kernels import kernel

__all__ = ["wrap", "wrap_k", "rot_k", "rot_x", "rot_y", "rot_z", "rotation_angle"]

_TWO_PI = 2.0 * math.pi


@kernel
def wrap_k(a: float) -> float:
    """An angle wrapped to (-pi, pi] (compiled; the one wrap of every kernel)."""
    return math.pi - (math.pi - a) % _TWO_PI


def wrap(a):  # noqa: ANN001, ANN201 -- array-like in, same shape out
    """Angles (any shape, or a scalar) wrapped to (-pi, pi], the same bits as :func:`wrap_k`."""
    return np.pi - np.mod(np.pi - np.asarray(a, dtype=np.float64), 2.0 * np.pi)


@kernel
def rot_k(axis: int, t: float) -> tuple[float, float, float, float, float, float, float, float, float]:
    """The elementary rotation about axis 0 (x), 1 (y) or 2 (z) by ``t``, as a row-major 9-tuple."""
    c, s = math.cos(t), math.sin(t)
    if axis == 0:
        return (1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
    if axis == 1:
        return (c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
    return (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)


def _elementary(axis: int, t) -> np.ndarray:  # noqa: ANN001
    t = np.asarray(t, dtype=np.float64)
    c, s = np.cos(t), np.sin(t)
    o, z = np.ones_like(t), np.zeros_like(t)
    rows = {
        0: ((o, z, z), (z, c, -s), (z, s, c)),
        1: ((c, z, s), (z, o, z), (-s, z, c)),
        2: ((c, -s, z), (s, c, z), (z, z, o)),
    }[axis]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def rot_x(t) -> np.ndarray:  # noqa: ANN001
    """Rotation matrices about x: ``t`` (...) -> (..., 3, 3)."""
    return _elementary(0, t)


def rot_y(t) -> np.ndarray:  # noqa: ANN001
    """Rotation matrices about y: ``t`` (...) -> (..., 3, 3)."""
    return _elementary(1, t)


def rot_z(t) -> np.ndarray:  # noqa: ANN001
    """Rotation matrices about z: ``t`` (...) -> (..., 3, 3)."""
    return _elementary(2, t)


def rotation_angle(ra: np.ndarray, rb: np.ndarray) -> np.ndarray:
    """The angle (rad) of ``ra^T rb`` for rotation matrices (..., 3, 3): the distance between them on SO(3).

    Computed as ``2 atan2(|v|, w)`` from the quaternion-like parts of ``ra^T rb``: accurate to rounding for
    small and for large angles (``arccos((tr - 1) / 2)`` loses half the digits near 0).
    """
    m = np.swapaxes(np.asarray(ra, dtype=np.float64), -1, -2) @ np.asarray(rb, dtype=np.float64)
    v = np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]], -1)
    w = 1.0 + m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=-1) / 2.0, w / 2.0)
