"""Closed-form kinematics of the quadruped's legs (seeds 004 and 002).

Conventions (base frame: x forward, y left, z up; metres, radians):

* legs ``"LF"``, ``"LH"``, ``"RF"``, ``"RH"``; ``sx = +1`` front / ``-1`` hind, ``sy = +1`` left / ``-1`` right;
* joint vector ``q = (q1, q2, q3)`` = (``<LEG>_HAA``, ``<LEG>_HFE``, ``<LEG>_KFE``), the seed's
  (aile, epaule, coude) angles; the foot frame ``<LEG>_FOOT`` is the seed's "pied";
* seed 004's transforms with its sign typo resolved: ``T01 = Tr(h) Rx(sy q1)``, ``T12 = Tr(0, sy y12, 0) Ry(-q2)``,
  ``T23 = Tr(x23, 0, z23) Ry(q3)``, ``T34 = Tr(x34, 0, foot_z)``.

Every function takes arrays with leading batch dimensions. A single input (``q`` or ``p`` of shape (3,))
returns plain arrays and raises on failure; a batch returns NaN rows where an item fails, and
``return_mask=True`` also returns the boolean mask of successes. Where two arrays come in (``foot_ik``'s ``p``
and ``q_ref``) their leading shapes broadcast, and the call is a single one only if the broadcast shape is ``()``
(a single target with a batch of ``q_ref`` is a batch).

Implementation (issue 16, see :mod:`legkin._kernels`): every function is a compiled numba kernel,
written once beside its seed equations; a batch is a compiled loop over the same kernel (``prange``, threads:
``numba.set_num_threads`` or ``NUMBA_NUM_THREADS``; batches below :data:`legkin._kernels.SERIAL_BELOW`
items run on the calling thread). The Python wrappers only check the inputs and apply the single/batch rule.

Inputs are checked at every public function: arrays as by :func:`legkin._batch.as_input` (wrong shape,
NaN/inf, complex, strings, ragged: ``InvalidInputError``; a float64 array of the right shape goes straight to
the kernel, which tests finiteness and reports it by its status code), keyword parameters for kind and range
(``InvalidParameterError`` naming the value and the valid range; ``foot_z``'s range is the registry's,
:data:`legkin.quadruped.spec.SPEC`). No numpy exception escapes: a failed item is NaN in a batch (mask False)
and a legkin error in a single call.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InvalidInputError, InvalidParameterError, JointLimitError, UnreachableError
from .spec import SPEC as _SPEC
from .._batch import real_number as _number, as_input
from .._kernels import OK, SERIAL_BELOW, as_rows, batch_kernel, kernel, prange

__all__ = [
    "LEGS",
    "X01",
    "Y01",
    "Z01",
    "Y12",
    "X23",
    "Z23",
    "X34",
    "JOINT_LIMITS",
    "hip_position",
    "foot_position",
    "foot_jacobian",
    "foot_ik",
    "foot_ik_all",
    "within_limits",
    "textbook_ik",
    "textbook_frame",
    "textbook_to_joints",
]

LEGS = ("LF", "LH", "RF", "RH")

# Seed 004 offsets (m): base_aile, aile_epaule, epaule_coude, coude_pied.
X01, Y01, Z01 = 0.3305, 0.175, -0.051
Y12 = 0.1077
X23, Z23 = -0.35192, -0.041509
X34 = 0.29604

#: Joint limits (POPI's), rows q1, q2, q3: (lower, upper) in rad.
JOINT_LIMITS = np.array([[-0.4, 0.4], [0.0, math.pi], [0.26, 1.92]])

#: Distance (m) by which a target may lie outside the reachable set and still be solved (on the boundary).
REACH_TOL = 1e-12

#: Branch order of :func:`foot_ik_all`: (s_u, k) with s_u = -1 foot below the hip plane, k the knee sign.
BRANCHES = ((-1, -1), (-1, 1), (1, -1), (1, 1))

#: Default slack (rad) of :func:`within_limits`, and of the representative choice of q2 near +-pi.
LIMIT_TOL = 1e-9
#: A branch of :func:`foot_ik` up to this far (rad) outside :data:`JOINT_LIMITS` is a candidate: targets made
#: at a limit come back a rounding error outside it, and near the abduction singularity (rho -> 0) the joints
#: err by up to ~rho / y12 <= 1.4e-8 rad along the singular direction (the foot itself stays exact). Such a
#: branch is clipped into the limits and the other joints re-solved (Gauss-Newton on the foot position); it is
#: kept only if the result is inside the limits and reproduces the target within :data:`CLIP_TOL`.
LIMIT_SLACK = 1e-7
#: Largest foot error (m) of a branch clipped into the limits.
CLIP_TOL = 1e-12

# ----------------------------------------------------------------------------- constants seen by the kernels
# numba freezes module globals into the compiled code: plain floats and tuples of floats.
_PI = math.pi
_TWO_PI = 2.0 * math.pi
_Y12_SQ = Y12**2
_L1 = math.hypot(X23, Z23)
_ALPHA = math.atan2(Z23, X23)
_LO = (float(JOINT_LIMITS[0, 0]), float(JOINT_LIMITS[1, 0]), float(JOINT_LIMITS[2, 0]))
_HI = (float(JOINT_LIMITS[0, 1]), float(JOINT_LIMITS[1, 1]), float(JOINT_LIMITS[2, 1]))
_SX = (1.0, -1.0, 1.0, -1.0)  # per leg index (LEGS order): front / hind
_SY = (1.0, 1.0, -1.0, -1.0)  # left / right
_SU = (-1.0, -1.0, 1.0, 1.0)  # BRANCHES, s_u column
_KS = (-1.0, 1.0, -1.0, 1.0)  # BRANCHES, k column
#: Rank cut of the Gauss-Newton steps of the clip repair (numpy ``pinv``'s ``rcond``).
_RCOND = 1e-10

# Kernel status codes (OK = 0).
_UNREACHABLE = 1
_JOINT_LIMIT = 2
_BAD_INPUT = 3  # a NaN/inf entry in the first array argument
_BAD_REF = 4  # a NaN/inf entry in q_ref

_LEG_INDEX = {leg: i for i, leg in enumerate(LEGS)}
_F64 = np.dtype(np.float64)
_S3 = (3,)
_S33 = (3, 3)
_S43 = (4, 3)
_NAN3 = np.full(3, np.nan)


# ----------------------------------------------------------------------------- parameter checks (Python)
_FOOT_Z = _SPEC.params["foot_z"]
# the fast path of the foot_z check: a float inside the registry's closed range is returned as it is
_FZ_LO = -math.inf if _FOOT_Z.low is None or _FOOT_Z.low_open else _FOOT_Z.low
_FZ_HI = math.inf if _FOOT_Z.high is None or _FOOT_Z.high_open else _FOOT_Z.high


def _checked_foot_z(foot_z) -> float:
    """``foot_z`` checked against the registry's range (:data:`legkin.quadruped.spec.SPEC`)."""
    if type(foot_z) is float and _FZ_LO <= foot_z <= _FZ_HI:
        return foot_z
    return _FOOT_Z.check("foot_z", _number(foot_z, "foot_z", _FOOT_Z.range_text))


