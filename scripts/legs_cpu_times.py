"""CPU time per target of the generic ``legs.Leg`` batch ``ik`` and ``ik_all`` on one numba thread, per
example-robot-data quadruped (docs/legs.md): 100,000 targets of the first leg, joint vectors uniform in its limits
(clipped to [-3.2, 3.2]), best of 7 runs (``time.thread_time``: see scripts/quadruped_cpu_times.py).

Run it on this tree and on another version exported with its own numba cache, interleaved::

    PYTHONPATH=src python scripts/legs_cpu_times.py after
    (cd /tmp/legkin-main && NUMBA_CACHE_DIR=/tmp/legkin-main/.nbcache PYTHONPATH=src \\
        python <this tree>/scripts/legs_cpu_times.py main)
"""

from __future__ import annotations

import sys

import numba
import numpy as np
from quadruped_cpu_times import cpu_time

from legkin import legs


def main(label: str) -> None:
    """Print one line ``label robot=ik/ik_all ...`` (ns per target)."""
    numba.set_num_threads(1)
    row = {}
    for name in legs.ERD_ROBOTS:
        leg = next(iter(legs.from_model(legs.load_erd(name)[0]).values()))
        lo, hi = np.clip(leg.lower, -3.2, 3.2), np.clip(leg.upper, -3.2, 3.2)
        p = leg.fk(lo + (hi - lo) * np.random.default_rng(0).random((100_000, 3)))
        ik = cpu_time(lambda: leg.ik(p), 1) / len(p) * 1e9
        ik_all = cpu_time(lambda: leg.ik_all(p), 1) / len(p) * 1e9
        row[name] = f"{ik:.0f}/{ik_all:.0f}"
    print(label, "ik/ik_all ns per target, 1 thread:", " ".join(f"{k}={v}" for k, v in row.items()))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "this")
