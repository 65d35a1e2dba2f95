"""Inverse kinematics of the tripod (seed eqs (98), (102)) and its actuation Jacobian A_u (Appendix D): the
public wrappers over the kernels of :mod:`legkin.tripod.closure`, and the diagnosis of a failed single call."""

from __future__ import annotations

from typing import Any, Literal, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import dispatch, same_signature
from .._kernels import OK
from ..errors import SingularityError, UnreachableError
from ._common import (
    BOUNDARY_TOL,
    DET_GUARD,
    GAIN_GUARD,
    HOME_MODE,
    LEGS,
    MODE_ARGS,
    MODES,
    SINGULAR_TOL,
    checked_mode,
    flag,
    geometry_of,
    modes_sel,
)
from .closure import IK_ALL_LOOP, IK_LOOP, JACOBIAN_LOOP, _k_actuation_jacobian, _k_ik, _k_ik_all
from .geometry import DEFAULT, Geometry

__all__ = ["ik", "ik_all", "ik_joints", "jacobian"]

_G_DEFAULT = DEFAULT._vector
_F64 = np.dtype(np.float64)  # the fast paths test ``dtype is _F64`` (3x cheaper than ``== np.float64``)
_BOOL = np.dtype(np.bool_)  # np.empty(n, _BOOL): 30 ns less than dtype=np.bool_


# ------------------------------------------------------------------------------------------ diagnosis
def _ik_status(c2: np.ndarray, one_cc: np.ndarray) -> tuple[Any, np.ndarray, np.ndarray]:
    """Masks: (singular platform (...), unreachable (..., 3), leg singular (..., 3))."""
    sing = one_cc <= SINGULAR_TOL
    with np.errstate(invalid="ignore"):
        gap = 1.0 - np.abs(c2)
        unreachable = ~sing[..., None] & (gap < -BOUNDARY_TOL)
        leg_sing = ~sing[..., None] & (np.abs(gap) <= BOUNDARY_TOL)
    return sing, unreachable, leg_sing


def _where(ay: float, az: float) -> str:
    return f"(alpha_y, alpha_z) = ({float(ay):.17g}, {float(az):.17g})"


def _ik_error(ay: float, az: float, c2: np.ndarray, sing: Any, unreachable: np.ndarray,
              leg_sing: np.ndarray) -> Exception:
    where = _where(ay, az)
    if sing:
        return SingularityError(
            f"{where} is singular: 1 + cos(alpha_y) cos(alpha_z) = 0 (platform axis turned back onto -x; "
            "the platform centre is undefined)"
        )
    for k, leg in enumerate(LEGS):
        if unreachable[k]:
            return UnreachableError(
                f"{where} is outside the workspace: leg {leg} would need cos q_{leg}2 = {float(c2[k]):.17g}, "
                "outside [-1, 1] (eq 98)",
                target=np.array([float(ay), float(az)]),
            )
    for k, leg in enumerate(LEGS):
        if leg_sing[k]:
            return SingularityError(
                f"{where} is on the workspace boundary: leg {leg} has sin q_{leg}2 = 0 "
                f"(cos q_{leg}2 = {float(c2[k]):.17g}); joints 1 and 3 of the leg are aligned"
            )
    return SingularityError(f"{where}: inverse kinematics failed")  # pragma: no cover


def ik_one(ay: float, az: float, G: np.ndarray, mode: str) -> tuple[np.ndarray, np.ndarray, int]:
    """The ik kernel on one orientation in one mode: joints (12,), aux (6,), status."""
    home, e, s = MODE_ARGS[mode]
    q, aux = np.empty(12), np.empty(6)
    return q, aux, _k_ik(ay, az, G, home, e, s, q, aux)


