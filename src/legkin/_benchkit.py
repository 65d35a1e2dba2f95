"""Bench modules, one per model: ``build(n, rng, quick) -> ModelBench``; the bench's types and shared helpers here."""

from __future__ import annotations

import contextlib
import importlib.util
import os
import sys
from dataclasses import dataclass, field, fields
from typing import Any, Callable, Iterable, Mapping

import numpy as np

from .errors import LegkinError

__all__ = [
    "Score",
    "Method",
    "ModelBench",
    "MethodResult",
    "missing", "quiet_stdout", "pinocchio_positions", "levenberg_marquardt", "rotation_error", "scalar_loop",
    "levenberg_marquardt_rows",
    "SOLVE_TOL"]

#: A target counts as solved when the method's result is within this distance (m or rad) of it.
SOLVE_TOL = 1e-9


#: Peers outside the ``bench`` extra, with why (pip would build them from source where no wheel exists).
NOT_IN_EXTRA = {"pytracik": "not in the bench extra: needs Boost, Eigen, orocos-KDL and NLopt where no wheel exists"}


def missing(dist: str, module: str | None = None) -> str | None:
    """None if ``module`` (default: ``dist``) imports, else the skip reason naming the install command."""
    if importlib.util.find_spec(module or dist) is None:
        if dist in NOT_IN_EXTRA:
            return f"{dist} is not installed (pip install {dist}; {NOT_IN_EXTRA[dist]})"
        return f"{dist} is not installed (pip install {dist}, or pip install -e '.[bench]')"
    return None


@contextlib.contextmanager
def quiet_stdout():
    """Silence C/C++ code printing to file descriptor 1 (e.g. KDL's URDF parser warnings)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def pinocchio_positions(model, data, frame_id: int, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World position (N, 3) and rotation (N, 3, 3) of one frame for each configuration row of ``qs``.

    Rows containing NaN give NaN.
    """
    import pinocchio as pin

    n = len(qs)
    pos = np.full((n, 3), np.nan)
    rot = np.full((n, 3, 3), np.nan)
    finite = np.all(np.isfinite(qs), axis=-1)
    for i in np.flatnonzero(finite):
        pin.framesForwardKinematics(model, data, qs[i])
        oMf = data.oMf[frame_id]
        pos[i] = oMf.translation
        rot[i] = oMf.rotation
    return pos, rot


def levenberg_marquardt(model, residual_and_jacobian, q: np.ndarray, free: np.ndarray, tol: float, max_iter: int):
    """:func:`legkin.loops.levenberg_marquardt` (the iteration of ``Robot.solve_loops``) on any residual.

    Returns:
        ``(q, iterations, residual evaluations, converged)``.
    """
    from .loops import levenberg_marquardt as lm

    return lm(model, residual_and_jacobian, q, free, tol, max_iter)[:4]


