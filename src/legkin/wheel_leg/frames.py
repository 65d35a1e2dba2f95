"""Leg frame to robot frame (seed 1.2) and the contact point in the robot frame with its Jacobian."""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, Literal, NamedTuple, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input, check_choice, check_flag, check_number, dispatch, same_signature
from .._kernels import OK, as_items, as_rows, batch_kernel, kernel
from ..errors import InvalidInputError
from ._common import _SCALARS, RIMS, Leg, Rim, _check_alpha, _check_theta, _check_w, rim_name
from .geometry import _DEFAULT_GEOMETRY, THETA_MAX, THETA_MIN, TYRE_THICKNESS, Geometry, _geometry, _leg
from .linkage import _Const, _constants, _kconst
from .rim import _k_plane, _k_select, _Sel, _select

# ---------------------------------------------------------------- leg frame -> robot frame
_R_LM = {  # columns: x_L, y_L, z_L in {M}
    "L": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
    "R": np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
}
_R_0 = {  # columns: x_M, y_M, z_M in {R} at gamma = 0
    "L": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    "R": np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
}


def module_origin(leg: Leg, *, geometry: Geometry | None = None) -> np.ndarray:
    """Origin of the module frame {M_i} in {R}: (+-L_body/2, +-W_body/2, d_abad) (a new array).

    Args:
        leg: "FL", "FR", "RR", "RL" or 0-3.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (3,) the origin (m).
    """
    geo = _geometry(geometry)
    try:
        return _origin(leg, geo).copy()
    except TypeError:  # unhashable: let _leg name it
        _leg(leg)
        raise


@lru_cache(maxsize=64, typed=True)  # typed: leg=1 must not admit leg=True or 1.0 (issue 25)
def _origin(leg, geo: Geometry) -> np.ndarray:
    _, side, sx = _leg(leg)
    sy = 1.0 if side == "L" else -1.0
    o = np.array([sx * geo.L_body / 2, sy * geo.W_body / 2, geo.d_abad])
    o.setflags(write=False)
    return o


@kernel(entry=True)
def _k_frame(p, gamma, RLM, R0, dwheel, o, out):
    """:func:`leg_frame_to_robot` for one point: ``out = o + R0 Rz(gamma) (RLM p + (d_wheel, 0, 0))``."""
    pm = np.empty(3)
    for i in range(3):
        pm[i] = RLM[i, 0] * p[0] + RLM[i, 1] * p[1] + RLM[i, 2] * p[2]
    pm[0] += dwheel
    c, s_ = math.cos(gamma), math.sin(gamma)
    r0, r1, r2 = c * pm[0] - s_ * pm[1], s_ * pm[0] + c * pm[1], pm[2]
    for i in range(3):
        out[i] = o[i] + R0[i, 0] * r0 + R0[i, 1] * r1 + R0[i, 2] * r2


@batch_kernel(rows="p gamma out", min_parallel=32768)
def _k_frame_batch(p, gamma, RLM, R0, dwheel, o, out):
    """:func:`_k_frame` over p (n, 3), gamma (n,) into out (n, 3)."""
    for i in range(p.shape[0]):
        _k_frame(p[i], gamma[i], RLM, R0, dwheel, o, out[i])


