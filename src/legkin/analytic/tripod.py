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
from dataclasses import dataclass
from typing import NamedTuple, Sequence

import numpy as np

from ..errors import ConvergenceError, InvalidParameterError, SingularityError, UnreachableError
from ._batch import as_angles, as_input, finish

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


# ------------------------------------------------------------------------------------------ helpers
def _params(d: float, alpha: float, eta: Sequence[float] | None = None) -> tuple[float, float, np.ndarray]:
    """Validate the geometry (same ranges as the registry); return (d, alpha, eta as (3,))."""
    try:
        d, alpha = float(d), float(alpha)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"d and alpha must be numbers, got d={d!r}, alpha={alpha!r}") from None
    if not (math.isfinite(d) and d > 0):
        raise InvalidParameterError(f"d={d!r} is out of range: must be in (0, inf) (metres)")
    if not (0 < alpha < math.pi):
        raise InvalidParameterError(f"alpha={alpha!r} is out of range: must be in (0, pi) (radians)")
    eta_arr = np.asarray(ETA if eta is None else eta, dtype=float)
    if eta_arr.shape != (3,) or not np.all(np.isfinite(eta_arr)):
        raise InvalidParameterError(f"eta must be three finite angles (eta_A, eta_B, eta_C), got {eta!r}")
    return d, alpha, eta_arr


def _rx(t: np.ndarray) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    o, z = np.ones_like(t), np.zeros_like(t)
    return np.stack([o, z, z, z, c, -s, z, s, c], axis=-1).reshape(t.shape + (3, 3))


def _ry(t: np.ndarray) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    o, z = np.ones_like(t), np.zeros_like(t)
    return np.stack([c, z, s, z, o, z, -s, z, c], axis=-1).reshape(t.shape + (3, 3))


def _rz(t: np.ndarray) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    o, z = np.ones_like(t), np.zeros_like(t)
    return np.stack([c, -s, z, s, c, z, z, z, o], axis=-1).reshape(t.shape + (3, 3))


def _homogeneous(rot: np.ndarray, pos: np.ndarray) -> np.ndarray:
    out = np.zeros(rot.shape[:-2] + (4, 4))
    out[..., :3, :3] = rot
    out[..., :3, 3] = pos
    out[..., 3, 3] = 1.0
    return out


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def _leg_position(q1: np.ndarray, q2: np.ndarray, eta: np.ndarray, d: float, alpha: float) -> np.ndarray:
    """Eqs (10) last column and (12): p = d (-h1, -(c_eta h2 + s_eta h3), c_eta h3 - s_eta h2)."""
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    ca, sa = math.cos(alpha), math.sin(alpha)
    ce, se = np.cos(eta), np.sin(eta)
    h1 = c1 * s2 * sa - s1 * (1 - ca)
    h2 = c1 * (1 - ca) + s1 * s2 * sa
    h3 = c2 * sa
    return np.stack([-d * h1, -d * (ce * h2 + se * h3), d * (ce * h3 - se * h2)], axis=-1)


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
    d, alpha, _ = _params(d, alpha)
    q = as_input(q, "q", (4,))
    eta = float(as_input(eta, "eta"))
    q1, q2, q3, q4 = (q[..., i] for i in range(4))
    shape = q1.shape
    rot = (
        _rx(np.full(shape, eta)) @ _rz(np.full(shape, np.pi)) @ _rz(q1) @ _ry(q2) @ _rx(np.full(shape, -alpha))
        @ _ry(q3) @ _rz(-q4) @ _rx(np.full(shape, np.pi - eta))
    )
    return _homogeneous(rot, _leg_position(q1, q2, np.float64(eta), d, alpha))


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
    d, alpha, _ = _params(d, alpha)
    q1, q2 = as_angles(q1, q2, names=("q1", "q2"))
    eta = float(as_input(eta, "eta"))
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    ca, sa = math.cos(alpha), math.sin(alpha)
    ce, se = math.cos(eta), math.sin(eta)
    g1 = c1**2 * (c2**2 - s2**2 * ca) + s1**2 * ca + 2 * c1 * s1 * s2 * sa
    g2 = c2 * (s1 * sa - c1 * s2 * (1 + ca))
    g3 = (c1**2 - s1**2) * s2 * sa + c1 * s1 * (2 * ca - c2**2 * (1 + ca))
    g4 = c2 * (c1 * sa + s1 * s2 * (1 + ca))
    g5 = c1**2 * ca + s1**2 * (c2**2 - s2**2 * ca) - 2 * c1 * s1 * s2 * sa
    g6 = s2**2 - c2**2 * ca
    g7 = (c2**2 - s2**2) * (1 + ca) + c1**2 * (s2**2 * (1 + ca) - (1 - ca)) - 2 * c1 * s1 * s2 * sa
    t23 = ce * se * g7 + (ce**2 - se**2) * g4
    rot = np.stack(
        [
            -g1, se * g2 - ce * g3, -ce * g2 - se * g3,
            -se * g2 + ce * g3, -2 * ce * se * g4 + ce**2 * g5 + se**2 * g6, t23,
            se * g3 + ce * g2, t23, 2 * ce * se * g4 + se**2 * g5 + ce**2 * g6,
        ],
        axis=-1,
    ).reshape(q1.shape + (3, 3))
    return _homogeneous(rot, _leg_position(q1, q2, np.float64(eta), d, alpha))


