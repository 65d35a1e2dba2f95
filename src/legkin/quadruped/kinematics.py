"""The quadruped's leg kinematics (seeds 004 and 002): thin wrappers over the generic :class:`legkin.legs.Leg`.

Conventions (base frame: x forward, y left, z up; metres, radians):

* legs ``"LF"``, ``"LH"``, ``"RF"``, ``"RH"``; joint vector ``q = (q1, q2, q3)`` = (``<LEG>_HAA``,
  ``<LEG>_HFE``, ``<LEG>_KFE``), the seed's (aile, epaule, coude) angles; the foot is the frame ``<LEG>_FOOT``;
* the foot position is seed 004's product ``T01 T12 T23 T34`` with ``foot_z`` the one xacro argument
  (:class:`Geometry`) and POPI's offsets (:mod:`legkin.quadruped.constants`)::

      p = h + R_x(s_y q_1) [(0, s_y y12, 0) + R_y(-q_2) (t23 + R_y(q_3) t34)],  t34 = (x34, 0, foot_z)

One implementation: :func:`fk`, :func:`jacobian`, :func:`ik` and :func:`ik_all` call the :class:`~legkin.legs.Leg`
of ``leg`` that :func:`legkin.legs.from_urdf` measures from the quadruped's URDF for ``geometry``
(:func:`~legkin.quadruped.measured.legs`): its compiled kernels, its input checks and its single/batch rule (a
single input (3,) returns plain arrays and raises a legkin error on failure; a batch (..., 3) returns NaN rows where
an item fails, and ``return_mask=True`` also returns the mask). Seed 002's law-of-cosines IK stays as a textbook
cross-check (:mod:`legkin.quadruped.textbook`), not used by these functions.
"""

from __future__ import annotations

from typing import Any, Literal, overload

import numpy as np
import numpy.typing as npt

from .._batch import check_flag, check_number
from .._kernels import OK
from ..legs.kinematics import _FK, _IK, _IK_ALL, _IK_NEAR, _JACOBIAN, Leg, _vector3
from . import constants as _constants
from ._common import foot_z_of, leg_index, rows
from .constants import *  # noqa: F403 - the quadruped's constants (LEGS, JOINT_LIMITS, X01, ...), re-exported
from .constants import JOINT_LIMITS, LIMIT_TOL
from .geometry import DEFAULT_GEOMETRY, Geometry
from .measured import CACHE_SIZE, SEED_ORDER, legs
from .textbook import textbook_frame, textbook_ik, textbook_to_joints

__all__ = _constants.__all__ + [
    "Geometry", "DEFAULT_GEOMETRY", "fk", "jacobian", "ik", "ik_all", "hip_position", "within_limits", "legs",
    "textbook_ik", "textbook_frame", "textbook_to_joints",
]

Mask = tuple[np.ndarray, np.ndarray]
#: POPI's limits as floats (equal to the URDF's, the measured legs' ``lower`` / ``upper``: tests/test_quadruped.py).
_LO, _HI = tuple(JOINT_LIMITS[:, 0].tolist()), tuple(JOINT_LIMITS[:, 1].tolist())
_REVERSED = np.array((3, 2, 1, 0))
#: Per leg, the rows of Leg.ik_all in seed 004's order (the left legs' is reversed: that array itself, a slice serves).
_ORDER = {leg: _REVERSED if order == (3, 2, 1, 0) else np.array(order) for leg, order in SEED_ORDER.items()}
#: The same order as the kernels' ``flip`` (seed row ``s`` holds Leg row ``s ^ flip``): the single call's kernel
#: writes its rows in seed order (a slice or ``take`` of its answer would cost ~150 ns of a ~1 us call).
_FLIP = {leg: order[0] for leg, order in SEED_ORDER.items()}  # (3, 2, 1, 0): 3, (1, 0, 3, 2): 1


#: The default geometry's measured legs by name, once measured (the single calls' look-up: one dict access).
_DEFAULT: dict[str, Leg] = {}
#: Their kernels' arguments by leg name, ``(params, q_ref, flip)``: the single-call fast paths below call the
#: compiled kernels of :class:`~legkin.legs.Leg` directly (one Python call fewer: ~100-200 ns of a ~1 us call).
_KERNEL_ARGS: dict[str, tuple[np.ndarray, np.ndarray, int]] = {}
#: The same for other geometries, by ``foot_z`` then leg name (as many as :func:`legs` keeps; two look-ups: no key
#: tuple to build and hash).
_KERNEL_ARGS_OF: dict[float, dict[str, tuple[np.ndarray, np.ndarray, int]]] = {}
_F64, _S3, _ND = np.dtype(np.float64), (3,), np.ndarray