def leg_frame_to_robot(p_L: ArrayLike, gamma: ArrayLike, leg: Leg, *, geometry: Geometry | None = None) -> np.ndarray:
    """Map points (..., 3) of the leg frame {L} to {R} (seed section 1.2).

    ``p_M = T_L^M p_L`` (the seed's matrices, offset d_wheel), ``p_R = o_i + R0_i Rz(gamma) p_M``; the
    seed does not print ``T_M^R``: this is the module placement of "Coord definitions".

    Args:
        p_L: (..., 3) points in the leg frame {L} (m).
        gamma: (...) ABAD angle(s) (rad), broadcast with p_L's leading shape.
        leg: "FL", "FR", "RR", "RL" or 0-3.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (..., 3) the points in the robot frame {R} (m).
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    try:
        o = _origin(leg, geo)
    except TypeError:  # unhashable: let _leg name it
        _leg(leg)
        raise
    side = "L" if o[1] > 0 else "R"
    if (type(p_L) is np.ndarray and p_L.shape == (3,) and p_L.dtype == np.float64 and isinstance(gamma, (float, int))
            and math.isfinite(gamma) and np.isfinite(p_L).all()):
        out = np.empty(3)
        _k_frame(p_L, float(gamma), _R_LM[side], _R_0[side], geo.d_wheel, o, out)
        return out
    p_L = as_input(p_L, "p_L", (3,))
    gamma = as_input(gamma, "gamma")
    try:
        shape = np.broadcast_shapes(p_L.shape[:-1], gamma.shape)
    except ValueError:  # the error numpy gave before
        shape = np.broadcast_shapes(p_L.shape, gamma.shape + (1,))[:-1]
    n = int(np.prod(shape, dtype=int))
    out = np.empty((n, 3))
    _k_frame_batch(as_rows(np.broadcast_to(p_L, shape + (3,)), 3), as_rows(np.broadcast_to(gamma, shape), 1)[:, 0],
                   _R_LM[side], _R_0[side], geo.d_wheel, o, out)
    return out.reshape(shape + (3,))


class _Ctx(NamedTuple):
    """Everything the contact FK needs besides q, prepared once per call (the IK iterates on it)."""

    sel: _Sel
    w: np.ndarray
    c: _Const
    geo: Geometry
    origin: np.ndarray  # module origin in {R}
    s: float  # +1 left legs, -1 right legs
    seed: bool

    def take(self, idx) -> "_Ctx":
        return self._replace(sel=self.sel.take(idx), w=self.w[idx])

    def items(self, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The kernels' per-item inputs besides q, broadcast to ``shape`` and flattened (writeable, contiguous):
        the rim selection (upper, right, e) and the wheel's lateral offset a = d_wheel + s w."""
        n = int(np.prod(shape, dtype=int))

        def flat(x, dtype):
            return as_items(np.broadcast_to(x, shape).reshape(n), n, dtype)

        return (flat(self.sel.upper, np.bool_), flat(self.sel.right, np.bool_), flat(self.sel.e, np.complex128),
                flat(self.geo.d_wheel + self.s * self.w, np.float64))


def _rim_kind(rim: str) -> bool:
    """True for the three-arc rim (``rim`` already normalised by :func:`rim_name`)."""
    return check_choice(rim, "rim", RIMS) == "three_arc"


def _context(alpha, w, leg, rim, geo, radius) -> _Ctx:
    seed = _rim_kind(rim)
    _, side, _ = _leg(leg)
    if radius is None:
        rho = geo.R + TYRE_THICKNESS if seed else geo.R
    else:
        rho = check_number(radius, "radius", 0.0, 2.0 * geo.R, low_open=True)
    sel = _select(alpha, seed, rho, geo.R)
    return _Ctx(sel, np.asarray(w, dtype=float), _constants(geo.R), geo, _origin(leg, geo),
                1.0 if side == "L" else -1.0, seed)


def _fk(q: np.ndarray, ctx: _Ctx, want_jac: bool):
    """Contact point in {R} (..., 3) and, if asked, d/d(theta, beta, gamma) (..., 3, 3): the batch of the
    kernel :func:`_k_fk`.

    Same map as :func:`leg_frame_to_robot` written out for the signed permutation ``R0``: with the rotated
    leg-plane point ``x + i y``, ``a = d_wheel + s w`` (s = +1 left, -1 right), ``m0 = cos(gamma) a -
    sin(gamma) y``, ``m1 = sin(gamma) a + cos(gamma) y``: ``p = o + (-x, s m0, m1)``.
    """
    q = np.asarray(q, dtype=np.float64)
    shape = np.broadcast_shapes(q.shape[:-1], ctx.sel.e.shape, ctx.w.shape)
    flat = as_rows(np.broadcast_to(q, shape + (3,)), 3)
    n = flat.shape[0]
    upper, right, e, a = ctx.items(shape)
    K, KC = _kconst(ctx.c.R, ctx.geo.R + TYRE_THICKNESS)
    P = np.empty((n, 3))
    J = np.empty((n, 9) if want_jac else (n, 0))
    o = ctx.origin
    _k_fk_batch.kernel(flat, upper, right, e, a, ctx.seed, K, KC, ctx.s, float(o[0]), float(o[1]), float(o[2]),
                       bool(want_jac), P, J)
    p = P.reshape(shape + (3,))
    return p, (J.reshape(shape + (3, 3)) if want_jac else None)


def _writeable(x: np.ndarray) -> np.ndarray:
    """``x`` itself if it is a writeable C-contiguous float64 array, else a copy that is (the inputs of a batch with
    per-target alpha or w: no copy of n items where the caller's arrays serve as they are)."""
    if x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable:
        return x
    return np.array(x, dtype=np.float64)


