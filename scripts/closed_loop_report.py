"""The closing note of issue 27: per robot of Gepetto's example-parallel-robots, loaded from its own files.

Prints one table: loops, motors, mobility (all joints free), idle mobility (motors held), iterations and CPU time
of the closing from neutral (solve_loops), load CPU time (kernels already loaded: the first load of a process
also pays numba's start-up, printed apart); then closed_fk on N reachable motor samples (motors held, loops
closed, solved fraction), on the raw +-0.1 rad box about q0 (solved fraction: a motor vector of the box may lie
outside the workspace), closed_jacobian vs central differences, and the speed of a warm-started closed_fk (its
Gauss-Newton iterations, its time) against one Pinocchio computeJointJacobians on the same model (CPU time of the
thread, best of 7 interleaved rounds each, ratio from one run).

    PYTHONPATH=src python scripts/closed_loop_report.py [--samples 1000] [--data tests/data/example-parallel-robots]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

import legkin
from legkin.closing import loop_errors
from legkin.errors import LoopClosureError
from legkin.loaders.checks import _spread, determined_frames, jacobian_fd_error, reachable_motors


def _closing(robot) -> tuple[str, str, str]:
    t0 = time.process_time()
    try:
        _, info = robot.solve_loops(return_info=True)
    except LoopClosureError as exc:
        return "FAILS", f"{time.process_time() - t0:.2f}", str(exc)
    return str(info.iterations), f"{(time.process_time() - t0) * 1e3:.1f} ms", info.strategy


def _fk_stats(robot, motors) -> tuple[int, float, float]:
    iq, _ = robot._motor_index()
    ok, held, closed = 0, 0.0, 0.0
    for m in motors:
        try:
            q = robot.closed_fk(m)
        except LoopClosureError:
            continue
        ok += 1
        held = max(held, float(np.max(np.abs(q[iq] - m))))
        closed = max(closed, max(e.worst for e in loop_errors(robot.model, robot.data, robot.loops, q)))
    return ok, held, closed


def _speed(robot, q, rounds: int = 7) -> tuple[float, float, int]:
    """Per-call CPU seconds of a warm closed_fk (``q_near`` a closed configuration, motors 1e-3 rad or m away) and
    of computeJointJacobians: the best of ``rounds`` interleaved rounds (the machine is shared; the minimum is the
    least disturbed); and the Gauss-Newton iterations of that closed_fk."""
    iq, _ = robot._motor_index()
    m = q[iq] + 1e-3
    robot.closed_fk(m, q)
    iterations = robot._tree_solve(q, robot._compiled()[3], motors=m)[2]
    data = robot.model.createData()
    n, fk, cjj = 200, np.inf, np.inf
    for _ in range(rounds):
        t0 = time.thread_time()
        for _ in range(n):
            robot.closed_fk(m, q)
        fk = min(fk, (time.thread_time() - t0) / n)
        t0 = time.thread_time()
        for _ in range(10 * n):
            pin.computeJointJacobians(robot.model, data, q)
        cjj = min(cjj, (time.thread_time() - t0) / (10 * n))
    return fk, cjj, iterations


def report(path: Path, samples: int) -> None:
    t0 = time.process_time()
    robot = legkin.load(path)
    load = time.process_time() - t0
    name = robot.name
    it, dt, how = _closing(robot)
    if it == "FAILS":
        print(f"{name:<19} {len(robot.loops):>5} {len(robot.actuated):>6}   -    -   FAILS {dt:>7} s {load:>6.2f} s"
              f"  (solve_loops raises LoopClosureError in {dt} s of CPU: {how})")
        return
    rng = np.random.default_rng(0)
    motors, qs = reachable_motors(robot, samples, rng)
    ok, held, closed = _fk_stats(robot, motors)
    iq, _ = robot._motor_index()
    box = robot.q0[iq] + rng.uniform(-1, 1, (samples, len(iq))) * _spread(robot)
    ok_box = _fk_stats(robot, box)[0]
    frame = determined_frames(robot, robot.q0)[-1]
    jac = max(jacobian_fd_error(robot, q, frame) for q in qs[:10])
    fk, cjj, fk_it = _speed(robot, qs[0])
    print(f"{name:<19} {len(robot.loops):>5} {len(robot.actuated):>6} {robot.mobility(robot.q0):>4} "
          f"{robot.idle_mobility():>4} {it:>5} {dt:>9} {load:>6.2f} s  {ok / samples:>7.1%} {held:.0e} {closed:.0e} "
          f"{ok_box / samples:>7.1%}  {jac:.0e}  {fk_it:>5} {fk * 1e6:>6.1f} us {cjj * 1e6:>5.2f} us "
          f"{fk / cjj:>5.1f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1000)
    parser.add_argument("--data", default=str(Path(__file__).parents[1] / "tests/data/example-parallel-robots"))
    args = parser.parse_args()
    paths = [d / "robot.urdf" for d in sorted(Path(args.data).iterdir()) if (d / "robot.urdf").exists()]
    t0 = time.process_time()
    legkin.load(paths[0])
    print(f"first load of the process ({paths[0].parent.name}, numba's start-up and legkin's kernels loaded from "
          f"its cache included): {time.process_time() - t0:.2f} s of CPU")
    print(f"{'robot':<19} loops motors  mob idle iters   closing   load    fk solved motors loops    box    "
          f"jac-fd  fk-it closed_fk    cJJ    ratio")
    for path in paths:
        report(path, args.samples)


if __name__ == "__main__":
    main()
