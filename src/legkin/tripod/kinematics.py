"""Analytic kinematics of the parallel tripod (seed 000): leg transforms, platform pose, IK, A_u, FK, workspace.

Conventions:
    * Base frame: origin at the base centre O; the legs are placed at the angles ``eta_K`` about the x axis.
      At the home pose the platform centre is E = (-L, 0, 0) with ``L = d sqrt(2 (1 - cos alpha))`` (eq 18).
    * Leg K (joints ``K_q1..K_q4``, ``eta = eta_K``), with ``P(eta) = Rx(eta) Rz(pi)``::

          T_K = P(eta) Rz(q1) Ry(q2) [Tr(0, d, 0) Rx(-alpha) Tr(0, -d, 0)] Ry(q3) Rz(-q4) Rx(pi - eta)

    * Platform orientation ``R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x)`` (eq 5) with
      ``alpha_x = atan2(s_y s_z, c_y + c_z)`` (eq 15, two-argument form: see :func:`alpha_x`).
    * Joint vectors of the whole mechanism are ordered A_q1..A_q4, B_q1..B_q4, C_q1..C_q4 (the Pinocchio order).
    * Branch: q_K2 in (0, pi), q_K3 = q_K2, q_K4 = q_K1 (the constant-velocity assembly); q_K1 in (-pi, pi].
    * Angles in radians, lengths in metres. Functions broadcast over leading dimensions; a scalar input
      raises on failure, a batch returns NaN where an item fails (``return_mask=True`` adds the mask).
"""

from __future__ import annotations

import math
import numbers
import types
from dataclasses import dataclass
from typing import NamedTuple, Sequence

import numpy as np

from ..errors import (
    AssemblyModeError,
    ConvergenceError,
    InvalidInputError,
    InvalidParameterError,
    SingularityError,
    UnreachableError,
)
from .spec import SPEC as _SPEC
from .._batch import real_number as _number, as_angles, as_input
from .._kernels import OK, batch_kernel, kernel, prange

__all__ = [
    "LEGS",
    "ETA",
    "D",
    "ALPHA",
    "leg_transform",
    "leg_transform_cv",
    "alpha_x",
    "platform_rotation",
    "platform_position",
    "platform_axis",
    "orientation_from_axis",
    "ik",
    "actuation_jacobian",
    "fk",
    "workspace",
    "Workspace",
    "MODES",
    "HOME_MODE",
    "DET_GUARD",
    "GAIN_GUARD",
]

LEGS = ("A", "B", "C")
#: Default leg placement angles (rad) and geometry (the registry defaults).
ETA = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)
D = 0.05
ALPHA = math.pi / 3.0
#: Below this, ``1 + c_y c_z`` counts as zero: the platform axis is turned back onto -x (E undefined).
SINGULAR_TOL = 1e-12
#: Below this, ``1 - |cos q_K2|`` counts as zero: leg K is on the workspace boundary, sin q_K2 = 0.
BOUNDARY_TOL = 1e-12
#: Assembly modes on the constant-velocity branch (q_K3 = q_K2, q_K4 = q_K1): a string of four signs, the side of
#: the platform centre E along x (``-``: E_x < 0) then the signs of sin q_A2, sin q_B2, sin q_C2. Every
#: orientation has one configuration per mode (E = -+L b/|b|, q_K2 = +-acos(cos q_K2)), all realising the
#: same platform rotation; the motors differ. See docs/tripod.md, "IK contract".
MODES = tuple(c + a + b + k for c in "-+" for a in "+-" for b in "+-" for k in "+-")
#: The mode the mechanism is built in: that of its SRDF reference pose ``home`` (E = (-L, 0, 0), q_K2 = pi/2).
HOME_MODE = "-+++"
#: Actuation-singularity guard: :func:`ik` and :func:`fk` refuse motor angles whose planes (see
#: :func:`_initial_guess`) have ``|det M| < DET_GUARD`` (unit normals). There the motors fix the pose only
#: to ~2e-16 / |det M| rad, and on det M = 0 they fit two poses (the planes share a line that cuts the sphere
#: |E| = L twice; at tangency the two merge and A_u loses rank): fk could not reproduce ik's answers to 1e-9.
DET_GUARD = 1e-6
#: Motor-gain guard: :func:`ik` and :func:`fk` refuse poses where ``|A_u|_F > GAIN_GUARD``. The motors are then so
#: sensitive to the orientation that its float representation fixes them only to ~ulp |A_u| > 1e-8 rad and the
#: Gauss-Newton of fk stalls on that noise. |A_u|_F <= sqrt(3/2) / (min_K |sin q_K2| sqrt(1 + c_y c_z)) (measured),
#: so this happens only where a leg is within ~1e-5 of its boundary next to the flip: near the points where the
#: workspace boundary meets the flip (alpha <= pi/3, e.g. six directions at the default alpha). Away from them
#: |A_u|_F stays below ~1e8 down to the singular tolerances (measured max 8e7 at alpha = pi/4).
GAIN_GUARD = 1e8


# ------------------------------------------------------------------------------------------ helpers
def _mode_signs(mode: str):
    """``None`` for :data:`HOME_MODE`, else ``(e, s)``: e = -1/+1 the side of E, s (3,) the signs of sin q_K2."""
    if mode == HOME_MODE:
        return None
    return (-1.0 if mode[0] == "-" else 1.0), np.array([-1.0 if c == "-" else 1.0 for c in mode[1:]])


def _in_range(value, name: str, lo: float, hi: float, valid: str, *, lo_open=False, hi_open=False) -> float:
    x = _number(value, name, valid)
    bad = math.isnan(x) or x < lo or x > hi or (lo_open and x == lo) or (hi_open and x == hi)
    if bad:
        raise InvalidParameterError(f"{name}={value!r} is out of range: must be in {valid}")
    return x


def _integer(value, name: str, lo: int, hi: int) -> int:
    ok = isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_))
    if not ok:
        raise InvalidParameterError(f"{name} must be an integer, got {value!r}; valid range [{lo}, {hi}]")
    if not lo <= int(value) <= hi:
        raise InvalidParameterError(f"{name}={value!r} is out of range: must be in [{lo}, {hi}]")
    return int(value)


