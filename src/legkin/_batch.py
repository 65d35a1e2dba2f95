"""Input checking and the scalar/batch convention shared by every analytic module.

The rule: a single input (an array of exactly the core shape, e.g. ``(3,)``)
returns plain arrays and raises a legkin error on failure; a batch (extra
leading dimensions) returns arrays with NaN where an item fails, and with
``return_mask=True`` also the boolean mask of successes.
"""

from __future__ import annotations

import inspect
import math
import numbers
from typing import Any, Callable, Iterable, Sequence, TypeVar, cast

import numpy as np

from .errors import InvalidArgumentError, InvalidInputError

F = TypeVar("F", bound=Callable[..., Any])

__all__ = [
    "as_input",
    "dispatch",
    "as_angles",
    "finish",
    "same_signature",
    "real_number",
    "check_number",
    "check_integer",
    "check_flag",
    "check_choice",
    "interval_text",
    "outside",
]


def as_input(x: object, name: str, core: tuple[int, ...] = (), *, allow_nan: bool = False) -> np.ndarray:
    """Return ``x`` as a float array whose trailing shape is ``core``.

    Args:
        x: the input, array-like.
        name: its name in the messages.
        core: the trailing shape of one item (``()``: scalars).
        allow_nan: accept NaN and inf entries.

    Returns:
        a float64 array (``x`` itself when it already is one).

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


#: Items per chunk of a batch (:func:`in_chunks`): a batch's temporaries take at most this many items' worth of
#: memory (65,536 items keep a wheel_leg.ik chunk's temporaries, ~310 B an item, near 20 MB).
CHUNK = 1 << 16


def in_chunks(solve: Callable[..., tuple[np.ndarray, ...]], rows: Sequence[np.ndarray | None],
              chunk: int | None = None) -> tuple[np.ndarray, ...]:
    """Run a batch ``chunk`` items at a time, so that its temporaries take ``chunk`` items' worth of memory, not n's.

    Args:
        solve: ``solve(*rows_slice) -> (arrays, each (m, ...))`` on consecutive slices of the rows (e.g. the values
            and the mask).
        rows: the per-item inputs, each (n, ...) (sliced) or None (passed as None); the first is not None.
        chunk: items per call (default :data:`CHUNK`).

    Returns:
        ``solve``'s arrays for the n items: its own answer when n <= ``chunk``, else arrays of n items filled chunk
        by chunk (the only arrays of n items allocated here).
    """
    n = next(x for x in rows if x is not None).shape[0]
    chunk = CHUNK if chunk is None else chunk
    part = solve(*(None if x is None else x[:chunk] for x in rows))
    if n <= chunk:
        return part
    whole = tuple(np.empty((n,) + a.shape[1:], a.dtype) for a in part)
    for lo in range(0, n, chunk):
        if lo:
            part = solve(*(None if x is None else x[lo:lo + chunk] for x in rows))
        for a, b in zip(whole, part):
            a[lo:lo + chunk] = b
    return whole


def _batch_rows(batch: Callable[..., tuple[np.ndarray, np.ndarray]], rows: np.ndarray,
                args: tuple[Any, ...]) -> tuple[np.ndarray, ...]:
    """``batch(rows, *args)`` by chunks of :data:`CHUNK` rows (:func:`in_chunks`); an argument that is an array with
    one row per item (first dimension n, e.g. a ``q_near`` per target) is cut with the rows."""
    n = rows.shape[0]
    per_row = [i for i, a in enumerate(args) if type(a) is np.ndarray and a.ndim > 0 and a.shape[0] == n]

    def solve(r: np.ndarray, *cut: np.ndarray) -> tuple[np.ndarray, ...]:
        part = list(args)
        for i, c in zip(per_row, cut):
            part[i] = c
        return batch(r, *part)

    return in_chunks(solve, [rows, *(args[i] for i in per_row)])


def as_angles(*xs: object, names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
    """Check scalar-per-item inputs (angles) and broadcast them together.

    Args:
        *xs: the inputs (rad, or any unit), array-like.
        names: their names in the messages.

    Returns:
        the float64 arrays, each of the broadcast shape (writeable).

    Raises:
        InvalidInputError: an input :func:`as_input` refuses, or shapes that do not broadcast.
    """
    arrs = [as_input(x, n) for x, n in zip(xs, names)]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrs))
    except ValueError as exc:
        shapes = ", ".join(f"{n}{a.shape}" for n, a in zip(names, arrs))
        raise InvalidInputError(f"inputs do not broadcast together: {shapes}") from exc
    # writeable arrays (a copy where one is broadcast): numba types read-only arrays apart (a second compilation)
    return tuple(a if a.shape == shape else np.broadcast_to(a, shape).copy() for a in arrs)


#: The float64 dtype: the fast path tests ``x.dtype is F64`` (3x cheaper than ``== np.float64``).
F64 = np.dtype(np.float64)
_TRUE = np.asarray(True)
_TRUE.setflags(write=False)


def dispatch(
    x: object,
    name: str,
    core: tuple[int, ...],
    fast: Callable[..., Any],
    batch: Callable[..., tuple[np.ndarray, np.ndarray]],
    error: Callable[..., Exception],
    args: tuple[Any, ...],
    return_mask: bool,
    *,
    chunks: bool = True,
) -> Any:
    """The single/batch rule of a kinematic function of one array argument, written once.

    Three paths, in this order:

    1. **fast**: ``x`` is a float64 ndarray of exactly the ``core`` shape: ``fast(x, args)`` (the kernel on that
       item; ``args`` as one tuple, which ``fast`` unpacks: a call ``fast(x, *args)`` took 70-100 ns more, 3-5 % of
       a single call) returns the result, or None when the item is not solved (then path 2 decides, and raises);
    2. **single call**: any other single input (a list, ints, NaN...) is checked by :func:`as_input` (which raises
       :class:`~legkin.errors.InvalidInputError`) and run through ``batch`` as one row, so that a single call equals
       its row of a batch bit for bit; if the row is not solved, ``error(item, out, ok, *args)`` is raised;
    3. **batch**: leading dimensions: ``batch(rows, *args)`` on the C-contiguous float64 rows ``(n, *core)``, by
       chunks of :data:`CHUNK` rows (:func:`in_chunks`): its memory beyond the answer stays bounded; an argument
       of ``args`` that is an array with one row per item (first dimension n) is cut with the rows.

    ``batch`` returns ``(out, ok)``, ``out`` (n, ...) NaN where not solved, ``ok`` (n,) (or (n, K) for ``ik_all``:
    then a single item counts as solved when any of its K is). The wrapper only checks its options and binds them
    in ``args`` (module-level callables: no closure is built on the fast path).

    Args:
        x: the input, array-like with trailing shape ``core``.
        name: its name in error messages (``"q"``, ``"target"``).
        core: the shape of one item, e.g. ``(3,)``.
        fast: ``fast(item, args) -> out | (out, ok) | None``: one float64 item straight to the kernel.
        batch: ``batch(rows, *args) -> (out, ok)``: the compiled loop.
        error: ``error(item, out, ok, *args) -> Exception``: why the single item ``item`` failed.
        args: the checked options.
        return_mask: also return the mask (True / False, already checked).
        chunks: run a large batch by chunks (False: in one call, for a function whose temporaries are already well
            below its answer, where copying the chunks' answers would only cost time).

    Returns:
        ``out`` (shape ``batch shape + item shape``), or ``(out, mask)`` with ``return_mask``.

    Raises:
        InvalidInputError: ``x`` is not a finite real array of trailing shape ``core``.
        LegkinError: ``error``'s, for a single input that is not solved.
    """
    if type(x) is np.ndarray and x.dtype is F64 and x.shape == core:
        res = fast(x, args)
        if res is not None:
            if type(res) is tuple:
                return res if return_mask else res[0]
            return (res, _TRUE) if return_mask else res
    arr = as_input(x, name, core)
    shape = arr.shape[: arr.ndim - len(core)]
    rows = np.ascontiguousarray(arr.reshape((-1,) + core))
    out, ok = _batch_rows(batch, rows, args) if chunks and rows.shape[0] > CHUNK else batch(rows, *args)
    if not shape:
        if not ok[0].any():
            raise error(arr, out[0], ok[0], *args)
        return (out[0], np.asarray(ok[0])) if return_mask else out[0]
    out, ok = out.reshape(shape + out.shape[1:]), ok.reshape(shape + ok.shape[1:])
    return (out, ok) if return_mask else out


def finish(
    value: Any,
    ok: Any,
    scalar: bool,
    return_mask: bool,
    error: Callable[[], Exception],
) -> Any:
    """Apply the scalar/batch rule to a computed result.

    Args:
        value: the result, an array or a tuple of arrays, already NaN where ``ok`` is False.
        ok: boolean mask of successes (shape = the batch shape; ``()`` for a scalar call).
        scalar: True for a single input: raise ``error()`` on failure.
        return_mask: also return the mask.
        error: builds the exception for a failed scalar call (called only then).

    Returns:
        ``value``, or ``(value, ok)`` (``(*value, ok)`` for a tuple) with ``return_mask``.
    """
    ok = np.asarray(ok, dtype=bool)
    if scalar and not bool(ok):
        raise error()
    if return_mask:
        if isinstance(value, tuple):
            return (*value, ok)
        return value, ok
    return value


def same_signature(template: F) -> Callable[[Callable[..., Any]], F]:
    """Decorator: the decorated function takes exactly the arguments of ``template`` and is typed as it is.

    For functions that share one signature whose return type depends on an argument (``return_mask``): the
    ``@overload`` stack is written once, on ``template``, and a type checker reads the decorated function's calls
    against it. The decorated function itself is returned unchanged (no call overhead); its parameters (names,
    kinds, defaults and annotations) are compared with ``template``'s when the module is imported.

    Args:
        template: the function whose parameters and (overloaded) type the decorated function shares.

    Returns:
        the decorator.

    Raises:
        TypeError: (at import) the decorated function's parameters differ from ``template``'s.
    """
    want = list(inspect.signature(template).parameters.values())

    def apply(fn: Callable[..., Any]) -> F:
        got = list(inspect.signature(fn).parameters.values())
        if got != want:
            raise TypeError(f"{fn.__qualname__} must take the arguments of {template.__qualname__}: {got} != {want}")
        return cast(F, fn)

    return apply


def real_number(value: object, name: str, valid: str | Callable[[], str]) -> float:
    """A real scalar parameter (int, float, numpy real, 0-d real array; not bool, str, complex) as float.

    Args:
        value: the value.
        name: its name in the message.
        valid: the range text for the message (or a callable making it, called only on failure). The range
            itself is the caller's to check.

    Returns:
        the value as a float.

    Raises:
        InvalidArgumentError: not a real number.
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
        return float(value)  # type: ignore[arg-type]  # a real number (checked above)
    except OverflowError:  # an int beyond the float range
        text = valid() if callable(valid) else valid
        raise InvalidArgumentError(f"{name}={value!r} is out of range: valid range {text}") from None


def interval_text(low: float | None, high: float | None, low_open: bool = False, high_open: bool = False) -> str:
    """The interval as text, e.g. ``(0, inf)`` or ``[1, 10000]``.

    Args:
        low, high: the bounds (None: unbounded, an open end).
        low_open, high_open: exclude the bound itself.

    Returns:
        the text.
    """
    lo = "-inf" if low is None else f"{low:g}"
    hi = "inf" if high is None else f"{high:g}"
    return f"{'(' if low_open or low is None else '['}{lo}, {hi}{')' if high_open or high is None else ']'}"


def outside(x: float, low: float | None, high: float | None, low_open: bool = False, high_open: bool = False) -> bool:
    """Whether ``x`` is NaN, infinite or outside the interval (the one range test of every option checker).

    Args:
        x: the value.
        low, high: the bounds (None: unbounded).
        low_open, high_open: exclude the bound itself.

    Returns:
        True if ``x`` is not a finite number inside the interval.
    """
    bad = not math.isfinite(x)
    if low is not None:
        bad |= x <= low if low_open else x < low
    if high is not None:
        bad |= x >= high if high_open else x > high
    return bad


def check_number(
    value: object, name: str, low: float | None = None, high: float | None = None, *,
    low_open: bool = False, high_open: bool = False,
) -> float:
    """A keyword parameter that must be one finite real number in a range; returns it as a float.

    Args:
        value: the value (int, float, numpy real or 0-d real array; not a bool).
        name: its name in the message.
        low, high: the bounds (None: unbounded), in the option's unit.
        low_open, high_open: exclude the bound itself.

    Returns:
        the value as a float.

    Raises:
        InvalidArgumentError: (a ``ValueError``) not a real number, NaN/inf, or outside the range; the
            message names the value and the range.
    """
    rng = interval_text(low, high, low_open, high_open)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        if not (isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"):
            raise InvalidArgumentError(f"{name} must be a real number in {rng}, got {value!r}")
    try:
        v = float(value)
    except OverflowError:  # an int beyond the float range
        raise InvalidArgumentError(f"{name}={value!r} is out of range: must be a finite number in {rng}") from None
    if outside(v, low, high, low_open, high_open):
        raise InvalidArgumentError(f"{name}={v!r} is out of range: must be a finite number in {rng}")
    return v


def check_integer(value: object, name: str, low: int | None = None, high: int | None = None) -> int:
    """A keyword parameter that must be an integer in ``[low, high]``.

    Args:
        value: the value (int or numpy integer; not a bool, not a float).
        name: its name in the message.
        low, high: the bounds (None: unbounded).

    Returns:
        the value as an int.

    Raises:
        InvalidArgumentError: not an integer, or outside the range.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        span = interval_text(low, high)
        raise InvalidArgumentError(f"{name} must be an integer in {span}, got {value!r}")
    v = int(value)
    if (low is not None and v < low) or (high is not None and v > high):
        span = interval_text(low, high)
        raise InvalidArgumentError(f"{name}={v} is out of range: must be an integer in {span}")
    return v


def check_flag(value: object, name: str) -> bool:
    """A keyword parameter that must be a bool.

    Args:
        value: the value (bool or numpy bool).
        name: its name in the message.

    Returns:
        the value as a bool.

    Raises:
        InvalidArgumentError: anything else.
    """
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidArgumentError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_choice(value: object, name: str, choices: Iterable[Any]) -> object:
    """A keyword parameter that must be one of ``choices`` (compared with ==, hashable values only).

    Args:
        value: the value.
        name: its name in the message.
        choices: the valid values.

    Returns:
        the value.

    Raises:
        InvalidArgumentError: any other value (the message lists the choices).
    """
    try:
        ok = value in tuple(choices)
    except Exception:  # noqa: BLE001 - an unhashable or array value is simply not a valid choice
        ok = False
    if isinstance(value, np.ndarray) or not ok:
        raise InvalidArgumentError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value
