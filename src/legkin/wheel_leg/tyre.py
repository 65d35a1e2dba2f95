"""The tyre surface of the leg-wheel in the leg plane (issue 12): the pitch curve of the four rim links swept by
a disk of radius ``r`` (the tyre thickness), as one closed, continuous curve of 16 circular pieces.

The pitch curve is the chain of the four rim arcs of radius R (the pitch radius) from the tip H_L to the tip
H_R: upper rim L about U_L (H_L -> F_L, 130 deg), lower rim L about L_L (F_L -> G, 50 deg), lower rim R about
L_R (G -> F_R), upper rim R about U_R (F_R -> H_R); counter-clockwise in {L} (the order of ``rim_point``'s
alpha). Its offset at distance ``r`` is closed into one curve:

* outer side (radius R + r about U, L), inner side (radius R - r, traversed back);
* at each hinge X = F_L, G, F_R the outer normals of the two arcs turn by ``delta = arg(n_2 / n_1)``.
  delta > 0 (measured: G for every theta > theta0): the outer offsets part, joined by a *fillet* of radius r
  about X (span delta), while the inner offsets overlap and are *trimmed* at their intersection (a zero-length
  corner piece). delta < 0 (measured: F_L, F_R): the outer offsets overlap and are trimmed, the inner side gets
  the fillet. |delta| <= 1e-9 rad (wheel mode): a fillet on both sides. Where the overlapping offsets do not
  meet inside both arcs (the inner lower rims at G for theta > ~110 deg: the inner circles about L_L and L_R
  no longer intersect), the two ends are joined by the arc of radius r about X the short way instead
  (span -delta: it runs inside the swept region);
* at the tips H_R, H_L a half circle of radius r about the tip (the *caps*) joins the outer and inner sides.

Every point of the curve is at distance r from the pitch curve, and the curve contains the boundary of the swept
region, so its lowest point along a direction is the swept region's (:mod:`.ground`). Where the caps of an
almost closed wheel overlap (theta near theta0), they run inside the region: they are not trimmed.

The contact parameter ``s`` in [0, 1] is the normalised arc length along the closed curve, 0 (= 1) at the outer
side of the tip H_L, increasing counter-clockwise along the outer side (:data:`PIECES` order). It is continuous
and non-decreasing; zero-length pieces (trimmed corners, the fillets in wheel mode) occupy no interval of s.

Each piece ``k`` is ``centre_k + radius_k exp(i (start_k + u span_k))``, u in [0, 1] (:func:`tyre_pieces`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, check_number
from .._kernels import as_rows, batch_kernel, kernel
from .._rotations import wrap_k
from ..errors import InvalidInputError
from ._common import _SCALARS, _check_theta
from .geometry import _DEFAULT_GEOMETRY, THETA_MAX, THETA_MIN, TYRE_THICKNESS, Geometry, _geometry
from .linkage import _IF, _IG, _IH, _IL, _IU, _k_closed, _kconst

__all__ = ["TYRE_THICKNESS", "PIECES", "PIECE_LINKS", "TyrePieces", "tyre_pieces", "tyre_point", "tyre_length"]

#: The 16 pieces of the closed tyre curve in the order of s. ``X`` = the piece at hinge X (a fillet of radius r
#: about X, or a trimmed corner of zero length, see the module docstring); ``cap_H`` = half circles about the tips.
PIECES = (
    "upper_L", "F_L", "lower_L", "G", "lower_R", "F_R", "upper_R", "cap_H_R",
    "upper_R_inner", "F_R_inner", "lower_R_inner", "G_inner", "lower_L_inner", "F_L_inner", "upper_L_inner",
    "cap_H_L",
)  # fmt: skip
_NP = 16
#: Rim links (0 rim_upper_L, 1 rim_lower_L, 2 rim_lower_R, 3 rim_upper_R) carrying the first half (u < 1/2) and
#: the second half of each piece: an arc is carried by its link; a fillet about a hinge by the link of the arc it
#: adjoins; a cap about a tip by its upper rim.
_LINK_A = np.array([0, 0, 1, 1, 2, 2, 3, 3, 3, 3, 2, 2, 1, 1, 0, 0], dtype=np.int64)
_LINK_B = np.array([0, 1, 1, 2, 2, 3, 3, 3, 3, 2, 2, 1, 1, 0, 0, 0], dtype=np.int64)
#: The URDF link names of the indices of :data:`_LINK_A` (``<leg>_`` prefix omitted).
LINK_NAMES = ("rim_upper_L", "rim_lower_L", "rim_lower_R", "rim_upper_R")
#: (first-half link, second-half link) of each piece, by name.
PIECE_LINKS = {p: (LINK_NAMES[a], LINK_NAMES[b]) for p, a, b in zip(PIECES, _LINK_A, _LINK_B)}
#: |delta| below this (rad) counts as a smooth joint (wheel mode): fillets of (almost) zero span on both sides.
_FLAT = 1e-9


@kernel(inline=True)
def _k_wrap_pos(a):
    """An angle wrapped to [0, 2 pi)."""
    return a % (2.0 * math.pi)


@kernel(inline=True)
def _k_meet(c1, c2, rho, X):
    """The intersection of the circles (c1, rho) and (c2, rho) on the side of X of the line c1 c2 (X lies on
    their perpendicular bisector: |X - c1| = |X - c2| = R) and whether they meet."""
    m = 0.5 * (c1 + c2)
    dv = c2 - c1
    D = abs(dv)
    h2 = rho * rho - 0.25 * D * D
    if not (D > 0.0 and h2 > 0.0):
        return m, False
    perp = 1j * dv / D
    h = math.sqrt(h2)
    side = ((X - m).conjugate() * perp).real
    return m + (h if side >= 0.0 else -h) * perp, True


@kernel(inline=True)
def _k_trim(c1, c2, rho, X, a1_lo, a1_hi, a2_lo, a2_hi):
    """Trim the end (angle ``a1_hi``) of the arc (c1, rho) over [a1_lo, a1_hi] and the start (``a2_lo``) of the
    arc (c2, rho) over [a2_lo, a2_hi] at their intersection near X: (ok, P, new a1_hi, new a2_lo). ``ok`` is
    False when the circles do not meet or the intersection lies outside either arc (then no trim)."""
    P, met = _k_meet(c1, c2, rho, X)
    if not met:
        return False, P, a1_hi, a2_lo
    b1 = a1_hi + wrap_k(math.atan2((P - c1).imag, (P - c1).real) - a1_hi)
    b2 = a2_lo + wrap_k(math.atan2((P - c2).imag, (P - c2).real) - a2_lo)
    if b1 < a1_lo or b1 > a1_hi or b2 < a2_lo or b2 > a2_hi:
        return False, P, a1_hi, a2_lo
    return True, P, b1, b2


@kernel
def _k_pieces(theta, r, K, KC, C, RAD, A0, SPAN):
    """The 16 pieces of the tyre curve at ``theta`` (before the beta rotation: left-half points of the closed
    form, right half = conjugates) into C (16,) complex centres, RAD, A0 (start angle), SPAN (signed)."""
    pts, _der = _k_closed(theta, K, KC, False)
    R = K[0]
    UL, LL, FL, G, HL = pts[_IU], pts[_IL], pts[_IF], pts[_IG], pts[_IH]
    UR, LR, FR, HR = UL.conjugate(), LL.conjugate(), FL.conjugate(), HL.conjugate()
    cen = (UL, LL, LR, UR)
    beg = (HL, FL, G, FR)
    end = (FL, G, FR, HR)
    hin = (FL, G, FR)
    a_s = np.empty(4)
    a_e = np.empty(4)
    for k in range(4):
        a_s[k] = math.atan2((beg[k] - cen[k]).imag, (beg[k] - cen[k]).real)
        ae = math.atan2((end[k] - cen[k]).imag, (end[k] - cen[k]).real)
        a_e[k] = a_s[k] + _k_wrap_pos(ae - a_s[k])
    o_s, o_e, i_s, i_e = a_s.copy(), a_e.copy(), a_s.copy(), a_e.copy()
    h_oc = np.empty(3, dtype=np.complex128)
    h_o0, h_osp, h_or = np.empty(3), np.empty(3), np.full(3, r)
    h_ic = np.empty(3, dtype=np.complex128)
    h_i0, h_isp, h_ir = np.empty(3), np.empty(3), np.full(3, r)
    ro, ri = R + r, R - r
    for j in range(3):
        X, c1, c2 = hin[j], cen[j], cen[j + 1]
        e1, n2 = a_e[j], a_s[j + 1]
        dlt = wrap_k(n2 - e1)
        h_oc[j] = X
        h_ic[j] = X
        # the side where the offsets part: a fillet about X (from the normal of arc j to that of arc j + 1);
        # the side where they overlap: trimmed at their intersection (a corner piece of zero length), or, where
        # they do not meet inside both arcs, joined by the arc about X the short way (inside the swept region)
        ok = False
        if dlt < -_FLAT:
            ok, P, o_e[j], o_s[j + 1] = _k_trim(c1, c2, ro, X, o_s[j], o_e[j], o_s[j + 1], o_e[j + 1])
        if ok:
            h_oc[j], h_o0[j], h_osp[j], h_or[j] = P, 0.0, 0.0, 0.0  # the corner: a point
        else:
            h_o0[j], h_osp[j] = e1, dlt
        ok = False
        if dlt > _FLAT:
            ok, P, i_e[j], i_s[j + 1] = _k_trim(c1, c2, ri, X, i_s[j], i_e[j], i_s[j + 1], i_e[j + 1])
        if ok:
            h_ic[j], h_i0[j], h_isp[j], h_ir[j] = P, 0.0, 0.0, 0.0
        else:  # traversed from arc j + 1 back to arc j
            h_i0[j], h_isp[j] = n2 + math.pi, -dlt
    for k in range(4):  # outer arcs: pieces 0, 2, 4, 6; inner arcs (reversed): 14, 12, 10, 8
        C[2 * k], RAD[2 * k], A0[2 * k], SPAN[2 * k] = cen[k], ro, o_s[k], o_e[k] - o_s[k]
        p = 14 - 2 * k
        C[p], RAD[p], A0[p], SPAN[p] = cen[k], ri, i_e[k], i_s[k] - i_e[k]
    for j in range(3):  # outer hinges 1, 3, 5; inner hinges 13, 11, 9
        C[2 * j + 1], RAD[2 * j + 1], A0[2 * j + 1], SPAN[2 * j + 1] = h_oc[j], h_or[j], h_o0[j], h_osp[j]
        p = 13 - 2 * j
        C[p], RAD[p], A0[p], SPAN[p] = h_ic[j], h_ir[j], h_i0[j], h_isp[j]
    C[7], RAD[7], A0[7], SPAN[7] = HR, r, a_e[3], math.pi
    C[15], RAD[15], A0[15], SPAN[15] = HL, r, a_s[0] + math.pi, math.pi


@kernel
def _k_cumulative(RAD, SPAN, CUM):
    """Cumulative arc lengths CUM (17,) of the pieces (CUM[16] = the total length)."""
    CUM[0] = 0.0
    for p in range(_NP):
        CUM[p + 1] = CUM[p] + RAD[p] * abs(SPAN[p])


@kernel(inline=True)
def _k_locate(s, CUM):
    """(piece, u) of the normalised arc length s in [0, 1]: the first piece of positive length holding it."""
    ell = s * CUM[_NP]
    for p in range(_NP):
        lp = CUM[p + 1] - CUM[p]
        if lp > 0.0 and ell <= CUM[p + 1]:
            u = (ell - CUM[p]) / lp
            return p, (0.0 if u < 0.0 else (1.0 if u > 1.0 else u))
    return _NP - 1, 1.0


@kernel(inline=True)
def _k_tyre_point_at(C, RAD, A0, SPAN, CUM, beta, s, w, out):
    """The point of contact parameter s on the pieces (C, RAD, A0, SPAN, CUM) of one theta, turned by beta, into
    out (3,)."""
    p, u = _k_locate(s, CUM)
    ang = A0[p] + u * SPAN[p]
    z = C[p] + RAD[p] * complex(math.cos(ang), math.sin(ang))
    z = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2)) * z
    out[0], out[1], out[2] = z.real, z.imag, w


@kernel(entry=True, inline=True)
def _k_tyre_point(theta, beta, s, w, r, K, KC, out):
    """:func:`tyre_point` for one item into out (3,)."""
    C = np.empty(_NP, dtype=np.complex128)
    RAD, A0, SPAN, CUM = np.empty(_NP), np.empty(_NP), np.empty(_NP), np.empty(_NP + 1)
    _k_pieces(theta, r, K, KC, C, RAD, A0, SPAN)
    _k_cumulative(RAD, SPAN, CUM)
    _k_tyre_point_at(C, RAD, A0, SPAN, CUM, beta, s, w, out)


@batch_kernel(rows="theta beta s w out", min_parallel=256)
def _k_tyre_point_batch(theta, beta, s, w, r, K, KC, out):
    """:func:`_k_tyre_point` per item, the pieces computed once per run of equal theta (the points of one
    configuration's curve: the same arithmetic, so the same bits, as item by item)."""
    C = np.empty(_NP, dtype=np.complex128)
    RAD, A0, SPAN, CUM = np.empty(_NP), np.empty(_NP), np.empty(_NP), np.empty(_NP + 1)
    last = math.nan
    for i in range(theta.shape[0]):
        if not theta[i] == last:
            _k_pieces(theta[i], r, K, KC, C, RAD, A0, SPAN)
            _k_cumulative(RAD, SPAN, CUM)
            last = theta[i]
        _k_tyre_point_at(C, RAD, A0, SPAN, CUM, beta[i], s[i], w[i], out[i])


@kernel(entry=True, inline=True)
def _k_tyre_pieces(theta, beta, r, K, KC, centre, radius, start, span, s_start, s_end):
    """:func:`tyre_pieces` for one item: the pieces at (theta, beta) in {L} into centre (16, 2), radius, start,
    span, s_start, s_end (16,); returns the curve's length."""
    C = np.empty(_NP, dtype=np.complex128)
    A0, CUM = np.empty(_NP), np.empty(_NP + 1)
    _k_pieces(theta, r, K, KC, C, radius, A0, span)
    _k_cumulative(radius, span, CUM)
    rot = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2))
    total = CUM[_NP]
    for p in range(_NP):
        z = C[p] * rot
        centre[p, 0], centre[p, 1] = z.real, z.imag
        start[p] = A0[p] + beta + math.pi / 2
        s_start[p], s_end[p] = CUM[p] / total, CUM[p + 1] / total
    return total


