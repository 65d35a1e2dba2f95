"""Where the leg-wheel touches flat ground (issue 12): the lowest point of the tyre surface (:mod:`.tyre`) along a
ground normal, its material-point Jacobian, and the stance IK that puts that point on a target.

The tyre in 3-D is the closed leg-plane curve of :mod:`.tyre` extruded over the width w in [-T/2, T/2] (T =
``geometry.T``) along z_L. For a ground normal n (robot frame, unit) the height of the tyre point (s, w) is
``<p(s), n_plane> + w n_z`` with n written in {L}: ``n_L = (R0 Rz(gamma) R_LM)^T n``, ``n_plane`` its leg-plane
part, ``n_z`` its lateral part. So:

* **w**: ``-sign(n_z) T/2`` (an edge of the tyre; with ABAD tilt gamma != 0 and n = z the lowest point is on the
  edge that tilts down); where ``|n_z| <= 1e-12`` the lowest set is a segment across the width and **w = 0** (its
  centre) is returned.
* **s**: the support point of the leg-plane curve toward ``-n_plane``: per piece (a circle of radius rho about
  c), ``c - rho n_plane/|n_plane|`` if that direction lies inside the piece's angle span, else the lower of its
  two ends; the minimum over the 16 pieces. A tie (the same height on two pieces, e.g. a shared end point)
  goes to the first piece in s order. The curve's points are all at distance r from the pitch curve and it
  contains the swept region's boundary, so this is the lowest point of the pitch curve moved by ``-r n``.
  Where ``|n_plane| <= 1e-12`` (the leg plane parallel to the ground) the whole side face is lowest: the point
  of that face toward the toe G is returned (the support point for ``n_plane = -G/|G|``).
* **stance IK**: :func:`~legkin.wheel_leg.stance.stance_ik` (module :mod:`.stance`, which builds on this one).
* **Jacobian**: the derivative d p / d(theta, beta, gamma) of the *material point*: the point of the rim link
  that carries the contact (:data:`.tyre.PIECE_LINKS`) fixed in that link at the solution, moved with the link.
  It is not the derivative of the (rolling) contact point itself; the two differ by the rolling of the
  contact along the tyre, which does not change the height: ``n . J`` is the derivative of the support height
  (envelope theorem, checked). The point and Jacobian are those of :func:`~legkin.wheel_leg.fk` on that link.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Literal, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input, check_flag
from .._kernels import OK, as_rows, batch_kernel, kernel
from ..errors import InvalidInputError
from ._common import Leg, _check_theta
from .frames import _R_0, _R_LM, _k_fk, _origin
from .geometry import _DEFAULT_GEOMETRY, THETA_MAX, THETA_MIN, TYRE_THICKNESS, Geometry, _geometry, _leg
from .linkage import _IF, _IG, _IL, _IU, _k_closed, _kconst
from .tyre import _LINK_A, _LINK_B, _NP, PIECES, _k_cumulative, _k_pieces, _thickness

__all__ = ["GroundContact", "ground_contact"]

_NONFINITE = 1
#: Below this a normal component counts as zero (lateral: the lowest set is a segment; in-plane: a face).
_ZERO = 1e-12


@dataclass(frozen=True)
class GroundContact:
    """The lowest tyre point along a ground normal (:func:`ground_contact`).

    Attributes:
        point: (..., 3) the point in the robot frame {R}.
        piece: (...) index into :data:`~legkin.wheel_leg.tyre.PIECES` of the tyre piece it lies on (-1: failed).
        s: (...) its contact parameter (normalised arc length of the tyre curve).
        w: (...) its lateral coordinate (-T/2, 0 or T/2).
        jacobian: (..., 3, 3) d point / d(theta, beta, gamma) of the material point (module docstring).
        link: (...) the rim link carrying the material point: index into :data:`~legkin.wheel_leg.tyre.LINK_NAMES`
            (0 rim_upper_L, 1 rim_lower_L, 2 rim_lower_R, 3 rim_upper_R; -1: failed).
    """

    point: np.ndarray
    piece: np.ndarray
    s: np.ndarray
    w: np.ndarray
    jacobian: np.ndarray
    link: np.ndarray

    @property
    def piece_name(self) -> np.ndarray:
        """The names of :attr:`piece` (``""`` where it failed)."""
        names = np.array(PIECES + ("",))
        return names[np.where(self.piece < 0, len(PIECES), self.piece)]


@kernel
def _k_normal_leg(gamma, n, RLM, R0):
    """The unit normal n (robot frame) in {L}: ``(R0 Rz(gamma) R_LM)^T n``."""
    v0 = R0[0, 0] * n[0] + R0[1, 0] * n[1] + R0[2, 0] * n[2]
    v1 = R0[0, 1] * n[0] + R0[1, 1] * n[1] + R0[2, 1] * n[2]
    v2 = R0[0, 2] * n[0] + R0[1, 2] * n[1] + R0[2, 2] * n[2]
    cg, sg = math.cos(gamma), math.sin(gamma)
    u0, u1, u2 = cg * v0 + sg * v1, -sg * v0 + cg * v1, v2
    return (RLM[0, 0] * u0 + RLM[1, 0] * u1 + RLM[2, 0] * u2, RLM[0, 1] * u0 + RLM[1, 1] * u1 + RLM[2, 1] * u2,
            RLM[0, 2] * u0 + RLM[1, 2] * u1 + RLM[2, 2] * u2)


@kernel
def _k_support(C, RAD, A0, SPAN, d):
    """The lowest point of the tyre curve along the unit direction ``d`` (pre-rotation plane): (piece, u, Y).

    Per piece the minimum of ``Re(conj(p) d)`` over the arc: at ``c - rho d`` if the angle of ``-d`` is inside
    the span, else at the lower end (u = 0 on a tie); the first piece wins a tie."""
    psi = math.atan2(-d.imag, -d.real)
    ad = math.atan2(d.imag, d.real)
    best, bp, bu = math.inf, -1, 0.0
    for p in range(_NP):
        c, rho, a0, sp = C[p], RAD[p], A0[p], SPAN[p]
        base = (c.conjugate() * d).real
        spa = abs(sp)
        rel = ((psi - a0) if sp > 0.0 else (a0 - psi)) % (2.0 * math.pi)
        if spa > 0.0 and rho > 0.0 and rel <= spa:
            h, u = base - rho, rel / spa
        else:
            h0 = base + rho * math.cos(a0 - ad)
            h1 = base + rho * math.cos(a0 + sp - ad)
            h, u = (h0, 0.0) if h0 <= h1 else (h1, 1.0)
        if h < best:
            best, bp, bu = h, p, u
    c, rho = C[bp], RAD[bp]
    if 0.0 < bu < 1.0:
        Y = c - rho * d
    else:
        ang = A0[bp] + bu * SPAN[bp]
        Y = c + rho * complex(math.cos(ang), math.sin(ang))
    return bp, bu, Y


@kernel(entry=True)
def _k_ground(q, n, r, K, KC, sl, dwheel, halfT, o0, o1, o2, RLM, R0, p, J, info, want_jac):
    """:func:`ground_contact` for one item: point p (3,), Jacobian J (9,) (when ``want_jac``), info (4,) =
    (piece, s, w, link)."""
    theta, beta, gamma = q[0], q[1], q[2]
    if not (math.isfinite(theta) and math.isfinite(beta) and math.isfinite(gamma)):
        return _NONFINITE
    nl0, nl1, nl2 = _k_normal_leg(gamma, n, RLM, R0)
    C = np.empty(_NP, dtype=np.complex128)
    RAD, A0, SPAN, CUM = np.empty(_NP), np.empty(_NP), np.empty(_NP), np.empty(_NP + 1)
    _k_pieces(theta, r, K, KC, C, RAD, A0, SPAN)
    _k_cumulative(RAD, SPAN, CUM)
    pts, _der = _k_closed(theta, K, KC, False)
    rot = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2))
    nz = complex(nl0, nl1)
    mag = abs(nz)
    if mag <= _ZERO:  # the leg plane is parallel to the ground: the face point toward the toe
        G = pts[_IG]
        d = -G / abs(G)
    else:
        d = rot.conjugate() * nz / mag
    bp, bu, Y = _k_support(C, RAD, A0, SPAN, d)
    w = -halfT if nl2 > _ZERO else (halfT if nl2 < -_ZERO else 0.0)
    link = _LINK_A[bp] if bu < 0.5 else _LINK_B[bp]
    upper = link == 0 or link == 3
    right = link >= 2
    ctr = pts[_IU] if upper else pts[_IL]
    v = (pts[_IF] if upper else pts[_IG]) - ctr
    e = ((Y.conjugate() if right else Y) - ctr) / v
    status = _k_fk(theta, beta, gamma, upper, right, e, False, K, KC, sl, dwheel + sl * w, o0, o1, o2, want_jac, p,
                   J)
    info[0] = bp
    info[1] = (CUM[bp] + bu * (CUM[bp + 1] - CUM[bp])) / CUM[_NP]
    info[2] = w
    info[3] = link
    return status


@batch_kernel(rows="q n P J info status", min_parallel=256)
def _k_ground_batch(q, n, r, K, KC, sl, dwheel, halfT, o0, o1, o2, RLM, R0, P, J, info, status):
    for i in range(q.shape[0]):
        status[i] = _k_ground(q[i], n[i], r, K, KC, sl, dwheel, halfT, o0, o1, o2, RLM, R0, P[i], J[i], info[i],
                              True)


def _normals(normal) -> np.ndarray:
    n = as_input(normal, "normal", (3,))
    size = np.linalg.norm(n, axis=-1)
    if np.any(size <= 1e-300):
        raise InvalidInputError("normal must be a nonzero vector")
    return n / size[..., None]


def _leg_consts(leg, geo: Geometry):
    _i, side, _sx = _leg(leg)
    o = _origin(leg, geo)
    return (1.0 if side == "L" else -1.0), o, _R_LM[side], _R_0[side]


@lru_cache(maxsize=64, typed=True)  # typed: leg=1 must not admit leg=True or 1.0 (issue 25)
def _kernel_args(leg, r, geometry) -> tuple[Any, ...]:
    """The ground kernel's per-call constants for (leg, r, geometry), validated (the single-call fast path)."""
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rho = _thickness(r, geo)
    sl, o, RLM, R0 = _leg_consts(leg, geo)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    return (rho, K, KC, sl, geo.d_wheel, geo.T / 2, float(o[0]), float(o[1]), float(o[2]), RLM, R0)


