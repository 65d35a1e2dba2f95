"""The tripod's workspace: reachable orientations and singular curves (for plots), as one compiled kernel."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._batch import check_integer
from .._kernels import OK, kernel
from ._common import LEGS, geometry_of
from .closure import _k_ik
from .geometry import Geometry

__all__ = ["workspace", "Workspace"]


@kernel(inline=True)
def _k_linspace(a, b, out):  # type: ignore[no-untyped-def]
    """np.linspace(a, b, len(out)) into out (the same operations: start + i * step, the last point exactly b)."""
    n = out.shape[0]
    step = (b - a) / (n - 1)
    for i in range(n):
        out[i] = i * step + a
    out[n - 1] = b


@kernel(inline=True)
def _k_tilt_curve(theta, phi, pts):  # type: ignore[no-untyped-def]
    """The curve of tilts theta (m,) in directions phi (m,) as (alpha_y, alpha_z) rows into pts (2m, 2), a NaN row
    wherever alpha_z wraps around (|jump| > pi); returns the row count."""
    k = 0
    prev = np.nan
    for i in range(theta.shape[0]):
        st = np.sin(theta[i])
        ay = -np.arcsin(min(max(st * np.sin(phi[i]), -1.0), 1.0))
        az = np.arctan2(st * np.cos(phi[i]), np.cos(theta[i]))
        if i > 0 and abs(az - prev) > math.pi:
            pts[k, 0] = pts[k, 1] = np.nan
            k += 1
        pts[k, 0], pts[k, 1] = ay, az
        k += 1
        prev = az
    return k


@kernel(entry=True)
def _k_workspace(G, eta, ch, ay, az, cos_q2, reachable, phi, theta_k, tilt_max, curves, counts):  # type: ignore[no-untyped-def]
    """:func:`workspace` on preallocated outputs: the grid (ik's kernel, home mode: cos q_K2 and success), the
    singular curves theta_K(phi) = 2 asin(cos(alpha/2) / |sin(phi - eta_K)|), their minimum and the four curves
    (boundary, legs A, B, C) as (alpha_y, alpha_z) rows with their counts."""
    _k_linspace(-math.pi / 2, math.pi / 2, ay)
    _k_linspace(-math.pi, math.pi, az)
    _k_linspace(-math.pi, math.pi, phi)
    q, aux, s = np.empty(12), np.empty(6), np.ones(3)
    for i in range(ay.shape[0]):
        for j in range(az.shape[0]):
            reachable[i, j] = _k_ik(ay[i], az[j], G, True, -1.0, s, q, aux) == OK
            cos_q2[0, i, j], cos_q2[1, i, j], cos_q2[2, i, j] = aux[0], aux[1], aux[2]
    m = phi.shape[0]
    for i in range(m):
        t = math.pi
        for K in range(3):
            ratio = ch / abs(np.sin(phi[i] - eta[K]))
            v = 2.0 * np.arcsin(min(ratio, 1.0)) if ratio <= 1.0 else np.nan
            theta_k[K, i] = v
            if v < t:  # noqa: PLR1730 (NaN: keeps t, as np.nanmin)
                t = v
        tilt_max[i] = t
    bound = np.empty(m)
    for i in range(m):
        bound[i] = tilt_max[i] if tilt_max[i] < math.pi else np.nan
    counts[0] = _k_tilt_curve(bound, phi, curves[0])
    for K in range(3):
        counts[K + 1] = _k_tilt_curve(theta_k[K], phi, curves[K + 1])


@dataclass(frozen=True)
class Workspace:
    """The reachable set of (alpha_y, alpha_z) for a given geometry (see :func:`workspace`).

    Attributes:
        alpha_y, alpha_z: 1-D grids (rad); fields below are indexed ``[i_y, i_z]``.
        cos_q2: (3, ny, nz) cos q_K2 per leg (eq 98); the leg reaches the pose where |cos q_K2| < 1.
        reachable: (ny, nz) True where :func:`ik` succeeds (home mode): all legs reach, not singular, and not
            an actuation singularity (:data:`DET_GUARD`).
        boundary: (m, 2) the workspace boundary (alpha_y, alpha_z), where some leg has sin q_K2 = 0
            (a singular curve); NaN rows separate pieces.
        leg_singular: {leg: (m, 2)} the whole curve sin q_K2 = 0 of each leg (NaN-separated pieces).
        platform_singular: (k, 2) points of 1 + c_y c_z = 0 in the grid's range.
        tilt_max: (m,) largest tilt theta (rad) reachable in each direction phi of ``phi``.
        phi: (m,) directions of the tilt (R e_x = (cos theta, sin theta cos phi, sin theta sin phi)).
    """

    alpha_y: np.ndarray
    alpha_z: np.ndarray
    cos_q2: np.ndarray
    reachable: np.ndarray
    boundary: np.ndarray
    leg_singular: dict
    platform_singular: np.ndarray
    tilt_max: np.ndarray
    phi: np.ndarray


def workspace(*, geometry: Geometry | None = None, n: int = 181, m: int = 721) -> Workspace:
    """Reachable orientations and singular curves, for plots.

    In terms of the tilt theta (angle between the base axis x and the platform axis R e_x) and its
    direction phi, eq (98) with :func:`platform_position` reads
    ``cos q_K2 = -sin(theta/2) sin(phi - eta_K) / cos(alpha/2)``. Leg K reaches the pose iff
    ``sin(theta/2) |sin(phi - eta_K)| < cos(alpha/2)``; its singular curve sin q_K2 = 0 is
    ``theta_K(phi) = 2 asin(cos(alpha/2) / |sin(phi - eta_K)|)`` (where that is <= 1), and the workspace is
    ``theta < min_K theta_K(phi)`` (star-shaped about home), bounded by those curves. The platform singularity
    1 + c_y c_z = 0 is theta = pi. The grid covers alpha_y in [-pi/2, pi/2], alpha_z in [-pi, pi].

    Args:
        geometry: the tripod's :class:`Geometry` (None: the default).
        n: grid size per axis, an integer in [2, 1001]. m: samples of phi along the curves, an integer in
            [2, 100001].

    Returns:
        a :class:`Workspace` (angles in rad).
    """
    g = geometry_of(geometry)
    if type(n) is not int or not 2 <= n <= 1001:
        n = check_integer(n, "n", 2, 1001)
    if type(m) is not int or not 2 <= m <= 100001:
        m = check_integer(m, "m", 2, 100001)
    ay, az, phi, tilt_max = np.empty(n), np.empty(n), np.empty(m), np.empty(m)
    cos_q2, reachable = np.empty((3, n, n)), np.empty((n, n), dtype=np.bool_)
    theta_k, curves, counts = np.empty((3, m)), np.empty((4, 2 * m, 2)), np.empty(4, dtype=np.int64)
    _k_workspace(g._vector, np.asarray(g.eta, dtype=np.float64), math.cos(g.alpha / 2.0), ay, az, cos_q2, reachable,
                 phi, theta_k, tilt_max, curves, counts)
    return Workspace(
        alpha_y=ay,
        alpha_z=az,
        cos_q2=cos_q2,
        reachable=reachable,
        boundary=curves[0, : counts[0]],
        leg_singular={leg: curves[k + 1, : counts[k + 1]] for k, leg in enumerate(LEGS)},
        platform_singular=np.array([[0.0, -np.pi], [0.0, np.pi]]),
        tilt_max=tilt_max,
        phi=phi,
    )