def _flag(value, name: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidParameterError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _checked_mode(mode, allow_all: bool = False) -> str:
    if isinstance(mode, str) and (mode in MODES or (allow_all and mode == "all")):
        return mode
    extra = ', or "all"' if allow_all else ""
    raise InvalidParameterError(f"mode={mode!r} is not valid: must be one of {', '.join(MODES)}{extra}")


def _angle(value, name: str) -> float:
    return _in_range(value, name, -math.inf, math.inf, "(-inf, inf) (rad), finite", lo_open=True, hi_open=True)


def _params(d: float, alpha: float, eta: Sequence[float] | None = None) -> tuple[float, float, np.ndarray]:
    """Validate the geometry against the registry's ranges (:data:`legkin.tripod.spec.SPEC`); return
    (d, alpha, eta as (3,))."""
    out = []
    for name, value in (("d", d), ("alpha", alpha)):
        param = _SPEC.params[name]
        out.append(param.check(name, _number(value, name, param.range_text)))
    if eta is None:
        eta_arr = np.asarray(ETA, dtype=float)
    else:
        try:
            eta_arr = as_input(eta, "eta", (3,))
        except InvalidInputError:
            eta_arr = None
        if eta_arr is None or eta_arr.shape != (3,):
            raise InvalidParameterError(f"eta must be three finite real angles (eta_A, eta_B, eta_C), got {eta!r}")
    return out[0], out[1], eta_arr


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


# ------------------------------------------------------------------------------------------ legs
def leg_transform(q, eta: float, d: float = D, alpha: float = ALPHA) -> np.ndarray:
    """Placement of K_ee in the base frame for any four joint values of one leg (open chain).

    Math (the chain of the URDF, checked against Pinocchio):
    ``R = Rx(eta) Rz(pi) Rz(q1) Ry(q2) Rx(-alpha) Ry(q3) Rz(-q4) Rx(pi - eta)`` and, since joints 3 and 4
    pass through E, ``p = d Rx(eta) (-h1, -h2, h3)`` with ``(h1, h2, h3) = Rz(q1) (s2 s_alpha, 1 - c_alpha,
    c2 s_alpha)``: the last column of seed eq (10) with eq (12), which holds for every q3, q4.
    On the constant-velocity branch (q3 = q2, q4 = q1) the rotation equals seed eqs (10)-(11), with T33
    read as ``+2 c_eta s_eta g4`` (the seed prints a minus): see :func:`leg_transform_cv`. The seed's
    Appendix A (the general form) is garbled in several entries and uses another frame convention,
    so it is not transcribed; the product above replaces it.

    Args:
        q: joint values (..., 4) = (q1, q2, q3, q4) of the leg.
        eta: the leg's placement angle eta_K.
        d, alpha: geometry (m, rad).

    Returns:
        (..., 4, 4) homogeneous transforms.
    """
    if not (d is D and alpha is ALPHA):
        d, alpha, _ = _params(d, alpha)
    eta = _angle(eta, "eta")
    G = _geo(d, alpha, None)[1] if type(d) is float and type(alpha) is float else _geo(float(d), float(alpha), None)[1]
    if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (4,):
        T = np.empty((4, 4))
        if _k_leg_transform(q[0], q[1], q[2], q[3], eta, alpha, G, T) == OK:
            return T
    q = as_input(q, "q", (4,))
    shape = q.shape[:-1]
    rows = np.ascontiguousarray(q.reshape(-1, 4))
    T = np.empty((rows.shape[0], 4, 4))
    _pick(_k_leg_transform_batch, rows.shape[0], "closed")(rows, eta, alpha, G, T)
    return T.reshape(shape + (4, 4))


def leg_transform_cv(q1, q2, eta: float, d: float = D, alpha: float = ALPHA) -> np.ndarray:
    """Seed eqs (10)-(12): placement of K_ee on the constant-velocity branch (q3 = q2, q4 = q1).

    ``T11 = -g1``, ``T21 = -s_eta g2 + c_eta g3``, ``T31 = s_eta g3 + c_eta g2``, ``T12 = s_eta g2 - c_eta g3``,
    ``T22 = -2 c_eta s_eta g4 + c_eta^2 g5 + s_eta^2 g6``, ``T32 = T23 = c_eta s_eta g7 + (c_eta^2 - s_eta^2) g4``,
    ``T13 = -c_eta g2 - s_eta g3``, ``T33 = +2 c_eta s_eta g4 + s_eta^2 g5 + c_eta^2 g6`` (**sign corrected**:
    eq (10) prints ``-2 c_eta s_eta g4``; with the minus the matrix is not a rotation for eta != 0 mod pi/2),
    ``T14 = -d h1``, ``T24 = -d (c_eta h2 + s_eta h3)``, ``T34 = d (c_eta h3 - s_eta h2)``, with g1..g7 of
    eq (11) and h1..h3 of eq (12), transcribed as printed.

    Args:
        q1, q2: joint values of the leg (broadcast together).
        eta: the leg's placement angle.
        d, alpha: geometry.

    Returns:
        (..., 4, 4) homogeneous transforms.
    """
    if not (d is D and alpha is ALPHA):
        d, alpha, _ = _params(d, alpha)
    eta = _angle(eta, "eta")
    G = _geo(d, alpha, None)[1] if type(d) is float and type(alpha) is float else _geo(float(d), float(alpha), None)[1]
    if isinstance(q1, float) and isinstance(q2, float) and math.isfinite(q1) and math.isfinite(q2):
        T = np.empty((4, 4))
        _k_leg_transform_cv(float(q1), float(q2), eta, G, T)
        return T
    q1, q2 = as_angles(q1, q2, names=("q1", "q2"))
    shape = q1.shape
    T = np.empty((q1.size, 4, 4))
    _pick(_k_leg_transform_cv_batch, q1.size, "closed")(np.ascontiguousarray(q1).reshape(-1), np.ascontiguousarray(q2).reshape(-1), eta, G, T)
    return T.reshape(shape + (4, 4))


# ------------------------------------------------------------------------------------------ platform
def alpha_x(alpha_y, alpha_z) -> np.ndarray:
    """Seed eq (15), two-argument form: ``alpha_x = atan2(s_y s_z, c_y + c_z)``.

    Departure from the seed: eq (15) prints ``arctan(s_y s_z / (c_y + c_z))``, which is right only when
    ``c_y + c_z > 0``; elsewhere it lands on the wrong branch (off by pi) and the orientation it gives is
    not the one the legs produce (rotation error up to 2 in matrix entries, see docs/tripod.md).
    The value is undefined at ``c_y + c_z = 0 = s_y s_z``, which is the singular set 1 + c_y c_z = 0.
    """
    if isinstance(alpha_y, float) and isinstance(alpha_z, float) and math.isfinite(alpha_y) and math.isfinite(alpha_z):
        return np.float64(_k_alpha_x(float(alpha_y), float(alpha_z)))
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    if not ay.ndim:
        return np.float64(_k_alpha_x(float(ay), float(az)))
    out = np.empty(ay.size)
    _pick(_k_alpha_x_batch, ay.size, "closed")(np.ascontiguousarray(ay).reshape(-1), np.ascontiguousarray(az).reshape(-1), out)
    return out.reshape(ay.shape)


def platform_rotation(alpha_y, alpha_z) -> np.ndarray:
    """Seed eqs (5) and (15): ``R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x(alpha_y, alpha_z))``, shape (..., 3, 3).

    This is the zero-torsion (constant-velocity) family: R is the rotation by the tilt angle theta about an
    axis perpendicular to x (the mechanism's base axis), where ``cos theta = c_y c_z``.
    """
    return _uv_closed(3, alpha_y, alpha_z, (3, 3), None)


def platform_axis(alpha_y, alpha_z) -> np.ndarray:
    """The platform axis ``R e_x = (c_z c_y, s_z c_y, -s_y)`` (first column of eq 5), shape (..., 3)."""
    return _uv_closed(1, alpha_y, alpha_z, (3,), None)


def orientation_from_axis(axis) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`platform_axis` on ``alpha_y`` in [-pi/2, pi/2]: ``(-asin(r3), atan2(r2, r1))``.

    The platform orientation is fixed by its axis (zero torsion), so this also inverts
    :func:`platform_rotation`; at ``c_y = 0`` (axis = -+z) alpha_z is arbitrary and 0 is returned.
    """
    if type(axis) is np.ndarray and axis.dtype == np.float64 and axis.shape == (3,):
        st, ay, az = _k_orientation_from_axis(axis[0], axis[1], axis[2])
        if st == OK:
            return np.float64(ay), np.float64(az)
    r = as_input(axis, "axis", (3,))
    shape = r.shape[:-1]
    rows = np.ascontiguousarray(r.reshape(-1, 3))
    out, status = np.empty((rows.shape[0], 2)), np.empty(rows.shape[0], dtype=np.int64)
    _pick(_k_orientation_from_axis_batch, rows.shape[0], "closed")(rows, out, status)
    if not (status == OK).all():
        raise InvalidInputError("axis must be a nonzero vector (every row)")
    if not shape:
        return np.float64(out[0, 0]), np.float64(out[0, 1])
    return out[:, 0].reshape(shape), out[:, 1].reshape(shape)


def platform_position(alpha_y, alpha_z, d: float = D, alpha: float = ALPHA) -> np.ndarray:
    """Platform centre E for the orientation (alpha_y, alpha_z), from Appendix B (eqs 64a-64d), shape (..., 3).

    Derivation. With ``r = R e_x = (c_z c_y, s_z c_y, -s_y)`` and ``b = e_x + r = (1 + c_y c_z, s_z c_y, -s_y)``,
    ``|b|^2 = 2 (1 + c_y c_z)``. The seed's identities give the magnitudes:
    (64a) ``|E| = L``; (64b) ``x^2 = L^2 (1 + c_y c_z) / 2 = L^2 b_x^2 / |b|^2``;
    (64c) ``(y + z)^2 = L^2 (s_y - c_y s_z)^2 / (2 (1 + c_y c_z)) = L^2 (b_y + b_z)^2 / |b|^2``;
    (64d) ``(y - z)^2 = L^2 (b_y - b_z)^2 / |b|^2``. So each of x, y + z, y - z equals +-L times the
    matching component of ``b / |b|``: E lies on the bisector of the base axis and the platform axis
    (the symmetry plane of a constant-velocity joint). The signs, which (64) squares away, are all the same
    and negative, fixed at the home pose (E = (-L, 0, 0), so x < 0) and by continuity on the workspace
    (E cannot cross the origin since |E| = L > 0):

        ``E = -L b / |b| = -L (1 + c_y c_z, s_z c_y, -s_y) / sqrt(2 (1 + c_y c_z))``,
        ``L = d sqrt(2 (1 - c_alpha))`` (eq 18).

    Checked against Pinocchio's platform frame at configurations from :func:`ik` (``legkin check tripod``).
    Undefined on ``1 + c_y c_z = 0`` (NaN there).
    """
    G = _geo(d, alpha, None)[1]
    return _uv_closed(2, alpha_y, alpha_z, (3,), G)


# ------------------------------------------------------------------------------------------ inverse kinematics
#: Cyclic index shifts K -> K+1 and K -> K+2 (mod 3) over the legs: cross products without np.cross.
_NEXT = np.array([1, 2, 0])
_PREV = np.array([2, 0, 1])


class _Geometry(NamedTuple):
    """Constants of one geometry, computed once per public call (not per iteration / per item)."""

    d: float
    ce: np.ndarray  # cos eta_K, (3,)
    se: np.ndarray  # sin eta_K, (3,)
    ca: float  # cos alpha
    sa: float  # sin alpha
    k: float  # 1 - cos alpha
    k2: float  # (1 - cos alpha)^2
    opc: float  # 1 + cos alpha
    dsa: float  # d sin alpha
    minus_l: float  # -L = -d sqrt(2 (1 - cos alpha)) (eq 18)
    tan_half: float  # tan(alpha / 2)
    ce_n: np.ndarray  # cos eta_{K+1} (legs cyclic: A -> B -> C -> A), (3,)
    ce_p: np.ndarray  # cos eta_{K+2}
    se_n: np.ndarray  # sin eta_{K+1}
    se_p: np.ndarray  # sin eta_{K+2}
    w: np.ndarray  # sin(eta_{K+2} - eta_{K+1})


def _geometry(d: float, alpha: float, eta: np.ndarray) -> _Geometry:
    """The constants of an already validated geometry (see :func:`_params`)."""
    ca, sa = math.cos(alpha), math.sin(alpha)
    ce, se = np.cos(eta), np.sin(eta)
    return _Geometry(
        d, ce, se, ca, sa, 1 - ca, (1 - ca) ** 2, 1 + ca, d * sa, -d * math.sqrt(2.0 * (1.0 - ca)),
        math.tan(alpha / 2.0), ce[_NEXT], ce[_PREV], se[_NEXT], se[_PREV], np.sin(eta[_PREV] - eta[_NEXT]),
    )


def _one_plus_cc(cy, sy, cz, sz):
    """``1 + c_y c_z`` without cancellation near the flip (c_y c_z -> -1), from the cos / sin of u.

    Where ``c_y c_z < -1/2`` one factor is positive and one negative; with ``a >= 0 > b`` (a, b the cosines, sa, sb
    the sines) ``1 + a b = (1 + b) + (-b)(1 - a) = sb^2 / (1 - b) - b sa^2 / (1 + a)``, a sum of two
    non-negative terms, each to a few ulps (the direct form loses ``1e-16 / (1 + c_y c_z)`` relative accuracy
    there). Elsewhere the direct form (bit for bit as before).
    """
    p = cy * cz
    out = 1.0 + p
    near = np.asarray(p < -0.5)
    if near.any():
        pos = cy >= 0.0
        a, b = np.where(pos, cy, cz), np.where(pos, cz, cy)
        sa, sb = np.where(pos, sy, sz), np.where(pos, sz, sy)
        out = np.where(near, sb * sb / (1.0 - b) - b * (sa * sa) / (1.0 + a), out)
    return out


def _ik_eval(cy, sy, cz, sz, g: _Geometry, signs=None, with_sc: bool = False):
    """Unchecked seed eqs (98), (102) on a trailing leg axis (call under ``np.errstate(invalid, divide)``).

    Args:
        cy, sy, cz, sz: cos / sin of alpha_y, alpha_z, shape (..., 1).
        g: the geometry's constants.
        signs: ``None`` for the home assembly mode, else ``(e, s)`` of :func:`_mode_signs`: the platform
            centre is ``E = e L b / |b|`` and ``q_K2 = s_K acos(cos q_K2)``.

    Returns:
        ``(q1, q2, cos q2, sin q2)`` per leg (..., 3) and ``1 + c_y c_z`` (..., 1); NaN where undefined.
        The platform centre E is :func:`platform_position` (same operations, so the same bits) in the home mode.
        With ``with_sc`` also ``(sin q1, cos q1)`` (..., 3), the arguments of the atan2 (unit norm to rounding).
    """
    nb2 = _one_plus_cc(cy, sy, cz, sz)
    lead = g.minus_l if signs is None else -signs[0] * g.minus_l  # e L, e = -1 at home
    scale = np.where(nb2 > SINGULAR_TOL, lead / np.sqrt(2.0 * nb2), np.nan)
    x, y, z = nb2 * scale, sz * cy * scale, -sy * scale  # E = e L b / |b|, b = (1 + c_y c_z, s_z c_y, -s_y)
    c2 = (g.ce * z - g.se * y) / g.dsa  # eq (98)
    q2 = np.arccos(c2)  # branch q2 in (0, pi); NaN where |c2| > 1
    if signs is not None:
        q2 = signs[1] * q2
    s2 = np.sin(q2)
    w = -(g.ce * y + g.se * z)
    s2sa = s2 * g.sa
    det = g.d * (g.k2 + s2sa**2)  # corrected determinant (d^2 (...) with 1/d folded in)
    sn, cn = (g.k * x + s2sa * w) / det, (-s2sa * x + g.k * w) / det
    q1 = np.arctan2(sn, cn)  # eq (102)
    if with_sc:
        return q1, q2, c2, s2, nb2, sn, cn
    return q1, q2, c2, s2, nb2


def _inside(c2: np.ndarray, nb2: np.ndarray) -> np.ndarray:
    """Success mask (..., 1) of :func:`_ik_eval`: not singular, every leg reached and 1 - |cos q_K2| > BOUNDARY_TOL.

    Equal to ``~sing & ~unreachable.any(-1) & ~leg_sing.any(-1)`` of :func:`_ik_status` (c2 is finite off
    the singular set), in fewer operations.
    """
    return (nb2 > SINGULAR_TOL) & (1.0 - np.maximum.reduce(np.abs(c2), axis=-1, keepdims=True) > BOUNDARY_TOL)


def _ik_core(ay: np.ndarray, az: np.ndarray, d: float, alpha: float, eta: np.ndarray):
    """Unchecked vectorised IK: joints (..., 3, 4), cos q_K2 (..., 3), 1 + c_y c_z (...)."""
    ay, az = np.asarray(ay)[..., None], np.asarray(az)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        q1, q2, c2, _, nb2 = _ik_eval(np.cos(ay), np.sin(ay), np.cos(az), np.sin(az), _geometry(d, alpha, eta))
    return np.stack([q1, q2, q2, q1], axis=-1), c2, nb2[..., 0]


def _ik_status(c2: np.ndarray, one_cc: np.ndarray):
    """Masks: (singular platform (...), unreachable (..., 3), leg singular (..., 3))."""
    sing = one_cc <= SINGULAR_TOL
    with np.errstate(invalid="ignore"):
        gap = 1.0 - np.abs(c2)
        unreachable = ~sing[..., None] & (gap < -BOUNDARY_TOL)
        leg_sing = ~sing[..., None] & (np.abs(gap) <= BOUNDARY_TOL)
    return sing, unreachable, leg_sing


def _ik_error(ay, az, c2, sing, unreachable, leg_sing) -> Exception:
    where = f"(alpha_y, alpha_z) = ({float(ay):.17g}, {float(az):.17g})"
    if sing:
        return SingularityError(
            f"{where} is singular: 1 + cos(alpha_y) cos(alpha_z) = 0 (platform axis turned back onto -x; "
            "the platform centre is undefined)"
        )
    for k, leg in enumerate(LEGS):
        if unreachable[k]:
            return UnreachableError(
                f"{where} is outside the workspace: leg {leg} would need cos q_{leg}2 = {float(c2[k]):.17g}, "
                "outside [-1, 1] (eq 98)",
                target=(float(ay), float(az)),
            )
    for k, leg in enumerate(LEGS):
        if leg_sing[k]:
            return SingularityError(
                f"{where} is on the workspace boundary: leg {leg} has sin q_{leg}2 = 0 "
                f"(cos q_{leg}2 = {float(c2[k]):.17g}); joints 1 and 3 of the leg are aligned"
            )
    return SingularityError(f"{where}: inverse kinematics failed")  # pragma: no cover


def _modes_sel(mode: str):
    """The kernels' mode arrays (homes, es, ss) for one mode or ``"all"``."""
    if mode == "all":
        return _MODE_HOME, _MODE_E, _MODE_S
    j = _MODE_INDEX[mode]
    return _MODE_HOME[j:j + 1], _MODE_E[j:j + 1], _MODE_S[j:j + 1]


def _ik_run(ay: np.ndarray, az: np.ndarray, G: np.ndarray, mode: str):
    """The ik batch kernel on broadcast orientations: q (shape, m, 12), aux (shape, m, 6), status (shape, m)."""
    shape = ay.shape
    y, z = np.ascontiguousarray(ay, dtype=np.float64).reshape(-1), np.ascontiguousarray(az, dtype=np.float64).reshape(-1)
    homes, es, ss = _modes_sel(mode)
    n, m = y.shape[0], homes.shape[0]
    q, aux, status = np.empty((n, m, 12)), np.empty((n, m, 6)), np.empty((n, m), dtype=np.int64)
    _pick(_k_ik_batch, n * m, "ik")(y, z, G, homes, es, ss, q, aux, status)
    return q.reshape(shape + (m, 12)), aux.reshape(shape + (m, 6)), status.reshape(shape + (m,))


def _ik_mode(ay, az, g: _Geometry, mode: str):
    """Unchecked :func:`ik` in one mode (the kernel): joints (..., 12) (NaN where not ok), ok, cos q_K2 (..., 3),
    1 + c_y c_z (..., 1), det M, motor gain |A_u|_F (exact only where large)."""
    ay, az = np.broadcast_arrays(np.asarray(ay, dtype=float), np.asarray(az, dtype=float))
    q, aux, status = _ik_run(ay, az, _geometry_vector(g), mode)
    aux = aux[..., 0, :]
    return q[..., 0, :], status[..., 0] == OK, aux[..., :3], aux[..., 3:4], aux[..., 4], aux[..., 5]


def _ik_one(ay: float, az: float, G: np.ndarray, mode: str):
    """The ik kernel on one orientation in one mode: joints (12,), aux (6,), status."""
    home, e, s = _MODE_ARGS[mode]
    q, aux = np.empty(12), np.empty(6)
    return q, aux, _k_ik(ay, az, G, home, e, s, q, aux)


def _ik_single_error(ay, az, g: _Geometry, mode: str, c2, nb2, det, gain) -> Exception:
    """The exception of a failed single :func:`ik` call at (ay, az) in ``mode`` (c2 (3,), nb2, det, gain: the
    kernel's aux)."""
    c2, nb2 = np.asarray(c2, dtype=float), np.asarray(nb2, dtype=float).reshape(())
    sing, unreachable, leg_sing = _ik_status(c2, nb2)
    if sing or unreachable.any() or leg_sing.any():
        return _ik_error(ay, az, c2, sing, unreachable, leg_sing)
    G = _geometry_vector(g)
    others = [m for m in MODES if m != mode and _ik_one(float(ay), float(az), G, m)[2] == OK]
    if not gain <= GAIN_GUARD:
        return SingularityError(
            f"(alpha_y, alpha_z) = ({float(ay):.17g}, {float(az):.17g}): its motors are too sensitive to the "
            f"orientation (|A_u| = {float(gain):.3g} > GAIN_GUARD = {GAIN_GUARD:g}: a leg next to its boundary near "
            "the flip); the float orientation fixes them only to ~1e-16 |A_u| rad and fk could not reproduce it"
        )
    return SingularityError(
        f"(alpha_y, alpha_z) = ({float(ay):.17g}, {float(az):.17g}) is an actuation singularity in mode {mode}: "
        f"its motor planes have |det M| = {abs(float(det)):.3g} < DET_GUARD = {DET_GUARD:g}, so the motor angles "
        f"do not determine the pose (fk could not reproduce it to 1e-9 rad); solvable in mode(s) "
        f"{', '.join(others) or 'none'}"
    )


def ik(
    alpha_y,
    alpha_z,
    d: float = D,
    alpha: float = ALPHA,
    eta: Sequence[float] | None = None,
    *,
    mode: str = HOME_MODE,
    return_mask: bool = False,
):
    """Every joint of every leg for the platform orientation (alpha_y, alpha_z): seed eqs (98), (102).

    Per leg K (``c_K = cos eta_K``, ``s_K = sin eta_K``), with E = (x, y, z) from :func:`platform_position`:

    * eq (98): ``cos q_K2 = (c_K z - s_K y) / (d s_alpha)``, ``q_K2 = acos(.) in (0, pi)``;
    * eq (102): ``(s_K1, c_K1) = [[1 - c_alpha, s2 s_alpha], [-s2 s_alpha, 1 - c_alpha]] (x, -(c_K y + s_K z))
      / d~``, ``q_K1 = atan2(s_K1, c_K1)``. Departures: eq (100) misses a ``c1`` in x_ee (correct:
      ``x = d (1 - c_alpha) s1 - d c1 s2 s_alpha``, as (101) uses), and the determinant of (101) is
      ``d^2 ((1 - c_alpha)^2 + (s2 s_alpha)^2)``; (102) is right with ``d~ = d ((1 - c_alpha)^2 + (s2 s_alpha)^2)``;
    * ``q_K3 = q_K2`` and ``q_K4 = q_K1`` (the constant-velocity branch).

    That is the home assembly mode (:data:`HOME_MODE`, that of the SRDF pose ``home``). ``mode`` picks another
    of :data:`MODES`: ``E = +L b / |b|`` when its first sign is ``+``, and ``q_K2 = -acos(.)`` for the legs
    whose sign is ``-`` (eq 102 then uses that sin q_K2). Every mode reaches the same orientations (the
    reachability test |cos q_K2| < 1 does not depend on the mode) with other motors; ``mode="all"`` returns
    every mode, shape (..., 16, 12) in :data:`MODES` order (mask (..., 16)).

    Args:
        alpha_y, alpha_z: platform orientation (rad), broadcast together.
        d, alpha: geometry; eta: (eta_A, eta_B, eta_C) (default 0, 2pi/3, 4pi/3).
        mode: assembly mode, one of :data:`MODES` or ``"all"``.
        return_mask: (batch) also return the success mask.

    Returns:
        (..., 12) joints ordered A_q1..A_q4, B_q1..B_q4, C_q1..C_q4.

    Raises:
        UnreachableError: (scalar) ``|cos q_K2| > 1`` for some leg K (outside the workspace).
        SingularityError: (scalar) ``sin q_K2 = 0`` (workspace boundary), ``1 + c_y c_z = 0``, or an actuation
            singularity: the motors' planes have ``|det M| < DET_GUARD`` (the motors do not determine the pose,
            so :func:`fk` could not reproduce it; the message lists the modes where the pose is solvable).
        InvalidInputError: non-finite, complex or non-broadcastable angles; InvalidParameterError: bad geometry,
            mode or return_mask.
    """
    g, G = _geo(d, alpha, eta)
    if type(mode) is not str or mode != HOME_MODE:
        mode = _checked_mode(mode, allow_all=True)
    if return_mask is not False and return_mask is not True:
        return_mask = _flag(return_mask, "return_mask")
    if isinstance(alpha_y, float) and isinstance(alpha_z, float):
        ay, az = float(alpha_y), float(alpha_z)
    else:
        ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
        if ay.ndim:
            q, aux, status = _ik_run(ay, az, G, mode)
            ok = status == OK
            if mode != "all":
                q, ok = q[..., 0, :], ok[..., 0]
            return (q, ok) if return_mask else q
        ay, az = float(ay), float(az)
    if mode == "all":
        q, aux, status = _ik_run(np.array(ay), np.array(az), G, mode)
        ok = status == OK
        if not ok.any():
            a = aux[0]
            raise _ik_single_error(ay, az, g, HOME_MODE, a[:3], a[3], a[4], a[5])
        return (q, ok) if return_mask else q
    q, aux, st = _ik_one(ay, az, G, mode)
    if st != OK:
        if st == _ST_NONFINITE:
            as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))  # raises InvalidInputError
        raise _ik_single_error(np.float64(ay), np.float64(az), g, mode, aux[:3], aux[3], aux[4], aux[5])
    return (q, np.asarray(True)) if return_mask else q