def _flag(value, name: str) -> bool:
    if value is True or value is False:
        return value
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidParameterError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _leg_index(leg: str) -> int:
    try:
        return _LEG_INDEX[leg]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"leg must be one of {', '.join(LEGS)}, got {leg!r}") from None


def _signs(leg: str) -> tuple[float, float]:
    i = _leg_index(leg)
    return _SX[i], _SY[i]


def _rows(x, name: str) -> np.ndarray:
    """``x`` as a float64 array (..., 3): a float64 ndarray of that shape as it is (its finiteness is the
    kernel's to test), anything else through :func:`as_input` (shape and type errors raised there)."""
    if type(x) is np.ndarray and x.dtype is _F64 and x.ndim >= 1 and x.shape[-1] == 3:
        return x
    return as_input(x, name, _S3, allow_nan=True)


def _raise_bad(x, name: str):
    """Raise the error of :func:`as_input` for an array a kernel found NaN/inf in."""
    as_input(x, name, _S3)
    raise AssertionError(f"{name}: a kernel reported a non-finite entry that as_input accepts")  # pragma: no cover


# ----------------------------------------------------------------------------- seed 004: forward kinematics
@kernel
def _finite3(x) -> bool:
    return np.isfinite(x[0]) and np.isfinite(x[1]) and np.isfinite(x[2])


@kernel
def _wrap_k(a):
    """Wrap an angle to (-pi, pi]."""
    return _PI - np.mod(_PI - a, _TWO_PI)


@kernel
def _knee_k(q3, foot_z):
    """``v = t23 + Ry(q3) t34`` in the thigh's x-z plane (foot from the shoulder, before q2)."""
    c3, s3 = np.cos(q3), np.sin(q3)
    return X23 + X34 * c3 + foot_z * s3, Z23 - X34 * s3 + foot_z * c3


@kernel
def _forward_k(q1, q2, q3, li, foot_z):
    """``R_x(s_y q_1)`` (c1, s1), ``R_y(-q_2)`` (c2, s2) and ``u = (0, s_y y12, 0) + R_y(-q_2) v``."""
    sy = _SY[li]
    a = sy * q1
    c1, s1 = np.cos(a), np.sin(a)
    c2, s2 = np.cos(q2), np.sin(q2)
    vx, vz = _knee_k(q3, foot_z)
    ux = vx * c2 - vz * s2  # Ry(-q2) v
    uz = vx * s2 + vz * c2
    uy = sy * Y12
    return c1, s1, c2, s2, ux, uy, uz


@kernel
def _foot_k(q1, q2, q3, li, foot_z):
    """Foot position ``h + R_x(s_y q_1) u`` (seed 004's product T01 T12 T23 T34)."""
    c1, s1, _, _, ux, uy, uz = _forward_k(q1, q2, q3, li, foot_z)
    return _SX[li] * X01 + ux, _SY[li] * Y01 + c1 * uy - s1 * uz, Z01 + s1 * uy + c1 * uz


@kernel
def _jacobian_k(q1, q2, q3, li, foot_z, jac):
    """d(foot)/dq into ``jac`` (3, 3), factor by factor of seed 004's product (see :func:`foot_jacobian`)."""
    sy = _SY[li]
    c1, s1, c2, s2, ux, uy, uz = _forward_k(q1, q2, q3, li, foot_z)
    c3, s3 = np.cos(q3), np.sin(q3)
    dvx = -X34 * s3 + foot_z * c3
    dvz = -X34 * c3 - foot_z * s3
    dux3, duz3 = dvx * c2 - dvz * s2, dvx * s2 + dvz * c2
    jac[0, 0] = 0.0
    jac[1, 0] = sy * (-s1 * uy - c1 * uz)
    jac[2, 0] = sy * (c1 * uy - s1 * uz)
    jac[0, 1] = -uz
    jac[1, 1] = -s1 * ux
    jac[2, 1] = c1 * ux
    jac[0, 2] = dux3
    jac[1, 2] = -s1 * duz3
    jac[2, 2] = c1 * duz3


@kernel
def _foot_position_k(q, li, foot_z, out) -> int:
    """:func:`foot_position` of one joint vector ``q`` (3,) into ``out`` (3,)."""
    if not _finite3(q):
        return _BAD_INPUT
    out[0], out[1], out[2] = _foot_k(q[0], q[1], q[2], li, foot_z)
    return OK


@kernel
def _foot_jacobian_k(q, li, foot_z, out) -> int:
    """:func:`foot_jacobian` of one joint vector ``q`` (3,) into ``out`` (3, 3)."""
    if not _finite3(q):
        return _BAD_INPUT
    _jacobian_k(q[0], q[1], q[2], li, foot_z, out)
    return OK


@batch_kernel
def _foot_position_batch(q, li, foot_z, out) -> int:
    n, bad = q.shape[0], 0
    if n < SERIAL_BELOW:
        for i in range(n):
            bad += _foot_position_k(q[i], li, foot_z, out[i]) != OK
    else:
        for i in prange(n):
            bad += _foot_position_k(q[i], li, foot_z, out[i]) != OK
    return bad


@batch_kernel
def _foot_jacobian_batch(q, li, foot_z, out) -> int:
    n, bad = q.shape[0], 0
    if n < SERIAL_BELOW:
        for i in range(n):
            bad += _foot_jacobian_k(q[i], li, foot_z, out[i]) != OK
    else:
        for i in prange(n):
            bad += _foot_jacobian_k(q[i], li, foot_z, out[i]) != OK
    return bad