def ik_single_error(ay: float, az: float, G: np.ndarray, mode: str, aux: np.ndarray) -> Exception:
    """The exception of a failed single ik call at (ay, az) in ``mode`` (aux: the kernel's (cos q_K2 (3),
    1 + c_y c_z, det M, |A_u|_F))."""
    c2, nb2 = np.asarray(aux[:3], dtype=float), np.asarray(aux[3], dtype=float).reshape(())
    det, gain = float(aux[4]), float(aux[5])
    sing, unreachable, leg_sing = _ik_status(c2, nb2)
    if sing or unreachable.any() or leg_sing.any():
        return _ik_error(ay, az, c2, sing, unreachable, leg_sing)
    if not gain <= GAIN_GUARD:
        return SingularityError(
            f"{_where(ay, az)}: its motors are too sensitive to the orientation (|A_u| = {gain:.3g} > "
            f"GAIN_GUARD = {GAIN_GUARD:g}: a leg next to its boundary near the flip); the float orientation fixes "
            "them only to ~1e-16 |A_u| rad and fk could not reproduce it"
        )
    others = [m for m in MODES if m != mode and ik_one(float(ay), float(az), G, m)[2] == OK]
    return SingularityError(
        f"{_where(ay, az)} is an actuation singularity in mode {mode}: its motor planes have |det M| = {abs(det):.3g} "
        f"< DET_GUARD = {DET_GUARD:g}, so the motor angles do not determine the pose (fk could not reproduce it "
        f"to 1e-9 rad); solvable in mode(s) {', '.join(others) or 'none'}"
    )