def actuation_jacobian(
    alpha_y,
    alpha_z,
    d: float = D,
    alpha: float = ALPHA,
    eta: Sequence[float] | None = None,
    *,
    mode: str = HOME_MODE,
    return_mask: bool = False,
):
    """A_u = d(q_A1, q_B1, q_C1) / d(alpha_y, alpha_z): seed Appendix D, eqs (103)-(105), shape (..., 3, 2).

    Row K (``c_K = cos eta_K``, ``s_K = sin eta_K``, ``s_K2 = sin q_K2`` from :func:`ik`,
    ``f_K = tan(alpha/2) (c_K s_y + s_K c_y s_z)``, ``n = 1 + c_y c_z``,
    ``m_K = (1 + c_alpha) s_K2^2 + 1 - c_alpha``, ``p_K = n^2 + (c_K c_y s_z - s_K s_y)^2``)::

        A_K1 = -f_K (c_K (c_y + c_z) - s_K s_y s_z + (c_K c_y - s_K s_y s_z) n) / (2 s_K2 n^2 m_K)
               - (c_K s_y s_z + s_K (c_y + c_z)) / p_K
        A_K2 = -f_K c_y (s_K (c_y + c_z) + c_K s_y s_z + s_K c_z n) / (2 s_K2 n^2 m_K)
               + c_y (c_K (c_y + c_z) - s_K s_y s_z) / p_K

    transcribed as printed (no error found: it matches Pinocchio's closed-loop differential kinematics
    and central differences of :func:`ik`, on the branch q_K2 in (0, pi)). A_u does not depend on d.
    In another assembly ``mode`` (:data:`MODES`) the chain rule through that mode's IK (:func:`_k_jac_general`).
    Undefined where the pose is outside the workspace or singular (NaN / the exceptions of :func:`ik`); the
    actuation-singularity guard of :func:`ik` (:data:`DET_GUARD`) does not apply: A_u is defined there.
    """
    G = _geo(d, alpha, eta)[1]
    if type(mode) is not str or mode != HOME_MODE:
        mode = _checked_mode(mode)
    if return_mask is not False and return_mask is not True:
        return_mask = _flag(return_mask, "return_mask")
    home, e, s = _MODE_ARGS[mode]
    if isinstance(alpha_y, float) and isinstance(alpha_z, float):
        ay, az = float(alpha_y), float(alpha_z)
    else:
        ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
        if ay.ndim:
            shape = ay.shape
            y, z = np.ascontiguousarray(ay).reshape(-1), np.ascontiguousarray(az).reshape(-1)
            n = y.shape[0]
            a, aux, status = np.empty((n, 3, 2)), np.empty((n, 4)), np.empty(n, dtype=np.int64)
            _pick(_k_actuation_jacobian_batch, n, "jac")(y, z, G, home, e, s, a, aux, status)
            a, ok = a.reshape(shape + (3, 2)), (status == OK).reshape(shape)
            return (a, ok) if return_mask else a
        ay, az = float(ay), float(az)
    a, aux = np.empty((3, 2)), np.empty(4)
    st = _k_actuation_jacobian(ay, az, G, home, e, s, a, aux)
    if st != OK:
        if st == _ST_NONFINITE:
            as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))  # raises InvalidInputError
        c2 = aux[:3].copy()
        raise _ik_error(np.float64(ay), np.float64(az), c2, *_ik_status(c2, np.asarray(aux[3])))
    return (a, np.asarray(True)) if return_mask else a


# ------------------------------------------------------------------------------------------ forward kinematics
#: :func:`_initial_guess` intersects the motor planes with the adjugate of M (rows: their unit normals) where
#: |det M| > PLANES_DET_MIN: there sigma_3 = |det M| / (sigma_1 sigma_2) > |det M| / 1.5 > 6.7e-9 (unit rows:
#: sigma_1 <= sqrt 3, sigma_1 sigma_2 <= 3/2), above the 1e-10 sigma_1 cut-off of the pseudo-inverse; below it
#: (nearly parallel planes) the SVD pseudo-inverse with rcond = 1e-10 gives the least-squares intersection.
PLANES_DET_MIN = 1e-8
#: Relative singular-value cut-off of the Gauss-Newton step (that of ``np.linalg.pinv(A_u, rcond=1e-12)``).
STEP_RCOND = 1e-12
#: fk's consistency test accepts ``inconsistency <= max_inconsistency + ROUNDING_FLOOR |A_u|_F``: a pose stored in
#: floats (|u| <= pi, ulp <= 4.4e-16) reproduces its own motors only to ~ulp |A_u|, which exceeds 1e-9 rad
#: where |A_u| is huge (a leg within ~1e-5 of its boundary sin q_K2 = 0 next to the flip: |A_u| ~ 1e9).
#: Elsewhere (|A_u| <= ~1e3) the allowance is below 3e-12 rad.
ROUNDING_FLOOR = 4.0 * math.pi * 2.0**-52