@kernel
def _hip_position_k(li, out) -> int:
    out[0], out[1], out[2] = _SX[li] * X01, _SY[li] * Y01, Z01
    return OK


def hip_position(leg: str) -> np.ndarray:
    """Point of the abduction axis ``base_aile`` of ``leg`` in the base frame (seed 004)."""
    out = np.empty(3)
    _hip_position_k(_leg_index(leg), out)
    return out


def _wrap(a):
    """Angles (any shape, or a scalar) wrapped to (-pi, pi] by the kernel ``_wrap_k``."""
    a = np.asarray(a, dtype=np.float64)
    out = np.empty(a.shape)
    _wrap_batch(np.ascontiguousarray(a).reshape(-1), out.reshape(-1))
    return out if out.ndim else out[()]


@batch_kernel
def _wrap_batch(a, out) -> None:
    for i in prange(a.shape[0]):
        out[i] = _wrap_k(a[i])


def _knee_vector(q3, foot_z: float):
    """``(v_x, v_z)`` of :func:`_knee_k` for angles ``q3`` (any shape, or a scalar)."""
    q3 = np.asarray(q3, dtype=np.float64)
    out = np.empty(q3.shape + (2,))
    _knee_batch(np.ascontiguousarray(q3).reshape(-1), float(foot_z), out.reshape(-1, 2))
    return (out[..., 0], out[..., 1]) if q3.ndim else (float(out[0]), float(out[1]))


@batch_kernel
def _knee_batch(q3, foot_z, out) -> None:
    for i in prange(q3.shape[0]):
        out[i, 0], out[i, 1] = _knee_k(q3[i], foot_z)


def foot_position(q, leg: str, *, foot_z: float = 0.0) -> np.ndarray:
    """Foot position in the base frame: the product of seed 004's transforms T01 T12 T23 T34.

    .. math:: p = h + R_x(s_y q_1)\\,\\big[(0, s_y y_{12}, 0) + R_y(-q_2)(t_{23} + R_y(q_3) t_{34})\\big]

    Seed 004 prints T01 with the ``+-`` signs stacked identically in rows 2 and 3 (not a rotation);
    the consistent reading, used here, is Rx(+q1) for left legs and Rx(-q1) for right legs.

    Args:
        q: joint angles (..., 3).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        foot_z: the foot drop below the shank axis (xacro argument ``foot_z``).

    Returns:
        Positions (..., 3) in metres.
    """
    if foot_z.__class__ is not float or not _FZ_LO <= foot_z <= _FZ_HI:
        foot_z = _checked_foot_z(foot_z)
    li = _LEG_INDEX.get(leg, -1) if leg.__class__ is str else _leg_index(leg)
    if li < 0:
        _leg_index(leg)
    if q.__class__ is np.ndarray and q.shape == _S3 and q.dtype is _F64:  # the single call, fast
        out = np.empty(3)
        if _foot_position_k(q, li, foot_z, out):
            _raise_bad(q, "q")
        return out
    arr = _rows(q, "q")
    if arr.ndim == 1:
        out = np.empty(3)
        if _foot_position_k(arr, li, foot_z, out):
            _raise_bad(q, "q")
        return out
    out = np.empty(arr.shape)
    if _foot_position_batch(as_rows(arr, 3), li, foot_z, out.reshape(-1, 3)):
        _raise_bad(q, "q")
    return out


def foot_jacobian(q, leg: str, *, foot_z: float = 0.0) -> np.ndarray:
    """Closed-form Jacobian d(foot position)/dq, shape (..., 3, 3) (columns q1, q2, q3).

    Differentiates :func:`foot_position` (seed 004's product) factor by factor:
    ``dp/dq1 = s_y R_x' u``, ``dp/dq2 = R_x (-u_z, 0, u_x)``, ``dp/dq3 = R_x R_y(-q_2) dv/dq_3``.
    """
    if foot_z.__class__ is not float or not _FZ_LO <= foot_z <= _FZ_HI:
        foot_z = _checked_foot_z(foot_z)
    li = _LEG_INDEX.get(leg, -1) if leg.__class__ is str else _leg_index(leg)
    if li < 0:
        _leg_index(leg)
    if q.__class__ is np.ndarray and q.shape == _S3 and q.dtype is _F64:  # the single call, fast
        out = np.empty(_S33)
        if _foot_jacobian_k(q, li, foot_z, out):
            _raise_bad(q, "q")
        return out
    arr = _rows(q, "q")
    if arr.ndim == 1:
        out = np.empty((3, 3))
        if _foot_jacobian_k(arr, li, foot_z, out):
            _raise_bad(q, "q")
        return out
    out = np.empty(arr.shape + (3,))
    if _foot_jacobian_batch(as_rows(arr, 3), li, foot_z, out.reshape(-1, 3, 3)):
        _raise_bad(q, "q")
    return out


# ----------------------------------------------------------------------------- joint limits
@kernel
def _within_limits_k(q, tol) -> bool:
    """Whether ``q`` (3,) lies inside :data:`JOINT_LIMITS` with slack ``tol`` (NaN: outside)."""
    return (
        q[0] >= _LO[0] - tol and q[0] <= _HI[0] + tol
        and q[1] >= _LO[1] - tol and q[1] <= _HI[1] + tol
        and q[2] >= _LO[2] - tol and q[2] <= _HI[2] + tol
    )


@batch_kernel
def _within_limits_batch(q, tol, out) -> None:
    n = q.shape[0]
    if n < SERIAL_BELOW:
        for i in range(n):
            out[i] = _within_limits_k(q[i], tol)
    else:
        for i in prange(n):
            out[i] = _within_limits_k(q[i], tol)


def within_limits(q, tol: float = LIMIT_TOL) -> np.ndarray:
    """Whether joint vectors (..., 3) lie inside :data:`JOINT_LIMITS` (with slack ``tol`` rad).

    NaN and infinite entries (e.g. the unreachable rows of :func:`foot_ik_all`) count as outside.

    Raises:
        InvalidInputError: ``q`` not a real array of shape (..., 3).
        InvalidParameterError: ``tol`` not a finite number >= 0.
    """
    if type(tol) is not float or not 0.0 <= tol < math.inf:
        tol = _number(tol, "tol", "[0, inf)")
        if not (math.isfinite(tol) and tol >= 0):
            raise InvalidParameterError(f"tol={tol!r} is out of range: must be in [0, inf) (rad)")
    arr = _rows(q, "q")
    if arr.ndim == 1:
        return np.True_ if _within_limits_k(arr, tol) else np.False_
    out = np.empty(arr.shape[:-1], dtype=np.bool_)
    _within_limits_batch(as_rows(arr, 3), tol, out.reshape(-1))
    return out


