"""Wheel-leg (Corgi, seed 001) kinematics: closed-form leg linkage, rim contact point, contact Jacobian, IK.

Conventions (metres, radians at every API, theta included):

* Robot frame {R}: x front, y left, z up. Legs ``"FL"``, ``"FR"``, ``"RR"``, ``"RL"`` = indices 0-3 of the
  design notes (left: 0, 3; right: 1, 2). Module origin ``(+-L_body/2, +-W_body/2, d_abad)``.
* Module frame {M}: ``R_R^M(gamma) = R0 Rz(gamma)`` with ``R0`` = (x_M, y_M, z_M) = (+y_R, +z_R, +x_R) on the left,
  (-y_R, +z_R, -x_R) on the right, so z_M = +x_R (left) / -x_R (right) as in "Coord definitions".
* Leg frame {L}: origin ``(d_wheel, 0, 0)`` in {M}; the seed's ``T_L^M`` (left: x_L = -z_M, y_L = y_M,
  z_L = x_M; right: x_L = z_M, y_L = y_M, z_L = -x_M). At gamma = 0 every leg has x_L = -x_R, y_L = +z_R,
  z_L = +y_R, so +w points outward on left legs and inward on right legs, gamma > 0 swings the foot
  outward on both sides, and beta > 0 moves the foot backward.
* Leg plane: complex numbers ``x + i y`` in {L}; the closed form is written for the left half with the
  leg axis along +x and rotated by ``exp(i (beta + pi/2))``; right-half points are the complex conjugates
  before that rotation. Leg-frame points are returned as ``(x, y, w)``.
* Motors: ``phi_L = beta + (theta - theta0)``, ``phi_R = beta - (theta - theta0)``, theta0 = 17 deg;
  theta in [17 deg, 160 deg].
* Rim parameter alpha: 0 at the toe G, alpha > 0 towards the right half (counter-clockwise in {L}),
  alpha in [-pi, pi]; alpha = +-pi are the rim tips H_R / H_L (which meet only in wheel mode).

A single input returns plain arrays and raises on failure; a batch (leading dimensions) returns NaN where
an item fails, and ``return_mask=True`` also returns the mask of successes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from functools import lru_cache
from typing import Mapping, NamedTuple

import numpy as np

from ..errors import InvalidInputError, InvalidParameterError, JointLimitError, UnreachableError
from .._kernels import OK, as_rows, batch_kernel, kernel, prange
from .._batch import as_angles, as_input, check_choice, check_flag, check_integer, check_number, finish

__all__ = [
    "LEGS",
    "THETA0",
    "THETA_MIN",
    "THETA_MAX",
    "PSI_FG",
    "FOOT_OFFSET",
    "TYRE_OFFSET",
    "Geometry",
    "linkage_constants",
    "POINTS",
    "PASSIVE_JOINTS",
    "linkage_points",
    "passive_angles",
    "motor_angles",
    "theta_beta",
    "rim_point",
    "rim_point_seed",
    "rim_jump_seed",
    "rim_segment",
    "contact_point",
    "contact_jacobian",
    "leg_frame_to_robot",
    "module_origin",
    "ik",
    "IKInfo",
]

LEGS = ("FL", "FR", "RR", "RL")
THETA0 = math.radians(17.0)
THETA_MIN = math.radians(17.0)
THETA_MAX = math.radians(160.0)
#: Half-angle of the seed's toe arc (rad).
PSI_FG = math.radians(40.0)
#: Foot radius minus the pitch radius in the seed's rim formula: 0.02225 + 0.01225 m (tyre included).
FOOT_OFFSET = 0.0345
#: Outer (collision/visual) tyre radius minus the pitch radius: 0.135 - 0.100 m.
TYRE_OFFSET = 0.035

_ARC_HF = math.radians(130.0)
_ARC_BC = math.radians(101.0)
_ARC_FG = math.pi - _ARC_HF  # 50 deg: each lower rim
_J_ANGLE = math.radians(140.0)  # J = U + r exp(i (140 deg + arg(H - U)))


@dataclass(frozen=True)
class Geometry:
    """Parameters of the wheel-leg robot (the xacro arguments that matter to kinematics).

    Attributes:
        R: wheel pitch radius (m); every linkage length is proportional to it.
        L_body: wheel base, front to rear module origin (m).
        W_body: hip-to-hip width (m).
        d_abad: height of the module origins above {R} (m).
        d_wheel: offset of the leg plane from the module origin along x_M (m).
        T: rim thickness (m); the lateral contact coordinate w is in [-T/2, T/2].
    """

    R: float = 0.1
    L_body: float = 0.51
    W_body: float = 0.24
    d_abad: float = 0.057166
    d_wheel: float = 0.091675
    T: float = 0.04

    def __post_init__(self) -> None:
        from .spec import SPEC  # the model's parameter ranges, one source

        for f in fields(self):
            object.__setattr__(self, f.name, float(SPEC.params[f.name].check(f.name, getattr(self, f.name))))

    @classmethod
    def from_params(cls, params: Mapping[str, object] | None) -> "Geometry":
        """Build from a mapping (e.g. ``Robot.params``); keys that are not kinematic are ignored."""
        if params is None:
            return cls()
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in params.items() if k in names})


def _geometry(geometry) -> Geometry:
    """``geometry`` or the default; anything but a :class:`Geometry` is refused."""
    if geometry is None:
        return _DEFAULT_GEOMETRY
    if not isinstance(geometry, Geometry):
        raise InvalidParameterError(f"geometry must be a wheel_leg.Geometry, got {type(geometry).__name__}")
    return geometry


_DEFAULT_GEOMETRY = Geometry()


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


def linkage_constants(R: float = 0.1) -> dict[str, float]:
    """Link lengths (m) and fixed angles (rad) of the leg linkage for pitch radius ``R``.

    ``l4 = CD`` is computed so that the rims close exactly into a circle about O at theta0 (the design
    notes give 0.882966335 R, which this reproduces to 1e-10 R).
    """
    return _constants(float(R))._asdict()


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


def _cis(x) -> np.ndarray:
    """``exp(i x)`` for real ``x``, built from cos and sin (bitwise the same as ``np.exp(1j * x)``, ~2x faster)."""
    x = np.asarray(x, dtype=float)
    out = np.empty(x.shape, dtype=complex)
    out.real = np.cos(x)
    out.imag = np.sin(x)
    return out


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


class _Loop:
    """A batch loop compiled from one body twice: serially (:func:`kernel`, ``prange`` runs as ``range``) for
    fewer than ``min_parallel`` items, where starting numba's threads costs more than the loop, and in
    parallel (:func:`batch_kernel`) from there on. Called like the body; the first argument's length is the
    item count."""

    def __init__(self, fn, min_parallel: int):
        self.serial = kernel(fn)
        self.parallel = batch_kernel(fn)
        self.min_parallel = min_parallel
        self.__doc__, self.__name__ = fn.__doc__, fn.__name__

    def __call__(self, *args):
        return (self.parallel if args[0].shape[0] >= self.min_parallel else self.serial)(*args)


def _loop(min_parallel: int):
    return lambda fn: _Loop(fn, min_parallel)


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


@_loop(32768)
def _k_closed_batch(theta, K, KC, want_der, P, DP):
    """:func:`_k_closed` over theta (n,) into P, DP (n, 12)."""
    for i in prange(theta.shape[0]):
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


def _check_theta(theta: np.ndarray, name: str = "theta") -> None:
    bad = (theta < THETA_MIN - 1e-12) | (theta > THETA_MAX + 1e-12)
    if np.any(bad):
        v = float(np.asarray(theta)[bad].ravel()[0])
        raise InvalidInputError(
            f"{name}={v!r} rad ({math.degrees(v):.4g} deg) is out of range: must be in "
            f"[{THETA_MIN:.6f}, {THETA_MAX:.6f}] rad (17 deg to 160 deg)"
        )


def _check_alpha(alpha: np.ndarray) -> None:
    bad = np.abs(alpha) > math.pi + 1e-12
    if np.any(bad):
        v = float(alpha[bad].ravel()[0])
        raise InvalidInputError(f"alpha={v!r} rad is out of range: must be in [-pi, pi]")


def _check_w(w: np.ndarray, geo: Geometry) -> None:
    bad = np.abs(w) > geo.T / 2 + 1e-15
    if np.any(bad):
        v = float(w[bad].ravel()[0])
        raise InvalidInputError(f"w={v!r} m is out of range: must be in [-T/2, T/2] = [{-geo.T / 2:g}, {geo.T / 2:g}]")


def _rot(beta: np.ndarray) -> np.ndarray:
    return _cis(beta + math.pi / 2)


#: For each name of :data:`POINTS`: (index in :data:`_CF_NAMES` or -1 for O, conjugated: right half).
_POINT_SOURCE = tuple(
    (-1 if n == "O" else _CF_NAMES.index(n.rsplit("_", 1)[0] if n.endswith(("_L", "_R")) else n), n.endswith("_R"))
    for n in POINTS
)
_PT_INDEX = np.array([i for i, _ in _POINT_SOURCE], dtype=np.int64)
_PT_CONJ = np.array([c for _, c in _POINT_SOURCE], dtype=np.bool_)


@kernel
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


@_loop(32768)
def _k_linkage_batch(theta, beta, K, KC, idx, conj, out):
    """:func:`_k_linkage` over theta, beta (n,) into out (n, 22, 3)."""
    for i in prange(theta.shape[0]):
        _k_linkage(theta[i], beta[i], K, KC, idx, conj, out[i])


@kernel
def _k_links(pts):
    """Left-half link vectors: crank (A), bar AE (E - A), bar CD (C - D), upper rim (C - B), lower rim (G - F)."""
    return (pts[_IA], pts[_IE] - pts[_IA], pts[_IC] - pts[_ID], pts[_IC] - pts[_IB], pts[_IG] - pts[_IF])


@kernel
def _k_turn(a, b):
    """``arg(u(a) conj(u(b)))``, u the unit vector: the angle from link vector b to a."""
    z = a * b.conjugate()  # (the positive scales of the unit vectors do not change the angle)
    return math.atan2(z.imag, z.real)


@kernel
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


@_loop(32768)
def _k_passive_batch(theta, beta, K, KC, KR, out):
    """:func:`_k_passive` over theta, beta (n,) into out (n, 10)."""
    for i in prange(theta.shape[0]):
        _k_passive(theta[i], beta[i], K, KC, KR, out[i])


@kernel
def _k_ref_links(K, KC, out):
    pts, _d = _k_closed(THETA0, K, KC, False)
    links = _k_links(pts)
    for j in range(5):
        out[j] = links[j]


@lru_cache(maxsize=16)
def _ref_links(R: float) -> np.ndarray:
    """The left-half link vectors of :func:`_k_links` at theta0 (wheel mode), once per geometry."""
    out = np.empty(5, dtype=np.complex128)
    _k_ref_links(*_kconst(R, R + FOOT_OFFSET), out)
    out.setflags(write=False)
    return out


def _angle_pair(theta, beta):
    """(theta, beta) checked, broadcast and flattened; the fast path for two numbers. Returns
    (theta (n,), beta (n,), shape)."""
    if type(theta) in _SCALARS and type(beta) in _SCALARS:
        t = float(theta)
        if THETA_MIN - 1e-12 <= t <= THETA_MAX + 1e-12 and math.isfinite(beta):
            return np.array([t]), np.array([float(beta)]), ()
    theta, beta = as_angles(theta, beta, names=("theta", "beta"))
    _check_theta(theta)
    return as_rows(theta, 1)[:, 0], as_rows(beta, 1)[:, 0], theta.shape


def linkage_points(theta, beta=0.0, *, geometry: Geometry | None = None) -> dict[str, np.ndarray]:
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
    K, KC = _kconst(geo.R, geo.R + FOOT_OFFSET)
    out = np.empty((t.shape[0], len(POINTS), 3))
    _k_linkage_batch(t, b, K, KC, _PT_INDEX, _PT_CONJ, out)
    return {k: out[:, j].reshape(shape + (3,)) for j, k in enumerate(POINTS)}


def passive_angles(theta, beta=0.0, *, geometry: Geometry | None = None) -> dict[str, np.ndarray]:
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
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    t, b, shape = _angle_pair(theta, beta)
    K, KC = _kconst(geo.R, geo.R + FOOT_OFFSET)
    out = np.empty((t.shape[0], len(PASSIVE_JOINTS)))
    _k_passive_batch(t, b, K, KC, _ref_links(geo.R), out)
    return {k: out[:, j].reshape(shape) for j, k in enumerate(PASSIVE_JOINTS)}


def motor_angles(theta, beta) -> tuple[np.ndarray, np.ndarray]:
    """(phi_L, phi_R) = (beta + theta - theta0, beta - theta + theta0) (reference, motor mapping)."""
    theta, beta = as_angles(theta, beta, names=("theta", "beta"))
    return beta + (theta - THETA0), beta - (theta - THETA0)


def theta_beta(phi_L, phi_R) -> tuple[np.ndarray, np.ndarray]:
    """(theta, beta) = ((phi_L - phi_R)/2 + theta0, (phi_L + phi_R)/2); inverse of :func:`motor_angles`.

    theta is not range-checked here (the motors can be commanded anywhere; the linkage cannot).
    """
    phi_L, phi_R = as_angles(phi_L, phi_R, names=("phi_L", "phi_R"))
    return (phi_L - phi_R) / 2 + THETA0, (phi_L + phi_R) / 2


# ---------------------------------------------------------------- rim contact points
#: Segments of the continuous rim: (name, alpha start, alpha end, link, centre point, reference point).
_SEGMENTS = (
    ("rim_upper_L", -math.pi, -_ARC_FG, "U_L", "F_L"),
    ("rim_lower_L", -_ARC_FG, 0.0, "L_L", "G"),
    ("rim_lower_R", 0.0, _ARC_FG, "L_R", "G"),
    ("rim_upper_R", _ARC_FG, math.pi, "U_R", "F_R"),
)
_SEG_A0 = (-_ARC_FG, 0.0, 0.0, _ARC_FG)  # alpha at which the segment's reference point is reached


def rim_segment(alpha) -> np.ndarray:
    """Index (0-3) of the rim link that carries the contact point of parameter ``alpha`` in :func:`rim_point`.

    0: upper rim left (alpha < -50 deg), 1: lower rim left (-50 deg <= alpha < 0), 2: lower rim right
    (0 <= alpha <= 50 deg), 3: upper rim right (alpha > 50 deg).
    """
    a = np.asarray(alpha, dtype=float)
    return np.where(a < -_ARC_FG, 0, np.where(a < 0.0, 1, np.where(a <= _ARC_FG, 2, 3)))


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


@kernel
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


@_loop(32768)
def _k_select_batch(alpha, seed, rho, R, upper, right, e):
    """:func:`_k_select` over alpha (n,) into upper, right, e (n,)."""
    for i in prange(alpha.shape[0]):
        upper[i], right[i], e[i] = _k_select(alpha[i], seed, rho, R)


def _select(alpha: np.ndarray, seed: bool, radius: float, R: float) -> _Sel:
    """The arc of every alpha (:data:`_SEGMENTS` for the continuous rim; seed 1.1's three arcs): the batch of
    :func:`_k_select`."""
    alpha = np.asarray(alpha, dtype=np.float64)
    flat = as_rows(alpha, 1)[:, 0]
    n = flat.shape[0]
    upper, right, e = np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.complex128)
    _k_select_batch(flat, bool(seed), float(radius), float(R), upper, right, e)
    return _Sel(seed, upper.reshape(alpha.shape), right.reshape(alpha.shape), e.reshape(alpha.shape))


@_loop(32768)
def _k_plane_batch(theta, upper, right, e, seed, K, KC, z):
    """:func:`_k_plane` (no derivative, right halves conjugated) over theta and the arc choice (n,) into z."""
    for i in prange(theta.shape[0]):
        z[i], _dz = _k_plane(theta[i], upper[i], right[i], e[i], seed, K, KC, False, True)


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


@kernel
def _k_contact(q, alpha, w, seed, rho, K, KC, s, dwheel, half_T, o0, o1, o2, want_jac, p, J):
    """:func:`contact_point` / :func:`contact_jacobian` for one item, inputs range-checked (status codes)."""
    theta = q[0]
    if not (math.isfinite(theta) and math.isfinite(q[1]) and math.isfinite(q[2]) and math.isfinite(alpha)
            and math.isfinite(w)):
        return _NONFINITE
    if theta < THETA_MIN - 1e-12 or theta > THETA_MAX + 1e-12:
        return _THETA_RANGE
    if abs(alpha) > math.pi + 1e-12:
        return _ALPHA_RANGE
    if abs(w) > half_T + 1e-15:
        return _W_RANGE
    upper, right, e = _k_select(alpha, seed, rho, K[0])
    return _k_fk(theta, q[1], q[2], upper, right, e, seed, K, KC, s, dwheel + s * w, o0, o1, o2, want_jac, p, J)


@_loop(32768)
def _k_contact_batch(q, alpha, w, seed, rho, K, KC, s, dwheel, half_T, o0, o1, o2, want_jac, P, J, status):
    """:func:`_k_contact` over q (n, 3), alpha, w (n,) into P (n, 3), J (n, 9), status (n,)."""
    for i in prange(q.shape[0]):
        status[i] = _k_contact(q[i], alpha[i], w[i], seed, rho, K, KC, s, dwheel, half_T, o0, o1, o2, want_jac,
                               P[i], J[i])


@_loop(32768)
def _k_fk_batch(q, upper, right, e, a, seed, K, KC, s, o0, o1, o2, want_jac, P, J):
    """:func:`_k_fk` over q (n, 3) and the prepared arc choice (:class:`_Sel`) into P (n, 3), J (n, 9)."""
    for i in prange(q.shape[0]):
        _k_fk(q[i, 0], q[i, 1], q[i, 2], upper[i], right[i], e[i], seed, K, KC, s, a[i], o0, o1, o2, want_jac,
              P[i], J[i])


@kernel
def _k_rim(theta, beta, alpha, w, seed, rho, K, KC, out):
    """:func:`rim_point` (``seed=False``) / :func:`rim_point_seed` for one item into ``out`` (3,): the arc of
    :func:`_k_select`, the point of :func:`_k_plane`, rotated by ``exp(i (beta + pi/2))``."""
    upper, right, e = _k_select(alpha, seed, rho, K[0])
    z, _dz = _k_plane(theta, upper, right, e, seed, K, KC, False, True)
    z = complex(math.cos(beta + math.pi / 2), math.sin(beta + math.pi / 2)) * z
    out[0], out[1], out[2] = z.real, z.imag, w


@_loop(32768)
def _k_rim_batch(theta, beta, alpha, w, seed, rho, K, KC, out):
    """:func:`_k_rim` over theta, beta, alpha, w (n,) into out (n, 3)."""
    for i in prange(theta.shape[0]):
        _k_rim(theta[i], beta[i], alpha[i], w[i], seed, rho, K, KC, out[i])


_PSI_NEXT = float(np.nextafter(PSI_FG, 4.0))


@kernel
def _k_jump(theta, rho, K, KC):
    """:func:`rim_jump_seed` for one theta: ``|z(psi_FG+) - z(psi_FG)|`` on the seed rim (beta = 0)."""
    rot = complex(math.cos(math.pi / 2), math.sin(math.pi / 2))
    u1, r1, e1 = _k_select(PSI_FG, True, rho, K[0])
    u2, r2, e2 = _k_select(_PSI_NEXT, True, rho, K[0])
    z1, _d = _k_plane(theta, u1, r1, e1, True, K, KC, False, True)
    z2, _d = _k_plane(theta, u2, r2, e2, True, K, KC, False, True)
    return abs(rot * z2 - rot * z1)


@_loop(32768)
def _k_jump_batch(theta, rho, K, KC, out):
    """:func:`_k_jump` over theta (n,) into out (n,)."""
    for i in prange(theta.shape[0]):
        out[i] = _k_jump(theta[i], rho, K, KC)


def _rim_call(theta, beta, alpha, w, radius, geometry, seed):
    """The wrapper of :func:`rim_point` / :func:`rim_point_seed`: checks (fast path for four numbers), then
    the batch of :func:`_k_rim`."""
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rho = (geo.R + FOOT_OFFSET if seed else geo.R) if radius is None else None
    K, KC = _kconst(geo.R, geo.R + FOOT_OFFSET)
    if (rho is not None and type(theta) in _SCALARS and type(beta) in _SCALARS and type(alpha) in _SCALARS and type(w) in _SCALARS
            and THETA_MIN - 1e-12 <= theta <= THETA_MAX + 1e-12 and math.isfinite(beta)
            and abs(alpha) <= math.pi + 1e-12 and abs(w) <= geo.T / 2 + 1e-15):
        out = np.empty(3)
        _k_rim(float(theta), float(beta), float(alpha), float(w), seed, rho, K, KC, out)
        return out
    theta, beta, alpha, w = _rim_inputs(theta, beta, alpha, w, geo)
    if rho is None:
        rho = float(radius)
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


def rim_point(theta, beta, alpha, w=0.0, *, radius: float | None = None, geometry: Geometry | None = None):
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


def rim_point_seed(theta, beta, alpha, w=0.0, *, radius: float | None = None, geometry: Geometry | None = None):
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
    """
    return _rim_call(theta, beta, alpha, w, radius, geometry, True)


def rim_jump_seed(theta, *, radius: float | None = None, geometry: Geometry | None = None) -> np.ndarray:
    """Size (m) of the jump of :func:`rim_point_seed` at alpha = +psi_FG (equal at -psi_FG by symmetry).

    The distance between the toe-arc point at alpha = psi_FG and the upper-rim point at alpha -> psi_FG+.
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    theta = as_input(theta, "theta")
    _check_theta(theta)
    rho = geo.R + FOOT_OFFSET if radius is None else float(radius)
    K, KC = _kconst(geo.R, geo.R + FOOT_OFFSET)
    out = np.empty(theta.size)
    _k_jump_batch(as_rows(theta, 1)[:, 0], rho, K, KC, out)
    return out.reshape(theta.shape)


# ---------------------------------------------------------------- leg frame -> robot frame
_R_LM = {  # columns: x_L, y_L, z_L in {M}
    "L": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
    "R": np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
}
_R_0 = {  # columns: x_M, y_M, z_M in {R} at gamma = 0
    "L": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    "R": np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
}


def _leg(leg) -> tuple[int, str, float]:
    """(index, side "L"/"R", sx) of a leg given by name or index."""
    if isinstance(leg, (int, np.integer)) and not isinstance(leg, bool) and 0 <= int(leg) < 4:
        i = int(leg)
    elif isinstance(leg, str) and leg in LEGS:
        i = LEGS.index(leg)
    else:
        raise InvalidParameterError(f"leg must be one of {', '.join(LEGS)} or an index 0-3, got {leg!r}")
    return i, ("L" if i in (0, 3) else "R"), (1.0 if i in (0, 1) else -1.0)


def module_origin(leg, geometry: Geometry | None = None) -> np.ndarray:
    """Origin of the module frame {M_i} in {R}: (+-L_body/2, +-W_body/2, d_abad)."""
    geo = _geometry(geometry)
    _, side, sx = _leg(leg)
    sy = 1.0 if side == "L" else -1.0
    return np.array([sx * geo.L_body / 2, sy * geo.W_body / 2, geo.d_abad])


@kernel
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


@_loop(32768)
def _k_frame_batch(p, gamma, RLM, R0, dwheel, o, out):
    """:func:`_k_frame` over p (n, 3), gamma (n,) into out (n, 3)."""
    for i in prange(p.shape[0]):
        _k_frame(p[i], gamma[i], RLM, R0, dwheel, o, out[i])


def leg_frame_to_robot(p_L, gamma, leg, *, geometry: Geometry | None = None) -> np.ndarray:
    """Map points (..., 3) of the leg frame {L} to {R} (seed section 1.2).

    ``p_M = T_L^M p_L`` (the seed's matrices, offset d_wheel), ``p_R = o_i + R0_i Rz(gamma) p_M``; the
    seed does not print ``T_M^R``: this is the module placement of "Coord definitions".
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    _, side, _ = _leg(leg)
    o = module_origin(leg, geo)
    if (type(p_L) is np.ndarray and p_L.shape == (3,) and p_L.dtype == np.float64 and type(gamma) in _SCALARS
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


def _rim_kind(rim: str) -> bool:
    return check_choice(rim, "rim", ("continuous", "seed")) == "seed"


def _context(alpha, w, leg, rim, geo, radius) -> _Ctx:
    seed = _rim_kind(rim)
    _, side, _ = _leg(leg)
    if radius is None:
        rho = geo.R + FOOT_OFFSET if seed else geo.R
    else:
        rho = check_number(radius, "radius", 0.0, 2.0 * geo.R, low_open=True)
    sel = _select(alpha, seed, rho, geo.R)
    return _Ctx(sel, np.asarray(w, dtype=float), _constants(geo.R), geo, module_origin(leg, geo),
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

    def items(x, dtype):
        return np.ascontiguousarray(np.broadcast_to(x, shape).reshape(n), dtype=dtype)

    sel = ctx.sel
    a = items(ctx.geo.d_wheel + ctx.s * ctx.w, np.float64)
    K, KC = _kconst(ctx.c.R, ctx.geo.R + FOOT_OFFSET)
    P = np.empty((n, 3))
    J = np.empty((n, 9) if want_jac else (n, 0))
    o = ctx.origin
    _k_fk_batch.serial(flat, items(sel.upper, np.bool_), items(sel.right, np.bool_), items(sel.e, np.complex128), a,
                ctx.seed, K, KC, ctx.s, float(o[0]), float(o[1]), float(o[2]), bool(want_jac), P, J)
    p = P.reshape(shape + (3,))
    return p, (J.reshape(shape + (3, 3)) if want_jac else None)


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
    q = np.broadcast_to(q, shape + (3,))
    alpha, w = np.broadcast_to(alpha, shape), np.broadcast_to(w, shape)
    _check_theta(q[..., 0], "theta (q[..., 0])")
    _check_alpha(alpha)
    _check_w(w, geo)
    return q, alpha, w


@lru_cache(maxsize=64)
def _kctx_cached(leg, rim, radius, geo: Geometry):
    ctx = _context(np.zeros(()), 0.0, leg, rim, geo, radius)
    if radius is None:
        rho = geo.R + FOOT_OFFSET if ctx.seed else geo.R
    else:
        rho = float(radius)
    K, KC = _kconst(geo.R, geo.R + FOOT_OFFSET)
    o = ctx.origin
    return (ctx.seed, rho, K, KC, ctx.s, geo.d_wheel, geo.T / 2, float(o[0]), float(o[1]), float(o[2]))


def _kctx(leg, rim, radius, geo: Geometry):
    """The contact kernels' per-call constants (validated: leg, rim, radius), cached per keyword set."""
    try:
        return _kctx_cached(leg, rim, radius, geo)
    except TypeError:  # unhashable: let the checks name it
        _context(np.zeros(()), 0.0, leg, rim, geo, radius)
        raise


_SCALARS = (float, int)


def _contact_call(q, alpha, w, leg, rim, radius, geometry, want_jac):
    """The wrapper of :func:`contact_point` / :func:`contact_jacobian`: kernel for a single item (fast path:
    a float64 (3,) q and number alpha, w), batch kernel otherwise; any failure status -> the checks' error."""
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    if (type(q) is np.ndarray and q.shape == (3,) and q.dtype == np.float64 and type(alpha) in _SCALARS
            and type(w) in _SCALARS):
        try:
            kc = _kctx(leg, rim, radius, geo)
        except Exception:  # noqa: BLE001 - the full checks below raise the documented error in order
            kc = None
        if kc is not None:
            p = np.empty(3)
            J = np.empty(9) if want_jac else _NO_JAC
            if _k_contact(q, float(alpha), float(w), *kc, want_jac, p, J) == OK:
                return J.reshape(3, 3) if want_jac else p
    q, alpha, w = _q_inputs(q, alpha, w, geo)  # raises the documented error for a bad input
    kc = _kctx(leg, rim, radius, geo)
    shape = q.shape[:-1]
    n = int(np.prod(shape, dtype=int))
    P = np.empty((n, 3))
    J = np.empty((n, 9) if want_jac else (n, 0))
    status = np.empty(n, dtype=np.int64)
    _k_contact_batch(as_rows(q, 3), as_rows(alpha, 1)[:, 0], as_rows(w, 1)[:, 0], *kc, want_jac, P, J, status)
    return J.reshape(shape + (3, 3)) if want_jac else P.reshape(shape + (3,))


_NO_JAC = np.empty(0)


def contact_point(q, alpha, w, leg, *, rim: str = "continuous", radius: float | None = None,
                  geometry: Geometry | None = None) -> np.ndarray:
    """Contact point in the robot frame {R} for q = (theta, beta, gamma) (seed section 1, FK).

    The leg-frame point of :func:`rim_point` (``rim="continuous"``, default) or :func:`rim_point_seed`
    (``rim="seed"``), then :func:`leg_frame_to_robot`.

    Args:
        q: (..., 3) (theta, beta, gamma) in rad.
        alpha: rim parameter (rad), w: lateral coordinate (m); broadcast with q's leading shape.
        leg: "FL", "FR", "RR", "RL" or 0-3.

    Returns:
        (..., 3) point in {R}.
    """
    return _contact_call(q, alpha, w, leg, rim, radius, geometry, False)


def contact_jacobian(q, alpha, w, leg, *, rim: str = "continuous", radius: float | None = None,
                     geometry: Geometry | None = None) -> np.ndarray:
    """Analytic d(contact point in {R}) / d(theta, beta, gamma), shape (..., 3, 3).

    Replaces the seed's forward-difference Jacobian (seed 2.3) by the exact one: the closed form's
    theta-derivatives are carried through every step (forward mode by hand, :func:`_closed_form`),
    d/dbeta is ``i z`` in the leg plane and d/dgamma is ``R0 Rz(gamma) (e_z x p_M)``.
    """
    return _contact_call(q, alpha, w, leg, rim, radius, geometry, True)


# ---------------------------------------------------------------- inverse kinematics
class IKInfo(NamedTuple):
    """What :func:`ik` did, per target: iterations used and final position error (m).

    ``solutions`` (``method="radial"`` only, else None): shape (..., S, 3), every solution found for each
    target, NaN-padded (see :func:`ik`). ``evaluations``: linkage evaluations per target (below).
    """

    iterations: np.ndarray
    error: np.ndarray
    solutions: np.ndarray | None = None
    #: Linkage evaluations per target: rows of the contact FK (with or without its Jacobian) for the
    #: iterative methods; radial: evaluations of the leg-plane closed form with its theta-derivative (Newton
    #: and extremum steps) plus the final contact FK that checks the answer (the grid and start tables are
    #: not counted).
    evaluations: np.ndarray | None = None


@lru_cache(maxsize=32)
def _arc_table(R: float, seed: bool, nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """``|c(theta, alpha)|^2`` and its theta-derivative on a theta grid, as a matrix for all alpha at once.

    For an arc ``c = ctr + e v`` (``v = ref - ctr``, made unit for the seed rim; :func:`_plane`),
    ``|c|^2 = A + |e|^2 V + 2 Re(W e)`` with ``A = |ctr|^2``, ``V = |v|^2``, ``W = conj(ctr) v``: functions
    of theta alone, tabulated once per geometry. Returns ``grid`` (K,) and ``table`` (9, 2K) such that
    :func:`_arc_coefficients` ``@ table`` is ``[f(grid), f'(grid)]``, ``f = |c|^2 - r^2``.
    """
    grid = np.linspace(THETA_MIN, THETA_MAX, nodes)
    coef = _arc_terms(grid, R, seed)
    table = np.zeros((9, 2 * nodes))
    for kind in range(2):
        for row in range(4):
            table[4 * kind + row, :nodes] = coef[kind, row]
            table[4 * kind + row, nodes:] = coef[kind, row + 4]
    table[8, :nodes] = 1.0
    grid.setflags(write=False)
    table.setflags(write=False)
    return grid, table


def _arc_terms(theta: np.ndarray, R: float, seed: bool) -> np.ndarray:
    """(2 arc kinds, 8, ...): A, V, Re W, Im W and their theta-derivatives (see :func:`_arc_table`)."""
    pts, der = _closed_form(theta, _constants(R), R + FOOT_OFFSET, True, full=seed)
    rows = []
    for ctr_name, ref_name in ((("U", "J"), ("O_r", "G")) if seed else (("U", "F"), ("L", "G"))):
        ctr, dctr = pts[ctr_name], der[ctr_name]
        v, dv = pts[ref_name] - ctr, der[ref_name] - dctr
        if seed:
            nv = np.abs(v)
            dnv = (np.conj(v) * dv).real / nv
            v, dv = v / nv, (dv - v * dnv / nv) / nv
        W, dW = np.conj(ctr) * v, np.conj(dctr) * v + np.conj(ctr) * dv
        rows.append([np.abs(ctr) ** 2, np.abs(v) ** 2, W.real, W.imag,
                     2 * (np.conj(ctr) * dctr).real, 2 * (np.conj(v) * dv).real, dW.real, dW.imag])
    return np.array(rows)


def _arc_coefficients(sel: _Sel, r2) -> np.ndarray:
    """(n, 9) rows ``[u, u |e|^2, 2 u Re e, -2 u Im e, l, l |e|^2, 2 l Re e, -2 l Im e, -r^2]`` (u = 1 on the
    upper rim, l = 1 - u) that turn :func:`_arc_table`'s table into ``f, f'`` for each item."""
    e = sel.e
    ee = e.real * e.real + e.imag * e.imag
    coef = np.empty(e.shape + (9,))
    for base, on in ((0, sel.upper), (4, ~sel.upper)):
        w8 = on.astype(float)
        coef[..., base] = w8
        coef[..., base + 1] = w8 * ee
        coef[..., base + 2] = w8 * 2.0 * e.real
        coef[..., base + 3] = w8 * -2.0 * e.imag
    coef[..., 8] = -r2
    return coef


_GUESS_NODES = 64
_START_MARGIN = 0.5 * (THETA_MAX - THETA_MIN) / (_GUESS_NODES - 1)


def _out_of_plane(target: np.ndarray, ctx: _Ctx):
    """The target's in-plane coordinates for the out-of-plane branch ``y_L <= 0``, and gamma.

    In {M} (before the ABAD rotation) the contact point is ``(a, y_L, -+x_L)`` with ``a = d_wheel + s w``;
    ``Rz(gamma)`` keeps the coordinate along z_M (so ``x_L = -(target - o)_x``) and the distance from
    that axis, ``|(a, y_L)| = |(x_M, y_M)|``, so ``y_L = -+sqrt(x_M^2 + y_M^2 - a^2)`` and gamma is the angle
    from ``(a, y_L)`` to ``(x_M, y_M)``. Returns ``(x_L, |y_L|, a, x_M + i y_M)``; ``|y_L|`` is clipped at 0
    when the target is closer to the ABAD axis than ``a``.
    """
    d = target - ctx.origin
    a = ctx.geo.d_wheel + ctx.s * ctx.w
    m = ctx.s * d[..., 1] + 1j * d[..., 2]
    yabs = np.sqrt(np.maximum(m.real**2 + m.imag**2 - a * a, 0.0))
    return -d[..., 0], yabs, a, m


def _initial_guesses(target, alpha, w, leg, rim, geo, radius, count: int = 3):
    """Geometric starts, best first: gamma exact from the leg-plane offset, theta from a grid, beta from
    the direction. Returns (count, ..., 3).

    Solves the out-of-plane part exactly (in {M}, ``|(x_M, y_M)| = |(d_wheel +- w, y_L)|``), then takes the
    local minima over a 64-point theta grid of ``| |z(theta, alpha)| - |target in plane| |`` (several
    theta can give the same radius), best first; beta rotates z onto the target.
    """
    return _guesses(target, _context(alpha, w, leg, rim, geo, radius), count)


def _guesses(target, ctx: _Ctx, count: int, branch: float = -1.0):
    """(count, ..., 3) starts on the out-of-plane branch ``sign(y_L) = branch`` (see :func:`_initial_guesses`)."""
    shape = target.shape[:-1]
    x_L, yabs, a, m = _out_of_plane(target, ctx)
    y = branch * yabs
    gamma = np.angle(_cis(np.arctan2(m.imag, m.real) - np.arctan2(y, a)))
    tgt = x_L + 1j * y
    grid, table = _arc_table(ctx.geo.R, ctx.seed, _GUESS_NODES)
    K = grid.size
    # | |z(theta_k)| - |target| | on the grid, |z|^2 from the tabulated coefficients (one small matrix product)
    # (in place: fresh (n, 64) temporaries cost more in page faults than the arithmetic)
    coef = _arc_coefficients(ctx.sel, 0.0).reshape(-1, 9)
    res = coef @ table[:, :K]
    np.maximum(res, 0.0, out=res)
    np.sqrt(res, out=res)
    res -= np.abs(tgt).reshape(-1, 1)
    np.abs(res, out=res)
    local = np.ones(res.shape, dtype=bool)
    np.less_equal(res[:, 1:], res[:, :-1], out=local[:, 1:])
    local[:, :-1] &= res[:, :-1] <= res[:, 1:]
    # local minima by increasing residual, then the other nodes in grid order (a stable sort of the key)
    key = res
    np.putmask(key, ~local, 1e300 * (1.0 + np.arange(K) / K))
    rows = np.arange(res.shape[0])
    order = []
    for _ in range(count):
        k = np.argmin(key, axis=1)
        key[rows, k] = np.inf
        order.append(k)
    K_, KC = _kconst(ctx.c.R, ctx.geo.R + FOOT_OFFSET)
    n = int(np.prod(shape, dtype=int))
    sel = [np.ascontiguousarray(np.broadcast_to(x, shape).reshape(n), dtype=dt)
           for x, dt in ((ctx.sel.upper, np.bool_), (ctx.sel.right, np.bool_), (ctx.sel.e, np.complex128))]
    out = []
    for k in order:
        k = k.reshape(shape)
        zk = np.empty(n, dtype=np.complex128)
        _k_plane_batch(np.ascontiguousarray(grid[k].reshape(n)), *sel, ctx.seed, K_, KC, zk)
        zk = _rot(0.0) * zk.reshape(shape)
        # half a grid cell inside the domain: a start on a bound of theta can stall the projected iteration
        # there (seen: theta = 160 deg start, solution at 158.5 deg, error stuck at 2.8e-5 m)
        theta = np.clip(grid[k], THETA_MIN + _START_MARGIN, THETA_MAX - _START_MARGIN)
        out.append(np.stack([theta, np.angle(tgt / zk), gamma], -1))
    return np.stack(out)


@lru_cache(maxsize=64)
def _radial_ctx(leg, rim, radius, geo: Geometry):
    """:func:`_kctx` and the radial tables for one keyword set (the single-call fast path of :func:`ik`)."""
    kc = _kctx_cached(leg, rim, radius, geo)
    return kc, _radial_table(geo.R, kc[0])


def _ik_radial_single(target, alpha, w, leg, rim, radius, geo, tol, return_mask, return_info):
    """:func:`ik`'s fast path for one target with the default method and keywords: the kernel
    :func:`_k_ik_radial` called directly. None (the general path then decides, and raises) unless solved."""
    if not (abs(alpha) <= math.pi + 1e-12 and abs(w) <= geo.T / 2 + 1e-15):
        return None
    try:
        kc, tables = _radial_ctx(leg, rim, radius, geo)
    except Exception:  # noqa: BLE001 - the general path raises the documented error
        return None
    seed, rho, K, KC, s, dwheel, _half_T, o0, o1, o2 = kc
    upper, right, e = _k_select(alpha, seed, rho, K[0])
    q = np.empty(3)
    sols = np.empty((_RADIAL_SOLS, 3))
    its, err, reason, _nr, nsol = _k_ik_radial(target, upper, right, e, dwheel + s * w, seed, K, KC, s, o0, o1, o2,
                                               *tables, tol, 60, _NO_Q0[0], False, True, q, sols)
    if reason != _SOLVED:
        return None
    out = (q, np.array(True)) if return_mask else q
    if not return_info:
        return out
    if nsol > _RADIAL_SOLS:
        sols = np.empty((nsol, 3))
        _k_ik_radial(target, upper, right, e, dwheel + s * w, seed, K, KC, s, o0, o1, o2, *tables, tol, 60,
                     _NO_Q0[0], False, True, np.empty(3), sols)
    info = IKInfo(np.array(its), np.array(err), sols[:nsol], np.array(its + 1))
    return (*out, info) if return_mask else (out, info)


def ik(target, alpha=0.0, w=0.0, leg="FL", q0=None, *, method: str = "radial", rim: str = "continuous",
       tol: float = 1e-12, max_iter: int | None = None, delta: float = 1e-6, radius: float | None = None,
       limits: bool = True, geometry: Geometry | None = None, return_mask: bool = False,
       return_info: bool = False):
    """(theta, beta, gamma) placing the rim point (alpha, w) of ``leg`` at ``target`` in {R} (seed 2).

    Methods:
        ``"radial"`` (default): not an iteration on the 3x3 system at all: gamma and beta in closed form
        and a 1-D bracketed Newton for theta (:func:`_ik_radial` states the math). It finds every theta in
        [17 deg, 160 deg] that reaches the target; ``info.solutions`` lists them, for both signs of the
        out-of-plane square root: the branch ``y_L <= 0`` by increasing theta, then the branch ``y_L > 0``.
        Without ``q0`` it returns the first solution in that order whose gamma is inside the ABAD limits;
        with ``q0`` the usable solution nearest ``q0`` (distance ``sqrt(dtheta^2 + dbeta^2 + dgamma^2)``,
        angle differences wrapped), with beta shifted by a multiple of 2 pi to lie within pi of ``q0``'s.
        ``max_iter`` (default 60) bounds the Newton iterations per root; ``delta`` is not used.
        ``"seed"``: seed 2.2-2.3 as printed: Gauss-Newton ``dq = -(J^T J)^{-1} J^T E`` with the
        forward-difference Jacobian ``(FK(q + delta e_k) - FK(q)) / delta``, full steps, no bounds
        (the baseline), from the best geometric start of each out-of-plane branch in turn. Fails if J^T J is singular, theta leaves the linkage's domain, or it does not
        converge in ``max_iter`` (default 100) iterations.
        ``"damped"``: the same iteration with the analytic Jacobian (:func:`contact_jacobian`),
        Levenberg-Marquardt damping when a full step does not reduce ``|E|``, and theta projected onto
        [17 deg, 160 deg] (default ``max_iter`` 60); once ``|E| <= tol`` one more step is taken if it
        lowers ``|E|`` (so the result is usually at rounding level, not just under ``tol``).

    The iterative methods start from ``q0`` if given, else from geometric guesses (gamma exact, theta from a
    grid; not the lab's beta = 90 deg default): the seed method from the best guess of each branch, the damped
    method restarts a failed target from the next local minima of the grid and then from the guesses of the other
    out-of-plane branch. Converged means ``|E| <= tol`` (m), ``E`` the contact point (:func:`contact_point`)
    minus the target. ``info.iterations`` counts every iteration, restarts included (radial: Newton and
    bracketing steps summed over the target's roots).

    The contract (docs/wheel_leg.md): every answer marked solved is reproduced by :func:`contact_point` with
    the same ``alpha, w, leg, rim, radius`` to ``tol``; with ``limits=True`` (default) its gamma lies inside
    the ABAD joint's URDF limits [-pi/2, pi/2] (:data:`ABAD_LIMIT`) and theta in [17 deg, 160 deg]; the
    default method solves every target that :func:`contact_point` makes from such joints.

    Args:
        target: (..., 3) points in {R}; alpha (rad), w (m), q0 broadcast with its leading shape.
        q0: (..., 3) start (theta, beta, gamma) (radial: the configuration to stay near).
        tol: convergence tolerance (m), in (0, 1e-3].
        max_iter: iteration bound, an integer >= 1 (None: the method's default).
        delta: forward-difference step of ``method="seed"`` (rad), in (0, 0.1].
        radius: rim radius of the contact point (m), in (0, 2 R] (None: the rim's own, see :func:`rim_point`).
        limits: keep only answers inside the ABAD joint limits (False: any gamma).
        return_mask: also return the mask of converged targets (batch).
        return_info: also return an :class:`IKInfo` (iterations, final error per target; radial: solutions).

    Raises:
        JointLimitError: single target reachable, but only with gamma outside the ABAD limits.
        UnreachableError: single target not reached (``closest`` = the point reached).
        InvalidInputError: NaN/inf, complex or wrong shapes, alpha or w out of range.
        InvalidParameterError: unknown ``method``, ``rim`` or ``leg``; a keyword out of its range.
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    if (type(method) is str and method == "radial" and q0 is None and max_iter is None and limits is True and type(target) is np.ndarray
            and target.shape == (3,) and target.dtype == np.float64 and type(alpha) in _SCALARS
            and type(w) in _SCALARS and type(tol) is float and 0.0 < tol <= 1e-3 and type(delta) is float
            and 0.0 < delta <= 0.1):
        out = _ik_radial_single(target, float(alpha), float(w), leg, rim, radius, geo, tol, return_mask, return_info)
        if out is not None:
            return out
    target = as_input(target, "target", (3,))
    alpha, w = as_input(alpha, "alpha"), as_input(w, "w")
    q0 = None if q0 is None else as_input(q0, "q0", (3,))
    tol = check_number(tol, "tol", 0.0, 1e-3, low_open=True)
    delta = check_number(delta, "delta", 0.0, 0.1, low_open=True)
    if max_iter is not None:
        max_iter = check_integer(max_iter, "max_iter", 1, 100_000)
    limits = check_flag(limits, "limits")
    shapes = [target.shape[:-1], alpha.shape, w.shape] + ([] if q0 is None else [q0.shape[:-1]])
    try:
        shape = np.broadcast_shapes(*shapes)
    except ValueError as exc:
        raise InvalidInputError(
            f"inputs do not broadcast together: target{target.shape}, alpha{alpha.shape}, w{w.shape}"
            + ("" if q0 is None else f", q0{q0.shape}")
        ) from exc
    scalar = shape == ()
    target = np.broadcast_to(target, shape + (3,)).astype(float)
    alpha, w = np.broadcast_to(alpha, shape).astype(float), np.broadcast_to(w, shape).astype(float)
    _check_alpha(alpha)
    _check_w(w, geo)
    _rim_kind(rim)
    check_choice(method, "method", _METHODS)
    _leg(leg)
    n = int(np.prod(shape, dtype=int))
    if q0 is not None:
        q0 = np.array(np.broadcast_to(q0, shape + (3,)), dtype=float)
        _check_theta(q0[..., 0], "theta (q0[..., 0])")
        q0 = q0.reshape(n, 3)
    ctx = _context(alpha.reshape(n), w.reshape(n), leg, rim, geo, radius)  # validated once; the solvers iterate on it
    flat = target.reshape(n, 3)
    solutions = None
    if method == "radial":
        q, it, err, ok, solutions, reason = _ik_radial(flat, ctx, tol, max_iter, q0, limits)
        solutions = solutions.reshape(shape + solutions.shape[1:]) if return_info else None
        ev = it + 1
    else:
        q, it, err, ok, reason, ev = _ik_iterative(flat, ctx, q0, method, tol, max_iter, delta, limits)
    q = q.reshape(shape + (3,))
    it, err, ok, reason = it.reshape(shape), err.reshape(shape), ok.reshape(shape), reason.reshape(shape)
    ev = ev.reshape(shape)
    closest = None
    if scalar and not bool(ok):
        with np.errstate(invalid="ignore"):
            qc = q.copy()
            qc[0] = np.clip(qc[0], THETA_MIN, THETA_MAX)
            closest = _fk(qc, ctx.take(0), False)[0] if np.all(np.isfinite(qc)) else None
    q_out = np.where(ok[..., None], q, np.nan)
    info = IKInfo(it, err, solutions, ev)

    def error():
        where = (f"target {np.asarray(target).reshape(3).tolist()} for leg {leg!r} (alpha={float(alpha)!r}, "
                 f"w={float(w)!r})")
        if int(reason) == _LIMITS:
            return JointLimitError(
                f"{where} is reachable only with the ABAD angle outside its limits [-pi/2, pi/2] "
                f"(gamma={float(q[2]):.6g} rad); pass limits=False to accept it",
                target=np.asarray(target).reshape(3), closest=closest,
            )
        return UnreachableError(
            f"{where} not reached with method {method!r}: final error {float(err):.3e} m after {int(it)} "
            f"iterations (tolerance {tol:.1e} m, theta in [17, 160] deg); closest point reached "
            f"{None if closest is None else closest.tolist()}",
            target=np.asarray(target).reshape(3),
            closest=closest,
        )

    out = finish(q_out, ok, scalar, return_mask, error)
    if return_info:
        return (*out, info) if isinstance(out, tuple) else (out, info)
    return out


#: ABAD joint limit (rad): the URDF's ``<leg>_abad`` joints range over [-ABAD_LIMIT, ABAD_LIMIT].
ABAD_LIMIT = math.pi / 2
#: Beyond a limit by at most this (rad) counts as on it (the answer is clipped onto the limit).
_LIMIT_ROUNDING = 1e-12
_SOLVED, _UNREACHABLE, _LIMITS = 0, 1, 2


def _in_limits(q: np.ndarray, limits: bool) -> np.ndarray:
    """Mask of answers inside theta's domain and (``limits``) the ABAD limits; clips within-rounding ones."""
    with np.errstate(invalid="ignore"):
        inside = (q[:, 0] >= THETA_MIN - 1e-12) & (q[:, 0] <= THETA_MAX + 1e-12) & np.all(np.isfinite(q), axis=1)
        if limits:
            inside &= np.abs(q[:, 2]) <= ABAD_LIMIT + _LIMIT_ROUNDING
            q[inside, 2] = np.clip(q[inside, 2], -ABAD_LIMIT, ABAD_LIMIT)
    return inside


def _ik_iterative(flat, ctx, q0, method, tol, max_iter, delta, limits):
    """The seed and damped methods: solve from each start in turn, restarting the targets not yet solved
    (not converged, or converged outside the limits)."""
    if q0 is not None:
        starts = q0[None]
    elif method == "seed":  # the best start of each out-of-plane branch
        starts = np.concatenate([_guesses(flat, ctx, 1), _guesses(flat, ctx, 1, branch=1.0)])
    else:  # the grid's three best starts on the branch y_L <= 0, then on y_L > 0
        starts = np.concatenate([_guesses(flat, ctx, 3), _guesses(flat, ctx, 3, branch=1.0)])
    solver = _ik_seed if method == "seed" else _ik_damped
    n = flat.shape[0]
    q = np.full((n, 3), np.nan)
    it, err = np.zeros(n, dtype=int), np.full(n, np.inf)
    ev = np.zeros(n, dtype=int)
    ok = np.zeros(n, dtype=bool)
    converged_outside = np.zeros(n, dtype=bool)
    for start in starts:
        f = np.flatnonzero(~ok)
        if f.size == 0:
            break
        qf, itf, errf, okf, evf = solver(start[f].copy(), flat[f], ctx if f.size == n else ctx.take(f), tol,
                                         max_iter, delta)
        it[f] += itf
        ev[f] += evf
        inside = _in_limits(qf, limits)
        good = okf & inside
        converged_outside[f] |= okf & ~inside
        take = good | (errf < err[f])
        q[f[take]], err[f[take]] = qf[take], errf[take]
        ok[f] = good
    reason = np.where(ok, _SOLVED, np.where(converged_outside, _LIMITS, _UNREACHABLE))
    return q, it, err, ok, reason, ev


_METHODS = ("damped", "seed", "radial")


@kernel
def _k_solve3(M, b, x):
    """``x = M^-1 b`` for a 3x3 system by LU with partial pivoting (as LAPACK's getrf/getrs); returns the
    determinant (0: singular, x untouched)."""
    A = M.copy()
    y = b.copy()
    det = 1.0
    for c in range(3):
        piv = c
        for r in range(c + 1, 3):
            if abs(A[r, c]) > abs(A[piv, c]):
                piv = r
        if A[piv, c] == 0.0:
            return 0.0
        if piv != c:
            det = -det
            for k in range(3):
                A[c, k], A[piv, k] = A[piv, k], A[c, k]
            y[c], y[piv] = y[piv], y[c]
        det *= A[c, c]
        for r in range(c + 1, 3):
            f = A[r, c] / A[c, c]
            for k in range(c, 3):
                A[r, k] -= f * A[c, k]
            y[r] -= f * y[c]
    for r in range(2, -1, -1):
        acc = y[r]
        for k in range(r + 1, 3):
            acc -= A[r, k] * x[k]
        x[r] = acc / A[r, r]
    return det


@kernel
def _k_ik_seed(q, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter, delta):
    """The seed's Gauss-Newton (seed 2.2-2.3) for one target from ``q`` (3,, updated in place): forward-difference
    Jacobian ``(FK(q + delta e_k) - FK(q)) / delta``, full steps ``-(J^T J)^-1 J^T E``, no bounds; stops at
    ``|E| <= tol``, a non-finite error, a singular ``J^T J`` (NaN step) or ``max_iter``. Returns (iterations,
    error, converged, FK evaluations)."""
    p = np.empty(3)
    pk = np.empty(3)
    J = np.empty((3, 3))
    JtJ = np.empty((3, 3))
    JtE = np.empty(3)
    dq = np.empty(3)
    qk = np.empty(3)
    _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, p, p)
    ev = 1
    err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)
    it = 0
    while True:
        if err <= tol:
            return it, err, True, ev
        if not math.isfinite(err) or it >= max_iter:
            return it, err, False, ev
        for k in range(3):
            qk[0], qk[1], qk[2] = q[0], q[1], q[2]
            qk[k] += delta
            _k_fk(qk[0], qk[1], qk[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, pk, pk)
            for r in range(3):
                J[r, k] = (pk[r] - p[r]) / delta
        ev += 3
        for i in range(3):
            JtE[i] = J[0, i] * (p[0] - tgt[0]) + J[1, i] * (p[1] - tgt[1]) + J[2, i] * (p[2] - tgt[2])
            for k in range(3):
                JtJ[i, k] = J[0, i] * J[0, k] + J[1, i] * J[1, k] + J[2, i] * J[2, k]
        det = _k_solve3(JtJ, JtE, dq)
        if not abs(det) > 1e-300:
            dq[0], dq[1], dq[2] = math.nan, math.nan, math.nan
        for k in range(3):
            q[k] -= dq[k]
        it += 1
        _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, p, p)
        ev += 1
        err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)


@_loop(256)
def _k_ik_seed_batch(q, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter, delta, its, err, ok, ev):
    """:func:`_k_ik_seed` over starts q (n, 3) (updated) and targets (n, 3)."""
    for i in prange(q.shape[0]):
        its[i], err[i], ok[i], ev[i] = _k_ik_seed(q[i], tgt[i], upper[i], right[i], e[i], a[i], seed, K, KC, s, o0,
                                                  o1, o2, tol, max_iter, delta)


def _ik_seed(q, target, ctx, tol, max_iter, delta):
    """The seed method on a batch: :func:`_k_ik_seed` per target (compiled loop)."""
    max_iter = 100 if max_iter is None else max_iter
    n = q.shape[0]
    q = as_rows(q, 3).copy()
    sel = ctx.sel

    def items(x, dtype):
        return np.ascontiguousarray(np.broadcast_to(x, (n,)), dtype=dtype)

    K, KC = _kconst(ctx.c.R, ctx.geo.R + FOOT_OFFSET)
    o = ctx.origin
    it, ev = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    err, ok = np.empty(n), np.empty(n, dtype=np.bool_)
    _k_ik_seed_batch(q, as_rows(target, 3), items(sel.upper, np.bool_), items(sel.right, np.bool_),
                     items(sel.e, np.complex128), items(ctx.geo.d_wheel + ctx.s * ctx.w, np.float64), ctx.seed, K, KC,
                     ctx.s, float(o[0]), float(o[1]), float(o[2]), float(tol), int(max_iter), float(delta), it, err, ok,
                     ev)
    return q, it, err, ok, ev


@kernel
def _k_ik_damped(q, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter):
    """The damped method for one target from ``q`` (3,, updated in place): Gauss-Newton with the analytic
    Jacobian (:func:`_k_fk`), Levenberg-Marquardt damping ``(J^T J + lam tr(J^T J) I)`` raised 100x while a
    step does not lower ``|E|`` (10 trials) and lowered 10x when it does, theta projected onto [17, 160] deg;
    once ``|E| <= tol`` one more step is taken if it lowers ``|E|``. Returns (iterations, error, FK evaluations)."""
    p = np.empty(3)
    pn = np.empty(3)
    J = np.empty(9)
    Jn = np.empty(9)
    M = np.empty((3, 3))
    JtE = np.empty(3)
    dq = np.empty(3)
    qn = np.empty(3)
    best = np.empty(3)
    JtJ = np.empty((3, 3))
    q[0] = _k_clip(q[0], THETA_MIN, THETA_MAX)
    _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, True, p, J)
    ev = 1
    err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)
    active = err > tol
    polish = not active
    mu = 1e-16
    it = 0
    for _ in range(max_iter):
        if not active:
            break
        for i in range(3):
            JtE[i] = J[i] * (p[0] - tgt[0]) + J[3 + i] * (p[1] - tgt[1]) + J[6 + i] * (p[2] - tgt[2])
            for k in range(3):
                JtJ[i, k] = J[i] * J[k] + J[3 + i] * J[3 + k] + J[6 + i] * J[6 + k]
        scale = max(JtJ[0, 0] + JtJ[1, 1] + JtJ[2, 2], 1e-300)
        best[0], best[1], best[2] = q[0], q[1], q[2]
        best_err = err
        improved = False
        lam = mu
        for _trial in range(10):
            if improved:
                break
            for i in range(3):
                for k in range(3):
                    M[i, k] = JtJ[i, k] + (lam * scale if i == k else 0.0)
            det = _k_solve3(M, JtE, dq)
            if not (math.isfinite(det) and det != 0.0):
                dq[0], dq[1], dq[2] = math.nan, math.nan, math.nan
            qn[0] = _k_clip(q[0] - dq[0], THETA_MIN, THETA_MAX)
            qn[1], qn[2] = q[1] - dq[1], q[2] - dq[2]
            _k_fk(qn[0], qn[1], qn[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, pn, Jn)
            ev += 1
            en = math.sqrt((pn[0] - tgt[0]) ** 2 + (pn[1] - tgt[1]) ** 2 + (pn[2] - tgt[2]) ** 2)
            if en < err:
                improved = True
                best[0], best[1], best[2] = qn[0], qn[1], qn[2]
                best_err = en
                lam = max(lam / 10.0, 1e-16)
            else:
                lam *= 100.0
        q[0], q[1], q[2] = best[0], best[1], best[2]
        err = best_err
        mu = lam
        it += 1
        _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, True, p, J)
        ev += 1
        done = err <= tol
        active = ((not done) or (not polish)) and improved
        polish = polish or done
    return it, err, ev


