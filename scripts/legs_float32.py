"""Float32-rounded feet of in-limit joints against ``Leg.ik``'s ``tol`` (issue 26): how many of 10^5 per robot are
refused with the default ``tol`` (1e-9 m) and with ``tol=1e-7``.

    python scripts/legs_float32.py [N]
"""

from __future__ import annotations

import sys

import numpy as np

from legkin import legs


def main(n: int = 100_000) -> None:
    rng = np.random.default_rng(2026)
    for name in [*legs.ERD_ROBOTS, "bolt"]:
        found = legs.from_model(legs.load_erd(name)[0])
        refused = refused7 = 0
        for leg in found.values():
            q = rng.uniform(leg.lower, leg.upper, (n // len(found), 3))
            p32 = leg.fk(q).astype(np.float32).astype(float)
            refused += int((~leg.ik(p32, return_mask=True)[1]).sum())
            refused7 += int((~leg.ik(p32, tol=1e-7, return_mask=True)[1]).sum())
        print(f"{name}: {n} float32 targets, refused {refused} (tol 1e-9), {refused7} (tol 1e-7)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