# ----------------------------------------------------------------------------- seed 004: the closed-form IK
def _leg_plane(foot_z: float):
    offset = math.atan2(foot_z, X34) - _ALPHA
    return math.hypot(X34, foot_z), offset, math.cos(offset), math.sin(offset)


_L2_0, _OFFSET_0, _CO_0, _SO_0 = _leg_plane(0.0)  # foot_z = 0 (the default), the same libm calls


@kernel
def _leg_plane_k(foot_z):
    """What the IK needs of ``foot_z`` (the same for every target of a call): ``L2 = |t34|``, the knee angle
    offset ``beta - alpha`` with ``alpha = atan2(z23, x23)``, ``beta = atan2(z34, x34)``, and its cosine and sine."""
    if foot_z == 0.0:
        return _L2_0, _OFFSET_0, _CO_0, _SO_0
    offset = math.atan2(foot_z, X34) - _ALPHA  # q3 = offset + k acos K
    return math.hypot(X34, foot_z), offset, math.cos(offset), math.sin(offset)


@kernel
def _reach_k(p, li, l2):
    """The target's leg-plane quantities: (dx, dy, dz, rho, K, sqrt(1 - K^2), acos K, reachable).

    ``d = p - h``; ``rho^2 = d_y^2 + d_z^2 - y12^2``; ``K = (|d|^2 - y12^2 - L1^2 - L2^2) / (2 L1 L2)`` clipped
    to [-1, 1]. Targets on the workspace boundary, built in floating point, may land a rounding error outside
    it: they are accepted within REACH_TOL metres (the clipped K / zero rho then give the boundary solution).
    Huge finite targets overflow to inf and are simply unreachable.
    """
    dx, dy, dz = p[0] - _SX[li] * X01, p[1] - _SY[li] * Y01, p[2] - Z01
    axis2 = dy * dy + dz * dz
    rho2 = axis2 - _Y12_SQ
    rho = np.sqrt(max(rho2, 0.0))
    r2 = dx * dx + rho2
    kk = min(max((r2 - _L1 * _L1 - l2 * l2) * (0.5 / (_L1 * l2)), -1.0), 1.0)
    sk = np.sqrt(1.0 - kk * kk)
    reachable = (
        axis2 >= (Y12 - REACH_TOL) ** 2
        and r2 <= (_L1 + l2 + REACH_TOL) ** 2
        and r2 >= (abs(_L1 - l2) - REACH_TOL) ** 2
    )
    return dx, dy, dz, rho, kk, sk, np.arccos(kk), reachable


@kernel
def _knee_angle_k(acos_k, k, offset):
    """Knee branch ``k``: ``q3 = (beta - alpha) + k acos K`` wrapped to (-pi, pi]."""
    q3 = offset + k * acos_k  # within 3 pi of 0: one shift wraps it (cheaper than a modulo)
    if q3 > _PI:
        return q3 - _TWO_PI
    if q3 <= -_PI:
        return q3 + _TWO_PI
    return q3


@kernel
def _knee_branch_k(kk, sk, k, co, so, foot_z):
    """``v`` (vx, vz) of knee branch ``k``, from the cosine and sine of q3 built without trig calls."""
    c3, s3 = co * kk - k * so * sk, so * kk + k * co * sk
    return X23 + X34 * c3 + foot_z * s3, Z23 - X34 * s3 + foot_z * c3


@kernel
def _branch_k(dx, dy, dz, rho, s_u, vx, vz, li):
    """q1 and q2 of abduction branch ``s_u`` for a knee vector ``v``; angle differences in one atan2
    (``atan2(a) - atan2(b) = atan2(a x b, a . b)``, wrapped to (-pi, pi] already)."""
    sy = _SY[li]
    uz = s_u * rho
    q1 = sy * np.arctan2(sy * Y12 * dz - dy * uz, sy * Y12 * dy + dz * uz)
    q2 = np.arctan2(uz * vx - dx * vz, dx * vx + uz * vz)
    return q1, q2


@kernel
def _foot_ik_all_core(p, li, foot_z, l2, offset, co, so, out) -> int:
    """Every branch of :func:`foot_ik_all` for one target ``p`` (3,) into ``out`` (4, 3) (NaN if unreachable)."""
    if not _finite3(p):
        return _BAD_INPUT
    dx, dy, dz, rho, kk, sk, acos_k, reachable = _reach_k(p, li, l2)
    if not reachable:
        out[:, :] = np.nan
        return _UNREACHABLE
    for b in range(4):
        k = _KS[b]
        vx, vz = _knee_branch_k(kk, sk, k, co, so, foot_z)
        q1, q2 = _branch_k(dx, dy, dz, rho, _SU[b], vx, vz, li)
        out[b, 0], out[b, 1], out[b, 2] = q1, q2, _knee_angle_k(acos_k, k, offset)
    return OK


@kernel
def _foot_ik_all_k(p, li, foot_z, out) -> int:
    l2, offset, co, so = _leg_plane_k(foot_z)
    return _foot_ik_all_core(p, li, foot_z, l2, offset, co, so, out)


@batch_kernel
def _foot_ik_all_batch(p, li, foot_z, out, ok) -> int:
    n, bad = p.shape[0], 0
    l2, offset, co, so = _leg_plane_k(foot_z)
    if n < SERIAL_BELOW:
        for i in range(n):
            s = _foot_ik_all_core(p[i], li, foot_z, l2, offset, co, so, out[i])
            ok[i] = s == OK
            bad += s == _BAD_INPUT
    else:
        for i in prange(n):
            s = _foot_ik_all_core(p[i], li, foot_z, l2, offset, co, so, out[i])
            ok[i] = s == OK
            bad += s == _BAD_INPUT
    return bad


