"""One leg of the tripod as an open chain: its end-effector placement, seed eqs (10)-(12).

Leg K (joints ``K_q1..K_q4``, ``eta = eta_K``), with ``P(eta) = Rx(eta) Rz(pi)``::

    T_K = P(eta) Rz(q1) Ry(q2) [Tr(0, d, 0) Rx(-alpha) Tr(0, -d, 0)] Ry(q3) Rz(-q4) Rx(pi - eta)
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input, check_choice
from .._kernels import OK, batch_kernel, kernel
from .._rotations import rot_k
from ._common import LEGS, ST_NONFINITE, geometry_of
from .geometry import G_CA, G_D, G_SA, Geometry

__all__ = ["leg_transform", "leg_transform_cv"]


# ------------------------------------------------------------------------------------------ kernels
@kernel(inline=True)
def _k_matmul3(A, B):  # type: ignore[no-untyped-def]
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
def _k_leg_position(q1, q2, eta, G, T):  # type: ignore[no-untyped-def]
    """Eqs (10) last column and (12): T[:3, 3] = d (-h1, -(c_eta h2 + s_eta h3), c_eta h3 - s_eta h2),
    T[3] = (0 0 0 1)."""
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    ca, sa, d = G[G_CA], G[G_SA], G[G_D]
    ce, se = np.cos(eta), np.sin(eta)
    h1 = c1 * s2 * sa - s1 * (1 - ca)
    h2 = c1 * (1 - ca) + s1 * s2 * sa
    h3 = c2 * sa
    T[0, 3], T[1, 3], T[2, 3] = -d * h1, -d * (ce * h2 + se * h3), d * (ce * h3 - se * h2)
    T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@kernel(entry=True, inline=True)
def _k_leg_transform(q1, q2, q3, q4, eta, alpha, G, T):  # type: ignore[no-untyped-def]
    """:func:`leg_transform` of one joint vector into T (4, 4); returns OK or ST_NONFINITE (T not written)."""
    if not (np.isfinite(q1) and np.isfinite(q2) and np.isfinite(q3) and np.isfinite(q4)):
        return ST_NONFINITE
    # Rx(eta) Rz(pi) Rz(q1) Ry(q2) Rx(-alpha) Ry(q3) Rz(-q4) Rx(pi - eta)
    R = _k_matmul3(rot_k(0, eta), rot_k(2, math.pi))
    R = _k_matmul3(R, rot_k(2, q1))
    R = _k_matmul3(R, rot_k(1, q2))
    R = _k_matmul3(R, rot_k(0, -alpha))
    R = _k_matmul3(R, rot_k(1, q3))
    R = _k_matmul3(R, rot_k(2, -q4))
    R = _k_matmul3(R, rot_k(0, math.pi - eta))
    for i in range(3):
        T[i, 0], T[i, 1], T[i, 2] = R[3 * i], R[3 * i + 1], R[3 * i + 2]
    _k_leg_position(q1, q2, eta, G, T)
    return OK


@kernel(entry=True, inline=True)
def _k_leg_transform_cv(q1, q2, eta, G, T):  # type: ignore[no-untyped-def]
    """Seed eqs (10)-(12) (:func:`leg_transform_cv`, T33 sign corrected) into T (4, 4)."""
    c1, s1, c2, s2 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2)
    ca, sa = G[G_CA], G[G_SA]
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


def _leg_transform_loop(q, eta, alpha, G, T):  # type: ignore[no-untyped-def]
    """leg_transform over joint vectors (n, 4): T (n, 4, 4)."""
    for i in range(q.shape[0]):
        _k_leg_transform(q[i, 0], q[i, 1], q[i, 2], q[i, 3], eta, alpha, G, T[i])


def _leg_transform_cv_loop(q, eta, G, T):  # type: ignore[no-untyped-def]
    """leg_transform_cv over (n, 2) joint pairs: T (n, 4, 4)."""
    for i in range(q.shape[0]):
        _k_leg_transform_cv(q[i, 0], q[i, 1], eta, G, T[i])


_LEG_TRANSFORM = batch_kernel(rows="q T", min_parallel=4096)(_leg_transform_loop)
_LEG_TRANSFORM_CV = batch_kernel(rows="q T", min_parallel=4096)(_leg_transform_cv_loop)


# ------------------------------------------------------------------------------------------ arguments
def _leg_eta(leg: object, geometry: Geometry | None) -> tuple[float, Geometry]:
    """(eta, geometry) of a call: the placement angle (rad) of ``leg`` (a name of LEGS) and the checked geometry."""
    g = geometry_of(geometry)
    if leg == "A" and type(leg) is str:
        return g.eta[0], g
    check_choice(leg, "leg", LEGS)
    return g.eta[LEGS.index(leg)], g  # type: ignore[arg-type]


# ------------------------------------------------------------------------------------------ public
def leg_transform(q: ArrayLike, leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Placement of K_ee in the base frame for any four joint values of leg K (open chain).

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
        leg: ``"A"``, ``"B"`` or ``"C"`` (its placement angle is ``geometry.eta``).
        geometry: the tripod's :class:`Geometry` (None: the default).

    Returns:
        (..., 4, 4) homogeneous transforms.
    """
    eta, g = _leg_eta(leg, geometry)
    G = g._vector
    if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (4,):
        T = np.empty((4, 4))
        if _k_leg_transform(q[0], q[1], q[2], q[3], eta, g.alpha, G, T) == OK:
            return T
    qa = as_input(q, "q", (4,))
    shape = qa.shape[:-1]
    rows = np.ascontiguousarray(qa.reshape(-1, 4))
    T = np.empty((rows.shape[0], 4, 4))
    _LEG_TRANSFORM(rows, eta, g.alpha, G, T)
    return T.reshape(shape + (4, 4))


