"""The single-call table of ``legkin bench`` (issue 16): one row per public analytic function.

Each bench module ``legkin.<model>.bench`` defines ``single_calls() -> list[SingleCall]``: one entry per
public function of its analytic module, with its inputs bound, and the Pinocchio call it is compared with
(its yardstick). The table reports, from one run, each function's time per single call next to the
yardstick's time per call on the same model, and their ratio.

This module holds the table's machinery: :func:`time_call` (``timeit``-style), :func:`yardstick_calls` (the
Pinocchio calls, inputs bound) and :func:`single_call_table`; :mod:`legkin.bench` re-exports them and prints the
table (:func:`format_single_table`).
"""

from __future__ import annotations

import time
import timeit
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ._benchkit import record

__all__ = [
    "SingleCall",
    "YARDSTICKS",
    "SOLVE_LOOPS_PERTURBATION",
    "SingleCallResult",
    "time_call",
    "yardstick_calls",
    "single_call_table",
    "format_single_table",
]

#: Yardstick kinds: the Pinocchio call for the same quantity on the same model.
YARDSTICKS = {
    "fk": "forwardKinematics + updateFramePlacement (one frame)",
    "jacobian": "computeFrameJacobian (one frame, LOCAL_WORLD_ALIGNED)",
    "solve_loops": "Robot.solve_loops (closes every loop from the actuated joints)",
    "quadruped_fk": "forwardKinematics + updateFramePlacement on the 12-DOF quadruped",
}


@dataclass(frozen=True)
class SingleCall:
    """One public function, called once with bound inputs.

    Attributes:
        name: the function's public name, e.g. ``"foot_ik"``.
        call: makes one single call (inputs already bound, no argument).
        yardstick: key of :data:`YARDSTICKS`.
        iterative: the function iterates (tripod ``fk``, hybrid platform orientation, wheel-leg ``ik``):
            its target is >= 10x faster than the ``solve_loops``-based equivalent.
    """

    name: str
    call: Callable[[], object]
    yardstick: str
    iterative: bool = False


# ------------------------------------------------------------------------------------------- single calls
#: Perturbation (rad or m, normal) of the passive coordinates the ``solve_loops`` yardstick starts from.
SOLVE_LOOPS_PERTURBATION = 1e-2


@dataclass
class SingleCallResult:
    """One row of the single-call table: a public function's time per call next to its yardstick's."""

    name: str
    yardstick: str
    time_per_call_s: float
    yardstick_time_s: float
    number: int
    repeats: int
    iterative: bool = False
    error: str = ""

    @property
    def ratio(self) -> float:
        """Function time / yardstick time (< 1: faster than Pinocchio)."""
        return self.time_per_call_s / self.yardstick_time_s

    def as_dict(self) -> dict:
        """The JSON row (docs/bench.json), :func:`legkin._benchkit.record`."""
        return record(self, {"yardstick_time_s": "yardstick_time_per_call_s"}, {"ratio": self.ratio})


def time_call(call: Callable[[], object], repeats: int, min_time: float) -> tuple[float, int]:
    """CPU time of one call of ``call`` (no argument), ``timeit``-style: the best of ``repeats`` loops.

    ``call()`` runs once untimed first (numba compiles on it). The loop size ``number`` doubles until a loop
    lasts at least ``min_time`` seconds; then ``repeats`` loops of ``number`` calls are timed and the shortest
    loop time divided by ``number`` is returned, with ``number``. The clock is the calling thread's CPU time
    (``time.thread_time``: a single call runs in the calling thread), so that another process on a shared machine
    does not move the ratio of a function to its yardstick; the best loop, as ``timeit`` recommends, drops the
    loops that an interrupt or a cache eviction slowed. Nothing is subtracted: the time includes the Python call
    of ``call`` itself (a few tens of ns), the same for the function and its yardstick.

    Args:
        call: the call to time.
        repeats: timed loops.
        min_time: the least duration of one loop (s).

    Returns:
        ``(time, number)``: the time of one call (s of CPU) and the calls per loop.
    """
    call()
    timer = timeit.Timer(call, timer=time.thread_time)
    number = 1
    while True:
        t = timer.timeit(number)
        if t >= min_time or number >= 1 << 24:
            break
        number *= 2 if t <= 0 else max(2, min(10, int(1.2 * min_time / t)))
    times = timer.repeat(repeats, number)
    return float(np.min(times)) / number, number