def _initial_guess(qm: np.ndarray, g: _Geometry, with_det: bool = False):
    """Closed-form start for :func:`fk` from the motor angles (n, 3); returns alpha_y, alpha_z as (n, 1).

    Eliminating s_K2 from the two rows of eq (101) leaves one linear equation per motor,
    ``s_K1 x - c_K1 (c_K y + s_K z) = d (1 - c_alpha)``: E lies on three planes with unit normals
    ``n_K = (s_K1, -c_K1 c_K, -c_K1 s_K)``, the rows of M. Their intersection is
    ``E = d (1 - c_alpha) M^-1 (1, 1, 1)`` with ``M^-1 = [n_B x n_C, n_C x n_A, n_A x n_B] / det M``; for
    ``(J, K) = (K+1, K+2)`` the cross product is ``n_J x n_K = (c_J1 c_K1 sin(eta_K - eta_J),
    s_J1 c_K1 s_K - c_J1 s_K1 s_J, c_J1 s_K1 c_J - s_J1 c_K1 c_K)``. Nearly parallel planes
    (``|det M| <= PLANES_DET_MIN``) take the least-squares intersection ``pinv(M)`` instead. Pushed onto the
    sphere |E| = L (eq 64a), E gives the platform axis ``r = R e_x = 2 (e_x . e) e - e_x`` (e = E / |E|: E is
    on the bisector, see :func:`platform_position`), i.e. ``r = (2 E_x^2 - |E|^2, 2 E_x E_y, 2 E_x E_z) / |E|^2``
    (invariant under E -> -E and scaling, so only the direction of ``adj(M) (1, 1, 1)`` is needed), and
    ``(alpha_y, alpha_z) = (-asin(r_z), atan2(r_y, r_x))`` as in :func:`orientation_from_axis`.
    """
    s, c = np.sin(qm), np.cos(qm)
    cn, cp, sn, sp = c[:, _NEXT], c[:, _PREV], s[:, _NEXT], s[:, _PREV]
    p, q = cn * sp, sn * cp
    x = cn * cp * g.w  # row K: n_{K+1} x n_{K+2}, components (x, y, z)
    y = q * g.se_p - p * g.se_n
    z = p * g.ce_n - q * g.ce_p
    det3 = np.add.reduce(s * x - c * (g.ce * y + g.se * z), axis=-1)  # sum_K n_K . (n_{K+1} x n_{K+2}) = 3 det M
    ex, ey, ez = (np.add.reduce(v, axis=-1, keepdims=True) for v in (x, y, z))  # adj(M) (1, 1, 1)
    weak = ~(np.abs(det3) > 3.0 * PLANES_DET_MIN) | (g.k == 0.0)
    if weak.any():
        m = np.stack([s[weak], -c[weak] * g.ce, -c[weak] * g.se], axis=-1)  # (k, 3, 3), rows n_K
        rhs = np.full(m.shape[:-1] + (1,), g.d * g.k)
        e = (np.linalg.pinv(m, rcond=1e-10) @ rhs)[..., 0]
        norm = np.linalg.norm(e, axis=-1, keepdims=True)
        e = np.where(norm > 0, e / np.where(norm > 0, norm, 1.0), np.array([-1.0, 0.0, 0.0]))
        ex[weak], ey[weak], ez[weak] = e[:, 0:1], e[:, 1:2], e[:, 2:3]
    ee = ex * ex + ey * ey + ez * ez
    t = ex + ex
    ay = -np.arcsin(np.minimum(np.maximum(t * ez / ee, -1.0), 1.0))
    az = np.arctan2(t * ey, t * ex - ee)
    if with_det:
        return ay, az, det3 / 3.0  # det M, (n,)
    return ay, az


