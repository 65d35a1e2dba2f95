"""The leg linkage in closed form (design notes, "Closed form of the left half"): hinge points, passive joint
angles, motor mapping."""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles
from .._kernels import as_rows, batch_kernel, kernel
from ._common import _SCALARS, _check_theta
from .geometry import (
    _ARC_BC,
    _ARC_HF,
    _DEFAULT_GEOMETRY,
    _J_ANGLE,
    THETA0,
    THETA_MAX,
    THETA_MIN,
    TYRE_THICKNESS,
    Geometry,
    _geometry,
)


class _Const(NamedTuple):
    R: float
    l1: float
    l3: float
    l4: float
    l5: float
    l6: float
    l_AE: float
    l7: float
    l8: float
    l_BF: float
    ang_UBC: float
    ang_BCF: float
    ang_LFG: float


def linkage_constants(*, geometry: Geometry | None = None) -> dict[str, float]:
    """Link lengths (m) and fixed angles (rad) of the leg linkage for the pitch radius ``geometry.R``.

    ``l4 = CD`` is computed so that the rims close exactly into a circle about O at theta0 (the design
    notes give 0.882966335 R, which this reproduces to 1e-10 R).

    Args:
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        the constants by name (m or rad).
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    return _constants(geo.R)._asdict()


@lru_cache(maxsize=16)
def _constants(R: float) -> _Const:
    l1 = 0.8 * R
    l3 = 2.0 * R * math.sin(_ARC_BC / 2)
    l5, l6 = 0.9 * R, 0.4 * R
    l_AE = l5 + l6
    l7 = 2.0 * R * math.sin((_ARC_HF - _ARC_BC - THETA0) / 2)
    l8 = 2.0 * R * math.sin((math.pi - _ARC_HF) / 2)
    l_BF = 2.0 * R * math.sin((_ARC_HF - THETA0) / 2)
    ang_UBC = (math.pi - _ARC_BC) / 2
    ang_LFG = _ARC_HF / 2
    ang_BCF = math.acos((l3**2 + l7**2 - l_BF**2) / (2 * l3 * l7))
    # l4 = |C - D| at theta0 with C on the wheel circle (U = O in wheel mode).
    s = l1 * math.sin(THETA0) / l_AE
    E = l1 * math.cos(THETA0) - l_AE * math.sqrt(1 - s * s)
    D = complex(E + l6 * math.sqrt(1 - s * s), l6 * s)
    C = R * complex(math.cos(THETA0 + _ARC_BC), math.sin(THETA0 + _ARC_BC))
    l4 = abs(C - D)
    return _Const(R, l1, l3, l4, l5, l6, l_AE, l7, l8, l_BF, ang_UBC, ang_BCF, ang_LFG)


#: Names returned by :func:`linkage_points` (``_L`` / ``_R``: left / right half; O_r and J: seed's foot).
POINTS = (
    "O", "A_L", "A_R", "B_L", "B_R", "C_L", "C_R", "D_L", "D_R", "E", "F_L", "F_R", "G",
    "H_L", "H_R", "U_L", "U_R", "L_L", "L_R", "O_r", "J_L", "J_R",
)  # fmt: skip

#: Tree joints of one leg (without the ``<leg>_`` prefix), as returned by :func:`passive_angles`.
PASSIVE_JOINTS = (
    "phi_L", "phi_R", "hinge_A_L", "hinge_A_R", "hinge_B_L", "hinge_B_R",
    "hinge_D_L", "hinge_D_R", "hinge_F_L", "hinge_F_R",
)  # fmt: skip


@lru_cache(maxsize=16)
def _factors(c: _Const, foot_radius: float) -> tuple[complex, ...]:
    """Constant complex factors of :func:`_closed_form` (computed once per geometry instead of per call)."""
    R = c.R
    return (
        complex(np.exp(-1j * c.ang_BCF) * c.l7 / c.l3),  # kF
        complex(np.exp(1j * c.ang_UBC) * R / c.l3),  # kU
        complex(np.exp(1j * c.ang_LFG) * R / c.l8),  # kL
        complex(np.exp(-1j * THETA0)),  # e0
        complex(np.exp(1j * _J_ANGLE) * foot_radius / R),  # kJ (|H - U| = R)
    )


#: Order of the left-half points in the closed-form kernel's output (:func:`_k_closed`).
_CF_NAMES = ("A", "B", "C", "D", "E", "F", "G", "U", "L", "H", "O_r", "J")
_IA, _IB, _IC, _ID, _IE, _IF, _IG, _IU, _IL, _IH, _IOR, _IJ = range(12)


@lru_cache(maxsize=16)
def _kconst(R: float, foot_radius: float) -> tuple[np.ndarray, np.ndarray]:
    """The kernels' constants: ``K`` (13,) = :class:`_Const` as floats, ``KC`` (5,) = :func:`_factors`."""
    c = _constants(R)
    K = np.array(c, dtype=np.float64)
    KC = np.array(_factors(c, foot_radius), dtype=np.complex128)
    K.setflags(write=False)
    KC.setflags(write=False)
    return K, KC