def _unreachable_message(leg, p, foot_z: float) -> str:
    """Why a single target is out of reach, and by how much (only on the error path)."""
    # distances recomputed from p with hypot (no overflow for huge finite targets)
    d = np.asarray(p, dtype=float) - hip_position(leg)
    l1, l2 = _L1, math.hypot(X34, foot_z)
    axis = math.hypot(float(d[1]), float(d[2]))
    if axis < Y12 - REACH_TOL:
        return (
            f"target {p.tolist()} for leg {leg} is inside the abduction cylinder: its distance to the "
            f"abduction axis is {axis:.6g} m < {Y12} m (by {Y12 - axis:.3g} m)"
        )
    rho = math.sqrt(max(axis - Y12, 0.0)) * math.sqrt(axis + Y12)
    r = math.hypot(float(d[0]), rho)
    if r > l1 + l2:
        return (
            f"target {p.tolist()} for leg {leg} is beyond full stretch: the hip-to-foot distance in the "
            f"leg plane is {r:.6g} m > L1 + L2 = {l1 + l2:.6g} m (by {r - l1 - l2:.3g} m)"
        )
    return (
        f"target {p.tolist()} for leg {leg} is too close to the hip: the hip-to-foot distance in the leg "
        f"plane is {r:.6g} m < |L1 - L2| = {abs(l1 - l2):.6g} m (by {abs(l1 - l2) - r:.3g} m)"
    )


def foot_ik_all(p, leg: str, *, foot_z: float = 0.0, return_mask: bool = False):
    """Every closed-form IK branch of a foot target: shape (..., 4, 3), branches in :data:`BRANCHES` order.

    The closed form for this geometry (knee offset included), checked against Pinocchio:

    1. ``d = p - h``; ``rho^2 = d_y^2 + d_z^2 - y12^2`` (< 0: inside the abduction cylinder);
    2. ``u_z = s_u rho``, ``u_x = d_x``; ``q1 = s_y [atan2(d_z, d_y) - atan2(u_z, s_y y12)]``;
    3. ``K = (|d|^2 - y12^2 - L1^2 - L2^2) / (2 L1 L2)`` (|K| > 1: out of reach);
       ``q3 = (beta - alpha) + k acos K`` with ``alpha = atan2(z23, x23)``, ``beta = atan2(z34, x34)``;
    4. ``q2 = atan2(u_z, u_x) - atan2(v_z, v_x)`` with ``v = t23 + Ry(q3) t34``; every angle wrapped to (-pi, pi].

    Joint limits are not applied (see :func:`within_limits`); rows are NaN where the target is unreachable.

    Raises:
        UnreachableError: single target out of reach (message says why and by how much).
        InvalidInputError: ``p`` not a finite real array (..., 3). InvalidParameterError: bad ``leg``/``foot_z``.
    """
    if foot_z.__class__ is not float or not _FZ_LO <= foot_z <= _FZ_HI:
        foot_z = _checked_foot_z(foot_z)
    if return_mask is not False and return_mask is not True:
        return_mask = _flag(return_mask, "return_mask")
    li = _LEG_INDEX.get(leg, -1) if leg.__class__ is str else _leg_index(leg)
    if li < 0:
        _leg_index(leg)
    arr = p if p.__class__ is np.ndarray and p.shape == _S3 and p.dtype is _F64 else _rows(p, "p")
    if arr.ndim == 1:
        out = np.empty(_S43)
        status = _foot_ik_all_k(arr, li, foot_z, out)
        if status:
            if status == _BAD_INPUT:
                _raise_bad(p, "p")
            raise UnreachableError(_unreachable_message(leg, arr, foot_z), target=arr)
        return (out, np.ones(4, dtype=bool)) if return_mask else out
    out = np.empty(arr.shape[:-1] + (4, 3))
    ok = np.empty(arr.shape[:-1], dtype=np.bool_)
    if _foot_ik_all_batch(as_rows(arr, 3), li, foot_z, out.reshape(-1, 4, 3), ok.reshape(-1)):
        _raise_bad(p, "p")
    return (out, np.repeat(ok[..., None], 4, axis=-1)) if return_mask else out


@kernel
def _toward_limits_k(x, row):
    """The representative of angle ``x`` (mod 2 pi) inside the limits of joint ``row`` when one is.

    Needed where a limit is +-pi (q2's upper limit): rounding can return -pi + eps for pi - eps.
    """
    lo, hi = _LO[row], _HI[row]
    if x < lo - LIMIT_TOL and x + _TWO_PI <= hi + LIMIT_TOL:
        x = x + _TWO_PI
    if x > hi + LIMIT_TOL and x - _TWO_PI >= lo - LIMIT_TOL:
        x = x - _TWO_PI
    return x


@kernel
def _pinv_solve_k(a, r, step) -> None:
    """``step = pinv(a) r`` for a (3, 3) matrix ``a`` (overwritten), numpy's ``rcond`` = :data:`_RCOND`.

    One-sided Jacobi SVD (Hestenes): column rotations ``a V`` until the columns are orthogonal, then
    ``a V = U S`` and ``pinv(a) r = sum_k V_k (A_k . r) / s_k^2`` over the singular values ``s_k > rcond max s``.
    """
    v = np.eye(3)
    for _sweep in range(60):
        rotated = False
        for i in range(2):
            for j in range(i + 1, 3):
                alpha = a[0, i] * a[0, i] + a[1, i] * a[1, i] + a[2, i] * a[2, i]
                beta = a[0, j] * a[0, j] + a[1, j] * a[1, j] + a[2, j] * a[2, j]
                gamma = a[0, i] * a[0, j] + a[1, i] * a[1, j] + a[2, i] * a[2, j]
                if gamma == 0.0 or abs(gamma) <= 1e-17 * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for k in range(3):
                    ai, aj = a[k, i], a[k, j]
                    a[k, i], a[k, j] = c * ai - s * aj, s * ai + c * aj
                    vi, vj = v[k, i], v[k, j]
                    v[k, i], v[k, j] = c * vi - s * vj, s * vi + c * vj
        if not rotated:
            break
    s2 = np.empty(3)
    big = 0.0
    for k in range(3):
        s2[k] = a[0, k] * a[0, k] + a[1, k] * a[1, k] + a[2, k] * a[2, k]
        big = max(big, s2[k])
    cut = _RCOND * _RCOND * big  # s_k > rcond max s  <=>  s_k^2 > rcond^2 max s^2
    step[0] = step[1] = step[2] = 0.0
    for k in range(3):
        if s2[k] > cut and s2[k] > 0.0:
            w = (a[0, k] * r[0] + a[1, k] * r[1] + a[2, k] * r[2]) / s2[k]
            step[0] += v[0, k] * w
            step[1] += v[1, k] * w
            step[2] += v[2, k] * w