@_loop(256)
def _k_ik_damped_batch(q, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter, its, err, ev):
    """:func:`_k_ik_damped` over starts q (n, 3) (updated) and targets (n, 3)."""
    for i in prange(q.shape[0]):
        its[i], err[i], ev[i] = _k_ik_damped(q[i], tgt[i], upper[i], right[i], e[i], a[i], seed, K, KC, s, o0, o1,
                                             o2, tol, max_iter)


def _ik_damped(q, target, ctx, tol, max_iter, delta):
    """The damped method on a batch: :func:`_k_ik_damped` per target (compiled loop)."""
    max_iter = 60 if max_iter is None else max_iter
    n = q.shape[0]
    q = as_rows(q, 3).copy()
    sel = ctx.sel

    def items(x, dtype):
        return np.ascontiguousarray(np.broadcast_to(x, (n,)), dtype=dtype)

    K, KC = _kconst(ctx.c.R, ctx.geo.R + FOOT_OFFSET)
    o = ctx.origin
    it, ev, err = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), np.empty(n)
    _k_ik_damped_batch(q, as_rows(target, 3), items(sel.upper, np.bool_), items(sel.right, np.bool_),
                       items(sel.e, np.complex128), items(ctx.geo.d_wheel + ctx.s * ctx.w, np.float64), ctx.seed, K,
                       KC, ctx.s, float(o[0]), float(o[1]), float(o[2]), float(tol), int(max_iter), it, err, ev)
    return q, it, err, err <= tol, ev


