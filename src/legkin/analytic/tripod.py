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
from typing import Sequence

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
def _ik_core(ay: np.ndarray, az: np.ndarray, d: float, alpha: float, eta: np.ndarray):
    """Unchecked vectorised IK: joints (..., 3, 4), cos q_K2 (..., 3), 1 + c_y c_z (...)."""
    e = platform_position(ay, az, d, alpha)  # (..., 3), NaN on the singular set
    x, y, z = e[..., 0:1], e[..., 1:2], e[..., 2:3]
    ce, se = np.cos(eta), np.sin(eta)  # (3,)
    ca, sa = math.cos(alpha), math.sin(alpha)
    c2 = (ce * z - se * y) / (d * sa)  # eq (98)
    with np.errstate(invalid="ignore"):
        q2 = np.arccos(c2)  # branch q2 in (0, pi); NaN where |c2| > 1
    s2 = np.sin(q2)
    w = -(ce * y + se * z)
    det = d * ((1 - ca) ** 2 + (s2 * sa) ** 2)  # corrected determinant (d^2 (...) with 1/d folded in)
    s1 = ((1 - ca) * x + s2 * sa * w) / det  # eq (102)
    c1 = (-s2 * sa * x + (1 - ca) * w) / det
    q1 = np.arctan2(s1, c1)
    joints = np.stack([q1, q2, q2, q1], axis=-1)
    return joints, c2, 1.0 + np.cos(ay) * np.cos(az)


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
    d, alpha, eta_arr = _params(d, alpha, eta)
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    joints, c2, one_cc = _ik_core(ay, az, d, alpha, eta_arr)
    sing, unreachable, leg_sing = _ik_status(c2, one_cc)
    ok = ~sing & ~unreachable.any(axis=-1) & ~leg_sing.any(axis=-1)
    out = np.where(ok[..., None, None], joints, np.nan).reshape(ok.shape + (12,))
    return finish(
        out, ok, ay.ndim == 0, return_mask, lambda: _ik_error(ay, az, c2, sing, unreachable, leg_sing)
    )


def _jacobian_core(ay: np.ndarray, az: np.ndarray, joints: np.ndarray, alpha: float, eta: np.ndarray) -> np.ndarray:
    """Unchecked eqs (103)-(105) from the IK joints (..., 3, 4); (..., 3, 2)."""
    eta_arr = eta
    cy, sy, cz, sz = (f(a)[..., None] for f, a in ((np.cos, ay), (np.sin, ay), (np.cos, az), (np.sin, az)))
    ck, sk = np.cos(eta_arr), np.sin(eta_arr)
    s2 = np.sin(joints[..., 1])
    ca = math.cos(alpha)
    n = 1.0 + cy * cz
    f = math.tan(alpha / 2.0) * (ck * sy + sk * cy * sz)  # eq (105)
    m = (1 + ca) * s2**2 + 1 - ca
    p = n**2 + (ck * cy * sz - sk * sy) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        a1 = -f * (ck * (cy + cz) - sk * sy * sz + (ck * cy - sk * sy * sz) * n) / (2 * s2 * n**2 * m) - (
            ck * sy * sz + sk * (cy + cz)
        ) / p
        a2 = -f * cy * (sk * (cy + cz) + ck * sy * sz + sk * cz * n) / (2 * s2 * n**2 * m) + cy * (
            ck * (cy + cz) - sk * sy * sz
        ) / p
    return np.stack([a1, a2], axis=-1)


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
    d, alpha, eta_arr = _params(d, alpha, eta)
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    joints, c2, one_cc = _ik_core(ay, az, d, alpha, eta_arr)
    sing, unreachable, leg_sing = _ik_status(c2, one_cc)
    ok = ~sing & ~unreachable.any(axis=-1) & ~leg_sing.any(axis=-1)
    jac = _jacobian_core(ay, az, joints, alpha, eta_arr)
    out = np.where(ok[..., None, None], jac, np.nan)
    return finish(
        out, ok, ay.ndim == 0, return_mask, lambda: _ik_error(ay, az, c2, sing, unreachable, leg_sing)
    )