@batch_kernel(rows="theta beta centre radius start span s_start s_end length", min_parallel=256)
def _k_tyre_pieces_batch(theta, beta, r, K, KC, centre, radius, start, span, s_start, s_end, length):
    for i in range(theta.shape[0]):
        length[i] = _k_tyre_pieces(theta[i], beta[i], r, K, KC, centre[i], radius[i], start[i], span[i],
                                   s_start[i], s_end[i])


def _thickness(r: object, geo: Geometry) -> float:
    """The tyre thickness checked: a number in (0, R) (the inner offset R - r must stay positive)."""
    if type(r) is float and 0.0 < r < geo.R:  # the common case, fast
        return r
    return check_number(r, "r", 0.0, geo.R, low_open=True, high_open=True)


@dataclass(frozen=True)
class TyrePieces:
    """The piece decomposition of the tyre curve (:func:`tyre_pieces`), in the order of :data:`PIECES`.

    Attributes:
        names: :data:`PIECES`.
        centre: (..., 16, 2) centres (x, y) in {L}.
        radius: (..., 16) radii (R + r outer arcs, R - r inner arcs, r fillets and caps).
        start: (..., 16) angle (rad, in {L}) of each piece's first point about its centre.
        span: (..., 16) signed angle swept (counter-clockwise > 0); 0 for a trimmed corner.
        s_start, s_end: (..., 16) the contact parameter s at both ends (normalised arc length).
        length: (...) total length of the closed curve (m).
    """

    names: tuple[str, ...]
    centre: np.ndarray
    radius: np.ndarray
    start: np.ndarray
    span: np.ndarray
    s_start: np.ndarray
    s_end: np.ndarray
    length: np.ndarray

    def point(self, k: int, u: ArrayLike) -> np.ndarray:
        """Point of piece ``k`` at the fraction ``u`` of its arc.

        Args:
            k: the piece's index (0 to 15, in arc-length order).
            u: fraction(s) of the piece's arc in [0, 1] (unitless), broadcast with the pieces' batch shape.

        Returns:
            The points (..., 2) in the leg frame (m).
        """
        ang = self.start[..., k] + np.asarray(u, dtype=float) * self.span[..., k]
        return self.centre[..., k, :] + self.radius[..., k, None] * np.stack([np.cos(ang), np.sin(ang)], -1)


