"""``legkin bench``: analytic kinematics timed side by side with iterative solvers, on the same targets.

How a model is benchmarked: its module ``legkin.<model>.bench`` defines
``build(n, rng, quick) -> ModelBench``, a list of :class:`Method` records, each with its inputs (the
same random reachable targets for every method of a group), a ``run`` callable (the timed part) and a
``score`` callable (untimed: turns the output into per-target errors measured the same way for every
method, by Pinocchio). This module times each method (median of ``repeats`` runs over the same inputs,
in one process, wall time: a batch may run on several threads), scores it, and prints one table per model;
``--json`` writes the same numbers.

The single-call table (issue 16): a bench module may also define ``single_calls() -> list[SingleCall]``
(:mod:`legkin._single_call`), one entry per public analytic function with its inputs bound. Each is timed
``timeit``-style (loops of ``number`` calls, the best of the repeats, in CPU time of the calling thread: another
process on a shared machine does not move the ratio) next to its yardstick, the Pinocchio call
for the same quantity (:data:`legkin._single_call.YARDSTICKS`) timed the same way in the same run on the
same model. For the quadruped the bench also runs the peer IK libraries of :mod:`legkin.peers`.
"""

from __future__ import annotations

import functools
import importlib
import json
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ._benchkit import Method, MethodResult, ModelBench, Score
from ._registry import MODELS, get_spec, list_models
from ._single_call import SingleCallResult, _fmt_time, format_single_table, time_call, yardstick_calls
from ._single_call import single_call_table as _single_call_table

__all__ = [
    "Method",
    "Score",
    "ModelBench",
    "MethodResult",
    "run_model",
    "run_bench",
    "format_table",
    "machine_info",
    "to_json",
    "run_bench_cli",
    "SingleCallResult",
    "time_call",
    "yardstick_calls",
    "single_call_table",
    "format_single_table",
]


# ------------------------------------------------------------------------------------------- progress
class _Progress:
    """A progress bar (tqdm) on stderr: methods timed so far, the one running now; off when disabled.

    Enabled by default only when stderr is a terminal; ``legkin bench --quiet`` disables it.
    """

    def __init__(self, total: int, label: str, enabled: bool | None = None):
        from ._progress import progress_bar

        self.enabled = sys.stderr.isatty() if enabled is None else bool(enabled)
        self._ctx = progress_bar(max(total, 1), f"legkin bench {label}".rstrip(), enabled=self.enabled)
        self._bar = self._ctx.__enter__()

    def show(self, what: str) -> None:
        self._bar.set_postfix_str(what[:80])

    def step(self, what: str) -> None:
        self._bar.update(1)
        self.show(what)

    def close(self) -> None:
        self._ctx.__exit__(None, None, None)


# ------------------------------------------------------------------------------------------- running
def _median_or_none(x) -> float | None:
    if x is None:
        return None
    x = np.asarray(x, dtype=float)
    return float(np.nanmedian(x)) if x.size and np.any(np.isfinite(x)) else float("nan")


def _mean_or_none(x) -> float | None:
    if x is None:
        return None
    x = np.asarray(x, dtype=float)
    return float(np.nanmean(x)) if x.size and np.any(np.isfinite(x)) else float("nan")


def _stats(err: np.ndarray) -> tuple[float, float]:
    """Median and worst error; a target with no result (NaN) makes the worst error NaN-free but counted."""
    err = np.asarray(err, dtype=float)
    finite = err[np.isfinite(err)]
    if finite.size == 0:
        return float("nan"), float("nan")
    return float(np.median(finite)), float(np.max(finite))


def _time_method(m: Method, inputs, progress: _Progress) -> tuple[float, Any]:
    times, out = [], None
    for r in range(m.repeats):
        progress.show(f"{m.name} (run {r + 1}/{m.repeats})")
        t0 = time.perf_counter()
        assert m.run is not None  # a method without run is skipped before timing
        out = m.run(inputs)
        times.append(time.perf_counter() - t0)
    progress.step(m.name)
    return float(np.median(times)), out


def _peak_bytes(m: Method, inputs) -> float:
    """The peak memory (bytes) one more run of ``m`` allocates, answer included (``tracemalloc``: numpy's arrays
    are traced; numba's compiled loops allocate none of their own)."""
    import tracemalloc

    assert m.run is not None
    tracemalloc.start()
    try:
        m.run(inputs)
        return float(tracemalloc.get_traced_memory()[1])
    finally:
        tracemalloc.stop()


