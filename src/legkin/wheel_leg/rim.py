"""Rim contact points in the leg frame: the continuous four-arc rim and the seed's three-arc formula (seed 1.1)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, as_input, check_number
from .._kernels import as_rows, batch_kernel, kernel
from ._common import _SCALARS, _check_alpha, _check_theta, _check_w
from .geometry import _ARC_FG, _DEFAULT_GEOMETRY, PSI_FG, THETA_MAX, THETA_MIN, TYRE_THICKNESS, Geometry, _geometry
from .linkage import _IF, _IG, _IJ, _IL, _IOR, _IU, _k_closed, _kconst


# ---------------------------------------------------------------- rim contact points
def rim_segment(alpha: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
    """Index (0-3) of the rim link that carries the contact point of parameter ``alpha`` in :func:`rim_point`.

    0: upper rim left (alpha < -50 deg), 1: lower rim left (-50 deg <= alpha < 0), 2: lower rim right
    (0 <= alpha <= 50 deg), 3: upper rim right (alpha > 50 deg). Independent of the geometry (``geometry`` is
    checked, for a uniform signature).

    Args:
        alpha: (...) rim parameter(s) (rad) in [-pi, pi].
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (...) the segment index of each alpha (an integer array).
    """
    if geometry is not None:
        _geometry(geometry)
    if type(alpha) is float and math.isfinite(alpha):
        return np.asarray(_k_segment(alpha))
    a = as_input(alpha, "alpha")
    out = np.empty(a.size, dtype=np.int64)
    _k_segment_batch(as_rows(a, 1)[:, 0], out)
    return out.reshape(a.shape)


@kernel(entry=True, inline=True)
def _k_segment(alpha):
    """:func:`rim_segment` for one alpha."""
    if alpha < -_ARC_FG:
        return 0
    if alpha < 0.0:
        return 1
    return 2 if alpha <= _ARC_FG else 3


@batch_kernel(rows="alpha out", min_parallel=32768)
def _k_segment_batch(alpha, out):
    """:func:`_k_segment` over alpha (n,) into out (n,)."""
    for i in range(alpha.shape[0]):
        out[i] = _k_segment(alpha[i])


class _Sel(NamedTuple):
    """Per-item choice of rim arc for fixed alpha: the arc is ``y = ctr + e (ref - ctr)`` (continuous rim) or
    ``y = ctr + e (ref - ctr) / |ref - ctr|`` (seed rim) on left-half points, conjugated on the right half.

    ``upper``: the arc's (ctr, ref) are (U, F) (continuous) / (U, J) (seed), else (L, G) / (O_r, G).
    ``right``: right half: the point is ``conj(y)``, and ``e`` is stored conjugated so that
    ``conj(y) = conj(ctr) + e_true conj(ref - ctr)`` (the formula of :func:`rim_point` on right-half points).
    """

    seed: bool
    upper: np.ndarray
    right: np.ndarray
    e: np.ndarray

    def take(self, idx) -> "_Sel":
        return _Sel(self.seed, self.upper[idx], self.right[idx], self.e[idx])


@kernel(entry=True)
def _k_select(alpha, seed, rho, R):
    """:func:`_select` for one alpha: (upper, right, e) (``e`` conjugated on the right half)."""
    if seed:
        if alpha > PSI_FG:
            upper, right, a0 = True, True, PSI_FG
        elif alpha < -PSI_FG:
            upper, right, a0 = True, False, -PSI_FG
        else:
            upper, right, a0 = False, False, 0.0
        k = rho
    else:
        if alpha < -_ARC_FG:
            upper, right, a0 = True, False, -_ARC_FG
        elif alpha < 0.0:
            upper, right, a0 = False, False, 0.0
        elif alpha <= _ARC_FG:
            upper, right, a0 = False, True, 0.0
        else:
            upper, right, a0 = True, True, _ARC_FG
        k = rho / R
    e = complex(math.cos(alpha - a0) * k, math.sin(alpha - a0) * k)
    return upper, right, (e.conjugate() if right else e)


@kernel
def _k_plane(theta, upper, right, e, seed, K, KC, want_der, conj):
    """:func:`_plane` for one item: the contact point in the leg plane (before the beta rotation) and its
    theta-derivative, ``y = ctr + e v`` (seed rim: ``ctr + e v / |v|``), ``v = ref - ctr``."""
    pts, der = _k_closed(theta, K, KC, want_der)
    if upper:
        ic, ir = _IU, (_IJ if seed else _IF)
    else:
        ic, ir = (_IOR if seed else _IL), _IG
    ctr = pts[ic]
    v = pts[ir] - ctr
    dc = der[ic]
    dv = der[ir] - dc
    if seed:
        nv = abs(v)
        y = ctr + e * v / nv
        dnv = (v.conjugate() * dv).real / nv
        dy = dc + e * (dv - v * dnv / nv) / nv
    else:
        y = ctr + e * v
        dy = dc + e * dv
    if conj and right:
        return y.conjugate(), dy.conjugate()
    return y, dy


@batch_kernel(rows="alpha upper right e", min_parallel=32768)
def _k_select_batch(alpha, seed, rho, R, upper, right, e):
    """:func:`_k_select` over alpha (n,) into upper, right, e (n,)."""
    for i in range(alpha.shape[0]):
        upper[i], right[i], e[i] = _k_select(alpha[i], seed, rho, R)


def _select(alpha: np.ndarray, seed: bool, radius: float, R: float) -> _Sel:
    """The arc of every alpha (the four links of :func:`rim_point`; seed 1.1's three arcs): the batch of
    :func:`_k_select`."""
    alpha = np.asarray(alpha, dtype=np.float64)
    flat = as_rows(alpha, 1)[:, 0]
    n = flat.shape[0]
    upper, right, e = np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.complex128)
    _k_select_batch(flat, bool(seed), float(radius), float(R), upper, right, e)
    return _Sel(seed, upper.reshape(alpha.shape), right.reshape(alpha.shape), e.reshape(alpha.shape))


@kernel(entry=True, inline=True)
def _k_rim(theta, beta, alpha, w, seed, rho, K, KC, out):
    """:func:`rim_point` (``seed=False``) / :func:`rim_point_seed` for one item into ``out`` (3,): the arc of
    :func:`_k_select`, the point of :func:`_k_plane`, rotated by ``exp(i (beta + pi/2))``."""
    upper, right, e = _k_select(alpha, seed, rho, K[0])
    z, _dz = _k_plane(theta, upper, right, e, seed, K, KC, False, True)
    z = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2)) * z
    out[0], out[1], out[2] = z.real, z.imag, w


@batch_kernel(rows="theta beta alpha w out", min_parallel=32768)
def _k_rim_batch(theta, beta, alpha, w, seed, rho, K, KC, out):
    """:func:`_k_rim` over theta, beta, alpha, w (n,) into out (n, 3)."""
    for i in range(theta.shape[0]):
        _k_rim(theta[i], beta[i], alpha[i], w[i], seed, rho, K, KC, out[i])


_PSI_NEXT = float(np.nextafter(PSI_FG, 4.0))


@kernel(entry=True)
def _k_jump(theta, rho, K, KC):
    """:func:`rim_jump_seed` for one theta: ``|z(psi_FG+) - z(psi_FG)|`` on the seed rim (beta = 0)."""
    rot = complex(math.cos(math.pi / 2), math.sin(math.pi / 2))
    u1, r1, e1 = _k_select(PSI_FG, True, rho, K[0])
    u2, r2, e2 = _k_select(_PSI_NEXT, True, rho, K[0])
    z1, _d = _k_plane(theta, u1, r1, e1, True, K, KC, False, True)
    z2, _d = _k_plane(theta, u2, r2, e2, True, K, KC, False, True)
    return abs(rot * z2 - rot * z1)


@batch_kernel(rows="theta out", min_parallel=32768)
def _k_jump_batch(theta, rho, K, KC, out):
    """:func:`_k_jump` over theta (n,) into out (n,)."""
    for i in range(theta.shape[0]):
        out[i] = _k_jump(theta[i], rho, K, KC)


def _rim_call(theta, beta, alpha, w, radius, geometry, seed):
    """The wrapper of :func:`rim_point` / :func:`rim_point_seed`: checks (fast path for four numbers), then
    the batch of :func:`_k_rim`."""
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    if radius is None:
        rho = geo.R + TYRE_THICKNESS if seed else geo.R
    else:
        rho = check_number(radius, "radius", 0.0, 2.0 * geo.R, low_open=True)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    scalars = type(theta) in _SCALARS and type(beta) in _SCALARS and type(alpha) in _SCALARS and type(w) in _SCALARS
    if (scalars
            and THETA_MIN - 1e-12 <= theta <= THETA_MAX + 1e-12 and math.isfinite(beta)
            and abs(alpha) <= math.pi + 1e-12 and abs(w) <= geo.T / 2 + 1e-15):
        out = np.empty(3)
        _k_rim(float(theta), float(beta), float(alpha), float(w), seed, rho, K, KC, out)
        return out
    theta, beta, alpha, w = _rim_inputs(theta, beta, alpha, w, geo)
    shape = theta.shape
    out = np.empty((int(np.prod(shape, dtype=int)), 3))
    _k_rim_batch(*(as_rows(x, 1)[:, 0] for x in (theta, beta, alpha, w)), seed, rho, K, KC, out)
    return out.reshape(shape + (3,))


def _rim_inputs(theta, beta, alpha, w, geo):
    theta, beta, alpha, w = as_angles(theta, beta, alpha, w, names=("theta", "beta", "alpha", "w"))
    _check_theta(theta)
    _check_alpha(alpha)
    _check_w(w, geo)
    return theta, beta, alpha, w


def rim_point(theta: ArrayLike, beta: ArrayLike, alpha: ArrayLike, w: ArrayLike = 0.0, *, radius: float | None = None,
              geometry: Geometry | None = None) -> np.ndarray:
    """Contact point on the real rims, continuous in alpha over the whole rim (leg frame, (x, y, w)).

    Departs from seed section 1.1 (see :func:`rim_point_seed`), whose three arcs leave the lower rims out.
    Here alpha walks the four rim links in order, each arc about its own centre::

        alpha in [-pi, -50 deg):  U_L + rho e^{i(alpha + 50 deg)} (F_L - U_L) / R     (upper rim, left)
        alpha in [-50 deg, 0):    L_L + rho e^{i alpha} (G - L_L) / R                  (lower rim, left)
        alpha in [0, 50 deg]:     L_R + rho e^{i alpha} (G - L_R) / R                  (lower rim, right)
        alpha in (50 deg, pi]:    U_R + rho e^{i(alpha - 50 deg)} (F_R - U_R) / R      (upper rim, right)

    (before the rotation ``exp(i (beta + pi/2))``), with ``rho = radius``. In wheel mode every arc is centred
    on O and alpha is the wheel angle measured from the toe. With ``rho = R`` (the pitch radius, the
    default: the "effective radius for kinematics" of the system parameters) the arcs meet exactly at the
    hinges F and G, so the point is continuous in alpha for every theta. With ``rho != R`` each point is
    still a fixed point of its rim link, but neighbouring arcs' offsets differ at F and G as soon as the
    leg opens (the tyre physically splits there). For a fixed alpha the point is fixed in one rim link
    (:func:`rim_segment`).

    Args:
        theta, beta: leg angles (rad); alpha in [-pi, pi] (rad); w in [-T/2, T/2] (m); broadcast together.
        radius: arc radius (default the pitch radius R).
        geometry: robot parameters.

    Returns:
        array (..., 3): (x, y, w) in {L}.
    """
    return _rim_call(theta, beta, alpha, w, radius, geometry, False)


def rim_point_seed(theta: ArrayLike, beta: ArrayLike, alpha: ArrayLike, w: ArrayLike = 0.0, *,
                   radius: float | None = None, geometry: Geometry | None = None) -> np.ndarray:
    """The seed's three-arc contact point (seed 001 section 1.1), exactly as printed, alpha in radians.

    ::

        alpha > psi_FG:           U_R + rho rot(alpha - psi_FG) (J_R - U_R) / |J_R - U_R|
        -psi_FG <= alpha <= psi:  O_r + rho rot(alpha) (G - O_r) / |G - O_r|
        alpha < -psi_FG:          U_L + rho rot(alpha + psi_FG) (J_L - U_L) / |J_L - U_L|

    with psi_FG = 40 deg, O_r = G + R on the axis, J = U + r e^{i(140 deg + arg(H - U))} and ``rho`` the
    foot radius R + 0.0345 m (the seed's "R" is the tyre radius, not the linkage R: default of ``radius``).
    The lab's code takes alpha in degrees and wraps it; here alpha is in radians, in [-pi, pi]. The formula
    leaves out the lower-rim arcs: it is discontinuous at alpha = +-psi_FG once theta > theta0
    (:func:`rim_jump_seed`), and the toe arc about O_r is not attached to any link.

    Args:
        theta, beta: leg angles (rad); alpha: rim parameter (rad) in [-pi, pi]; w: lateral
        coordinate (m); all broadcast together.
        radius: arc radius (m) (None: R + TYRE_THICKNESS, the seed's).
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (..., 3) points in the leg frame {L} (m).
    """
    return _rim_call(theta, beta, alpha, w, radius, geometry, True)


def rim_jump_seed(theta: ArrayLike, *, radius: float | None = None, geometry: Geometry | None = None) -> np.ndarray:
    """Size (m) of the jump of :func:`rim_point_seed` at alpha = +psi_FG (equal at -psi_FG by symmetry).

    The distance between the toe-arc point at alpha = psi_FG and the upper-rim point at alpha -> psi_FG+.

    Args:
        theta: (...) leg angle(s) (rad).
        radius: arc radius (m) (None: the seed's).
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (...) the jump of the three-arc formula (m).
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rho = geo.R + TYRE_THICKNESS if radius is None else check_number(radius, "radius", 0.0, 2.0 * geo.R, low_open=True)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    if type(theta) is float and THETA_MIN - 1e-12 <= theta <= THETA_MAX + 1e-12:
        return np.asarray(_k_jump(theta, rho, K, KC))
    theta = as_input(theta, "theta")
    _check_theta(theta)
    out = np.empty(theta.size)
    _k_jump_batch(as_rows(theta, 1)[:, 0], rho, K, KC, out)
    return out.reshape(theta.shape)