def _gauss_newton_step(a1: np.ndarray, a2: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``-pinv(A) r`` for ``A = [a1 a2]`` (n, 3, 2) given as its columns (n, 3), without an SVD; (n, 1) each (a loop over
    the kernel :func:`_k_gn_step`, for tests).

    Least squares in closed form: with ``n = a1 x a2``, ``|n|^2 = det(A^T A)`` (Lagrange's identity) and the
    normal equations solved by Cramer's rule, ``x = ((r x a2) . n, (a1 x r) . n) / |n|^2``. Written with cross
    products, no entry of ``A^T A`` is formed, so the error grows like cond(A), not cond(A)^2. Where
    ``sigma_2 <= STEP_RCOND sigma_1`` (i.e. ``|n|^2 <= STEP_RCOND^2 |A|_F^4``: ``alpha_y`` at +-pi/2 makes
    the second column vanish), the rank-1 pseudo-inverse ``A^T r / |A|_F^2`` is used, as ``np.linalg.pinv``
    with that rcond would (``0`` for ``A = 0``).
    """
    rows = [np.ascontiguousarray(v, dtype=np.float64).reshape(-1, 3) for v in (a1, a2, r)]
    n = rows[0].shape[0]
    s0, s1 = np.empty((n, 1)), np.empty((n, 1))
    for i in range(n):  # the kernel of fk's iteration (:func:`_k_gn_step`), item by item
        s0[i, 0], s1[i, 0] = _k_gn_step(rows[0][i], rows[1][i], rows[2][i])
    return s0, s1


def _det_planes(s: np.ndarray, c: np.ndarray, g: _Geometry) -> np.ndarray:
    """det M of the motor planes' unit normals ``n_K = (s_K1, -c_K1 c_K, -c_K1 s_K)`` from sin / cos of the
    motors (..., 3); the triple product ``n_A . (n_B x n_C)``, shape (...)."""
    cn, cp, sn, sp = c[..., _NEXT], c[..., _PREV], s[..., _NEXT], s[..., _PREV]
    p, q = cn * sp, sn * cp
    x = cn * cp * g.w
    y = q * g.se_p - p * g.se_n
    z = p * g.ce_n - q * g.ce_p
    return np.add.reduce(s * x - c * (g.ce * y + g.se * z), axis=-1) / 3.0



# ------------------------------------------------------------------------------------------ compiled kernels
# The one implementation (issue 16, see :mod:`legkin._kernels`): scalar kernels beside the equations
# they implement (the docstrings of the numpy-era helpers above and below give the derivations), batch loops
# over them, and status codes. Geometry: a float64 vector (see :func:`_geometry_vector`):
_G_D, _G_CA, _G_SA, _G_K, _G_K2, _G_OPC, _G_DSA, _G_ML, _G_TH, _G_CE, _G_SE, _G_W = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 12, 15
#: Kernel status codes of fk (those of :func:`_fk_mode`) and of the closed forms.
_ST_SINGULAR_PLANES, _ST_LEFT, _ST_NOT_CONVERGED, _ST_INCONSISTENT, _ST_OUTSIDE, _ST_GAIN = 1, 2, 3, 4, 5, 6
_ST_NONFINITE = 7  # an input is NaN or inf (the wrapper raises InvalidInputError with as_input's message)
_ST_FAIL = 8  # closed forms: the pose is outside / singular (the wrapper diagnoses it)
_TWO_PI = 2.0 * math.pi


def _geometry_vector(g: _Geometry) -> np.ndarray:
    """The kernels' geometry: (d, c_alpha, s_alpha, k, k^2, 1 + c_alpha, d s_alpha, -L, tan(alpha/2), c_eta (3),
    s_eta (3), sin(eta_{K+2} - eta_{K+1}) (3))."""
    head = [g.d, g.ca, g.sa, g.k, g.k2, g.opc, g.dsa, g.minus_l, g.tan_half]
    return np.ascontiguousarray(np.concatenate([head, g.ce, g.se, g.w]), dtype=np.float64)


@kernel
def _k_wrap(a):
    """:func:`_wrap` on a float: ``(a + pi) mod 2 pi - pi`` (Python's floor modulo, as np.remainder)."""
    return (a + math.pi) % _TWO_PI - math.pi


@kernel
def _k_one_plus_cc(cy, sy, cz, sz):
    """:func:`_one_plus_cc` on floats."""
    p = cy * cz
    out = 1.0 + p
    if p < -0.5:
        if cy >= 0.0:
            a, b, sa, sb = cy, cz, sy, sz
        else:
            a, b, sa, sb = cz, cy, sz, sy
        out = sb * sb / (1.0 - b) - b * (sa * sa) / (1.0 + a)
    return out


@kernel
def _k_centre(cy, sy, cz, sz, G, home, e):
    """Platform centre E = e L b / |b| (:func:`_ik_eval`, :func:`platform_position`): (x, y, z, 1 + c_y c_z);
    NaN where 1 + c_y c_z <= SINGULAR_TOL."""
    nb2 = _k_one_plus_cc(cy, sy, cz, sz)
    lead = G[_G_ML] if home else -e * G[_G_ML]
    scale = lead / np.sqrt(2.0 * nb2) if nb2 > SINGULAR_TOL else np.nan
    return nb2 * scale, sz * cy * scale, -sy * scale, nb2


@kernel
def _k_leg(K, x, y, z, G, home, s):
    """Seed eqs (98), (102) for leg K at E = (x, y, z): (q1, q2, cos q2, sin q2, sin q1 (unnormalised), cos q1).
    ``s``: the sign of sin q_K2 (ignored in the home mode)."""
    ce, se = G[_G_CE + K], G[_G_SE + K]
    c2 = (ce * z - se * y) / G[_G_DSA]  # eq (98)
    q2 = np.arccos(c2)  # NaN where |c2| > 1
    if not home:
        q2 = s * q2
    s2 = np.sin(q2)
    w = -(ce * y + se * z)
    s2sa = s2 * G[_G_SA]
    det = G[_G_D] * (G[_G_K2] + s2sa * s2sa)
    sn = (G[_G_K] * x + s2sa * w) / det
    cn = (-s2sa * x + G[_G_K] * w) / det
    return np.arctan2(sn, cn), q2, c2, s2, sn, cn  # eq (102)


@kernel
def _k_inside(c2a, c2b, c2c, nb2):
    """:func:`_inside` on floats (False on NaN)."""
    return (nb2 > SINGULAR_TOL) and (1.0 - abs(c2a) > BOUNDARY_TOL) and (1.0 - abs(c2b) > BOUNDARY_TOL) and (
        1.0 - abs(c2c) > BOUNDARY_TOL
    )


@kernel
def _k_jac_home(K, cy, sy, cz, sz, s2, n, G):
    """Seed eqs (103)-(105), row K of A_u (home mode): (A_K1, A_K2), the expressions of :func:`actuation_jacobian`'s
    docstring evaluated in the same order (repeated sub-expressions computed once)."""
    ck, sk = G[_G_CE + K], G[_G_SE + K]
    cpc = cy + cz
    ck_cpc, sk_cpc = ck * cpc, sk * cpc
    ck_sy, sk_sy, ck_cy = ck * sy, sk * sy, ck * cy
    ck_sy_sz, sk_sy_sz = ck_sy * sz, sk_sy * sz
    f = G[_G_TH] * (ck_sy + sk * cy * sz)  # eq (105)
    m = G[_G_OPC] * (s2 * s2) + 1 - G[_G_CA]
    t = ck_cy * sz - sk_sy
    p = n * n + t * t
    den = 2 * s2 * (n * n) * m
    mf = -f
    a1 = mf * (ck_cpc - sk_sy_sz + (ck_cy - sk_sy_sz) * n) / den - (ck_sy_sz + sk_cpc) / p
    a2 = mf * cy * (sk_cpc + ck_sy_sz + sk * cz * n) / den + cy * (ck_cpc - sk_sy_sz) / p
    return a1, a2


@kernel
def _k_jac_general(K, cy, sy, cz, sz, c2, s2, n, G, e):
    """Row K of A_u in any assembly mode, by the chain rule through the mode's IK (:func:`_k_leg`).

    With ``E = e L b / sqrt(2 n)`` (n = 1 + c_y c_z): ``dE = e L (2 n)^(-1/2) (db - b dn / (2 n))``;
    ``d cos q2 = (c_K dz - s_K dy) / (d s_alpha)``, ``d sin q2 = -cos q2 d cos q2 / sin q2`` (either sign of
    sin q2); ``q1 = atan2(P, Q)`` with ``P = k x + sigma w``, ``Q = -sigma x + k w``, ``sigma = s_alpha sin q2``,
    ``w = -(c_K y + s_K z)``, ``k = 1 - c_alpha``: ``dq1 = (Q dP - P dQ) / (P^2 + Q^2)``. In the home mode it
    equals eqs (103)-(105) (:func:`_k_jac_home`) to rounding.
    """
    ce, se, k, sa = G[_G_CE + K], G[_G_SE + K], G[_G_K], G[_G_SA]
    lead = -e * G[_G_ML] / np.sqrt(2.0 * n)
    bx, by, bz = n, sz * cy, -sy
    x, y, z = lead * bx, lead * by, lead * bz
    w = -(ce * y + se * z)
    sig = sa * s2
    p_, q_ = k * x + sig * w, -sig * x + k * w
    pq = p_ * p_ + q_ * q_
    out0 = 0.0
    out1 = 0.0
    for col in range(2):
        if col == 0:
            dn, dbx, dby, dbz = -sy * cz, -sy * cz, -sz * sy, -cy
        else:
            dn, dbx, dby, dbz = -cy * sz, -cy * sz, cz * cy, 0.0 * cy
        h = dn / (2.0 * n)
        dx, dy, dz = lead * (dbx - bx * h), lead * (dby - by * h), lead * (dbz - bz * h)
        dc2 = (ce * dz - se * dy) / G[_G_DSA]
        dsig = sa * (-c2 * dc2 / s2)
        dw = -(ce * dy + se * dz)
        dp = k * dx + sig * dw + w * dsig
        dq = -sig * dx - x * dsig + k * dw
        v = (q_ * dp - p_ * dq) / pq
        if col == 0:
            out0 = v
        else:
            out1 = v
    return out0, out1


@kernel
def _k_pose(cy, sy, cz, sz, G, home, e, s, q1, c2, s2, sn, cn):
    """IK at the trig of u: fills q1, c2, s2, sn, cn (3,) per leg; returns 1 + c_y c_z."""
    x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, home, e)
    for K in range(3):
        q1[K], _q2, c2[K], s2[K], sn[K], cn[K] = _k_leg(K, x, y, z, G, home, s[K])
    return nb2


@kernel
def _k_jac(cy, sy, cz, sz, c2, s2, nb2, G, home, e, a1, a2):
    """Both columns of A_u (3,) each, in place."""
    for K in range(3):
        if home:
            a1[K], a2[K] = _k_jac_home(K, cy, sy, cz, sz, s2[K], nb2, G)
        else:
            a1[K], a2[K] = _k_jac_general(K, cy, sy, cz, sz, c2[K], s2[K], nb2, G, e)


@kernel
def _k_det_planes(sa_, sb_, sc_, ca_, cb_, cc_, G):
    """det M of the motor planes (:func:`_det_planes`), from sin / cos of the three motors (scalars)."""
    s = (sa_, sb_, sc_)
    c = (ca_, cb_, cc_)
    tot = 0.0
    for K in range(3):
        J, L = (K + 1) % 3, (K + 2) % 3
        p, q = c[J] * s[L], s[J] * c[L]
        x = c[J] * c[L] * G[_G_W + K]
        y = q * G[_G_SE + L] - p * G[_G_SE + J]
        z = p * G[_G_CE + J] - q * G[_G_CE + L]
        tot += s[K] * x - c[K] * (G[_G_CE + K] * y + G[_G_SE + K] * z)
    return tot / 3.0


@kernel
def _k_initial_guess(qa, qb, qc, G):
    """Closed-form start of fk (:func:`_initial_guess`) from the motors: (alpha_y, alpha_z, det M).
    Only the adjugate intersection (regular planes, ``|det M| > PLANES_DET_MIN`` and 1 - c_alpha > 0); fk refuses
    ``|det M| < DET_GUARD`` before iterating, so the parallel-planes fallback is never needed there; with
    ``1 - c_alpha = 0`` (E = 0) the start is the home direction, as the fallback gives."""
    s = (np.sin(qa), np.sin(qb), np.sin(qc))
    c = (np.cos(qa), np.cos(qb), np.cos(qc))
    det3 = 0.0
    ex = 0.0
    ey = 0.0
    ez = 0.0
    for K in range(3):
        J, L = (K + 1) % 3, (K + 2) % 3
        p, q = c[J] * s[L], s[J] * c[L]
        x = c[J] * c[L] * G[_G_W + K]
        y = q * G[_G_SE + L] - p * G[_G_SE + J]
        z = p * G[_G_CE + J] - q * G[_G_CE + L]
        det3 += s[K] * x - c[K] * (G[_G_CE + K] * y + G[_G_SE + K] * z)
        ex += x
        ey += y
        ez += z
    if G[_G_K] == 0.0:
        ex, ey, ez = -1.0, 0.0, 0.0
    ee = ex * ex + ey * ey + ez * ez
    t = ex + ex
    ay = -np.arcsin(min(max(t * ez / ee, -1.0), 1.0))
    az = np.arctan2(t * ey, t * ex - ee)
    return ay, az, det3 / 3.0


@kernel
def _k_gn_step(a1, a2, r):
    """``-pinv([a1 a2]) r`` in closed form (:func:`_gauss_newton_step`) for (3,) columns: (s0, s1)."""
    nn = 0.0
    t0 = 0.0
    t1 = 0.0
    f = 0.0
    for K in range(3):
        I, J = (K + 1) % 3, (K + 2) % 3
        n = a1[I] * a2[J] - a1[J] * a2[I]
        nn += n * n
        t0 += (a2[I] * r[J] - a2[J] * r[I]) * n
        t1 += (r[I] * a1[J] - r[J] * a1[I]) * n
        f += a1[K] * a1[K] + a2[K] * a2[K]
    s0, s1 = t0 / nn, t1 / nn
    if nn <= (STEP_RCOND * STEP_RCOND) * f * f:
        fs = f if f > 0 else 1.0
        u0 = 0.0
        u1 = 0.0
        for K in range(3):
            u0 += a1[K] * r[K]
            u1 += a2[K] * r[K]
        s0, s1 = -u0 / fs, -u1 / fs
    return s0, s1


@kernel
def _k_normal_residual(a1, a2, r):
    """|r - A A^+ r| and |A|_F for A = [a1 a2] (the part of r off the range of A: rank 2 ``|r . n| / |n|``, n = a1 x a2; rank-1 projection where ``sigma_2 <= STEP_RCOND sigma_1``)."""
    nn = 0.0
    f = 0.0
    rn = 0.0
    for K in range(3):
        I, J = (K + 1) % 3, (K + 2) % 3
        n = a1[I] * a2[J] - a1[J] * a2[I]
        nn += n * n
        rn += r[K] * n
        f += a1[K] * a1[K] + a2[K] * a2[K]
    out = abs(rn) / np.sqrt(nn)
    if not nn > (STEP_RCOND * STEP_RCOND) * f * f:
        fs = f if f > 0 else 1.0
        u0 = 0.0
        u1 = 0.0
        for K in range(3):
            u0 += a1[K] * r[K]
            u1 += a2[K] * r[K]
        pp = 0.0
        for K in range(3):
            p = r[K] - (a1[K] * u0 + a2[K] * u1) / fs
            pp += p * p
        out = np.sqrt(pp)
    return out, np.sqrt(f)


@kernel
def _k_shrunk(ay, az, f):
    """The orientation of tilt (1 - f) theta in the direction of (ay, az) (towards home)."""
    cy = np.cos(ay)
    r0, r1, r2 = np.cos(az) * cy, np.sin(az) * cy, -np.sin(ay)
    theta = np.arccos(min(max(r0, -1.0), 1.0)) * (1.0 - f)
    side = np.hypot(r1, r2)
    side = side if side > 0 else 1.0
    st = np.sin(theta) / side
    return -np.arcsin(min(max(r2 * st, -1.0), 1.0)), np.arctan2(r1 * st, np.cos(theta))


@kernel
def _k_fk_report(ay, az, qm, G, home, e, s, a1, a2, q1, c2, s2, sn, cn, r, last):
    """The reported pose (alpha_y in [-pi/2, pi/2]), its inconsistency, ik's success test and the rounding floor.
    ``last`` = (alpha_y, alpha_z, 1 + c_y c_z) of the pose q1, c2, ... were last evaluated at: reused when the
    reported pose is that one (the usual exit: converged without a further step)."""
    if np.cos(ay) < 0:
        ay, az = math.pi - ay, az + math.pi
    ay, az = _k_wrap(ay), _k_wrap(az)
    if ay == last[0] and az == last[1] and ay != 0.0 and az != 0.0:  # (not at a signed zero: same bits)
        nb2 = last[2]
    else:
        nb2 = _k_pose(np.cos(ay), np.sin(ay), np.cos(az), np.sin(az), G, home, e, s, q1, c2, s2, sn, cn)
    for K in range(3):
        r[K] = _k_wrap(q1[K] - qm[K])
    inc, norm_a = _k_normal_residual(a1, a2, r)
    return ay, az, inc, _k_inside(c2[0], c2[1], c2[2], nb2), ROUNDING_FLOOR * norm_a


@kernel
def _k_fk(qa, qb, qc, G, home, e, s, tol, max_iter, max_inc, out):
    """fk of one motor triple in one assembly mode: writes (alpha_y, alpha_z, inconsistency) into ``out`` (3,)
    and returns the status (0 ok, else the codes of :func:`_fk_mode`; :data:`_ST_NONFINITE` for NaN / inf motors).

    Gauss-Newton from the planes' intersection (:func:`_initial_guess`), kept inside the workspace (a step that
    lands outside is halved, a start outside is pulled in towards home); early exit per target. See :func:`fk`.
    """
    if not (np.isfinite(qa) and np.isfinite(qb) and np.isfinite(qc)):
        out[0] = out[1] = out[2] = np.nan
        return _ST_NONFINITE
    qm = np.empty(3)
    qm[0], qm[1], qm[2] = qa, qb, qc
    scratch = np.empty((8, 3))
    q1, c2, s2, sn, cn, r, a1, a2 = (scratch[0], scratch[1], scratch[2], scratch[3], scratch[4], scratch[5],
                                     scratch[6], scratch[7])
    ay, az, det = _k_initial_guess(qa, qb, qc, G)
    if not abs(det) >= DET_GUARD:
        out[0] = out[1] = out[2] = np.nan
        return _ST_SINGULAR_PLANES
    y0, z0 = ay, az
    converged = False
    active = True
    rn_prev = np.inf
    py = pz = np.nan
    tries = 0
    a1[:] = np.nan
    a2[:] = np.nan
    last = (np.nan, np.nan, np.nan)
    for _ in range(max_iter):
        cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
        nb2 = _k_pose(cy, sy, cz, sz, G, home, e, s, q1, c2, s2, sn, cn)
        last = (ay, az, nb2)
        rr = 0.0
        for K in range(3):
            r[K] = _k_wrap(q1[K] - qm[K])
            rr += r[K] * r[K]
        rn = np.sqrt(rr)
        good = _k_inside(c2[0], c2[1], c2[2], nb2) and np.isfinite(rn)
        if active and not converged and not good:
            tries += 1
            if tries > 6:
                active = False
            elif np.isfinite(py):  # halve the step from the last iterate inside
                ay, az = 0.5 * (py + ay), 0.5 * (pz + az)
            else:  # pull the start in
                ay, az = _k_shrunk(y0, z0, 10.0 ** (-14.0 + 2.0 * tries))
        work = active and not converged and good
        _k_jac(cy, sy, cz, sz, c2, s2, nb2, G, home, e, a1, a2)
        stalled = rn >= rn_prev  # no progress: at the (least-squares) minimum to rounding
        if work:
            rn_prev = rn
        f = 0.0
        for K in range(3):
            f += a1[K] * a1[K] + a2[K] * a2[K]
        at_floor = rn <= ROUNDING_FLOOR * np.sqrt(f)
        s0, s1 = _k_gn_step(a1, a2, r)
        motor_step = 0.0
        for K in range(3):
            v = abs(a1[K] * s0 + a2[K] * s1)
            if not v <= motor_step:  # NaN propagates, as np.maximum
                motor_step = v
        big = abs(s0)
        if not abs(s1) <= big:
            big = abs(s1)
        small = (big <= tol) or (motor_step <= tol) or stalled or at_floor
        if work:
            py, pz = ay, az
            if not at_floor:
                ay, az = ay + s0, az + s1
            if small:
                converged = True
        if converged or not active:
            break
    if not np.isfinite(py):
        active = False
    ry, rz, inc, inside, floor = _k_fk_report(ay, az, qm, G, home, e, s, a1, a2, q1, c2, s2, sn, cn, r, last)
    if converged and not inside:  # the last (tiny) step left the workspace: report the iterate before it
        last = (np.nan, np.nan, np.nan)  # q1, c2, ... now hold the reported pose's, not py's
        by, bz, binc, binside, bfloor = _k_fk_report(py, pz, qm, G, home, e, s, a1, a2, q1, c2, s2, sn, cn, r, last)
        if binside:
            ry, rz, inc, inside, floor = by, bz, binc, binside, bfloor
    out[0], out[1], out[2] = ry, rz, inc
    consistent = inc <= max_inc + floor
    tame = floor <= ROUNDING_FLOOR * GAIN_GUARD
    if not active:
        return _ST_LEFT
    if not converged:
        return _ST_NOT_CONVERGED
    if not inside:
        return _ST_OUTSIDE
    if not tame:
        return _ST_GAIN
    if not consistent:
        return _ST_INCONSISTENT
    return OK


def _k_fk_batch(qm, G, homes, es, ss, tol, max_iter, max_inc, out, status):
    """fk over motors (n, 3) in the modes given (homes (m,), es (m,), ss (m, 3)): out (n, m, 3), status (n, m);
    NaN where an item fails."""
    n, m = qm.shape[0], homes.shape[0]
    for i in prange(n):
        for j in range(m):
            st = _k_fk(qm[i, 0], qm[i, 1], qm[i, 2], G, homes[j], es[j], ss[j], tol, max_iter, max_inc, out[i, j])
            status[i, j] = st
            if st != OK:
                out[i, j, 0] = out[i, j, 1] = out[i, j, 2] = np.nan


@kernel
def _k_ik(ay, az, G, home, e, s, q, aux):
    """ik of one orientation in one assembly mode (seed eqs (98), (102); see :func:`ik`): writes the 12 joints into
    ``q`` (NaN unless ok) and (cos q_A2, cos q_B2, cos q_C2, 1 + c_y c_z, det M, |A_u|_F) into ``aux`` (6,); the
    motor gain |A_u|_F is the cheap bound sqrt(3/2) / (min |sin q_K2| sqrt(1 + c_y c_z)) (1.3 for sqrt(3/2),
    measured to hold), exact where that bound exceeds GAIN_GUARD. Returns OK, _ST_FAIL or _ST_NONFINITE."""
    if not (np.isfinite(ay) and np.isfinite(az)):
        q[:] = np.nan
        aux[:] = np.nan
        return _ST_NONFINITE
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, home, e)
    q1a, q2a, c2a, s2a, sna, cna = _k_leg(0, x, y, z, G, home, s[0])
    q1b, q2b, c2b, s2b, snb, cnb = _k_leg(1, x, y, z, G, home, s[1])
    q1c, q2c, c2c, s2c, snc, cnc = _k_leg(2, x, y, z, G, home, s[2])
    det = _k_det_planes(sna, snb, snc, cna, cnb, cnc, G)
    inside = _k_inside(c2a, c2b, c2c, nb2)
    n = nb2 if inside else 1.0
    m = abs(s2a)
    for v in (abs(s2b), abs(s2c)):
        if not v >= m:  # NaN propagates, as np.minimum
            m = v
    gain = 1.3 / (m * np.sqrt(n))
    if gain > GAIN_GUARD:
        tot = 0.0
        for K in range(3):
            c2k = c2a if K == 0 else (c2b if K == 1 else c2c)
            s2k = s2a if K == 0 else (s2b if K == 1 else s2c)
            if home:
                j1, j2 = _k_jac_home(K, cy, sy, cz, sz, s2k, n, G)
            else:
                j1, j2 = _k_jac_general(K, cy, sy, cz, sz, c2k, s2k, n, G, e)
            tot += j1 * j1 + j2 * j2
        gain = np.sqrt(tot)
    aux[0], aux[1], aux[2], aux[3], aux[4], aux[5] = c2a, c2b, c2c, nb2, det, gain
    if inside and abs(det) >= DET_GUARD and gain <= GAIN_GUARD:
        q[0], q[1], q[2], q[3] = q1a, q2a, q2a, q1a
        q[4], q[5], q[6], q[7] = q1b, q2b, q2b, q1b
        q[8], q[9], q[10], q[11] = q1c, q2c, q2c, q1c
        return OK
    q[:] = np.nan
    return _ST_FAIL


