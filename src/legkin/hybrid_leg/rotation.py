"""A platform rotation's closed forms, for either centre joint (seed 003, eqs 3-16): the motor angles that close
both chains, the lever-tip spherical joints, and the rotation the seed's spherical centre leaves free.

A single rotation (3, 3) returns plain arrays and raises on failure; a batch (..., 3, 3) returns NaN where an item
fails, and ``return_mask=True`` also the mask. A matrix that is not a rotation (orthonormal with det +1 within 1e-9)
raises InvalidInputError.
"""

from __future__ import annotations

import math
from typing import Callable, Literal, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input, check_flag, finish, same_signature
from .._kernels import OK, batch_kernel, kernel
from ..errors import InvalidInputError
from ._options import ST_INPUT, Branch, check_branch, fast_branch, resolve, unreachable
from .chains import CX, CY, CZ, L, arm_k, chains_k, is_rotation_k, lever_tips_k, rotation_error_k
from .geometry import BETA, K_TOL, Geometry

__all__ = ["motor_angles_from_rotation", "sphere_joint_angles", "spherical_free_axis"]


@kernel(entry=True)
def rot_angles_k(m, b1, b2, theta, kout):
    """:func:`motor_angles_from_rotation` of one matrix m (3, 3): ST_INPUT unless a rotation, else the chains."""
    if not is_rotation_k(m):
        theta[0], theta[1] = math.nan, math.nan
        return ST_INPUT
    return chains_k(m, b1, b2, K_TOL, theta, kout)


@kernel(entry=True)
def sphere_k(m, b1, b2, out, kout):
    """:func:`sphere_joint_angles` out (2, 3) of one rotation m: ``u = Rz(phi_i)^T (A_i - S_i) / L``,
    ``alpha = atan2(u_y, u_x)``, ``beta = -asin(u_z)``, ``gamma = 0``. Returns a status (out NaN unless OK)."""
    th = np.empty(2)
    st = rot_angles_k(m, b1, b2, th, kout)
    out[:, :] = math.nan
    if st != OK:
        return st
    tip, dtip = lever_tips_k(th[0], th[1])
    for i in range(2):
        phi = th[i] + (BETA if i == 0 else -BETA)
        rx, ry, rz = arm_k(m, i)
        dx, dy, dz = CX + rx - tip[i, 0], CY + ry - tip[i, 1], CZ + rz - tip[i, 2]
        c, s = math.cos(phi), math.sin(phi)
        ux, uy, uz = (c * dx + s * dy) / L, (-s * dx + c * dy) / L, dz / L
        out[i, 0] = math.atan2(uy, ux)
        out[i, 1] = -math.asin(min(max(uz, -1.0), 1.0))
        out[i, 2] = 0.0
    return OK


@kernel(entry=True)
def free_axis_k(m, b1, b2, out, kout):
    """:func:`spherical_free_axis` out (3,) of one rotation m: ``g_1 x g_2`` normalised, ``g_i = (R a_i) x d_i``,
    positive z. Returns a status (out NaN unless OK)."""
    th = np.empty(2)
    st = rot_angles_k(m, b1, b2, th, kout)
    out[:] = math.nan
    if st != OK:
        return st
    tip, dtip = lever_tips_k(th[0], th[1])
    g = np.empty((2, 3))
    for i in range(2):
        rx, ry, rz = arm_k(m, i)
        dx, dy, dz = CX + rx - tip[i, 0], CY + ry - tip[i, 1], CZ + rz - tip[i, 2]
        g[i, 0], g[i, 1], g[i, 2] = ry * dz - rz * dy, rz * dx - rx * dz, rx * dy - ry * dx
    a0 = g[0, 1] * g[1, 2] - g[0, 2] * g[1, 1]
    a1 = g[0, 2] * g[1, 0] - g[0, 0] * g[1, 2]
    a2 = g[0, 0] * g[1, 1] - g[0, 1] * g[1, 0]
    n = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    sg = -1.0 if a2 / n < 0.0 else 1.0
    out[0], out[1], out[2] = sg * a0 / n, sg * a1 / n, sg * a2 / n
    return OK


@batch_kernel(rows="m out kout st", min_parallel=4096)
def _rot_angles_b(m, b1, b2, out, kout, st):
    for j in range(m.shape[0]):
        st[j] = rot_angles_k(m[j], b1, b2, out[j], kout[j])


