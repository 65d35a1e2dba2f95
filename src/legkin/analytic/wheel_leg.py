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
from typing import Mapping, NamedTuple

import numpy as np

from ..errors import InvalidInputError, InvalidParameterError, UnreachableError
from ._batch import as_angles, as_input, finish

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

    @classmethod
    def from_params(cls, params: Mapping[str, object] | None) -> "Geometry":
        """Build from a mapping (e.g. ``Robot.params``); keys that are not kinematic are ignored."""
        if params is None:
            return cls()
        names = {f.name for f in fields(cls)}
        return cls(**{k: float(v) for k, v in params.items() if k in names})


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


def _closed_form(theta: np.ndarray, c: _Const, foot_radius: float) -> tuple[dict, dict]:
    """Left-half points (complex, leg axis +x, before the beta rotation) and their theta-derivatives.

    Implements the closed form of the design notes (reference "Closed form of the left half"),
    differentiated by hand (forward mode). ``foot_radius`` only scales J (whose direction alone is used).
    """
    R = c.R
    eth = np.exp(1j * theta)
    A, dA = c.l1 * eth, 1j * c.l1 * eth
    B, dB = R * eth, 1j * R * eth
    s = c.l1 * np.sin(theta) / c.l_AE  # sin(OEA)
    ds = c.l1 * np.cos(theta) / c.l_AE
    cs = np.sqrt(1.0 - s * s)
    E = A.real - c.l_AE * cs
    dE = dA.real + c.l_AE * s * ds / cs
    eo = cs + 1j * s  # exp(i OEA)
    D = E + c.l6 * eo
    dD = dE + 1j * c.l6 * eo * (ds / cs)
    BD, dBD = D - B, dD - dB
    lBD = np.abs(BD)
    dlBD = (np.conj(BD) * dBD).real / lBD
    cosg = (lBD**2 + c.l3**2 - c.l4**2) / (2 * lBD * c.l3)  # cos(DBC)
    dcosg = (1.0 / (2 * c.l3) - (c.l3**2 - c.l4**2) / (2 * c.l3 * lBD**2)) * dlBD
    sing = np.sqrt(1.0 - cosg * cosg)
    dg = -dcosg / sing
    eg = cosg - 1j * sing  # exp(-i DBC)
    u = BD / lBD
    du = (dBD - u * dlBD) / lBD
    C = B + c.l3 * u * eg
    dC = dB + c.l3 * eg * (du - 1j * dg * u)
    kF = np.exp(-1j * c.ang_BCF) * c.l7 / c.l3
    F = C + (B - C) * kF
    dF = dC + (dB - dC) * kF
    t = F.imag / c.l8  # sin(OGF)
    ct = np.sqrt(1.0 - t * t)
    G = F.real - c.l8 * ct + 0j
    dG = dF.real + t * dF.imag / ct + 0j
    kU = np.exp(1j * c.ang_UBC) * R / c.l3
    U = B + (C - B) * kU
    dU = dB + (dC - dB) * kU
    kL = np.exp(1j * c.ang_LFG) * R / c.l8
    L = F + (G - F) * kL
    dL = dF + (dG - dF) * kL
    e0 = np.exp(-1j * THETA0)
    H = U + (B - U) * e0
    dH = dU + (dB - dU) * e0
    Or, dOr = G + R, dG
    kJ = np.exp(1j * _J_ANGLE) * foot_radius / R  # |H - U| = R
    J = U + (H - U) * kJ
    dJ = dU + (dH - dU) * kJ
    zero = np.zeros_like(A)
    pts = dict(O=zero, A=A, B=B, C=C, D=D, E=E + 0j, F=F, G=G, H=H, U=U, L=L, O_r=Or, J=J)
    der = dict(O=zero, A=dA, B=dB, C=dC, D=dD, E=dE + 0j, F=dF, G=dG, H=dH, U=dU, L=dL, O_r=dOr, J=dJ)
    return pts, der


