"""Forward kinematics of the closed sub-chain: the platform pose (roll, pitch) of motor angles (theta1, theta2),
in the assembly mode asked for (seed 003, eqs 1-16; the poses of :mod:`.polynomial`)."""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import as_angles, as_input, check_flag, check_integer, check_number, finish
from .._kernels import OK, batch_kernel, kernel
from .._rotations import wrap_k
from ..errors import ConvergenceError, InvalidInputError
from ._options import (
    SCALARS,
    ST_ASSEMBLE,
    ST_INPUT,
    Branch,
    check_assembly,
    check_branch,
    fast_branch,
    fast_sign,
    flat,
    mode_text,
    resolve,
)
from .chains import chains_k, lever_tips_k, ref_of, rot_k
from .geometry import K_TOL, Geometry
from .polynomial import MAX_SOL, rod_newton_k, solutions_k

__all__ = ["platform_orientation", "platform_poses", "PlatformPoses"]


@kernel(entry=True)
def fk_select_k(t1, t2, b1, b2, s, tol, max_iter, x):
    """The pose x (2,) of motors (t1, t2) in mode (b1, b2), s within the limits nearest R_P = I (the numpy
    ``_fk_select``). Returns _OK, ST_INPUT (non-finite motors) or ST_ASSEMBLE (x NaN)."""
    x[0] = math.nan
    x[1] = math.nan
    if not (math.isfinite(t1) and math.isfinite(t2)):
        return ST_INPUT
    xs = np.empty((MAX_SOL, 2))
    bl = np.empty((MAX_SOL, 2))
    sdet = np.empty(MAX_SOL)
    m = solutions_k(t1, t2, tol, max_iter, xs, bl, sdet)
    ref = ref_of(b1, b2)
    best = math.inf
    for j in range(m):
        if not ((bl[j, 0] == b1 or bl[j, 0] == 0.0) and (bl[j, 1] == b2 or bl[j, 1] == 0.0) and sdet[j] * ref == s):
            continue
        nrm = math.hypot(xs[j, 0], xs[j, 1])
        if nrm < best:
            best = nrm
            x[0], x[1] = xs[j, 0], xs[j, 1]
    return OK if best < math.inf else ST_ASSEMBLE


@batch_kernel(rows="t1 t2 b1 b2 s x ok", min_parallel=64)
def _fk_select_b(t1, t2, b1, b2, s, tol, max_iter, x, ok):
    for j in range(t1.shape[0]):
        ok[j] = fk_select_k(t1[j], t2[j], b1[j], b2[j], s[j], tol, max_iter, x[j]) == OK


@kernel(entry=True)
def poses_k(t1, t2, tol, max_iter, x, br, asm):
    """:func:`platform_poses` for one motor pair: every pose (nearest R_P = I first, duplicates - the same pose
    with the same sign of det N - dropped), its motor branch and assembly mode, into x (8, 2), br (8, 2),
    asm (8,) (NaN / 0 padded). Returns the number of poses."""
    x[:, :] = math.nan
    br[:, :] = 0
    asm[:] = 0
    if not (math.isfinite(t1) and math.isfinite(t2)):
        return 0
    xs = np.empty((MAX_SOL, 2))
    bl = np.empty((MAX_SOL, 2))
    sdet = np.empty(MAX_SOL)
    m = solutions_k(t1, t2, tol, max_iter, xs, bl, sdet)
    nrm = np.empty(m)
    for j in range(m):
        nrm[j] = math.hypot(xs[j, 0], xs[j, 1])
    order = np.argsort(nrm, kind="mergesort")
    sd = np.zeros(8)
    cnt = 0
    for c in order:
        if cnt >= 8:
            break
        dup = False
        for q in range(cnt):
            if max(abs(x[q, 0] - xs[c, 0]), abs(x[q, 1] - xs[c, 1])) <= 1e-9 and sd[q] == sdet[c]:
                dup = True
                break
        if dup:
            continue
        x[cnt, 0], x[cnt, 1] = xs[c, 0], xs[c, 1]
        sd[cnt] = sdet[c]
        br[cnt, 0], br[cnt, 1] = int(bl[c, 0]), int(bl[c, 1])
        asm[cnt] = int(sdet[c] * ref_of(1.0 if bl[c, 0] == 0.0 else bl[c, 0], 1.0 if bl[c, 1] == 0.0 else bl[c, 1]))
        cnt += 1
    return cnt


@batch_kernel(rows="t1 t2 x br asm", min_parallel=64)
def _poses_b(t1, t2, tol, max_iter, x, br, asm):
    for j in range(t1.shape[0]):
        poses_k(t1[j], t2[j], tol, max_iter, x[j], br[j], asm[j])


