"""The platform and its two motor chains in closed form (seed 003, eqs 2-16): motor angles of a platform pose,
their Jacobian and assembly mode, the rod spans, the lever-tip spherical joints and the spherical centre's free axis.

Every function takes arrays with leading batch dimensions. A single input (the core shape exactly) returns plain
arrays and raises on failure; a batch returns NaN where an item fails, and ``return_mask=True`` also returns the
boolean mask of successes.
"""

from __future__ import annotations

import math
from typing import Callable, Literal, Sequence, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, as_input, finish
from .._kernels import OK, batch_kernel, kernel, prange
from ..errors import InvalidInputError, SingularityError
from ._options import (
    SCALARS,
    ST_INPUT,
    ST_REACH,
    ST_SINGULAR,
    check_branch,
    fast_branch,
    flag,
    flat,
    loop,
    resolve,
    unreachable,
)
from .chains import (
    AX0,
    AX1,
    AY0,
    AY1,
    AZ0,
    AZ1,
    CX,
    CY,
    CZ,
    L,
    chains_k,
    is_rotation_k,
    motor_angles_k,
    ref_of,
    rod_rates_k,
    rot_k,
    rotation_error_k,
    sgn_k,
    tips_k,
)
from .geometry import BETA, K_TOL, Geometry

__all__ = [
    "platform_rotation", "rod_spans", "motor_angles", "motor_angles_from_rotation", "motor_jacobian",
    "assembly_mode", "sphere_joint_angles", "spherical_free_axis",
]

Branch = Sequence[int]


# ----------------------------------------------------------------------------- kernels
@batch_kernel
def _rot_b(r, p, out):
    for j in prange(r.shape[0]):
        rot_k(r[j], p[j], out[j])


@kernel
def _rot_s(r, p, out):
    for j in range(r.shape[0]):
        rot_k(r[j], p[j], out[j])


@kernel
def spans_k(t1, t2, r, p, out):
    """|A_i - S_i| (2,): lever tips of eqs 7, 14 to the platform points of eqs 9, 16 at R_P = Rx(r) Ry(p)."""
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    tips_k(t1, t2, tip, dtip)
    m = np.empty((3, 3))
    rot_k(r, p, m)
    for i in range(2):
        ax, ay, az = (AX0, AY0, AZ0) if i == 0 else (AX1, AY1, AZ1)
        dx = CX + (m[0, 0] * ax + m[0, 1] * ay + m[0, 2] * az) - tip[i, 0]
        dy = CY + (m[1, 0] * ax + m[1, 1] * ay + m[1, 2] * az) - tip[i, 1]
        dz = CZ + (m[2, 0] * ax + m[2, 1] * ay + m[2, 2] * az) - tip[i, 2]
        out[i] = math.sqrt(dx * dx + dy * dy + dz * dz)


@batch_kernel
def _spans_b(t1, t2, r, p, out):
    for j in prange(t1.shape[0]):
        spans_k(t1[j], t2[j], r[j], p[j], out[j])


@kernel
def _spans_s(t1, t2, r, p, out):
    for j in range(t1.shape[0]):
        spans_k(t1[j], t2[j], r[j], p[j], out[j])


@batch_kernel
def _motor_angles_b(r, p, b1, b2, theta, kout, ok):
    for j in prange(r.shape[0]):
        ok[j] = motor_angles_k(r[j], p[j], b1, b2, theta[j], kout[j]) == OK


@kernel
def _motor_angles_s(r, p, b1, b2, theta, kout, ok):
    for j in range(r.shape[0]):
        ok[j] = motor_angles_k(r[j], p[j], b1, b2, theta[j], kout[j]) == OK


@kernel
def rot_angles_k(m, b1, b2, theta, kout):
    """:func:`motor_angles_from_rotation` of one matrix m (3, 3): ST_INPUT unless a rotation, else the chains."""
    if not is_rotation_k(m):
        theta[0], theta[1] = math.nan, math.nan
        return ST_INPUT
    return chains_k(m, b1, b2, K_TOL, theta, kout)