@kernel
def _k_closed(theta, K, KC, want_der):
    """The closed form of the left half (design notes, "Closed form of the left half"), one theta.

    Left-half points (complex, leg axis +x, before the beta rotation), in the order of :data:`_CF_NAMES`,
    and their theta-derivatives (forward mode by hand; zeros when ``want_der`` is False)::

        A = l1 e^{i theta}, B = R e^{i theta}, sin(OEA) = l1 sin(theta) / l_AE, E = Re A - l_AE cos(OEA),
        D = E + l6 e^{i OEA}, cos(DBC) = (|BD|^2 + l3^2 - l4^2) / (2 |BD| l3), C = B + l3 e^{-i DBC} BD/|BD|,
        F = C + (B - C) kF, sin(OGF) = Im F / l8, G = Re F - l8 cos(OGF), U = B + (C - B) kU,
        L = F + (G - F) kL, H = U + (B - U) e0, O_r = G + R, J = U + (H - U) kJ

    with ``kF = e^{-i BCF} l7/l3``, ``kU = e^{i UBC} R/l3``, ``kL = e^{i LFG} R/l8``, ``e0 = e^{-i theta0}``,
    ``kJ = e^{i 140 deg} r_foot/R``. Outside the linkage's domain the square roots give NaN.
    """
    R, l1, l3, l4, l6, l_AE, l8 = K[0], K[1], K[2], K[3], K[5], K[6], K[8]
    kF, kU, kL, e0, kJ = KC[0], KC[1], KC[2], KC[3], KC[4]
    ct_, st_ = math.cos(theta), math.sin(theta)
    eth = complex(ct_, st_)
    A = l1 * eth
    B = R * eth
    s = l1 * st_ / l_AE
    cs = math.sqrt(1.0 - s * s)
    E = A.real - l_AE * cs
    eo = complex(cs, s)
    D = E + l6 * eo
    BD = D - B
    lBD = abs(BD)
    cosg = (lBD * lBD + l3 * l3 - l4 * l4) / (2 * lBD * l3)
    sing = math.sqrt(1.0 - cosg * cosg)
    eg = complex(cosg, -sing)
    u = BD / lBD
    C = B + l3 * u * eg
    F = C + (B - C) * kF
    t = F.imag / l8
    ct = math.sqrt(1.0 - t * t)
    G = complex(F.real - l8 * ct, 0.0)
    U = B + (C - B) * kU
    L = F + (G - F) * kL
    H = U + (B - U) * e0
    Or = G + R
    J = U + (H - U) * kJ
    pts = (A, B, C, D, complex(E, 0.0), F, G, U, L, H, Or, J)
    if not want_der:
        z = 0j
        return pts, (z, z, z, z, z, z, z, z, z, z, z, z)
    dA, dB = 1j * A, 1j * B
    ds = l1 * ct_ / l_AE
    dE = dA.real + l_AE * s * ds / cs
    dD = dE + 1j * l6 * eo * (ds / cs)
    dBD = dD - dB
    dlBD = (BD.conjugate() * dBD).real / lBD
    dcosg = (1.0 / (2 * l3) - (l3 * l3 - l4 * l4) / (2 * l3 * lBD * lBD)) * dlBD
    dg = -dcosg / sing
    du = (dBD - u * dlBD) / lBD
    dC = dB + l3 * eg * (du - 1j * dg * u)
    dF = dC + (dB - dC) * kF
    dG = complex(dF.real + t * dF.imag / ct, 0.0)
    dU = dB + (dC - dB) * kU
    dL = dF + (dG - dF) * kL
    dH = dU + (dB - dU) * e0
    dJ = dU + (dH - dU) * kJ
    return pts, (dA, dB, dC, dD, complex(dE, 0.0), dF, dG, dU, dL, dH, dG, dJ)