def _kernel_args(leg: object, geometry: object) -> tuple[np.ndarray, np.ndarray, int] | None:
    """The kernel arguments ``(params, q_ref, flip)`` of ``leg`` for a :class:`Geometry` (measured on first use), or
    None (a bad leg or geometry: the general path then raises its error)."""
    if geometry.__class__ is not Geometry:
        return None
    found = _KERNEL_ARGS_OF.get(geometry.foot_z)  # type: ignore[attr-defined]
    if found is None:
        if len(_KERNEL_ARGS_OF) >= CACHE_SIZE:  # a sweep over foot_z: keep the memory bounded
            _KERNEL_ARGS_OF.clear()
        found = _KERNEL_ARGS_OF[geometry.foot_z] = {  # type: ignore[attr-defined]
            name: (one._g, one._ref, _FLIP[name]) for name, one in legs(geometry).items()}  # type: ignore[arg-type]
    return found.get(leg) if leg.__class__ is str else None  # type: ignore[call-overload]


def _leg(leg: object, geometry: Geometry | None) -> Leg:
    """The measured :class:`~legkin.legs.Leg` of ``leg`` for ``geometry`` (InvalidParameterError for a bad one)."""
    if geometry is None and leg.__class__ is str:
        found_leg = _DEFAULT.get(leg)  # type: ignore[call-overload]
        if found_leg is not None:
            return found_leg
    found = legs(geometry)
    if geometry is None:
        _DEFAULT.update(found)
        _KERNEL_ARGS.update({name: (one._g, one._ref, _FLIP[name]) for name, one in found.items()})
    try:
        return found[leg]  # type: ignore[index]
    except (KeyError, TypeError):
        leg_index(leg)  # raises, naming the legs
        raise  # pragma: no cover


def _flag(value: object) -> bool:
    return value if value is True or value is False else check_flag(value, "return_mask")


def _with_mask(x: np.ndarray, tail: int, return_mask: object) -> np.ndarray | Mask:
    """``x``, or ``(x, mask)`` with an all-True mask (a finite input always has an answer)."""
    if not _flag(return_mask):
        return x
    return x, np.ones(x.shape[: x.ndim - tail], dtype=bool)