_ON_AXIS = ("O", "E", "G", "O_r")


def _both_halves(half: dict) -> dict:
    """Left-half dict -> dict keyed by POINTS (right half = conjugates), still unrotated."""
    out = {}
    for k, v in half.items():
        if k in _ON_AXIS:
            out[k] = v
        else:
            out[k + "_L"], out[k + "_R"] = v, np.conj(v)
    return out


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
    return np.exp(1j * (beta + math.pi / 2))


def _xyw(z: np.ndarray, w) -> np.ndarray:
    return np.stack(np.broadcast_arrays(z.real, z.imag, np.asarray(w, dtype=float)), axis=-1)


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
    geo = geometry or Geometry()
    theta, beta = as_angles(theta, beta, names=("theta", "beta"))
    _check_theta(theta)
    pts, _ = _closed_form(theta, _constants(geo.R), geo.R + FOOT_OFFSET)
    rot = _rot(beta)
    return {k: _xyw(rot * v, 0.0) for k, v in _both_halves(pts).items()}


def _link_angles(pts: dict) -> dict:
    """Absolute orientation (as unit complex numbers) of the left-half links."""
    def unit(v):
        return v / np.abs(v)
    return dict(
        crank=unit(pts["A"]),
        bar_AE=unit(pts["E"] - pts["A"]),
        bar_CD=unit(pts["C"] - pts["D"]),
        rim_upper=unit(pts["C"] - pts["B"]),
        rim_lower=unit(pts["G"] - pts["F"]),
    )


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
    geo = geometry or Geometry()
    theta, beta = as_angles(theta, beta, names=("theta", "beta"))
    _check_theta(theta)
    c = _constants(geo.R)
    now = _link_angles(_closed_form(theta, c, geo.R)[0])
    ref = _link_angles(_closed_form(np.array(THETA0), c, geo.R)[0])
    d = {k: np.angle(now[k] * np.conj(ref[k])) for k in now}
    out = {"phi_L": beta + (theta - THETA0), "phi_R": beta - (theta - THETA0)}
    for hinge, child, parent in (
        ("A", "bar_AE", "crank"), ("B", "rim_upper", "crank"), ("D", "bar_CD", "bar_AE"), ("F", "rim_lower", "rim_upper"),
    ):  # fmt: skip
        a = d[child] - d[parent]
        out[f"hinge_{hinge}_L"], out[f"hinge_{hinge}_R"] = a, -a
    return {k: out[k] for k in PASSIVE_JOINTS}


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


def _rim_continuous(theta, beta, alpha, geo: Geometry, radius: float, want_der: bool):
    pts, der = _closed_form(theta, _constants(geo.R), geo.R + FOOT_OFFSET)
    P, dP = _both_halves(pts), _both_halves(der)
    seg = np.broadcast_to(rim_segment(alpha), np.broadcast(theta, alpha).shape)
    z = np.zeros(np.broadcast(theta, alpha).shape, dtype=complex)
    dz = np.zeros_like(z)
    for k, (_, _, _, cen, ref) in enumerate(_SEGMENTS):
        m = seg == k
        if not np.any(m):
            continue
        ctr, q = np.broadcast_to(P[cen], z.shape)[m], np.broadcast_to(P[ref], z.shape)[m]
        e = np.exp(1j * (np.broadcast_to(alpha, z.shape)[m] - _SEG_A0[k])) * radius / geo.R
        z[m] = ctr + e * (q - ctr)
        if want_der:
            dc, dq = np.broadcast_to(dP[cen], z.shape)[m], np.broadcast_to(dP[ref], z.shape)[m]
            dz[m] = dc + e * (dq - dc)
    rot = _rot(beta)
    return rot * z, rot * dz