def _k_ik_batch(ay, az, G, homes, es, ss, q, aux, status):
    """ik over orientations (n,) in the modes given (homes (m,), es (m,), ss (m, 3)): q (n, m, 12), aux (n, m, 6),
    status (n, m)."""
    n, m = ay.shape[0], homes.shape[0]
    for i in prange(n):
        for j in range(m):
            status[i, j] = _k_ik(ay[i], az[i], G, homes[j], es[j], ss[j], q[i, j], aux[i, j])


@kernel
def _k_actuation_jacobian(ay, az, G, home, e, s, a, aux):
    """A_u (3, 2) of one orientation in one mode into ``a`` (NaN unless inside the workspace), (cos q_K2 (3),
    1 + c_y c_z) into ``aux``; returns OK, _ST_FAIL or _ST_NONFINITE (see :func:`actuation_jacobian`)."""
    if not (np.isfinite(ay) and np.isfinite(az)):
        a[:, :] = np.nan
        aux[:] = np.nan
        return _ST_NONFINITE
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    x, y, z, nb2 = _k_centre(cy, sy, cz, sz, G, home, e)
    for K in range(3):
        _q1, _q2, c2, s2, _sn, _cn = _k_leg(K, x, y, z, G, home, s[K])
        aux[K] = c2
        if home:
            a[K, 0], a[K, 1] = _k_jac_home(K, cy, sy, cz, sz, s2, nb2, G)
        else:
            a[K, 0], a[K, 1] = _k_jac_general(K, cy, sy, cz, sz, c2, s2, nb2, G, e)
    aux[3] = nb2
    if _k_inside(aux[0], aux[1], aux[2], nb2):
        return OK
    a[:, :] = np.nan
    return _ST_FAIL


def _k_actuation_jacobian_batch(ay, az, G, home, e, s, a, aux, status):
    """A_u over orientations (n,): a (n, 3, 2), aux (n, 4), status (n,)."""
    for i in prange(ay.shape[0]):
        status[i] = _k_actuation_jacobian(ay[i], az[i], G, home, e, s, a[i], aux[i])


@kernel
def _k_alpha_x(ay, az):
    """Seed eq (15), two-argument form (:func:`alpha_x`)."""
    return np.arctan2(np.sin(ay) * np.sin(az), np.cos(ay) + np.cos(az))


