"""Seed 002's textbook leg IK (law of cosines), transcribed with its two fixes: :func:`textbook_ik`, with
:func:`textbook_frame` (base frame -> seed 002's frame) and :func:`textbook_to_joints` (its angles -> q).

The names keep the seed's word on purpose: these functions are the seed as printed (fixed), beside the
closed form of :func:`legkin.quadruped.ik_all` (the generic :class:`legkin.legs.Leg`), whose (s_u, k) = (-1, -1)
branch they reproduce: a textbook cross-check (``legkin check quadruped``'s "seed 002" row and
``tests/test_quadruped.py``), not an implementation the other functions use.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from .._batch import check_flag, check_number
from .._kernels import OK, as_rows, batch_kernel, batch_loop, kernel, prange
from .._rotations import wrap_k
from ..legs._fk_kernels import _finite3
from ._common import foot_z_of, leg_index, raise_bad, rows
from .constants import BAD_INPUT, KNEE_OFFSET, PI, SX, SY, X01, X34, Y01, Z01
from .geometry import Geometry

__all__ = ["textbook_ik", "textbook_frame", "textbook_to_joints"]


@kernel(entry=True)
def _textbook_frame_k(p, li, out) -> int:
    """``(x_f, y_f, z_f) = (s_y d_y, d_x, -d_z)`` with ``d = p - h``."""
    if not _finite3(p):
        return BAD_INPUT
    sy = SY[li]
    out[0], out[1], out[2] = sy * (p[1] - sy * Y01), p[0] - SX[li] * X01, -(p[2] - Z01)
    return OK


_textbook_frame_batch = batch_loop(_textbook_frame_k, min_parallel=256, parfor=True)


def textbook_frame(p: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Express base-frame foot targets (..., 3) in seed 002's frame for ``leg``.

    Seed 002 works from the abduction axis with x lateral (towards the hip offset, so mirrored on right
    legs: x_f -> -x_f), y forward and z down: ``(x_f, y_f, z_f) = (s_y d_y, d_x, -d_z)`` with ``d = p - h``.
    ``geometry`` is accepted like everywhere (checked; the frame does not depend on it).

    Args:
        p: foot targets (3,) or (..., 3) in the base frame (m).
        leg: ``"LF"``, ``"RF"``, ``"LH"`` or ``"RH"``.
        geometry: the quadruped's geometry (checked only).

    Returns:
        The targets in seed 002's frame of ``leg``, same shape (m).
    """
    if geometry is not None:
        foot_z_of(geometry)
    li = leg_index(leg)
    arr = rows(p, "p")
    if arr.ndim == 1:
        out = np.empty(3)
        if _textbook_frame_k(arr, li, out):
            raise_bad(p, "p")
        return out
    out = np.empty(arr.shape)
    if _textbook_frame_batch(as_rows(arr, 3), li, out.reshape(-1, 3)):
        raise_bad(p, "p")
    return out


@kernel(entry=True)
def _textbook_ik_k(p, a, b, c, literal, out) -> int:
    """Seed 002's law of cosines for one target ``p`` (3,) in its frame (NaN where acos/asin are out of range)."""
    if not _finite3(p):
        return BAD_INPUT
    xf, yf, zf = p[0], p[1], p[2]
    big_l = xf * xf + yf * yf + zf * zf
    m = np.sqrt(big_l - a * a)
    first = np.arctan(xf / zf) if literal else np.arctan2(xf, zf)
    out[0] = first + np.arccos(a / np.sqrt(xf * xf + zf * zf))
    out[1] = PI / 2 - np.arcsin(-yf / m) - np.arccos((b * b - a * a - c * c + big_l) / (2 * b * m))
    out[2] = np.arccos((a * a + b * b + c * c - big_l) / (2 * b * c))
    return OK


@batch_kernel(rows="p out", min_parallel=256, parfor=True)
def _textbook_ik_batch(p, a, b, c, literal, out) -> int:
    n, bad = p.shape[0], 0
    for i in prange(n):
        bad += _textbook_ik_k(p[i], a, b, c, literal, out[i]) != OK
    return bad


