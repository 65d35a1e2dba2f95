"""POPI's joint limits: :func:`within_limits` and the kernels that keep an IK answer inside them."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .._batch import check_number
from .._kernels import as_rows, batch_kernel, kernel, prange
from ._common import foot_z_of, rows
from .constants import HI, LIMIT_TOL, LO, TWO_PI
from .geometry import Geometry

__all__ = ["within_limits"]


@kernel(entry=True)
def _within_limits_k(q, tol) -> bool:
    """Whether ``q`` (3,) lies inside :data:`JOINT_LIMITS` with slack ``tol`` (NaN: outside)."""
    return (
        q[0] >= LO[0] - tol and q[0] <= HI[0] + tol
        and q[1] >= LO[1] - tol and q[1] <= HI[1] + tol
        and q[2] >= LO[2] - tol and q[2] <= HI[2] + tol
    )


@batch_kernel(rows="q out", min_parallel=256, parfor=True)
def _within_limits_batch(q, tol, out) -> None:
    n = q.shape[0]
    for i in prange(n):
        out[i] = _within_limits_k(q[i], tol)


@kernel(inline=True)
def _toward_limits_k(x, row):
    """The representative of angle ``x`` (mod 2 pi) inside the limits of joint ``row`` when one is.

    Needed where a limit is +-pi (q2's upper limit): rounding can return -pi + eps for pi - eps.
    """
    lo, hi = LO[row], HI[row]
    if x < lo - LIMIT_TOL and x + TWO_PI <= hi + LIMIT_TOL:
        x = x + TWO_PI
    if x > hi + LIMIT_TOL and x - TWO_PI >= lo - LIMIT_TOL:
        x = x - TWO_PI
    return x


@kernel(inline=True)
def _strictly_inside_k(q1, q2, q3) -> bool:
    """Inside :data:`JOINT_LIMITS` with no slack."""
    return q1 >= LO[0] and q1 <= HI[0] and q2 >= LO[1] and q2 <= HI[1] and q3 >= LO[2] and q3 <= HI[2]


@kernel(inline=True)
def _inside_by_k(q1, q2, q3, slack) -> bool:
    """Inside :data:`JOINT_LIMITS` widened by ``slack`` (rad)."""
    return (
        q1 >= LO[0] - slack and q1 <= HI[0] + slack
        and q2 >= LO[1] - slack and q2 <= HI[1] + slack
        and q3 >= LO[2] - slack and q3 <= HI[2] + slack
    )


def within_limits(
    q: npt.ArrayLike, tol: float = LIMIT_TOL, *, geometry: Geometry | None = None
) -> np.ndarray | np.bool_:
    """Whether joint vectors (..., 3) lie inside :data:`~legkin.quadruped.JOINT_LIMITS` (slack ``tol`` rad).

    NaN and infinite entries (e.g. the unreachable rows of :func:`~legkin.quadruped.ik_all`) count as
    outside. A single ``q`` (3,) gives a numpy bool, a batch a bool array (...). ``geometry`` is accepted
    like everywhere (checked; the limits do not depend on it).

    Raises:
        InvalidInputError: ``q`` not a real array of shape (..., 3).
        InvalidParameterError: ``tol`` not a finite number >= 0; bad ``geometry``.
    """
    if type(tol) is not float or not 0.0 <= tol < np.inf:
        tol = check_number(tol, "tol", 0.0)
    if geometry is not None:
        foot_z_of(geometry)
    arr = rows(q, "q")
    if arr.ndim == 1:
        return np.True_ if _within_limits_k(arr, tol) else np.False_
    out = np.empty(arr.shape[:-1], dtype=np.bool_)
    _within_limits_batch(as_rows(arr, 3), tol, out.reshape(-1))
    return out
