"""``legkin check``: analytic kinematics against Pinocchio, one row per comparison."""

from __future__ import annotations

import contextlib
import functools
import importlib
import json
import sys
import time
import types
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ._registry import get_spec, list_models

__all__ = [
    "CheckResult",
    "compare",
    "run_checks",
    "format_table",
    "write_json",
    "IKRobustness",
    "classify_failures",
    "robustness_row",
]


@dataclass(frozen=True)
class CheckResult:
    """One row of ``legkin check``.

    Attributes:
        name: what was compared (e.g. ``"LF foot position"``).
        samples: how many samples were compared.
        max_error, p99_error: largest and 99th-percentile error over the samples.
        tolerance: the bound every sample must meet.
        passed: ``max_error <= tolerance`` and no sample was NaN.
    """

    name: str
    samples: int
    max_error: float
    p99_error: float
    tolerance: float
    passed: bool
    errors: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: the counts of an IK robustness row (:class:`IKRobustness`), else None.
    counts: object = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict:
        """The JSON row (per-sample errors left out)."""
        row = {k: getattr(self, k) for k in ("name", "samples", "max_error", "p99_error", "tolerance", "passed")}
        if self.counts is not None:
            row["counts"] = dict(vars(self.counts))
        return row


def compare(name: str, errors, tolerance: float) -> CheckResult:
    """Summarise per-sample errors (any shape; NaN counts as a failure) into a row."""
    e = np.abs(np.asarray(errors, dtype=float)).ravel()
    if e.size == 0:
        return CheckResult(name, 0, float("nan"), float("nan"), tolerance, False, e)
    finite = bool(np.all(np.isfinite(e)))
    emax = float(np.max(e)) if finite else float("nan")
    p99 = float(np.percentile(e, 99)) if finite else float("nan")
    return CheckResult(name, int(e.size), emax, p99, tolerance, finite and emax <= tolerance, e)


def per_sample(diff, axis=-1):
    """Euclidean norm of a difference along ``axis`` (per-sample error)."""
    return np.linalg.norm(np.asarray(diff, dtype=float), axis=axis)


@contextlib.contextmanager
def progress_bar(total: int, desc: str, enabled: bool = True):
    """A tqdm bar on stderr (steps done, elapsed time, what runs now in its postfix), redrawn every second.

    A step can take several seconds: a thread redraws the bar so that its clock keeps running. Disabled,
    the bar prints nothing and starts no thread.
    """
    import threading

    from tqdm import tqdm

    bar = tqdm(
        total=total, desc=desc, unit="step", file=sys.stderr, disable=not enabled, leave=False,
        dynamic_ncols=True, bar_format="{desc}: {n_fmt}/{total_fmt} |{bar:20}| {elapsed}{postfix}",
    )
    stop = threading.Event()

    def tick():
        while not stop.wait(1.0):
            bar.refresh()

    ticker = threading.Thread(target=tick, daemon=True) if enabled else None
    if ticker is not None:
        ticker.start()
    try:
        yield bar
    finally:
        stop.set()
        if ticker is not None:
            ticker.join()
        bar.close()


def _checks_module(spec) -> Any:
    """The module whose ``run(samples, rng)`` checks ``spec``: ``legkin.<name>.checks``, or for an external
    quadruped :mod:`legkin.legs.checks` bound to its name."""
    module = importlib.import_module(f"{spec.package}.checks")
    if spec.external:
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
    """The worker group of a model: ``"legs"`` for the external robots of :mod:`legkin.legs` (they share their
    kernels), a checks module's ``KERNEL_GROUP`` when it runs another group's kernels (the quadruped's checks run
    :mod:`legkin.legs` on POPI: in one process the legs kernels compile once), else the model's own name."""
    spec = get_spec(name)
    if spec.external:
        return "legs"
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
                bar: Any = None) -> dict[str, tuple[list[CheckResult], float]]:
    """The rows of each model, advancing ``bar`` per model and stage (None, in a worker process: no bar)."""
    if bar is None:
        with progress_bar(0, "", enabled=False) as bar:
            return _run_models(names, samples=samples, seed=seed, ik_targets=ik_targets, classify=classify, bar=bar)
    out = {}
    for name in names:
        module = _checks_module(get_spec(name))
        rng = np.random.default_rng(seed)
        t0 = time.perf_counter()
        bar.set_postfix_str(f"{name}: checks ({samples} samples)")
        rows = list(module.run(samples, rng))
        rows += _mujoco_rows(name, samples, seed)
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

    if get_spec(name).external or unavailable_reason() is not None:
        return []  # the export covers legkin's own models (their loops); the external robots have .dae meshes
    return list(check_rows(name, samples=min(samples, 20), rng=np.random.default_rng(seed + 2)))


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


def pinocchio_frames(robot, qs, frames: list[str], jacobians: bool = False):
    """Pinocchio's world placements (and LOCAL_WORLD_ALIGNED Jacobians) of ``frames`` for each row of ``qs``.

    Returns:
        ``(positions (N, F, 3), rotations (N, F, 3, 3))``, plus ``jacobians (N, F, 6, nv)`` if asked.
    """
    import pinocchio as pin

    model, data = robot.model, robot.data
    ids = [robot.frame_id(f) for f in frames]
    n = len(qs)
    pos = np.empty((n, len(ids), 3))
    rot = np.empty((n, len(ids), 3, 3))
    jac = np.empty((n, len(ids), 6, model.nv if jacobians else 0))
    for i, q in enumerate(qs):
        if jacobians:
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            placements = np.array([data.oMf[fid].homogeneous for fid in ids])
            for k, fid in enumerate(ids):
                jac[i, k] = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        else:  # only the frames asked, one Pinocchio call each (3-4x faster than copying them out of data.oMf)
            pin.forwardKinematics(model, data, q)
            placements = np.array([pin.updateFramePlacement(model, data, fid).homogeneous for fid in ids])
        pos[i] = placements[:, :3, 3]
        rot[i] = placements[:, :3, :3]
    return (pos, rot, jac) if jacobians else (pos, rot)


