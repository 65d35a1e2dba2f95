"""Compiled kernels: the one implementation of every analytic function (numba).

The rule (issue 16), for every analytic module:

* Each kinematic quantity is written **once**, as a scalar kernel decorated with :func:`kernel`
  (``numba.njit(cache=True)``), beside the seed equations it implements. A kernel takes floats (and small
  preallocated output arrays), writes its result into the outputs and returns a status code
  (:data:`OK` or a module-specific failure code); it never raises.
* The batch is a compiled loop over that same kernel, decorated with :func:`batch_kernel`: a plain
  ``for i in range(n)`` loop compiled once, without the GIL (``nogil=True``); for a kernel of one input row and
  one output row per item, :func:`batch_loop` writes that loop. From ``min_parallel`` items on,
  the call splits the item rows into contiguous chunks and runs one chunk per thread, the thread count being
  numba's own setting (``numba.set_num_threads(k)`` or the ``NUMBA_NUM_THREADS`` environment variable); below it
  the loop runs on the calling thread. (Not numba's ``prange``, except for the cheapest closed forms: numba's
  parallel compiler took a third of the first-run compile time of legkin's kernels; see :class:`BatchLoop`.)
* Who calls a kernel is declared, for the first-run compile: ``@kernel`` (only kernels: no CPython wrapper,
  :class:`InternalKernel`), ``@kernel(entry=True)`` (also the Python wrapper of a single call),
  ``@kernel(inline=True)`` (typed inside each caller: thin wrappers and one-caller helpers). numba compiles
  every kernel with the whole tree of kernels it calls, so each level of a call chain costs its whole tree again.
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

import functools
import inspect
import os
import threading
import types as pytypes
import weakref
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, TypeVar, overload

import numba
import numpy as np
from numba.core import config, types
from numba.core.compiler_lock import global_compiler_lock
from numba.core.registry import CPUDispatcher

from . import _cache

__all__ = ["kernel", "batch_kernel", "batch_loop", "BatchLoop", "OK", "as_items", "as_rows", "prange", "threads"]

F = TypeVar("F", bound=Callable[..., Any])

#: Status code of a kernel that succeeded (every failure code is a nonzero int of the module).
OK = 0


class KernelDispatcher(CPUDispatcher):
    """numba's CPU dispatcher, except that a call from another kernel is compiled for the *non-literal* types of
    its arguments: numba would compile one version of a kernel per constant it is called with
    (``rot_k(0, a)``, ``rot_k(1, a)``, ``f(..., True)``), each with its whole call tree, and one more for the calls
    from Python. A kernel's code never depends on a literal argument, so one version serves them all."""

    _cache_enabled = True  # numba's on-disk cache (cache=True), also for an InternalKernel's twin
    _cache_ready = False  # the cache is set up by the first compile (or cache load), not at import

    def get_call_template(self, args, kws):  # noqa: D102 - numba API
        args = tuple(types.unliteral(a) for a in args)
        kws = {k: types.unliteral(v) for k, v in kws.items()}
        return super().get_call_template(args, kws)

    def compile(self, sig):  # noqa: D102 - numba API
        # Every compile and cache load of a dispatcher goes through this method; numba's (re-entrant) compiler
        # lock makes the cache's set-up happen once before any thread's compile.
        with global_compiler_lock:
            self.ensure_cache()
            return super().compile(sig)

    def ensure_cache(self) -> None:
        """Set up numba's on-disk cache of this kernel (once; a no-op with ``cache=False``). numba's
        ``enable_caching`` finds the cache directory on the file system (a test file written and deleted per
        kernel): done for the ~250 kernels at import it took 30-50 ms of a warm start; done on the first
        compile, only for the kernels a process uses."""
        if self._cache_enabled and not self._cache_ready:
            self._cache_ready = True
            self.enable_caching()

    def enable_caching(self) -> None:
        """numba's on-disk cache, checked and degrading (:mod:`legkin._cache`): a damaged file is discarded and
        rebuilt, and with no writable directory the kernel loads from a readable cache or compiles in memory."""
        self._cache = _cache.function_cache(self.py_func)