def _rim_seed(theta, beta, alpha, geo: Geometry, radius: float, want_der: bool):
    pts, der = _closed_form(theta, _constants(geo.R), geo.R + FOOT_OFFSET)
    P, dP = _both_halves(pts), _both_halves(der)
    shape = np.broadcast(theta, alpha).shape
    a = np.broadcast_to(alpha, shape)
    z = np.zeros(shape, dtype=complex)
    dz = np.zeros_like(z)
    up_r, up_l = a > PSI_FG, a < -PSI_FG
    toe = ~(up_r | up_l)
    for m, cen, ref, a0 in ((up_r, "U_R", "J_R", PSI_FG), (up_l, "U_L", "J_L", -PSI_FG), (toe, "O_r", "G", 0.0)):
        if not np.any(m):
            continue
        ctr, q = np.broadcast_to(P[cen], shape)[m], np.broadcast_to(P[ref], shape)[m]
        dc, dq = np.broadcast_to(dP[cen], shape)[m], np.broadcast_to(dP[ref], shape)[m]
        v = q - ctr
        nv = np.abs(v)
        e = np.exp(1j * (a[m] - a0)) * radius
        z[m] = ctr + e * v / nv
        if want_der:
            dnv = (np.conj(v) * (dq - dc)).real / nv
            dz[m] = dc + e * ((dq - dc) - v * dnv / nv) / nv
    rot = _rot(beta)
    return rot * z, rot * dz


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
    geo = geometry or Geometry()
    theta, beta, alpha, w = _rim_inputs(theta, beta, alpha, w, geo)
    z, _ = _rim_continuous(theta, beta, alpha, geo, geo.R if radius is None else float(radius), False)
    return _xyw(z, w)


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
    geo = geometry or Geometry()
    theta, beta, alpha, w = _rim_inputs(theta, beta, alpha, w, geo)
    rho = geo.R + FOOT_OFFSET if radius is None else float(radius)
    z, _ = _rim_seed(theta, beta, alpha, geo, rho, False)
    return _xyw(z, w)


def rim_jump_seed(theta, *, radius: float | None = None, geometry: Geometry | None = None) -> np.ndarray:
    """Size (m) of the jump of :func:`rim_point_seed` at alpha = +psi_FG (equal at -psi_FG by symmetry).

    The distance between the toe-arc point at alpha = psi_FG and the upper-rim point at alpha -> psi_FG+.
    """
    geo = geometry or Geometry()
    theta = as_input(theta, "theta")
    _check_theta(theta)
    rho = geo.R + FOOT_OFFSET if radius is None else float(radius)
    a = np.full(theta.shape, PSI_FG)
    inside, _ = _rim_seed(theta, 0.0, a, geo, rho, False)
    above, _ = _rim_seed(theta, 0.0, np.nextafter(a, 4.0), geo, rho, False)
    return np.abs(above - inside)


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
    elif leg in LEGS:
        i = LEGS.index(leg)
    else:
        raise InvalidParameterError(f"leg must be one of {', '.join(LEGS)} or an index 0-3, got {leg!r}")
    return i, ("L" if i in (0, 3) else "R"), (1.0 if i in (0, 1) else -1.0)


def module_origin(leg, geometry: Geometry | None = None) -> np.ndarray:
    """Origin of the module frame {M_i} in {R}: (+-L_body/2, +-W_body/2, d_abad)."""
    geo = geometry or Geometry()
    _, side, sx = _leg(leg)
    sy = 1.0 if side == "L" else -1.0
    return np.array([sx * geo.L_body / 2, sy * geo.W_body / 2, geo.d_abad])


def _rz(gamma: np.ndarray) -> np.ndarray:
    c, s = np.cos(gamma), np.sin(gamma)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def leg_frame_to_robot(p_L, gamma, leg, *, geometry: Geometry | None = None) -> np.ndarray:
    """Map points (..., 3) of the leg frame {L} to {R} (seed section 1.2).

    ``p_M = T_L^M p_L`` (the seed's matrices, offset d_wheel), ``p_R = o_i + R0_i Rz(gamma) p_M``; the
    seed does not print ``T_M^R``: this is the module placement of "Coord definitions".
    """
    geo = geometry or Geometry()
    _, side, _ = _leg(leg)
    p_L = as_input(p_L, "p_L", (3,))
    gamma = as_input(gamma, "gamma")
    p_M = p_L @ _R_LM[side].T + np.array([geo.d_wheel, 0.0, 0.0])
    rot = _R_0[side] @ _rz(gamma)
    return module_origin(leg, geo) + np.einsum("...ij,...j->...i", rot, p_M)


