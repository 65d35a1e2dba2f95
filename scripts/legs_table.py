"""Tables of docs/legs.md: the geometry legkin.legs measures on the nine example-robot-data quadrupeds, and
its errors against Pinocchio (legkin.legs.checks.run: FK, Jacobian, IK round trip, every IK branch).

Usage: python scripts/legs_table.py [--samples 10000] [--seed 0]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from legkin import legs
from legkin.legs import checks


def _fmt(v: float) -> str:
    return f"{round(v, 4) + 0.0:+.4f}"  # + 0.0: no "-0.0000"


def geometry_table() -> str:
    lines = [
        "| robot | legs | joints (first leg) | foot frame | axes HAA, HFE, KFE | lateral offset d (m) | "
        "HAA->HFE h (X, Y) (m) | thigh \\|k\\| (m) | shank \\|l\\| (m) | thigh zero (deg) | knee zero (deg) | "
        "knee sign s3 | axis deviation (rad) |",
        "|---|---|---|---|---|---|---|---:|---:|---:|---:|---:|---|",
    ]
    for name in legs.ERD_ROBOTS:
        found = legs.from_model(legs.load_erd(name)[0])
        first = next(iter(found.values()))
        axes = sorted({", ".join(leg.axis_labels) for leg in found.values()})
        d = " / ".join(f"{leg.name} {_fmt(leg.lateral_offset)}" for leg in found.values())
        hs = sorted({f"({_fmt(leg.hip_offset[0])}, {_fmt(abs(leg.hip_offset[1]))})" for leg in found.values()})
        tz = sorted({round(math.degrees(leg.knee_offset_angles[0]), 2) + 0.0 for leg in found.values()})
        kz = sorted({round(math.degrees(leg.knee_offset_angles[1]), 2) + 0.0 for leg in found.values()})
        s3 = sorted({int(leg.knee_sign) for leg in found.values()})
        dev = max(max(leg.axis_deviation) for leg in found.values())
        lines.append(
            f"| {name} | {', '.join(found)} | {', '.join(first.joint_names)} | {first.foot_frame} | "
            f"{' ; '.join(axes)} | "
            f"{d} | {' ; '.join(hs)} | {first.thigh_length:.4f} | {first.shank_length:.4f} | "
            f"{' ; '.join(f'{v:g}' for v in tz)} | {' ; '.join(f'{v:g}' for v in kz)} | "
            f"{' ; '.join(f'{v:+d}' for v in s3)} | {dev:.1e} |"
        )
    return "\n".join(lines)


def error_table(samples: int, seed: int) -> str:
    lines = [
        "| robot | samples x legs | FK vs oMf (m) | Jacobian vs getFrameJacobian | IK round trip (m) | "
        "solved in limits | all branches (m) | branches | time (s) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name in legs.ERD_ROBOTS:
        t0 = time.perf_counter()
        rows = checks.run(name, samples, np.random.default_rng(seed))
        sec = time.perf_counter() - t0
        fk, jac, ik, allb = rows
        solved = ik.name.split("(")[-1].split(" solved")[0]
        branches = allb.name.split("(")[-1].split(" branches")[0]
        ok = all(r.passed for r in rows)
        lines.append(
            f"| {name} | {fk.samples} | {fk.max_error:.1e} | {jac.max_error:.1e} | {ik.max_error:.1e} | {solved} | "
            f"{allb.max_error:.1e} | {branches} | {sec:.1f} |" + ("" if ok else " **FAIL**")
        )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    print(geometry_table())
    print()
    print(error_table(args.samples, args.seed))


if __name__ == "__main__":
    main()
