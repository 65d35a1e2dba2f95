"""The foot: its position from the platform pose and LL (seed 003, eqs 1, 17, 18, 20), the leg's forward
kinematics from the three motors (:func:`fk`, through the closed sub-chain's FK and eq 19) and its Jacobian."""

from __future__ import annotations

import math
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, dispatch, same_signature
from .._kernels import OK, batch_kernel, kernel
from ..errors import ConvergenceError, SingularityError
from ._options import SCALARS, ST_ASSEMBLE, ST_BAND, ST_INPUT, ST_SINGULAR, Branch, flat, mode_args, resolve
from .chains import CX, CY, CZ, OX, OZ, lever_tips_k, rod_rates_k
from .extension import ll_k
from .forward import fk_failure, fk_select_k
from .geometry import FK_GAIN_MAX, FOOT_X, RATIO, Geometry

__all__ = ["foot_position_from_platform", "fk", "jacobian"]


@kernel(entry=True)
def foot_k(r, p, t, out):
    """Foot FCS in CCS (seed eqs 1, 17, 18, 20): ``CENTER + R_P (o_LL + Ry(t) (FOOT_X, 0, 0))``."""
    if not (math.isfinite(r) and math.isfinite(p) and math.isfinite(t)):
        out[0], out[1], out[2] = math.nan, math.nan, math.nan
        return ST_INPUT
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    fx = OX + FOOT_X * math.cos(t)
    fz = OZ - FOOT_X * math.sin(t)
    out[0] = CX + (cp * fx + sp * fz)
    out[1] = CY + (sr * sp * fx - sr * cp * fz)
    out[2] = CZ + (-cr * sp * fx + cr * cp * fz)
    return OK


@batch_kernel(rows="r p t out", min_parallel=8192)
def _foot_b(r, p, t, out):
    for j in range(r.shape[0]):
        foot_k(r[j], p[j], t[j], out[j])


# --- forward kinematics of the closed sub-chain (the polynomial in tan(roll / 2), see the comment above


@kernel(inline=True)
def gain_k(r, p, tll, tip, dtip):
    """Spectral norm of d(foot)/d(theta1, theta2) (m/rad) at the pose (r, p) closed by the lever tips tip:
    ``dx/dtheta = N^-1 diag(D)``, ``dp/dx = [e_x x R f, (Rx(roll) e_y) x R f]``; inf on det N = 0."""
    nm = np.empty((2, 2))
    dd = np.empty(2)
    rod_rates_k(r, p, tip, dtip, nm, dd)
    return gain_of_rates_k(r, p, tll, nm, dd)


@kernel(inline=True)
def gain_of_rates_k(r, p, tll, nm, dd):
    """:func:`gain_k` from the rod system's Jacobian nm (2, 2) and rates dd (2,) (:func:`.chains.rod_rates_k`)."""
    return gain_cs_k(math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(tll), math.sin(tll), nm, dd)


@kernel
def gain_cs_k(cr, sr, cp, sp, ct, st, nm, dd):
    """:func:`gain_of_rates_k` from the cosines and sines of roll, pitch and theta_LL."""
    det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
    # adj(N) diag(D)
    j00, j01 = nm[1, 1] * dd[0], -nm[0, 1] * dd[1]
    j10, j11 = -nm[1, 0] * dd[0], nm[0, 0] * dd[1]
    ffx = OX + FOOT_X * ct
    ffz = OZ - FOOT_X * st
    fx = cp * ffx + sp * ffz
    fy = sr * sp * ffx - sr * cp * ffz
    fz = -cr * sp * ffx + cr * cp * ffz
    # dp/dx rows: (0, cr fz - sr fy), (-fz, sr fx), (fy, -cr fx)
    q0, q1 = cr * fz - sr * fy, sr * fx
    m00, m01 = q0 * j10, q0 * j11
    m10, m11 = -fz * j00 + q1 * j10, -fz * j01 + q1 * j11
    m20, m21 = fy * j00 - cr * fx * j10, fy * j01 - cr * fx * j11
    a = m00 * m00 + m10 * m10 + m20 * m20
    b = m00 * m01 + m10 * m11 + m20 * m21
    c = m01 * m01 + m11 * m11 + m21 * m21
    gain = math.sqrt(0.5 * (a + c) + math.sqrt(0.25 * (a - c) ** 2 + b * b)) / abs(det)
    return gain if math.isfinite(gain) else math.inf