@kernel
def fk_guess_k(t1, t2, g0, g1, b1, b2, tol, max_iter, x):
    """:func:`platform_orientation` from a guess: plain Newton from (g0, g1), then the pose must close both rods
    within tol and give back the motors (t1, t2) on branch (b1, b2). Returns _OK or ST_ASSEMBLE (x NaN)."""
    tip, dtip = lever_tips_k(t1, t2)
    x[0], x[1] = g0, g1
    err = rod_newton_k(x, tip, max_iter, False)
    x[0], x[1] = wrap_k(x[0]), wrap_k(x[1])
    ok = err <= tol
    if ok:
        rot = np.empty((3, 3))
        rot_k(x[0], x[1], rot)
        th = np.empty(2)
        kk = np.empty(2)
        ok = chains_k(rot, b1, b2, K_TOL, th, kk) == OK
        ok = ok and max(abs(wrap_k(th[0] - t1)), abs(wrap_k(th[1] - t2))) <= 1e-6
    if ok:
        return OK
    x[0], x[1] = math.nan, math.nan
    return ST_ASSEMBLE


@batch_kernel(rows="t1 t2 g x ok", min_parallel=64)
def _fk_guess_b(t1, t2, g, b1, b2, tol, max_iter, x, ok):
    for j in range(t1.shape[0]):
        ok[j] = fk_guess_k(t1[j], t2[j], g[j, 0], g[j, 1], b1, b2, tol, max_iter, x[j]) == OK


# ----------------------------------------------------------------------------- wrappers
class PlatformPoses(NamedTuple):
    """Every platform pose of :func:`platform_poses`, nearest R_P = I first (NaN / 0 padded to 8)."""

    #: (..., 8, 2) (roll, pitch), NaN where there is no further pose.
    x: np.ndarray
    #: (..., 8, 2) motor branch of each chain: +1, -1, or 0 on the chain's reach boundary (both branches).
    branch: np.ndarray
    #: (..., 8) assembly mode on that branch (+1: as at R_P = I); for a boundary chain, that of branch +1.
    assembly: np.ndarray
    #: (..., 8) True where there is a pose.
    mask: np.ndarray


def platform_poses(theta1: ArrayLike, theta2: ArrayLike, *, tol: float = 1e-12, max_iter: int = 50,
                   geometry: Geometry | None = None) -> PlatformPoses:
    """Every platform pose within the joint limits for motor angles (theta1, theta2), with its mode.

    The forward kinematics of the closed sub-chain in closed form (see :func:`platform_orientation`): the real
    roots of a degree-8 polynomial in tan(roll / 2), the pitch of each from the two (linear in cos, sin) rod
    equations, polished by Newton's method. All modes, nearest R_P = I first. Never raises for valid input (a
    single input gives arrays of shape (8, ...)).

    Args:
        theta1, theta2: motor angles (rad), broadcast together.
        tol: rod-length residual (m), in (0, 1e-6].
        max_iter: Newton iterations, in [1, 10000].
        geometry: the geometry (universal centre); None = the default.

    Returns:
        a :class:`PlatformPoses` (angles in rad).
    """
    if (type(theta1) in SCALARS and type(theta2) in SCALARS and geometry is None and type(tol) is float
            and 0.0 < tol <= 1e-6 and type(max_iter) is int and 1 <= max_iter <= 10_000):
        x, bran, asm = np.empty((8, 2)), np.empty((8, 2), dtype=np.int64), np.empty(8, dtype=np.int64)
        poses_k(theta1, theta2, tol, max_iter, x, bran, asm)
        return PlatformPoses(x, bran, asm, np.isfinite(x[:, 0]))
    resolve(geometry, universal="platform_poses")
    t1, t2 = as_angles(theta1, theta2, names=("theta1", "theta2"))
    tol = check_number(tol, "tol", 0.0, 1e-6, low_open=True)
    max_iter = check_integer(max_iter, "max_iter", 1, 10_000)
    shape = t1.shape
    n = t1.size
    x = np.empty((n, 8, 2))
    bran = np.empty((n, 8, 2), dtype=np.int64)
    asm = np.empty((n, 8), dtype=np.int64)
    _poses_b(flat(t1), flat(t2), tol, max_iter, x, bran, asm)
    mask = np.isfinite(x[..., 0])
    return PlatformPoses(x.reshape(shape + (8, 2)), bran.reshape(shape + (8, 2)), asm.reshape(shape + (8,)),
                         mask.reshape(shape + (8,)))


def fk_failure(t1: float, t2: float, b: np.ndarray, s: float, guessed: bool = False) -> str:
    """Why the closed sub-chain did not assemble for motors (t1, t2) in mode (b, s): the modes in which it does."""
    what = f"(theta1, theta2) = ({t1:.17g}, {t2:.17g})"
    if guessed:
        return (f"platform_orientation: Newton from q_start did not close both rods for {what} on branch "
                f"({int(b[0])}, {int(b[1])}) within the joint limits")
    poses = platform_poses(t1, t2)
    found = [f"({pose[0]:.6g}, {pose[1]:.6g}) on branch ({br[0]}, {br[1]}) in assembly mode {a:+d}"
             for pose, br, a, m in zip(poses.x, poses.branch, poses.assembly, poses.mask) if m]
    return (f"the closed sub-chain does not assemble for {what} in mode {mode_text(b, s)} within the joint limits "
            f"(|roll|, |pitch| <= pi/2); " + ("it does at (roll, pitch) = " + "; ".join(found) if found
                                              else "it assembles nowhere within the limits"))


