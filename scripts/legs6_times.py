"""Per humanoid of example-robot-data: the leg's structure, the IK's errors and CPU times (``time.thread_time``, best
of 5 loops; one numba thread) of ``Leg6.ik`` and ``Leg6.ik_all`` single calls, of the batch per target, and of EAIK's
``IK`` single calls (every solution, no limits) on the same targets in the same run (issue 26). ``--wall``: wall
times (``time.perf_counter``, best of 5) with numba's default thread count instead (a batch of 1000 targets then
runs on every thread).

    python scripts/legs6_times.py [--wall]
"""

from __future__ import annotations

import sys
import time

import numba
import numpy as np

import legkin

_CLOCK = time.thread_time


def _best(f, n: int, repeats: int = 5) -> float:
    ts = []
    for _ in range(repeats):
        t0 = _CLOCK()
        f()
        ts.append(_CLOCK() - t0)
    return min(ts) / n * 1e6


def _eaik(leg, targets: np.ndarray) -> float | None:
    try:
        from eaik.IK_HP import HPRobot
    except ImportError:
        return None
    offsets = np.vstack([leg.origins[0], np.diff(leg.origins, axis=0), leg.foot_pose[:3, 3] - leg.origins[5]])
    robot = HPRobot(np.array(leg.axes), offsets)
    if not robot.hasKnownDecomposition():
        return None
    te = targets.copy()
    te[:, :3, :3] = te[:, :3, :3] @ leg.foot_pose[:3, :3].T  # EAIK's tool frame: the foot frame turned back
    robot.IK(te[0])
    return _best(lambda: [robot.IK(t) for t in te], len(te))


def main() -> None:
    global _CLOCK
    if "--wall" in sys.argv[1:]:
        _CLOCK = time.perf_counter
        print(f"wall time, {numba.get_num_threads()} numba threads")
    else:
        numba.set_num_threads(1)
    for name in ["talos", "romeo", "icub", "simple_humanoid", "alexander", "g1"]:
        r = legkin.load(name)
        leg = r.geometry[list(r.geometry)[0]]
        n = 1000 if leg.structure == "6R-spherical-hip" else 200
        q = np.random.default_rng(7).uniform(leg.lower, leg.upper, (n, 6))
        targets = leg.fk(q)
        leg.ik(targets[:3]), leg.ik(targets[0]), leg.ik_all(targets[0])
        back = leg.fk(leg.ik(targets))
        perr = np.linalg.norm(back[:, :3, 3] - targets[:, :3, 3], axis=-1).max()
        rerr = np.abs(back[:, :3, :3] - targets[:, :3, :3]).max()
        ts = _best(lambda: [leg.ik(t) for t in targets], n)
        tsa = _best(lambda: [leg.ik_all(t) for t in targets], n)
        tb = _best(lambda: leg.ik(targets), n)
        te = _eaik(leg, targets)
        peer = "EAIK: none (no known decomposition or not installed)" if te is None else (
            f"EAIK IK {te:6.2f} us | ik/EAIK {ts / te:.2f}, ik_all/EAIK {tsa / te:.2f}")
        print(f"{name:16s} {leg.structure:18s} pos err {perr:.1e} m, R err {rerr:.1e} | ik {ts:6.2f} us, ik_all "
              f"{tsa:6.2f} us, batch {tb:6.2f} us/target ({tb / ts:.2f}x ik) | {peer}")


if __name__ == "__main__":
    main()