@batch_kernel(rows="theta P DP", min_parallel=32768)
def _k_closed_batch(theta, K, KC, want_der, P, DP):
    """:func:`_k_closed` over theta (n,) into P, DP (n, 12)."""
    for i in range(theta.shape[0]):
        pts, der = _k_closed(theta[i], K, KC, want_der)
        for j in range(12):
            P[i, j] = pts[j]
            DP[i, j] = der[j]


def _closed_form(theta: np.ndarray, c: _Const, foot_radius: float, want_der: bool = True,
                 full: bool = True) -> tuple[dict, dict | None]:
    """Left-half points (complex, leg axis +x, before the beta rotation) and their theta-derivatives, as
    dicts of arrays of theta's shape: the batch of the kernel :func:`_k_closed` (which states the math).

    ``want_der=False``: ``der`` is None; ``full=False`` leaves out H, J and O_r (the seed rim's points).
    """
    theta = np.asarray(theta, dtype=np.float64)
    K, KC = _kconst(c.R, float(foot_radius))
    flat = np.ascontiguousarray(theta.reshape(-1))
    n = flat.size
    P = np.empty((n, 12), dtype=np.complex128)
    DP = np.empty((n, 12), dtype=np.complex128)
    _k_closed_batch(flat, K, KC, bool(want_der), P, DP)
    names = _CF_NAMES if full else _CF_NAMES[:9]
    zero = np.zeros(theta.shape, dtype=complex)
    pts = {"O": zero, **{k: P[:, j].reshape(theta.shape) for j, k in enumerate(names)}}
    if not want_der:
        return pts, None
    return pts, {"O": zero, **{k: DP[:, j].reshape(theta.shape) for j, k in enumerate(names)}}


#: For each name of :data:`POINTS`: (index in :data:`_CF_NAMES` or -1 for O, conjugated: right half).
_POINT_SOURCE = tuple(
    (-1 if n == "O" else _CF_NAMES.index(n.rsplit("_", 1)[0] if n.endswith(("_L", "_R")) else n), n.endswith("_R"))
    for n in POINTS
)
_PT_INDEX = np.array([i for i, _ in _POINT_SOURCE], dtype=np.int64)
_PT_CONJ = np.array([c for _, c in _POINT_SOURCE], dtype=np.bool_)


@kernel(entry=True, inline=True)
def _k_linkage(theta, beta, K, KC, idx, conj, out):
    """:func:`linkage_points` for one (theta, beta) into ``out`` (22, 3): the closed form (:func:`_k_closed`),
    right half = conjugates, rotated by ``exp(i (beta + pi/2))``, w = 0."""
    pts, _der = _k_closed(theta, K, KC, False)
    rot = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2))
    for j in range(idx.shape[0]):
        i = idx[j]
        if i < 0:
            v = 0j
        else:
            v = pts[0]
            for k in range(12):  # (a tuple is indexed by constants only)
                if k == i:
                    v = pts[k]
        if conj[j]:
            v = v.conjugate()
        v = rot * v
        out[j, 0], out[j, 1], out[j, 2] = v.real, v.imag, 0.0