@kernel
def _k_rot(axis, t):
    """The elementary rotation about axis 0 (x), 1 (y) or 2 (z) by t, as a row-major 9-tuple."""
    c, s = np.cos(t), np.sin(t)
    if axis == 0:
        return (1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
    if axis == 1:
        return (c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
    return (c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)


@kernel
def _k_matmul3(A, B):
    """A @ B for 3 x 3 matrices given as row-major 9-tuples (no heap arrays)."""
    return (
        A[0] * B[0] + A[1] * B[3] + A[2] * B[6], A[0] * B[1] + A[1] * B[4] + A[2] * B[7],
        A[0] * B[2] + A[1] * B[5] + A[2] * B[8],
        A[3] * B[0] + A[4] * B[3] + A[5] * B[6], A[3] * B[1] + A[4] * B[4] + A[5] * B[7],
        A[3] * B[2] + A[4] * B[5] + A[5] * B[8],
        A[6] * B[0] + A[7] * B[3] + A[8] * B[6], A[6] * B[1] + A[7] * B[4] + A[8] * B[7],
        A[6] * B[2] + A[7] * B[5] + A[8] * B[8],
    )


@kernel
def _k_platform_rotation(ay, az, R):
    """Seed eqs (5), (15): R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x) into R (3, 3)."""
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    ax = _k_alpha_x(ay, az)
    cx, sx = np.cos(ax), np.sin(ax)
    R[0, 0], R[0, 1], R[0, 2] = cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx
    R[1, 0], R[1, 1], R[1, 2] = sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx
    R[2, 0], R[2, 1], R[2, 2] = -sy, cy * sx, cy * cx


@kernel
def _k_platform_axis(ay, az, out):
    """R e_x = (c_z c_y, s_z c_y, -s_y) into out (3,)."""
    cy = np.cos(ay)
    out[0], out[1], out[2] = np.cos(az) * cy, np.sin(az) * cy, -np.sin(ay)


@kernel
def _k_platform_position(ay, az, G, out):
    """E = -L b / |b| (:func:`platform_position`) into out (3,); NaN where 1 + c_y c_z <= SINGULAR_TOL."""
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    nb2 = _k_one_plus_cc(cy, sy, cz, sz)
    scale = G[_G_ML] / np.sqrt(2.0 * nb2) if nb2 > SINGULAR_TOL else np.nan
    out[0], out[1], out[2] = nb2 * scale, sz * cy * scale, -sy * scale


@kernel
def _k_orientation_from_axis(r0, r1, r2):
    """(status, alpha_y, alpha_z) of a platform axis (:func:`orientation_from_axis`): _ST_NONFINITE, _ST_FAIL
    (zero vector) or OK."""
    if not (np.isfinite(r0) and np.isfinite(r1) and np.isfinite(r2)):
        return _ST_NONFINITE, np.nan, np.nan
    scale = max(abs(r0), abs(r1), abs(r2))
    if not scale > 0:
        return _ST_FAIL, np.nan, np.nan
    r0, r1, r2 = r0 / scale, r1 / scale, r2 / scale
    n = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
    r0, r1, r2 = r0 / n, r1 / n, r2 / n
    return OK, -np.arcsin(min(max(r2, -1.0), 1.0)), np.arctan2(r1, r0)


@kernel
def _k_leg_position(q1, q2, eta, G, T):
    """Eqs (10) last column and (12): T[:3, 3] = d (-h1, -(c_eta h2 + s_eta h3), c_eta h3 - s_eta h2), T[3] = (0 0 0 1)."""
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    ca, sa, d = G[_G_CA], G[_G_SA], G[_G_D]
    ce, se = np.cos(eta), np.sin(eta)
    h1 = c1 * s2 * sa - s1 * (1 - ca)
    h2 = c1 * (1 - ca) + s1 * s2 * sa
    h3 = c2 * sa
    T[0, 3], T[1, 3], T[2, 3] = -d * h1, -d * (ce * h2 + se * h3), d * (ce * h3 - se * h2)
    T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@kernel
def _k_leg_transform(q1, q2, q3, q4, eta, alpha, G, T):
    """:func:`leg_transform` of one joint vector into T (4, 4); returns OK or _ST_NONFINITE (T not written)."""
    if not (np.isfinite(q1) and np.isfinite(q2) and np.isfinite(q3) and np.isfinite(q4)):
        return _ST_NONFINITE
    R = _k_matmul3(_k_rot(0, eta), _k_rot(2, math.pi))  # Rx(eta) Rz(pi) Rz(q1) Ry(q2) Rx(-alpha) Ry(q3) Rz(-q4) Rx(pi - eta)
    R = _k_matmul3(R, _k_rot(2, q1))
    R = _k_matmul3(R, _k_rot(1, q2))
    R = _k_matmul3(R, _k_rot(0, -alpha))
    R = _k_matmul3(R, _k_rot(1, q3))
    R = _k_matmul3(R, _k_rot(2, -q4))
    R = _k_matmul3(R, _k_rot(0, math.pi - eta))
    for i in range(3):
        T[i, 0], T[i, 1], T[i, 2] = R[3 * i], R[3 * i + 1], R[3 * i + 2]
    _k_leg_position(q1, q2, eta, G, T)
    return OK


@kernel
def _k_leg_transform_cv(q1, q2, eta, G, T):
    """Seed eqs (10)-(12) (:func:`leg_transform_cv`, T33 sign corrected) into T (4, 4)."""
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    ca, sa = G[_G_CA], G[_G_SA]
    ce, se = np.cos(eta), np.sin(eta)
    g1 = c1**2 * (c2**2 - s2**2 * ca) + s1**2 * ca + 2 * c1 * s1 * s2 * sa
    g2 = c2 * (s1 * sa - c1 * s2 * (1 + ca))
    g3 = (c1**2 - s1**2) * s2 * sa + c1 * s1 * (2 * ca - c2**2 * (1 + ca))
    g4 = c2 * (c1 * sa + s1 * s2 * (1 + ca))
    g5 = c1**2 * ca + s1**2 * (c2**2 - s2**2 * ca) - 2 * c1 * s1 * s2 * sa
    g6 = s2**2 - c2**2 * ca
    g7 = (c2**2 - s2**2) * (1 + ca) + c1**2 * (s2**2 * (1 + ca) - (1 - ca)) - 2 * c1 * s1 * s2 * sa
    t23 = ce * se * g7 + (ce**2 - se**2) * g4
    T[0, 0], T[0, 1], T[0, 2] = -g1, se * g2 - ce * g3, -ce * g2 - se * g3
    T[1, 0], T[1, 1], T[1, 2] = -se * g2 + ce * g3, -2 * ce * se * g4 + ce**2 * g5 + se**2 * g6, t23
    T[2, 0], T[2, 1], T[2, 2] = se * g3 + ce * g2, t23, 2 * ce * se * g4 + se**2 * g5 + ce**2 * g6
    _k_leg_position(q1, q2, eta, G, T)


def _k_uv_batch(kind, ay, az, G, out):
    """The per-orientation closed forms over (n,) orientations: kind 0 alpha_x (out (n, 1)), 1 platform_axis (n, 3),
    2 platform_position (n, 3), 3 platform_rotation (n, 3, 3) (out flattened to (n, 9))."""
    for i in prange(ay.shape[0]):
        if kind == 0:
            out[i, 0] = _k_alpha_x(ay[i], az[i])
        elif kind == 1:
            _k_platform_axis(ay[i], az[i], out[i])
        elif kind == 2:
            _k_platform_position(ay[i], az[i], G, out[i])
        else:
            _k_platform_rotation(ay[i], az[i], out[i].reshape((3, 3)))


def _k_alpha_x_batch(ay, az, out):
    """alpha_x over (n,) orientations into out (n,) (a loop of its own: the branch of _k_uv_batch costs ~15%)."""
    for i in prange(ay.shape[0]):
        out[i] = _k_alpha_x(ay[i], az[i])


def _k_orientation_from_axis_batch(r, out, status):
    """orientation_from_axis over axes (n, 3): out (n, 2), status (n,)."""
    for i in prange(r.shape[0]):
        status[i], out[i, 0], out[i, 1] = _k_orientation_from_axis(r[i, 0], r[i, 1], r[i, 2])


def _k_leg_transform_batch(q, eta, alpha, G, T):
    """leg_transform over joint vectors (n, 4): T (n, 4, 4)."""
    for i in prange(q.shape[0]):
        _k_leg_transform(q[i, 0], q[i, 1], q[i, 2], q[i, 3], eta, alpha, G, T[i])


def _k_leg_transform_cv_batch(q1, q2, eta, G, T):
    """leg_transform_cv over (n,) joint pairs: T (n, 4, 4)."""
    for i in prange(q1.shape[0]):
        _k_leg_transform_cv(q1[i], q2[i], eta, G, T[i])


_NO_GEOMETRY = np.zeros(18)


def _uv_closed(kind: int, alpha_y, alpha_z, core: tuple, G):
    """A closed form of the orientation (see :func:`_k_uv_batch`) on checked, broadcast angles; (..., *core)."""
    if G is None:
        G = _NO_GEOMETRY
    size = 1
    for c in core:
        size *= c
    if isinstance(alpha_y, float) and isinstance(alpha_z, float) and math.isfinite(alpha_y) and math.isfinite(alpha_z):
        if kind != 0:  # one item: the scalar kernel straight into the result
            res = np.empty(core)
            if kind == 1:
                _k_platform_axis(float(alpha_y), float(alpha_z), res)
            elif kind == 2:
                _k_platform_position(float(alpha_y), float(alpha_z), G, res)
            else:
                _k_platform_rotation(float(alpha_y), float(alpha_z), res)
            return res
        y, z, shape = np.array([float(alpha_y)]), np.array([float(alpha_z)]), ()
    else:
        ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
        shape = ay.shape
        y, z = np.ascontiguousarray(ay).reshape(-1), np.ascontiguousarray(az).reshape(-1)
    out = np.empty((y.shape[0], size))
    if y.shape[0] == 1:  # one item: the scalar kernel, no thread pool
        if kind == 0:
            out[0, 0] = _k_alpha_x(y[0], z[0])
        elif kind == 1:
            _k_platform_axis(y[0], z[0], out[0])
        elif kind == 2:
            _k_platform_position(y[0], z[0], G, out[0])
        else:
            _k_platform_rotation(y[0], z[0], out[0].reshape(3, 3))
    else:
        _pick(_k_uv_batch, y.shape[0], "closed")(kind, y, z, G, out)
    res = out.reshape(shape + core)
    return res[()] if not core else res


@kernel
def _k_linspace(a, b, out):
    """np.linspace(a, b, len(out)) into out (the same operations: start + i * step, the last point exactly b)."""
    n = out.shape[0]
    step = (b - a) / (n - 1)
    for i in range(n):
        out[i] = i * step + a
    out[n - 1] = b


@kernel
def _k_tilt_curve(theta, phi, pts):
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


@kernel
def _k_workspace(G, eta, ch, ay, az, cos_q2, reachable, phi, theta_k, tilt_max, curves, counts):
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


def _serial(fn):
    """The serial twin of a batch loop (the same loop compiled without threads, ``prange`` as ``range``): the wrappers
    use it below :data:`_PARALLEL_MIN` items, where waking numba's thread pool costs more than the loop (on a busy
    machine, milliseconds)."""
    twin = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + "_serial", fn.__defaults__, fn.__closure__)
    twin.__qualname__ = fn.__qualname__ + "_serial"
    twin.__doc__ = fn.__doc__
    return kernel(twin)


#: Batches smaller than this (items x modes, per function) run the serial twin of the batch loop. Chosen on a busy
#: 2-core machine, where waking the pool costs up to ~10 ms: fk (~3 us an item) from 4096 items, the closed forms
#: (~0.1-1 us an item) from 50000.
_PARALLEL_MIN = {"fk": 4096, "ik": 50000, "jac": 50000, "closed": 50000}

_k_fk_batch, _k_fk_batch_serial = batch_kernel(_k_fk_batch), _serial(_k_fk_batch)
_k_ik_batch, _k_ik_batch_serial = batch_kernel(_k_ik_batch), _serial(_k_ik_batch)
_k_actuation_jacobian_batch, _k_actuation_jacobian_batch_serial = (batch_kernel(_k_actuation_jacobian_batch), _serial(_k_actuation_jacobian_batch))
_k_uv_batch, _k_uv_batch_serial = batch_kernel(_k_uv_batch), _serial(_k_uv_batch)
_k_alpha_x_batch, _k_alpha_x_batch_serial = batch_kernel(_k_alpha_x_batch), _serial(_k_alpha_x_batch)
_k_orientation_from_axis_batch, _k_orientation_from_axis_batch_serial = (batch_kernel(_k_orientation_from_axis_batch), _serial(_k_orientation_from_axis_batch))
_k_leg_transform_batch, _k_leg_transform_batch_serial = (batch_kernel(_k_leg_transform_batch), _serial(_k_leg_transform_batch))
_k_leg_transform_cv_batch, _k_leg_transform_cv_batch_serial = (batch_kernel(_k_leg_transform_cv_batch), _serial(_k_leg_transform_cv_batch))
_SERIAL = {
    _k_fk_batch: _k_fk_batch_serial,
    _k_ik_batch: _k_ik_batch_serial,
    _k_actuation_jacobian_batch: _k_actuation_jacobian_batch_serial,
    _k_uv_batch: _k_uv_batch_serial,
    _k_alpha_x_batch: _k_alpha_x_batch_serial,
    _k_orientation_from_axis_batch: _k_orientation_from_axis_batch_serial,
    _k_leg_transform_batch: _k_leg_transform_batch_serial,
    _k_leg_transform_cv_batch: _k_leg_transform_cv_batch_serial,
}


def _pick(par, n: int, kind: str):
    """The parallel batch loop ``par`` for n >= _PARALLEL_MIN[kind] items, else its serial twin."""
    return par if n >= _PARALLEL_MIN[kind] else _SERIAL[par]


#: Per assembly mode (:data:`MODES` order): home flag, side of E, signs of sin q_K2 (the kernels' mode arguments).
_MODE_HOME = np.array([m == HOME_MODE for m in MODES])
_MODE_E = np.array([-1.0 if m[0] == "-" else 1.0 for m in MODES])
_MODE_S = np.array([[-1.0 if c == "-" else 1.0 for c in m[1:]] for m in MODES])
_MODE_INDEX = {m: i for i, m in enumerate(MODES)}
_MODE_ARGS = {m: (bool(_MODE_HOME[i]), float(_MODE_E[i]), _MODE_S[i]) for i, m in enumerate(MODES)}
_GEO_CACHE: dict = {}


def _geo(d, alpha, eta):
    """Validated geometry: (_Geometry, the kernels' vector), cached for plain-float d, alpha and the default eta."""
    if eta is None and type(d) is float and type(alpha) is float:
        hit = _GEO_CACHE.get((d, alpha))
        if hit is not None:
            return hit
        g = _geometry(*_params(d, alpha, None))
        if len(_GEO_CACHE) > 64:
            _GEO_CACHE.clear()
        hit = _GEO_CACHE[(d, alpha)] = (g, _geometry_vector(g))
        return hit
    g = _geometry(*_params(d, alpha, eta))
    return g, _geometry_vector(g)


def _fk_one(qa: float, qb: float, qc: float, G, mode: str, tol: float, max_iter: int, max_inc: float):
    """The fk kernel on one motor triple in one mode: (alpha_y, alpha_z, inconsistency) (raw, also on failure), status."""
    home, e, s = _MODE_ARGS[mode]
    out = np.empty(3)
    return out, _k_fk(qa, qb, qc, G, home, e, s, tol, max_iter, max_inc, out)


def _fk_mode(qm: np.ndarray, g: _Geometry, tol: float, max_iter: int, max_inconsistency: float, mode: str):
    """:func:`fk` on motors (n, 3) in one mode: alpha_y, alpha_z, inconsistency (n,), ok (n,), status (n,)
    (0 ok, 1 actuation singular, 2 left the workspace, 3 not converged, 4 inconsistent, 5 ended outside,
    6 motor gain above GAIN_GUARD); the raw values (not NaN) also where an item fails."""
    G = _geometry_vector(g)
    n = qm.shape[0]
    ay, az, inc, status = np.empty(n), np.empty(n), np.empty(n), np.empty(n, dtype=np.int64)
    for i in range(n):
        out, status[i] = _fk_one(float(qm[i, 0]), float(qm[i, 1]), float(qm[i, 2]), G, mode, tol, max_iter,
                                 max_inconsistency)
        ay[i], az[i], inc[i] = out
    return ay, az, inc, status == OK, status


def fk(
    q_A1,
    q_B1,
    q_C1,
    d: float = D,
    alpha: float = ALPHA,
    eta: Sequence[float] | None = None,
    *,
    mode: str = HOME_MODE,
    tol: float = 1e-13,
    max_iter: int = 30,
    max_inconsistency: float = 1e-9,
    return_mask: bool = False,
):
    """Platform orientation from the three motor angles: Gauss-Newton on :func:`ik` with :func:`actuation_jacobian`.

    Solves ``min_u |wrap(ik_motors(u) - q_m)|`` over u = (alpha_y, alpha_z) (three equations, two unknowns):
    ``u <- u - pinv(A_u) r`` (the 3 x 2 least-squares step in closed form, see :func:`_gauss_newton_step`),
    from the closed-form start of :func:`_initial_guess` (the motor planes; not in the seed), until the step
    (or its image ``A_u du`` in the motors) is below ``tol``; from consistent motors the start is already
    exact to rounding and one iteration confirms it. The iterates are kept inside the workspace (a step that
    leaves it is halved, see :func:`_k_fk`). The result is reported with ``alpha_y`` in [-pi/2, pi/2]
    (``(pi - alpha_y, alpha_z + pi)`` is the same orientation). Inputs are checked once here; the iteration
    runs on the unchecked private functions (a single call is a batch of one).

    Assembly mode: ``ik_motors`` is :func:`ik` in ``mode`` (default :data:`HOME_MODE`, the mode the mechanism is
    built in). Motors from another mode are not consistent with any pose of this one: unsolved (batch: NaN,
    mask False; single call: ``AssemblyModeError`` naming the mode(s) in which they are consistent, in
    ``.modes`` as ``[{"mode": ...}]``). ``mode="all"`` solves in every mode: each output then has a trailing
    axis of 16 (:data:`MODES` order), NaN where the motors do not fit that mode.

    Redundant actuation: three motor angles produced by no pose are not averaged silently. The
    inconsistency (rad) is the distance of the motors from the consistent set, to first order: the residual
    ``r`` at the reported pose less its projection on the range of A_u (at the least-squares solution that is
    ``|r|``; for consistent motors it is rounding, also near the flip where A_u is large). Above
    ``max_inconsistency`` the call fails (scalar: ``UnreachableError`` carrying the least-squares pose in
    ``closest``; batch: NaN). Pass ``max_inconsistency=np.inf`` to get least-squares poses for noisy readings.

    Actuation singularity: motors whose planes have ``|det M| < DET_GUARD`` are refused (they fit two poses,
    or fix the pose only to ~2e-16 / |det M| rad); :func:`ik` refuses the same poses, so every pose ik returns
    is reproduced by fk and every pose fk returns is solved by ik.

    Args:
        q_A1, q_B1, q_C1: motor angles (rad), broadcast together.
        d, alpha, eta: geometry.
        mode: assembly mode, one of :data:`MODES` or ``"all"``.
        tol: step-size tolerance (rad), in [0, 0.1]. max_iter: iteration cap, an integer in [1, 10000].
        max_inconsistency: largest accepted inconsistency (rad), in [0, inf].
        return_mask: (batch) also return the success mask.

    Returns:
        ``(alpha_y, alpha_z, inconsistency)`` (each of the batch shape).

    Raises:
        AssemblyModeError: (scalar) the motors are consistent only in other assembly modes.
        UnreachableError: (scalar) the motor angles are inconsistent beyond ``max_inconsistency`` (in every
            mode), or the iterate left the workspace.
        SingularityError: (scalar) an actuation singularity (``|det M| < DET_GUARD``), or the solution is on
            the workspace boundary (where :func:`ik` fails).
        ConvergenceError: (scalar) no convergence within ``max_iter``.
        InvalidInputError: non-finite, complex or non-broadcastable motors; InvalidParameterError: bad geometry,
            mode, tol, max_iter, max_inconsistency or return_mask.
    """
    g, G = _geo(d, alpha, eta)
    if type(mode) is not str or mode != HOME_MODE:
        mode = _checked_mode(mode, allow_all=True)
    if type(tol) is not float or not 0.0 <= tol <= 0.1:
        tol = _in_range(tol, "tol", 0.0, 0.1, "[0, 0.1] (rad)")
    if type(max_iter) is not int or not 1 <= max_iter <= 10000:
        max_iter = _integer(max_iter, "max_iter", 1, 10000)
    if type(max_inconsistency) is not float or not 0.0 <= max_inconsistency <= math.inf:
        max_inconsistency = _in_range(max_inconsistency, "max_inconsistency", 0.0, math.inf, "[0, inf] (rad)")
    if return_mask is not False and return_mask is not True:
        return_mask = _flag(return_mask, "return_mask")
    if isinstance(q_A1, float) and isinstance(q_B1, float) and isinstance(q_C1, float):
        qs = (float(q_A1), float(q_B1), float(q_C1))
    else:
        a1, b1, c1 = as_angles(q_A1, q_B1, q_C1, names=("q_A1", "q_B1", "q_C1"))
        if a1.ndim:
            return _fk_batch(a1, b1, c1, g, G, mode, tol, max_iter, max_inconsistency, return_mask)
        qs = (float(a1), float(b1), float(c1))
    return _fk_single(qs, g, G, mode, tol, max_iter, max_inconsistency, return_mask, (q_A1, q_B1, q_C1))


def _motors_text(qs) -> str:
    return f"(q_A1, q_B1, q_C1) = ({qs[0]:.17g}, {qs[1]:.17g}, {qs[2]:.17g})"


def _fk_single(qs, g, G, mode, tol, max_iter, max_inconsistency, return_mask, raw):
    """A single fk call: np.float64 outputs, a legkin error on failure."""
    if mode == "all":
        outs = np.full((3, len(MODES)), np.nan)
        ok = np.zeros(len(MODES), dtype=bool)
        first = None
        for j, m in enumerate(MODES):
            out, st = _fk_one(*qs, G, m, tol, max_iter, max_inconsistency)
            if st == _ST_NONFINITE:
                as_angles(*raw, names=("q_A1", "q_B1", "q_C1"))  # raises InvalidInputError
            if j == 0:
                first = (out[0], out[1], out[2], False, st)
            if st == OK:
                outs[:, j], ok[j] = out, True
        if not ok.any():
            raise _fk_error(_motors_text(qs), np.array([qs]), first, HOME_MODE, [], max_iter, max_inconsistency, g)
        res = (outs[0], outs[1], outs[2])
        return (*res, ok) if return_mask else res
    out, st = _fk_one(*qs, G, mode, tol, max_iter, max_inconsistency)
    if st != OK:
        if st == _ST_NONFINITE:
            as_angles(*raw, names=("q_A1", "q_B1", "q_C1"))  # raises InvalidInputError
        qm = np.array([qs])
        others = []
        if st != _ST_SINGULAR_PLANES:  # consistent motors fit the mode their planes' intersection E points to
            likely = _motor_mode(qm[0], g)
            for m in [likely] if likely else MODES:
                if m != mode and _fk_one(*qs, G, m, tol, max_iter, max_inconsistency)[1] == OK:
                    others.append(m)
                    break
        raise _fk_error(_motors_text(qs), qm, (out[0], out[1], out[2], False, st), mode, others, max_iter, max_inconsistency, g)
    res = (np.float64(out[0]), np.float64(out[1]), np.float64(out[2]))
    return (*res, np.asarray(True)) if return_mask else res


def _fk_batch(a1, b1, c1, g, G, mode, tol, max_iter, max_inconsistency, return_mask):
    """A batch fk call: the compiled loop, NaN where an item fails."""
    shape = a1.shape
    qm = np.empty(shape + (3,))
    qm[..., 0], qm[..., 1], qm[..., 2] = a1, b1, c1
    qm = qm.reshape(-1, 3)
    if mode == "all":
        sel = slice(None)
    else:
        j = _MODE_INDEX[mode]
        sel = slice(j, j + 1)
    homes, es, ss = _MODE_HOME[sel], _MODE_E[sel], _MODE_S[sel]
    n, m = qm.shape[0], homes.shape[0]
    out = np.empty((n, m, 3))
    status = np.empty((n, m), dtype=np.int64)
    _pick(_k_fk_batch, n * m, "fk")(qm, G, homes, es, ss, tol, max_iter, max_inconsistency, out, status)
    ok = status == OK
    if mode == "all":
        res = tuple(out[:, :, k].reshape(shape + (m,)) for k in range(3))
        ok = ok.reshape(shape + (m,))
    else:
        res = tuple(out[:, 0, k].reshape(shape) for k in range(3))
        ok = ok.reshape(shape)
    return (*res, ok) if return_mask else res


def _motor_mode(qm: np.ndarray, g: _Geometry) -> str | None:
    """The assembly mode of motors (3,) read off their planes: E = d (1 - c_alpha) M^-1 (1, 1, 1) (None if M is
    singular): the side of E_x, and per leg the sign of sin q_K2 sin(alpha) = c_K1 h1 + s_K1 h2 with
    (h1, h2) = (-x, -(c_K y + s_K z)) / d (the leg's position equations, eq 101)."""
    s, c = np.sin(qm), np.cos(qm)
    m = np.stack([s, -c * g.ce, -c * g.se], axis=-1)
    try:
        e = np.linalg.solve(m, np.full(3, g.d * g.k))
    except np.linalg.LinAlgError:
        return None
    s2 = c * (-e[0] / g.d) + s * (-(g.ce * e[1] + g.se * e[2]) / g.d)
    return ("-" if e[0] < 0 else "+") + "".join("-" if v < 0 else "+" for v in s2)


def _fk_error(motors: str, qm, res, mode: str, others, max_iter: int, max_inconsistency: float, g) -> Exception:
    """The exception of a failed single :func:`fk` call (``res`` from :func:`_fk_mode` on one item)."""
    ay, az, inconsistency, _, status = (float(np.ravel(v)[0]) for v in res)
    target = qm.reshape(3).copy()
    if others:
        return AssemblyModeError(
            f"{motors} are consistent only in assembly mode(s) {', '.join(others)}, not in mode {mode}",
            target=target, modes=[{"mode": m} for m in others],
        )
    if status == 1:
        return SingularityError(
            f"{motors} are an actuation singularity: their planes have |det M| < DET_GUARD = {DET_GUARD:g} "
            "(nearly sharing a line): the motor angles do not determine the pose"
        )
    if status == 2:  # diagnose at the planes' intersection (the start), as ik would there
        G = _geometry_vector(g)
        y0, z0, _ = _k_initial_guess(*(float(v) for v in qm.reshape(3)), G)
        _, aux, st = _ik_one(y0, z0, G, mode)
        if st != OK:
            exc = _ik_single_error(np.float64(y0), np.float64(z0), g, mode, aux[:3], aux[3], aux[4], aux[5])
            return type(exc)(f"{motors}: no pose found; their planes meet at {exc}", *exc.args[1:])
        return UnreachableError(f"{motors}: the solver left the workspace; no pose was found", target=target)
    if status == 3:
        return ConvergenceError(f"{motors}: Gauss-Newton did not converge in {max_iter} iterations (singular A_u?)")
    if status == 6:
        return SingularityError(
            f"{motors}: at the pose (alpha_y, alpha_z) = ({ay:.17g}, {az:.17g}) the motors are too sensitive to the "
            f"orientation (|A_u| > GAIN_GUARD = {GAIN_GUARD:g}: a leg next to its boundary near the flip)"
        )
    if status == 5:
        return SingularityError(
            f"{motors}: the pose (alpha_y, alpha_z) = ({ay:.17g}, {az:.17g}) is on the workspace boundary or the "
            "platform singularity, where ik is undefined"
        )
    return UnreachableError(
        f"{motors} are inconsistent: no pose produces all three; the least-squares pose "
        f"(alpha_y, alpha_z) = ({ay:.17g}, {az:.17g}) misses them by {inconsistency:.3e} rad "
        f"(max_inconsistency = {max_inconsistency:.1e})",
        target=target,
        closest=(ay, az),
    )


# ------------------------------------------------------------------------------------------ workspace
@dataclass(frozen=True)
class Workspace:
    """The reachable set of (alpha_y, alpha_z) for given d, alpha, eta (see :func:`workspace`).

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


def workspace(
    d: float = D, alpha: float = ALPHA, eta: Sequence[float] | None = None, n: int = 181, m: int = 721
) -> Workspace:
    """Reachable orientations and singular curves, for plots.

    In terms of the tilt theta (angle between the base axis x and the platform axis R e_x) and its
    direction phi, eq (98) with :func:`platform_position` reads
    ``cos q_K2 = -sin(theta/2) sin(phi - eta_K) / cos(alpha/2)``. Leg K reaches the pose iff
    ``sin(theta/2) |sin(phi - eta_K)| < cos(alpha/2)``; its singular curve sin q_K2 = 0 is
    ``theta_K(phi) = 2 asin(cos(alpha/2) / |sin(phi - eta_K)|)`` (where that is <= 1), and the workspace is
    ``theta < min_K theta_K(phi)`` (star-shaped about home), bounded by those curves. The platform singularity
    1 + c_y c_z = 0 is theta = pi. The grid covers alpha_y in [-pi/2, pi/2], alpha_z in [-pi, pi].

    Args:
        d, alpha, eta: geometry. n: grid size per axis, an integer in [2, 1001]. m: samples of phi along the
            curves, an integer in [2, 100001].
    """
    G = _geo(d, alpha, eta)[1]  # validates the geometry
    alpha = float(alpha)
    eta_arr = np.asarray(ETA) if eta is None else as_input(eta, "eta", (3,))
    if type(n) is not int or not 2 <= n <= 1001:
        n = _integer(n, "n", 2, 1001)
    if type(m) is not int or not 2 <= m <= 100001:
        m = _integer(m, "m", 2, 100001)
    ay, az, phi, tilt_max = np.empty(n), np.empty(n), np.empty(m), np.empty(m)
    cos_q2, reachable = np.empty((3, n, n)), np.empty((n, n), dtype=np.bool_)
    theta_k, curves, counts = np.empty((3, m)), np.empty((4, 2 * m, 2)), np.empty(4, dtype=np.int64)
    _k_workspace(G, np.ascontiguousarray(eta_arr, dtype=np.float64), math.cos(alpha / 2.0), ay, az, cos_q2, reachable,
                 phi, theta_k, tilt_max, curves, counts)
    boundary = curves[0, : counts[0]]
    leg_singular = {leg: curves[k + 1, : counts[k + 1]] for k, leg in enumerate(LEGS)}
    platform_singular = np.array([[0.0, -np.pi], [0.0, np.pi]])
    return Workspace(
        alpha_y=ay,
        alpha_z=az,
        cos_q2=cos_q2,
        reachable=reachable,
        boundary=boundary,
        leg_singular=leg_singular,
        platform_singular=platform_singular,
        tilt_max=tilt_max,
        phi=phi,
    )
