"""The foot IK in closed form (seed 003): the platform pose of a foot target (:func:`foot_platform_ik`), the motor
angles in the mode asked for (:func:`ik`), and every closed-form branch with its mode (:func:`ik_all`)."""

from __future__ import annotations

from typing import Literal, NamedTuple, Sequence, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_input, check_flag, dispatch, finish
from ..errors import InvalidInputError, UnreachableError
from ._ik_errors import arc_error, axis_error, ik_error, platform_pose
from ._ik_kernels import foot_ik_b, ik_all_b, ik_all_out_k, platform_pose_b
from ._options import Branch, check_assembly, check_branch, check_sign, fast_geometry, fmt, mode_args, resolve
from .chains import CX, CY, CZ
from .geometry import CENTER, FOOT_IK_ORDER, Geometry

__all__ = ["foot_platform_ik", "ik", "ik_all", "ik_branches", "FootIKSolutions"]

_COMBOS = np.array(FOOT_IK_ORDER, dtype=np.float64)
_NO_NEAR = np.full((1, 3), np.nan)  # the near row of a single call (none)
_CENTER_ROW = CENTER.reshape(1, 3)  # p[None] - _CENTER_ROW: a single target's row u = p - CENTER (one numpy call)
_BOOL = np.dtype(np.bool_)  # np.empty(n, _BOOL): 30 ns less than dtype=np.bool_
_NO_BRANCH = bytes(16)  # the bytes of a mask (16,) without any branch (10x cheaper to compare than .any())


def _combos(llb: float | None, rb: float | None) -> list:
    return [(l, r) for l, r in FOOT_IK_ORDER if (llb is None or l == llb) and (rb is None or r == rb)]