# ---------------------------------------------------------------- radial IK (method="radial")
#: Nodes of the theta grid that brackets the roots of the radial equation (8.9 deg cells).
_RADIAL_NODES = 17
#: Sub-cells per cell of the fine coefficient table that refines the Newton start (0.14 deg).
_RADIAL_SUB = 64
_EPS = float(np.finfo(float).eps)


@lru_cache(maxsize=16)
def _radial_table(R: float, seed: bool):
    """The radial IK's tables: :func:`_arc_table` on a coarse and a fine grid, and curvature bounds.

    Returns ``grid`` (K,), ``table`` (9, 2K) (coarse: brackets every root of every target with one small
    matrix product), ``m2`` (2, 3, K - 1): bounds of ``|A''|, |V''|, |W''|`` in each cell (finite
    differences of the exact first derivatives on 256 sub-intervals per cell, times 1.25), so
    ``|f''| <= m2[k, 0, j] + |e|^2 m2[k, 1, j] + 2 |e| m2[k, 2, j]`` in cell j for arc kind k; and ``fine``
    (Kf,), ``fine_rows`` (2 Kf, 9) (the fine table transposed: rows are gathered per root to refine its
    start).
    """
    grid, table = _arc_table(R, seed, _RADIAL_NODES)
    k = grid.size
    per = 256
    fine = np.linspace(THETA_MIN, THETA_MAX, (k - 1) * per + 1)
    d = _arc_terms(fine, R, seed)[:, 4:]
    d2 = np.abs(np.diff(d, axis=-1)) / (fine[1] - fine[0])  # (2, 4, fine intervals): A'', V'', Re W'', Im W''
    d2 = d2.reshape(2, 4, k - 1, per).max(axis=-1)
    m2 = 1.25 * np.stack([d2[:, 0], d2[:, 1], np.hypot(d2[:, 2], d2[:, 3])], 1)  # (2, 3, cells)
    fine, fine_table = _arc_table(R, seed, (k - 1) * _RADIAL_SUB + 1)
    fine_rows = np.ascontiguousarray(fine_table.T)
    for arr in (m2, fine_rows):
        arr.setflags(write=False)
    return grid, table, m2, fine, fine_rows