def _q_inputs(q, alpha, w, geo):
    q = as_input(q, "q", (3,))
    alpha = as_input(alpha, "alpha")
    w = as_input(w, "w")
    try:
        shape = np.broadcast_shapes(q.shape[:-1], alpha.shape, w.shape)
    except ValueError as exc:
        raise InvalidInputError(
            f"inputs do not broadcast together: q{q.shape}, alpha{alpha.shape}, w{w.shape}"
        ) from exc
    q = q if q.shape == shape + (3,) else np.broadcast_to(q, shape + (3,))  # (a view only where it broadcasts)
    alpha = alpha if alpha.shape == shape else np.broadcast_to(alpha, shape)
    w = w if w.shape == shape else np.broadcast_to(w, shape)
    _check_theta(q[..., 0], "theta (q[..., 0])")
    _check_alpha(alpha)
    _check_w(w, geo)
    return q, alpha, w


@lru_cache(maxsize=64, typed=True)  # typed: leg=1 must not admit leg=True or 1.0 (issue 25)
def _kctx_cached(leg, rim, radius, geo: Geometry) -> tuple[tuple, tuple]:
    ctx = _context(np.zeros(()), 0.0, leg, rim, geo, radius)
    if radius is None:
        rho = geo.R + TYRE_THICKNESS if ctx.seed else geo.R
    else:
        rho = float(radius)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    o = ctx.origin
    kc = (ctx.seed, rho, K, KC, ctx.s, geo.d_wheel, geo.T / 2, float(o[0]), float(o[1]), float(o[2]))
    C = np.array([ctx.seed, rho, ctx.s, geo.d_wheel, geo.T / 2, o[0], o[1], o[2]], dtype=np.float64)
    C.setflags(write=False)
    return kc, (C, K, KC)


#: :func:`_kctx` of the default geometry and radius by (leg name, rim): one dict look-up on the single-call path.
_KCTX_DEFAULT: dict[tuple[str, str], tuple[tuple, tuple]] = {}


def _kctx(leg, rim, radius, geo: Geometry) -> tuple[tuple, tuple]:
    """The contact kernels' per-call constants (validated: leg, rim, radius), cached per keyword set: the unpacked
    tuple (seed, rho, K, KC, s, d_wheel, T/2, o (3)) and :func:`_k_contact`'s packed ``(C, K, KC)``."""
    if radius is None and geo is _DEFAULT_GEOMETRY and type(leg) is str:
        hit = _KCTX_DEFAULT.get((leg, rim))
        if hit is None:
            hit = _KCTX_DEFAULT[(leg, rim)] = _kctx_cached(leg, rim, None, geo)
        return hit
    try:
        return _kctx_cached(leg, rim, radius, geo)
    except TypeError:  # unhashable: let the checks name it
        _context(np.zeros(()), 0.0, leg, rim, geo, radius)
        raise


def _contact_call(q: ArrayLike, alpha: ArrayLike, w: ArrayLike, leg: Leg, rim: str, radius: float | None,
                  geometry: Geometry | None, want_jac: bool, return_mask: bool = False) -> Any:
    """The wrapper of :func:`fk` / :func:`jacobian` (:func:`legkin._batch.dispatch`): number alpha, w go to the
    kernels as they are; arrays are broadcast with q first (then q is a batch of that shape)."""
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    a: Any
    b: Any
    if type(alpha) in _SCALARS and type(w) in _SCALARS:
        a, b = float(alpha), float(w)  # type: ignore[arg-type]
        checked = None
    else:  # broadcast together (and range-checked) before the single/batch rule
        qb, a_arr, w_arr = _q_inputs(q, alpha, w, geo)
        q = _writeable(qb)  # numba types read-only arrays apart (a second compilation): copies only where needed
        a, b = (float(a_arr), float(w_arr)) if a_arr.ndim == 0 else (_writeable(a_arr).reshape(-1),
                                                                     _writeable(w_arr).reshape(-1))
        checked = True
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    kc = _KCTX_DEFAULT.get((leg, rim)) if radius is None and geo is _DEFAULT_GEOMETRY and type(leg) is str else None
    C, K, KC = (_kctx(leg, rim, radius, geo) if kc is None else kc)[1]  # (the look-up of _kctx, without its call)
    return dispatch(q, "q", (3,), _contact_fast, _contact_batch, _contact_fail, (a, b, C, K, KC, want_jac, geo,
                                                                                 checked), return_mask)


