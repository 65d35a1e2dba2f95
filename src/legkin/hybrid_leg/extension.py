"""The extension joint: LL driven by the leg-extension motor theta0 (seed 003, eq 19)."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input
from .._kernels import batch_kernel, kernel
from ..errors import InvalidInputError
from ._options import SCALARS, fast_geometry, flat, resolve
from .geometry import RATIO, Geometry

__all__ = ["ll_angle", "extension_motor_angle"]


@kernel(entry=True)
def ll_k(t0, sv):
    """Eq 19 (OCR artefact removed): ``theta_LL = -theta0 * 0.07 / (2 pi 1.5) + starting_value``."""
    return -RATIO * t0 + sv


@kernel(entry=True)
def theta0_k(tll, sv):
    """Eq 19 solved for theta0: ``(starting_value - theta_LL) / RATIO`` (inf beyond |theta_LL| ~ 1e306)."""
    return (sv - tll) / RATIO


@batch_kernel(rows="t out", min_parallel=8192)
def _ll_b(t, sv, out):
    for j in range(t.shape[0]):
        out[j] = ll_k(t[j], sv)


@batch_kernel(rows="t out", min_parallel=8192)
def _theta0_b(t, sv, out):
    for j in range(t.shape[0]):
        out[j] = theta0_k(t[j], sv)


def _apply(x: ArrayLike, name: str, sv: float, batch: Callable[..., object]
           ) -> np.ndarray | float:
    a = as_input(x, name)
    out = np.empty(a.size)
    batch(flat(a), sv, out)
    return out.reshape(a.shape) if a.ndim else np.float64(out[0])


def ll_angle(theta0: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray | float:
    """LL joint angle driven by the leg-extension motor (seed eq 19, OCR artefact removed).

    .. math:: \\theta_{LL} = -\\theta_0 \\frac{0.07}{2 \\pi \\, 1.5} + \\text{startingValue}

    The seed prints ``-1 * theta0 * 0 * 0.07 / (2 pi 1.5)``: the ``* 0`` is an OCR artefact (taken literally
    theta_LL would not depend on the motor). 0.07 m of travel per motor revolution applied on the 1.5 m arc
    of the foot: ~70 mm of near-vertical foot travel per revolution.

    Args:
        theta0: extension-motor angles (rad), any shape.
        geometry: the geometry (its ``starting_value`` is the LL zero offset, rad); None = the default.

    Returns:
        theta_LL (rad), same shape (a numpy float for a scalar).
    """
    g = fast_geometry(geometry)
    if type(theta0) in SCALARS and g is not None:
        return np.float64(ll_k(theta0, g.starting_value))
    g = resolve(geometry)
    return _apply(theta0, "theta0", g.starting_value, _ll_b)


def extension_motor_angle(theta_ll: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray | float:
    """Inverse of :func:`ll_angle`: ``theta0 = (starting_value - theta_LL) / RATIO`` (eq 19 solved for theta0).

    Args:
        theta_ll: LL joint angles (rad), any shape.
        geometry: the geometry (its ``starting_value`` is the LL zero offset, rad); None = the default.

    Returns:
        theta0 (rad), same shape (a numpy float for a scalar).
    """
    g = fast_geometry(geometry)
    if type(theta_ll) in SCALARS and g is not None:
        theta0 = theta0_k(theta_ll, g.starting_value)
        if math.isfinite(theta0):
            return np.float64(theta0)
    g = resolve(geometry)
    out = _apply(theta_ll, "theta_ll", g.starting_value, _theta0_b)
    if not np.isfinite(out).all():  # finite inputs (as_input): theta0 overflowed
        bad = float(np.asarray(theta_ll, dtype=float).ravel()[np.argmax(~np.isfinite(np.ravel(out)))])
        raise InvalidInputError(f"theta_ll={bad!r} rad is out of range: theta0 = (starting_value - theta_ll) / "
                                f"{RATIO:.6g} overflows beyond |theta_ll| ~ {RATIO * np.finfo(float).max:.3g} rad")
    return out
