"""Faults a user's program meets (issue 25), each reproduced in a fresh Python process and now handled: a fork after
a parallel batch, concurrent batches on a threading layer that is not thread-safe, a damaged or read-only numba cache,
signals to the command line, a viewer open to the network, and small gaps of the error contract.

Each test runs its program in a subprocess (a fork, an abort or a hang must not take pytest down), with a timeout."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import legkin

SRC = str(Path(legkin.__file__).resolve().parents[1])


def run_py(code: str, *, env: dict[str, str] | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter that imports this legkin; its completed process (text output)."""
    full = {**os.environ, "PYTHONPATH": SRC, **(env or {})}
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          env=full, timeout=timeout)


# --- fork and threads -------------------------------------------------------------------------------------------

FORK_CHILD = """
    import os, signal, numpy as np
    from legkin import {module}
    {setup}
    first = {call}
    pid = os.fork()
    if pid == 0:
        signal.alarm(20)  # a hung child dies of SIGALRM instead of hanging the test
        os._exit(0 if np.array_equal({call}, first, equal_nan=True) else 1)
    _, status = os.waitpid(pid, 0)
    print("child", status)
"""


@pytest.mark.parametrize("module, setup, call", [
    # tripod, wheel_leg and hybrid_leg split large batches among a thread pool, whose threads a fork does not copy
    ("tripod", "m = tripod.ik(np.tile([0.2, -0.1], (1000, 1)))", "tripod.fk(m)"),
    # the quadruped's batches run on numba's threading layer (GNU OpenMP here: it kills a forked child)
    ("quadruped", "q = np.tile([0.1, 0.8, 1.2], (5000, 1))", "quadruped.fk(q, 'LF')"),
], ids=["pool", "openmp"])
def test_batch_in_a_forked_child(module, setup, call):
    """The issue's reproducer: after the parent has run a large batch, the same batch in a forked child returns
    the parent's answer (it hung on the pool's missing threads, or was killed by GNU OpenMP)."""
    proc = run_py(FORK_CHILD.format(module=module, setup=setup, call=call))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["child", "0"], (proc.stdout, proc.stderr)


def test_multiprocessing_fork_pool():
    """A ``multiprocessing`` pool with the fork start method (Linux's default before Python 3.14) runs batches."""
    proc = run_py("""
        import multiprocessing, numpy as np
        from legkin import quadruped, tripod
        m = tripod.ik(np.tile([0.2, -0.1], (1000, 1))); tripod.fk(m)
        q = np.tile([0.1, 0.8, 1.2], (5000, 1)); quadruped.fk(q, "LF")
        def work(i):
            return float(np.nansum(tripod.fk(m)) + np.nansum(quadruped.fk(q, "LF")))
        with multiprocessing.get_context("fork").Pool(2) as pool:
            res = pool.map_async(work, range(4)).get(timeout=60)
        print(len(set(res)) == 1 and res[0] == work(0))
    """)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "True"


@pytest.mark.parametrize("layer", ["workqueue", "omp"])
def test_concurrent_batches_on_every_threading_layer(layer):
    """Four Python threads run ``parfor`` batches at once: bit-identical to a serial run. Under ``workqueue``
    (numba's fallback where OpenMP and TBB are absent) this aborted the process ("Concurrent access has been
    detected"); legkin serializes the batches of a layer that is not thread-safe."""
    proc = run_py("""
        import threading, numba, numpy as np
        from legkin import quadruped
        q = np.tile([0.1, 0.8, 1.2], (20000, 1))
        ref = quadruped.fk(q, "LF")
        same = []
        def run():
            for _ in range(25):
                same.append(np.array_equal(quadruped.fk(q, "LF"), ref))
        threads = [threading.Thread(target=run) for _ in range(4)]
        for t in threads: t.start()
        for t in threads: t.join()
        print(numba.threading_layer(), all(same), len(same))
    """, env={"NUMBA_THREADING_LAYER": layer})
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == [layer, "True", "100"]
