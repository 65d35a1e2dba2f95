"""``legkin check``: analytic kinematics against Pinocchio, one row per comparison."""

from __future__ import annotations

import functools
import importlib
import json
import sys
import time
import types
from pathlib import Path
from typing import Any

import numpy as np

from ._checkkit import CheckResult
from ._progress import progress_bar
from ._registry import get_spec, list_models

__all__ = [
    "run_checks",
    "format_table",
    "write_json",
    "all_passed",
    "mujoco_note",
]


def _checks_module(spec) -> Any:
    """The module whose ``run(samples, rng)`` checks ``spec``: ``<package>.checks``, its ``run`` bound to the
    model's name when the package serves several models (:attr:`ModelSpec.shared_package`)."""
    module = importlib.import_module(f"{spec.package}.checks")
    if spec.shared_package:
        return types.SimpleNamespace(run=functools.partial(module.run, spec.name))
    return module


def run_checks(
    models: list[str] | None = None,
    samples: int = 10_000,
    seed: int = 0,
    *,
    ik_targets: int | None = None,
    classify: int | None = 2000,
    progress: bool = False,
    jobs: int = 1,
):
    """Run every check of each model; returns ``{model: (rows, seconds)}``.

    A model's checks module may define ``ik_robustness(n, rng, *, classify) -> CheckResult`` (the IK contract
    row on ``n`` random targets in and around the workspace, see :func:`robustness_row`); it runs on
    ``ik_targets`` targets (default ``samples``), classifying at most ``classify`` unsolved ones (None: all)
    by single calls. ``progress=True`` shows a progress bar (tqdm) on stderr, one step per model and stage.
    ``jobs`` > 1 runs the models in that many worker processes (the mechanisms whose kernels they share, such as
    the external quadrupeds of :mod:`legkin.legs`, in one process); the rows are the same as with ``jobs=1``
    (each model draws from its own ``default_rng(seed)``).
    """
    names = list(models or list_models())
    specs = [get_spec(name) for name in names]  # every unknown name raises before any work
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        from .errors import InvalidArgumentError

        raise InvalidArgumentError(f"jobs={jobs!r} must be an integer >= 1")
    modules = [_checks_module(spec) for spec in specs]
    steps = {name: 2 if hasattr(m, "ik_robustness") else 1 for name, m in zip(names, modules)}
    options: dict[str, Any] = dict(samples=samples, seed=seed, ik_targets=ik_targets, classify=classify)
    groups = _groups(names)
    out: dict[str, tuple[list[CheckResult], float]] = {}
    with progress_bar(sum(steps.values()), "legkin check", enabled=progress) as bar:
        if jobs == 1 or len(groups) == 1:
            out = _run_models(names, bar=bar, **options)
        else:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor, as_completed

            bar.set_postfix_str(f"{len(names)} models in {min(jobs, len(groups))} processes")
            context = multiprocessing.get_context("spawn")  # no fork of a process with threads (numba, tqdm)
            pool = ProcessPoolExecutor(max_workers=min(jobs, len(groups)), mp_context=context,
                                       initializer=_one_thread)
            try:
                futures = {pool.submit(_run_models, group, **options): group for group in groups}
                for future in as_completed(futures):
                    out.update(future.result())
                    bar.update(sum(steps[name] for name in futures[future]))
            except BaseException:  # Ctrl-C, SIGTERM (legkin.__main__), a failed worker: stop the others now
                _kill_workers(pool)
                raise
            finally:
                pool.shutdown(wait=True, cancel_futures=True)
    return {name: out[name] for name in names}


def _kill_workers(pool: Any) -> None:
    """Kill the worker processes of ``pool`` (a ``ProcessPoolExecutor``) and reap them: ``shutdown`` alone waits
    for the running checks (minutes)."""
    workers = list((getattr(pool, "_processes", None) or {}).values())
    for proc in workers:
        proc.kill()
    for proc in workers:
        proc.join(timeout=5)


def _one_thread() -> None:
    """A worker process runs its batches on one thread: the worker processes are the parallelism (numba's threads
    in each would oversubscribe the CPUs; the rows do not depend on the thread count), and its ``parfor`` loops on
    their serial compilation (no parallel twin to compile: ~4 s of CPU on a first run). It leaves Ctrl-C to the
    parent (which kills the workers at once) and dies with the parent (Linux's parent-death signal), so that no
    worker outlives a killed ``legkin check``."""
    import signal

    import numba

    from . import _kernels

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent()
    numba.set_num_threads(1)
    _kernels.serial_parfor_loops = True


def _die_with_parent() -> None:
    """Linux: this process gets SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``); elsewhere nothing."""
    import ctypes
    import ctypes.util
    import signal

    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1 = PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


#: The order in which the worker processes take the groups: dearest first by the first-run time of their checks
#: (compiling the kernels dominates; measured in 2-worker runs on 2 cores, calm and slow spells of a shared machine:
#: wheel_leg 48-69 s, hybrid_leg 27-45 s, tripod 17-32 s; the nine external robots and the quadruped, one group
#: as they share the legs kernels, 29-32 s on a slower machine where wheel_leg took 60-68 s).
#: Order only; the rows do not depend on it.
_COST = {"wheel_leg": 4, "hybrid_leg": 3, "tripod": 2, "legs": 1}


