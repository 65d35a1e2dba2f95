"""Input checking and the scalar/batch convention shared by every analytic module.

The rule: a single input (an array of exactly the core shape, e.g. ``(3,)``)
returns plain arrays and raises a legkin error on failure; a batch (extra
leading dimensions) returns arrays with NaN where an item fails, and with
``return_mask=True`` also the boolean mask of successes.
"""

from __future__ import annotations

import numbers
from typing import Callable, Sequence

import numpy as np

from .errors import InvalidArgumentError, InvalidInputError

__all__ = [
    "as_input",
    "as_angles",
    "finish",
    "real_number",
    "check_number",
    "check_integer",
    "check_flag",
    "check_choice",
]


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
    if raw.dtype.kind == "O" and raw.size and all(type(v) is int for v in raw.ravel()):  # ints beyond int64
        big = [v for v in raw.ravel() if abs(v) > int(np.finfo(float).max)]
        if big:
            raise InvalidInputError(f"{name} must be finite, got an integer of {len(str(abs(big[0])))} digits, "
                                    "beyond the largest float (1.8e308)")
        raw = raw.astype(float)
    if raw.dtype.kind not in "biuf":
        raise InvalidInputError(f"{name} must be numeric, got {x!r}")
    arr = raw if raw.dtype == np.float64 else raw.astype(float)
    if core and (arr.ndim < len(core) or arr.shape[arr.ndim - len(core):] != core):
        raise InvalidInputError(
            f"{name} must have shape (..., {', '.join(map(str, core))}), got shape {arr.shape}"
        )
    if not allow_nan and not np.isfinite(arr).all():
        raise InvalidInputError(_not_finite(arr, name, len(core)))
    return arr


def _not_finite(arr: np.ndarray, name: str, core: int) -> str:
    """The message for an array with a NaN or inf entry: the first such entry, and in a batch its row (the index
    over the leading dimensions), e.g. ``target must be finite: row 3 has inf (target[3, 0])``."""
    where = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
    value = arr[where]
    if arr.ndim <= core:
        return f"{name} must be finite, got a {value} entry"
    lead = where[: arr.ndim - core]
    row = lead[0] if len(lead) == 1 else lead
    return f"{name} must be finite: row {row} has {value} ({name}[{', '.join(map(str, where))}])"


#: Items per chunk of a batch that a function splits to bound its working memory (:func:`in_chunks`): 65,536 items
#: keep a wheel_leg.ik chunk's temporaries (~310 B an item) near 20 MB.
CHUNK = 1 << 16


def in_chunks(solve: Callable[..., tuple[np.ndarray, np.ndarray]], rows: Sequence[np.ndarray | None],
              out_core: int, chunk: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run a batch ``chunk`` items at a time, so that its temporaries take ``chunk`` items' worth of memory, not n's.

    Args:
        solve: ``solve(*rows_slice) -> (values (m, out_core), mask (m,))`` on consecutive slices of the rows.
        rows: the per-item inputs, each (n, ...) (sliced) or None (passed as None); the first is not None.
        out_core: the width of one item's values.
        chunk: items per call (default :data:`CHUNK`).

    Returns:
        ``(values (n, out_core), mask (n,))``, filled chunk by chunk (the only arrays of n items allocated here).
    """
    n = next(x for x in rows if x is not None).shape[0]
    chunk = CHUNK if chunk is None else chunk
    values, mask = np.empty((n, out_core)), np.empty(n, dtype=bool)
    for lo in range(0, n, chunk):
        hi = min(n, lo + chunk)
        v, m = solve(*(None if x is None else x[lo:hi] for x in rows))
        values[lo:hi], mask[lo:hi] = v, m
    return values, mask


def as_angles(*xs, names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
    """Check scalar-per-item inputs (angles) and broadcast them together."""
    arrs = [as_input(x, n) for x, n in zip(xs, names)]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrs))
    except ValueError as exc:
        shapes = ", ".join(f"{n}{a.shape}" for n, a in zip(names, arrs))
        raise InvalidInputError(f"inputs do not broadcast together: {shapes}") from exc
    # writeable arrays (a copy where one is broadcast): numba types read-only arrays apart (a second compilation)
    return tuple(a if a.shape == shape else np.broadcast_to(a, shape).copy() for a in arrs)


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


def real_number(value, name: str, valid) -> float:
    """A real scalar parameter (int, float, numpy real, 0-d real array; not bool, str, complex) as float.

    ``valid``: the range text for the message (or a callable making it, called only on failure). The range
    itself is the caller's to check.
    """
    if type(value) is float:  # the common case, fast
        return value
    ok = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    if not ok and isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        ok, value = True, value.item()
    if not ok:
        text = valid() if callable(valid) else valid
        raise InvalidArgumentError(f"{name} must be a real number, got {value!r}; valid range {text}")
    try:
        return float(value)
    except OverflowError:  # an int beyond the float range
        text = valid() if callable(valid) else valid
        raise InvalidArgumentError(f"{name}={value!r} is out of range: valid range {text}") from None


def _range_text(low, high, low_open: bool, high_open: bool) -> str:
    lo = "-inf" if low is None else f"{low:g}"
    hi = "inf" if high is None else f"{high:g}"
    return f"{'(' if low_open or low is None else '['}{lo}, {hi}{')' if high_open or high is None else ']'}"


def check_number(
    value, name: str, low: float | None = None, high: float | None = None, *,
    low_open: bool = False, high_open: bool = False,
) -> float:
    """A keyword parameter that must be one finite real number in a range; returns it as a float.

    Raises:
        InvalidArgumentError: (a ``ValueError``) not a real number, NaN/inf, or outside the range; the
            message names the value and the range.
    """
    rng = _range_text(low, high, low_open, high_open)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        if not (isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"):
            raise InvalidArgumentError(f"{name} must be a real number in {rng}, got {value!r}")
    try:
        v = float(value)
    except OverflowError:  # an int beyond the float range
        raise InvalidArgumentError(f"{name}={value!r} is out of range: must be a finite number in {rng}") from None
    bad = not np.isfinite(v)
    if low is not None:
        bad |= v <= low if low_open else v < low
    if high is not None:
        bad |= v >= high if high_open else v > high
    if bad:
        raise InvalidArgumentError(f"{name}={v!r} is out of range: must be a finite number in {rng}")
    return v


def check_integer(value, name: str, low: int | None = None, high: int | None = None) -> int:
    """A keyword parameter that must be an integer in ``[low, high]``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        span = _range_text(low, high, False, False)
        raise InvalidArgumentError(f"{name} must be an integer in {span}, got {value!r}")
    v = int(value)
    if (low is not None and v < low) or (high is not None and v > high):
        span = _range_text(low, high, False, False)
        raise InvalidArgumentError(f"{name}={v} is out of range: must be an integer in {span}")
    return v


def check_flag(value, name: str) -> bool:
    """A keyword parameter that must be a bool."""
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgumentError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_choice(value, name: str, choices) -> object:
    """A keyword parameter that must be one of ``choices`` (compared with ==, hashable values only)."""
    try:
        ok = value in tuple(choices)
    except Exception:  # noqa: BLE001 - an unhashable or array value is simply not a valid choice
        ok = False
    if isinstance(value, np.ndarray) or not ok:
        raise InvalidArgumentError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value
