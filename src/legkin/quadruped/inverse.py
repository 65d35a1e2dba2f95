"""The default IK of a leg, :func:`ik`: the branch of :func:`~legkin.quadruped.ik_all` inside POPI's joint
limits (nearest ``q_near`` when given), with the clip repair of :mod:`legkin.quadruped.repair`."""

from __future__ import annotations

from typing import Literal, overload

import numpy as np
import numpy.typing as npt

from .._batch import as_input, check_flag
from .._kernels import OK, as_rows, batch_kernel, kernel, prange
from .._rotations import wrap_k
from ..errors import InvalidInputError, JointLimitError, UnreachableError
from ._common import F64, LEG_INDEX, S3, foot_z_of, leg_index, rows
from .closed_form import (
    _abduction_k,
    _hip_k,
    _ik_all_k,
    _knee_angle_k,
    _knee_branch_k,
    _leg_plane_k,
    _reach_k,
    unreachable_message,
)
from .constants import (
    BAD_INPUT,
    BAD_REF,
    HI,
    JOINT_LIMIT,
    JOINT_LIMITS,
    KS,
    LIMIT_SLACK,
    LIMIT_TOL,
    LO,
    SU,
    UNREACHABLE,
)
from .forward import _finite3
from .geometry import Geometry
from .limits import _inside_by_k, _strictly_inside_k, _toward_limits_k
from .repair import _clipped_k

__all__ = ["ik"]


@kernel
def _ik_core(p, li, foot_z, l2, offset, co, so, has_ref, q_near, out) -> int:
    """:func:`ik` of one target ``p`` (3,) into ``out`` (3,): the branch inside the limits (nearest ``q_near``
    when ``has_ref``), or NaN and the failure code (unreachable, or only outside the limits).

    A knee branch is computed only if its q3 is inside the limits (q3 depends on the knee sign alone): inside
    POPI's limits the k = +1 branch never is, which halves the work; and q1 (one atan2) only if q2 is.
    """
    if not _finite3(p):
        return BAD_INPUT
    if has_ref and not _finite3(q_near):
        return BAD_REF
    out[0] = out[1] = out[2] = np.nan
    dx, dy, dz, rho, kk, sk, acos_k, reachable = _reach_k(p, li, l2)
    if not reachable:
        return UNREACHABLE
    best = np.inf
    for b in range(4):  # scalars only on this path: no heap allocation per target
        k = KS[b]
        q3 = _knee_angle_k(acos_k, k, offset)
        if not (q3 >= LO[2] - LIMIT_TOL and q3 <= HI[2] + LIMIT_TOL):
            continue
        vx, vz = _knee_branch_k(kk, sk, k, co, so, foot_z)
        q2 = _toward_limits_k(_hip_k(dx, rho, SU[b], vx, vz), 1)  # q1 and q3 limits are far from +-pi
        if not (q2 >= LO[1] - LIMIT_SLACK and q2 <= HI[1] + LIMIT_SLACK):
            continue  # (q1 is computed only for a branch whose q2 may be inside the limits)
        q1 = _abduction_k(dy, dz, rho, SU[b], li)
        if not _inside_by_k(q1, q2, q3, LIMIT_SLACK):
            continue
        if not _strictly_inside_k(q1, q2, q3):  # a hair outside the limits: clip, re-solve the other joints
            good, q1, q2, q3 = _clipped_k(q1, q2, q3, p, li, foot_z)
            if not good:
                continue
        if not has_ref:
            out[0], out[1], out[2] = q1, q2, q3
            return OK  # the first branch inside the limits
        d0 = wrap_k(q1 - q_near[0])
        d1 = wrap_k(q2 - q_near[1])
        d2 = wrap_k(q3 - q_near[2])
        cost = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if cost < best:
            best = cost
            out[0], out[1], out[2] = q1, q2, q3
    return OK if best < np.inf else JOINT_LIMIT


@kernel(entry=True)
def _ik_k(p, li, foot_z, has_ref, q_near, out) -> int:
    l2, offset, co, so = _leg_plane_k(foot_z)
    return _ik_core(p, li, foot_z, l2, offset, co, so, has_ref, q_near, out)


@kernel(entry=True)
def _ik_noref_k(p, li, foot_z, out) -> int:
    """:func:`_ik_k` without ``q_near`` (fewer arguments: a cheaper single call)."""
    l2, offset, co, so = _leg_plane_k(foot_z)
    return _ik_core(p, li, foot_z, l2, offset, co, so, False, p, out)


@batch_kernel(rows="p q_near out ok", min_parallel=256, parfor=True)
def _ik_batch(p, li, foot_z, has_ref, q_near, out, ok) -> int:
    """:func:`_ik_k` over rows ``p`` (n, 3), ``q_near`` (n, 3) (ignored unless ``has_ref``); returns the
    number of rows with a NaN/inf entry."""
    n, bad = p.shape[0], 0
    l2, offset, co, so = _leg_plane_k(foot_z)
    for i in prange(n):
        s = _ik_core(p[i], li, foot_z, l2, offset, co, so, has_ref, q_near[i], out[i])
        ok[i] = s == OK
        bad += s >= BAD_INPUT
    return bad


def _check_arrays(p_in: object, q_near_in: object) -> None:
    """Raise the InvalidInputError of :func:`as_input` for the inputs a kernel found NaN/inf in, in the
    order of the arguments."""
    as_input(p_in, "p", S3)
    if q_near_in is not None:
        as_input(q_near_in, "q_near", S3)
    raise AssertionError("ik: a kernel reported a non-finite entry that as_input accepts")  # pragma: no cover