_Z = (0.0, 0.0, 1.0)
_Z_ARRAY = np.array(_Z)  # writeable, like the batch rows: one compiled version of the kernels (never written)


def _single(q: np.ndarray, leg, r, geometry) -> GroundContact | None:
    """The fast path of one (3,) float64 q with the default normal: None when anything needs the full checks."""
    if not (THETA_MIN - 1e-12 <= q[0] <= THETA_MAX + 1e-12 and math.isfinite(q[1]) and math.isfinite(q[2])):
        return None
    try:
        args = _kernel_args(leg, r, geometry)
    except Exception:  # noqa: BLE001 - the full checks raise the documented error
        return None
    P, Jm, info = np.empty(3), np.empty(9), np.empty(4)
    if _k_ground(q, _Z_ARRAY, *args, P, Jm, info, True) != OK:  # type: ignore[call-arg]
        return None
    return GroundContact(P, np.asarray(int(info[0])), np.asarray(info[1]), np.asarray(info[2]), Jm.reshape(3, 3),
                         np.asarray(int(info[3])))


@overload
def ground_contact(q: ArrayLike, leg: Leg, normal: ArrayLike = ..., *, r: float = ..., geometry: Geometry | None = ...,
                   return_mask: Literal[False] = False) -> GroundContact: ...