@kernel
def sphere_k(m, b1, b2, out, kout):
    """:func:`sphere_joint_angles` out (2, 3) of one rotation m: ``u = Rz(phi_i)^T (A_i - S_i) / L``,
    ``alpha = atan2(u_y, u_x)``, ``beta = -asin(u_z)``, ``gamma = 0``. Returns a status (out NaN unless OK)."""
    th = np.empty(2)
    st = rot_angles_k(m, b1, b2, th, kout)
    out[:, :] = math.nan
    if st != OK:
        return st
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    tips_k(th[0], th[1], tip, dtip)
    for i in range(2):
        ax, ay, az = (AX0, AY0, AZ0) if i == 0 else (AX1, AY1, AZ1)
        phi = th[i] + (BETA if i == 0 else -BETA)
        dx = CX + (m[0, 0] * ax + m[0, 1] * ay + m[0, 2] * az) - tip[i, 0]
        dy = CY + (m[1, 0] * ax + m[1, 1] * ay + m[1, 2] * az) - tip[i, 1]
        dz = CZ + (m[2, 0] * ax + m[2, 1] * ay + m[2, 2] * az) - tip[i, 2]
        c, s = math.cos(phi), math.sin(phi)
        ux, uy, uz = (c * dx + s * dy) / L, (-s * dx + c * dy) / L, dz / L
        out[i, 0] = math.atan2(uy, ux)
        out[i, 1] = -math.asin(min(max(uz, -1.0), 1.0))
        out[i, 2] = 0.0
    return OK


@kernel
def free_axis_k(m, b1, b2, out, kout):
    """:func:`spherical_free_axis` out (3,) of one rotation m: ``g_1 x g_2`` normalised, ``g_i = (R a_i) x d_i``,
    positive z. Returns a status (out NaN unless OK)."""
    th = np.empty(2)
    st = rot_angles_k(m, b1, b2, th, kout)
    out[:] = math.nan
    if st != OK:
        return st
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    tips_k(th[0], th[1], tip, dtip)
    g = np.empty((2, 3))
    for i in range(2):
        ax, ay, az = (AX0, AY0, AZ0) if i == 0 else (AX1, AY1, AZ1)
        rx = m[0, 0] * ax + m[0, 1] * ay + m[0, 2] * az
        ry = m[1, 0] * ax + m[1, 1] * ay + m[1, 2] * az
        rz = m[2, 0] * ax + m[2, 1] * ay + m[2, 2] * az
        dx, dy, dz = CX + rx - tip[i, 0], CY + ry - tip[i, 1], CZ + rz - tip[i, 2]
        g[i, 0], g[i, 1], g[i, 2] = ry * dz - rz * dy, rz * dx - rx * dz, rx * dy - ry * dx
    a0 = g[0, 1] * g[1, 2] - g[0, 2] * g[1, 1]
    a1 = g[0, 2] * g[1, 0] - g[0, 0] * g[1, 2]
    a2 = g[0, 0] * g[1, 1] - g[0, 1] * g[1, 0]
    n = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    sg = -1.0 if a2 / n < 0.0 else 1.0
    out[0], out[1], out[2] = sg * a0 / n, sg * a1 / n, sg * a2 / n
    return OK


@batch_kernel
def _rot_angles_b(m, b1, b2, out, kout, st):
    for j in prange(m.shape[0]):
        st[j] = rot_angles_k(m[j], b1, b2, out[j], kout[j])


@kernel
def _rot_angles_s(m, b1, b2, out, kout, st):
    for j in range(m.shape[0]):
        st[j] = rot_angles_k(m[j], b1, b2, out[j], kout[j])


@batch_kernel
def _sphere_b(m, b1, b2, out, kout, st):
    for j in prange(m.shape[0]):
        st[j] = sphere_k(m[j], b1, b2, out[j], kout[j])


@kernel
def _sphere_s(m, b1, b2, out, kout, st):
    for j in range(m.shape[0]):
        st[j] = sphere_k(m[j], b1, b2, out[j], kout[j])


@batch_kernel
def _free_axis_b(m, b1, b2, out, kout, st):
    for j in prange(m.shape[0]):
        st[j] = free_axis_k(m[j], b1, b2, out[j], kout[j])