def levenberg_marquardt_rows(model, problems: Iterable[tuple[Callable, np.ndarray]], n: int, free: np.ndarray,
                             tol: float, max_iter: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`levenberg_marquardt` on each of ``n`` problems, a Pinocchio peer's Python loop over the targets.

    Args:
        model: the Pinocchio model.
        problems: ``n`` pairs ``(residual_and_jacobian, q_start)``, one a target.
        n: how many problems.
        free: (nv,) the velocity coordinates the solver moves.
        tol: the stopping tolerance on the residual (its units: m or rad).
        max_iter: the most iterations a problem.

    Returns:
        ``(qs (n, nq), iterations (n,), residual evaluations (n,))``; qs NaN rows where the solver did not converge.
    """
    qs = np.full((n, model.nq), np.nan)
    iters, evals = np.full(n, np.nan), np.full(n, np.nan)
    for i, (residual_and_jacobian, q_start) in enumerate(problems):
        q, it, ev, ok = levenberg_marquardt(model, residual_and_jacobian, q_start, free, tol, max_iter)
        iters[i], evals[i] = it, ev
        if ok:
            qs[i] = q
    return qs, iters, evals


def sizes(n: int | None, quick: bool, full: tuple[int, int, int], small: tuple[int, int, int]) -> tuple[int, int, int]:
    """(batch targets, scalar-loop targets, iterative-solver targets): ``full`` or, with ``quick``, ``small``;
    ``n`` overrides the batch size and caps the others."""
    batch, scalar, iterative = small if quick else full
    n = n or batch
    return n, min(n, scalar), min(n, iterative)


def scalar_loop(call: Callable[[np.ndarray], Any], rows: np.ndarray, width: int) -> np.ndarray:
    """``call`` on one row at a time (a Python loop of single calls), the way a user calls a function once.

    Args:
        call: the single call, ``row -> (width,)`` result (units those of the method).
        rows: (n, ...) the inputs.
        width: the length of one result.

    Returns:
        (n, width) the results, NaN rows where ``call`` raised a legkin error.
    """
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        try:
            out[i] = call(row)
        except LegkinError:
            pass
    return out


def rotation_error(r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """Geodesic angle (rad) between rotation matrices (..., 3, 3); NaN where either is NaN."""
    rel = np.einsum("...ji,...jk->...ik", r1, r2)
    tr = np.trace(rel, axis1=-2, axis2=-1)
    # atan2 form: accurate near 0 (acos of the trace loses half the digits)
    skew = np.stack(
        [rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0], rel[..., 1, 0] - rel[..., 0, 1]], -1
    )
    return np.arctan2(0.5 * np.linalg.norm(skew, axis=-1), 0.5 * (tr - 1.0))


@dataclass
class Score:
    """Per-target outcome of one method (arrays of length = number of targets; NaN marks a failure).

    Attributes:
        error: primary error per target (position in m, or orientation in rad; see ``ModelBench.units``).
        solved: boolean mask: the target was reached within the model's tolerance (and joint limits).
        orientation: secondary error per target (rad), when the task has one.
        iterations: iterations per target, for iterative methods.
        fk_evals: forward-kinematics evaluations per target, for iterative methods.
        reached: error within tolerance, whatever the joint limits (when ``solved`` also asks for limits).
    """

    error: np.ndarray
    solved: np.ndarray
    orientation: np.ndarray | None = None
    iterations: np.ndarray | None = None
    fk_evals: np.ndarray | None = None
    reached: np.ndarray | None = None


@dataclass
class Method:
    """One way of solving a model's task.

    Attributes:
        name: row label (the batch closed form's contains "batch", Pinocchio's contains "pinocchio").
        inputs: targets, first axis = targets (shared with the other methods of the group).
        run: ``run(inputs) -> output``; the timed part (everything a user would call).
        score: ``score(inputs, output) -> Score``; not timed.
        group: methods are compared (ratio to fastest) within their group.
        max_targets: solve only the first ``max_targets`` inputs (slow per-target methods).
        repeats: timed runs; the time reported is their median.
        skip: if set, the method is not run and this reason is printed instead.
        note: printed under the table.
    """

    name: str
    inputs: Any = None
    run: Callable[[Any], Any] | None = None
    score: Callable[[Any, Any], Score] | None = None
    group: str = "ik"
    max_targets: int | None = None
    repeats: int = 5
    skip: str | None = None
    note: str = ""


@dataclass
class ModelBench:
    """What a bench module returns for one model.

    Attributes:
        methods: the rows, in display order.
        units: unit of ``Score.error`` per group (e.g. ``{"ik": "m"}``).
        tolerance: the ``solved`` threshold, same for every method (stated in the table).
        notes: lines printed under the table (how the targets were made, what each peer was given).
        summary: ``summary(results) -> lines``: derived figures (speed-ups, IK/FK), printed and in the JSON.
        secondary: column label of ``Score.orientation`` (e.g. "rot" in rad, or "loop |r|").
    """

    methods: list[Method]
    units: dict[str, str] = field(default_factory=lambda: {"ik": "m"})
    tolerance: str = ""
    notes: list[str] = field(default_factory=list)
    summary: Callable[[list], list[str]] | None = None
    secondary: str = "rot"


@dataclass
class MethodResult:
    """A timed and scored method (one table row)."""

    name: str
    group: str
    unit: str
    targets: int
    solved: float  # percent
    solved_count: int
    median_error: float
    max_error: float
    time_per_target_s: float
    repeats: int
    ratio: float = float("nan")
    median_orientation_error: float | None = None
    max_orientation_error: float | None = None
    iterations_median: float | None = None
    fk_evals_mean: float | None = None
    reached: float | None = None  # percent
    bytes_per_target: float | None = None  # legkin's batch methods: peak memory a call allocates, per target
    note: str = ""

    def as_dict(self) -> dict:
        """The JSON row (docs/bench.json), :func:`record`."""
        return record(self, {"unit": "error_unit", "ratio": "ratio_to_fastest",
                             "median_orientation_error": "median_secondary_error",
                             "max_orientation_error": "max_secondary_error"})


def record(result: Any, renamed: Mapping[str, str], extra: Mapping[str, Any] | None = None) -> dict:
    """A result dataclass as a JSON record: its fields in order (named as ``renamed`` says), an optional field (one
    whose default is None or "") left out while it has that default, then ``extra``.

    Args:
        result: the dataclass instance.
        renamed: field name -> key in the record.
        extra: more keys (computed properties).

    Returns:
        the record, a new dict.
    """
    d = {}
    for f in fields(result):
        value = getattr(result, f.name)
        if not (f.default in (None, "") and value == f.default):
            d[renamed.get(f.name, f.name)] = value
    return {**d, **(extra or {})}