def leg_transform_cv(q: ArrayLike, leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Seed eqs (10)-(12): placement of K_ee of leg K on the constant-velocity branch (q3 = q2, q4 = q1).

    ``T11 = -g1``, ``T21 = -s_eta g2 + c_eta g3``, ``T31 = s_eta g3 + c_eta g2``, ``T12 = s_eta g2 - c_eta g3``,
    ``T22 = -2 c_eta s_eta g4 + c_eta^2 g5 + s_eta^2 g6``, ``T32 = T23 = c_eta s_eta g7 + (c_eta^2 - s_eta^2) g4``,
    ``T13 = -c_eta g2 - s_eta g3``, ``T33 = +2 c_eta s_eta g4 + s_eta^2 g5 + c_eta^2 g6`` (**sign corrected**:
    eq (10) prints ``-2 c_eta s_eta g4``; with the minus the matrix is not a rotation for eta != 0 mod pi/2),
    ``T14 = -d h1``, ``T24 = -d (c_eta h2 + s_eta h3)``, ``T34 = d (c_eta h3 - s_eta h2)``, with g1..g7 of
    eq (11) and h1..h3 of eq (12), transcribed as printed.

    Args:
        q: joint values (..., 2) = (q1, q2) of the leg (rad).
        leg: ``"A"``, ``"B"`` or ``"C"``.
        geometry: the tripod's :class:`Geometry` (None: the default).

    Returns:
        (..., 4, 4) homogeneous transforms (m for the translation).
    """
    eta, g = _leg_eta(leg, geometry)
    if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (2,) and math.isfinite(q[0]) \
            and math.isfinite(q[1]):
        T = np.empty((4, 4))
        _k_leg_transform_cv(q[0], q[1], eta, g._vector, T)
        return T
    qa = as_input(q, "q", (2,))
    shape = qa.shape[:-1]
    rows = np.ascontiguousarray(qa.reshape(-1, 2))
    T = np.empty((rows.shape[0], 4, 4))
    _LEG_TRANSFORM_CV(rows, eta, g._vector, T)
    return T.reshape(shape + (4, 4))