def _subset(inputs, k: int | None):
    if k is None:
        return inputs
    if isinstance(inputs, tuple):
        return tuple(x[:k] for x in inputs)
    return inputs[:k]


def _count(inputs) -> int:
    return len(inputs[0]) if isinstance(inputs, tuple) else len(inputs)


def run_model(
    bench: ModelBench, label: str = "", progress: _Progress | None = None, quiet: bool = False
) -> list[MethodResult]:
    """Time and score every method of a model; fills the ratio to the fastest method of each group.

    A progress bar shows on stderr when it is a terminal, unless ``quiet``.
    """
    runnable = [m for m in bench.methods if m.skip is None]
    own = progress is None
    progress = progress or _Progress(len(runnable), label, enabled=False if quiet else None)
    try:
        return _run_methods(bench, runnable, progress)
    finally:
        if own:
            progress.close()


def _run_methods(bench: ModelBench, runnable: list[Method], progress: _Progress) -> list[MethodResult]:
    results: list[MethodResult] = []
    for m in runnable:
        inputs = _subset(m.inputs, m.max_targets)
        k = _count(inputs)
        seconds, out = _time_method(m, inputs, progress)
        assert m.score is not None
        s = m.score(inputs, out)
        solved = np.asarray(s.solved, dtype=bool)
        med, worst = _stats(s.error)
        # a target without any result counts as a failure and its error as infinite in "worst"
        if not np.all(np.isfinite(np.asarray(s.error, dtype=float))):
            worst = float("inf")
        r = MethodResult(
            name=m.name,
            group=m.group,
            unit=bench.units.get(m.group, ""),
            targets=k,
            solved=100.0 * float(solved.sum()) / k,
            solved_count=int(solved.sum()),
            median_error=med,
            max_error=worst,
            time_per_target_s=seconds / k,
            repeats=m.repeats,
            iterations_median=_median_or_none(s.iterations),
            fk_evals_mean=_mean_or_none(s.fk_evals),
            note=m.note,
        )
        if s.reached is not None:
            r.reached = 100.0 * float(np.sum(s.reached)) / k
        if m.name.startswith("legkin") and "batch" in m.name:  # the memory of legkin's batch calls (issue 25)
            r.bytes_per_target = _peak_bytes(m, inputs) / k
        if s.orientation is not None:
            omed, oworst = _stats(s.orientation)
            if not np.all(np.isfinite(np.asarray(s.orientation, dtype=float))):
                oworst = float("inf")
            r.median_orientation_error, r.max_orientation_error = omed, oworst
        results.append(r)
    for g in {r.group for r in results}:
        fastest = min(r.time_per_target_s for r in results if r.group == g)
        for r in results:
            if r.group == g:
                r.ratio = r.time_per_target_s / fastest
    return results


def _load_bench_module(name: str):
    """The bench module of ``name``, or None if there is none (for a model of a shared package, e.g.
    :mod:`legkin.legs.bench`, its ``build(name, n, rng, quick)`` and ``single_calls(name)`` bound to the name)."""
    spec = MODELS.get(name)
    if spec is not None and spec.shared_package:
        import types

        module = importlib.import_module(f"{spec.package}.bench")
        if not hasattr(module, "build"):
            return None
        return types.SimpleNamespace(
            build=functools.partial(module.build, name), single_calls=functools.partial(module.single_calls, name)
        )
    modname = f"legkin.{name}.bench"
    try:
        return importlib.import_module(modname)
    except ModuleNotFoundError as exc:
        if exc.name in (modname, f"legkin.{name}"):
            return None
        raise


def run_bench(
    models: list[str] | None = None, n: int | None = None, seed: int = 0, quick: bool = False, quiet: bool = False
) -> dict:
    """Build and run the benches of ``models`` (default: all registered); ``quiet``: no progress bar.

    Returns:
        ``{"models": {name: (ModelBench, [MethodResult])}, "single": {name: single_call_table(...)},
        "skipped": {name: reason}}``.
    """
    names = models or list_models("legkin")
    for name in names:
        get_spec(name)  # unknown names raise UnknownModelError
    out: dict = {"models": {}, "single": {}, "skipped": {}}
    for name in names:
        module = _load_bench_module(name)
        if module is None:
            out["skipped"][name] = f"no bench module legkin.{name}.bench"
            continue
        rng = np.random.default_rng(seed)
        bench = module.build(n, rng, quick)
        if name == "quadruped":
            from . import peers

            peers.add_quadruped_peers(bench)
        out["models"][name] = (bench, run_model(bench, label=name, quiet=quiet))
        out["single"][name] = single_call_table(name, module, quick=quick, seed=seed)
    return out


