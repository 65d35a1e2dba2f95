"""Where a first run's compile time goes: each kernel's numba compile time, less its callees' (exclusive).

Runs ``legkin check MODELS --jobs 1`` in this process, on one thread, with a fresh numba cache (a temporary
``NUMBA_CACHE_DIR`` unless one is set), records numba's ``numba:compile`` events and prints the kernels by
exclusive compile time, with their inclusive time and compile count::

    python scripts/compile_profile.py wheel_leg            # one mechanism's first run
    python scripts/compile_profile.py a1 quadruped --top 15  # a group of models in one worker

The total is the CPU a first ``legkin check`` spends compiling for these models (CONTRIBUTING.md, "First-run
compile"); on a shared machine, compare runs interleaved.
"""

from __future__ import annotations

import argparse
import collections
import os
import sys
import tempfile
import time


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="+", help="models to check (legkin list)")
    parser.add_argument("--top", type=int, default=30, help="kernels to list (default 30)")
    args = parser.parse_args(argv)
    if "NUMBA_CACHE_DIR" not in os.environ:
        os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="legkin-numba-")
    os.environ["NUMBA_NUM_THREADS"] = "1"  # before numba is imported: batches on the calling thread

    from numba.core import event

    from legkin import _kernels
    from legkin.__main__ import main as legkin_main

    _kernels.serial_parfor_loops = True  # as legkin check's workers: no parallel twin
    stack: list[list] = []
    exclusive: collections.Counter[str] = collections.Counter()
    inclusive: collections.Counter[str] = collections.Counter()
    count: collections.Counter[str] = collections.Counter()

    class Listener(event.Listener):
        def on_start(self, ev: event.Event) -> None:
            stack.append([ev.data["dispatcher"], time.perf_counter(), 0.0])

        def on_end(self, ev: event.Event) -> None:
            dispatcher, t0, callees = stack.pop()
            dt = time.perf_counter() - t0
            fn = dispatcher.py_func
            name = f"{fn.__module__.removeprefix('legkin.')}.{fn.__qualname__}"
            inclusive[name] += dt
            exclusive[name] += dt - callees
            count[name] += 1
            if stack:
                stack[-1][2] += dt

    event.register("numba:compile", Listener())
    t0, c0 = time.perf_counter(), time.process_time()
    status = legkin_main(["check", *args.models, "--jobs", "1", "--quiet"])
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"\nlegkin check {' '.join(args.models)} (exit {status}): wall {wall:.1f} s, CPU {cpu:.1f} s; compile "
          f"{sum(exclusive.values()):.1f} s in {sum(count.values())} compiles of {len(exclusive)} functions")
    print(f"{'exclusive':>9} {'inclusive':>9} {'n':>3}  function")
    for name, seconds in exclusive.most_common(args.top):
        print(f"{seconds:8.2f}s {inclusive[name]:8.2f}s {count[name]:3d}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