@overload
def platform_orientation(theta1: ArrayLike, theta2: ArrayLike, branch: Branch = ..., *, assembly: int = ...,
                         q_start: ArrayLike | None = ..., tol: float = ..., max_iter: int = ...,
                         geometry: Geometry | None = ..., return_mask: Literal[False] = ...) -> np.ndarray: ...
@overload
def platform_orientation(theta1: ArrayLike, theta2: ArrayLike, branch: Branch = ..., *, assembly: int = ...,
                         q_start: ArrayLike | None = ..., tol: float = ..., max_iter: int = ...,
                         geometry: Geometry | None = ...,
                         return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def platform_orientation(
    theta1: ArrayLike,
    theta2: ArrayLike,
    branch: Branch = (1, 1),
    *,
    assembly: int = 1,
    q_start: ArrayLike | None = None,
    tol: float = 1e-12,
    max_iter: int = 50,
    geometry: Geometry | None = None,
    return_mask: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """(roll, pitch) (..., 2) of the universal-centre platform for motor angles (theta1, theta2).

    Forward kinematics of the closed sub-chain (seed eqs 1-16 with both motors given), in closed form: with
    the lever tips known, rod i closes iff ``w_i . R_P a_i = kappa_i`` (``w_i = c - S_i``), which is linear in
    (cos pitch, sin pitch); eliminating the pitch leaves a polynomial of degree 8 in tan(roll / 2). Its real
    roots with |roll| <= pi/2 give every pose within the joint limits (:func:`platform_poses`), each polished by
    Newton's method on the rod equations (with the forward-singularity barrier near det N = 0). The answer is
    the pose on motor branch ``branch`` in assembly mode ``assembly`` (:func:`assembly_mode`); if that mode
    holds several poses, the one nearest R_P = I. The defaults (branch (1, 1), mode +1) are the mode the
    mechanism is built in (SRDF ``neutral``); there the motor map is one-to-one over the pitches below
    :data:`PITCH_SPLIT`, and the region of the same sign beyond it (pitch >= 1.48 rad) is only used when the
    motors reach no pose below it. Near the forward singularity (det N = 0, where the platform could move with
    the motors locked) the solution is ill-conditioned: error ~ 1e-16 / sigma_min(dtheta/dx).

    Args:
        theta1, theta2: motor angles (rad), broadcast together.
        branch: the motor branch pair (b1, b2) the solution must lie on (a chain on its reach boundary lies on
            both).
        assembly: +1 (default) or -1, see :func:`assembly_mode`.
        q_start: starting (roll, pitch) (..., 2): plain Newton from it instead (the pose it reaches on
            ``branch``, whatever its assembly mode).
        tol: required rod-length residual | |A_i - S_i| - L | (m), in (0, 1e-6].
        max_iter: Newton iterations, in [1, 10000].
        geometry: must have the universal centre (None: the default geometry).

    Returns:
        (..., 2) (roll, pitch) (rad), NaN where a batch item fails; then the mask, if asked.

    Raises:
        ConvergenceError: single input whose closed sub-chain does not assemble in that mode within the joint
            limits (the message lists the modes in which it does).
    """
    if (return_mask is False and q_start is None and geometry is None
            and type(theta1) in SCALARS and type(theta2) in SCALARS
            and type(tol) is float and 0.0 < tol <= 1e-6
            and type(max_iter) is int and 1 <= max_iter <= 10_000):
        fb, fs = fast_branch(branch), fast_sign(assembly)
        if fb is not None and fs is not None:
            x = np.empty(2)
            if fk_select_k(theta1, theta2, fb[0], fb[1], fs, tol, max_iter, x) == OK:
                return x
    resolve(geometry, universal="platform_orientation")
    t1, t2 = as_angles(theta1, theta2, names=("theta1", "theta2"))
    b = check_branch(branch)
    s = check_assembly(assembly)
    tol = check_number(tol, "tol", 0.0, 1e-6, low_open=True)
    max_iter = check_integer(max_iter, "max_iter", 1, 10_000)
    check_flag(return_mask, "return_mask")
    shape = t1.shape
    n = t1.size
    x = np.empty((n, 2))
    ok = np.empty(n, dtype=np.bool_)
    if q_start is not None:
        g = as_input(q_start, "q_start", (2,))
        try:
            g = np.broadcast_to(g, shape + (2,)).reshape(-1, 2)
        except ValueError:
            raise InvalidInputError(f"q_start must broadcast to shape {shape + (2,)}, got shape {g.shape}") from None
        _fk_guess_b(flat(t1), flat(t2), np.array(g, dtype=np.float64), float(b[0]),
                                         float(b[1]), tol, max_iter, x, ok)
    else:
        b1, b2, ss = np.full(n, b[0]), np.full(n, b[1]), np.full(n, s)
        _fk_select_b(flat(t1), flat(t2), b1, b2, ss, tol, max_iter, x, ok)
    guessed = q_start is not None
    return finish(np.where(ok[:, None], x, np.nan).reshape(shape + (2,)), ok.reshape(shape), t1.ndim == 0, return_mask,
                  lambda: ConvergenceError(fk_failure(float(t1), float(t2), b, s, guessed)))