def textbook_ik(p: npt.ArrayLike, a: float, b: float, c: float, *, literal: bool = False) -> np.ndarray:
    """Seed 002's law-of-cosines IK: (theta_abad, theta_hip, theta_knee), shape (..., 3).

    .. math::
        \\theta_{abad} = \\operatorname{atan2}(x_f, z_f) + \\arccos\\frac{a}{\\sqrt{x_f^2 + z_f^2}}, \\quad
        \\theta_{hip} = \\frac{\\pi}{2} - \\arcsin\\frac{-y_f}{\\sqrt{L - a^2}}
            - \\arccos\\frac{b^2 - a^2 - c^2 + L}{2 b \\sqrt{L - a^2}}, \\quad
        \\theta_{knee} = \\arccos\\frac{a^2 + b^2 + c^2 - L}{2 b c}

    with ``L = x_f^2 + y_f^2 + z_f^2`` and ``p = (x_f, y_f, z_f)`` in seed 002's frame (:func:`textbook_frame`).
    Two fixes to the seed as printed: "90" is pi/2 (radians), and ``atan(x_f / z_f)`` is ``atan2(x_f, z_f)``
    (the literal atan is wrong for every z_f < 0 and divides by zero at z_f = 0). ``literal=True`` keeps the
    printed atan, to show that failure. Only one branch (knee k = -1, foot below the hip) is returned.
    ``theta_adab`` and ``theta_abd`` in the seed are typos for theta_abad. NaN where acos/asin are out of range
    (a transcription of the seed: it does not follow the single-call-raises rule of the other functions).
    The seed's own geometry is ``(a, b, c)`` (a = y12, b = L1 = |t23|, c = L2 = |t34| = hypot(x34, foot_z)).

    Args:
        p: targets (3,) or (..., 3) in seed 002's frame (m).
        a: the abduction offset y12 (m).
        b: the thigh length L1 (m).
        c: the shank length L2 (m).
        literal: keep the printed ``atan(x_f / z_f)`` (to show its failure).

    Returns:
        (theta_abad, theta_hip, theta_knee) (3,) or (..., 3) (rad), NaN where the seed's formulas leave their
        domain.

    Raises:
        InvalidInputError: ``p`` not a finite real array (..., 3).
        InvalidParameterError: ``a`` not a finite number >= 0, ``b`` or ``c`` not finite and > 0, ``literal``
            not a bool.
    """
    a = check_number(a, "a", 0.0)
    b = check_number(b, "b", 0.0, low_open=True)
    c = check_number(c, "c", 0.0, low_open=True)
    literal = check_flag(literal, "literal")
    arr = rows(p, "p")
    if arr.ndim == 1:
        out = np.empty(3)
        if _textbook_ik_k(arr, a, b, c, literal, out):
            raise_bad(p, "p")
        return out
    out = np.empty(arr.shape)
    if _textbook_ik_batch(as_rows(arr, 3), a, b, c, literal, out.reshape(-1, 3)):
        raise_bad(p, "p")
    return out


@kernel(entry=True)
def _textbook_to_joints_k(theta, beta, out) -> int:
    """``q = wrap(theta - (pi/2, KNEE_OFFSET, KNEE_OFFSET - beta))`` (NaN maps to NaN)."""
    out[0] = wrap_k(theta[0] - PI / 2)
    out[1] = wrap_k(theta[1] - KNEE_OFFSET)
    out[2] = wrap_k(theta[2] - KNEE_OFFSET + beta)
    return OK


@batch_kernel(rows="theta out", min_parallel=256, parfor=True)
def _textbook_to_joints_batch(theta, beta, out) -> None:
    n = theta.shape[0]
    for i in prange(n):
        _textbook_to_joints_k(theta[i], beta, out[i])


def textbook_to_joints(theta: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """Map seed 002's (theta_abad, theta_hip, theta_knee) (..., 3) onto the quadruped's (q1, q2, q3) of ``leg``.

    With a = y12, b = L1, c = L2: ``q1 = theta_abad - pi/2``, ``q2 = theta_hip - 0.1174``,
    ``q3 = theta_knee - 0.1174 + beta`` (0.1174 = atan(0.041509 / 0.35192), the thigh's offset angle;
    ``beta = atan2(foot_z, x34)`` the foot's, 0 for the default geometry); this is :func:`ik_all`'s branch
    (s_u, k) = (-1, -1). The same formulas hold on both sides because seed 002's frame is mirrored on right
    legs (see :func:`textbook_frame`). NaN entries (``textbook_ik`` out of range) map to NaN.

    Args:
        theta: seed 002's angles (3,) or (..., 3) (rad).
        leg: ``"LF"``, ``"RF"``, ``"LH"`` or ``"RH"``.
        geometry: the quadruped's geometry (its ``foot_z`` sets ``beta``); None: the default.

    Returns:
        The joint values (q1, q2, q3), same shape (rad).
    """
    fz = 0.0 if geometry is None else foot_z_of(geometry)
    leg_index(leg)
    beta = math.atan2(fz, X34) if fz else 0.0  # atan2(0, X34) is 0: no call for the default geometry
    arr = rows(theta, "theta")
    if arr.ndim == 1:
        out = np.empty(3)
        _textbook_to_joints_k(arr, beta, out)
        return out
    out = np.empty(arr.shape)
    _textbook_to_joints_batch(as_rows(arr, 3), beta, out.reshape(-1, 3))
    return out