# ------------------------------------------------------------------------------------------ the solve
def _run(ay: np.ndarray, az: np.ndarray, G: np.ndarray, mode: str,
         width: int = 12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ik batch loop on broadcast orientations: q (shape, m, width) (every joint, 12, or the motors, 3),
    aux (shape, m, 6), status (shape, m)."""
    shape = ay.shape
    y = np.ascontiguousarray(ay, dtype=np.float64).reshape(-1)
    z = np.ascontiguousarray(az, dtype=np.float64).reshape(-1)
    homes, es, ss = modes_sel(mode)
    n, m = y.shape[0], homes.shape[0]
    q, aux, status = np.empty((n, m, width)), np.empty((n, m, 6)), np.empty((n, m), dtype=np.int64)
    IK_LOOP(y, z, G, homes, es, ss, q, aux, status)
    return q.reshape(shape + (m, width)), aux.reshape(shape + (m, 6)), status.reshape(shape + (m,))


def _checked(mode: object, geometry: object, return_mask: object,
             allow_all: bool = True) -> tuple[str, np.ndarray, bool]:
    """(mode, the kernels' geometry vector, return_mask) of a call, checked (fast for the common values)."""
    if not (type(mode) is str and mode in MODE_ARGS):
        mode = checked_mode(mode, allow_all=allow_all)
    G = _G_DEFAULT if geometry is None else geometry_of(geometry)._vector
    if return_mask is not False and return_mask is not True:
        return_mask = flag(return_mask, "return_mask")
    return mode, G, return_mask  # type: ignore[return-value]


def _yz(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.ascontiguousarray(rows[:, 0]), np.ascontiguousarray(rows[:, 1])


#: The kernels' diagnostic output on the fast paths, never read there (a failure is diagnosed again by the
#: error function), so one buffer serves every call; so does ik_all's mask (16,) when it is not returned.
_SCRATCH_AUX, _SCRATCH_AUX4, _SCRATCH_OK16 = np.empty(6), np.empty(4), np.empty(16, _BOOL)


# ---- ik / ik_joints: one mode (width 3: the motors, 12: every joint)
def _ik_fast(t: np.ndarray, args: tuple[np.ndarray, str, int]) -> np.ndarray | None:
    G, mode, width = args
    home, e, s = MODE_ARGS[mode]
    out = np.empty(width)
    ay, az = t.tolist()  # Python floats: numba dispatches them faster than numpy scalars
    return out if _k_ik(ay, az, G, home, e, s, out, _SCRATCH_AUX) == OK else None


def _ik_batch(rows: np.ndarray, G: np.ndarray, mode: str, width: int) -> tuple[np.ndarray, np.ndarray]:
    q, _, status = _run(*_yz(rows), G, mode, width)
    return q[:, 0], status[:, 0] == OK


def _ik_fail(t: np.ndarray, out: np.ndarray, ok: np.ndarray, G: np.ndarray, mode: str, width: int) -> Exception:
    ay, az = float(t[0]), float(t[1])
    return ik_single_error(np.float64(ay), np.float64(az), G, mode, ik_one(ay, az, G, mode)[1])


# ---- ik_all: every mode
def _all_fast(t: np.ndarray, args: tuple[np.ndarray, int, bool]) -> Any:
    """One orientation: q (16, width), or (q, mask) with ``return_mask`` (else the mask goes to a scratch buffer)."""
    G, width, return_mask = args
    q, ok = np.empty((16, width)), (np.empty(16, _BOOL) if return_mask else _SCRATCH_OK16)
    ay, az = t.tolist()
    if _k_ik_all(ay, az, G, q, ok) != OK:
        return None
    return (q, ok) if return_mask else q


#: ``dispatch(..., chunks=False)`` for :func:`_all_batch`: its temporaries (status, 8 B a target) are far below its
#: answer (16 modes, 400 B a target); copying chunks of that answer cost 10% of ik_all's CPU time.
def _all_batch(rows: np.ndarray, G: np.ndarray, width: int, return_mask: bool) -> tuple[np.ndarray, np.ndarray]:
    n = rows.shape[0]
    q, ok, status = np.empty((n, 16, width)), np.empty((n, 16), dtype=np.bool_), np.empty(n, dtype=np.int64)
    IK_ALL_LOOP(*_yz(rows), G, q, ok, status)
    return q, ok


def _all_fail(t: np.ndarray, out: np.ndarray, ok: np.ndarray, G: np.ndarray, width: int,
              return_mask: bool) -> Exception:
    return _ik_fail(t, out, ok, G, HOME_MODE, width)


# ---- jacobian
def _jac_fast(t: np.ndarray, args: tuple[np.ndarray, str]) -> np.ndarray | None:
    G, mode = args
    home, e, s = MODE_ARGS[mode]
    a = np.empty((3, 2))
    ay, az = t.tolist()
    return a if _k_actuation_jacobian(ay, az, G, home, e, s, a, _SCRATCH_AUX4) == OK else None


def _jac_batch(rows: np.ndarray, G: np.ndarray, mode: str) -> tuple[np.ndarray, np.ndarray]:
    home, e, s = MODE_ARGS[mode]
    n = rows.shape[0]
    a, aux, status = np.empty((n, 3, 2)), np.empty((n, 4)), np.empty(n, dtype=np.int64)
    JACOBIAN_LOOP(*_yz(rows), G, home, e, s, a, aux, status)
    return a, status == OK


def _jac_fail(t: np.ndarray, out: np.ndarray, ok: np.ndarray, G: np.ndarray, mode: str) -> Exception:
    home, e, s = MODE_ARGS[mode]
    a, aux = np.empty((3, 2)), np.empty(4)
    _k_actuation_jacobian(float(t[0]), float(t[1]), G, home, e, s, a, aux)
    c2 = aux[:3].copy()
    return _ik_error(np.float64(t[0]), np.float64(t[1]), c2, *_ik_status(c2, np.asarray(aux[3])))


# ------------------------------------------------------------------------------------------ public
@overload
def ik(target: ArrayLike, *, mode: str = ..., geometry: Geometry | None = ...,
       return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def ik(target: ArrayLike, *, mode: str = ..., geometry: Geometry | None = ...,
       return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def ik(target: ArrayLike, *, mode: str = HOME_MODE, geometry: Geometry | None = None,
       return_mask: bool = False) -> Any:
    """The three motor angles (q_A1, q_B1, q_C1) for the platform orientation ``target = (alpha_y, alpha_z)``.

    Seed eqs (98), (102) per leg K (``c_K = cos eta_K``, ``s_K = sin eta_K``), with E = (x, y, z) from
    :func:`platform_position`:

    * eq (98): ``cos q_K2 = (c_K z - s_K y) / (d s_alpha)``, ``q_K2 = acos(.) in (0, pi)``;
    * eq (102): ``(s_K1, c_K1) = [[1 - c_alpha, s2 s_alpha], [-s2 s_alpha, 1 - c_alpha]] (x, -(c_K y + s_K z))
      / d~``, ``q_K1 = atan2(s_K1, c_K1)``. Departures: eq (100) misses a ``c1`` in x_ee (correct:
      ``x = d (1 - c_alpha) s1 - d c1 s2 s_alpha``, as (101) uses), and the determinant of (101) is
      ``d^2 ((1 - c_alpha)^2 + (s2 s_alpha)^2)``; (102) is right with ``d~ = d ((1 - c_alpha)^2 + (s2 s_alpha)^2)``;
    * ``q_K3 = q_K2`` and ``q_K4 = q_K1`` (the constant-velocity branch; every joint: :func:`ik_joints`).

    That is the home assembly mode (:data:`HOME_MODE`, that of the SRDF pose ``home``). ``mode`` picks another
    of :data:`MODES`: ``E = +L b / |b|`` when its first sign is ``+``, and ``q_K2 = -acos(.)`` for the legs
    whose sign is ``-`` (eq 102 then uses that sin q_K2). Every mode reaches the same orientations with other
    motors; ``mode="all"`` is :func:`ik_all`.

    Args:
        target: platform orientation(s) (..., 2) = (alpha_y, alpha_z) (rad).
        mode: assembly mode, one of :data:`MODES` (or ``"all"``).
        geometry: the tripod's :class:`Geometry` (None: the default).
        return_mask: (batch) also return the success mask.

    Returns:
        (..., 3) motor angles (q_A1, q_B1, q_C1) in (-pi, pi] (``mode="all"``: (..., 16, 3)).

    Raises:
        UnreachableError: (single) ``|cos q_K2| > 1`` for some leg K (outside the workspace).
        SingularityError: (single) ``sin q_K2 = 0`` (workspace boundary), ``1 + c_y c_z = 0``, or an actuation
            singularity: the motors' planes have ``|det M| < DET_GUARD`` (the motors do not determine the pose,
            so :func:`fk` could not reproduce it; the message lists the modes where the pose is solvable), or
            ``|A_u|_F > GAIN_GUARD``.
        InvalidInputError: non-finite, complex or wrongly shaped target; InvalidParameterError: bad geometry,
            mode or return_mask.
    """
    mode, G, return_mask = _checked(mode, geometry, return_mask)
    if mode == "all":
        return dispatch(target, "target", (2,), _all_fast, _all_batch, _all_fail, (G, 3, return_mask), return_mask,
                        chunks=False)
    return dispatch(target, "target", (2,), _ik_fast, _ik_batch, _ik_fail, (G, mode, 3), return_mask)


@overload
def ik_all(target: ArrayLike, *, geometry: Geometry | None = ..., return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def ik_all(target: ArrayLike, *, geometry: Geometry | None = ...,
           return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def ik_all(target: ArrayLike, *, geometry: Geometry | None = None, return_mask: bool = False) -> Any:
    """The motors of every assembly mode for ``target`` (..., 2): shape (..., 16, 3) in :data:`MODES` order, NaN
    (mask False) where a mode does not solve it (every mode reaches the same orientations; a mode fails only on
    its own actuation singularities, :data:`DET_GUARD`, :data:`GAIN_GUARD`). A single call raises only when no
    mode solves the target. Equals :func:`ik` with ``mode="all"``, and row j equals ``ik(target, mode=MODES[j])``
    bit for bit: one kernel (:func:`legkin.tripod.closure._k_ik_all`) solves each leg once per side of E and sign
    of sin q_K2 and combines the 12 leg solutions into the 16 modes; the batch is a compiled loop over it.

    Args:
        target: platform orientation(s) (..., 2) = (alpha_y, alpha_z) (rad).
        geometry: the tripod's :class:`Geometry` (None: the default).
        return_mask: also return the mask (..., 16) of the modes that solve the target.

    Returns:
        (..., 16, 3) motor angles (rad) in :data:`MODES` order, NaN rows where a mode does not solve the target;
        then the mask, if asked.
    """
    G = _G_DEFAULT if geometry is None else geometry_of(geometry)._vector  # (no mode to check: _checked's rest)
    if return_mask is not False and return_mask is not True:
        return_mask = flag(return_mask, "return_mask")
    return dispatch(target, "target", (2,), _all_fast, _all_batch, _all_fail, (G, 3, return_mask), return_mask,
                    chunks=False)


@same_signature(ik)
def ik_joints(target: ArrayLike, *, mode: str = HOME_MODE, geometry: Geometry | None = None,
              return_mask: bool = False) -> Any:
    """Every joint for ``target`` (..., 2): (..., 12) ordered A_q1..A_q4, B_q1..B_q4, C_q1..C_q4 (the Pinocchio
    order: a closed configuration of ``legkin.load("tripod")``), ``q_K3 = q_K2``, ``q_K4 = q_K1``; otherwise as
    :func:`ik` (whose motors are columns 0, 4, 8). ``mode="all"``: (..., 16, 12).

    Args:
        target: platform orientation(s) (..., 2) = (alpha_y, alpha_z) (rad).
        mode: assembly mode, one of :data:`MODES` or ``"all"``.
        geometry: the tripod's :class:`Geometry` (None: the default).
        return_mask: (batch) also return the success mask.

    Returns:
        (..., 12) joint angles (rad) (``mode="all"``: (..., 16, 12)); then the mask, if asked.
    """
    mode, G, return_mask = _checked(mode, geometry, return_mask)
    if mode == "all":
        return dispatch(target, "target", (2,), _all_fast, _all_batch, _all_fail, (G, 12, return_mask), return_mask,
                        chunks=False)
    return dispatch(target, "target", (2,), _ik_fast, _ik_batch, _ik_fail, (G, mode, 12), return_mask)


@same_signature(ik)
def jacobian(target: ArrayLike, *, mode: str = HOME_MODE, geometry: Geometry | None = None,
             return_mask: bool = False) -> Any:
    """A_u = d(q_A1, q_B1, q_C1) / d(alpha_y, alpha_z), the Jacobian of :func:`ik`: seed Appendix D, eqs (103)-(105),
    shape (..., 3, 2) for ``target`` (..., 2).

    Row K (``c_K = cos eta_K``, ``s_K = sin eta_K``, ``s_K2 = sin q_K2`` from :func:`ik`,
    ``f_K = tan(alpha/2) (c_K s_y + s_K c_y s_z)``, ``n = 1 + c_y c_z``,
    ``m_K = (1 + c_alpha) s_K2^2 + 1 - c_alpha``, ``p_K = n^2 + (c_K c_y s_z - s_K s_y)^2``)::

        A_K1 = -f_K (c_K (c_y + c_z) - s_K s_y s_z + (c_K c_y - s_K s_y s_z) n) / (2 s_K2 n^2 m_K)
               - (c_K s_y s_z + s_K (c_y + c_z)) / p_K
        A_K2 = -f_K c_y (s_K (c_y + c_z) + c_K s_y s_z + s_K c_z n) / (2 s_K2 n^2 m_K)
               + c_y (c_K (c_y + c_z) - s_K s_y s_z) / p_K

    transcribed as printed (no error found: it matches Pinocchio's closed-loop differential kinematics
    and central differences of :func:`ik`, on the branch q_K2 in (0, pi)). A_u does not depend on d.
    In another assembly ``mode`` (:data:`MODES`) the chain rule through that mode's IK. Undefined where the
    pose is outside the workspace or singular (NaN / the exceptions of :func:`ik`); the actuation-singularity
    guard of :func:`ik` (:data:`DET_GUARD`) does not apply: A_u is defined there.

    Args:
        target: platform orientation(s) (..., 2) = (alpha_y, alpha_z) (rad).
        mode: assembly mode, one of :data:`MODES`.
        geometry: the tripod's :class:`Geometry` (None: the default).
        return_mask: (batch) also return the success mask.

    Returns:
        (..., 3, 2) A_u (rad/rad), NaN where undefined; then the mask, if asked.
    """
    mode, G, return_mask = _checked(mode, geometry, return_mask, allow_all=False)
    return dispatch(target, "target", (2,), _jac_fast, _jac_batch, _jac_fail, (G, mode), return_mask)
