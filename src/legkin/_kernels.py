"""Compiled kernels: the one implementation of every analytic function (numba).

The rule (issue 16), for every analytic module:

* Each kinematic quantity is written **once**, as a scalar kernel decorated with :func:`kernel`
  (``numba.njit(cache=True)``), beside the seed equations it implements. A kernel takes floats (and small
  preallocated output arrays), writes its result into the outputs and returns a status code
  (:data:`OK` or a module-specific failure code); it never raises.
* The batch is a compiled loop over that same kernel, decorated with :func:`batch_kernel`
  (``parallel=True``: ``numba.prange`` over the items). Its thread count is numba's own setting:
  ``numba.set_num_threads(k)`` or the ``NUMBA_NUM_THREADS`` environment variable. Below
  :data:`SERIAL_BELOW` items the loop runs on the calling thread (``range`` instead of ``prange`` in the
  same compiled function): starting the worker threads costs a few microseconds.
* The Python wrapper only checks the inputs (lean: a float64 array of the core shape goes straight to the
  kernel), calls the kernel (single input) or the batch loop (leading dimensions), and applies the
  single/batch rule of :mod:`legkin._batch` (a single call raises a legkin error on failure, a batch
  gives NaN plus the mask).
* Iterative solvers are per-target compiled loops with early exit.

Kernels are cached on disk by numba (``cache=True``): compiled on the first call after an install, loaded
from the cache afterwards. When the package directory is read-only (a system site-packages), numba writes
its cache to the user-wide cache directory instead; ``NUMBA_CACHE_DIR`` overrides both. (Tested by
``.ci/run``: legkin bind-mounted read-only, the second process loads every kernel from ``$HOME/.cache/numba``.)

A cached kernel is invalidated when *its own* source file changes (numba keys the cache on that file's
modification time), not when a kernel it calls in *another* module changes: after editing a kernel that
kernels of other files call, delete the ``*.nbi``/``*.nbc`` files under ``src/legkin/**/__pycache__`` (a fresh
install writes every file anew, so users never see a stale kernel).
"""

from __future__ import annotations

from typing import Any, Callable, TypeVar

import numba
import numpy as np

__all__ = ["kernel", "batch_kernel", "prange", "OK", "SERIAL_BELOW", "as_rows"]

F = TypeVar("F", bound=Callable[..., Any])

#: Status code of a kernel that succeeded (every failure code is a nonzero int of the module).
OK = 0

#: Batches with fewer items run serially (no thread start-up, ~3 us); frozen into the kernels at compile time
#: (numba's cache does not see a change here: delete the ``__pycache__`` entries of the modules after one).
SERIAL_BELOW = 256

prange = numba.prange


def kernel(fn: F) -> F:
    """Compile a scalar kernel: ``numba.njit(cache=True, error_model="numpy")`` (no ZeroDivisionError: IEEE
    semantics, NaN/inf propagate and the kernel's status reports them)."""
    return numba.njit(cache=True, error_model="numpy")(fn)  # type: ignore[return-value]


def batch_kernel(fn: F) -> F:
    """Compile a batch loop over a kernel: like :func:`kernel`, with ``parallel=True`` (use ``prange``)."""
    return numba.njit(cache=True, error_model="numpy", parallel=True)(fn)  # type: ignore[return-value]


def as_rows(x: np.ndarray, core: int) -> np.ndarray:
    """``x`` (..., core) as a C-contiguous float64 (n, core) array (a view when it already is one)."""
    return np.ascontiguousarray(x.reshape(-1, core), dtype=np.float64)
