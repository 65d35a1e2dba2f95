"""Completeness of the 6-DOF legs' one-dimensional searches (issue 26): per leg of g1 and alexander, random in-limit
configurations, their foot poses solved by ``Leg6.ik_all`` and ``Leg6.ik`` (batches); printed per leg and seed:

* ``missed``: samples whose configuration is not among ``ik_all``'s rows: the nearest row (each angle mod 2 pi) is
  farther than ``max(1e-9, 1e-12 / sigma_min)`` rad, ``sigma_min`` the least singular value of the foot Jacobian at
  the sampled configuration (a pose reproduced to 1e-12 fixes the joints only to ``1e-12 / sigma_min``: near a
  singular configuration two solutions merge);
* ``near singular``: samples that needed that allowance (their gap beyond 1e-9 rad), with their worst gap;
* ``worst row error``: the largest pose error of any row of ``ik_all`` (position m and rotation rad, legkin's
  forward map, which equals Pinocchio's to ~1e-15: ``legkin check``);
* ``ik``: the poses ``Leg6.ik`` solved inside the limits and its worst pose error.

    python scripts/legs6_completeness.py                       # g1 and alexander, 10^5 per leg, seed 0
    python scripts/legs6_completeness.py g1 --samples 100000 --seeds 0,1,2
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import legkin

#: The sampled configuration is among the rows when the nearest is within this (rad) ...
GAP = 1e-9
#: ... or within this pose accuracy (m, rad) over the Jacobian's least singular value.
POSE = 1e-12


def _pose_error(leg, q: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """max(position error, rotation angle) of ``fk(q)`` against ``targets`` (..., 4, 4)."""
    f = leg.fk(q)
    dp = np.linalg.norm(f[..., :3, 3] - targets[..., :3, 3], axis=-1)
    rel = np.einsum("...ji,...jk->...ik", f[..., :3, :3], targets[..., :3, :3])
    cos = np.clip((np.trace(rel, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    skew = np.stack([rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0],
                     rel[..., 1, 0] - rel[..., 0, 1]], axis=-1)
    ang = np.arctan2(0.5 * np.linalg.norm(skew, axis=-1), cos)
    return np.maximum(dp, ang)


def check_leg(leg, samples: int, seed: int) -> dict:
    """The figures of one leg on ``samples`` configurations drawn with ``seed`` (see the module docstring)."""
    q = np.random.default_rng(seed).uniform(leg.lower, leg.upper, (samples, 6))
    targets = leg.fk(q)
    t0 = time.process_time()
    rows, mask = leg.ik_all(targets, return_mask=True)
    t_all = time.process_time() - t0
    gap = np.where(mask, np.abs(np.angle(np.exp(1j * (rows - q[:, None])))).max(axis=-1), np.inf).min(axis=-1)
    far = np.nonzero(gap > GAP)[0]
    sigma = np.linalg.svd(leg.jacobian(q[far]), compute_uv=False)[:, -1] if len(far) else np.zeros(0)
    missed = far[gap[far] > POSE / np.maximum(sigma, 1e-300)]
    err = _pose_error(leg, np.where(mask[..., None], rows, 0.0), targets[:, None])[mask]
    q_ik, ok = leg.ik(targets, return_mask=True)
    ok &= np.asarray(leg.within_limits(np.nan_to_num(q_ik)))
    return {"missed": missed, "q": q, "gap": gap, "near": len(far) - len(missed),
            "near_gap": float(gap[far].max()) if len(far) else 0.0, "rows": int(mask.sum()),
            "row_err": float(err.max()), "ik_ok": int(ok.sum()),
            "ik_err": float(_pose_error(leg, q_ik[ok], targets[ok]).max()), "us": t_all / samples * 1e6}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("robots", nargs="*", default=["g1", "alexander"])
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--seeds", default="0")
    a = ap.parse_args()
    print("| robot | leg | seed | samples | missed | near singular (worst gap, rad) | ik_all rows | worst row error "
          "| ik solved in limits | ik worst error | ik_all CPU us / target |")
    print("|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|")
    for name in a.robots:
        robot = legkin.load(name)
        for seed in (int(s) for s in a.seeds.split(",")):
            for ln, leg in robot.geometry.items():
                r = check_leg(leg, a.samples, seed)
                print(f"| {name} | {ln} | {seed} | {a.samples} | {len(r['missed'])} | {r['near']} "
                      f"({r['near_gap']:.1e}) | {r['rows']} | {r['row_err']:.1e} | {r['ik_ok']}/{a.samples} | "
                      f"{r['ik_err']:.1e} | {r['us']:.1f} |", flush=True)
                for i in r["missed"]:
                    print(f"    missed: {name} {ln} seed {seed} sample {i}: q = {r['q'][i].tolist()!r}, gap "
                          f"{r['gap'][i]:.3g} rad", flush=True)


if __name__ == "__main__":
    main()