@kernel
def _clip_repair_k(qc, q, p, li, foot_z, best) -> bool:
    """Branch ``q`` (3,) clipped into the limits (``qc``, modified): re-solve the unclipped joints for the foot ``p``.

    Up to three Gauss-Newton steps on the foot position over the joints that clipping left alone (the clipped
    ones stay on their limit), keeping the best iterate (the clipped branch itself when clipping moved it by a
    rounding error only). Near the abduction singularity the branch's error lies along the singular direction
    of the Jacobian, which the free joints absorb. Writes the joints (inside the limits) into ``best`` and
    returns whether they reproduce ``p`` within :data:`CLIP_TOL`.
    """
    free = np.empty(3, dtype=np.bool_)
    for k in range(3):
        free[k] = qc[k] == q[k]
    best_err = np.inf
    jac = np.empty((3, 3))
    r = np.empty(3)
    step = np.empty(3)
    for it in range(4):
        fx, fy, fz = _foot_k(qc[0], qc[1], qc[2], li, foot_z)
        r[0], r[1], r[2] = p[0] - fx, p[1] - fy, p[2] - fz
        err = np.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        if err < best_err:  # keep the best iterate: near rho -> 0 a step can only add rounding
            best_err = err
            best[0], best[1], best[2] = qc[0], qc[1], qc[2]
        if it == 3 or best_err <= 0.5 * CLIP_TOL:
            break
        _jacobian_k(qc[0], qc[1], qc[2], li, foot_z, jac)
        for k in range(3):
            if not free[k]:
                jac[0, k] = jac[1, k] = jac[2, k] = 0.0
        _pinv_solve_k(jac, r, step)
        for k in range(3):
            moved = qc[k] + step[k]
            qc[k] = min(max(moved, _LO[k]), _HI[k])
            free[k] = free[k] and qc[k] == moved  # a joint pushed onto its limit by the step stays there
    return best_err <= CLIP_TOL


@kernel
def _clipped_k(q1, q2, q3, p, li, foot_z):
    """A branch a hair outside the limits, clipped into them and repaired (:func:`_clip_repair_k`):
    (kept, q1, q2, q3). The rare path: its scratch arrays are allocated here."""
    q = np.empty(3)
    q[0], q[1], q[2] = q1, q2, q3
    qc = np.empty(3)
    for j in range(3):
        qc[j] = min(max(q[j], _LO[j]), _HI[j])
    fixed = np.empty(3)
    good = _clip_repair_k(qc, q, p, li, foot_z, fixed)
    return good, fixed[0], fixed[1], fixed[2]


@kernel
def _foot_ik_core(p, li, foot_z, l2, offset, co, so, has_ref, q_ref, out) -> int:
    """:func:`foot_ik` of one target ``p`` (3,) into ``out`` (3,): the branch inside the limits (nearest ``q_ref``
    when ``has_ref``), or NaN and the failure code (unreachable, or only outside the limits).

    A knee branch is computed only if its q3 is inside the limits (q3 depends on the knee sign alone): inside
    POPI's limits the k = +1 branch never is, which halves the work.
    """
    if not _finite3(p):
        return _BAD_INPUT
    if has_ref and not _finite3(q_ref):
        return _BAD_REF
    out[0] = out[1] = out[2] = np.nan
    dx, dy, dz, rho, kk, sk, acos_k, reachable = _reach_k(p, li, l2)
    if not reachable:
        return _UNREACHABLE
    best = np.inf
    for b in range(4):  # scalars only on this path: no heap allocation per target
        k = _KS[b]
        q3 = _knee_angle_k(acos_k, k, offset)
        if not (q3 >= _LO[2] - LIMIT_TOL and q3 <= _HI[2] + LIMIT_TOL):
            continue
        vx, vz = _knee_branch_k(kk, sk, k, co, so, foot_z)
        q1, q2 = _branch_k(dx, dy, dz, rho, _SU[b], vx, vz, li)
        q2 = _toward_limits_k(q2, 1)  # q1 and q3 limits are far from +-pi
        if not (
            q1 >= _LO[0] - LIMIT_SLACK and q1 <= _HI[0] + LIMIT_SLACK
            and q2 >= _LO[1] - LIMIT_SLACK and q2 <= _HI[1] + LIMIT_SLACK
            and q3 >= _LO[2] - LIMIT_SLACK and q3 <= _HI[2] + LIMIT_SLACK
        ):
            continue
        if not (
            q1 >= _LO[0] and q1 <= _HI[0] and q2 >= _LO[1] and q2 <= _HI[1] and q3 >= _LO[2] and q3 <= _HI[2]
        ):  # a branch just outside the limits: clip it and re-solve the other joints
            good, q1, q2, q3 = _clipped_k(q1, q2, q3, p, li, foot_z)
            if not good:
                continue
        if has_ref:
            d0 = _wrap_k(q1 - q_ref[0])
            d1 = _wrap_k(q2 - q_ref[1])
            d2 = _wrap_k(q3 - q_ref[2])
            cost = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if cost < best:
                best = cost
                out[0], out[1], out[2] = q1, q2, q3
        else:
            best = 0.0
            out[0], out[1], out[2] = q1, q2, q3
            break  # the first branch inside the limits
    return OK if best < np.inf else _JOINT_LIMIT


@kernel
def _foot_ik_k(p, li, foot_z, has_ref, q_ref, out) -> int:
    l2, offset, co, so = _leg_plane_k(foot_z)
    return _foot_ik_core(p, li, foot_z, l2, offset, co, so, has_ref, q_ref, out)


@kernel
def _foot_ik_noref_k(p, li, foot_z, out) -> int:
    """:func:`_foot_ik_k` without ``q_ref`` (fewer arguments: a cheaper single call)."""
    l2, offset, co, so = _leg_plane_k(foot_z)
    return _foot_ik_core(p, li, foot_z, l2, offset, co, so, False, p, out)


@batch_kernel
def _foot_ik_batch(p, li, foot_z, has_ref, q_ref, out, ok) -> int:
    """:func:`_foot_ik_k` over rows ``p`` (n, 3), ``q_ref`` (n, 3) (ignored unless ``has_ref``); returns the
    number of rows with a NaN/inf entry."""
    n, bad = p.shape[0], 0
    l2, offset, co, so = _leg_plane_k(foot_z)
    if n < SERIAL_BELOW:
        for i in range(n):
            s = _foot_ik_core(p[i], li, foot_z, l2, offset, co, so, has_ref, q_ref[i], out[i])
            ok[i] = s == OK
            bad += s >= _BAD_INPUT
    else:
        for i in prange(n):
            s = _foot_ik_core(p[i], li, foot_z, l2, offset, co, so, has_ref, q_ref[i], out[i])
            ok[i] = s == OK
            bad += s >= _BAD_INPUT
    return bad