@kernel
def _k_f_and_slope(theta, upper, right, e, seed, K, KC, r2):
    """``f = |c(theta)|^2 - r2`` and ``f' = 2 Re(conj(c) dc/dtheta)``, ``c`` the contact point in the leg plane
    (right halves unconjugated: same modulus), and ``c, dc``: the radial IK's only linkage evaluation."""
    y, dy = _k_plane(theta, upper, right, e, seed, K, KC, True, False)
    return y.real * y.real + y.imag * y.imag - r2, 2.0 * (y.real * dy.real + y.imag * dy.imag), y, dy


@kernel
def _k_clip(x, lo, hi):
    """``np.clip`` for one float (NaN passes through)."""
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@kernel
def _k_max(a, b):
    """``np.maximum`` for floats (NaN propagates)."""
    if a != a or b != b:
        return math.nan
    return a if a >= b else b


@kernel
def _k_min(a, b):
    """``np.minimum`` for floats (NaN propagates)."""
    if a != a or b != b:
        return math.nan
    return a if a <= b else b


@kernel
def _k_lower_bound(Fa, Fb, Ga, Gb, h, M):
    """Lower bound of f on a cell of width h from its ends (f oriented positive there: Fa, Fb > 0; slopes
    Ga, Gb) and a bound M of |f''|: the larger of the Taylor bounds from the two ends,
    ``Fa + Ga t - M t^2/2`` and ``Fb - Gb (h - t) - M (h - t)^2/2``, at the t where they cross."""
    tc = _k_clip((Fa - Fb + Gb * h + M * h * h / 2) / (Gb - Ga + M * h), 0.0, h)
    if not math.isfinite(tc):
        tc = 0.5 * h
    return _k_max(Fa + Ga * tc - M * tc * tc / 2, Fb - Gb * (h - tc) - M * (h - tc) ** 2 / 2)