# ------------------------------------------------------------------------------------------- single calls
def single_call_table(name: str, module, quick: bool = False, seed: int = 0) -> dict:
    """The single-call table of one model (:func:`legkin._single_call.single_call_table`), timed by this
    module's :func:`time_call` and :func:`yardstick_calls` (the names a test may patch)."""
    return _single_call_table(name, module, quick=quick, seed=seed, timer=time_call, yardsticks=yardstick_calls)


# ------------------------------------------------------------------------------------------- output
def _fmt_err(x: float | None) -> str:
    if x is None:
        return "-"
    if np.isnan(x):
        return "nan"
    if np.isinf(x):
        return "fail"
    return f"{x:.1e}"


def _summary(bench: ModelBench, results: list[MethodResult]) -> list[str]:
    return list(bench.summary(results)) if bench.summary is not None else []


def _optional(x: float | None, fmt: str) -> str:
    return "-" if x is None else format(x, fmt)


def _columns(bench: ModelBench, results: list[MethodResult]) -> list[tuple[str, int, Callable[[MethodResult], str]]]:
    """The columns after solved that some result fills: ``(header, width, cell)``."""
    sec = bench.secondary[:4]
    candidates = [
        (any(r.reached is not None for r in results), [
            ("reached", 7, lambda r: "-" if r.reached is None else f"{r.reached:.1f}%")]),
        (True, [("err med", 8, lambda r: _fmt_err(r.median_error)), ("err max", 8, lambda r: _fmt_err(r.max_error))]),
        (any(r.median_orientation_error is not None for r in results), [
            (sec + " med", 8, lambda r: _fmt_err(r.median_orientation_error)),
            (sec + " max", 8, lambda r: _fmt_err(r.max_orientation_error))]),
        (any(r.iterations_median is not None for r in results), [
            ("iters", 5, lambda r: _optional(r.iterations_median, "g"))]),
        (any(r.fk_evals_mean is not None for r in results), [
            ("FK/solve", 8, lambda r: _optional(r.fk_evals_mean, ".3g"))]),
        (any(r.bytes_per_target is not None for r in results), [
            ("B/target", 8, lambda r: _optional(r.bytes_per_target, ".0f"))]),
        (True, [("time/target", 11, lambda r: _fmt_time(r.time_per_target_s))]),
    ]
    return [col for present, cols in candidates if present for col in cols]


def format_table(name: str, bench: ModelBench, results: list[MethodResult]) -> str:
    """One model's table: method, targets, solved, errors, time per target, ratio to the fastest."""
    lines = [f"{name}" + (f"  (solved: {bench.tolerance})" if bench.tolerance else "")]
    has_ori = any(r.median_orientation_error is not None for r in results)
    width = max([len(r.name) for r in results] + [len(m.name) for m in bench.methods] + [6])
    columns = _columns(bench, results)
    head = f"  {'method':<{width}}  {'targets':>7}  {'solved':>7}"
    head += "".join(f"  {title:>{w}}" for title, w, _ in columns) + f"  {'ratio':>8}"
    groups = list(dict.fromkeys(m.group for m in bench.methods))
    for g in groups:
        rows = [r for r in results if r.group == g]
        unit = bench.units.get(g, "")
        lines.append(f"  [{g}] err in {unit}" + (f", {bench.secondary}" if has_ori else ""))
        lines.append(head)
        for r in rows:
            line = f"  {r.name:<{width}}  {r.targets:>7d}  {r.solved:>6.1f}%"
            line += "".join(f"  {cell(r):>{w}}" for _, w, cell in columns) + f"  {r.ratio:>7.1f}x"
            lines.append(line)
        for m in bench.methods:
            if m.group == g and m.skip is not None:
                lines.append(f"  {m.name:<{width}}  skipped: {m.skip}")
    for text in _summary(bench, results):
        lines.append(f"  = {text}")
    notes = [f"{r.name}: {r.note}" for r in results if r.note] + list(bench.notes)
    for text in notes:
        lines.append(f"  * {text}")
    return "\n".join(lines) + "\n"


