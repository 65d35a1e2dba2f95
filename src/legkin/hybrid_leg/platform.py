"""The universal-centre platform and its two motor chains in closed form (seed 003, eqs 2-16): the rotation
R_P = Rx(roll) Ry(pitch), the motor angles of a platform pose, their Jacobian and assembly mode, the rod spans (the
closed forms of a rotation matrix, for either centre, are in :mod:`.rotation`).

Every function takes arrays with leading batch dimensions. A single input (the core shape exactly) returns plain
arrays and raises on failure; a batch returns NaN where an item fails, and ``return_mask=True`` also returns the
boolean mask of successes.
"""

from __future__ import annotations

import math
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, check_flag, finish, same_signature
from .._kernels import OK, batch_kernel, kernel
from ..errors import SingularityError
from ._options import SCALARS, ST_REACH, ST_SINGULAR, Branch, check_branch, fast_branch, flat, resolve, unreachable
from .chains import CX, CY, CZ, arm_k, lever_tips_k, motor_angles_k, ref_of, rod_rates_k, rot_k, sgn_k
from .geometry import Geometry

__all__ = ["platform_rotation", "rod_spans", "motor_angles", "motor_jacobian", "assembly_mode"]


# ----------------------------------------------------------------------------- kernels
@batch_kernel(rows="r p out", min_parallel=8192)
def _rot_b(r, p, out):
    for j in range(r.shape[0]):
        rot_k(r[j], p[j], out[j])


@kernel(entry=True)
def spans_k(t1, t2, r, p, out):
    """|A_i - S_i| (2,): lever tips of eqs 7, 14 to the platform points of eqs 9, 16 at R_P = Rx(r) Ry(p)."""
    tip, dtip = lever_tips_k(t1, t2)
    m = np.empty((3, 3))
    rot_k(r, p, m)
    for i in range(2):
        rx, ry, rz = arm_k(m, i)
        dx, dy, dz = CX + rx - tip[i, 0], CY + ry - tip[i, 1], CZ + rz - tip[i, 2]
        out[i] = math.sqrt(dx * dx + dy * dy + dz * dz)


@batch_kernel(rows="t1 t2 r p out", min_parallel=8192)
def _spans_b(t1, t2, r, p, out):
    for j in range(t1.shape[0]):
        spans_k(t1[j], t2[j], r[j], p[j], out[j])


@batch_kernel(rows="r p theta kout ok", min_parallel=4096)
def _motor_angles_b(r, p, b1, b2, theta, kout, ok):
    for j in range(r.shape[0]):
        ok[j] = motor_angles_k(r[j], p[j], b1, b2, theta[j], kout[j]) == OK


@kernel(entry=True)
def motor_jacobian_k(r, p, b1, b2, jac, kout, mode):
    """:func:`motor_jacobian` jac (2, 2) = d(theta1, theta2)/d(roll, pitch) = D^-1 N and :func:`assembly_mode`
    mode (1,) = sign(det N) x its sign at R_P = I on (b1, b2), at the pose (r, p). Returns OK, ST_INPUT,
    ST_REACH (jac NaN, mode 0) or ST_SINGULAR (on the reach boundary, D = 0: jac NaN)."""
    jac[:, :] = math.nan
    mode[0] = 0.0
    th = np.empty(2)
    st = motor_angles_k(r, p, b1, b2, th, kout)
    if st != OK:
        return st
    tip, dtip = lever_tips_k(th[0], th[1])
    nm = np.empty((2, 2))
    dd = np.empty(2)
    rod_rates_k(r, p, tip, dtip, nm, dd)
    mode[0] = sgn_k(nm[0, 0] * nm[1, 1] - nm[0, 1] * nm[1, 0]) * ref_of(b1, b2)
    for i in range(2):
        if dd[i] == 0.0:
            jac[:, :] = math.nan
            return ST_SINGULAR
        jac[i, 0] = nm[i, 0] / dd[i]
        jac[i, 1] = nm[i, 1] / dd[i]
    for i in range(2):
        for j in range(2):
            if not math.isfinite(jac[i, j]):
                jac[:, :] = math.nan
                return ST_SINGULAR
    return OK


@batch_kernel(rows="r p jac kout mode st", min_parallel=4096)
def _motor_jacobian_b(r, p, b1, b2, jac, kout, mode, st):
    for j in range(r.shape[0]):
        st[j] = motor_jacobian_k(r[j], p[j], b1, b2, jac[j], kout[j], mode[j])