@kernel
def _k_hermite_root(h, flo, fhi, glo, ghi):
    """Root (offset from the lower end, in [0, h]) of the cubic Hermite model of f on a bracket of width h
    (values flo, fhi of opposite signs, slopes glo, ghi): four Newton steps on the cubic from the regula
    falsi point, clipped to the bracket."""
    df = fhi - flo
    c2 = (3 * df / h - 2 * glo - ghi) / h
    c3 = (glo + ghi - 2 * df / h) / (h * h)
    t = _k_clip(-flo / df, 0.0, 1.0) * h
    for _ in range(4):
        t = _k_clip(t - (flo + t * (glo + t * (c2 + t * c3))) / (glo + t * (2 * c2 + 3 * t * c3)), 0.0, h)
    return t


@kernel
def _k_radial_extremum(lo, hi, flo, fhi, glo, ghi, M, upper, right, e, seed, K, KC, r2, ftol, max_iter):
    """Decide whether f (of one sign at both ends of [lo, hi]) reaches 0 near the extremum inside.

    Regula falsi (Illinois) on f' from the extremum of the cubic Hermite model, until: f changes sign at
    the new point (two roots: split the bracket there), ``|f| <= 4 eps r^2`` (a double root at rounding
    level), :func:`_k_lower_bound` on the shrunk bracket is above ftol (no root), or the bracket is 1e-11
    wide (the extremum: a double root if ``|f| <= ftol`` there, else none). Returns (theta, f and f'
    there, status: 1 split / 2 double root / 0 none, f'' estimated by the secant of f' over the last
    bracket, iterations).
    """
    sig = 1.0 if flo > 0 else -1.0
    Fa, Fb, Ga, Gb = sig * flo, sig * fhi, sig * glo, sig * ghi  # oriented: Fa, Fb > 0, Ga < 0 < Gb
    h = hi - lo
    c2 = (3 * (Fb - Fa) / h - 2 * Ga - Gb) / h  # extremum of the cubic model p'(t) = 0
    c3 = (Ga + Gb - 2 * (Fb - Fa) / h) / (h * h)
    disc = math.sqrt(_k_max(c2 * c2 - 3 * c3 * Ga, 0.0))
    t0 = -Ga / (c2 + disc)  # the root of Ga + 2 c2 t + 3 c3 t^2 between the slopes' sign change
    th = lo + t0 if (t0 > 0 and t0 < h) else lo - Ga * h / (Gb - Ga)
    ga, gb = Ga, Gb  # Illinois-modified slopes
    f_out, g_out = math.nan, math.nan
    status = 0
    its = 0
    kept = 0  # +1: the upper end was kept last time, -1: the lower end
    for _ in range(max_iter):
        t = th
        f, g, _y, _dy = _k_f_and_slope(t, upper, right, e, seed, K, KC, r2)
        its += 1
        F, G = sig * f, sig * g
        f_out, g_out = f, g
        split = F < 0
        double = (not split) and F <= 4 * _EPS * r2  # at rounding level: a double root
        if G < 0:  # t replaces the lower end
            lo, Fa, Ga = t, F, G
            ga = G
            if kept == 1:
                gb = 0.5 * gb
            kept = 1
        else:
            hi, Fb, Gb = t, F, G
            if kept == -1:
                ga = 0.5 * ga
            gb = G
            kept = -1
        none = _k_lower_bound(Fa, Fb, Ga, Gb, hi - lo, M) > ftol
        narrow = (hi - lo <= 1e-11) or G == 0  # the extremum found: a double root if within tolerance
        if (not split) and narrow and F <= ftol:
            double = True
        status = 1 if split else (2 if double else 0)
        if split or double or none or narrow:
            th = t
            break
        nxt = (lo * gb - hi * ga) / (gb - ga)
        th = nxt if (nxt > lo and nxt < hi) else 0.5 * (lo + hi)
    curv = sig * (Gb - Ga) / (hi - lo)
    return th, f_out, g_out, status, curv, its


