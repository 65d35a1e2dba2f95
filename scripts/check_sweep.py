"""Every ``legkin check`` row over many seeds and sample counts (issue 25): each row's worst error / tolerance.

A row's tolerance is safe when no seed and no sample count brings its error near it. This script runs the rows of
``legkin check`` (:func:`legkin.validation._run_models`, the same draws as ``legkin check --random-seed S
--samples N``) for every seed and size, in one process (each model's kernels compile or load once), and appends
one JSON line per (model, samples, seed) to ``--out``; a second run skips the lines already there, so an
interrupted sweep resumes. It then prints, for every row, the worst ratio max error / tolerance over what the file
holds, with the seed and sample count that reached it, and the seeds and sizes covered per model.

The draws of different sample counts are not nested (``legkin check --samples 100000`` draws its own samples, not
10^4 of them and more), so every size runs. The MuJoCo export's rows (when mujoco is installed) use at most 20
samples from their own generator (``default_rng(seed + 2)``) whatever ``--samples`` is: they run once per seed, at
the smallest size.

    nice python scripts/check_sweep.py --out sweep.jsonl                 # every model, seeds 0-19, 10^3-10^5
    python scripts/check_sweep.py --out sweep.jsonl --table              # only the table of what the file holds
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
from pathlib import Path

from legkin._registry import list_models
from legkin.validation import _run_models

#: The mechanisms and the robots the issue names first, then the other registry models.
FIRST = ["tripod", "wheel_leg", "hybrid_leg", "quadruped", "go2", "talos", "g1"]


def row_key(name: str) -> str:
    """A row's name without its counts (``"999/1000 converged"``, ``"(16.8 %; 150 on ...)"``: they change with the
    seed and the sample count), its parameters kept (``[alpha=pi/4]``, ``r = 0.019``, ``h=0.0001``)."""
    if name.startswith("IK on "):
        return "IK robustness (the contract row)"
    name = re.sub(r"\d+/\d+", "#/#", name)
    return re.sub(r"(?<![=/\w.])(?<!= )\d+(\.\d+)?", "#", name)


def run_one(model: str, samples: int, seed: int, mujoco: bool) -> dict:
    """One ``legkin check`` run of ``model``: its rows as JSON (name, max error, tolerance, passed)."""
    t0 = time.process_time()
    rows, _ = _run_models([model], samples=samples, seed=seed, ik_targets=None, classify=2000, mujoco=mujoco)[model]
    return {
        "model": model, "samples": samples, "seed": seed, "mujoco": mujoco,
        "cpu_s": round(time.process_time() - t0, 2),
        "rows": [[r.name, r.max_error, r.tolerance, bool(r.passed)] for r in rows],
    }


def load(path: Path) -> list[dict]:
    """The records of ``path`` (none if it does not exist)."""
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def table(records: list[dict]) -> tuple[str, bool]:
    """The worst ratio per row (with its seed and samples) and the coverage per model; and whether all passed."""
    worst: dict[tuple[str, str], tuple[float, int, int, bool]] = {}
    cover: dict[str, dict[int, set[int]]] = {}
    for rec in records:
        cover.setdefault(rec["model"], {}).setdefault(rec["samples"], set()).add(rec["seed"])
        seen: dict[str, int] = {}
        for name, err, tol, passed in rec["rows"]:
            ratio = err / tol if tol and math.isfinite(err) else (0.0 if err == 0 else math.inf)  # tol 0: exact rows
            name = row_key(name)
            seen[name] = seen.get(name, 0) + 1
            key = (rec["model"], name if seen[name] == 1 else f"{name} (#{seen[name]})")
            old_ratio, old_seed, old_n, ok = worst.get(key, (-1.0, 0, 0, True))
            if ratio > old_ratio:
                old_ratio, old_seed, old_n = ratio, rec["seed"], rec["samples"]
            worst[key] = (old_ratio, old_seed, old_n, ok and passed)
    lines = [f"{'model':<16} {'row':<70} {'worst err/tol':>13} {'seed':>4} {'samples':>7}  result"]
    for (model, name), (ratio, seed, n, ok) in worst.items():
        lines.append(f"{model:<16} {name[:70]:<70} {ratio:>13.3f} {seed:>4} {n:>7}  {'pass' if ok else 'FAIL'}")
    lines.append("")
    lines.append("covered (samples: seeds):")
    for model, sizes in cover.items():
        lines.append(f"  {model:<16} " + "; ".join(f"{n}: {_ranges(sorted(s))}" for n, s in sorted(sizes.items())))
    return "\n".join(lines), all(ok for *_, ok in worst.values())


def _ranges(seeds: list[int]) -> str:
    """``[0, 1, 2, 5]`` as ``"0-2,5"``."""
    parts, start = [], None
    for i, s in enumerate(seeds):
        start = s if start is None else start
        if i + 1 == len(seeds) or seeds[i + 1] != s + 1:
            parts.append(f"{start}-{s}" if s > start else f"{s}")
            start = None
    return ",".join(parts)


def main(argv: list[str] | None = None) -> int:
    """Run what ``--out`` does not hold yet, then print the table; exit 1 if a row failed anywhere."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("models", nargs="*", help="models (default: every registry model, the mechanisms first)")
    p.add_argument("--seeds", type=int, nargs="+", default=list(range(20)))
    p.add_argument("--sizes", type=int, nargs="+", default=[1000, 10_000, 100_000])
    p.add_argument("--out", type=Path, required=True, help="JSON lines file (appended; resumes)")
    p.add_argument("--no-mujoco", action="store_true", help="no MuJoCo rows (another run covers them)")
    p.add_argument("--table", action="store_true", help="only print the table of --out")
    args = p.parse_args(argv)
    models = args.models or FIRST + [m for m in list_models() if m not in FIRST]
    if not args.table:
        done = {(r["model"], r["samples"], r["seed"]) for r in load(args.out)}
        for n in sorted(args.sizes):  # every model at the small sizes first: the largest dominates the time
            for model in models:
                for seed in args.seeds:
                    if (model, n, seed) in done:
                        continue
                    rec = run_one(model, n, seed, mujoco=not args.no_mujoco and n == min(args.sizes))
                    with args.out.open("a") as f:
                        f.write(json.dumps(rec) + "\n")
                    ok = all(r[3] for r in rec["rows"])
                    print(f"{model} n={n} seed={seed} {rec['cpu_s']} s CPU {'pass' if ok else 'FAIL'}", flush=True)
    text, ok = table(load(args.out))
    print(text)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