def _contact(q, alpha, w, leg, rim, geo, want_jac, radius):
    _, side, _ = _leg(leg)
    theta, beta, gamma = q[..., 0], q[..., 1], q[..., 2]
    if rim == "continuous":
        rho = geo.R if radius is None else float(radius)
        z, dz = _rim_continuous(theta, beta, alpha, geo, rho, want_jac)
    elif rim == "seed":
        rho = geo.R + FOOT_OFFSET if radius is None else float(radius)
        z, dz = _rim_seed(theta, beta, alpha, geo, rho, want_jac)
    else:
        raise InvalidParameterError(f"rim must be 'continuous' or 'seed', got {rim!r}")
    w = np.broadcast_to(w, z.shape)
    p_L = _xyw(z, w)
    p_M = p_L @ _R_LM[side].T + np.array([geo.d_wheel, 0.0, 0.0])
    rot = _R_0[side] @ _rz(np.broadcast_to(gamma, z.shape))
    p = module_origin(leg, geo) + np.einsum("...ij,...j->...i", rot, p_M)
    if not want_jac:
        return p, None
    zero = np.zeros(z.shape)
    d_theta = np.stack([dz.real, dz.imag, zero], -1) @ _R_LM[side].T
    d_beta = np.stack([-z.imag, z.real, zero], -1) @ _R_LM[side].T  # d/dbeta = i z
    d_gamma = np.stack([-p_M[..., 1], p_M[..., 0], zero], -1)  # e_z x p_M
    cols = [np.einsum("...ij,...j->...i", rot, d) for d in (d_theta, d_beta, d_gamma)]
    return p, np.stack(cols, -1)


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
    geo = geometry or Geometry()
    q, alpha, w = _q_inputs(q, alpha, w, geo)
    return _contact(q, alpha, w, leg, rim, geo, False, radius)[0]


def contact_jacobian(q, alpha, w, leg, *, rim: str = "continuous", radius: float | None = None,
                     geometry: Geometry | None = None) -> np.ndarray:
    """Analytic d(contact point in {R}) / d(theta, beta, gamma), shape (..., 3, 3).

    Replaces the seed's forward-difference Jacobian (seed 2.3) by the exact one: the closed form's
    theta-derivatives are carried through every step (forward mode by hand, :func:`_closed_form`),
    d/dbeta is ``i z`` in the leg plane and d/dgamma is ``R0 Rz(gamma) (e_z x p_M)``.
    """
    geo = geometry or Geometry()
    q, alpha, w = _q_inputs(q, alpha, w, geo)
    return _contact(q, alpha, w, leg, rim, geo, True, radius)[1]


# ---------------------------------------------------------------- inverse kinematics
class IKInfo(NamedTuple):
    """What :func:`ik` did, per target: iterations used and final position error (m)."""

    iterations: np.ndarray
    error: np.ndarray