@kernel
def _k_fine_f(fine_rows, i, coef):
    """f (f' for rows kf + i) from the fine table at node i: ``fine_rows[i] . coef``."""
    acc = 0.0
    for j in range(9):
        acc += fine_rows[i, j] * coef[j]
    return acc


@kernel
def _k_radial_newton(lo, hi, flo, fhi, glo, ghi, guess, coef, fine, fine_rows, upper, right, e, seed, K, KC, r2,
                     mb, max_iter):
    """Safeguarded Newton on ``f(theta) = |c(theta)|^2 - r2`` in a bracket [lo, hi] where f changes sign.

    Start (no linkage evaluation): the root of the cubic Hermite model of f on the bracket
    (:func:`_k_hermite_root`) picks a sub-cell of the fine table (0.14 deg); if f (from the table and
    ``coef`` (9,), the target's :func:`_arc_coefficients`) does not change sign there, bisection on the
    table's nodes inside the bracket finds one; the start is then the root of the cubic model on that
    sub-cell, which becomes the bracket (if the table's signs do not bracket the root, e.g. a root at a
    node, the start on the whole bracket is kept). ``guess`` (NaN: none) overrides the start (the
    parabola start of the brackets split at an extremum). Each step ``-f/f'`` stays inside the
    (shrinking) bracket, else bisects. Stops when the predicted radius error after the step,
    ``|f''| step^2 / (4 r)`` with ``mb`` bounding ``|f''|``, is below one ulp of r, when
    ``|f| <= 4 eps r^2``, or when the bracket is ~eps wide.

    Returns (theta, c(theta) (complex, conjugated on right halves: the contact point before the beta
    rotation, from the last evaluation's Taylor step ``c + (theta - t) dc``, at rounding level since
    the last step is), iterations, converged).
    """
    kf = fine.shape[0]
    hf = fine[1] - fine[0]
    start = lo + _k_hermite_root(hi - lo, flo, fhi, glo, ghi)
    x = (start - THETA_MIN) / hf
    i_lo = int(x) if math.isfinite(x) else 0
    i_lo = min(max(i_lo, 0), kf - 2)
    i_hi = i_lo + 1
    f_lo, f_hi = _k_fine_f(fine_rows, i_lo, coef), _k_fine_f(fine_rows, i_hi, coef)
    ok = ((f_lo > 0) != (f_hi > 0)) and fine[i_lo] >= lo and fine[i_hi] <= hi
    if not ok and guess != guess:  # bisection on the table's nodes inside the bracket
        b_lo = min(max(int(math.ceil((lo - THETA_MIN) / hf - 1e-6)), 0), kf - 1)
        b_hi = min(max(int(math.floor((hi - THETA_MIN) / hf + 1e-6)), 0), kf - 1)
        b_p = _k_fine_f(fine_rows, b_lo, coef) > 0
        ok = (b_p != (_k_fine_f(fine_rows, b_hi, coef) > 0)) and b_lo < b_hi
        if ok:
            while b_hi - b_lo > 1:
                mid = (b_lo + b_hi) // 2
                if (_k_fine_f(fine_rows, mid, coef) > 0) == b_p:
                    b_lo = mid
                else:
                    b_hi = mid
        i_lo, i_hi = b_lo, b_hi
        f_lo, f_hi = _k_fine_f(fine_rows, b_lo, coef), _k_fine_f(fine_rows, b_hi, coef)
    if ok:  # the cubic model on the sub-cell
        lo, hi, flo, fhi = fine[i_lo], fine[i_hi], f_lo, f_hi
        glo, ghi = _k_fine_f(fine_rows, kf + i_lo, coef), _k_fine_f(fine_rows, kf + i_hi, coef)
        start = lo + _k_hermite_root(hi - lo, flo, fhi, glo, ghi)
    if guess == guess:
        start = guess
    th = start if (start > lo and start < hi) else 0.5 * (lo + hi)
    root = math.nan
    z = complex(math.nan, math.nan)
    its = 0
    conv = False
    pos_lo = flo > 0
    tol_step = 4 * _EPS * r2 / mb  # step^2 below this: the Newton update is at rounding level
    tol_f = 4 * _EPS * r2
    for _ in range(max_iter):
        t = th
        f, g, y, dy = _k_f_and_slope(t, upper, right, e, seed, K, KC, r2)
        its += 1
        if (f > 0) == pos_lo:
            lo = t
        else:
            hi = t
        step = f / g
        new = t - step
        newton = new > lo and new < hi
        if not newton:
            new = 0.5 * (lo + hi)
        small = abs(f) <= tol_f
        done = small or (newton and step * step <= tol_step) or (hi - lo <= 4 * _EPS * hi)
        if small:
            new = t
        root, z = new, y + (new - t) * dy
        conv = done
        th = new
        if done:
            break
    if right:
        z = z.conjugate()
    return root, z, its, conv