# ------------------------------------------------------------------------------------------ forward kinematics
def _initial_guess(qm: np.ndarray, d: float, alpha: float, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form start for :func:`fk` from the motor angles (..., 3).

    Eliminating s_K2 from the two rows of eq (101) leaves one linear equation per motor,
    ``s_K1 x - c_K1 (c_K y + s_K z) = d (1 - c_alpha)``: E lies on three planes. Their least-squares
    intersection, pushed onto the sphere |E| = L (eq 64a), gives the platform axis
    ``R e_x = 2 (e_x . e) e - e_x`` (e = E / |E|: E is on the bisector, see :func:`platform_position`).
    """
    s1, c1 = np.sin(qm), np.cos(qm)
    ce, se = np.cos(eta), np.sin(eta)
    normals = np.stack([s1, -c1 * ce, -c1 * se], axis=-1)  # (..., 3, 3)
    rhs = np.full(qm.shape, d * (1 - math.cos(alpha)))
    pinv = np.linalg.pinv(normals, rcond=1e-10)
    e = (pinv @ rhs[..., None])[..., 0]
    norm = np.linalg.norm(e, axis=-1, keepdims=True)
    e = np.where(norm > 0, e / np.where(norm > 0, norm, 1.0), np.array([-1.0, 0.0, 0.0]))
    axis = 2.0 * e[..., 0:1] * e
    axis[..., 0] -= 1.0
    return orientation_from_axis(axis)


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
    ``u <- u - pinv(A_u) r``, from the closed-form start of :func:`_initial_guess` (the motor planes; not in
    the seed), until the step (or its image ``A_u du`` in the motors) is below ``tol``; it typically takes 1-3 iterations. The result is reported
    with ``alpha_y`` in [-pi/2, pi/2] (``(pi - alpha_y, alpha_z + pi)`` is the same orientation).

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
    qm = np.stack([a1, b1, c1], axis=-1)
    ay, az = _initial_guess(qm, d, alpha, eta_arr)
    converged = np.zeros(ay.shape, dtype=bool)
    active = np.ones(ay.shape, dtype=bool)
    rn_prev = np.full(ay.shape, np.inf)
    for _ in range(max_iter):
        joints, c2, one_cc = _ik_core(ay, az, d, alpha, eta_arr)
        sing, unreachable, leg_sing = _ik_status(c2, one_cc)
        inside = ~sing & ~unreachable.any(axis=-1) & ~leg_sing.any(axis=-1)
        jac = np.where(inside[..., None, None], _jacobian_core(ay, az, joints, alpha, eta_arr), np.nan)
        r = _wrap(joints[..., 0] - qm)
        rn = np.linalg.norm(r, axis=-1)
        stalled = rn >= rn_prev  # no progress: at the (least-squares) minimum to rounding
        rn_prev = np.where(np.isfinite(rn), rn, np.inf)
        with np.errstate(invalid="ignore"):
            step = -(np.linalg.pinv(np.nan_to_num(jac), rcond=1e-12) @ np.nan_to_num(r)[..., None])[..., 0]
        bad = ~np.all(np.isfinite(jac), axis=(-1, -2)) | ~np.all(np.isfinite(r), axis=-1)
        active &= ~bad
        # converged when the step, or its effect on the motors (the step is ill-determined near the
        # parametrisation singularity c_y = 0 and near 1 + c_y c_z = 0), is below tol
        motor_step = np.abs(np.nan_to_num(jac) @ step[..., None])[..., 0]
        small = (np.max(np.abs(step), axis=-1) <= tol) | (np.max(motor_step, axis=-1) <= tol) | stalled
        upd = active & ~converged
        ay = np.where(upd, ay + step[..., 0], ay)
        az = np.where(upd, az + step[..., 1], az)
        converged |= active & small
        if np.all(converged | ~active):
            break
    # report alpha_y in [-pi/2, pi/2], alpha_z in [-pi, pi)
    flip = np.cos(ay) < 0
    ay = np.where(flip, np.pi - ay, ay)
    az = np.where(flip, az + np.pi, az)
    ay, az = _wrap(ay), _wrap(az)
    joints, c2, one_cc = _ik_core(ay, az, d, alpha, eta_arr)
    r = _wrap(joints[..., 0] - qm)
    inconsistency = np.linalg.norm(r, axis=-1)
    consistent = inconsistency <= max_inconsistency
    ok = converged & active & consistent
    nan = np.where(ok, 0.0, np.nan)

    def error() -> Exception:
        motors = f"(q_A1, q_B1, q_C1) = ({float(a1):.17g}, {float(b1):.17g}, {float(c1):.17g})"
        if not active:
            return UnreachableError(f"{motors}: the solver left the workspace; no pose was found", target=qm)
        if not converged:
            return ConvergenceError(
                f"{motors}: Gauss-Newton did not converge in {max_iter} iterations (singular A_u?)"
            )
        return UnreachableError(
            f"{motors} are inconsistent: no pose produces all three; the least-squares pose "
            f"(alpha_y, alpha_z) = ({float(ay):.17g}, {float(az):.17g}) misses them by {float(inconsistency):.3e} rad "
            f"(max_inconsistency = {max_inconsistency:.1e})",
            target=qm,
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