def _contact_fast(q: np.ndarray, args: tuple) -> np.ndarray | None:
    """One joint vector straight to :func:`_k_contact` (None unless solved: NaN, theta / alpha / w out of range);
    ``args``: those of :func:`_contact_batch`."""
    a, b, C, K, KC, want_jac, _geo, _checked = args
    p = np.empty(3)
    J = np.empty((3, 3)) if want_jac else _NO_JAC
    if _k_contact(q, a, b, C, K, KC, want_jac, p, J) == OK:
        return J if want_jac else p
    return None


def _contact_batch(rows: np.ndarray, a: Any, b: Any, C: np.ndarray, K: np.ndarray, KC: np.ndarray, want_jac: bool,
                   geo: Geometry, checked: Any) -> tuple[np.ndarray, np.ndarray]:
    """The compiled loop on joint rows (n, 3), after the range checks (an out-of-range theta, alpha or w raises,
    in a batch too)."""
    n = rows.shape[0]
    if checked is None:
        _q_inputs(rows, a, b, geo)
    alpha = np.full(n, a) if type(a) is float else a
    w = np.full(n, b) if type(b) is float else b
    P = np.empty((n, 3))
    J = np.empty((n, 9) if want_jac else (n, 0))
    status = np.empty(n, dtype=np.int64)
    _k_contact_batch(rows, alpha, w, C, K, KC, want_jac, P, J, status)
    ok = status == OK
    value = J.reshape(n, 3, 3) if want_jac else P
    value[~ok] = np.nan
    return value, ok


def _contact_fail(q: np.ndarray, out: np.ndarray, ok: np.ndarray, a: Any, b: Any, C: np.ndarray, K: np.ndarray,
                  KC: np.ndarray, want_jac: bool, geo: Geometry, checked: Any) -> Exception:
    return InvalidInputError(f"the contact {'Jacobian' if want_jac else 'point'} is not finite at q={q.tolist()}")


_NO_JAC = np.empty((0, 0))  # no Jacobian asked (a single call's J is (3, 3), a batch row's (9,): see _k_contact)