@kernel
def _free_axis_s(m, b1, b2, out, kout, st):
    for j in range(m.shape[0]):
        st[j] = free_axis_k(m[j], b1, b2, out[j], kout[j])


@kernel
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
    tip = np.empty((2, 3))
    dtip = np.empty((2, 3))
    tips_k(th[0], th[1], tip, dtip)
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


@batch_kernel
def _motor_jacobian_b(r, p, b1, b2, jac, kout, mode, st):
    for j in prange(r.shape[0]):
        st[j] = motor_jacobian_k(r[j], p[j], b1, b2, jac[j], kout[j], mode[j])


@kernel
def _motor_jacobian_s(r, p, b1, b2, jac, kout, mode, st):
    for j in range(r.shape[0]):
        st[j] = motor_jacobian_k(r[j], p[j], b1, b2, jac[j], kout[j], mode[j])


# ----------------------------------------------------------------------------- wrappers
def _pose_text(r: np.ndarray, p: np.ndarray) -> str:
    return f"(roll, pitch) = ({float(r):.6g}, {float(p):.6g})" if r.ndim == 0 else ""


def platform_rotation(roll: ArrayLike, pitch: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
    """``R_P = Rx(roll) Ry(pitch)``, shape (..., 3, 3): the universal centre (x fixed in CCS, then y).

    Seed eq 2 writes R_P as a unit quaternion (a spherical joint); the universal joint is the physical
    2-DOF platform (see the docs: the spherical centre leaves one rotation uncontrolled).
    """
    if type(roll) in SCALARS and type(pitch) in SCALARS and geometry is None:
        out = np.empty((3, 3))
        rot_k(roll, pitch, out)
        return out
    resolve(geometry)
    r, p = as_angles(roll, pitch, names=("roll", "pitch"))
    out = np.empty((r.size, 3, 3))
    loop(_rot_b, _rot_s, r.size)(flat(r), flat(p), out)
    return out.reshape(r.shape + (3, 3))


def rod_spans(theta1: ArrayLike, theta2: ArrayLike, roll: ArrayLike = 0.0, pitch: ArrayLike = 0.0, *,
              geometry: Geometry | None = None) -> np.ndarray:
    """Distances |A_i - S_i| (..., 2) from each lever tip to its platform point (closed iff = ROD_LENGTH).

    The chains of seed eqs 3-9 and 10-16 up to the first spherical joint, and the platform points of
    eqs 9, 16. At zero motors and R_P = I the span is 0.0839 m, not 0.11: that pose does not close.
    """
    if (type(theta1) in SCALARS and type(theta2) in SCALARS and type(roll) in SCALARS and type(pitch) in SCALARS
            and geometry is None and math.isfinite(theta1 + theta2 + roll + pitch)):  # type: ignore[operator, arg-type]
        out = np.empty(2)
        spans_k(theta1, theta2, roll, pitch, out)
        return out
    resolve(geometry)
    t1, t2, r, p = as_angles(theta1, theta2, roll, pitch, names=("theta1", "theta2", "roll", "pitch"))
    out = np.empty((t1.size, 2))
    loop(_spans_b, _spans_s, t1.size)(flat(t1), flat(t2), flat(r), flat(p), out)
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
    flag(return_mask, "return_mask")
    n = r.size
    theta, k, ok = np.empty((n, 2)), np.empty((n, 2)), np.empty(n, dtype=np.bool_)
    loop(_motor_angles_b, _motor_angles_s, n)(flat(r), flat(p), float(b[0]), float(b[1]), theta, k, ok)
    return finish(theta.reshape(r.shape + (2,)), ok.reshape(r.shape), r.ndim == 0, return_mask,
                  lambda: unreachable(_pose_text(r, p), k[0]))


def _rotation_call(kernels: tuple[Callable[..., object], Callable[..., object]], core: tuple[int, ...],
                   rotation: ArrayLike, branch: Branch, return_mask: bool, geometry: Geometry | None
                   ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """The three functions of a platform rotation (motor angles, sphere joint angles, free axis) on their batch
    kernels (parallel, serial): rotations checked (InvalidInputError unless orthonormal with det +1 within 1e-9)."""
    resolve(geometry)
    rot = as_input(rotation, "rotation", (3, 3))
    b = check_branch(branch)
    flag(return_mask, "return_mask")
    shape = rot.shape[:-2]
    m = np.ascontiguousarray(rot.reshape(-1, 3, 3))
    n = len(m)
    out, k, st = np.empty((n,) + core), np.empty((n, 2)), np.empty(n, dtype=np.int64)
    loop(*kernels, n)(m, float(b[0]), float(b[1]), out, k, st)
    if np.any(st == ST_INPUT):
        worst = max(rotation_error_k(mj) for mj in m[st == ST_INPUT])
        raise InvalidInputError(f"rotation must be rotation matrices (orthonormal, det +1 within 1e-9); worst "
                                f"|R^T R - I| = {worst:.3g} (inf: det < 0)")
    ok = (st == OK).reshape(shape)
    return finish(out.reshape(shape + core), ok, rot.ndim == 2, return_mask,
                  lambda: unreachable("the platform rotation", k[0]))


def _fast_rotation(rotation: object, branch: Branch, return_mask: bool, geometry: object) -> tuple[float, float] | None:
    if (return_mask is False and geometry is None and type(rotation) is np.ndarray and rotation.shape == (3, 3)
            and rotation.dtype == np.float64):
        return fast_branch(branch)
    return None


@overload
def motor_angles_from_rotation(rotation: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                               return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def motor_angles_from_rotation(rotation: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                               return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def motor_angles_from_rotation(rotation: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                               return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Motor angles (..., 2) = (theta1, theta2) for platform rotations (..., 3, 3) (any centre joint).

    Seed eqs 3-16: each chain closes when ``|A_i - S_i(theta_i)| = L``. With ``w_i = p_i - A_i`` and
    ``phi_i = sigma_i BETA + theta_i`` this is, per chain,

    .. math:: A \\cos\\phi + B \\sin\\phi = C,\\quad A = l_x w_x,\\ B = l_x w_y,\\
              C = \\tfrac12 (L^2 - |w|^2 - l_x^2 - l_z^2 - 2 l_z w_z)

    so ``phi = atan2(B, A) - sigma_i b_i acos(C / sqrt(A^2 + B^2))``. Unreachable where
    ``|C| > sqrt(A^2 + B^2)``. Angles wrapped to (-pi, pi].

    Raises:
        UnreachableError: single rotation out of reach.
    """
    fb = _fast_rotation(rotation, branch, return_mask, geometry)
    if fb is not None:
        theta, k = np.empty(2), np.empty(2)
        if rot_angles_k(rotation, fb[0], fb[1], theta, k) == OK:
            return theta
    return _rotation_call((_rot_angles_b, _rot_angles_s), (2,), rotation, branch, return_mask, geometry)  # type: ignore[no-any-return]


@overload
def sphere_joint_angles(rotation: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                        return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def sphere_joint_angles(rotation: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                        return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def sphere_joint_angles(rotation: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                        return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Angles (..., 2, 3) of each lever-tip spherical joint (z, y, x revolutes) that close the chains.

    The model writes spherical joint i-1 (seed eqs 7, 14: ``R_quat(a, b, c, d)`` relative to the lever
    frame) as ``Rz(alpha) Ry(beta) Rx(gamma)``, the rod along the x axis of the result (eqs 8, 15). With
    ``u = Rz(phi_i)^T (A_i - S_i) / L`` the rod direction in the lever frame,
    ``alpha = atan2(u_y, u_x)``, ``beta = -asin(u_z)``; ``gamma`` is the rod's spin about its own axis,
    a trivial internal DOF, returned as 0. Gimbal lock would need the rod along the lever's z axis
    (|beta| = 90 deg); at the neutral pose |beta| = 3.65 deg. The rod-end sphere (i-2) is the point
    closure itself and has no joint angles.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    fb = _fast_rotation(rotation, branch, return_mask, geometry)
    if fb is not None:
        out, k = np.empty((2, 3)), np.empty(2)
        if sphere_k(rotation, fb[0], fb[1], out, k) == OK:
            return out
    return _rotation_call((_sphere_b, _sphere_s), (2, 3), rotation, branch, return_mask, geometry)  # type: ignore[no-any-return]


@overload
def spherical_free_axis(rotation: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                        return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def spherical_free_axis(rotation: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                        return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def spherical_free_axis(rotation: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                        return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Unit axis (..., 3) in CCS of the rotation left free by the seed's spherical centre, motors locked.

    With a spherical joint at LCS the platform's angular velocity w changes rod i's squared span at the rate
    ``2 d_i . (w x R a_i) = 2 w . ((R a_i) x d_i)``; both rods are held when ``w`` is orthogonal to
    ``g_i = (R a_i) x d_i``, so the free axis is ``g_1 x g_2`` (normalised; sign: positive z component).
    At R_P = I on the neutral branch it is ~(-0.39, 0, 0.92) through the LCS centre.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    fb = _fast_rotation(rotation, branch, return_mask, geometry)
    if fb is not None:
        out, k = np.empty(3), np.empty(2)
        if free_axis_k(rotation, fb[0], fb[1], out, k) == OK:
            return out
    return _rotation_call((_free_axis_b, _free_axis_s), (3,), rotation, branch, return_mask, geometry)  # type: ignore[no-any-return]


def _jacobian_and_mode(r: np.ndarray, p: np.ndarray, b: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The kernel :func:`motor_jacobian_k` over checked (roll, pitch) arrays: jac (..., 2, 2), k (..., 2),
    status (...), mode (...)."""
    n = r.size
    jac, k, mode, st = np.empty((n, 2, 2)), np.empty((n, 2)), np.empty((n, 1)), np.empty(n, dtype=np.int64)
    loop(_motor_jacobian_b, _motor_jacobian_s, n)(flat(r), flat(p), float(b[0]), float(b[1]), jac, k, mode, st)
    sh = r.shape
    return jac.reshape(sh + (2, 2)), k.reshape(sh + (2,)), st.reshape(sh), mode.reshape(sh)


@overload
def motor_jacobian(roll: ArrayLike, pitch: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                   return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def motor_jacobian(roll: ArrayLike, pitch: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                   return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def motor_jacobian(roll: ArrayLike, pitch: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                   return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """d(theta1, theta2)/d(roll, pitch), shape (..., 2, 2), by implicit differentiation of the rod lengths.

    With ``d_i = A_i - S_i``: ``dtheta_i/dx_k = (d_i . dA_i/dx_k) / (d_i . dS_i/dtheta_i)`` where
    ``dA/droll = e_x x R a``, ``dA/dpitch = (Rx(roll) e_y) x R a``, ``dS/dtheta = e_z x Rz(phi) l``.
    Infinite (NaN here) on the reach boundary, where ``d_i . dS_i/dtheta_i = 0``.

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
    flag(return_mask, "return_mask")
    jac, k, st, _ = _jacobian_and_mode(r, p, b)

    def error() -> Exception:
        if bool(st == ST_REACH):
            return unreachable(_pose_text(r, p), k)
        return SingularityError(f"{_pose_text(r, p)} is on the reach boundary: a lever is perpendicular to its "
                                "rod's motion, dtheta/d(roll, pitch) is infinite")

    return finish(jac, st == OK, r.ndim == 0, return_mask, error)


@overload
def assembly_mode(roll: ArrayLike, pitch: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                  return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def assembly_mode(roll: ArrayLike, pitch: ArrayLike, branch: Branch = ..., *, geometry: Geometry | None = ...,
                  return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def assembly_mode(roll: ArrayLike, pitch: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                  return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Assembly mode (..., ) of platform poses on a motor branch: +1, -1 (0 on the forward singularity).

    +1 where det(dtheta/d(roll, pitch)) (:func:`motor_jacobian`) has the sign it has at the neutral pose
    R_P = I on the same branch (equivalently det N, ``N_ik = d_i . dA_i/dx_k``), -1 where it has the other
    sign. The mechanism is built in mode +1 on branch (1, 1) (the SRDF pose ``neutral``). A single pose gives a
    0-d integer array.

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
    flag(return_mask, "return_mask")
    _, k, st, mode = _jacobian_and_mode(r, p, b)
    return finish(mode.astype(int), st != ST_REACH, r.ndim == 0, return_mask,
                  lambda: unreachable(_pose_text(r, p), k))