def _foot_ik_error(status: int, leg: str, li: int, p: np.ndarray, foot_z: float, p_in, q_ref_in) -> Exception:
    """The legkin error of a failed single call (the kernel's status says which)."""
    if status >= _BAD_INPUT:  # the checks of as_input, in the order of the arguments
        as_input(p_in, "p", _S3)
        as_input(q_ref_in, "q_ref", _S3)
        raise AssertionError("foot_ik: a kernel reported a non-finite entry that as_input accepts")  # pragma: no cover
    if status == _UNREACHABLE:
        return UnreachableError(_unreachable_message(leg, p, foot_z), target=p)
    q_all = np.empty((4, 3))
    _foot_ik_all_k(p, li, foot_z, q_all)
    return JointLimitError(
        f"target {p.tolist()} for leg {leg} is reachable only outside the joint limits "
        f"{JOINT_LIMITS.tolist()}: branches {np.round(q_all, 4).tolist()}",
        target=p,
    )


def foot_ik(p, leg: str, q_ref=None, *, foot_z: float = 0.0, return_mask: bool = False) -> np.ndarray:
    """Joint angles (..., 3) placing the foot at ``p``: the branch inside the joint limits.

    Branch choice (the knee and abduction branches are IK-only choices: the forward map has none). Among the
    four branches of :func:`foot_ik_all`, keeps those inside :data:`JOINT_LIMITS` (a branch a hair outside,
    by at most :data:`LIMIT_SLACK`, is clipped into the limits and kept if it still reaches the target within
    :data:`CLIP_TOL`, see :func:`_clip_repair_k`: the answer is always inside the URDF limits); picks
    the one nearest ``q_ref`` (Euclidean norm of the wrapped joint differences; ties go to the earlier
    branch) when given, else the first in :data:`BRANCHES` order: (s_u, k) = (-1, -1), (-1, 1), (1, -1), (1, 1)
    (foot below the hip plane first). Inside POPI's limits only the k = -1 knee branch occurs, but both s_u
    branches do (s_u = +1 for large q2), so the choice is made here, not assumed.

    Args:
        p: foot targets (..., 3) in the base frame.
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        q_ref: configurations (..., 3) to stay near. The leading shapes of ``p`` and ``q_ref`` broadcast
            together: a single target with a batch of ``q_ref`` is a batch (one answer per ``q_ref``).
        foot_z: the foot drop (m), in the registry's range [-0.1, 0.1].
        return_mask: also return the boolean mask of targets solved inside the limits.

    Raises:
        UnreachableError: single target out of reach.
        JointLimitError: single target reachable only outside the joint limits.
        InvalidInputError: ``p`` or ``q_ref`` not finite real arrays (..., 3), or not broadcastable.
        InvalidParameterError: bad ``leg``, ``foot_z`` or ``return_mask``.
    """
    if foot_z.__class__ is not float or not _FZ_LO <= foot_z <= _FZ_HI:
        foot_z = _checked_foot_z(foot_z)
    if return_mask is not False and return_mask is not True:
        return_mask = _flag(return_mask, "return_mask")
    li = _LEG_INDEX.get(leg, -1) if leg.__class__ is str else _leg_index(leg)
    if li < 0:
        _leg_index(leg)
    if p.__class__ is np.ndarray and p.shape == _S3 and p.dtype is _F64:  # the single call, fast
        if q_ref is None:
            out = np.empty(3)
            status = _foot_ik_noref_k(p, li, foot_z, out)
            if status:
                raise _foot_ik_error(status, leg, li, p, foot_z, p, q_ref)
            return (out, np.array(True)) if return_mask else out
        if q_ref.__class__ is np.ndarray and q_ref.shape == _S3 and q_ref.dtype is _F64:
            out = np.empty(3)
            status = _foot_ik_k(p, li, foot_z, True, q_ref, out)
            if status:
                raise _foot_ik_error(status, leg, li, p, foot_z, p, q_ref)
            return (out, np.array(True)) if return_mask else out
    arr = _rows(p, "p")
    has_ref = q_ref is not None
    if has_ref:
        try:
            ref = _rows(q_ref, "q_ref")
        except InvalidInputError:
            as_input(p, "p", _S3)  # p is checked entirely (finiteness too) before q_ref
            raise
    else:
        ref = arr
    if arr.ndim == 1 and ref.ndim == 1:  # a single call
        out = np.empty(3)
        status = _foot_ik_k(arr, li, foot_z, has_ref, ref, out)
        if status:
            raise _foot_ik_error(status, leg, li, arr, foot_z, p, q_ref)
        return (out, np.array(True)) if return_mask else out
    if has_ref and ref.shape != arr.shape:
        try:
            batch = np.broadcast_shapes(arr.shape[:-1], ref.shape[:-1])
        except ValueError:
            if not np.isfinite(arr).all():  # as_input checks p entirely before q_ref
                as_input(p, "p", _S3)
            if not np.isfinite(ref).all():
                as_input(q_ref, "q_ref", _S3)
            raise InvalidInputError(
                f"p (shape {arr.shape}) and q_ref (shape {ref.shape}) do not broadcast together"
            ) from None
        rows = as_rows(np.broadcast_to(arr, batch + _S3), 3)
        ref_rows = as_rows(np.broadcast_to(ref, batch + _S3), 3)
    else:
        batch = arr.shape[:-1]
        rows = arr if arr.ndim == 2 and arr.flags.c_contiguous else as_rows(arr, 3)
        ref_rows = (ref if ref.ndim == 2 and ref.flags.c_contiguous else as_rows(ref, 3)) if has_ref else rows
    out = np.empty(batch + _S3)
    ok = np.empty(batch, dtype=np.bool_)
    flat = len(batch) == 1
    if _foot_ik_batch(rows, li, foot_z, has_ref, ref_rows, out if flat else out.reshape(-1, 3),
                      ok if flat else ok.reshape(-1)):
        as_input(p, "p", _S3)
        as_input(q_ref, "q_ref", _S3)
        raise AssertionError("foot_ik: a kernel reported a non-finite entry that as_input accepts")  # pragma: no cover
    return (out, ok) if return_mask else out


