#!/usr/bin/env python3
"""Write docs/robustness.md: the bad inputs tried (tests/test_bad_inputs.py) and what each gets.

``python scripts/robustness.py [--out PATH]``: runs every entry of the catalogue and writes the class and
the message it actually raises, so the page always matches the code. The IK contract counts on 10^6
targets are printed by ``legkin check --ik-targets 1000000 --classify-all`` (see the page).
"""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

HEAD = """# Robustness: bad inputs and the IK contract

Every legkin function checks what comes in. NaN/inf, complex input and wrong shapes raise
`InvalidInputError`; keyword parameters of the wrong kind or out of range raise `InvalidParameterError`
(both are `ValueError` subclasses of `LegkinError`); a target that cannot be solved raises
`UnreachableError`, `JointLimitError` (reachable only outside the URDF limits) or `AssemblyModeError`
(reachable only in another assembly mode) from a single call, and is NaN with mask False in a batch. No
numpy, scipy or Pinocchio exception escapes (an integer beyond the largest float, 1.8e308, is an
`InvalidInputError` too; a batch's error names its first bad row: `target must be finite: row 3 has inf
(target[3, 1])`). The uncompiled path (`NUMBA_DISABLE_JIT=1`) raises the same errors. The CLI prints one line on
stderr and exits non-zero (checks failed 1, usage 2, legkin and OS errors 2, internal 3, Ctrl-C 130, SIGHUP 129,
SIGTERM 143, and 141 quietly when the reader of its output went away, as in `legkin check | head -1`), never a
traceback.

## Faults a program meets (issue 25; `tests/test_faults.py` reproduces each in a fresh process)

* **Threads.** Every function may be called from several Python threads at once. Large batches of the
  quadruped and the legs of `legkin.legs` run on numba's threading layer, chosen by numba on the first parallel
  batch: TBB if installed (`pip install tbb`), else OpenMP, else `workqueue`; `NUMBA_THREADING_LAYER=omp|tbb|
  workqueue` (before the first batch) chooses it, `legkin._kernels.threading_layer()` says which one runs.
  `workqueue` is not thread-safe (two threads in it abort the process): under it legkin runs one such batch at a
  time. The other mechanisms split large batches among a thread pool of their own. `numba.set_num_threads(k)` or
  `NUMBA_NUM_THREADS` sets the thread count.
* **fork.** A process forked after a large batch (`multiprocessing`'s default start method on Linux before
  Python 3.14) runs its batches too: legkin's pool starts afresh in the child (`os.register_at_fork`), and where
  the parent's threading layer does not survive a fork (GNU OpenMP, `workqueue`) the child's batches run serially.
  TBB, or the `spawn` / `forkserver` start methods, keep them parallel.
* **The kernel cache.** numba caches the compiled kernels on disk (the package's `__pycache__`, else the user
  cache directory; `NUMBA_CACHE_DIR` overrides both). Each file legkin writes carries a SHA-256 of its name and
  contents: a damaged file (truncated, garbage, altered, another kernel's) is discarded with a
  `legkin.errors.CacheWarning` naming it and the kernel compiled again. With no writable location, kernels load
  from a readable cache or compile in memory in each process, with one `CacheWarning`.
* **Signals.** Ctrl-C or SIGTERM stops `legkin check` and its worker processes at once (measured 0.03-0.1 s idle;
  the workers also die with their parent if it is killed). SIGHUP or SIGTERM to `legkin view` stops its meshcat
  server.
* **The viewer's address.** `legkin view` serves the scene on 127.0.0.1 (this machine only); `--host 0.0.0.0`
  opens it to the network on purpose (anyone who reaches the machine's port 7000 then sees it).
* **Memory.** `wheel_leg.ik` solves a batch of more than 65,536 targets by chunks: its memory beyond the answer
  stays ~20 MB (it was ~310 bytes a target, 13x the answer).

## The IK contract

For every mechanism: every answer marked solved is reproduced by the module's own forward kinematics with
default options (to 1e-9, measured far tighter below); every target that the default forward kinematics
produces from in-limit joints is solved by the default IK; default answers lie inside the URDF joint limits;
branch and assembly-mode choices that FK also makes are explicit arguments of both FK and IK (tripod `mode`,
hybrid leg `branch` / `assembly` / `ll_branch`), defaulting to the mode of the SRDF reference pose. The
mechanism pages (docs/<name>.md) state each one's modes and branch order.

`legkin check` has one row per mechanism, "IK on N random targets in and around the workspace": half made
by FK from in-limit joints, the rest pushed off or anywhere around the workspace; every unsolved target is
classified by the legkin error a single call raises. On 10^6 targets
(`legkin check --ik-targets 1000000 --classify-all`, seed 0):

IK_TABLE

## Bad inputs

Generated by `python scripts/robustness.py` from the catalogue in `tests/test_bad_inputs.py` (a test
checks every row). Each mechanism's test file has more (property tests on random targets, boundaries and
singular sets; keyword checks).

"""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "robustness.md"))
    parser.add_argument("--ik-table", default=str(ROOT / "docs" / "robustness_ik.md"),
                        help="markdown table of the 10^6-target counts (kept between runs)")
    args = parser.parse_args()
    spec = importlib.util.spec_from_file_location("bad_inputs", ROOT / "tests" / "test_bad_inputs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = ["| mechanism | call | raises | message |", "| --- | --- | --- | --- |"]
    for mechanism, text, call, expected in module.CASES:
        try:
            call()
        except Exception as exc:  # noqa: BLE001 - reporting what each bad input gets is the point
            got, message = type(exc).__name__, str(exc).replace("|", "\\|").replace("\n", " ")
        else:
            got, message = "nothing", "(no error: a defect)"
        if len(message) > 160:
            message = message[:157] + "..."
        flag = "" if got == expected.__name__ else f" (expected {expected.__name__})"
        rows.append(f"| {mechanism} | `{text}` | `{got}`{flag} | {message} |")
    ik_path = Path(args.ik_table)
    ik_table = ik_path.read_text().strip() if ik_path.exists() else "(not measured yet)"
    Path(args.out).write_text(HEAD.replace("IK_TABLE", ik_table) + "\n".join(rows) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