@kernel(entry=True, inline=True)
def foot_position_k(t1, t2, t0, sv, b1, b2, s, out, aux):
    """:func:`fk`: the FK pose in mode (b1, b2), s, the band check, the foot. aux = (roll, pitch,
    gain). Returns OK, ST_INPUT, ST_ASSEMBLE or ST_BAND (out NaN then)."""
    out[0] = math.nan
    out[1] = math.nan
    out[2] = math.nan
    if not math.isfinite(t0):
        return ST_INPUT
    x = aux[:2]
    st = fk_select_k(t1, t2, b1, b2, s, 1e-12, 50, x)
    aux[2] = math.inf
    if st != OK:
        return st
    tll = ll_k(t0, sv)
    tip, dtip = lever_tips_k(t1, t2)
    aux[2] = gain_k(x[0], x[1], tll, tip, dtip)
    if not (aux[2] < FK_GAIN_MAX):
        return ST_BAND
    return foot_k(x[0], x[1], tll, out)


@batch_kernel(rows="q out aux st", min_parallel=64)
def _fk_b(q, sv, b1, b2, s, out, aux, st):
    for j in range(q.shape[0]):
        st[j] = foot_position_k(q[j, 0], q[j, 1], q[j, 2], sv, b1, b2, s, out[j], aux[j])


@kernel(entry=True)
def foot_jacobian_k(t1, t2, t0, sv, b1, b2, s, jac):
    """:func:`jacobian`: d(foot)/d(theta1, theta2, theta0) (3, 3) at the FK pose in mode (b1, b2), s.

    ``dx/dtheta = N^-1 diag(D)``, ``dp/droll = e_x x R f``, ``dp/dpitch = (Rx(roll) e_y) x R f``,
    ``dp/dtheta0 = -RATIO R_P df/dtheta_LL`` (eq 19). Returns OK, ST_INPUT, ST_ASSEMBLE or ST_SINGULAR
    (N singular; jac NaN then)."""
    jac[:, :] = math.nan
    if not math.isfinite(t0):
        return ST_INPUT
    x = np.empty(2)
    st = fk_select_k(t1, t2, b1, b2, s, 1e-12, 50, x)
    if st != OK:
        return st
    r, p = x[0], x[1]
    tip, dtip = lever_tips_k(t1, t2)
    nm = np.empty((2, 2))
    dd = np.empty(2)
    rod_rates_k(r, p, tip, dtip, nm, dd)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    det = nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]
    scale = max(max(abs(nm[0, 0]), abs(nm[0, 1])), max(abs(nm[1, 0]), abs(nm[1, 1]))) ** 2
    if not abs(det) > 1e-12 * max(scale, 1e-300):
        return ST_SINGULAR
    # dx/dtheta = N^-1 diag(D)
    d00, d01 = nm[1, 1] / det * dd[0], -nm[0, 1] / det * dd[1]
    d10, d11 = -nm[1, 0] / det * dd[0], nm[0, 0] / det * dd[1]
    tll = ll_k(t0, sv)
    ct, st_ = math.cos(tll), math.sin(tll)
    ffx, ffz = OX + FOOT_X * ct, OZ - FOOT_X * st_
    dfx, dfz = -FOOT_X * st_, -FOOT_X * ct
    fx = cp * ffx + sp * ffz
    fy = sr * sp * ffx - sr * cp * ffz
    fz = -cr * sp * ffx + cr * cp * ffz
    # dp/dx (3, 2): columns e_x x R f = (0, -fz, fy) and (0, cr, sr) x R f = (cr fz - sr fy, sr fx, -cr fx)
    a0, a1, a2 = 0.0, -fz, fy
    c0, c1, c2 = cr * fz - sr * fy, sr * fx, -cr * fx
    jac[0, 0], jac[0, 1] = a0 * d00 + c0 * d10, a0 * d01 + c0 * d11
    jac[1, 0], jac[1, 1] = a1 * d00 + c1 * d10, a1 * d01 + c1 * d11
    jac[2, 0], jac[2, 1] = a2 * d00 + c2 * d10, a2 * d01 + c2 * d11
    jac[0, 2] = -RATIO * (cp * dfx + sp * dfz)
    jac[1, 2] = -RATIO * (sr * sp * dfx - sr * cp * dfz)
    jac[2, 2] = -RATIO * (-cr * sp * dfx + cr * cp * dfz)
    return OK