# ------------------------------------------------------------------------------------------ platform
def alpha_x(alpha_y, alpha_z) -> np.ndarray:
    """Seed eq (15), two-argument form: ``alpha_x = atan2(s_y s_z, c_y + c_z)``.

    Departure from the seed: eq (15) prints ``arctan(s_y s_z / (c_y + c_z))``, which is right only when
    ``c_y + c_z > 0``; elsewhere it lands on the wrong branch (off by pi) and the orientation it gives is
    not the one the legs produce (rotation error up to 2 in matrix entries, see docs/tripod.md).
    The value is undefined at ``c_y + c_z = 0 = s_y s_z``, which is the singular set 1 + c_y c_z = 0.
    """
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    return np.arctan2(np.sin(ay) * np.sin(az), np.cos(ay) + np.cos(az))


def platform_rotation(alpha_y, alpha_z) -> np.ndarray:
    """Seed eqs (5) and (15): ``R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x(alpha_y, alpha_z))``, shape (..., 3, 3).

    This is the zero-torsion (constant-velocity) family: R is the rotation by the tilt angle theta about an
    axis perpendicular to x (the mechanism's base axis), where ``cos theta = c_y c_z``.
    """
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    return _rz(az) @ _ry(ay) @ _rx(alpha_x(ay, az))


def platform_axis(alpha_y, alpha_z) -> np.ndarray:
    """The platform axis ``R e_x = (c_z c_y, s_z c_y, -s_y)`` (first column of eq 5), shape (..., 3)."""
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    return np.stack([cz * cy, sz * cy, -sy], axis=-1)


