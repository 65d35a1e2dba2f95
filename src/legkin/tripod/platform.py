"""The platform's pose as a function of its orientation u = (alpha_y, alpha_z): seed eqs (5), (15), Appendix B.

Kernels beside their equations; the wrappers check the inputs and apply the single/batch rule.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, as_input
from .._kernels import OK, batch_kernel, kernel
from ..errors import InvalidInputError
from ._common import SINGULAR_TOL, ST_FAIL, ST_NONFINITE, geometry_of
from .geometry import G_ML, Geometry

__all__ = ["alpha_x", "platform_rotation", "platform_position", "platform_axis", "orientation_from_axis"]


# ------------------------------------------------------------------------------------------ kernels
@kernel
def _k_one_plus_cc(cy, sy, cz, sz):  # type: ignore[no-untyped-def]
    """``1 + c_y c_z`` without cancellation near the flip (c_y c_z -> -1), from the cos / sin of u.

    Where ``c_y c_z < -1/2`` one factor is positive and one negative; with ``a >= 0 > b`` (a, b the cosines, sa, sb
    the sines) ``1 + a b = (1 + b) + (-b)(1 - a) = sb^2 / (1 - b) - b sa^2 / (1 + a)``, a sum of two
    non-negative terms, each to a few ulps (the direct form loses ``1e-16 / (1 + c_y c_z)`` relative accuracy
    there). Elsewhere the direct form.
    """
    p = cy * cz
    out = 1.0 + p
    if p < -0.5:
        if cy >= 0.0:
            a, b, sa, sb = cy, cz, sy, sz
        else:
            a, b, sa, sb = cz, cy, sz, sy
        out = sb * sb / (1.0 - b) - b * (sa * sa) / (1.0 + a)
    return out


@kernel(entry=True, inline=True)
def _k_alpha_x(ay, az):  # type: ignore[no-untyped-def]
    """Seed eq (15), two-argument form (:func:`alpha_x`)."""
    return np.arctan2(np.sin(ay) * np.sin(az), np.cos(ay) + np.cos(az))


@kernel(entry=True)
def _k_platform_rotation(ay, az, R):  # type: ignore[no-untyped-def]
    """Seed eqs (5), (15): R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x) into R (3, 3)."""
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    ax = _k_alpha_x(ay, az)
    cx, sx = np.cos(ax), np.sin(ax)
    R[0, 0], R[0, 1], R[0, 2] = cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx
    R[1, 0], R[1, 1], R[1, 2] = sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx
    R[2, 0], R[2, 1], R[2, 2] = -sy, cy * sx, cy * cx


@kernel(entry=True, inline=True)
def _k_platform_axis(ay, az, out):  # type: ignore[no-untyped-def]
    """R e_x = (c_z c_y, s_z c_y, -s_y) into out (3,)."""
    cy = np.cos(ay)
    out[0], out[1], out[2] = np.cos(az) * cy, np.sin(az) * cy, -np.sin(ay)


@kernel(entry=True, inline=True)
def _k_platform_position(ay, az, G, out):  # type: ignore[no-untyped-def]
    """E = -L b / |b| (:func:`platform_position`) into out (3,); NaN where 1 + c_y c_z <= SINGULAR_TOL."""
    cy, sy, cz, sz = np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    nb2 = _k_one_plus_cc(cy, sy, cz, sz)
    scale = G[G_ML] / np.sqrt(2.0 * nb2) if nb2 > SINGULAR_TOL else np.nan
    out[0], out[1], out[2] = nb2 * scale, sz * cy * scale, -sy * scale


@kernel(entry=True, inline=True)
def _k_orientation_from_axis(r0, r1, r2):  # type: ignore[no-untyped-def]
    """(status, alpha_y, alpha_z) of a platform axis (:func:`orientation_from_axis`): ST_NONFINITE, ST_FAIL
    (zero vector) or OK."""
    if not (np.isfinite(r0) and np.isfinite(r1) and np.isfinite(r2)):
        return ST_NONFINITE, np.nan, np.nan
    scale = max(abs(r0), abs(r1), abs(r2))
    if not scale > 0:
        return ST_FAIL, np.nan, np.nan
    r0, r1, r2 = r0 / scale, r1 / scale, r2 / scale
    n = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
    r0, r1, r2 = r0 / n, r1 / n, r2 / n
    return OK, -np.arcsin(min(max(r2, -1.0), 1.0)), np.arctan2(r1, r0)


def _uv_loop(kind, ay, az, G, out):  # type: ignore[no-untyped-def]
    """The per-orientation closed forms over (n,) orientations: kind 1 platform_axis (out (n, 3)), 2
    platform_position (n, 3), 3 platform_rotation (n, 3, 3) (out flattened to (n, 9))."""
    for i in range(ay.shape[0]):
        if kind == 1:
            _k_platform_axis(ay[i], az[i], out[i])
        elif kind == 2:
            _k_platform_position(ay[i], az[i], G, out[i])
        else:
            _k_platform_rotation(ay[i], az[i], out[i].reshape((3, 3)))


def _alpha_x_loop(ay, az, out):  # type: ignore[no-untyped-def]
    """alpha_x over (n,) orientations into out (n,)."""
    for i in range(ay.shape[0]):
        out[i] = _k_alpha_x(ay[i], az[i])


def _axis_loop(r, out, status):  # type: ignore[no-untyped-def]
    """orientation_from_axis over axes (n, 3): out (n, 2), status (n,)."""
    for i in range(r.shape[0]):
        status[i], out[i, 0], out[i, 1] = _k_orientation_from_axis(r[i, 0], r[i, 1], r[i, 2])


_UV = batch_kernel(rows="ay az out", min_parallel=8192)(_uv_loop)
_ALPHA_X = batch_kernel(rows="ay az out", min_parallel=8192)(_alpha_x_loop)
_AXIS = batch_kernel(rows="r out status", min_parallel=8192)(_axis_loop)
_NO_GEOMETRY = np.zeros(18)


def _fast(a: object, b: object) -> bool:
    return type(a) is float and type(b) is float and math.isfinite(a) and math.isfinite(b)  # type: ignore[arg-type]


def _uv_closed(kind: int, alpha_y: ArrayLike, alpha_z: ArrayLike, core: tuple[int, ...], G: np.ndarray) -> np.ndarray:
    """A closed form of the orientation (see :func:`_uv_loop`) on checked, broadcast angles; (..., *core)."""
    if _fast(alpha_y, alpha_z):  # one item: the scalar kernel straight into the result
        ay, az = float(alpha_y), float(alpha_z)  # type: ignore[arg-type]
        res = np.empty(core)
        if kind == 1:
            _k_platform_axis(ay, az, res)
        elif kind == 2:
            _k_platform_position(ay, az, G, res)
        else:
            _k_platform_rotation(ay, az, res)
        return res
    y_, z_ = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    if not y_.ndim:
        return _uv_closed(kind, float(y_), float(z_), core, G)
    shape = y_.shape
    y, z = np.ascontiguousarray(y_).reshape(-1), np.ascontiguousarray(z_).reshape(-1)
    out = np.empty((y.shape[0], int(np.prod(core))))
    _UV(kind, y, z, G, out)
    return out.reshape(shape + core)


def _no_geometry(geometry: Geometry | None) -> None:
    if geometry is not None:
        geometry_of(geometry)


# ------------------------------------------------------------------------------------------ public
def alpha_x(alpha_y: ArrayLike, alpha_z: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
    """Seed eq (15), two-argument form: ``alpha_x = atan2(s_y s_z, c_y + c_z)``.

    Departure from the seed: eq (15) prints ``arctan(s_y s_z / (c_y + c_z))``, which is right only when
    ``c_y + c_z > 0``; elsewhere it lands on the wrong branch (off by pi) and the orientation it gives is
    not the one the legs produce (rotation error up to 2 in matrix entries, see docs/tripod.md).
    The value is undefined at ``c_y + c_z = 0 = s_y s_z``, which is the singular set 1 + c_y c_z = 0.
    ``geometry`` is accepted for uniformity (alpha_x does not depend on it).

    Args:
        alpha_y, alpha_z: platform orientation angles (rad), broadcast together.
        geometry: the tripod's :class:`Geometry` (None: the default; unused here, accepted for uniformity).

    Returns:
        alpha_x (rad), the broadcast shape (a numpy float for scalars).
    """
    _no_geometry(geometry)
    if _fast(alpha_y, alpha_z):
        return np.float64(_k_alpha_x(alpha_y, alpha_z))  # type: ignore[no-any-return]
    ay, az = as_angles(alpha_y, alpha_z, names=("alpha_y", "alpha_z"))
    if not ay.ndim:
        return np.float64(_k_alpha_x(float(ay), float(az)))  # type: ignore[no-any-return]
    out = np.empty(ay.size)
    _ALPHA_X(np.ascontiguousarray(ay).reshape(-1), np.ascontiguousarray(az).reshape(-1), out)
    return out.reshape(ay.shape)


def platform_rotation(alpha_y: ArrayLike, alpha_z: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
    """Seed eqs (5) and (15): ``R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x(alpha_y, alpha_z))``, shape (..., 3, 3).

    This is the zero-torsion (constant-velocity) family: R is the rotation by the tilt angle theta about an
    axis perpendicular to x (the mechanism's base axis), where ``cos theta = c_y c_z``. Independent of the
    geometry (``geometry`` accepted for uniformity).

    Args:
        alpha_y, alpha_z: platform orientation angles (rad), broadcast together.
        geometry: the tripod's :class:`Geometry` (None: the default; unused here, accepted for uniformity).

    Returns:
        (..., 3, 3) rotation matrices.
    """
    _no_geometry(geometry)
    return _uv_closed(3, alpha_y, alpha_z, (3, 3), _NO_GEOMETRY)


def platform_axis(alpha_y: ArrayLike, alpha_z: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
    """The platform axis ``R e_x = (c_z c_y, s_z c_y, -s_y)`` (first column of eq 5), shape (..., 3).

    Args:
        alpha_y, alpha_z: platform orientation angles (rad), broadcast together.
        geometry: the tripod's :class:`Geometry` (None: the default; unused here, accepted for uniformity).

    Returns:
        (..., 3) unit vectors R e_x.
    """
    _no_geometry(geometry)
    return _uv_closed(1, alpha_y, alpha_z, (3,), _NO_GEOMETRY)


def orientation_from_axis(axis: ArrayLike, *, geometry: Geometry | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`platform_axis` on ``alpha_y`` in [-pi/2, pi/2]: ``(-asin(r3), atan2(r2, r1))``.

    The platform orientation is fixed by its axis (zero torsion), so this also inverts
    :func:`platform_rotation`; at ``c_y = 0`` (axis = -+z) alpha_z is arbitrary and 0 is returned. ``axis``
    (..., 3) need not be a unit vector; a zero vector raises InvalidInputError.

    Args:
        axis: (..., 3) platform axes (any nonzero length).
        geometry: the tripod's :class:`Geometry` (None: the default; unused here, accepted for uniformity).

    Returns:
        (alpha_y, alpha_z) (rad), each of the batch shape (numpy floats for one axis).
    """
    _no_geometry(geometry)
    if type(axis) is np.ndarray and axis.dtype == np.float64 and axis.shape == (3,):
        st, ay, az = _k_orientation_from_axis(axis[0], axis[1], axis[2])
        if st == OK:
            return np.float64(ay), np.float64(az)
    r = as_input(axis, "axis", (3,))
    shape = r.shape[:-1]
    rows = np.ascontiguousarray(r.reshape(-1, 3))
    out, status = np.empty((rows.shape[0], 2)), np.empty(rows.shape[0], dtype=np.int64)
    _AXIS(rows, out, status)
    if not (status == OK).all():
        raise InvalidInputError("axis must be a nonzero vector (every row)")
    if not shape:
        return np.float64(out[0, 0]), np.float64(out[0, 1])
    return out[:, 0].reshape(shape), out[:, 1].reshape(shape)


def platform_position(alpha_y: ArrayLike, alpha_z: ArrayLike, *, geometry: Geometry | None = None) -> np.ndarray:
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

    Args:
        alpha_y, alpha_z: platform orientation angles (rad), broadcast together.
        geometry: the tripod's :class:`Geometry` (None: the default).

    Returns:
        (..., 3) platform centres E (m).
    """
    g = geometry_of(geometry)
    return _uv_closed(2, alpha_y, alpha_z, (3,), g._vector)