@batch_kernel(rows="q jac st", min_parallel=64)
def _jacobian_b(q, sv, b1, b2, s, jac, st):
    for j in range(q.shape[0]):
        st[j] = foot_jacobian_k(q[j, 0], q[j, 1], q[j, 2], sv, b1, b2, s, jac[j])


# ----------------------------------------------------------------------------- wrappers
def foot_position_from_platform(roll: ArrayLike, pitch: ArrayLike, theta_ll: ArrayLike, *,
                                geometry: Geometry | None = None) -> np.ndarray:
    """Foot FCS in CCS (..., 3) from the platform angles and theta_LL: ``CENTER + R_P (o_LL + Ry(theta_LL) (-1.5, 0,
    0))``.

    Seed eqs 1, 17, 18, 20 (eq 18 printed without its last row (0, 0, 0, 1)). At theta_LL = 0 the foot is at
    (0.140, 0, -0.037) in P.

    Args:
        roll, pitch: platform angles (rad); theta_ll: LL joint angle (rad); broadcast together.
        geometry: accepted for uniformity (None: the default).

    Returns:
        (..., 3) foot positions in CCS (m).
    """
    if type(roll) in SCALARS and type(pitch) in SCALARS and type(theta_ll) in SCALARS and geometry is None:
        out = np.empty(3)
        if foot_k(roll, pitch, theta_ll, out) == OK:
            return out
    resolve(geometry)
    r, p, t = as_angles(roll, pitch, theta_ll, names=("roll", "pitch", "theta_ll"))
    out = np.empty((r.size, 3))
    _foot_b(flat(r), flat(p), flat(t), out)
    return out.reshape(r.shape + (3,))


def band_message(what: str, x: np.ndarray, gain: float) -> str:
    """The SingularityError text of a pose in the forward-singularity band."""
    return (
        f"{what}: the platform pose (roll, pitch) = ({float(x[0]):.6g}, {float(x[1]):.6g}) is at the forward "
        f"singularity (det N = 0, the platform could move with the motors locked) or within its band: the foot moves "
        f"{gain:.3g} m per motor radian (limit FK_GAIN_MAX = {FK_GAIN_MAX:g}), so double-precision motor angles do not "
        "fix it to 1e-9 m"
    )


def _motors_text(q: np.ndarray) -> str:
    return f"(theta1, theta2) = ({float(q[0]):.17g}, {float(q[1]):.17g})"