def sample_within_limits(robot, n: int, rng: np.random.Generator, joints: list[str] | None = None) -> np.ndarray:
    """``n`` configurations: ``q0`` with the given 1-DOF joints (default: all) drawn uniformly in their limits."""
    model = robot.model
    qs = np.tile(robot.q0, (n, 1))
    for name in joints or robot.joint_names:
        j = model.joints[robot.joint_id(name)]
        if j.nq != 1:
            continue
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        qs[:, j.idx_q] = rng.uniform(lo, hi, n)
    return qs


# ---------------------------------------------------------------- the IK contract row
#: Reasons a default IK may give for leaving a target unsolved, by the legkin error a single call raises.
REASONS = ("out of reach", "out of limits", "other mode")


@dataclass(frozen=True)
class IKRobustness:
    """Counts of one IK robustness run (see :func:`robustness_row`)."""

    targets: int
    made: int
    solved: int
    wrong: int
    missed: int
    reasons: dict
    exceptions: int
    max_error: float

    def summary(self) -> str:
        why = ", ".join(f"{k} {v}" for k, v in self.reasons.items() if v) or "none"
        return (
            f"{self.targets} targets ({self.made} made by FK from in-limit joints): {self.solved} solved, "
            f"{self.wrong} not reproduced, {self.missed} FK-made targets missed, unsolved by reason: {why}; "
            f"{self.exceptions} foreign exceptions"
        )


def classify_failures(call, indices) -> tuple[dict, int]:
    """Classify unsolved targets by the legkin error that a single call on each raises.

    ``call(i)`` runs the default IK on target ``i`` as a single call. Returns ``(reasons, exceptions)``:
    counts per reason (:data:`REASONS`; another legkin error counts under its class name, a single call that
    succeeds where the batch failed under ``"solved by a single call"``) and the number of non-legkin
    exceptions (each one a defect).
    """
    from .errors import AssemblyModeError, JointLimitError, LegkinError, UnreachableError

    reasons = {k: 0 for k in REASONS}
    exceptions = 0
    for i in indices:
        try:
            call(int(i))
        except AssemblyModeError:
            reasons["other mode"] += 1
        except JointLimitError:
            reasons["out of limits"] += 1
        except UnreachableError:
            reasons["out of reach"] += 1
        except LegkinError as exc:
            key = type(exc).__name__
            reasons[key] = reasons.get(key, 0) + 1
        except Exception:  # noqa: BLE001 - counting foreign exceptions is the point
            exceptions += 1
        else:
            reasons["solved by a single call"] = reasons.get("solved by a single call", 0) + 1
    return reasons, exceptions


def robustness_row(
    mechanism: str,
    *,
    made: np.ndarray,
    solved: np.ndarray,
    error: np.ndarray,
    reasons: dict,
    classified: int,
    exceptions: int,
    tolerance: float = 1e-9,
) -> CheckResult:
    """The IK contract row: "IK on N random targets in and around the workspace".

    Args:
        made: (N,) True for targets made by the default forward kinematics from in-limit joints (each must
            be solved).
        solved: (N,) the default batch IK's mask.
        error: (N,) ``|FK(IK(x)) - x|`` (default FK options) for the solved targets (ignored elsewhere).
        reasons: counts of the classified unsolved targets (:func:`classify_failures`).
        classified: how many unsolved targets were classified.
        exceptions: non-legkin exceptions seen (batch call included).

    Passes when every solved answer reproduces its target within ``tolerance``, every FK-made target is
    solved, no single call succeeds where the batch failed, and no foreign exception was raised.
    """
    made, solved = np.asarray(made, bool), np.asarray(solved, bool)
    err = np.abs(np.asarray(error, dtype=float))[solved]
    wrong = int(np.sum(~(err <= tolerance)))
    missed = int(np.sum(made & ~solved))
    counts = IKRobustness(
        targets=int(made.size), made=int(made.sum()), solved=int(solved.sum()), wrong=wrong, missed=missed,
        reasons=dict(reasons), exceptions=int(exceptions), max_error=float(err.max()) if err.size else 0.0,
    )
    unsolved = int(made.size - solved.sum())
    why = ", ".join(f"{k} {v}" for k, v in reasons.items() if v) or "none"
    name = (
        f"IK on {made.size} random targets in and around the workspace: {counts.solved} solved "
        f"({wrong} not reproduced), {unsolved} unsolved ({missed} of them FK-made; {classified} classified: "
        f"{why}), {exceptions} exceptions"
    )
    passed = (
        wrong == 0 and missed == 0 and exceptions == 0 and reasons.get("solved by a single call", 0) == 0
    )
    emax = counts.max_error
    p99 = float(np.percentile(err, 99)) if err.size else 0.0
    return CheckResult(name, int(made.size), emax, p99, tolerance, bool(passed), err, counts)