class InternalKernel(KernelDispatcher):
    """A kernel that only other kernels call (:func:`kernel`'s default): compiled without numba's CPython wrapper.

    numba compiles each kernel with its whole call tree (every kernel it calls is linked in, optimized and turned
    into machine code again), and with a wrapper that unboxes Python arguments; for a kernel that only compiled
    code calls, the wrapper is never used. A call from Python still works: it compiles, once, a Python-callable
    twin of the kernel (its own cache entry, see :func:`_renamed`), listed in :data:`python_twins`. The library
    calls kernels from Python only through ``kernel(entry=True)`` kernels and batch loops."""

    _twin: KernelDispatcher | None = None

    def __call__(self, *args: Any, **kws: Any) -> Any:
        twin = self._twin
        if twin is None:
            options = {k: v for k, v in self.targetoptions.items() if k not in ("no_cpython_wrapper", "inline")}
            twin = self._twin = _njit(_renamed(self.py_func, "_py"), cache=self._cache_enabled, **options)
            python_twins.append(f"{self.py_func.__module__}.{self.py_func.__qualname__}")
        return twin(*args, **kws)


#: Internal kernels called from Python in this process (each compiled a Python-callable twin; see
#: :class:`InternalKernel`). The checks and the public functions call none.
python_twins: list[str] = []


def _njit(fn: Callable[..., Any], *, cache: bool = True, entry: bool = True, **options: Any) -> Any:
    """``numba.njit(cache=cache, error_model="numpy", **options)(fn)`` on a :class:`KernelDispatcher`
    (``entry=False``: an :class:`InternalKernel`, without the CPython wrapper)."""
    if config.DISABLE_JIT:  # type: ignore[attr-defined]
        return _uncompiled(fn)
    # no_cfunc_wrapper: the C-callable wrapper serves numba's first-class functions, which legkin does not use
    targetoptions = {"nopython": True, "boundscheck": None, "error_model": "numpy", "no_cfunc_wrapper": True}
    if not entry:
        targetoptions["no_cpython_wrapper"] = True
    cls = KernelDispatcher if entry else InternalKernel
    disp = cls(py_func=fn, locals={}, targetoptions={**targetoptions, **options})
    disp._cache_enabled = cache  # numba's cache, set up on the first compile (KernelDispatcher.compile)
    if cache and not options.get("parallel"):  # a parfor twin compiles only on a large batch: not counted
        _cached_kernels.append(weakref.ref(disp))
    return disp