@overload
def fk(q: ArrayLike, *, branch: Branch = ..., assembly: int = ..., geometry: Geometry | None = ...,
       return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def fk(q: ArrayLike, *, branch: Branch = ..., assembly: int = ..., geometry: Geometry | None = ...,
       return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def fk(q: ArrayLike, *, branch: Branch = (1, 1), assembly: int = 1, geometry: Geometry | None = None,
       return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Foot FCS in CCS (..., 3) for the three motors ``q = (theta1, theta2, theta0)`` (..., 3).

    (theta1, theta2) -> (roll, pitch) by :func:`platform_orientation` (the closed sub-chain, eqs 1-16, in the mode
    ``branch``, ``assembly``; the defaults are the mode of the SRDF reference pose), theta0 -> theta_LL by
    :func:`ll_angle` (eq 19, ``geometry.starting_value``), then :func:`foot_position_from_platform` (eqs 17, 18,
    20). Poses in the forward-singularity band (the foot moving more than :data:`FK_GAIN_MAX` m per motor radian)
    are refused: there double-precision motor angles do not fix the foot to 1e-9 m.

    Args:
        q: motor angles (theta1, theta2, theta0) (rad), shape (..., 3).
        branch, assembly: the assembly mode (motor branches (b1, b2), :func:`assembly_mode`), as in :func:`ik`.
        geometry: the geometry (universal centre); None = the default.
        return_mask: also return the mask of successes.

    Returns:
        (..., 3) foot positions in CCS (m), NaN where a batch item fails; then the mask, if asked.

    Raises:
        ConvergenceError: single input whose closed sub-chain does not assemble in that mode.
        SingularityError: single input in the forward-singularity band.
    """
    args = mode_args(branch, assembly, geometry, return_mask, "fk")
    return dispatch(q, "q", (3,), _fk_fast, _fk_batch, _fk_fail, args[:4], args[4])


@same_signature(fk)
def jacobian(q: ArrayLike, *, branch: Branch = (1, 1), assembly: int = 1, geometry: Geometry | None = None,
             return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """d(foot position)/d(theta1, theta2, theta0), shape (..., 3, 3), of the closed-loop leg (the Jacobian of
    :func:`fk`).

    With x = (roll, pitch) from :func:`platform_orientation` (mode ``branch``, ``assembly``) and
    ``dtheta/dx = D^-1 N`` (:func:`motor_jacobian`), ``dx/dtheta = N^-1 D``; the foot ``p = c + R_P f(theta_LL)``
    gives ``dp/droll = e_x x R f``, ``dp/dpitch = (Rx(roll) e_y) x R f``, ``dp/dtheta_LL = R_P df/dtheta_LL`` and
    ``dtheta_LL/dtheta0 = -RATIO`` (eq 19). Finite on the reach boundary (D = 0: a column vanishes);
    undefined where N is singular (the platform moves with the motors locked).

    Args:
        q: motor angles (theta1, theta2, theta0) (rad), shape (..., 3).
        branch, assembly: the assembly mode, as in :func:`fk`.
        geometry: the geometry (universal centre); None = the default.
        return_mask: also return the mask of successes.

    Returns:
        (..., 3, 3) d(foot, m) / d(theta1, theta2, theta0) (m/rad); then the mask, if asked.

    Raises:
        ConvergenceError: single input whose closed sub-chain did not assemble in that mode.
        SingularityError: single input where N is singular.
    """
    args = mode_args(branch, assembly, geometry, return_mask, "jacobian")
    return dispatch(q, "q", (3,), _jac_fast, _jac_batch, _jac_fail, args[:4], args[4])


def _fk_fast(q: np.ndarray, args: tuple[float, float, float, float]) -> np.ndarray | None:
    sv, b1, b2, s = args
    out, aux = np.empty(3), np.empty(3)
    q0, q1, q2 = q.tolist()
    return out if foot_position_k(q0, q1, q2, sv, b1, b2, s, out, aux) == OK else None


def _fk_rows(rows: np.ndarray, sv: float, b1: float, b2: float, s: float) -> tuple[np.ndarray, ...]:
    """The fk loop on rows (n, 3): foot (n, 3) NaN where it fails, aux (n, 3), status (n,)."""
    n = len(rows)
    p, aux, st = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int64)
    _fk_b(rows, sv, b1, b2, s, p, aux, st)
    return p, aux, st


def _fk_batch(rows: np.ndarray, sv: float, b1: float, b2: float, s: float) -> tuple[np.ndarray, np.ndarray]:
    p, _, st = _fk_rows(rows, sv, b1, b2, s)
    return p, st == OK


def _fk_fail(q: np.ndarray, out: np.ndarray, ok: np.ndarray, sv: float, b1: float, b2: float,
             s: float) -> Exception:
    _, aux, st = _fk_rows(np.ascontiguousarray(q.reshape(1, 3)), sv, b1, b2, s)
    if st[0] == ST_ASSEMBLE:
        return ConvergenceError(fk_failure(float(q[0]), float(q[1]), np.array([b1, b2]), s))
    return SingularityError(band_message(_motors_text(q), aux[0, :2], aux[0, 2]))


def _jac_fast(q: np.ndarray, args: tuple[float, float, float, float]) -> np.ndarray | None:
    sv, b1, b2, s = args
    jac = np.empty((3, 3))
    q0, q1, q2 = q.tolist()
    return jac if foot_jacobian_k(q0, q1, q2, sv, b1, b2, s, jac) == OK else None


def _jac_batch(rows: np.ndarray, sv: float, b1: float, b2: float, s: float) -> tuple[np.ndarray, np.ndarray]:
    n = len(rows)
    jac, st = np.empty((n, 3, 3)), np.empty(n, dtype=np.int64)
    _jacobian_b(rows, sv, b1, b2, s, jac, st)
    return jac, st == OK


def _jac_fail(q: np.ndarray, out: np.ndarray, ok: np.ndarray, sv: float, b1: float, b2: float,
              s: float) -> Exception:
    jac, st = np.empty((1, 3, 3)), np.empty(1, dtype=np.int64)
    _jacobian_b(np.ascontiguousarray(q.reshape(1, 3)), sv, b1, b2, s, jac, st)
    if st[0] == ST_ASSEMBLE:
        return ConvergenceError(fk_failure(float(q[0]), float(q[1]), np.array([b1, b2]), s))
    return SingularityError(
        f"(theta1, theta2) = ({float(q[0]):.6g}, {float(q[1]):.6g}) is a forward singularity: the platform can "
        "move with both motors locked (N singular), the foot Jacobian is undefined"
    )
