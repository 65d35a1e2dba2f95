"""Throughput of legkin.study: raw batch kernels, in-process, dask LocalCluster with 1 and 2 workers, the chunk
size and dask's per-chunk overhead (docs/study.md, "Throughput").

    PYTHONPATH=src python scripts/bench_study.py [--model quadruped] [--n 3000000] [--cluster-n 100000000]

Prints the conditions (CPUs, load, numba threads in-process and in each worker), one table and the ratios, all
from this one run. Every run is timed by wall clock and by CPU time: the CPU seconds of this process (all its
threads) for the in-process runs, the sum of the worker processes' CPU seconds (all their threads) for the
clusters. On a shared machine the wall-clock ratios measure the cores the other processes left free; the
CPU-time ones measure the work. ~2.5 minutes for the quadruped on 2 idle cores.
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any, Callable

import numba
import numpy as np

from legkin.study import BLOCK_SIZE, CHUNK_BLOCKS, DEFAULT_METRICS, get_target, local_cluster, study
from legkin.study.run import plan, run_chunk


def _raw(model: str, params: dict, n: int, cond: bool = False) -> None:
    """The raw batches alone (sampling, IK, Jacobian) over n samples in blocks of BLOCK_SIZE; ``cond``: also numpy's
    condition number of each reached Jacobian (what a hand-written loop measuring dexterity would add)."""
    target = get_target(model)
    resolved = plan(model, {k: [v] for k, v in params.items()}, 1).resolved[0]
    rng = np.random.default_rng(0)
    for lo in range(0, n, BLOCK_SIZE):
        solved = target.solve(target.sample(rng, min(BLOCK_SIZE, n - lo), resolved), resolved, ())
        if cond:
            np.linalg.cond(solved.jac[solved.ok].reshape(-1, *solved.shape))


def _raw_1_thread(model: str, params: dict, n: int) -> None:
    """:func:`_raw` on one numba thread (what one worker process runs)."""
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        _raw(model, params, n)
    finally:
        numba.set_num_threads(before)


def _timed(fn: Callable[..., Any], *args: Any, **kw: Any) -> tuple[float, float]:
    """(wall seconds, CPU seconds of this process, all its threads) of one call."""
    t0, c0 = time.perf_counter(), time.process_time()
    fn(*args, **kw)
    return time.perf_counter() - t0, time.process_time() - c0


def _noop(x: int) -> int:
    return x


def _task_overhead(client: Any, k: int = 400) -> float:
    """Seconds a trivial task costs end to end (submit, schedule, run, gather), k of them on the cluster."""
    client.gather([client.submit(_noop, i, pure=False) for i in range(20)])
    t0 = time.perf_counter()
    client.gather([client.submit(_noop, i, pure=False) for i in range(k)])
    return (time.perf_counter() - t0) / k


def _autogroup() -> str:
    """Linux's autogroup scheduling: the processes of one session (this script, its scheduler, its workers) share
    one fair share of the CPUs against the other sessions, so on a busy machine k workers get the cores of one."""
    try:
        with open("/proc/sys/kernel/sched_autogroup_enabled") as f:
            on = f.read().strip() == "1"
    except OSError:
        return ""
    return ("; autogroup scheduling on: this session's processes share one CPU share with other sessions busy"
            if on else "")


def _worker_conditions() -> str:
    """What a worker process ran on: numba's thread count (a study task runs on 1), the thread env vars, its OS
    threads, legkin's batch-pool threads (started only by a batch split over numba threads) and dask's profiler."""
    import threading

    import dask
    import psutil

    env = ",".join(f"{v}={os.environ.get(v, '-')}" for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"))
    pool = sum(t.name.startswith("legkin") for t in threading.enumerate())
    return (f"numba threads {numba.get_num_threads()} (a study task: 1), {env}, {psutil.Process().num_threads()} OS "
            f"threads, {pool} legkin pool threads, dask profiler "
            f"{'on' if dask.config.get('distributed.worker.profile.enabled') else 'off'}")


def _cluster_run(k: int, model: str, grid: dict, n: int, with_overhead: bool) -> dict[str, Any]:
    """The study of n samples over ``grid`` on a fresh :func:`local_cluster` of k workers: wall seconds, the
    workers' CPU seconds (each process, all its threads), this process's CPU seconds (client, scheduler, nannies),
    the seconds the workers held a task (dask's task stream) and, with ``with_overhead``, dask's cost a task."""
    from distributed import get_task_stream

    with local_cluster(k) as client:
        resolved = plan(model, {p: v[:1] for p, v in grid.items()}, 1).resolved[0]
        client.run(run_chunk, model, resolved, 0, (BLOCK_SIZE,), 0, 0, DEFAULT_METRICS, 0.01, 1)  # loads kernels
        cpu0, main0, t0 = client.run(time.process_time), time.process_time(), time.perf_counter()
        with get_task_stream(client) as stream:
            study(model, grid, samples=n // len(next(iter(grid.values()))), client=client)
        wall, main = time.perf_counter() - t0, time.process_time() - main0
        cpu1 = client.run(time.process_time)
        conditions = client.run(_worker_conditions)
        busy = sum(s["stop"] - s["start"] for t in stream.data for s in t["startstops"] if s["action"] == "compute")
        per_task = _task_overhead(client) if with_overhead else float("nan")
    workers = [cpu1[w] - cpu0[w] for w in cpu0]
    return {"wall": wall, "cpu": sum(workers), "workers": workers, "main": main, "busy": busy / (k * wall),
            "per_task": per_task, "conditions": sorted(set(conditions.values()))}


def _in_process(a: argparse.Namespace) -> list[tuple[str, int, float, float]]:
    """The raw batches (numba's threads, then one), raw + np.linalg.cond and the study in-process: interleaved,
    best of ``a.repeat`` by wall and by CPU time each (the machine is shared)."""
    params = {a.param: a.value}
    study(a.model, {a.param: [a.value]}, samples=BLOCK_SIZE)  # compile / load the kernels
    runs: dict[str, Callable[[], Any]] = {
        f"raw batch kernels, {numba.get_num_threads()} numba threads": lambda: _raw(a.model, params, a.n),
        "raw batch kernels, 1 numba thread": lambda: _raw_1_thread(a.model, params, a.n),
        f"study, in-process ({numba.get_num_threads()} numba threads)":
            lambda: study(a.model, {a.param: [a.value]}, samples=a.n),
    }
    best = {name: (float("inf"), float("inf")) for name in runs}
    for _ in range(a.repeat):
        for name, fn in runs.items():
            wall, cpu = _timed(fn)
            best[name] = (min(best[name][0], wall), min(best[name][1], cpu))
    rows = [(name, a.n, wall, cpu) for name, (wall, cpu) in best.items()]
    rows.insert(2, ("raw + np.linalg.cond of the reached (once)", a.n, *_timed(_raw, a.model, params, a.n, True)))
    return rows


def _print_table(rows: list[tuple[str, int, float, float]]) -> None:
    print(f"\n{'run':<48} {'samples':>9} {'wall s':>8} {'eval/s':>9} {'CPU s':>8} {'CPU-ns/eval':>11} {'cores':>6}")
    for name, n, wall, cpu in rows:
        print(f"{name:<48} {n:>9.3g} {wall:>8.2f} {n / wall:>9.3g} {cpu:>8.2f} {1e9 * cpu / n:>11.0f} "
              f"{cpu / wall:>6.2f}")
    print("(CPU s: this process's, all threads, for the in-process runs; the worker processes' sum for the "
          "clusters; cores = CPU s / wall s)")


def _print_scaling(one: dict[str, Any], two: dict[str, Any], n: int, tasks: int) -> None:
    by_wall = one["wall"] / two["wall"]
    per_cpu = (n / two["cpu"]) / (n / one["cpu"])
    by_cpu = one["cpu"] / max(two["workers"])
    shares = ", ".join(f"{c / two['wall']:.2f}" for c in two["workers"])
    print(f"\n2 workers / 1 worker, by wall time: {by_wall:.2f}x (target >= 1.7x); the workers got "
          f"{shares} of a core each (1 worker: "
          f"{one['cpu'] / one['wall']:.2f}), and held a task {100 * two['busy']:.1f} % of the wall time (1 worker: "
          f"{100 * one['busy']:.1f} %)")
    print(f"2 workers / 1 worker, by CPU time: {by_cpu:.2f}x = the 1 worker's CPU seconds over the busier of the 2 "
          f"workers' ({one['cpu']:.1f} s vs {max(two['workers']):.1f} s): the wall-time ratio when each worker "
          f"has a core to itself; evaluations per worker CPU-second {n / one['cpu']:.3g} (1 worker) vs "
          f"{n / two['cpu']:.3g} (2 workers), ratio {per_cpu:.3f}")
    print(f"client + scheduler + nannies (this process): {one['main']:.2f} CPU s (1 worker), {two['main']:.2f} CPU s "
          f"(2 workers); {tasks} tasks, {tasks // 2} a worker")


def _print_chunk(one: dict[str, Any], n: int, tasks: int) -> None:
    chunk = CHUNK_BLOCKS * BLOCK_SIZE
    chunk_s = chunk * one["cpu"] / n
    print(f"chunk size: {CHUNK_BLOCKS} blocks x {BLOCK_SIZE} samples = {chunk} samples a task, {chunk_s:.3f} s of "
          f"one worker's CPU; dask's cost a task {1e3 * one['per_task']:.2f} ms (400 trivial tasks on 1 worker, "
          f"wall): per-chunk overhead {100 * one['per_task'] / chunk_s:.2f} % (target < 5 %)")
    print(f"chosen so: a chunk is >= 100 x dask's cost a task (overhead < 1 %), the {tasks} tasks of this study "
          f"leave one worker idle at the end for at most one task, "
          f"{100 * 2 * chunk_s / one['cpu']:.1f} % of the 2-worker run, and a point of 10^7 samples still splits "
          "into 10 tasks")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="quadruped")
    ap.add_argument("--param", default="foot_z")
    ap.add_argument("--value", type=float, default=0.0)
    ap.add_argument("--n", type=int, default=3 * 10**6, help="samples of the raw / in-process runs")
    ap.add_argument("--cluster-n", type=int, default=10**8, help="samples of the 1- and 2-worker runs (0: skip them)")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved repeats of the raw / in-process runs (best)")
    a = ap.parse_args()
    start = time.perf_counter()
    print(f"conditions: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} (1 min, lags) at start, numba "
          f"threads {numba.get_num_threads()} in-process; model {a.model}, {a.param}={a.value}, metrics "
          f"{'+'.join(DEFAULT_METRICS)}{_autogroup()}")
    rows = _in_process(a)
    grid = {a.param: [a.value] * 4}  # 4 points: chunks for both workers from the start
    runs = {k: _cluster_run(k, a.model, grid, a.cluster_n, k == 1) for k in ((1, 2) if a.cluster_n else ())}
    for k, r in runs.items():
        print(f"{k} worker(s): {'; '.join(r['conditions'])}")
        rows.append((f"study, dask LocalCluster, {k} worker(s)", a.cluster_n, r["wall"], r["cpu"]))
    print(f"load average {os.getloadavg()[0]:.2f} (1 min) at the end; {time.perf_counter() - start:.0f} s in all")
    _print_table(rows)
    raw, local = rows[0], rows[3]
    print(f"\nin-process / raw throughput: {raw[2] / local[2]:.3f} by wall time, {raw[3] / local[3]:.3f} by CPU time "
          f"(target >= 0.8; study overhead {100 * (local[3] / raw[3] - 1):.1f} % of CPU)")
    if runs:
        tasks = len(plan(a.model, grid, a.cluster_n // 4).chunks)
        _print_scaling(runs[1], runs[2], a.cluster_n, tasks)
        _print_chunk(runs[1], a.cluster_n, tasks)


if __name__ == "__main__":
    main()