def _uncompiled(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` run as Python (``NUMBA_DISABLE_JIT=1``) with numba's ``error_model="numpy"`` semantics: numpy's
    floating-point warnings off, so that NaN and inf propagate to the kernel's status code and the wrapper raises
    the same legkin error as the compiled kernel (not a ``RuntimeWarning``, an exception under ``-W error``)."""
    @functools.wraps(fn)
    def run(*args: Any, **kws: Any) -> Any:
        with np.errstate(all="ignore"):
            return fn(*args, **kws)
    return run


#: The cached kernels created in this process (weak references), for :func:`cache_status`.
_cached_kernels: list[weakref.ref] = []


def cache_status() -> tuple[int, int]:
    """``(in numba's on-disk cache, all)``: the count of this process's legkin kernels (those of the modules
    imported so far, less the ``parfor`` twins) that a first call would load from numba's cache rather than
    compile. ``legkin check`` tells a first run after an install by it."""
    cached = total = 0
    for ref in _cached_kernels:
        disp = ref()
        if disp is None:
            continue
        disp.ensure_cache()
        index = getattr(getattr(disp._cache, "_cache_file", None), "_index_path", None)
        total += 1
        cached += index is not None and os.path.exists(index)
    return cached, total


@overload
def kernel(fn: F, /) -> F: ...
@overload
def kernel(*, entry: bool = False, inline: bool = False) -> Callable[[F], F]: ...
def kernel(fn: F | None = None, /, *, entry: bool = False, inline: bool = False) -> F | Callable[[F], F]:
    """Compile a scalar kernel: ``numba.njit(cache=True, error_model="numpy")`` (no ZeroDivisionError: IEEE
    semantics, NaN/inf propagate and the kernel's status reports them), typed on non-literal arguments
    (:class:`KernelDispatcher`).

    ``@kernel``: a kernel that other kernels call (an :class:`InternalKernel`, without numba's CPython wrapper).
    ``@kernel(entry=True)``: also called from Python (a single call of a public function).
    ``@kernel(inline=True)``: inlined into each kernel that calls it (numba's ``inline="always"``), for a thin
    wrapper or a helper with a single caller: numba then types it inside its caller instead of compiling it, with
    its whole call tree, on its own (see CONTRIBUTING.md, "first-run compile")."""
    def wrap(f: F) -> F:
        options: dict[str, Any] = {"inline": "always"} if inline else {}
        return _njit(f, entry=entry, **options)  # type: ignore[no-any-return]
    return wrap if fn is None else wrap(fn)


_pool: ThreadPoolExecutor | None = None
_pool_size = 0
_pool_lock = threading.Lock()


def threads() -> int:
    """The thread count of a large batch: numba's setting (``numba.set_num_threads``, ``NUMBA_NUM_THREADS``)."""
    return int(numba.get_num_threads())


prange = numba.prange


def _executor(workers: int) -> ThreadPoolExecutor:
    global _pool, _pool_size
    with _pool_lock:
        if _pool is None or _pool_size < workers:
            if _pool is not None:
                _pool.shutdown(wait=False)
            _pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="legkin")
            _pool_size = workers
        return _pool


#: numba's threading layers that run ``parfor`` loops from several Python threads at once (numba's documentation,
#: "Selecting a threading layer"): ``workqueue`` aborts the process ("Concurrent access has been detected").
_THREADSAFE_LAYERS = ("tbb", "omp")
#: The layers that survive a fork: GNU OpenMP kills a forked child at its first parallel region ("fork() called
#: from a process already using GNU OpenMP"); numba's ``workqueue`` threads do not exist in the child.
_FORKSAFE_LAYERS = ("tbb",)
#: Serializes the ``parfor`` batches of a threading layer that is not thread-safe (:data:`_THREADSAFE_LAYERS`).
_parfor_lock = threading.Lock()
#: True in a process forked after numba's threads were started on a layer that does not survive a fork
#: (:data:`_FORKSAFE_LAYERS`): its ``parfor`` batches run their serial compilation.
_forked_serial = False


def threading_layer() -> str | None:
    """numba's threading layer of this process (``"tbb"``, ``"omp"``, ``"workqueue"``), or None before the first
    ``parfor`` batch starts it. numba picks the first available of TBB, OpenMP, workqueue, unless
    ``NUMBA_THREADING_LAYER`` (or ``numba.config.THREADING_LAYER``, set before the first parallel batch) names
    one; see docs/robustness.md, "Threads, processes and fork"."""
    try:
        return str(numba.threading_layer())
    except ValueError:  # numba: "Threading layer is not initialized."
        return None


def _after_fork_in_child() -> None:
    """``os.register_at_fork`` hook: the child of a fork has none of the parent's threads. Its chunk pool starts
    afresh (the parent's pool threads, and any lock they held, do not exist), and its ``parfor`` batches run
    serially when the parent's numba threading layer does not survive a fork."""
    global _pool, _pool_size, _pool_lock, _parfor_lock, _forked_serial
    _pool, _pool_size = None, 0
    _pool_lock, _parfor_lock = threading.Lock(), threading.Lock()
    layer = threading_layer()
    _forked_serial = _forked_serial or (layer is not None and layer not in _FORKSAFE_LAYERS)


os.register_at_fork(after_in_child=_after_fork_in_child)


#: True: a ``parfor`` batch loop runs its serial compilation and never compiles its parallel twin (numba's parallel
#: compiler, 0.4-0.9 s a loop on the first run). Set in ``legkin check``'s worker processes, which run on one
#: thread and need the rows, not the speed (the rows are the same bit for bit).
serial_parfor_loops = False


class BatchLoop:
    """A compiled batch loop (:func:`batch_kernel`), called like its Python function. The arguments named in
    ``rows`` hold one row per item (inputs and outputs alike); the first of them gives the item count n.

    Below ``min_parallel`` items the loop runs on the calling thread. From there on, either (default) the rows
    are split into contiguous chunks, one per thread, each run by the same compiled loop without the GIL (a row
    argument with a single row, shared by all items, is passed whole; an int return value, a count, is summed
    over the chunks); or, with ``parfor=True``, the loop's ``prange`` runs on numba's parallel backend, from a
    second compilation of the same source made on the first large batch (also on one thread: numba's parallel
    loop is faster there too), unless :data:`serial_parfor_loops` is set. ``parfor`` suits the cheapest loops
    (~0.1 us an item: numba's parallel loop saves ~30 ns an item of array-view bookkeeping); the chunks need no
    second compilation (numba's parallel compiler is slow) and suit everything else."""

    def __init__(self, fn: Callable[..., Any], rows: str, min_parallel: int, parfor: bool = False):
        names = list(inspect.signature(fn).parameters)
        unknown = [r for r in rows.split() if r not in names]
        if unknown or not rows.split():
            raise TypeError(f"batch_kernel(rows={rows!r}): {fn.__name__} has no argument {unknown[0]!r}"
                            if unknown else "batch_kernel needs the names of the row arguments")
        self.kernel = _njit(fn, nogil=True)
        self.rows = tuple(names.index(r) for r in rows.split())
        self.min_parallel = int(min_parallel)
        self.parfor = _njit(_renamed(fn, "_parfor"), parallel=True) if parfor else None
        self.__name__, self.__qualname__, self.__doc__ = fn.__name__, fn.__qualname__, fn.__doc__
        self.__module__, self.__wrapped__ = fn.__module__, fn

    def __call__(self, *args: Any) -> Any:
        n = args[self.rows[0]].shape[0]
        if n < self.min_parallel:
            return self.kernel(*args)
        if self.parfor is not None and not (serial_parfor_loops or _forked_serial):
            return self._run_parfor(args)
        k = min(threads(), n)
        if k <= 1:
            return self.kernel(*args)
        edges = [n * j // k for j in range(k + 1)]
        chunks = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            part = list(args)
            for r in self.rows:
                if args[r].shape[0] == n:  # a single row shared by all items (broadcast) is passed whole
                    part[r] = args[r][lo:hi]
            chunks.append(part)
        pool = _executor(k - 1)
        futures = [pool.submit(self.kernel, *part) for part in chunks[1:]]
        first = self.kernel(*chunks[0])
        rest = [f.result() for f in futures]
        return first if first is None else first + sum(rest)

    def _run_parfor(self, args: tuple[Any, ...]) -> Any:
        """The ``parfor`` twin on numba's threading layer, one batch at a time where the layer is not thread-safe
        (or not yet started: numba picks it on the first parallel batch)."""
        parfor: Callable[..., Any] = self.parfor  # type: ignore[assignment] # set: BatchLoop.__call__ checked it
        if threading_layer() in _THREADSAFE_LAYERS:
            return parfor(*args)
        with _parfor_lock:
            return parfor(*args)


def _renamed(fn: Callable[..., Any], suffix: str) -> Callable[..., Any]:
    """A copy of ``fn`` whose qualified name ends in ``suffix``: numba keys its cache files on the qualified name and
    the signature, not on the compile options, so the parallel compilation of a loop needs a name of its own
    (otherwise each process loads whichever of the two was cached first)."""
    twin = pytypes.FunctionType(fn.__code__, fn.__globals__, fn.__name__, fn.__defaults__, fn.__closure__)
    twin.__qualname__, twin.__doc__, twin.__module__ = fn.__qualname__ + suffix, fn.__doc__, fn.__module__
    return twin


def batch_kernel(rows: str, min_parallel: int, parfor: bool = False) -> Callable[[Callable[..., Any]], BatchLoop]:
    """Compile a batch loop over a kernel (like :func:`kernel`, plus ``nogil=True``); see :class:`BatchLoop`.
    ``rows``: the names of the arguments with one row per item. ``min_parallel``: the item count from which the
    loop runs on several threads (choose it so that one thread's share takes at least ~0.2 ms, well above the
    cost of handing work to a thread). ``parfor``: the loop is written with ``prange`` (``range`` below
    ``min_parallel``) and runs on numba's parallel backend."""
    return lambda fn: BatchLoop(fn, rows, min_parallel, parfor)


# The source of every batch_loop (the kernel is the global _kernel of each copy). Its cache files are those of the
# kernel's module: after editing this loop, delete the *.nbi/*.nbc files (as after editing a kernel other files call).
def _row_loop(x, shared, out):
    n, bad = x.shape[0], 0
    for i in prange(n):
        bad += _kernel(x[i], shared, out[i]) != OK  # noqa: F821
    return bad


def batch_loop(kernel_: Any, min_parallel: int, parfor: bool = False) -> BatchLoop:
    """The batch loop of a kernel ``name_k(x, shared, out) -> status`` that reads one row ``x`` and writes one row
    ``out`` per item: ``for i in prange(n): bad += name_k(x[i], shared, out[i]) != OK``, returning the number of
    failed items; a :class:`BatchLoop` (see :func:`batch_kernel` for ``min_parallel`` and ``parfor``).

    The loop, named ``name_batch``, is one source (``_row_loop``) given the kernel as its global, and filed under
    the kernel's module: numba keys its cache files on the loop's name and on that module's source file, so the
    loop is compiled again when the kernel's file changes, as a loop written there would be.

    Args:
        kernel_: the kernel (a :func:`kernel`), named ``..._k``.
        min_parallel: the item count from which the loop runs on several threads.
        parfor: run the loop on numba's parallel backend.

    Returns:
        the batch loop ``(x, shared, out) -> int``.
    """
    py = getattr(kernel_, "py_func", None) or kernel_.__wrapped__  # (NUMBA_DISABLE_JIT: the Python kernel)
    if not py.__name__.endswith("_k"):
        raise TypeError(f"batch_loop: the kernel's name must end in _k, got {py.__name__}")
    name = py.__name__[:-2] + "_batch"
    code = _row_loop.__code__.replace(co_filename=py.__code__.co_filename, co_name=name)
    fn = pytypes.FunctionType(code, {"_kernel": kernel_, "prange": prange, "OK": OK}, name)
    fn.__qualname__, fn.__module__ = name, py.__module__
    fn.__doc__ = f"{py.__name__} over the rows of x and out; returns the number of failed items."
    return BatchLoop(fn, "x out", min_parallel, parfor)


def as_rows(x: np.ndarray, core: int) -> np.ndarray:
    """``x`` (..., core) as a C-contiguous, writeable float64 (n, core) array (a view when it already is one).

    Writeable always (a read-only view, e.g. of ``np.broadcast_to``, is copied): numba types read-only arrays
    apart, and a kernel called with both would be compiled twice, with its whole call tree."""
    rows = np.ascontiguousarray(x.reshape(-1, core), dtype=np.float64)
    return rows if rows.flags.writeable else rows.copy()


def as_items(x: Any, n: int, dtype: Any = np.float64) -> np.ndarray:
    """``x`` broadcast to (n,) as a C-contiguous, writeable array of ``dtype`` (see :func:`as_rows`)."""
    items = np.ascontiguousarray(np.broadcast_to(x, (n,)), dtype=dtype)
    return items if items.flags.writeable else items.copy()
