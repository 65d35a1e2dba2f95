"""Input checking and the scalar/batch convention shared by every analytic module.

The rule: a single input (an array of exactly the core shape, e.g. ``(3,)``)
returns plain arrays and raises a legkin error on failure; a batch (extra
leading dimensions) returns arrays with NaN where an item fails, and with
``return_mask=True`` also the boolean mask of successes.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import InvalidInputError

__all__ = ["as_input", "as_angles", "finish"]


def as_input(x, name: str, core: tuple[int, ...] = (), *, allow_nan: bool = False) -> np.ndarray:
    """Return ``x`` as a float array whose trailing shape is ``core``.

    Raises:
        InvalidInputError: (a ``ValueError``) wrong trailing shape, NaN/inf entries, complex or non-numeric
            input (a complex array is refused, never cut to its real part).
    """
    try:
        raw = np.asarray(x)
    except (TypeError, ValueError) as exc:  # ragged nested sequences
        raise InvalidInputError(f"{name} must be a numeric array, got {x!r}") from exc
    if raw.dtype.kind == "c":
        raise InvalidInputError(f"{name} must be real, got a complex array ({raw.dtype})")
    if raw.dtype.kind not in "biuf":
        raise InvalidInputError(f"{name} must be numeric, got {x!r}")
    arr = raw if raw.dtype == np.float64 else raw.astype(float)
    if core and (arr.ndim < len(core) or arr.shape[arr.ndim - len(core):] != core):
        raise InvalidInputError(
            f"{name} must have shape (..., {', '.join(map(str, core))}), got shape {arr.shape}"
        )
    if not allow_nan and not np.isfinite(arr).all():
        bad = arr[~np.isfinite(arr)].ravel()[0]
        raise InvalidInputError(f"{name} must be finite, got a {bad} entry")
    return arr


def as_angles(*xs, names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
    """Check scalar-per-item inputs (angles) and broadcast them together."""
    arrs = [as_input(x, n) for x, n in zip(xs, names)]
    try:
        return tuple(np.broadcast_arrays(*arrs))
    except ValueError as exc:
        shapes = ", ".join(f"{n}{a.shape}" for n, a in zip(names, arrs))
        raise InvalidInputError(f"inputs do not broadcast together: {shapes}") from exc


def finish(
    value,
    ok: np.ndarray,
    scalar: bool,
    return_mask: bool,
    error: Callable[[], Exception],
):
    """Apply the scalar/batch rule to a computed result.

    Args:
        value: the result, an array or a tuple of arrays, already NaN where ``ok`` is False.
        ok: boolean mask of successes (shape = the batch shape; ``()`` for a scalar call).
        scalar: True for a single input: raise ``error()`` on failure.
        return_mask: also return the mask.
        error: builds the exception for a failed scalar call (called only then).
    """
    ok = np.asarray(ok, dtype=bool)
    if scalar and not bool(ok):
        raise error()
    if return_mask:
        if isinstance(value, tuple):
            return (*value, ok)
        return value, ok
    return value