def _version(dist: str) -> str | None:
    try:
        from importlib.metadata import version

        return version(dist)
    except Exception:
        return None


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_info() -> dict:
    """CPU, core count, OS, and the versions of Python and of every library the bench touches."""
    return {
        "cpu": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pin": _version("pin"),
        "legkin": _version("legkin"),
        "ikpy": _version("ikpy"),
        "pytracik": _version("pytracik"),
        "scipy": _version("scipy"),
        "numba": _version("numba"),
        "numba_threads": _numba_threads(),
        "roboticstoolbox-python": _version("roboticstoolbox-python"),
        "mink": _version("mink"),
        "mujoco": _version("mujoco"),
        "pin-pink": _version("pin-pink"),
        "pytorch-kinematics": _version("pytorch-kinematics"),
        "torch": _version("torch"),
        "load_average_1min": _loadavg(),
    }


def _numba_threads() -> int | None:
    """numba's thread count for parallel batch kernels (``NUMBA_NUM_THREADS`` / ``numba.set_num_threads``)."""
    try:
        import numba

        return int(numba.get_num_threads())
    except Exception:
        return None


def _loadavg() -> float | None:
    """1-minute load average: other processes on the machine make every timing slower."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def to_json(run: dict, settings: dict | None = None, machine: dict | None = None) -> dict:
    """The ``--json`` document: ``{"machine", "settings", "models": {name: {"methods": [...]}}, "skipped"}``."""
    models = {}
    for name, (bench, results) in run["models"].items():
        models[name] = {
            "methods": [r.as_dict() for r in results],
            "skipped_methods": {m.name: m.skip for m in bench.methods if m.skip is not None},
            "tolerance": bench.tolerance,
            "units": bench.units,
            "secondary_error": bench.secondary,
            "notes": list(bench.notes),
            "summary": _summary(bench, results),
        }
    for name, table in run.get("single", {}).items():
        if name in models:
            models[name]["single_calls"] = {
                "rows": [r.as_dict() for r in table["rows"]],
                "yardsticks": table["yardsticks"],
            }
            if table.get("skipped"):
                models[name]["single_calls"]["skipped"] = table["skipped"]
    return {
        "machine": machine or machine_info(),
        "settings": settings or {},
        "models": models,
        "skipped": run["skipped"],
    }


def _finite(obj):
    """Replace NaN and infinities by None (strict JSON): null means "no finite value" (a failed target)."""
    if isinstance(obj, float):
        return obj if np.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    return obj


def run_bench_cli(args) -> int:
    """Entry point of ``legkin bench`` (arguments: models, n, json, quick, seed)."""
    if args.n is not None and args.n < 1:
        print(f"legkin: error: --n must be a positive integer, got {args.n}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    info = machine_info()  # before the run: the load average then is the other processes'
    run = run_bench(
        args.models or None, n=args.n, seed=args.seed, quick=args.quick, quiet=getattr(args, "quiet", False)
    )
    print(
        f"legkin bench on {info['cpu']} ({info['cpu_count']} cores), Python {info['python']}, "
        f"numpy {info['numpy']}, pin {info['pin']}, numba {info['numba']} ({info['numba_threads']} threads), "
        f"load average {info['load_average_1min']:.2f}"
        + ("  [--quick]" if args.quick else "")
    )
    print("time/target = median over repeats of (wall time of the whole call) / targets\n")
    for name, (bench, results) in run["models"].items():
        print(format_table(name, bench, results))
    print("single calls: time/call = median over repeats of (loop wall time) / calls per loop; each yardstick "
          "timed the same way in this run")
    for name, table in run["single"].items():
        print(format_single_table(name, table))
    for name, reason in run["skipped"].items():
        print(f"{name}: skipped ({reason})")
    print(f"total {time.perf_counter() - t0:.1f} s")
    if args.json:
        doc = to_json(run, {"n": args.n, "seed": args.seed, "quick": bool(args.quick)}, machine=info)
        Path(args.json).write_text(json.dumps(_finite(doc), indent=2, allow_nan=False) + "\n")
        print(f"wrote {args.json}")
    return 0