@overload
def fk(q: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
       radius: float | None = None, geometry: Geometry | None = None,
       return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def fk(q: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
       radius: float | None = None, geometry: Geometry | None = None,
       return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def fk(q: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
       radius: float | None = None, geometry: Geometry | None = None,
       return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Contact point in the robot frame {R} for q = (theta, beta, gamma) (seed section 1, FK).

    The leg-frame point of :func:`~legkin.wheel_leg.rim_point` (``rim="continuous"``, default) or of the
    seed's three-arc formula :func:`~legkin.wheel_leg.rim_point_seed` (``rim="three_arc"``), then
    :func:`leg_frame_to_robot`.

    Args:
        q: (..., 3) (theta, beta, gamma) in rad, theta in [17 deg, 160 deg].
        leg: "FL", "FR", "RR", "RL" or 0-3.
        alpha: rim parameter (rad) in [-pi, pi]; w: lateral coordinate (m) in [-T/2, T/2]; broadcast with q's
            leading shape.
        rim: ``"continuous"`` (the four rim links) or ``"three_arc"`` (seed 1.1's formula).
        radius: arc radius (m) in (0, 2 R] (None: the rim's own, see :func:`~legkin.wheel_leg.rim_point`).
        geometry: robot parameters (None: the default geometry).
        return_mask: also return the mask of finite results (all True for valid inputs).

    Returns:
        (..., 3) point in {R} (and the mask).

    Raises:
        InvalidInputError: NaN/inf, complex or wrong shapes; theta, alpha or w out of range.
        InvalidParameterError: unknown ``leg`` or ``rim``, ``radius`` out of range, not a Geometry.
    """
    return _contact_call(q, alpha, w, leg, rim_name(rim), radius, geometry, False, return_mask)


@same_signature(fk)
def jacobian(q: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
             radius: float | None = None, geometry: Geometry | None = None,
             return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Analytic d(contact point in {R}) / d(theta, beta, gamma) of :func:`fk`, shape (..., 3, 3).

    Replaces the seed's forward-difference Jacobian (seed 2.3) by the exact one: the closed form's
    theta-derivatives are carried through every step (forward mode by hand,
    :func:`~legkin.wheel_leg.linkage._k_closed`), d/dbeta is ``i z`` in the leg plane and d/dgamma is
    ``R0 Rz(gamma) (e_z x p_M)``. Arguments as :func:`fk`.

    Args:
        q: (..., 3) (theta, beta, gamma) in rad, theta in [17 deg, 160 deg].
        leg: "FL", "FR", "RR", "RL" or 0-3.
        alpha: rim parameter (rad) in [-pi, pi]; w: lateral coordinate (m) in [-T/2, T/2]; broadcast with q's
        leading shape.
        rim, radius: the rim model and arc radius (m), as in :func:`fk`.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).
        return_mask: also return the mask of successes (batch).

    Returns:
        (..., 3, 3) d(contact point, m) / d(theta, beta, gamma) (m/rad); then the mask, if asked.
    """
    return _contact_call(q, alpha, w, leg, rim_name(rim), radius, geometry, True, return_mask)


#: Kernel status codes (besides :data:`OK`): NaN/inf input or result, theta / alpha / w out of range.
_NONFINITE, _THETA_RANGE, _ALPHA_RANGE, _W_RANGE = 1, 2, 3, 4


@kernel
def _k_fk(theta, beta, gamma, upper, right, e, seed, K, KC, s, a, o0, o1, o2, want_jac, p, J):
    """The contact FK for one item (:func:`_fk` states the map) into ``p`` (3,) and ``J`` (9,) (row-major
    d p / d(theta, beta, gamma)); returns :data:`OK` or :data:`_NONFINITE`."""
    z, dz = _k_plane(theta, upper, right, e, seed, K, KC, want_jac, True)
    rot = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2))
    zr = rot * z
    x, y = zr.real, zr.imag
    cg, sg = math.cos(gamma), math.sin(gamma)
    m0 = cg * a - sg * y
    m1 = sg * a + cg * y
    p[0] = o0 - x
    p[1] = o1 + s * m0
    p[2] = o2 + m1
    status = OK if (math.isfinite(p[0]) and math.isfinite(p[1]) and math.isfinite(p[2])) else _NONFINITE
    if want_jac:
        dzr = rot * dz
        dx, dy = dzr.real, dzr.imag
        ssg = s * sg
        J[0], J[1], J[2] = -dx, y, 0.0
        J[3], J[4], J[5] = -ssg * dy, -ssg * x, -s * m1
        J[6], J[7], J[8] = cg * dy, cg * x, m0
        for k in range(9):
            if not math.isfinite(J[k]):
                status = _NONFINITE
    return status


@kernel(entry=True, inline=True)
def _k_contact(q, alpha, w, C, K, KC, want_jac, p, J):
    """:func:`fk` / :func:`jacobian` for one item, inputs range-checked (status codes); ``C`` (8,): the packed
    constants of :func:`_kctx` (seed, rho, s, d_wheel, T/2, origin): 9 arguments, a cheaper call from Python.
    ``J``: (3, 3) (a single call's answer, no reshape in Python) or (9,) (a batch row), (0, 0) / (0,) if not
    ``want_jac``; :func:`_k_fk` writes it flat."""
    theta = q[0]
    if not (math.isfinite(theta) and math.isfinite(q[1]) and math.isfinite(q[2]) and math.isfinite(alpha)
            and math.isfinite(w)):
        return _NONFINITE
    if theta < THETA_MIN - 1e-12 or theta > THETA_MAX + 1e-12:
        return _THETA_RANGE
    if abs(alpha) > math.pi + 1e-12:
        return _ALPHA_RANGE
    if abs(w) > C[4] + 1e-15:
        return _W_RANGE
    seed, s = C[0] != 0.0, C[2]
    upper, right, e = _k_select(alpha, seed, C[1], K[0])
    return _k_fk(theta, q[1], q[2], upper, right, e, seed, K, KC, s, C[3] + s * w, C[5], C[6], C[7], want_jac, p,
                 J.reshape(J.size))


@batch_kernel(rows="q alpha w P J status", min_parallel=32768)
def _k_contact_batch(q, alpha, w, C, K, KC, want_jac, P, J, status):
    """:func:`_k_contact` over q (n, 3), alpha, w (n,) into P (n, 3), J (n, 9), status (n,)."""
    for i in range(q.shape[0]):
        status[i] = _k_contact(q[i], alpha[i], w[i], C, K, KC, want_jac, P[i], J[i])


@batch_kernel(rows="q upper right e a P J", min_parallel=32768)
def _k_fk_batch(q, upper, right, e, a, seed, K, KC, s, o0, o1, o2, want_jac, P, J):
    """:func:`_k_fk` over q (n, 3) and the prepared arc choice (:class:`_Sel`) into P (n, 3), J (n, 9)."""
    for i in range(q.shape[0]):
        _k_fk(q[i, 0], q[i, 1], q[i, 2], upper[i], right[i], e[i], seed, K, KC, s, a[i], o0, o1, o2, want_jac,
              P[i], J[i])

