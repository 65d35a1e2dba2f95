"""Finite differences for the wheel-leg's check rows (issue 25): central where the function is smooth over the
stencil, second-order one-sided where the central stencil would leave the joint limits or cross a switch of the
function's branch.

Central differences ``(f(q + h) - f(q - h)) / 2h`` are accurate to ``h^2 |f'''| / 6`` plus rounding only where f is
smooth over ``[q - h, q + h]``. Two cases break that at random samples, each with a probability ~h per sample (the
check sweep met both at 10^5 samples):

* theta within h of its limit: the stencil clipped onto the limit is off-centre, a first-order difference (error
  ``|offset| |f''|``, 3.7e-8 at theta 1.5e-7 rad above THETA_MIN: seed 2, 10^5 samples);
* the ground contact's height at a switch of the lowest point (another tyre piece or the other tyre edge): the
  height is the minimum of two smooth functions there, with a kink (6.9e-2 across a jump from one tip cap to the
  other, 9.0e-3 across the edge switch at gamma = 0: seeds 0-3, 10^5 samples).

There the derivative of the centre's branch is taken from the three points q, q + h, q + 2h (or q, q - h, q - 2h),
``(-3 f(q) + 4 f(q + h) - f(q + 2h)) / 2h``, on the side where they stay inside the limits and on the centre's branch
(truncation ``h^2 |f'''| / 3``, rounding ~3x the central's); a sample where neither side fits (two switches within
2h) is left out and counted.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

#: f(q (m, 3), rows (m,)) -> (values (m, k), branch (m,) int, or None where f has one smooth branch): ``rows``
#: index the samples' fixed parameters (contact point, leg, ...).
Function = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray | None]]


def derivative(f: Function, q: np.ndarray, c: int, h: float, lower: float, upper: float,
               centre: tuple[np.ndarray, np.ndarray | None]) -> tuple[np.ndarray, np.ndarray]:
    """d f / d q_c at each row of q by the module's differences.

    Args:
        f: the function (see :data:`Function`).
        q: (n, 3) the samples (rad).
        c: the column differentiated.
        h: the step (rad).
        lower: q_c's lower limit (rad; f is not evaluated below it).
        upper: q_c's upper limit (rad).
        centre: ``f(q, arange(n))``, the values at the samples and their branches.

    Returns:
        ``(derivative, fitted)``: (n, k) the derivative (f's unit per rad; NaN where no stencil fits) and (n,) the
        samples whose stencil is one-sided or left out (True), for counting.
    """
    n = len(q)
    rows = np.arange(n)

    def at(k: int, sel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """f at q + k h e_c of the samples ``sel``: values, branch (zeros without branches), inside the limits."""
        x = q[sel].copy()
        x[:, c] += k * h
        inside = (x[:, c] >= lower) & (x[:, c] <= upper)
        x[:, c] = np.clip(x[:, c], lower, upper)
        values, branch = f(x, rows[sel])
        return values, np.zeros(len(x), dtype=np.int64) if branch is None else branch, inside

    f0, b0 = centre[0], np.zeros(n, dtype=np.int64) if centre[1] is None else centre[1]
    fp, bp, ip = at(1, rows)
    fm, bm, im = at(-1, rows)
    out = np.full(f0.shape, np.nan)
    central = ip & im & (bp == b0) & (bm == b0)
    out[central] = (fp[central] - fm[central]) / (2 * h)
    side_ok = {1: ip & (bp == b0), -1: im & (bm == b0)}
    near = {1: fp, -1: fm}
    for k in (1, -1):
        sel = ~central & side_ok[k] & np.isnan(out[:, 0])
        if sel.any():
            f2, b2, i2 = at(2 * k, sel)
            ok = i2 & (b2 == b0[sel])
            idx = rows[sel][ok]
            out[idx] = k * (-3 * f0[idx] + 4 * near[k][idx] - f2[ok]) / (2 * h)
    return out, ~central