# ----------------------------------------------------------------------------- seed 002
@kernel
def _textbook_frame_k(p, li, out) -> int:
    """``(x_f, y_f, z_f) = (s_y d_y, d_x, -d_z)`` with ``d = p - h``."""
    if not _finite3(p):
        return _BAD_INPUT
    sy = _SY[li]
    out[0], out[1], out[2] = sy * (p[1] - sy * Y01), p[0] - _SX[li] * X01, -(p[2] - Z01)
    return OK


@batch_kernel
def _textbook_frame_batch(p, li, out) -> int:
    n, bad = p.shape[0], 0
    if n < SERIAL_BELOW:
        for i in range(n):
            bad += _textbook_frame_k(p[i], li, out[i]) != OK
    else:
        for i in prange(n):
            bad += _textbook_frame_k(p[i], li, out[i]) != OK
    return bad


def textbook_frame(p, leg: str) -> np.ndarray:
    """Express base-frame foot targets in seed 002's frame for ``leg``.

    Seed 002 works from the abduction axis with x lateral (towards the hip offset, so mirrored on right
    legs: x_f -> -x_f), y forward and z down: ``(x_f, y_f, z_f) = (s_y d_y, d_x, -d_z)`` with ``d = p - h``.
    """
    li = _leg_index(leg)
    arr = _rows(p, "p")
    if arr.ndim == 1:
        out = np.empty(3)
        if _textbook_frame_k(arr, li, out):
            _raise_bad(p, "p")
        return out
    out = np.empty(arr.shape)
    if _textbook_frame_batch(as_rows(arr, 3), li, out.reshape(-1, 3)):
        _raise_bad(p, "p")
    return out


@kernel
def _textbook_ik_k(p, a, b, c, literal, out) -> int:
    """Seed 002's law of cosines for one target ``p`` (3,) in its frame (NaN where acos/asin are out of range)."""
    if not _finite3(p):
        return _BAD_INPUT
    xf, yf, zf = p[0], p[1], p[2]
    big_l = xf * xf + yf * yf + zf * zf
    m = np.sqrt(big_l - a * a)
    first = np.arctan(xf / zf) if literal else np.arctan2(xf, zf)
    out[0] = first + np.arccos(a / np.sqrt(xf * xf + zf * zf))
    out[1] = _PI / 2 - np.arcsin(-yf / m) - np.arccos((b * b - a * a - c * c + big_l) / (2 * b * m))
    out[2] = np.arccos((a * a + b * b + c * c - big_l) / (2 * b * c))
    return OK


@batch_kernel
def _textbook_ik_batch(p, a, b, c, literal, out) -> int:
    n, bad = p.shape[0], 0
    if n < SERIAL_BELOW:
        for i in range(n):
            bad += _textbook_ik_k(p[i], a, b, c, literal, out[i]) != OK
    else:
        for i in prange(n):
            bad += _textbook_ik_k(p[i], a, b, c, literal, out[i]) != OK
    return bad


def textbook_ik(p, a: float, b: float, c: float, *, literal: bool = False) -> np.ndarray:
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

    Raises:
        InvalidInputError: ``p`` not a finite real array (..., 3).
        InvalidParameterError: ``a`` not a finite number >= 0, ``b`` or ``c`` not finite and > 0, ``literal`` not a bool.
    """
    a = _number(a, "a", "[0, inf)")
    b = _number(b, "b", "(0, inf)")
    c = _number(c, "c", "(0, inf)")
    for name, value, positive in (("a", a, False), ("b", b, True), ("c", c, True)):
        if not math.isfinite(value) or value < 0 or (positive and value == 0):
            raise InvalidParameterError(
                f"{name}={value!r} is out of range: must be in {'(0, inf)' if positive else '[0, inf)'} (m)"
            )
    literal = _flag(literal, "literal")
    arr = _rows(p, "p")
    if arr.ndim == 1:
        out = np.empty(3)
        if _textbook_ik_k(arr, a, b, c, literal, out):
            _raise_bad(p, "p")
        return out
    out = np.empty(arr.shape)
    if _textbook_ik_batch(as_rows(arr, 3), a, b, c, literal, out.reshape(-1, 3)):
        _raise_bad(p, "p")
    return out


#: Angle of the thigh offset: atan(|z23| / |x23|) = 0.1174 rad, the seed-002 servo zero offset.
KNEE_OFFSET = math.atan2(-Z23, -X23)


@kernel
def _textbook_to_joints_k(theta, out) -> int:
    """``q = wrap(theta - (pi/2, KNEE_OFFSET, KNEE_OFFSET))`` (NaN maps to NaN)."""
    out[0] = _wrap_k(theta[0] - _PI / 2)
    out[1] = _wrap_k(theta[1] - KNEE_OFFSET)
    out[2] = _wrap_k(theta[2] - KNEE_OFFSET)
    return OK


@batch_kernel
def _textbook_to_joints_batch(theta, out) -> None:
    n = theta.shape[0]
    if n < SERIAL_BELOW:
        for i in range(n):
            _textbook_to_joints_k(theta[i], out[i])
    else:
        for i in prange(n):
            _textbook_to_joints_k(theta[i], out[i])


def textbook_to_joints(theta, leg: str) -> np.ndarray:
    """Map seed 002's (theta_abad, theta_hip, theta_knee) onto the quadruped's (q1, q2, q3) of ``leg``.

    With a = y12, b = L1, c = L2 (foot_z = 0): ``q1 = theta_abad - pi/2``, ``q2 = theta_hip - 0.1174``,
    ``q3 = theta_knee - 0.1174`` (0.1174 = atan(0.041509 / 0.35192), the thigh's offset angle); this is
    foot_ik's branch (s_u, k) = (-1, -1). The same formulas hold on both sides because seed 002's frame is
    mirrored on right legs (see :func:`textbook_frame`).
    """
    _leg_index(leg)
    arr = _rows(theta, "theta")  # NaN (textbook_ik out of range) maps to NaN
    if arr.ndim == 1:
        out = np.empty(3)
        _textbook_to_joints_k(arr, out)
        return out
    out = np.empty(arr.shape)
    _textbook_to_joints_batch(as_rows(arr, 3), out.reshape(-1, 3))
    return out