@batch_kernel(rows="theta beta out", min_parallel=32768)
def _k_linkage_batch(theta, beta, K, KC, idx, conj, out):
    """:func:`_k_linkage` over theta, beta (n,) into out (n, 22, 3)."""
    for i in range(theta.shape[0]):
        _k_linkage(theta[i], beta[i], K, KC, idx, conj, out[i])


@kernel
def _k_links(pts):
    """Left-half link vectors: crank (A), bar AE (E - A), bar CD (C - D), upper rim (C - B), lower rim (G - F)."""
    return (pts[_IA], pts[_IE] - pts[_IA], pts[_IC] - pts[_ID], pts[_IC] - pts[_IB], pts[_IG] - pts[_IF])


@kernel(inline=True)
def _k_turn(a, b):
    """``arg(u(a) conj(u(b)))``, u the unit vector: the angle from link vector b to a."""
    z = a * b.conjugate()  # (the positive scales of the unit vectors do not change the angle)
    return math.atan2(z.imag, z.real)


@kernel(entry=True, inline=True)
def _k_passive(theta, beta, K, KC, KR, out):
    """:func:`passive_angles` for one (theta, beta) into ``out`` (10,) in the order of :data:`PASSIVE_JOINTS`:
    the link orientations of the closed form at theta and at theta0, ``d(link) = arg(u(theta) conj(u(theta0)))``
    with the unit vectors u of the crank (A), bar AE (E - A), bar CD (C - D), upper rim (C - B), lower rim (G - F)."""
    now, _d = _k_closed(theta, K, KC, False)
    ln = _k_links(now)
    lr = (KR[0], KR[1], KR[2], KR[3], KR[4])  # the link vectors at theta0 (:func:`_ref_links`)
    d0, d1, d2 = _k_turn(ln[0], lr[0]), _k_turn(ln[1], lr[1]), _k_turn(ln[2], lr[2])
    d3, d4 = _k_turn(ln[3], lr[3]), _k_turn(ln[4], lr[4])
    out[0] = beta + (theta - THETA0)
    out[1] = beta - (theta - THETA0)
    hA, hB, hD, hF = d1 - d0, d3 - d0, d2 - d1, d4 - d3
    out[2], out[3], out[4], out[5] = hA, -hA, hB, -hB
    out[6], out[7], out[8], out[9] = hD, -hD, hF, -hF


@batch_kernel(rows="theta beta out", min_parallel=32768)
def _k_passive_batch(theta, beta, K, KC, KR, out):
    """:func:`_k_passive` over theta, beta (n,) into out (n, 10)."""
    for i in range(theta.shape[0]):
        _k_passive(theta[i], beta[i], K, KC, KR, out[i])


@kernel(entry=True)
def _k_ref_links(K, KC, out):
    pts, _d = _k_closed(THETA0, K, KC, False)
    links = _k_links(pts)
    for j in range(5):
        out[j] = links[j]


@lru_cache(maxsize=16)
def _ref_links(R: float) -> np.ndarray:
    """The left-half link vectors of :func:`_k_links` at theta0 (wheel mode), once per geometry."""
    out = np.empty(5, dtype=np.complex128)
    _k_ref_links(*_kconst(R, R + TYRE_THICKNESS), out)
    out.setflags(write=False)
    return out