def _pieces_one(theta, beta, rho, K, KC):
    """:func:`tyre_pieces` of two numbers in range (the kernel directly), else None (the full checks)."""
    if not (type(theta) in _SCALARS and type(beta) in _SCALARS and THETA_MIN - 1e-12 <= theta <= THETA_MAX + 1e-12
            and math.isfinite(beta)):
        return None
    centre, (radius, start, span, s_start, s_end) = np.empty((_NP, 2)), np.empty((5, _NP))
    length = _k_tyre_pieces(float(theta), float(beta), rho, K, KC, centre, radius, start, span, s_start, s_end)
    return TyrePieces(PIECES, centre, radius, start, span, s_start, s_end, np.array(length))


def _point_one(theta, beta, s, w, geo, rho, K, KC):
    """:func:`tyre_point` of four numbers in range (the kernel directly), else None (the full checks)."""
    if (type(theta) in _SCALARS and type(beta) in _SCALARS and type(s) in _SCALARS and type(w) in _SCALARS
            and THETA_MIN - 1e-12 <= theta <= THETA_MAX + 1e-12 and math.isfinite(beta) and 0.0 <= s <= 1.0
            and abs(w) <= geo.T / 2 + 1e-15):
        point = np.empty(3)
        _k_tyre_point(float(theta), float(beta), float(s), float(w), rho, K, KC, point)
        return point
    return None