@batch_kernel(rows="m out kout st", min_parallel=4096)
def _sphere_b(m, b1, b2, out, kout, st):
    for j in range(m.shape[0]):
        st[j] = sphere_k(m[j], b1, b2, out[j], kout[j])


@batch_kernel(rows="m out kout st", min_parallel=4096)
def _free_axis_b(m, b1, b2, out, kout, st):
    for j in range(m.shape[0]):
        st[j] = free_axis_k(m[j], b1, b2, out[j], kout[j])


_F64 = np.dtype(np.float64)  # ``dtype is _F64``: 3x cheaper than ``== np.float64``


def _rotation_call(single: Callable[..., int], kernels: Callable[..., object], core: tuple[int, ...],
                   rotation: ArrayLike, branch: Branch, return_mask: bool, geometry: Geometry | None
                   ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """The three functions of a platform rotation (motor angles, sphere joint angles, free axis): one float64
    rotation with the default keywords straight to its kernel ``single``, else the batch loop ``kernels`` on the
    rotations checked (InvalidInputError unless orthonormal with det +1 within 1e-9)."""
    if (return_mask is False and geometry is None and type(rotation) is np.ndarray and rotation.dtype is _F64
            and rotation.shape == (3, 3)):
        fb = fast_branch(branch)
        if fb is not None:
            out1, k1 = np.empty(core), np.empty(2)
            if single(rotation, fb[0], fb[1], out1, k1) == OK:
                return out1
    resolve(geometry)
    rot = as_input(rotation, "rotation", (3, 3))
    b = check_branch(branch)
    check_flag(return_mask, "return_mask")
    shape = rot.shape[:-2]
    m = np.ascontiguousarray(rot.reshape(-1, 3, 3))
    n = len(m)
    out, k, st = np.empty((n,) + core), np.empty((n, 2)), np.empty(n, dtype=np.int64)
    kernels(m, float(b[0]), float(b[1]), out, k, st)
    if np.any(st == ST_INPUT):
        worst = max(rotation_error_k(mj) for mj in m[st == ST_INPUT])
        raise InvalidInputError(f"rotation must be rotation matrices (orthonormal, det +1 within 1e-9); worst "
                                f"|R^T R - I| = {worst:.3g} (inf: det < 0)")
    ok = (st == OK).reshape(shape)
    return finish(out.reshape(shape + core), ok, rot.ndim == 2, return_mask,
                  lambda: unreachable("the platform rotation", k[0]))


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

    Args:
        rotation: (..., 3, 3) platform rotation matrices.
        branch: the motor branch pair (b1, b2), each +1 or -1.
        geometry: the geometry (universal centre); None = the default.
        return_mask: also return the mask of successes.

    Returns:
        (..., 2) (theta1, theta2) (rad), NaN where out of reach; then the mask, if asked.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    return _rotation_call(rot_angles_k, _rot_angles_b, (2,), rotation, branch, return_mask, geometry)


@same_signature(motor_angles_from_rotation)
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

    Args:
        rotation: (..., 3, 3) platform rotation matrices; branch, geometry, return_mask: as
            :func:`motor_angles_from_rotation`.

    Returns:
        (..., 2, 3) the z-y-x angles (rad) of the two lever-tip spheres; then the mask, if asked.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    return _rotation_call(sphere_k, _sphere_b, (2, 3), rotation, branch, return_mask, geometry)


@same_signature(motor_angles_from_rotation)
def spherical_free_axis(rotation: ArrayLike, branch: Branch = (1, 1), *, geometry: Geometry | None = None,
                        return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Unit axis (..., 3) in CCS of the rotation left free by the seed's spherical centre, motors locked.

    With a spherical joint at LCS the platform's angular velocity w changes rod i's squared span at the rate
    ``2 d_i . (w x R a_i) = 2 w . ((R a_i) x d_i)``; both rods are held when ``w`` is orthogonal to
    ``g_i = (R a_i) x d_i``, so the free axis is ``g_1 x g_2`` (normalised; sign: positive z component).
    At R_P = I on the neutral branch it is ~(-0.39, 0, 0.92) through the LCS centre.

    Args:
        rotation: (..., 3, 3) platform rotation matrices; branch, geometry, return_mask: as
            :func:`motor_angles_from_rotation`.

    Returns:
        (..., 3) unit axes of the free rotation (CCS); then the mask, if asked.

    Raises:
        UnreachableError: single rotation out of reach.
    """
    return _rotation_call(free_axis_k, _free_axis_b, (3,), rotation, branch, return_mask, geometry)