@overload
def fk(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None,
       return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def fk(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None, return_mask: Literal[True]) -> Mask: ...


def fk(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None,
       return_mask: bool = False) -> np.ndarray | Mask:
    """Foot position (m, base frame) of the joint angles ``q``: seed 004's product ``T01 T12 T23 T34``.

    Computed by :meth:`legkin.legs.Leg.fk` (the product of exponentials with the joint axes measured from the
    URDF, as Pinocchio). Seed 004 prints T01 with the ``+-`` signs stacked identically in rows 2 and 3 (not a
    rotation); the URDF, and this function, read it as Rx(+q1) for left legs and Rx(-q1) for right legs.

    Args:
        q: joint angles (..., 3) (rad): (``<LEG>_HAA``, ``<LEG>_HFE``, ``<LEG>_KFE``).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        geometry: the :class:`~legkin.quadruped.Geometry` (None: the default, ``foot_z = 0``).
        return_mask: also return the mask (...) of the answers (all True: every finite ``q`` has one).

    Returns:
        Foot positions (..., 3) in metres (and the mask).

    Raises:
        InvalidInputError: ``q`` not a finite real array (..., 3).
        InvalidParameterError: bad ``leg``, ``geometry`` or ``return_mask``.
    """
    if return_mask is False and q.__class__ is _ND and q.shape == _S3 and q.dtype is _F64:
        args = _KERNEL_ARGS.get(leg) if geometry is None and leg.__class__ is str else _kernel_args(leg, geometry)
        if args is not None and _FK.call(q, args[0], out := np.empty(3)) == OK:
            return out
    x = _leg(leg, geometry).fk(q)
    return x if return_mask is False else _with_mask(x, 1, return_mask)


@overload
def jacobian(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None,
             return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def jacobian(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None,
             return_mask: Literal[True]) -> Mask: ...


def jacobian(q: npt.ArrayLike, leg: str, *, geometry: Geometry | None = None,
             return_mask: bool = False) -> np.ndarray | Mask:
    """Jacobian ``dp/dq`` of :func:`fk` (m/rad): :meth:`legkin.legs.Leg.jacobian`, column j = ``a_j x (p - o_j)``.

    Args:
        q: joint angles (..., 3) (rad).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        geometry: the :class:`~legkin.quadruped.Geometry` (None: the default).
        return_mask: also return the mask (...) of the answers (all True).

    Returns:
        Jacobians (..., 3, 3), columns q1, q2, q3, in m/rad (and the mask).

    Raises:
        InvalidInputError: ``q`` not a finite real array (..., 3).
        InvalidParameterError: bad ``leg``, ``geometry`` or ``return_mask``.
    """
    if return_mask is False and q.__class__ is _ND and q.shape == _S3 and q.dtype is _F64:
        args = _KERNEL_ARGS.get(leg) if geometry is None and leg.__class__ is str else _kernel_args(leg, geometry)
        if args is not None and _JACOBIAN.call(q, args[0], out := np.empty((3, 3))) == OK:
            return out
    x = _leg(leg, geometry).jacobian(q)
    return x if return_mask is False else _with_mask(x, 2, return_mask)


@overload
def ik(target: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
       return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def ik(target: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
       return_mask: Literal[True]) -> Mask: ...


def ik(target: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None, geometry: Geometry | None = None,
       return_mask: bool = False) -> np.ndarray | Mask:
    """Joint angles placing the foot at ``target``: the branch inside POPI's joint limits nearest ``q_near``.

    :meth:`legkin.legs.Leg.ik`: among the branches of :func:`ik_all`, each angle at its 2 pi representative inside
    :data:`JOINT_LIMITS` (an angle up to ``legkin.legs.LIMIT_TOL`` outside is clipped onto its limit), the branch
    with the least ``|q - q_near|^2``; ``q_near`` defaults to the middle of the limits, (0, pi/2, 1.09). Inside
    POPI's limits only one knee branch occurs, but both abduction branches do (s_u = +1 for large q2).

    Args:
        target: foot targets (..., 3) in the base frame (m).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        q_near: configurations (..., 3) (rad) to stay near; its leading shape broadcasts with the target's (a
            single target with a batch of ``q_near`` is a batch).
        geometry: the :class:`~legkin.quadruped.Geometry` (None: the default).
        return_mask: also return the boolean mask of the targets solved inside the limits.

    Returns:
        Joint angles (..., 3) (rad), NaN rows for unsolved batch items (and the mask).

    Raises:
        UnreachableError: a single target out of reach (``distance``: by how much, m; the message says why).
        JointLimitError: a single target reachable only outside the joint limits (``joint``, ``value``,
            ``lower``, ``upper`` of the closest branch's joint farthest outside, ``distance`` in rad).
        InvalidInputError: ``target`` or ``q_near`` not finite real arrays (..., 3), or not broadcastable.
        InvalidParameterError: bad ``leg``, ``geometry`` or ``return_mask``.
    """
    p: Any = target
    if return_mask is False and p.__class__ is _ND and p.shape == _S3 and p.dtype is _F64:
        args = _KERNEL_ARGS.get(leg) if geometry is None and leg.__class__ is str else _kernel_args(leg, geometry)
        ref = None if args is None else args[1] if q_near is None else _vector3(q_near)
    else:
        args = ref = None
    if args is not None and ref is not None:
        out = np.empty(3)
        if (_IK.call(p, args[0], out) if q_near is None else _IK_NEAR.call(p, args[0], ref, out)) == OK:
            return out
    return _leg(leg, geometry).ik(target, q_near=q_near, return_mask=return_mask)  # type: ignore[no-any-return]


@overload
def ik_all(target: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None,
           geometry: Geometry | None = None, return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def ik_all(target: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None,
           geometry: Geometry | None = None, return_mask: Literal[True]) -> Mask: ...


def ik_all(target: npt.ArrayLike, leg: str, *, q_near: npt.ArrayLike | None = None,
           geometry: Geometry | None = None, return_mask: bool = False) -> np.ndarray | Mask:
    """Every IK branch of the foot targets, joint limits ignored: :meth:`legkin.legs.Leg.ik_all` in seed order.

    Rows in :data:`BRANCHES` order ``(s_u, k)`` = (-1, -1), (-1, 1), (1, -1), (1, 1): ``s_u = -1`` the foot below
    the hip plane (``u_z < 0`` in the abduction-rotated frame), ``k`` the sign of ``acos K`` in
    ``q3 = (beta - alpha) + k acos K`` (see :data:`~legkin.quadruped.measured.SEED_ORDER`); each angle is the 2 pi
    representative nearest ``q_near`` (default: the middle of the limits). On the singular sets (foot on the
    abduction cylinder, knee straight or folded) two rows coincide.

    Args:
        target: foot targets (..., 3) in the base frame (m).
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        q_near: configurations (..., 3) (rad) the representatives stay near (broadcast with the targets).
        geometry: the :class:`~legkin.quadruped.Geometry` (None: the default).
        return_mask: also return the mask (..., 4) of the branches that exist.

    Returns:
        Joint angles (..., 4, 3) (rad), NaN rows where a branch does not exist (and the mask).

    Raises:
        UnreachableError: a single target out of reach (``distance``: by how much, m).
        InvalidInputError: ``target`` or ``q_near`` not finite real arrays (..., 3), or not broadcastable.
        InvalidParameterError: bad ``leg``, ``geometry`` or ``return_mask``.
    """
    p: Any = target
    if q_near is None and return_mask is False and p.__class__ is _ND and p.shape == _S3 \
            and p.dtype is _F64:
        args = _KERNEL_ARGS.get(leg) if geometry is None and leg.__class__ is str else _kernel_args(leg, geometry)
        if args is not None:
            out = np.empty((4, 3))
            if _IK_ALL.call(p, args[0], args[2], out) == OK:
                return out
    found = _leg(leg, geometry)
    order = _ORDER[leg]
    if not (return_mask if return_mask is False or return_mask is True else _flag(return_mask)):
        q = found.ik_all(target, q_near=q_near)
        return q[..., ::-1, :] if order is _REVERSED else q.take(order, axis=-2)  # type: ignore[no-any-return]
    q, mask = found.ik_all(target, q_near=q_near, return_mask=True)
    if order is _REVERSED:  # the left legs: a view, cheaper than take
        return q[..., ::-1, :], mask[..., ::-1]
    return q.take(order, axis=-2), mask.take(order, axis=-1)


def hip_position(leg: str, *, geometry: Geometry | None = None) -> np.ndarray:
    """The origin (3,) of ``leg``'s abduction joint (``<LEG>_HAA``) in the base frame (m): seed 004's ``h``.

    Args:
        leg: ``"LF"``, ``"LH"``, ``"RF"`` or ``"RH"``.
        geometry: the :class:`~legkin.quadruped.Geometry` (checked; the hip does not depend on it).

    Returns:
        ``(s_x x01, s_y y01, z01)`` as measured from the URDF (m).

    Raises:
        InvalidParameterError: bad ``leg`` or ``geometry``.
    """
    return _leg(leg, geometry).origin.copy()


def within_limits(q: npt.ArrayLike, tol: float = LIMIT_TOL, *,
                  geometry: Geometry | None = None) -> np.ndarray | bool:
    """Whether joint vectors (..., 3) lie inside :data:`JOINT_LIMITS` widened by ``tol`` (rad).

    NaN and infinite entries (e.g. the NaN rows of :func:`ik_all`) count as outside.

    Args:
        q: joint angles (..., 3) (rad).
        tol: slack (rad), a finite number >= 0.
        geometry: the :class:`~legkin.quadruped.Geometry` (checked; the limits do not depend on it).

    Returns:
        A bool for a single ``q`` (3,), a bool array (...) for a batch.

    Raises:
        InvalidInputError: ``q`` not a real array of shape (..., 3).
        InvalidParameterError: ``tol`` not a finite number >= 0; bad ``geometry``.
    """
    if type(tol) is not float or not 0.0 <= tol < np.inf:
        tol = check_number(tol, "tol", 0.0)
    if geometry is not None:
        foot_z_of(geometry)
    arr = rows(q, "q")
    if arr.ndim == 1:  # a single call: plain floats (numpy's elementwise calls cost ~1 us each on (3,))
        q1, q2, q3 = arr.tolist()
        return (_LO[0] - tol <= q1 <= _HI[0] + tol and _LO[1] - tol <= q2 <= _HI[1] + tol
                and _LO[2] - tol <= q3 <= _HI[2] + tol)
    return np.all((arr >= JOINT_LIMITS[:, 0] - tol) & (arr <= JOINT_LIMITS[:, 1] + tol), axis=-1)