#: Most roots of one target kept by the radial kernel (16 cells, two per split cell, the ends, doubles).
_RADIAL_CAP = 64


@kernel
def _k_phase(z):
    return math.atan2(z.imag, z.real)


@kernel
def _k_ik_radial(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows, tol,
                 max_iter, q0, use_q0, limits, q, sols):
    """The radial IK for one target (:func:`_ik_radial` states the math) into ``q`` (3,) and ``sols``
    (S, 3) (NaN-padded, as many as fit). Returns (iterations, error, reason, roots, solutions)."""
    K_ = grid.shape[0]
    d0, d1, d2 = tgt[0] - o0, tgt[1] - o1, tgt[2] - o2
    x_L = -d0
    m = complex(s * d1, d2)
    yabs = math.sqrt(_k_max(m.real * m.real + m.imag * m.imag - a * a, 0.0))
    r2 = x_L * x_L + yabs * yabs
    ftol = 2.0 * math.sqrt(r2) * tol
    coef = np.zeros(9)
    base = 0 if upper else 4
    ee = e.real * e.real + e.imag * e.imag
    coef[base] = 1.0
    coef[base + 1] = ee
    coef[base + 2] = 2.0 * e.real
    coef[base + 3] = -2.0 * e.imag
    coef[8] = -r2
    kind = 0 if upper else 1
    ea = math.sqrt(ee)
    f = np.empty(K_)
    g = np.empty(K_)
    for k in range(K_):
        fk, gk = 0.0, 0.0
        for j in range(9):
            fk += coef[j] * table[j, k]
            gk += coef[j] * table[j, K_ + k]
        f[k], g[k] = fk, gk
    h = grid[1] - grid[0]
    # brackets: (lo, hi, flo, fhi, glo, ghi, curvature bound, start guess)
    jobs = np.empty((3 * K_, 8))
    nj = 0
    for k in range(K_ - 1):
        if (f[k] > 0) != (f[k + 1] > 0):
            M = m2[kind, 0, k] + ee * m2[kind, 1, k] + 2.0 * ea * m2[kind, 2, k]
            jobs[nj, 0], jobs[nj, 1], jobs[nj, 2], jobs[nj, 3] = grid[k], grid[k + 1], f[k], f[k + 1]
            jobs[nj, 4], jobs[nj, 5], jobs[nj, 6], jobs[nj, 7] = g[k], g[k + 1], M, math.nan
            nj += 1
    its = 0
    rth = np.empty(_RADIAL_CAP)
    rz = np.empty(_RADIAL_CAP, dtype=np.complex128)
    nx = 0  # roots found without Newton (ends of the range, double roots)
    xth = np.empty(K_ + 2)
    for end in range(2):
        col, inward, cell = (0, 1.0, 0) if end == 0 else (K_ - 1, -1.0, K_ - 2)
        # An end of [17, 160] deg with |f| <= ftol is a root within rounding (issue 15; see _ik_radial).
        near = abs(f[col]) <= ftol
        same_side = (inward * g[col] > 0) == (f[col] > 0)
        change = (f[cell] > 0) != (f[cell + 1] > 0)
        if near and (not change or same_side):
            xth[nx] = grid[col]
            nx += 1
    n_change = nj
    split_lo = np.empty((K_, 8))
    split_hi = np.empty((K_, 8))
    ns = 0
    for k in range(K_ - 1):
        if ((g[k] > 0) != (g[k + 1] > 0)) and ((f[k] > 0) == (f[k + 1] > 0)):  # extremum, no sign change
            sig = 1.0 if f[k] > 0 else -1.0
            Fa, Fb, Ga, Gb = sig * f[k], sig * f[k + 1], sig * g[k], sig * g[k + 1]
            M = m2[kind, 0, k] + ee * m2[kind, 1, k] + 2.0 * ea * m2[kind, 2, k]
            # |f| falls into the cell from both ends and the curvature bound allows it to reach 0
            if Ga < 0 and Gb > 0 and _k_lower_bound(Fa, Fb, Ga, Gb, h, M) <= ftol:
                th_e, f_e, g_e, status, k_e, its_e = _k_radial_extremum(
                    grid[k], grid[k + 1], f[k], f[k + 1], g[k], g[k + 1], M, upper, right, e, seed, K, KC, r2,
                    ftol, max_iter)
                its += its_e
                if status == 2:
                    xth[nx] = th_e
                    nx += 1
                elif status == 1:
                    # start both roots from the parabola f_s + f'_s d + k d^2 / 2 through the split point
                    sq = math.sqrt(_k_max(g_e * g_e - 2 * k_e * f_e, 0.0))
                    dd1, dd2 = (-g_e - sq) / k_e, (-g_e + sq) / k_e
                    row = split_lo[ns]
                    row[0], row[1], row[2], row[3] = grid[k], th_e, f[k], f_e
                    row[4], row[5], row[6], row[7] = g[k], g_e, M, th_e + _k_min(dd1, dd2)
                    row = split_hi[ns]
                    row[0], row[1], row[2], row[3] = th_e, grid[k + 1], f_e, f[k + 1]
                    row[4], row[5], row[6], row[7] = g_e, g[k + 1], M, th_e + _k_max(dd1, dd2)
                    ns += 1
    for i in range(ns):
        jobs[nj] = split_lo[i]
        nj += 1
    for i in range(ns):
        jobs[nj] = split_hi[i]
        nj += 1
    nr = 0
    for j in range(nj):
        root, zr, its_n, conv = _k_radial_newton(jobs[j, 0], jobs[j, 1], jobs[j, 2], jobs[j, 3], jobs[j, 4],
                                                 jobs[j, 5], jobs[j, 7], coef, fine, fine_rows, upper, right, e,
                                                 seed, K, KC, r2, jobs[j, 6], max_iter)
        its += its_n
        if conv and nr < _RADIAL_CAP:
            rth[nr], rz[nr] = root, zr
            nr += 1
    for i in range(nx):  # roots without a Newton evaluation: the contact point from the closed form
        if nr < _RADIAL_CAP:
            y, _dy = _k_plane(xth[i], upper, right, e, seed, K, KC, False, True)
            rth[nr], rz[nr] = xth[i], y
            nr += 1
    if nx > 0 or ns > 0:  # stable sort by theta, then one root found twice is listed once
        for i in range(1, nr):
            tv, zv = rth[i], rz[i]
            j = i - 1
            while j >= 0 and rth[j] > tv:
                rth[j + 1], rz[j + 1] = rth[j], rz[j]
                j -= 1
            rth[j + 1], rz[j + 1] = tv, zv
        keep = 1 if nr > 0 else 0
        prev = rth[0] if nr > 0 else 0.0
        for i in range(1, nr):
            cur = rth[i]
            if not (abs(cur - prev) <= 1e-10):
                rth[keep], rz[keep] = cur, rz[i]
                keep += 1
            prev = cur
        nr = keep
    # solutions: branch y_L <= 0 by increasing theta, then branch y_L > 0
    tau = complex(x_L, -yabs)  # exp(i (beta + pi/2)) c = tau on the branch y_L <= 0
    gamma1 = _k_phase(m * complex(a, yabs))
    gamma2 = _k_phase(m * complex(a, -yabs))
    nsol = nr * (2 if yabs > 0 else 1)
    S = sols.shape[0]
    for i in range(S):
        sols[i, 0], sols[i, 1], sols[i, 2] = math.nan, math.nan, math.nan
    best = -1
    best_d2 = math.inf
    sq0 = np.empty(3)
    sel = np.empty(3)
    for i in range(nsol):
        r = i if i < nr else i - nr
        ccz = rz[r].conjugate() * -1j
        sq0[0] = rth[r]
        if i < nr:
            sq0[1], sq0[2] = _k_phase(tau * ccz), gamma1
        else:
            sq0[1], sq0[2] = _k_phase(tau.conjugate() * ccz), gamma2
        usable = sq0[0] == sq0[0]
        if limits:  # the ABAD joint's URDF limits; within rounding of a limit counts as on it
            usable = usable and abs(sq0[2]) <= ABAD_LIMIT + _LIMIT_ROUNDING
            if usable:
                sq0[2] = _k_clip(sq0[2], -ABAD_LIMIT, ABAD_LIMIT)
        if i < S:
            sols[i, 0], sols[i, 1], sols[i, 2] = sq0[0], sq0[1], sq0[2]
        if i == 0:
            sel[0], sel[1], sel[2] = sq0[0], sq0[1], sq0[2]  # kept for the out-of-limits answer
        if usable:
            if not use_q0:
                if best < 0:
                    best = i
                    q[0], q[1], q[2] = sq0[0], sq0[1], sq0[2]
            else:
                dist = (sq0[0] - q0[0]) ** 2
                w1 = _k_phase(complex(math.cos(sq0[1] - q0[1]), math.sin(sq0[1] - q0[1])))
                w2 = _k_phase(complex(math.cos(sq0[2] - q0[2]), math.sin(sq0[2] - q0[2])))
                dist += w1 * w1 + w2 * w2
                if dist < best_d2 or best < 0:
                    best, best_d2 = i, dist
                    q[0], q[1], q[2] = sq0[0], q0[1] + w1, (q0[2] + w2 if not limits else sq0[2])
    if best >= 0:
        reason = _SOLVED
    elif nr > 0:  # reachable only outside the ABAD limits: the first solution, for the error message
        q[0], q[1], q[2] = sel[0], sel[1], sel[2]
        reason = _LIMITS
    else:  # no root: the grid node of smallest |f|, as the point reached
        kb = 0
        for k in range(1, K_):
            if abs(f[k]) < abs(f[kb]):
                kb = k
        cz, _dz = _k_plane(grid[kb], upper, right, e, seed, K, KC, False, True)
        q[0], q[1], q[2] = grid[kb], _k_phase(tau * cz.conjugate() * -1j), gamma1
        reason = _UNREACHABLE
    p = np.empty(3)
    _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, p, p)
    err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)
    if reason == _SOLVED and not (err <= tol):
        reason = _UNREACHABLE  # (does not happen: each root is checked against tol by the FK)
    return its, err, reason, nr, nsol