def _search(u: np.ndarray, sv: float, combos: list, b: np.ndarray, s: float, limits_only: bool = False,
            axis_ok: bool = True, near: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First accepted candidate per target u (n, 3), in the order ``combos`` (or the nearest ``near`` (n, 3)):
    motors, pose, ok (the batch kernel :func:`foot_ik_b`)."""
    n = len(u)
    motors, pose, ok = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.bool_)
    nr = np.full((n, 3), np.nan) if near is None else near
    foot_ik_b(np.ascontiguousarray(u, dtype=np.float64), float(sv),
                                  np.array(combos, dtype=np.float64).reshape(-1, 2), float(b[0]), float(b[1]),
                                  float(s), bool(limits_only), bool(axis_ok), np.ascontiguousarray(nr), motors, pose,
                                  ok)
    return motors, pose, ok


def _one(p: np.ndarray, sv: float, b1: float, b2: float, s: float, limits_only: bool, axis_ok: bool
         ) -> np.ndarray | None:
    """The fast single call: the batch loop :func:`foot_ik_b` on one row (its kernel then has one caller and is
    inlined, see CONTRIBUTING.md), in the default order of the branches; the pose (3,), or None (the checked path
    then decides, and raises)."""
    motors, pose, ok = np.empty((1, 3)), np.empty((1, 3)), np.empty(1, _BOOL)
    foot_ik_b.kernel(p[None] - _CENTER_ROW, sv, _COMBOS, b1, b2, s, limits_only, axis_ok, _NO_NEAR, motors, pose, ok)
    return pose[0] if ok[0] else None


def _targets(target: ArrayLike) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    pp = as_input(target, "target", (3,))
    return pp, (pp - CENTER).reshape(-1, 3), pp.shape[:-1]


@overload
def foot_platform_ik(target: ArrayLike, *, ll_branch: int | None = ..., roll_branch: int | None = ...,
                     branch: Branch | None = ..., assembly: int | None = ..., geometry: Geometry | None = ...,
                     return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def foot_platform_ik(target: ArrayLike, *, ll_branch: int | None = ..., roll_branch: int | None = ...,
                     branch: Branch | None = ..., assembly: int | None = ..., geometry: Geometry | None = ...,
                     return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def foot_platform_ik(target: ArrayLike, *, ll_branch: int | None = None, roll_branch: int | None = None,
                     branch: Branch | None = None, assembly: int | None = None, geometry: Geometry | None = None,
                     return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """(theta_LL, roll, pitch) (..., 3) placing the foot at ``p = target`` (CCS), in closed form.

    Inverts :func:`foot_position_from_platform`:

    1. the distance from the LCS centre depends on theta_LL alone:
       ``|p - c|^2 = |o|^2 + h^2 - 2 h |o| cos(theta_LL - delta)`` with ``o = (1.640, -0.037)``,
       ``h = 1.5``, ``delta = atan2(0.037, 1.640)``; ``theta_LL = delta + ll_branch acos(...)``
       (``ll_branch = -1``: theta_LL <= delta, the extension side). Unreachable unless
       ``|o| - h <= |p - c| <= |o| + h`` (0.14042 to 3.14042 m, :data:`LL_TOL` of rounding allowed).
    2. ``u = p - c = Rx(roll) v``, ``v = Ry(pitch) f`` with ``f`` the foot in P: ``v_y = 0`` gives
       ``v_z = +-sqrt(u_y^2 + u_z^2)``, ``roll = atan2(-u_y / v_z, u_z / v_z)`` (``roll_branch = +1``:
       |roll| <= pi/2), and ``pitch = atan2(f_z, f_x) - atan2(v_z, u_x)``.

    Branches: with neither ``ll_branch`` nor ``roll_branch`` given (default) the branches are tried in the order
    :data:`FOOT_IK_ORDER` and the first inside the joint limits (|roll|, |pitch| <= pi/2) is returned; with
    ``branch`` / ``assembly`` given (either; the other defaults to (1, 1) / +1), also in that assembly mode, as
    :func:`ik` (the foot's forward map from the pose has no assembly mode, hence no mode check by default).
    Giving ``ll_branch`` or ``roll_branch`` alone returns that closed-form branch as is (the other defaulting to
    -1 / +1), unchecked.

    Singular exactly on the roll axis (``u_y = u_z = 0``: roll undetermined, SingularityError; with ``branch`` /
    ``assembly`` given, as :func:`ik`, roll 0 or pi is tried there); within :data:`RHO_TOL` of it roll is
    taken as 0 (roll_branch +1) or pi (-1).

    Args:
        target: foot targets (..., 3) in CCS (m).
        ll_branch, roll_branch: None (search, default) or +1 / -1.
        branch, assembly: None (no mode check, default) or the mode of :func:`ik`.
        geometry: the geometry (universal centre); None = the default.
        return_mask: also return the mask of successes.

    Returns:
        (..., 3) (theta_LL, roll, pitch) (rad), NaN where a batch item fails; then the mask, if asked.

    Raises:
        UnreachableError: single target out of reach (JointLimitError: only outside the limits;
            AssemblyModeError: only in another mode).
        SingularityError: single target exactly on the roll axis.
    """
    if (ll_branch is None and roll_branch is None and branch is None and assembly is None and return_mask is False
            and geometry is None and type(target) is np.ndarray and target.shape == (3,)
            and target.dtype == np.float64):
        pose = _one(target, 0.0, 1.0, 1.0, 1.0, True, False)
        if pose is not None:
            return pose
    resolve(geometry)
    pp, u, shape = _targets(target)
    llb = check_sign(ll_branch, "ll_branch", allow_none=True)
    rb = check_sign(roll_branch, "roll_branch", allow_none=True)
    moded = branch is not None or assembly is not None
    b = check_branch((1, 1) if branch is None else branch)
    s = check_assembly(1 if assembly is None else assembly)
    check_flag(return_mask, "return_mask")
    if (llb is not None or rb is not None) and not moded:
        n = len(u)
        out, info = np.empty((n, 3)), np.empty((n, 3))
        platform_pose_b(np.ascontiguousarray(u), -1.0 if llb is None else llb,
                                                  1.0 if rb is None else rb, out, info)
        ok = (info[:, 1] == 1.0) & (info[:, 2] > 0.0)
        out = np.where(ok[:, None], out, np.nan)

        def error() -> Exception:
            return arc_error(pp) if info[0, 1] != 1.0 else axis_error(pp)

        return finish(out.reshape(shape + (3,)), ok.reshape(shape), pp.ndim == 1, return_mask, error)
    combos = _combos(llb, rb)
    _, pose, ok = _search(u, 0.0, combos, b, s, limits_only=not moded, axis_ok=moded)
    return finish(pose.reshape(shape + (3,)), ok.reshape(shape), pp.ndim == 1, return_mask,
                  lambda: ik_error(pp, 0.0, combos, b, s, limits_only=not moded))


@overload
def ik(target: ArrayLike, *, branch: Branch = ..., assembly: int = ..., ll_branch: int | None = ...,
       roll_branch: int | None = ..., q_near: ArrayLike | None = ..., geometry: Geometry | None = ...,
       return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def ik(target: ArrayLike, *, branch: Branch = ..., assembly: int = ..., ll_branch: int | None = ...,
       roll_branch: int | None = ..., q_near: ArrayLike | None = ..., geometry: Geometry | None = ...,
       return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def ik(target: ArrayLike, *, branch: Branch = (1, 1), assembly: int = 1, ll_branch: int | None = None,
       roll_branch: int | None = None, q_near: ArrayLike | None = None, geometry: Geometry | None = None,
       return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Motor angles ``q = (theta1, theta2, theta0)`` (..., 3) placing the foot at ``target`` (..., 3) (CCS), in closed
    form: :func:`foot_platform_ik` (target -> theta_LL -> roll, pitch), :func:`motor_angles` (eqs 3-16 per chain)
    and :func:`extension_motor_angle` (eq 19 inverted).

    The IK contract: the answer is in the mode ``branch`` (motor branches), ``assembly`` (:func:`assembly_mode`)
    that :func:`fk` uses with the same arguments (defaults: the mode of the SRDF reference pose ``neutral``),
    inside the URDF joint limits, and :func:`fk` of it is the target. The IK-only branches ``ll_branch`` (LL side)
    and ``roll_branch`` are tried in the order :data:`FOOT_IK_ORDER` ((-1, +1), (+1, +1), (-1, -1), (+1, -1));
    giving one restricts the search to it. The first candidate kept is inside the limits, in the mode, outside the
    forward-singularity band (:data:`FK_GAIN_MAX`) and the pose the forward kinematics returns for its motor angles.

    Args:
        target: foot targets (..., 3) in CCS (m).
        branch, assembly: the assembly mode (default (1, 1), +1), as in :func:`fk`.
        ll_branch, roll_branch: None (search both, default) or +1 / -1.
        q_near: motor angles (theta1, theta2, theta0) (3,) or (..., 3): of the candidates kept, return the one
            nearest them in the joints (MCS1, MCS2 wrapped, LL = RATIO theta0) instead of the first.
        geometry: the geometry (universal centre; ``starting_value`` of eq 19); None = the default.
        return_mask: also return the mask of successes.

    Returns:
        (..., 3) motor angles (theta1, theta2, theta0) (rad), NaN where a batch item fails; then the
        mask, if asked.

    Raises:
        UnreachableError: single target out of reach (of the LL arc or of the motors);
            JointLimitError: reachable only outside the joint limits;
            AssemblyModeError: reachable only in other modes (``.modes`` lists the arguments that reach it).
        SingularityError: single target in the forward-singularity band, or exactly on the roll axis (where roll
            is undetermined and ik tries roll = 0 and pi) with neither roll reaching it in the mode.
    """
    sv, b1, b2, s, return_mask = mode_args(branch, assembly, geometry, return_mask, "ik")
    combos: Sequence[tuple[int, int]] = FOOT_IK_ORDER
    order = _COMBOS
    if ll_branch is not None or roll_branch is not None:
        combos = _combos(check_sign(ll_branch, "ll_branch", allow_none=True),
                         check_sign(roll_branch, "roll_branch", allow_none=True))
        order = np.array(combos, dtype=np.float64).reshape(-1, 2)
    near = _NO_NEAR
    if q_near is not None:
        target = as_input(target, "target", (3,))
        near = _near_rows(q_near, target.shape[:-1])
    return dispatch(target, "target", (3,), _ik_fast, _ik_batch, _ik_fail, (sv, b1, b2, s, combos, order, near),
                    return_mask)


def _near_rows(q_near: ArrayLike, shape: tuple[int, ...]) -> np.ndarray:
    """``q_near`` (3,) or (..., 3) broadcast to the targets' batch shape, as rows (n, 3)."""
    qn = as_input(q_near, "q_near", (3,))
    try:
        return np.ascontiguousarray(np.broadcast_to(qn, shape + (3,)).reshape(-1, 3))
    except ValueError:
        raise InvalidInputError(f"q_near must broadcast to shape {shape + (3,)}, got shape {qn.shape}") from None


def _ik_fast(p: np.ndarray, args: tuple) -> np.ndarray | None:
    """One target: the batch loop :func:`foot_ik_b` on one row (its kernel then has one caller and is inlined);
    ``args``: those of :func:`_ik_batch`."""
    sv, b1, b2, s, _combos, order, near = args
    motors, pose, ok = np.empty((1, 3)), np.empty((1, 3)), np.empty(1, _BOOL)
    foot_ik_b.kernel(p[None] - _CENTER_ROW, sv, order, b1, b2, s, False, True, near, motors, pose, ok)
    return motors[0] if ok[0] else None


def _ik_batch(rows: np.ndarray, sv: float, b1: float, b2: float, s: float, combos: Sequence[tuple[int, int]],
              order: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = len(rows)
    motors, pose, ok = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.bool_)
    nr = np.full((n, 3), np.nan) if near is _NO_NEAR else near
    foot_ik_b(rows - CENTER, sv, order, b1, b2, s, False, True, nr, motors, pose, ok)
    return motors, ok


def _ik_fail(p: np.ndarray, out: np.ndarray, ok: np.ndarray, sv: float, b1: float, b2: float, s: float,
             combos: Sequence[tuple[int, int]], order: np.ndarray, near: np.ndarray) -> Exception:
    return ik_error(p, sv, list(combos), np.array([b1, b2]), s)


class FootIKSolutions(NamedTuple):
    """Every closed-form foot IK branch of :func:`ik_all`, in :data:`FOOT_IK_BRANCHES` order."""

    #: (..., 16, 3) motor angles (theta1, theta2, theta0), NaN where the branch does not exist.
    motors: np.ndarray
    #: (..., 16, 3) (theta_LL, roll, pitch) of each branch.
    pose: np.ndarray
    #: (..., 16) the branch exists (LL arc and motors reach, target off the roll axis).
    mask: np.ndarray
    #: (..., 16) assembly mode of the branch's pose on its motor branch (+1 / -1, 0 where it does not exist).
    assembly: np.ndarray
    #: (..., 16) the branch's pose is inside the joint limits.
    within_limits: np.ndarray
    #: (..., 16) what :func:`ik` returns with these mode arguments: inside the limits, off the
    #: forward-singularity band, reproduced by :func:`fk` in that mode.
    valid: np.ndarray


def _all_outputs(shape: tuple[int, ...]) -> tuple[np.ndarray, ...]:
    return (np.empty(shape + (16, 3)), np.empty(shape + (16, 3)), np.empty(shape + (16,), dtype=np.bool_),
            np.empty(shape + (16,), dtype=np.int64), np.empty(shape + (16,), dtype=np.bool_),
            np.empty(shape + (16,), dtype=np.bool_))


def ik_branches(target: ArrayLike, *, geometry: Geometry | None = None) -> FootIKSolutions:
    """Every closed-form foot IK branch of ``target`` with its mode and flags: the 16 branches ((ll_branch,
    roll_branch, b1, b2) in :data:`FOOT_IK_BRANCHES` order) with their platform pose, assembly mode, joint-limit
    and validity flags (the compiled :func:`._ik_kernels.ik_all_out_k` per target). :func:`ik_all` returns the
    ``motors`` and ``mask`` of this.

    Args:
        target: foot targets (..., 3) in CCS (m).
        geometry: the geometry (universal centre); None = the default.

    Returns:
        a :class:`FootIKSolutions` of arrays (..., 16[, 3]) (angles in rad). Never raises for valid input.
    """
    g = fast_geometry(geometry)
    if (type(target) is np.ndarray and target.shape == (3,) and target.dtype == np.float64 and g is not None
            and g.center == "universal"):
        out = _all_outputs(())
        if ik_all_out_k(target[0] - CX, target[1] - CY, target[2] - CZ, g.starting_value, *out):
            return FootIKSolutions(*out)
    g = resolve(geometry, universal="ik_branches")
    _, u, shape = _targets(target)
    out = _all_outputs((len(u),))
    ik_all_b(np.ascontiguousarray(u), g.starting_value, *out)
    return FootIKSolutions(*(a.reshape(shape + a.shape[1:]) for a in out))


@overload
def ik_all(target: ArrayLike, *, geometry: Geometry | None = ..., return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def ik_all(target: ArrayLike, *, geometry: Geometry | None = ...,
           return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def ik_all(target: ArrayLike, *, geometry: Geometry | None = None,
           return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """The motor angles of every closed-form foot IK branch: (..., 16, 3) in :data:`FOOT_IK_BRANCHES` order, NaN
    rows (mask False) where a branch does not exist (LL arc or motors out of reach, target on the roll axis).

    Every branch, whatever its joint limits and assembly mode; :func:`ik_branches` gives each branch's pose,
    assembly mode and limit / validity flags.

    Args:
        target: foot targets (..., 3) in CCS (m).
        geometry: the geometry (universal centre); None = the default.
        return_mask: also return the mask (..., 16) of the branches that exist.

    Returns:
        (..., 16, 3) motor angles (theta1, theta2, theta0) (rad); then the mask, if asked.

    Raises:
        UnreachableError: (single) no branch exists (out of the LL arc's or the motors' reach).
        SingularityError: (single) the target is on the roll axis, and no branch exists.
    """
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    g = fast_geometry(geometry)
    if g is None or g.center != "universal":
        g = resolve(geometry, universal="ik_all")
    return dispatch(target, "target", (3,), _all_fast, _all_batch, _all_fail, (g.starting_value,), return_mask)


def _all_fast(p: np.ndarray, args: tuple[float]) -> tuple[np.ndarray, np.ndarray] | None:
    (sv,) = args
    out = _all_outputs(())
    x, y, z = p.tolist()  # Python floats: numba dispatches them faster than numpy scalars
    if ik_all_out_k(x - CX, y - CY, z - CZ, sv, *out) and out[2].tobytes() != _NO_BRANCH:
        return out[0], out[2]
    return None


def _all_batch(rows: np.ndarray, sv: float) -> tuple[np.ndarray, np.ndarray]:
    out = _all_outputs((len(rows),))
    ik_all_b(rows - CENTER, sv, *out)
    return out[0], out[2]


def _all_fail(p: np.ndarray, out: np.ndarray, ok: np.ndarray, sv: float) -> Exception:
    return _no_branch(p)


def _no_branch(target: np.ndarray) -> Exception:
    """The error of a single :func:`ik_all` call without any branch."""
    _, arc = platform_pose(target, -1.0, 1.0)
    if arc[1] != 1.0:
        return arc_error(target)
    if not arc[2] > 0.0:
        return axis_error(target, False)
    return UnreachableError(f"foot target {fmt(target)} is out of the motors' reach on every branch", target=target)