def _angle_pair(theta, beta):
    """(theta, beta) checked, broadcast and flattened; the fast path for two numbers. Returns
    (theta (n,), beta (n,), shape)."""
    if type(theta) in _SCALARS and type(beta) in _SCALARS:
        try:
            t, b = float(theta), float(beta)
        except OverflowError:  # an int beyond 1.8e308: as_angles names it
            t = b = math.nan
        if THETA_MIN - 1e-12 <= t <= THETA_MAX + 1e-12 and math.isfinite(b):
            return np.array([t]), np.array([b]), ()
    theta, beta = as_angles(theta, beta, names=("theta", "beta"))
    _check_theta(theta)
    return as_rows(theta, 1)[:, 0], as_rows(beta, 1)[:, 0], theta.shape


def linkage_points(theta: ArrayLike, beta: ArrayLike = 0.0, *,
                   geometry: Geometry | None = None) -> dict[str, np.ndarray]:
    """Every hinge point and rim centre of the leg in the leg frame {L}, by the closed form.

    Implements the reference's closed form of the linkage (the lab's ``LegModel.calculate``):
    ``A = l1 e^{i theta}``, ``B = R e^{i theta}``, ``E`` on the axis from ``|AE| = l_AE``, ``D`` on AE,
    ``C`` from the triangle BCD (law of cosines), ``F`` from the fixed angle BCF, ``G`` on the axis from
    ``|FG| = l8``, rim centres ``U`` (|UB| = |UC| = R) and ``L`` (|LF| = |LG| = R), the rim tip ``H`` and the
    seed's ``O_r = G + R`` and ``J``; right half = conjugates; all rotated by ``exp(i (beta + pi/2))``.

    Args:
        theta: leg opening angle (rad), in [17 deg, 160 deg]; any shape.
        beta: leg rotation (rad), broadcast with theta.
        geometry: robot parameters (default: the design-note values).

    Returns:
        dict name -> array (..., 3) of (x, y, w = 0) in {L}; names in :data:`POINTS`.
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    t, b, shape = _angle_pair(theta, beta)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    out = np.empty((t.shape[0], len(POINTS), 3))
    if shape == ():
        _k_linkage(t[0], b[0], K, KC, _PT_INDEX, _PT_CONJ, out[0])
        return dict(zip(POINTS, out[0]))
    _k_linkage_batch(t, b, K, KC, _PT_INDEX, _PT_CONJ, out)
    return dict(zip(POINTS, out.transpose(1, 0, 2).reshape((len(POINTS),) + shape + (3,))))


def passive_angles(theta: ArrayLike, beta: ArrayLike = 0.0, *,
                   geometry: Geometry | None = None) -> dict[str, np.ndarray]:
    """Angles of the 10 tree joints of a leg that close its four loops, from the closed form.

    Every tree joint is a revolute joint about z_L whose zero is the wheel-mode configuration
    (theta = theta0, beta = 0). With the left-half link orientations ``a_link(theta)`` of the closed form
    (crank: arg A, bar AE: arg(E - A), bar CD: arg(C - D), upper rim: arg(C - B), lower rim: arg(G - F)) and
    ``d(link) = a_link(theta) - a_link(theta0)``::

        phi_L = beta + d(crank) = beta + theta - theta0,   phi_R = beta - (theta - theta0)
        hinge_A = d(bar_AE) - d(crank),  hinge_D = d(bar_CD) - d(bar_AE),
        hinge_B = d(rim_upper) - d(crank),  hinge_F = d(rim_lower) - d(rim_upper)

    for the left half; the right half (mirror image) has the opposite hinge angles. The hinge angles do
    not depend on beta. Not in the seed (which has no passive joints).

    Returns:
        dict joint name (without the ``<leg>_`` prefix, see :data:`PASSIVE_JOINTS`) -> array.

    Args:
        theta: (...) the leg's theta (rad), in [17 deg, 160 deg].
        beta: (...) the leg's beta (rad), broadcast with theta.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    t, b, shape = _angle_pair(theta, beta)
    K, KC = _kconst(geo.R, geo.R + TYRE_THICKNESS)
    out = np.empty((t.shape[0], len(PASSIVE_JOINTS)))
    if shape == ():
        _k_passive(t[0], b[0], K, KC, _ref_links(geo.R), out[0])
        return {k: np.asarray(v) for k, v in zip(PASSIVE_JOINTS, out[0])}
    _k_passive_batch(t, b, K, KC, _ref_links(geo.R), out)
    return dict(zip(PASSIVE_JOINTS, out.T.reshape((len(PASSIVE_JOINTS),) + shape)))