# ----------------------------------------------------------------------------- wrappers
def _pose_text(r: np.ndarray, p: np.ndarray) -> str:
    return f"(roll, pitch) = ({float(r):.6g}, {float(p):.6g})" if r.ndim == 0 else ""


def platform_rotation(roll: ArrayLike, pitch: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
    """``R_P = Rx(roll) Ry(pitch)``, shape (..., 3, 3): the universal centre (x fixed in CCS, then y).

    Seed eq 2 writes R_P as a unit quaternion (a spherical joint); the universal joint is the physical
    2-DOF platform (see the docs: the spherical centre leaves one rotation uncontrolled).

    Args:
        roll, pitch: platform angles (rad), broadcast together.
        geometry: accepted for uniformity (None: the default).

    Returns:
        (..., 3, 3) rotation matrices.
    """
    if type(roll) in SCALARS and type(pitch) in SCALARS and geometry is None:
        out = np.empty((3, 3))
        rot_k(roll, pitch, out)
        return out
    resolve(geometry)
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    out = np.empty((r.size, 3, 3))
    _rot_b(flat(r), flat(p), out)
    return out.reshape(r.shape + (3, 3))


def rod_spans(theta1: ArrayLike, theta2: ArrayLike, roll: ArrayLike = 0.0, pitch: ArrayLike = 0.0, *,
              geometry: Geometry | None = None) -> np.ndarray:
    """Distances |A_i - S_i| (..., 2) from each lever tip to its platform point (closed iff = ROD_LENGTH).

    The chains of seed eqs 3-9 and 10-16 up to the first spherical joint, and the platform points of
    eqs 9, 16. At zero motors and R_P = I the span is 0.0839 m, not 0.11: that pose does not close.

    Args:
        theta1, theta2: motor angles (rad); roll, pitch: platform angles (rad); broadcast together.
        geometry: the geometry (universal centre); None = the default.

    Returns:
        (..., 2) the lever-tip to rod-attachment distances (m).
    """
    if (type(theta1) in SCALARS and type(theta2) in SCALARS and type(roll) in SCALARS and type(pitch) in SCALARS
            and geometry is None and math.isfinite(theta1 + theta2 + roll + pitch)):  # type: ignore[operator, arg-type]
        out = np.empty(2)
        spans_k(theta1, theta2, roll, pitch, out)
        return out
    resolve(geometry)
    t1, t2, r, p = as_angles(theta1, theta2, roll, pitch, names=("theta1", "theta2", "roll", "pitch"))
    out = np.empty((t1.size, 2))
    _spans_b(flat(t1), flat(t2), flat(r), flat(p), out)
    return out.reshape(t1.shape + (2,))


@overload
def motor_angles(roll: ArrayLike, pitch: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                 return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def motor_angles(roll: ArrayLike, pitch: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                 return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def motor_angles(roll: ArrayLike, pitch: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                 return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Motor angles (..., 2) = (theta1, theta2) putting the universal-centre platform at (roll, pitch).

    :func:`motor_angles_from_rotation` applied to ``R_P = Rx(roll) Ry(pitch)`` (seed eq 2's quaternion
    replaced by the universal joint). Each chain's rod-length condition is A cos(theta) + B sin(theta) = C,
    solved in closed form; ``branch = (b1, b2)`` picks one of its two solutions per chain.

    Args:
        roll, pitch: platform angles (rad), broadcast together; branch, geometry (universal centre), return_mask:
            as :func:`motor_angles_from_rotation`.

    Returns:
        (..., 2) (theta1, theta2) (rad), NaN where out of reach; then the mask, if asked.

    Raises:
        UnreachableError: single (roll, pitch) out of reach (message names the chain and its |k|).
    """
    if return_mask is False and type(roll) in SCALARS and type(pitch) in SCALARS and geometry is None:
        fb = fast_branch(branch)
        if fb is not None:
            theta, k = np.empty(2), np.empty(2)
            if motor_angles_k(roll, pitch, fb[0], fb[1], theta, k) == OK:
                return theta
    resolve(geometry)
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = check_branch(branch)
    check_flag(return_mask, "return_mask")
    n = r.size
    theta, k, ok = np.empty((n, 2)), np.empty((n, 2)), np.empty(n, dtype=np.bool_)
    _motor_angles_b(flat(r), flat(p), float(b[0]), float(b[1]), theta, k, ok)
    return finish(theta.reshape(r.shape + (2,)), ok.reshape(r.shape), r.ndim == 0, return_mask,
                  lambda: unreachable(_pose_text(r, p), k[0]))


def _jacobian_and_mode(r: np.ndarray, p: np.ndarray, b: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The kernel :func:`motor_jacobian_k` over checked (roll, pitch) arrays: jac (..., 2, 2), k (..., 2),
    status (...), mode (...)."""
    n = r.size
    jac, k, mode, st = np.empty((n, 2, 2)), np.empty((n, 2)), np.empty((n, 1)), np.empty(n, dtype=np.int64)
    _motor_jacobian_b(flat(r), flat(p), float(b[0]), float(b[1]), jac, k, mode, st)
    sh = r.shape
    return jac.reshape(sh + (2, 2)), k.reshape(sh + (2,)), st.reshape(sh), mode.reshape(sh)


@same_signature(motor_angles)
def motor_jacobian(roll: ArrayLike, pitch: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                   return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """d(theta1, theta2)/d(roll, pitch), shape (..., 2, 2), by implicit differentiation of the rod lengths.

    With ``d_i = A_i - S_i``: ``dtheta_i/dx_k = (d_i . dA_i/dx_k) / (d_i . dS_i/dtheta_i)`` where
    ``dA/droll = e_x x R a``, ``dA/dpitch = (Rx(roll) e_y) x R a``, ``dS/dtheta = e_z x Rz(phi) l``.
    Infinite (NaN here) on the reach boundary, where ``d_i . dS_i/dtheta_i = 0``.

    Args:
        roll, pitch: platform angles (rad), broadcast together; branch, geometry, return_mask: as
            :func:`motor_angles`.

    Returns:
        (..., 2, 2) dtheta/d(roll, pitch) (rad/rad); then the mask, if asked.

    Raises:
        UnreachableError: single (roll, pitch) out of reach.
        SingularityError: single pose on the reach boundary (a motor cannot move its rod end).
    """
    if return_mask is False and type(roll) in SCALARS and type(pitch) in SCALARS and geometry is None:
        fb = fast_branch(branch)
        if fb is not None:
            jac, k, mode = np.empty((2, 2)), np.empty(2), np.empty(1)
            if motor_jacobian_k(roll, pitch, fb[0], fb[1], jac, k, mode) == OK:
                return jac
    resolve(geometry)
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = check_branch(branch)
    check_flag(return_mask, "return_mask")
    jac, k, st, _ = _jacobian_and_mode(r, p, b)

    def error() -> Exception:
        if bool(st == ST_REACH):
            return unreachable(_pose_text(r, p), k)
        return SingularityError(f"{_pose_text(r, p)} is on the reach boundary: a lever is perpendicular to its "
                                "rod's motion, dtheta/d(roll, pitch) is infinite")

    return finish(jac, st == OK, r.ndim == 0, return_mask, error)


@same_signature(motor_angles)
def assembly_mode(roll: ArrayLike, pitch: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                  return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Assembly mode (..., ) of platform poses on a motor branch: +1, -1 (0 on the forward singularity).

    +1 where det(dtheta/d(roll, pitch)) (:func:`motor_jacobian`) has the sign it has at the neutral pose
    R_P = I on the same branch (equivalently det N, ``N_ik = d_i . dA_i/dx_k``), -1 where it has the other
    sign. The mechanism is built in mode +1 on branch (1, 1) (the SRDF pose ``neutral``). A single pose gives a
    0-d integer array.

    Args:
        roll, pitch: platform angles (rad), broadcast together; branch, geometry, return_mask: as
            :func:`motor_angles`.

    Returns:
        (...) +1 or -1 (an integer array); then the mask, if asked.

    Raises:
        UnreachableError: single pose out of the motors' reach on that branch.
    """
    if return_mask is False and type(roll) in SCALARS and type(pitch) in SCALARS and geometry is None:
        fb = fast_branch(branch)
        if fb is not None:
            jac, k, mode = np.empty((2, 2)), np.empty(2), np.empty(1)
            if motor_jacobian_k(roll, pitch, fb[0], fb[1], jac, k, mode) in (OK, ST_SINGULAR):
                return np.array(int(mode[0]))
    resolve(geometry)
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    b = check_branch(branch)
    check_flag(return_mask, "return_mask")
    _, k, st, mode = _jacobian_and_mode(r, p, b)
    return finish(mode.astype(int), st != ST_REACH, r.ndim == 0, return_mask,
                  lambda: unreachable(_pose_text(r, p), k))
