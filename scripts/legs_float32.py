"""Float32-rounded targets of in-limit joints against the IK's ``tol`` (issue 26): how many of N per robot are refused
with the default ``tol`` (:data:`legkin.legs.kinematics.IK_TOL` = 1e-7) and with ``tol=1e-9``. Quadrupeds (the nine
example-robot-data ones, POPI's) and bolt: ``Leg.ik`` of the rounded foot positions; humanoids: ``Leg6.ik`` of the
rounded 4x4 foot poses (rotation block and position).

    python scripts/legs_float32.py [N]
"""

from __future__ import annotations

import sys

import numpy as np

from legkin import legs
from legkin.quadruped.measured import legs as popi_legs


def _robots():
    for name in [*legs.ERD_ROBOTS, "popi", *legs.ERD_BIPEDS]:
        yield name, (popi_legs() if name == "popi" else legs.from_model(legs.load_erd(name)[0]))


def main(n: int = 100_000) -> None:
    rng = np.random.default_rng(2026)
    for name, found in _robots():
        refused = refused9 = 0
        for leg in found.values():
            q = rng.uniform(leg.lower, leg.upper, (n // len(found), leg.dof))
            t32 = leg.fk(q).astype(np.float32).astype(float)
            refused += int((~leg.ik(t32, return_mask=True)[1]).sum())
            refused9 += int((~leg.ik(t32, tol=1e-9, return_mask=True)[1]).sum())
        print(f"{name}: {n} float32 targets, refused {refused} (default tol {legs.kinematics.IK_TOL:g}), "
              f"{refused9} (tol 1e-9)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