def _initial_guesses(target, alpha, w, leg, rim, geo, radius, count: int = 3):
    """Geometric starts, best first: gamma exact from the leg-plane offset, theta from a grid, beta from
    the direction. Returns (count, ..., 3).

    Solves the out-of-plane part exactly (in {M}, ``|(x_M, y_M)| = |(d_wheel +- w, y_L)|``), then takes the
    local minima over a 64-point theta grid of ``| |z(theta, alpha)| - |target in plane| |`` (several
    theta can give the same radius), best first; beta rotates z onto the target.
    """
    _, side, _ = _leg(leg)
    t_M = np.einsum("ji,...j->...i", _R_0[side], target - module_origin(leg, geo))
    sw, sx = (1.0, -1.0) if side == "L" else (-1.0, 1.0)
    a = geo.d_wheel + sw * w
    r2 = t_M[..., 0] ** 2 + t_M[..., 1] ** 2
    y = -np.sqrt(np.maximum(r2 - a * a, 0.0))
    gamma = np.angle(np.exp(1j * (np.arctan2(t_M[..., 1], t_M[..., 0]) - np.arctan2(y, a))))
    tgt = sx * t_M[..., 2] + 1j * y
    grid = np.linspace(THETA_MIN, THETA_MAX, 64)
    shape = target.shape[:-1]
    th = grid.reshape((64,) + (1,) * len(shape))
    if rim == "continuous":
        z, _ = _rim_continuous(th, 0.0, alpha[None], geo, geo.R if radius is None else radius, False)
    else:
        z, _ = _rim_seed(th, 0.0, alpha[None], geo, geo.R + FOOT_OFFSET if radius is None else radius, False)
    res = np.abs(np.abs(z) - np.abs(tgt)[None])
    pad = np.concatenate([np.full((1,) + res.shape[1:], np.inf), res, np.full((1,) + res.shape[1:], np.inf)])
    local = (res <= pad[:-2]) & (res <= pad[2:])
    order = np.argsort(np.where(local, res, np.inf + res), axis=0, kind="stable")[:count]
    out = []
    for k in order:
        zk = np.take_along_axis(z, k[None], 0)[0]
        out.append(np.stack([grid[k], np.angle(tgt / zk), gamma], -1))
    return np.stack(out)


