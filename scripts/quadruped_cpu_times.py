"""CPU-time ratios of the quadruped's single calls and batch IK (docs/quadruped.md, "Timings").

One line per run: each call's CPU time (``time.thread_time``, best of 7 loops of 20,000 calls) divided by the
yardstick's (Pinocchio ``forwardKinematics`` + ``updateFramePlacement(LF_FOOT)``, same process), and the batch
``ik`` / ``fk`` on 100,000 targets uniform in the joint limits on one numba thread (ns per target). CPU time, not
wall time: on a shared machine a wall-clock run moves by 2x between runs.

Run it on this tree, and on another version exported with its own numba cache, interleaved::

    PYTHONPATH=src python scripts/quadruped_cpu_times.py after
    git archive main | tar -x -C /tmp/legkin-main
    (cd /tmp/legkin-main && NUMBA_CACHE_DIR=/tmp/legkin-main/.nbcache PYTHONPATH=src \\
        python <this tree>/scripts/quadruped_cpu_times.py main)
"""

from __future__ import annotations

import sys
import time
import timeit
from typing import Callable

import numba
import numpy as np
import pinocchio as pin

import legkin
from legkin import quadruped as aq


def cpu_time(f: Callable[[], object], number: int = 20_000) -> float:
    """Best CPU time (s) of one call of ``f`` over 7 loops of ``number`` calls (after one warm-up call)."""
    f()
    return min(timeit.repeat(f, number=number, repeat=7, timer=time.thread_time)) / number


def main(label: str) -> None:
    """Print one line ``label name=value ...`` (ratios to the yardstick; batch rows in ns per target)."""
    q = np.array([0.0, 0.75, 1.5])
    p = aq.fk(q, "LF")
    qn, batch, geometry = q + 0.01, np.stack([p] * 8), aq.Geometry(foot_z=-0.015)
    model = legkin.load("quadruped").model
    data, fid, q0 = model.createData(), model.getFrameId("LF_FOOT"), pin.neutral(model)

    def yardstick() -> None:
        pin.forwardKinematics(model, data, q0)
        pin.updateFramePlacement(model, data, fid)

    y = cpu_time(yardstick)
    row = {"yardstick (ns)": y * 1e9}
    calls: dict[str, Callable[[], object]] = {
        "fk": lambda: aq.fk(q, "LF"), "fk (geometry)": lambda: aq.fk(q, "LF", geometry=geometry),
        "jacobian": lambda: aq.jacobian(q, "LF"), "ik": lambda: aq.ik(p, "LF"),
        "ik (q_near)": lambda: aq.ik(p, "LF", q_near=qn), "ik, batch of 8": lambda: aq.ik(batch, "LF"),
        "ik_all": lambda: aq.ik_all(p, "LF"),
    }
    for name, f in calls.items():
        row[name] = cpu_time(f) / y
    lo, hi = aq.JOINT_LIMITS[:, 0], aq.JOINT_LIMITS[:, 1]
    qs = lo + (hi - lo) * np.random.default_rng(0).random((100_000, 3))
    ps = aq.fk(qs, "LF")
    numba.set_num_threads(1)
    row["batch ik 1 thread (ns/target)"] = cpu_time(lambda: aq.ik(ps, "LF"), 1) / len(ps) * 1e9
    row["batch fk 1 thread (ns/target)"] = cpu_time(lambda: aq.fk(qs, "LF"), 1) / len(qs) * 1e9
    print(label, " ".join(f"{k}={v:.3g}" for k, v in row.items()))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "this")