@kernel(entry=True)
def _k_motor_angles(theta, beta):
    """The motor mapping (reference): ``phi_L = beta + (theta - theta0)``, ``phi_R = beta - (theta - theta0)``."""
    return beta + (theta - THETA0), beta - (theta - THETA0)


@kernel(entry=True)
def _k_theta_beta(phi_L, phi_R):
    """Its inverse: ``theta = (phi_L - phi_R) / 2 + theta0``, ``beta = (phi_L + phi_R) / 2``."""
    return (phi_L - phi_R) / 2 + THETA0, (phi_L + phi_R) / 2


@batch_kernel(rows="x y u v", min_parallel=32768)
def _k_pair_batch(x, y, inverse, u, v):
    """:func:`_k_motor_angles` (or, ``inverse``, :func:`_k_theta_beta`) over x, y (n,) into u, v (n,)."""
    for i in range(x.shape[0]):
        if inverse:
            u[i], v[i] = _k_theta_beta(x[i], y[i])
        else:
            u[i], v[i] = _k_motor_angles(x[i], y[i])


def _pair(x, y, names: tuple[str, str], inverse: bool, geometry: object) -> tuple[np.ndarray, np.ndarray]:
    """The wrapper of :func:`motor_angles` / :func:`theta_beta`: two numbers -> the kernel, else the batch;
    ``geometry`` only checked (neither depends on it)."""
    if geometry is not None:
        _geometry(geometry)
    if type(x) is float and type(y) is float and math.isfinite(x) and math.isfinite(y):
        u, v = _k_theta_beta(x, y) if inverse else _k_motor_angles(x, y)
        return np.asarray(u), np.asarray(v)
    x, y = as_angles(x, y, names=names)
    shape = x.shape
    n = x.size
    u, v = np.empty(n), np.empty(n)
    _k_pair_batch(as_rows(x, 1)[:, 0], as_rows(y, 1)[:, 0], inverse, u, v)
    return u.reshape(shape), v.reshape(shape)


def motor_angles(theta: ArrayLike, beta: ArrayLike, *,
                 geometry: Geometry | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(phi_L, phi_R) = (beta + theta - theta0, beta - theta + theta0) (reference, motor mapping).

    Broadcast together; two numbers give two 0-d arrays. It does not depend on the geometry (``geometry`` is
    checked, for a uniform signature).

    Args:
        theta, beta: (...) leg angles (rad), broadcast together; theta in [17 deg, 160 deg].
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (phi_L, phi_R) (rad), each of the broadcast shape.
    """
    return _pair(theta, beta, ("theta", "beta"), False, geometry)


def theta_beta(phi_L: ArrayLike, phi_R: ArrayLike, *,
               geometry: Geometry | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(theta, beta) = ((phi_L - phi_R)/2 + theta0, (phi_L + phi_R)/2); inverse of :func:`motor_angles`.

    theta is not range-checked here (the motors can be commanded anywhere; the linkage cannot). Independent of
    the geometry (``geometry`` is checked, for a uniform signature).

    Args:
        phi_L, phi_R: (...) motor angles (rad), broadcast together.
        geometry: the wheel-leg's :class:`Geometry` (None: the default).

    Returns:
        (theta, beta) (rad), each of the broadcast shape.
    """
    return _pair(phi_L, phi_R, ("phi_L", "phi_R"), True, geometry)