def ik(target, alpha=0.0, w=0.0, leg="FL", q0=None, *, method: str = "damped", rim: str = "continuous",
       tol: float = 1e-12, max_iter: int | None = None, delta: float = 1e-6, radius: float | None = None,
       geometry: Geometry | None = None, return_mask: bool = False, return_info: bool = False):
    """(theta, beta, gamma) placing the rim point (alpha, w) of ``leg`` at ``target`` in {R} (seed 2).

    Methods:
        ``"seed"``: seed 2.2-2.3 as printed: Gauss-Newton ``dq = -(J^T J)^{-1} J^T E`` with the
        forward-difference Jacobian ``(FK(q + delta e_k) - FK(q)) / delta``, full steps, no bounds
        (the baseline). Fails if J^T J is singular, theta leaves the linkage's domain, or it does not
        converge in ``max_iter`` (default 100) iterations.
        ``"damped"`` (default): the same iteration with the analytic Jacobian (:func:`contact_jacobian`),
        Levenberg-Marquardt damping when a full step does not reduce ``|E|``, and theta projected onto
        [17 deg, 160 deg] (default ``max_iter`` 60); once ``|E| <= tol`` one more step is taken if it
        lowers ``|E|`` (so the result is usually at rounding level, not just under ``tol``).

    Both start from ``q0`` if given, else from a geometric guess (gamma exact, theta from a grid; not the
    lab's beta = 90 deg default): the seed method from the best guess only, the damped method restarts
    a failed target from the next two local minima of the grid (several theta can give the same radius).
    Converged means ``|E| <= tol`` (m). ``info.iterations`` counts every iteration, restarts included.

    Args:
        target: (..., 3) points in {R}; alpha (rad), w (m) broadcast with its leading shape.
        q0: (..., 3) start (theta, beta, gamma).
        return_mask: also return the mask of converged targets (batch).
        return_info: also return an :class:`IKInfo` (iterations, final error per target).

    Raises:
        UnreachableError: single target not reached (``closest`` = the point reached).
        InvalidInputError: NaN/inf or wrong shapes, alpha or w out of range.
    """
    geo = geometry or Geometry()
    target = as_input(target, "target", (3,))
    alpha, w = as_input(alpha, "alpha"), as_input(w, "w")
    try:
        shape = np.broadcast_shapes(target.shape[:-1], alpha.shape, w.shape)
    except ValueError as exc:
        raise InvalidInputError(f"inputs do not broadcast together: target{target.shape}, alpha{alpha.shape}, w{w.shape}") from exc
    scalar = shape == ()
    target = np.broadcast_to(target, shape + (3,)).astype(float)
    alpha, w = np.broadcast_to(alpha, shape).astype(float), np.broadcast_to(w, shape).astype(float)
    _check_alpha(alpha)
    _check_w(w, geo)
    if rim not in ("continuous", "seed"):
        raise InvalidParameterError(f"rim must be 'continuous' or 'seed', got {rim!r}")
    if method not in ("seed", "damped"):
        raise InvalidParameterError(f"method must be 'seed' or 'damped', got {method!r}")
    _leg(leg)
    if q0 is None:
        starts = _initial_guesses(target, alpha, w, leg, rim, geo, radius, 1 if method == "seed" else 3)
    else:
        starts = np.array(np.broadcast_to(as_input(q0, "q0", (3,)), shape + (3,)), dtype=float)[None]
        _check_theta(starts[..., 0], "theta (q0[..., 0])")
    n = int(np.prod(shape, dtype=int))
    starts = starts.reshape(-1, n, 3)
    target, alpha, w = target.reshape(n, 3), alpha.reshape(n), w.reshape(n)
    solver = _ik_seed if method == "seed" else _ik_damped
    q, it, err, ok = solver(starts[0].copy(), target, alpha, w, leg, rim, geo, radius, tol, max_iter, delta)
    for start in starts[1:]:  # restart the failures from the next geometric guess
        f = np.flatnonzero(~ok)
        if f.size == 0:
            break
        qf, itf, errf, okf = solver(start[f].copy(), target[f], alpha[f], w[f], leg, rim, geo, radius, tol,
                                    max_iter, delta)
        it[f] += itf
        take = okf | (errf < err[f])
        q[f[take]], err[f[take]], ok[f] = qf[take], errf[take], okf
    with np.errstate(invalid="ignore"):
        inside = (q[:, 0] >= THETA_MIN - 1e-12) & (q[:, 0] <= THETA_MAX + 1e-12)
    ok &= inside & np.all(np.isfinite(q), axis=1)
    q = q.reshape(shape + (3,))
    it, err, ok = it.reshape(shape), err.reshape(shape), ok.reshape(shape)
    closest = None
    if scalar and not bool(ok):
        with np.errstate(invalid="ignore"):
            qc = q.copy()
            qc[0] = np.clip(qc[0], THETA_MIN, THETA_MAX)
            closest = _contact(qc, alpha.reshape(()), w.reshape(()), leg, rim, geo, False, radius)[0] if np.all(np.isfinite(qc)) else None
    q_out = np.where(ok[..., None], q, np.nan)
    info = IKInfo(it, err)

    def error():
        return UnreachableError(
            f"target {np.asarray(target).reshape(3).tolist()} not reached for leg {leg!r} (alpha={float(alpha[0])!r}, "
            f"w={float(w[0])!r}) with method {method!r}: final error {float(err):.3e} m after {int(it)} iterations "
            f"(tolerance {tol:.1e} m, theta in [17, 160] deg); closest point reached {None if closest is None else closest.tolist()}",
            target=np.asarray(target).reshape(3),
            closest=closest,
        )

    out = finish(q_out, ok, scalar, return_mask, error)
    if return_info:
        return (*out, info) if isinstance(out, tuple) else (out, info)
    return out


def _fk_flat(q, alpha, w, leg, rim, geo, radius, jac):
    return _contact(q, alpha, w, leg, rim, geo, jac, radius)