def _group_key(name: str) -> str:
    """The worker group of a model: its package's name when the package serves several models (the robots of
    :mod:`legkin.legs` share their kernels), a checks module's ``KERNEL_GROUP`` when it runs another group's
    kernels (the quadruped's checks run :mod:`legkin.legs` on POPI: in one process the legs kernels compile once),
    else the model's own name."""
    spec = get_spec(name)
    if spec.shared_package:
        return spec.package.rsplit(".", 1)[-1]
    return str(getattr(_checks_module(spec), "KERNEL_GROUP", name))


def _groups(names: list[str]) -> list[list[str]]:
    """The models in groups run by one worker process each, dearest first: one group per mechanism package,
    models whose checks share kernels together (:func:`_group_key`)."""
    groups: dict[str, list[str]] = {}
    for name in names:
        groups.setdefault(_group_key(name), []).append(name)
    order = sorted(groups, key=lambda key: -_COST.get(key, 1))
    return [groups[key] for key in order]


def _run_models(names: list[str], *, samples: int, seed: int, ik_targets: int | None, classify: int | None,
                bar: Any = None, mujoco: bool = True) -> dict[str, tuple[list[CheckResult], float]]:
    """The rows of each model, advancing ``bar`` per model and stage (None, in a worker process: no bar);
    ``mujoco=False`` leaves out the MuJoCo export's rows (:func:`_mujoco_rows`: they do not depend on
    ``samples``, so ``scripts/check_sweep.py`` runs them once per seed)."""
    if bar is None:
        with progress_bar(0, "", enabled=False) as bar:
            return _run_models(names, samples=samples, seed=seed, ik_targets=ik_targets, classify=classify, bar=bar,
                               mujoco=mujoco)
    out = {}
    for name in names:
        module = _checks_module(get_spec(name))
        rng = np.random.default_rng(seed)
        t0 = time.perf_counter()
        bar.set_postfix_str(f"{name}: checks ({samples} samples)")
        rows = list(module.run(samples, rng))
        rows += _mujoco_rows(name, samples, seed) if mujoco else []
        bar.update(1)
        if hasattr(module, "ik_robustness"):
            n = samples if ik_targets is None else ik_targets
            bar.set_postfix_str(f"{name}: IK robustness ({n} targets)")
            rows.append(module.ik_robustness(n, np.random.default_rng(seed + 1), classify=classify))
            bar.update(1)
        out[name] = (rows, time.perf_counter() - t0)
    return out


def _mujoco_rows(name: str, samples: int, seed: int) -> list[CheckResult]:
    """The MuJoCo export's rows (:func:`legkin.mjcf.check_rows`) when mujoco is installed, else none (the CLI
    says so: :func:`mujoco_note`). At most 20 samples: each is a loop solve, the simulation rows need no more."""
    from .mjcf import check_rows, unavailable_reason
    from .mjcf.scenarios import ground_rows

    if unavailable_reason() is not None:
        return []
    rows = []
    if get_spec(name).mjcf:  # the export covers legkin's own models (their loops); the robots of legs have .dae meshes
        rows = list(check_rows(name, samples=min(samples, 20), rng=np.random.default_rng(seed + 2)))
    rows += ground_rows(name)  # the ground scenarios (issue 28) of the models with a ground model
    return rows


def mujoco_note() -> str | None:
    """Why ``legkin check`` has no MuJoCo rows (mujoco not installed), or None when it has them."""
    from .mjcf import unavailable_reason

    reason = unavailable_reason()
    return None if reason is None else f"MuJoCo export rows skipped: {reason}"


def format_table(results) -> str:
    lines = []
    for name, (rows, seconds) in results.items():
        lines.append(f"{name}  ({seconds:.1f} s)")
        width = max([len(r.name) for r in rows] + [5])
        head = f"{'samples':>8}  {'max error':>10}  {'p99 error':>10}  {'tolerance':>9}  result"
        lines.append(f"  {'check':<{width}}  {head}")
        for r in rows:
            lines.append(
                f"  {r.name:<{width}}  {r.samples:>8d}  {r.max_error:>10.2e}  {r.p99_error:>10.2e}  "
                f"{r.tolerance:>9.0e}  {'pass' if r.passed else 'FAIL'}"
            )
        lines.append("")
    return "\n".join(lines)


def all_passed(results) -> bool:
    return all(r.passed for rows, _ in results.values() for r in rows)


def write_json(results, path: str | Path) -> None:
    doc = {
        "passed": all_passed(results),
        "models": {
            name: {"seconds": seconds, "checks": [r.as_dict() for r in rows]}
            for name, (rows, seconds) in results.items()
        },
    }
    Path(path).write_text(json.dumps(doc, indent=2, allow_nan=True) + "\n")
