"""The tripod's check rows held to a conditioning bound, over many seeds and sample counts (issue 25): the
measurement behind ``legkin.tripod.checks.AMP_CONSTANT`` (``--row jacobian``, the "A_u vs Pinocchio" rows; too slow
for CI: ~0.5 ms a sample, Pinocchio's SVD in Python), and ``FK_CONSTANT`` and ``INCONSISTENCY_CONSTANT``
(``--row fk``, the "fk(ik(u))" rows: fast).

For each seed and sample count it draws the orientations as ``legkin check`` does (``sample_workspace``, and the
near-flip samples where the workspace reaches the flip), and prints the largest error and the largest
error / (eps x amplification), the row's value, with whether the row passes (<= the constant). ``--row fk`` prints
the round trip's ratio far from the flip / near it and the inconsistency's ratio.

    python scripts/tripod_conditioning_sweep.py --alpha pi/2 --seeds 20 --sizes 1000 10000 100000
    python scripts/tripod_conditioning_sweep.py --row fk --alpha pi/4
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from legkin import load
from legkin import tripod as at
from legkin.tripod import checks
from legkin.tripod.configuration import sample_workspace

ALPHAS = {"pi/3": math.pi / 3, "pi/4": math.pi / 4, "pi/2": math.pi / 2}


EPS = float(np.finfo(float).eps)


def _draw(geo: at.Geometry, alpha: float, seed: int, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The orientations (alpha_y, alpha_z) of a check run's draw and their ik configurations."""
    rng = np.random.default_rng(seed)
    ay, az = sample_workspace(n, rng, geo)
    fy, fz = checks.sample_near_flip(max(n // 10, 50), rng, alpha)
    if len(fy):
        ay, az = np.concatenate([ay, fy]), np.concatenate([az, fz])
    return ay, az, at.ik_joints(np.stack([ay, az], axis=-1), geometry=geo)


def sweep_one(robot, geo: at.Geometry, alpha: float, seed: int, n: int) -> tuple[float, float, int]:
    """(largest error, largest error / (eps x amplification): the row's value, samples) of one check run's draw."""
    ay, az, q = _draw(geo, alpha, seed, n)
    err, amp = checks.actuation_jacobian_errors(robot, geo, q, ay, az)
    return float(err.max()), float((err / (EPS * amp)).max()), len(q)


def sweep_fk(geo: at.Geometry, alpha: float, seed: int, n: int) -> tuple[float, list[float], int]:
    """(largest round-trip error, [its largest ratio far from the flip, near it, the inconsistency's], samples)."""
    ay, az, q = _draw(geo, alpha, seed, n)
    far = 1 + np.cos(ay) * np.cos(az) > checks.NEAR_FLIP
    err, amp, inc, inc_amp = checks.fk_round_trip_errors(geo, q, ay, az, far)
    ratio = err / (EPS * amp)
    worst = [float(np.max(ratio[sel], initial=0.0)) for sel in (far, ~far)]  # NaN (fk failed) propagates
    return float(np.max(err)), worst + [float(np.max(inc[far] / (EPS * inc_amp[far])))], len(q)


def main(argv: list[str] | None = None) -> int:
    """Print one line per (seed, sample count) and the overall maxima; exit 1 if a row would fail."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--alpha", choices=sorted(ALPHAS), default="pi/2")
    p.add_argument("--row", choices=["jacobian", "fk"], default="jacobian")
    p.add_argument("--seeds", type=int, default=20)
    p.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    args = p.parse_args(argv)
    alpha = ALPHAS[args.alpha]
    geo = at.Geometry(alpha=alpha)
    robot = load("tripod") if args.alpha == "pi/3" else load("tripod", alpha=alpha)
    if args.row == "fk":
        return _main_fk(geo, alpha, args)
    worst_err = worst_ratio = 0.0
    print(f"alpha={args.alpha}: the row's tolerance AMP_CONSTANT={checks.AMP_CONSTANT:g}")
    for n in args.sizes:
        for seed in range(args.seeds):
            t0 = time.perf_counter()
            err, ratio, m = sweep_one(robot, geo, alpha, seed, n)
            worst_err, worst_ratio = max(worst_err, err), max(worst_ratio, ratio)
            print(f"n={n:>6} seed={seed:>2} samples={m:>6}  max error {err:.3e}  max error/(eps amp) {ratio:6.3f}  "
                  f"{'pass' if ratio <= checks.AMP_CONSTANT else 'FAIL'}  ({time.perf_counter() - t0:.0f} s)",
                  flush=True)
    failed = worst_ratio > checks.AMP_CONSTANT
    print(f"overall: max error {worst_err:.3e}, max error/(eps amp) {worst_ratio:.3f} (AMP_CONSTANT "
          f"{checks.AMP_CONSTANT:g}); {'FAIL' if failed else 'the row passes at every seed and size'}")
    return 1 if failed else 0


def _main_fk(geo: at.Geometry, alpha: float, args: argparse.Namespace) -> int:
    """``--row fk``: the fk(ik(u)) rows' ratios per (seed, sample count) and overall; exit 1 if a row would fail."""
    limits = (checks.FK_CONSTANT, checks.FK_CONSTANT, checks.INCONSISTENCY_CONSTANT)
    print(f"alpha={args.alpha}: FK_CONSTANT={checks.FK_CONSTANT:g}, "
          f"INCONSISTENCY_CONSTANT={checks.INCONSISTENCY_CONSTANT:g}")
    worst_err, worst = 0.0, [0.0, 0.0, 0.0]
    for n in args.sizes:
        for seed in range(args.seeds):
            err, ratios, m = sweep_fk(geo, alpha, seed, n)
            worst_err, worst = max(worst_err, err), [max(a, b) for a, b in zip(worst, ratios)]
            ok = all(r <= lim for r, lim in zip(ratios, limits))
            print(f"n={n:>6} seed={seed:>2} samples={m:>6}  max error {err:.3e}  round trip / (eps amp) far "
                  f"{ratios[0]:6.3f} near the flip {ratios[1]:6.3f}  inconsistency {ratios[2]:6.3f}  "
                  f"{'pass' if ok else 'FAIL'}", flush=True)
    failed = not all(r <= lim for r, lim in zip(worst, limits))
    verdict = "FAIL" if failed else "the rows pass at every seed and size"
    print(f"overall: max error {worst_err:.3e}, round trip / (eps amp) far {worst[0]:.3f}, near the flip "
          f"{worst[1]:.3f}, inconsistency {worst[2]:.3f}; {verdict}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