def orientation_from_axis(axis) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`platform_axis` on ``alpha_y`` in [-pi/2, pi/2]: ``(-asin(r3), atan2(r2, r1))``.

    The platform orientation is fixed by its axis (zero torsion), so this also inverts
    :func:`platform_rotation`; at ``c_y = 0`` (axis = -+z) alpha_z is arbitrary and 0 is returned.
    """
    r = as_input(axis, "axis", (3,))
    r = r / np.linalg.norm(r, axis=-1, keepdims=True)
    ay = -np.arcsin(np.clip(r[..., 2], -1.0, 1.0))
    az = np.arctan2(r[..., 1], r[..., 0])
    return ay, az


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
    d, alpha, _ = _params(d, alpha)
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    b = platform_axis(ay, az)
    b[..., 0] += 1.0
    nb2 = 1.0 + np.cos(ay) * np.cos(az)
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(nb2 > SINGULAR_TOL, -d * np.sqrt(2.0 * (1.0 - math.cos(alpha))) / np.sqrt(2.0 * nb2), np.nan)
    return b * scale[..., None]


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


def _ik_eval(cy, sy, cz, sz, g: _Geometry):
    """Unchecked seed eqs (98), (102) on a trailing leg axis (call under ``np.errstate(invalid, divide)``).

    Args:
        cy, sy, cz, sz: cos / sin of alpha_y, alpha_z, shape (..., 1).
        g: the geometry's constants.

    Returns:
        ``(q1, q2, cos q2, sin q2)`` per leg (..., 3) and ``1 + c_y c_z`` (..., 1); NaN where undefined.
        The platform centre E is :func:`platform_position` (same operations, so the same bits).
    """
    nb2 = 1.0 + cy * cz
    scale = np.where(nb2 > SINGULAR_TOL, g.minus_l / np.sqrt(2.0 * nb2), np.nan)
    x, y, z = nb2 * scale, sz * cy * scale, -sy * scale  # E = -L b / |b|, b = (1 + c_y c_z, s_z c_y, -s_y)
    c2 = (g.ce * z - g.se * y) / g.dsa  # eq (98)
    q2 = np.arccos(c2)  # branch q2 in (0, pi); NaN where |c2| > 1
    s2 = np.sin(q2)
    w = -(g.ce * y + g.se * z)
    s2sa = s2 * g.sa
    det = g.d * (g.k2 + s2sa**2)  # corrected determinant (d^2 (...) with 1/d folded in)
    q1 = np.arctan2((g.k * x + s2sa * w) / det, (-s2sa * x + g.k * w) / det)  # eq (102)
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


def _checked_u(alpha_y, alpha_z, d, alpha, eta):
    """Validate once at a public entry point: (alpha_y, alpha_z) broadcast, their cos/sin (..., 1), geometry."""
    d, alpha, eta_arr = _params(d, alpha, eta)
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    yc, zc = ay[..., None], az[..., None]
    return ay, az, (np.cos(yc), np.sin(yc), np.cos(zc), np.sin(zc)), _geometry(d, alpha, eta_arr)


def ik(
    alpha_y,
    alpha_z,
    d: float = D,
    alpha: float = ALPHA,
    eta: Sequence[float] | None = None,
    *,
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

    Args:
        alpha_y, alpha_z: platform orientation (rad), broadcast together.
        d, alpha: geometry; eta: (eta_A, eta_B, eta_C) (default 0, 2pi/3, 4pi/3).
        return_mask: (batch) also return the success mask.

    Returns:
        (..., 12) joints ordered A_q1..A_q4, B_q1..B_q4, C_q1..C_q4.

    Raises:
        UnreachableError: (scalar) ``|cos q_K2| > 1`` for some leg K (outside the workspace).
        SingularityError: (scalar) ``sin q_K2 = 0`` (workspace boundary) or ``1 + c_y c_z = 0``.
        InvalidInputError: non-finite or non-broadcastable angles; InvalidParameterError: bad geometry.
    """
    ay, az, trig, g = _checked_u(alpha_y, alpha_z, d, alpha, eta)
    with np.errstate(invalid="ignore", divide="ignore"):
        q1, q2, c2, _, nb2 = _ik_eval(*trig, g)
    ok = _inside(c2, nb2)[..., 0]
    out = np.where(ok[..., None, None], np.stack([q1, q2, q2, q1], axis=-1), np.nan).reshape(ok.shape + (12,))
    return finish(
        out, ok, ay.ndim == 0, return_mask, lambda: _ik_error(ay, az, c2, *_ik_status(c2, nb2[..., 0]))
    )


def _jac_eval(cy, sy, cz, sz, s2, nb2, g: _Geometry) -> tuple[np.ndarray, np.ndarray]:
    """Unchecked eqs (103)-(105): the two columns of A_u, (..., 3) each, from the trig of u (..., 1),
    sin q_K2 (..., 3) and 1 + c_y c_z (..., 1) of :func:`_ik_eval` (call under ``np.errstate``).

    The expressions of :func:`actuation_jacobian`'s docstring, evaluated in the same order (repeated
    sub-expressions are computed once).
    """
    ck, sk, n = g.ce, g.se, nb2
    cpc = cy + cz
    ck_cpc, sk_cpc = ck * cpc, sk * cpc
    ck_sy, sk_sy, ck_cy = ck * sy, sk * sy, ck * cy
    ck_sy_sz, sk_sy_sz = ck_sy * sz, sk_sy * sz
    f = g.tan_half * (ck_sy + sk * cy * sz)  # eq (105)
    m = g.opc * s2**2 + 1 - g.ca
    p = n**2 + (ck_cy * sz - sk_sy) ** 2
    den = 2 * s2 * n**2 * m
    mf = -f
    a1 = mf * (ck_cpc - sk_sy_sz + (ck_cy - sk_sy_sz) * n) / den - (ck_sy_sz + sk_cpc) / p
    a2 = mf * cy * (sk_cpc + ck_sy_sz + sk * cz * n) / den + cy * (ck_cpc - sk_sy_sz) / p
    return a1, a2