@overload
def ground_contact(q: ArrayLike, leg: Leg, normal: ArrayLike = ..., *, r: float = ..., geometry: Geometry | None = ...,
                   return_mask: Literal[True]) -> tuple[GroundContact, np.ndarray]: ...
def ground_contact(q: ArrayLike, leg: Leg, normal: ArrayLike = _Z, *, r: float = TYRE_THICKNESS,
                   geometry: Geometry | None = None,
                   return_mask: bool = False) -> GroundContact | tuple[GroundContact, np.ndarray]:
    """The lowest point of the tyre of ``leg`` along the ground normal (module docstring), in {R}.

    Args:
        q: (..., 3) (theta, beta, gamma) of that leg (rad), theta in [17 deg, 160 deg].
        leg: "FL", "FR", "RR", "RL" or 0-3.
        normal: (3,) or (..., 3) the ground normal in {R} (any nonzero length; broadcast with q): the point
            returned is the support point toward ``-normal``.
        r: tyre thickness (m) in (0, R); geometry: robot parameters.
        return_mask: also return the mask of finite results (all True for valid inputs).

    Returns:
        :class:`GroundContact` (and the mask). Batch: NaN (piece -1) where an item fails.

    Raises:
        InvalidInputError: NaN/inf/complex/wrong shapes, theta out of range, a zero normal.
        InvalidParameterError: unknown leg, r out of range, geometry not a Geometry.
    """
    if normal is _Z and type(q) is np.ndarray and q.shape == (3,) and q.dtype == np.float64 and return_mask is False:
        fast = _single(q, leg, r, geometry)
        if fast is not None:
            return fast
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    return_mask = check_flag(return_mask, "return_mask")
    rho = _thickness(r, geo)
    sl, o, RLM, R0 = _leg_consts(leg, geo)
    q = as_input(q, "q", (3,))
    n = _normals(normal)
    try:
        shape = np.broadcast_shapes(q.shape[:-1], n.shape[:-1])
    except ValueError as exc:
        raise InvalidInputError(f"inputs do not broadcast together: q{q.shape}, normal{n.shape}") from exc
    q = np.broadcast_to(q, shape + (3,))
    _check_theta(q[..., 0], "theta (q[..., 0])")
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    qr = as_rows(q, 3)
    nr = as_rows(np.broadcast_to(n, shape + (3,)), 3)
    m = qr.shape[0]
    P, Jm, info, status = np.empty((m, 3)), np.empty((m, 9)), np.empty((m, 4)), np.empty(m, dtype=np.int64)
    args = (rho, K, KC, sl, geo.d_wheel, geo.T / 2, float(o[0]), float(o[1]), float(o[2]), RLM, R0)
    if shape == ():
        status[0] = _k_ground(qr[0], nr[0], *args, P[0], Jm[0], info[0], True)
    else:
        _k_ground_batch(qr, nr, *args, P, Jm, info, status)
    ok = status == OK
    P[~ok], Jm[~ok], info[~ok] = np.nan, np.nan, np.nan
    piece = np.where(ok, info[:, 0], -1).astype(np.int64)
    link = np.where(ok, info[:, 3], -1).astype(np.int64)
    gc = GroundContact(P.reshape(shape + (3,)), piece.reshape(shape), info[:, 1].reshape(shape),
                       info[:, 2].reshape(shape), Jm.reshape(shape + (3, 3)), link.reshape(shape))
    if shape == () and not bool(ok[0]):
        raise InvalidInputError(f"the ground contact is not finite at q={q.tolist()}")
    return (gc, ok.reshape(shape)) if return_mask else gc