def _ik_seed(q, target, alpha, w, leg, rim, geo, radius, tol, max_iter, delta):
    max_iter = 100 if max_iter is None else max_iter
    n = q.shape[0]
    it = np.zeros(n, dtype=int)
    active = np.ones(n, dtype=bool)
    ok = np.zeros(n, dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = _fk_flat(q, alpha, w, leg, rim, geo, radius, False)[0]
        err = np.linalg.norm(p - target, axis=1)
        for _ in range(max_iter + 1):
            ok |= active & (err <= tol)
            active &= ~ok & np.isfinite(err)
            if not np.any(active) or np.all(it[active] >= max_iter):
                break
            a = np.flatnonzero(active & (it < max_iter))
            qa, pa = q[a], p[a]
            E = pa - target[a]
            J = np.empty((a.size, 3, 3))
            for k in range(3):
                qk = qa.copy()
                qk[:, k] += delta
                J[:, :, k] = (_fk_flat(qk, alpha[a], w[a], leg, rim, geo, radius, False)[0] - pa) / delta
            JtJ = np.einsum("nji,njk->nik", J, J)
            JtE = np.einsum("nji,nj->ni", J, E)
            good = np.abs(np.linalg.det(JtJ)) > 1e-300
            dq = np.full((a.size, 3), np.nan)
            if np.any(good):
                dq[good] = -np.linalg.solve(JtJ[good], JtE[good][..., None])[..., 0]
            q[a] = qa + dq
            it[a] += 1
            p[a] = _fk_flat(q[a], alpha[a], w[a], leg, rim, geo, radius, False)[0]
            err[a] = np.linalg.norm(p[a] - target[a], axis=1)
    return q, it, err, ok


def _ik_damped(q, target, alpha, w, leg, rim, geo, radius, tol, max_iter, delta):
    max_iter = 60 if max_iter is None else max_iter
    n = q.shape[0]
    q = q.copy()
    q[:, 0] = np.clip(q[:, 0], THETA_MIN, THETA_MAX)
    it = np.zeros(n, dtype=int)
    mu = np.full(n, 1e-16)
    p, J = _fk_flat(q, alpha, w, leg, rim, geo, radius, True)
    err = np.linalg.norm(p - target, axis=1)
    active = err > tol
    polish = ~active  # one more (kept only if it helps) Gauss-Newton step after reaching tol
    for _ in range(max_iter):
        a = np.flatnonzero(active)
        if a.size == 0:
            break
        E = p[a] - target[a]
        Ja = J[a]
        JtJ = np.einsum("nji,njk->nik", Ja, Ja)
        JtE = np.einsum("nji,nj->ni", Ja, E)
        scale = np.maximum(np.trace(JtJ, axis1=1, axis2=2), 1e-300)
        best_q, best_err = q[a].copy(), err[a].copy()
        improved = np.zeros(a.size, dtype=bool)
        # Try Gauss-Newton first (mu tiny), then damp harder where the error does not drop.
        lam = mu[a].copy()
        for _trial in range(10):
            todo = ~improved
            if not np.any(todo):
                break
            t = np.flatnonzero(todo)
            M = JtJ[t] + (lam[t] * scale[t])[:, None, None] * np.eye(3)
            dq = -np.linalg.solve(M, JtE[t][..., None])[..., 0]
            qn = q[a[t]] + dq
            qn[:, 0] = np.clip(qn[:, 0], THETA_MIN, THETA_MAX)
            pn = _fk_flat(qn, alpha[a[t]], w[a[t]], leg, rim, geo, radius, False)[0]
            en = np.linalg.norm(pn - target[a[t]], axis=1)
            better = en < err[a[t]]
            improved[t[better]] = True
            best_q[t[better]], best_err[t[better]] = qn[better], en[better]
            lam[t[~better]] *= 100.0
            lam[t[better]] = np.maximum(lam[t[better]] / 10.0, 1e-16)
        q[a], err[a], mu[a] = best_q, best_err, lam
        it[a] += 1
        p[a], J[a] = _fk_flat(q[a], alpha[a], w[a], leg, rim, geo, radius, True)
        done = err[a] <= tol
        active[a] = (~done | ~polish[a]) & improved
        polish[a] |= done
    return q, it, err, err <= tol