@_loop(256)
def _k_ik_radial_batch(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows, tol,
                       max_iter, q0, use_q0, limits, q, sols, its, err, reason, nsol):
    """:func:`_k_ik_radial` over targets (n, 3) (q0 (n, 3) or (1, 3) unused) into q, sols, its, err, reason,
    nsol (solutions found per target, possibly more than sols holds)."""
    for i in prange(tgt.shape[0]):
        iq0 = i if use_q0 else i - i  # (same integer type as i)
        its[i], err[i], reason[i], _nr, nsol[i] = _k_ik_radial(
            tgt[i], upper[i], right[i], e[i], a[i], seed, K, KC, s, o0, o1, o2, grid, table, m2, fine, fine_rows,
            tol, max_iter, q0[iq0], use_q0, limits, q[i], sols[i])


def _ik_radial(target, ctx, tol, max_iter, q0, limits=True):
    """The radial IK: gamma and beta in closed form, theta from the 1-D equation ``|c(theta, alpha)| = r``.

    Not in the seed, which iterates Gauss-Newton on all three unknowns with a forward-difference Jacobian
    (seed 2.2-2.3). This uses the structure of the map q -> contact point:

    * For fixed (alpha, w) the contact point is a fixed point of one rim link; in the leg plane {L} it is
      ``exp(i (beta + pi/2)) c(theta, alpha)`` (:func:`rim_point`; ``c`` depends on theta alone), at
      lateral coordinate w.
    * gamma rotates the module about z_M, the robot's x axis through the module origin o, so the target's
      coordinate along that axis and its distance from it do not depend on gamma. With ``d = target - o``
      and ``a = d_wheel + s w`` (s = +1 left, -1 right), the contact point in {M} before the ABAD rotation
      is ``(a, y_L, -+x_L)``, so ``x_L = -d_x`` and ``a^2 + y_L^2 = d_y^2 + d_z^2``: ``y_L = -+sqrt(d_y^2 +
      d_z^2 - a^2)`` (two branches; clipped at 0 if negative: then the FK check decides), and
      ``gamma = arg((s d_y + i d_z) / (a + i y_L))``.
    * beta rotates the leg plane about the motor axis O, so ``r = |x_L + i y_L|`` must equal ``|c|``, which
      depends on theta alone. The equation solved is ``f(theta) = |c(theta, alpha)|^2 - r^2 = 0`` on
      [17 deg, 160 deg], with the exact ``f' = 2 Re(conj(c) dc/dtheta)`` (the closed form's forward-mode
      derivatives, as in :func:`contact_jacobian`). Then ``beta = arg((x_L + i y_L) / c) - pi/2``.

    Roots: f and f' on a 17-node grid come from tabulated theta-coefficients (:func:`_arc_table`: one
    small matrix product for the batch). Every cell where f changes sign holds a root, found by
    :func:`_radial_newton` (usually one evaluation of the closed form, from a start refined on a fine
    table). A cell where f keeps its sign while f' changes sign holds an extremum of f: unless a
    curvature bound shows that f stays above ``2 r tol`` in it, :func:`_radial_extremum` decides whether f
    reaches 0 there (then the cell is split into two brackets, or the extremum taken as a double root if
    ``|f| <= 2 r tol`` at it). An end of the range with ``|f| <= 2 r tol`` is a root too. This finds every
    root if each cell holds at most one extremum of f. For the default geometry ``|c|^2`` has at most one
    extremum in theta for any alpha, both rims (checked on 1441 alpha x 20001 theta). At alpha = +-163 deg
    the contact point is the crank hinge B, ``|c| = R`` for every theta: f is rounding noise, every theta
    solves the IK and the grid reports many roots.

    Returns ``(q, iterations, error, converged, solutions, reason)``; ``solutions`` (n, S, 3), NaN-padded:
    for each root by increasing theta the branch ``y_L <= 0``, then the same roots on the branch ``y_L > 0``
    (absent when ``y_L = 0``). The answer is the first solution in that order whose gamma is inside the ABAD
    joint's URDF limits ``[-pi/2, pi/2]`` (``limits=False``: the first), or with ``q0`` the usable solution
    nearest ``q0``. It is checked with the forward kinematics (:func:`_k_fk`): converged means
    ``|contact_point(q) - target| <= tol``. ``reason`` per target: 0 solved, 1 no root (out of reach),
    2 every root outside the ABAD limits. A target without a root gets, as its (unconverged) q, the grid
    node of smallest ``|f|`` with beta, gamma from the branch ``y_L <= 0``; one reachable only outside the
    limits, its first solution.
    """
    max_iter = 60 if max_iter is None else max_iter
    n = target.shape[0]
    grid, table, m2, fine, fine_rows = _radial_table(ctx.geo.R, ctx.seed)
    K, KC = _kconst(ctx.c.R, ctx.geo.R + FOOT_OFFSET)
    sel = ctx.sel

    def items(x, dtype):
        return np.ascontiguousarray(np.broadcast_to(x, (n,)), dtype=dtype)

    upper, right, e = items(sel.upper, np.bool_), items(sel.right, np.bool_), items(sel.e, np.complex128)
    a = items(ctx.geo.d_wheel + ctx.s * ctx.w, np.float64)
    tgt = as_rows(target, 3)
    q0a = _NO_Q0 if q0 is None else as_rows(q0, 3)
    o = ctx.origin
    q = np.empty((n, 3))
    its, reason, nsol = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    err = np.empty(n)
    cap = _RADIAL_SOLS
    sols = np.empty((n, cap, 3))
    args = (ctx.seed, K, KC, ctx.s, float(o[0]), float(o[1]), float(o[2]), grid, table, m2, fine, fine_rows, tol,
            max_iter)
    _k_ik_radial_batch(tgt, upper, right, e, a, *args, q0a, q0 is not None, bool(limits), q, sols, its, err,
                       reason, nsol)
    S = int(nsol.max()) if n else 0
    if S > cap:  # a target with more solutions than the first pass kept: solve those again, keeping all
        big = np.flatnonzero(nsol > cap)
        wide = np.full((n, S, 3), np.nan)
        wide[:, :cap] = sols
        qb, sb = np.empty((big.size, 3)), np.empty((big.size, S, 3))
        tmp = [np.empty(big.size, dtype=np.int64) for _ in range(3)]
        _k_ik_radial_batch(tgt[big], upper[big], right[big], e[big], a[big], *args,
                           q0a if q0 is None else q0a[big], q0 is not None, bool(limits), qb, sb, tmp[0],
                           np.empty(big.size), tmp[1], tmp[2])
        wide[big] = sb
        sols = wide
    return q, its, err, reason == _SOLVED, sols[:, :S], reason


#: Solutions per target kept by the first pass of the radial batch (more: that target is solved again).
_RADIAL_SOLS = 8
_NO_Q0 = np.zeros((1, 3))