def _closed_configuration(robot) -> np.ndarray:
    """``q0`` with every loop closed, the actuated joints held (``q0`` if it does not close)."""
    from .errors import LegkinError

    try:
        return robot.solve_loops(fixed=list(robot.actuated_joints))
    except LegkinError:
        return robot.q0.copy()


def _frame_name(name: str, robot) -> str:
    """The frame of the yardstick calls: the registry entry's :attr:`ModelSpec.yardstick_frame`, else the model's
    last frame."""
    frame = robot.spec.yardstick_frame
    if callable(frame):
        return frame(robot)
    return frame or robot.model.frames[len(robot.model.frames) - 1].name


def yardstick_calls(name: str, keys, seed: int = 0) -> dict[str, tuple[Callable[[], object], str]]:
    """The yardstick calls of model ``name`` for ``keys`` (keys of ``YARDSTICKS``): ``{key: (call, label)}``.

    fk: ``forwardKinematics`` + ``updateFramePlacement`` of the model's representative frame at its closed
    ``q0``; jacobian: ``computeFrameJacobian`` of that frame (LOCAL_WORLD_ALIGNED); solve_loops:
    ``Robot.solve_loops`` from the closed ``q0`` with its passive coordinates perturbed, the actuated joints
    held; quadruped_fk: fk on ``legkin.load("quadruped")`` (LF_FOOT). Inputs are bound outside the calls.
    """
    import pinocchio as pin

    from .robot import load

    out: dict[str, tuple[Callable[[], object], str]] = {}
    robots: dict[str, Any] = {}

    def robot_of(model_name: str):
        if model_name not in robots:
            robots[model_name] = load(model_name)
        return robots[model_name]

    def fk_call(model_name: str):
        robot = robot_of(model_name)
        frame = _frame_name(model_name, robot)
        model, data, fid = robot.model, robot.model.createData(), robot.frame_id(frame)
        q = _closed_configuration(robot)
        fk, upd = pin.forwardKinematics, pin.updateFramePlacement

        def call():
            fk(model, data, q)
            return upd(model, data, fid)

        return call, f"{model_name}: forwardKinematics + updateFramePlacement({frame})"

    for key in dict.fromkeys(keys):
        if key not in YARDSTICKS:
            raise KeyError(f"unknown yardstick {key!r} (known: {', '.join(YARDSTICKS)})")
        if key == "fk":
            out[key] = fk_call(name)
        elif key == "quadruped_fk":
            out[key] = fk_call("quadruped")
        elif key == "jacobian":
            robot = robot_of(name)
            frame = _frame_name(name, robot)
            model, data, fid = robot.model, robot.model.createData(), robot.frame_id(frame)
            q = _closed_configuration(robot)
            jac, lwa = pin.computeFrameJacobian, pin.LOCAL_WORLD_ALIGNED

            def call(model=model, data=data, q=q, fid=fid, jac=jac, lwa=lwa):
                return jac(model, data, q, fid, lwa)

            out[key] = (call, f"{name}: computeFrameJacobian({frame}, LOCAL_WORLD_ALIGNED)")
        elif key == "solve_loops":
            robot = robot_of(name)
            act = list(robot.actuated_joints)
            q = _closed_configuration(robot)
            held = {robot.idx_q(j) for j in act}
            free = np.array([i for i in range(robot.model.nq) if i not in held], dtype=int)
            q_start = q.copy()
            q_start[free] += np.random.default_rng(seed).normal(0.0, SOLVE_LOOPS_PERTURBATION, len(free))
            solve = robot.solve_loops

            def call(solve=solve, q_start=q_start, act=act):  # type: ignore[misc]  # one name per branch
                return solve(q_start, fixed=act)

            label = (f"{name}: solve_loops(q0 closed + N(0, {SOLVE_LOOPS_PERTURBATION:g}) on the "
                     f"{len(free)} passive coordinates, {len(act)} actuated joints held)")
            out[key] = (call, label)
    return out