def actuation_jacobian(
    alpha_y,
    alpha_z,
    d: float = D,
    alpha: float = ALPHA,
    eta: Sequence[float] | None = None,
    *,
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
    Undefined where :func:`ik` fails (NaN / same exceptions).
    """
    ay, az, trig, g = _checked_u(alpha_y, alpha_z, d, alpha, eta)
    with np.errstate(invalid="ignore", divide="ignore"):
        _, _, c2, s2, nb2 = _ik_eval(*trig, g)
        a1, a2 = _jac_eval(*trig, s2, nb2, g)
    ok = _inside(c2, nb2)[..., 0]
    out = np.where(ok[..., None, None], np.stack([a1, a2], axis=-1), np.nan)
    return finish(
        out, ok, ay.ndim == 0, return_mask, lambda: _ik_error(ay, az, c2, *_ik_status(c2, nb2[..., 0]))
    )


# ------------------------------------------------------------------------------------------ forward kinematics
#: :func:`_initial_guess` intersects the motor planes with the adjugate of M (rows: their unit normals) where
#: |det M| > PLANES_DET_MIN: there sigma_3 = |det M| / (sigma_1 sigma_2) > |det M| / 1.5 > 6.7e-9 (unit rows:
#: sigma_1 <= sqrt 3, sigma_1 sigma_2 <= 3/2), above the 1e-10 sigma_1 cut-off of the pseudo-inverse; below it
#: (nearly parallel planes) the SVD pseudo-inverse with rcond = 1e-10 gives the least-squares intersection.
PLANES_DET_MIN = 1e-8
#: Relative singular-value cut-off of the Gauss-Newton step (that of ``np.linalg.pinv(A_u, rcond=1e-12)``).
STEP_RCOND = 1e-12


def _initial_guess(qm: np.ndarray, g: _Geometry) -> tuple[np.ndarray, np.ndarray]:
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
    return ay, az


def _gauss_newton_step(a1: np.ndarray, a2: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``-pinv(A) r`` for ``A = [a1 a2]`` (n, 3, 2) given as its columns (n, 3), without an SVD; (n, 1) each.

    Least squares in closed form: with ``n = a1 x a2``, ``|n|^2 = det(A^T A)`` (Lagrange's identity) and the
    normal equations solved by Cramer's rule, ``x = ((r x a2) . n, (a1 x r) . n) / |n|^2``. Written with cross
    products, no entry of ``A^T A`` is formed, so the error grows like cond(A), not cond(A)^2. Where
    ``sigma_2 <= STEP_RCOND sigma_1`` (i.e. ``|n|^2 <= STEP_RCOND^2 |A|_F^4``: ``alpha_y`` at +-pi/2 makes
    the second column vanish), the rank-1 pseudo-inverse ``A^T r / |A|_F^2`` is used, as ``np.linalg.pinv``
    with that rcond would (``0`` for ``A = 0``).
    """
    a1i, a1j, a2i, a2j, ri, rj = a1[:, _NEXT], a1[:, _PREV], a2[:, _NEXT], a2[:, _PREV], r[:, _NEXT], r[:, _PREV]
    n = a1i * a2j - a1j * a2i  # a1 x a2
    nn = np.add.reduce(n * n, axis=-1, keepdims=True)
    s0 = np.add.reduce((a2i * rj - a2j * ri) * n, axis=-1, keepdims=True) / nn  # -((r x a2) . n) / |n|^2
    s1 = np.add.reduce((ri * a1j - rj * a1i) * n, axis=-1, keepdims=True) / nn  # -((a1 x r) . n) / |n|^2
    f = np.add.reduce(a1 * a1 + a2 * a2, axis=-1, keepdims=True)
    rank1 = nn <= (STEP_RCOND * STEP_RCOND) * f * f
    if rank1.any():
        fs = np.where(f > 0, f, 1.0)
        s0 = np.where(rank1, -np.add.reduce(a1 * r, axis=-1, keepdims=True) / fs, s0)
        s1 = np.where(rank1, -np.add.reduce(a2 * r, axis=-1, keepdims=True) / fs, s1)
    return s0, s1


def _fk_core(qm: np.ndarray, g: _Geometry, tol: float, max_iter: int):
    """Unchecked :func:`fk` on motors (n, 3) (call under ``np.errstate(invalid, divide)``).

    Returns:
        alpha_y, alpha_z, inconsistency, converged, active: (n, 1) each.
    """
    ay, az = _initial_guess(qm, g)
    converged = np.zeros(ay.shape, dtype=bool)
    active = np.ones(ay.shape, dtype=bool)
    rn_prev = np.full(ay.shape, np.inf)
    for _ in range(max_iter):
        cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
        q1, _, c2, s2, nb2 = _ik_eval(cy, sy, cz, sz, g)
        a1, a2 = _jac_eval(cy, sy, cz, sz, s2, nb2, g)
        r = _wrap(q1 - qm)
        rn = np.sqrt(np.add.reduce(r * r, axis=-1, keepdims=True))
        stalled = rn >= rn_prev  # no progress: at the (least-squares) minimum to rounding
        finite = np.isfinite(rn)
        rn_prev = np.where(finite, rn, np.inf)
        active &= _inside(c2, nb2) & finite  # A_u and r are finite exactly there
        s0, s1 = _gauss_newton_step(a1, a2, r)
        # converged when the step, or its effect on the motors (the step is ill-determined near the
        # parametrisation singularity c_y = 0 and near 1 + c_y c_z = 0), is below tol
        motor_step = np.maximum.reduce(np.abs(a1 * s0 + a2 * s1), axis=-1, keepdims=True)
        small = (np.maximum(np.abs(s0), np.abs(s1)) <= tol) | (motor_step <= tol) | stalled
        upd = active & ~converged
        ay = np.where(upd, ay + s0, ay)
        az = np.where(upd, az + s1, az)
        converged |= active & small
        if (converged | ~active).all():
            break
    # report alpha_y in [-pi/2, pi/2], alpha_z in [-pi, pi)
    flip = np.cos(ay) < 0
    ay = _wrap(np.where(flip, np.pi - ay, ay))
    az = _wrap(np.where(flip, az + np.pi, az))
    q1 = _ik_eval(np.cos(ay), np.sin(ay), np.cos(az), np.sin(az), g)[0]
    r = _wrap(q1 - qm)
    return ay, az, np.sqrt(np.add.reduce(r * r, axis=-1, keepdims=True)), converged, active


def fk(
    q_A1,
    q_B1,
    q_C1,
    d: float = D,
    alpha: float = ALPHA,
    eta: Sequence[float] | None = None,
    *,
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
    exact to rounding and one iteration confirms it. The result is reported with ``alpha_y`` in
    [-pi/2, pi/2] (``(pi - alpha_y, alpha_z + pi)`` is the same orientation). Inputs are checked once here;
    the iteration runs on the unchecked private functions (a single call is a batch of one).

    Redundant actuation: three motor angles produced by no pose are not averaged silently. The
    inconsistency ``|r|`` (rad) at the least-squares solution is returned; above ``max_inconsistency`` the
    call fails (scalar: ``UnreachableError`` carrying the least-squares pose in ``closest``; batch: NaN).
    Pass ``max_inconsistency=np.inf`` to get least-squares poses for noisy motor readings.

    Args:
        q_A1, q_B1, q_C1: motor angles (rad), broadcast together.
        d, alpha, eta: geometry.
        tol: step-size tolerance (rad). max_iter: iteration cap.
        max_inconsistency: largest accepted residual norm of the motor angles (rad).
        return_mask: (batch) also return the success mask.

    Returns:
        ``(alpha_y, alpha_z, inconsistency)`` (each of the batch shape).

    Raises:
        UnreachableError: (scalar) the motor angles are inconsistent beyond ``max_inconsistency``, or
            the iterate left the workspace.
        ConvergenceError: (scalar) no convergence within ``max_iter`` (e.g. at a singularity of A_u).
    """
    d, alpha, eta_arr = _params(d, alpha, eta)
    a1, b1, c1 = as_angles(q_A1, q_B1, q_C1, names=("q_A1", "q_B1", "q_C1"))
    shape = a1.shape
    qm = np.stack([a1, b1, c1], axis=-1).reshape(-1, 3)
    with np.errstate(invalid="ignore", divide="ignore"):
        ay, az, inconsistency, converged, active = _fk_core(qm, _geometry(d, alpha, eta_arr), tol, max_iter)
    ay, az, inconsistency = ay.reshape(shape), az.reshape(shape), inconsistency.reshape(shape)
    converged, active = converged.reshape(shape), active.reshape(shape)
    ok = converged & active & (inconsistency <= max_inconsistency)
    nan = np.where(ok, 0.0, np.nan)

    def error() -> Exception:
        motors = f"(q_A1, q_B1, q_C1) = ({float(a1):.17g}, {float(b1):.17g}, {float(c1):.17g})"
        target = qm.reshape(shape + (3,))
        if not active:
            return UnreachableError(f"{motors}: the solver left the workspace; no pose was found", target=target)
        if not converged:
            return ConvergenceError(
                f"{motors}: Gauss-Newton did not converge in {max_iter} iterations (singular A_u?)"
            )
        return UnreachableError(
            f"{motors} are inconsistent: no pose produces all three; the least-squares pose "
            f"(alpha_y, alpha_z) = ({float(ay):.17g}, {float(az):.17g}) misses them by {float(inconsistency):.3e} rad "
            f"(max_inconsistency = {max_inconsistency:.1e})",
            target=target,
            closest=(float(ay), float(az)),
        )

    return finish((ay + nan, az + nan, inconsistency + nan), ok, a1.ndim == 0, return_mask, error)


# ------------------------------------------------------------------------------------------ workspace
@dataclass(frozen=True)
class Workspace:
    """The reachable set of (alpha_y, alpha_z) for given d, alpha, eta (see :func:`workspace`).

    Attributes:
        alpha_y, alpha_z: 1-D grids (rad); fields below are indexed ``[i_y, i_z]``.
        cos_q2: (3, ny, nz) cos q_K2 per leg (eq 98); the leg reaches the pose where |cos q_K2| < 1.
        reachable: (ny, nz) True inside the workspace (all legs reach, not singular).
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


def _tilt_to_u(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    ay = -np.arcsin(np.clip(np.sin(theta) * np.sin(phi), -1.0, 1.0))
    az = np.arctan2(np.sin(theta) * np.cos(phi), np.cos(theta))
    pts = np.stack([ay, az], axis=-1)
    # split pieces where alpha_z wraps around
    jump = np.abs(np.diff(az)) > np.pi
    if np.any(jump):
        idx = np.nonzero(jump)[0] + 1
        pts = np.insert(pts, idx, np.nan, axis=0)
    return pts


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
        d, alpha, eta: geometry. n: grid size per axis. m: samples of phi along the curves.
    """
    d, alpha, eta_arr = _params(d, alpha, eta)
    ay = np.linspace(-np.pi / 2, np.pi / 2, n)
    az = np.linspace(-np.pi, np.pi, n)
    gy, gz = np.meshgrid(ay, az, indexing="ij")
    _, c2, one_cc = _ik_core(gy, gz, d, alpha, eta_arr)
    sing, unreachable, leg_sing = _ik_status(c2, one_cc)
    reachable = ~sing & ~unreachable.any(axis=-1) & ~leg_sing.any(axis=-1)
    phi = np.linspace(-np.pi, np.pi, m)
    ch = math.cos(alpha / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = ch / np.abs(np.sin(phi[:, None] - eta_arr))  # (m, 3)
        theta_k = np.where(ratio <= 1.0, 2.0 * np.arcsin(np.minimum(ratio, 1.0)), np.nan)
    tilt_max = np.nanmin(np.where(np.isnan(theta_k), np.pi, theta_k), axis=-1)
    on_curve = tilt_max < np.pi
    boundary = _tilt_to_u(np.where(on_curve, tilt_max, np.nan), phi)
    leg_singular = {leg: _tilt_to_u(theta_k[:, k], phi) for k, leg in enumerate(LEGS)}
    platform_singular = np.array([[0.0, -np.pi], [0.0, np.pi]])
    return Workspace(
        alpha_y=ay,
        alpha_z=az,
        cos_q2=np.moveaxis(c2, -1, 0),
        reachable=reachable,
        boundary=boundary,
        leg_singular=leg_singular,
        platform_singular=platform_singular,
        tilt_max=tilt_max,
        phi=phi,
    )