def tyre_pieces(theta: ArrayLike, beta: ArrayLike = 0.0, *, r: float = TYRE_THICKNESS,
                geometry: Geometry | None = None) -> TyrePieces:
    """The 16 circular pieces of the closed tyre curve at (theta, beta), in the order of s (module docstring).

    Args:
        theta: leg opening (rad) in [17 deg, 160 deg]; beta: leg rotation (rad); broadcast together.
        r: tyre thickness (m) in (0, R).
        geometry: robot parameters.

    Returns:
        a :class:`TyrePieces` (lengths in m, angles in rad).

    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rho = _thickness(r, geo)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    one = _pieces_one(theta, beta, rho, K, KC)
    if one is not None:
        return one
    theta, beta = as_angles(theta, beta, names=("theta", "beta"))
    _check_theta(theta)
    shape, t, b = theta.shape, as_rows(theta, 1)[:, 0], as_rows(beta, 1)[:, 0]
    n = t.shape[0]
    centre, length, (radius, start, span, s_start, s_end) = np.empty((n, _NP, 2)), np.empty(n), np.empty((5, n, _NP))
    _k_tyre_pieces_batch(t, b, rho, K, KC, centre, radius, start, span, s_start, s_end, length)
    core = shape + (_NP,)
    return TyrePieces(PIECES, centre.reshape(core + (2,)), radius.reshape(core), start.reshape(core),
                      span.reshape(core), s_start.reshape(core), s_end.reshape(core), length.reshape(shape))


def tyre_length(theta: ArrayLike, *, r: float = TYRE_THICKNESS, geometry: Geometry | None = None) -> np.ndarray:
    """Length (m) of the closed tyre curve (the scale of the contact parameter s).

    Args:
        theta: (...) leg angle(s) (rad).
        r: tyre thickness (m).
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (...) the length of the tyre's outline (m).
    """
    return tyre_pieces(theta, 0.0, r=r, geometry=geometry).length


def tyre_point(theta: ArrayLike, beta: ArrayLike, s: ArrayLike, w: ArrayLike = 0.0, *, r: float = TYRE_THICKNESS,
               geometry: Geometry | None = None) -> np.ndarray:
    """Point of the tyre surface of contact parameter ``s`` (normalised arc length, module docstring) in {L}.

    Args:
        theta, beta: leg angles (rad), theta in [17 deg, 160 deg]; s in [0, 1]; w: lateral coordinate (m) in
            [-T/2, T/2]; broadcast together.
        r: tyre thickness (m) in (0, R); geometry: robot parameters.

    Returns:
        (..., 3): (x, y, w) in {L} (s = 0 and s = 1 are the same point: the curve is closed).

    Raises:
        InvalidInputError: NaN/inf/complex/unbroadcastable inputs, theta, s or w out of range.
        InvalidParameterError: r out of range, geometry not a Geometry.
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rho = _thickness(r, geo)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    point = _point_one(theta, beta, s, w, geo, rho, K, KC)
    if point is not None:
        return point
    theta, beta, s, w = as_angles(theta, beta, s, w, names=("theta", "beta", "s", "w"))
    _check_theta(theta)
    if np.any((s < 0.0) | (s > 1.0)):
        raise InvalidInputError(f"s={float(s[(s < 0) | (s > 1)].ravel()[0])!r} is out of range: must be in [0, 1]")
    if np.any(np.abs(w) > geo.T / 2 + 1e-15):
        raise InvalidInputError(f"w is out of range: must be in [-T/2, T/2] = [{-geo.T / 2:g}, {geo.T / 2:g}]")
    shape = theta.shape
    rows = [as_rows(x, 1)[:, 0] for x in (theta, beta, s, w)]
    out = np.empty((rows[0].shape[0], 3))
    if shape == ():
        _k_tyre_point(rows[0][0], rows[1][0], rows[2][0], rows[3][0], rho, K, KC, out[0])
        return out[0]
    _k_tyre_point_batch(*rows, rho, K, KC, out)
    return out.reshape(shape + (3,))