def single_call_table(name: str, module, quick: bool = False, seed: int = 0, *,
                      timer: Callable | None = None, yardsticks: Callable | None = None) -> dict:
    """The single-call table of one model: ``{"rows": [SingleCallResult], "yardsticks": {key: {...}}}``.

    ``{"rows": [], "skipped": reason}`` when the bench module has no ``single_calls``. An entry whose call
    raises gets a row with ``error`` set and NaN times (the rest of the table is still measured). ``timer`` and
    ``yardsticks`` replace :func:`time_call` and :func:`yardstick_calls` (:func:`legkin.bench.single_call_table`
    passes its module's names, so that patching ``legkin.bench.time_call`` reaches the table).
    """
    timer = time_call if timer is None else timer
    yardsticks = yardstick_calls if yardsticks is None else yardsticks
    make = getattr(module, "single_calls", None)
    if make is None:
        return {"rows": [], "yardsticks": {}, "skipped": "no single-call entries yet"}
    entries = list(make())
    repeats, min_time = (3, 0.01) if quick else (7, 0.1)
    stick_times: dict[str, dict[str, Any]] = {}
    stick_errors: dict[str, str] = {}
    for key in dict.fromkeys(e.yardstick for e in entries):
        try:
            ((call, label),) = yardsticks(name, [key], seed=seed).values()
            t, number = timer(call, repeats, min_time)
        except Exception as exc:  # noqa: BLE001 - an unknown or failing yardstick fails its rows only
            stick_errors[key] = f"yardstick {key!r}: {type(exc).__name__}: {exc}"
            continue
        stick_times[key] = {"label": label, "time_per_call_s": t, "number": number, "repeats": repeats}
    rows = []
    for e in entries:
        if e.yardstick in stick_errors:
            rows.append(SingleCallResult(e.name, e.yardstick, float("nan"), float("nan"), 0, repeats,
                                         bool(e.iterative), error=stick_errors[e.yardstick]))
            continue
        ref = stick_times[e.yardstick]["time_per_call_s"]
        try:
            t, number = timer(e.call, repeats, min_time)
            rows.append(SingleCallResult(e.name, e.yardstick, t, ref, number, repeats, bool(e.iterative)))
        except Exception as exc:  # noqa: BLE001 - reported in the table, the bench goes on
            rows.append(SingleCallResult(e.name, e.yardstick, float("nan"), ref, 0, repeats, bool(e.iterative),
                                         error=f"{type(exc).__name__}: {exc}"))
    return {"rows": rows, "yardsticks": stick_times}


def format_single_table(name: str, table: dict) -> str:
    """The printed single-call table of one model."""
    if table.get("skipped"):
        return f"{name} single calls: {table['skipped']}\n"
    rows = table["rows"]
    width = max([len(r.name) for r in rows] + [8])
    lines = [(f"{name} single calls (CPU time, best of {rows[0].repeats if rows else 0} timeit loops; "
              "ratio = function / yardstick, < 1 is faster than Pinocchio)")]
    lines.append(f"  {'function':<{width}}  {'time/call':>10}  {'yardstick':<12}  {'yardstick/call':>14}  {'ratio':>8}")
    for r in rows:
        if r.error:
            lines.append(f"  {r.name:<{width}}  failed: {r.error}")
            continue
        mark = ""
        if r.iterative:
            mark = "  (iterative: target ratio <= 0.1"
            if r.yardstick == "solve_loops":
                mark += ", met" if r.ratio <= 0.1 else ", NOT met"
            mark += ")"
        lines.append(f"  {r.name:<{width}}  {_fmt_time(r.time_per_call_s):>10}  {r.yardstick:<12}  "
                     f"{_fmt_time(r.yardstick_time_s):>14}  {r.ratio:>8.3g}{mark}")
    for key, y in table["yardsticks"].items():
        lines.append(f"  * {key}: {y['label']}")
    return "\n".join(lines) + "\n"


def _fmt_time(t: float) -> str:
    if t >= 1e-3:
        return f"{t * 1e3:.3g} ms"
    if t >= 1e-6:
        return f"{t * 1e6:.3g} us"
    return f"{t * 1e9:.3g} ns"