def _ik_error(
    status: int, leg: str, li: int, p: np.ndarray, foot_z: float, p_in: object, q_near_in: object
) -> Exception:
    """The legkin error of a failed single call (the kernel's status says which)."""
    if status >= BAD_INPUT:
        _check_arrays(p_in, q_near_in)
    if status == UNREACHABLE:
        return UnreachableError(unreachable_message(leg, p, foot_z), target=p)
    q_all = np.empty((4, 3))
    _ik_all_k(p, li, foot_z, q_all)
    return JointLimitError(
        f"target {p.tolist()} for leg {leg} is reachable only outside the joint limits "
        f"{JOINT_LIMITS.tolist()}: branches {np.round(q_all, 4).tolist()}",
        target=p,
    )


def _broadcast_rows(
    arr: np.ndarray, ref: np.ndarray, p_in: object, q_near_in: object
) -> tuple[tuple[int, ...], np.ndarray, np.ndarray]:
    """The batch shape of ``p`` and ``q_near`` and both as C-contiguous (n, 3) rows."""
    if ref.shape == arr.shape:
        batch = arr.shape[:-1]
        return batch, as_rows(arr, 3), as_rows(ref, 3)
    try:
        batch = np.broadcast_shapes(arr.shape[:-1], ref.shape[:-1])
    except ValueError:
        if not np.isfinite(arr).all():  # as_input checks p entirely before q_near
            as_input(p_in, "p", S3)
        if not np.isfinite(ref).all():
            as_input(q_near_in, "q_near", S3)
        raise InvalidInputError(
            f"p (shape {arr.shape}) and q_near (shape {ref.shape}) do not broadcast together"
        ) from None
    return batch, as_rows(np.broadcast_to(arr, batch + S3), 3), as_rows(np.broadcast_to(ref, batch + S3), 3)


@overload
def ik(
    p: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
    return_mask: Literal[False] = False,
) -> np.ndarray: ...
@overload
def ik(
    p: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
    return_mask: Literal[True],
) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def ik(
    p: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
    return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...


def ik(
    p: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
    return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Joint angles (..., 3) placing the foot at ``p``: the branch inside the joint limits.

    Branch choice (the knee and abduction branches are IK-only choices: the forward map has none). Among the
    four branches of :func:`~legkin.quadruped.ik_all`, keeps those inside :data:`JOINT_LIMITS` (a branch a
    hair outside, by at most :data:`LIMIT_SLACK`, is clipped into the limits and kept if it still reaches the
    target within :data:`CLIP_TOL`, see :mod:`legkin.quadruped.repair`: the answer is always inside the URDF
    limits); picks the one nearest ``q_near`` (Euclidean norm of the wrapped joint differences; ties go to the
    earlier branch) when given, else the first in :data:`BRANCHES` order: (s_u, k) = (-1, -1), (-1, 1),
    (1, -1), (1, 1) (foot below the hip plane first). Inside POPI's limits only the k = -1 knee branch occurs,
    but both s_u branches do (s_u = +1 for large q2), so the choice is made here, not assumed.

    Args:
        p: foot targets (..., 3) in the base frame (m).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        q_near: configurations (..., 3) to stay near. The leading shapes of ``p`` and ``q_near`` broadcast
            together: a single target with a batch of ``q_near`` is a batch (one answer per ``q_near``).
        geometry: the :class:`~legkin.quadruped.Geometry` (None: the default).
        return_mask: also return the boolean mask of targets solved inside the limits.

    Raises:
        UnreachableError: single target out of reach.
        JointLimitError: single target reachable only outside the joint limits.
        InvalidInputError: ``p`` or ``q_near`` not finite real arrays (..., 3), or not broadcastable.
        InvalidParameterError: bad ``leg``, ``geometry`` or ``return_mask``.
    """
    fz = 0.0 if geometry is None else foot_z_of(geometry)
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    try:
        li = LEG_INDEX[leg]
    except (KeyError, TypeError):
        li = leg_index(leg)
    if type(p) is np.ndarray and p.shape == S3 and p.dtype is F64:  # the single call, fast
        if q_near is None:
            out = np.empty(S3)
            status = _ik_noref_k(p, li, fz, out)
            if status:
                raise _ik_error(status, leg, li, p, fz, p, q_near)
            return (out, np.array(True)) if return_mask else out
        if type(q_near) is np.ndarray and q_near.shape == S3 and q_near.dtype is F64:
            out = np.empty(S3)
            status = _ik_k(p, li, fz, True, q_near, out)
            if status:
                raise _ik_error(status, leg, li, p, fz, p, q_near)
            return (out, np.array(True)) if return_mask else out
    arr = rows(p, "p")
    has_ref = q_near is not None
    if has_ref:
        try:
            ref = rows(q_near, "q_near")
        except InvalidInputError:
            as_input(p, "p", S3)  # p is checked entirely (finiteness too) before q_near
            raise
    else:
        ref = arr
    if arr.ndim == 1 and ref.ndim == 1:  # a single call
        out = np.empty(S3)
        status = _ik_k(arr, li, fz, has_ref, ref, out)
        if status:
            raise _ik_error(status, leg, li, arr, fz, p, q_near)
        return (out, np.array(True)) if return_mask else out
    if has_ref:
        batch, p_rows, ref_rows = _broadcast_rows(arr, ref, p, q_near)
    else:
        batch = arr.shape[:-1]
        p_rows = ref_rows = arr if arr.ndim == 2 and arr.flags.c_contiguous else as_rows(arr, 3)
    out = np.empty(batch + S3)
    ok = np.empty(batch, dtype=np.bool_)
    flat = len(batch) == 1
    if _ik_batch(p_rows, li, fz, has_ref, ref_rows, out if flat else out.reshape(-1, 3),
                 ok if flat else ok.reshape(-1)):
        _check_arrays(p, q_near)
    return (out, ok) if return_mask else out
