"""Compare two ``legkin bench --json`` runs (issue 24: "every bench ratio equal or better, before and after").

Each run's times are divided by its own Pinocchio yardstick (``forwardKinematics + updateFramePlacement``, timed in
the same process), so that two runs on a shared machine compare by their ratios, not their wall times:

* single calls: the bench's own ratio (function / yardstick);
* batch and peer methods: time per target / yardstick time per call.

Usage (one run each, the old tree with its own numba cache)::

    git archive 97b2f6a | tar -x -C /tmp/legkin-old
    (cd /tmp/legkin-old && NUMBA_CACHE_DIR=/tmp/legkin-old/.nbcache PYTHONPATH=src \\
        python -m legkin bench --quick -q --json /tmp/before.json)
    PYTHONPATH=src python -m legkin bench --quick -q --json /tmp/after.json
    python scripts/bench_compare.py /tmp/before.json /tmp/after.json [--slack 0.10]

A row is ``worse`` when its after/before change exceeds ``1 + slack`` (the run-to-run spread of an unchanged
function on this machine, measured by running the same tree twice); the exit code is 1 if any row is.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from typing import Any


def pooled_yardsticks(data: dict[str, Any]) -> dict[tuple[str, str], float]:
    """The median over a run's models of each yardstick's time per call (s), by (key, label): the same call only
    (``solve_loops`` is another call on each model).

    A run times the same Pinocchio call (``quadruped_fk``) once per model; on a shared 2-core machine even its CPU
    time moves by ~10 % between those timings (586 vs 522 ns in one run), and with it every ratio of the model it
    was timed for. The median of the run's timings is the steadier yardstick.
    """
    times: dict[tuple[str, str], list[float]] = {}
    for m in data["models"].values():
        for key, y in ((m.get("single_calls") or {}).get("yardsticks") or {}).items():
            times.setdefault((key, y["label"]), []).append(float(y["time_per_call_s"]))
    return {key: statistics.median(t) for key, t in times.items()}


def ratios(path: str, pooled: bool = False) -> dict[tuple[str, str], float]:
    """Every ratio of a bench JSON file by (model, row name).

    Args:
        path: a file written by ``legkin bench --json``.
        pooled: divide single calls by the run's median yardstick (:func:`pooled_yardsticks`), not their model's.

    Returns:
        ``{(model, "single: NAME") or (model, "method: NAME"): ratio}``, dimensionless.
    """
    with open(path, encoding="utf-8") as f:
        data: dict[str, Any] = json.load(f)
    sticks = pooled_yardsticks(data)
    out: dict[tuple[str, str], float] = {}
    for model, m in data["models"].items():
        single = m.get("single_calls") or {}
        labels = {key: y["label"] for key, y in (single.get("yardsticks") or {}).items()}
        for row in single.get("rows", []):
            ratio = float(row["ratio"])
            stick = (row.get("yardstick"), labels.get(row.get("yardstick")))
            if pooled and row.get("time_per_call_s") and stick in sticks:
                ratio = float(row["time_per_call_s"]) / sticks[stick]
            out[(model, f"single: {row['name']}")] = ratio
        yard = [y["time_per_call_s"] for y in single.get("yardsticks", {}).values() if y["number"] >= 1000]
        if not yard:
            continue
        for method in m.get("methods", []):
            t = method.get("time_per_target_s")
            if t:
                out[(model, f"method: {method['name']}")] = float(t) / yard[0]
    return out


def main(argv: list[str] | None = None) -> int:
    """Print the before / after table and return 1 if a row got worse by more than the slack."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--slack", type=float, default=0.10, help="run-to-run spread allowed (default 0.10)")
    ap.add_argument("--pooled", action="store_true", help="single calls over the run's median yardstick")
    args = ap.parse_args(argv)
    old, new = ratios(args.before, args.pooled), ratios(args.after, args.pooled)
    worse = 0
    print(f"{'model':12s} {'row':78s} {'before':>9s} {'after':>9s} {'after/before':>12s}")
    for key in sorted(set(old) & set(new)):
        change = new[key] / old[key]
        flag = "worse" if change > 1.0 + args.slack else ("better" if change < 1.0 - args.slack else "")
        worse += flag == "worse"
        print(f"{key[0]:12s} {key[1][:78]:78s} {old[key]:9.3g} {new[key]:9.3g} {change:12.2f} {flag}")
    for key in sorted(set(old) ^ set(new)):
        print(f"{key[0]:12s} {key[1][:78]:78s} {'only in ' + ('before' if key in old else 'after')}")
    print(f"{worse} row(s) worse by more than {args.slack:.0%}")
    return 1 if worse else 0


if __name__ == "__main__":
    sys.exit(main())
