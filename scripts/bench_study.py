"""Throughput of legkin.study: raw batch kernels, in-process, dask LocalCluster with 1 and 2 workers, and dask's
per-chunk overhead at the default chunk size (docs/study.md, "Throughput").

    PYTHONPATH=src python scripts/bench_study.py [--model quadruped] [--n 10000000] [--cluster-n 100000000]

Prints the conditions (CPUs, load average, numba threads) and one table; ratios come from this one run.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from legkin import _kernels
from legkin.study import BLOCK_SIZE, CHUNK_BLOCKS, get_target, study
from legkin.study.cli import scheduler_client
from legkin.study.run import plan


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


def _timed(fn, *args, **kw) -> float:
    return _timed2(fn, *args, **kw)[0]


def _timed2(fn, *args, **kw) -> tuple[float, float]:
    """(wall seconds, CPU seconds of this process, all its threads) of one call."""
    t0, c0 = time.perf_counter(), time.process_time()
    fn(*args, **kw)
    return time.perf_counter() - t0, time.process_time() - c0


def _noop(x: int) -> int:
    return x


def _task_overhead(client, k: int = 400) -> float:
    """Seconds a trivial task costs end to end (submit, schedule, run, gather), k of them on the cluster."""
    client.gather([client.submit(_noop, i, pure=False) for i in range(20)])
    t0 = time.perf_counter()
    client.gather([client.submit(_noop, i, pure=False) for i in range(k)])
    return (time.perf_counter() - t0) / k


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="quadruped")
    ap.add_argument("--param", default="foot_z")
    ap.add_argument("--value", type=float, default=0.0)
    ap.add_argument("--n", type=int, default=10**7, help="samples of the raw / in-process runs")
    ap.add_argument("--cluster-n", type=int, default=10**8, help="samples of the 1- and 2-worker runs (0: skip them)")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved repeats of the raw / in-process runs (best)")
    a = ap.parse_args()
    params = {a.param: a.value}
    print(f"conditions: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} (1 min) at start, numba "
          f"threads {_kernels.threads()} in-process, 1 per dask worker (NUMBA_NUM_THREADS=1); model {a.model}, "
          f"{a.param}={a.value}, metrics reach+conditioning+singularity")
    study(a.model, {a.param: [a.value]}, samples=BLOCK_SIZE)  # compile / load the kernels
    raw = local = raw_cpu = local_cpu = float("inf")
    for _ in range(a.repeat):  # interleaved, best of each: the machine is shared
        wall, cpu = _timed2(_raw, a.model, params, a.n)
        raw, raw_cpu = min(raw, wall), min(raw_cpu, cpu)
        wall, cpu = _timed2(study, a.model, {a.param: [a.value]}, samples=a.n)
        local, local_cpu = min(local, wall), min(local_cpu, cpu)
    numpy_cond = _timed(_raw, a.model, params, a.n, True)
    rows = [("raw batch kernels (sample + ik + jacobian)", a.n, raw),
            ("raw + np.linalg.cond of the reached", a.n, numpy_cond), ("study, in-process", a.n, local)]

    grid = {a.param: [a.value] * 4}  # 4 points: chunks for both workers from the start
    per_task = float("nan")
    for k in (1, 2) if a.cluster_n else ():
        with scheduler_client(f"local:{k}") as client:
            client.wait_for_workers(k)
            study(a.model, grid, samples=BLOCK_SIZE, client=client)  # each worker loads the kernels
            rows.append((f"study, dask LocalCluster {k} worker(s)", a.cluster_n,
                         _timed(study, a.model, grid, samples=a.cluster_n // 4, client=client)))
            if k == 1:
                per_task = _task_overhead(client)
    print(f"load average {os.getloadavg()[0]:.2f} (1 min) at the end")
    print(f"\n{'run':<44} {'samples':>12} {'seconds':>9} {'evaluations/s':>14}")
    for name, n, t in rows:
        print(f"{name:<44} {n:>12.3g} {t:>9.2f} {n / t:>14.4g}")
    print(f"\nin-process / raw throughput: {raw / local:.3f} by wall time (overhead {100 * (local / raw - 1):.1f} %)"
          f", {raw_cpu / local_cpu:.3f} by CPU time ({1e9 * raw_cpu / a.n:.0f} vs {1e9 * local_cpu / a.n:.0f} CPU-ns a "
          f"sample; overhead {100 * (local_cpu / raw_cpu - 1):.1f} %: CPU time is what other processes disturb least)")
    if not a.cluster_n:
        return
    rate1 = rows[3][1] / rows[3][2]
    chunk_s = CHUNK_BLOCKS * BLOCK_SIZE / rate1
    print(f"2 workers / 1 worker: {rows[3][2] / rows[4][2]:.2f}x")
    print(f"chunk size: {CHUNK_BLOCKS} blocks x {BLOCK_SIZE} samples = {CHUNK_BLOCKS * BLOCK_SIZE} samples, "
          f"{chunk_s:.3f} s of one worker's compute; dask's cost a task {1e3 * per_task:.2f} ms "
          f"(trivial tasks on 1 worker): per-chunk overhead {100 * per_task / chunk_s:.2f} %")
    print("chosen so: a chunk takes >= 100 x dask's per-task cost (overhead < 1 %) and a point of 10^7 samples "
          "still splits into >= 9 tasks, so 2 workers start at once and finish together")


if __name__ == "__main__":
    main()
