"""Forward kinematics of the tripod: the platform orientation from the motor angles (the public wrapper over
:mod:`legkin.tripod.forward_kernels`, and the diagnosis of a failed single call)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, Sequence, overload

import numpy as np
from numpy.typing import ArrayLike

from .._batch import check_integer, check_number, dispatch
from .._kernels import OK
from ..errors import AssemblyModeError, ConvergenceError, SingularityError, UnreachableError
from ._common import (
    DET_GUARD,
    GAIN_GUARD,
    HOME_MODE,
    MODE_ARGS,
    MODES,
    ST_GAIN,
    ST_LEFT,
    ST_NOT_CONVERGED,
    ST_OUTSIDE,
    ST_SINGULAR_PLANES,
    checked_mode,
    flag,
    geometry_of,
    modes_sel,
)
from .forward_kernels import FK_LOOP, _k_fk, _k_initial_guess
from .geometry import Geometry
from .inverse import ik_one, ik_single_error

__all__ = ["fk", "FKInfo"]


@dataclass(frozen=True)
class FKInfo:
    """What :func:`fk` measured besides the pose (``return_info=True``).

    Attributes:
        inconsistency: (batch shape, or () for a single call; mode="all": (..., 16)) the distance (rad) of the
            motors from the consistent set at the reported pose, to first order (NaN where an item failed).
    """

    inconsistency: np.ndarray


def _fk_one(qa: float, qb: float, qc: float, G: np.ndarray, mode: str, tol: float, max_iter: int,
            max_inc: float) -> tuple[np.ndarray, int]:
    """The fk kernel on one motor triple in one mode: (alpha_y, alpha_z, inconsistency) (raw, also on failure),
    status."""
    home, e, s = MODE_ARGS[mode]
    out = np.empty(3)
    return out, _k_fk(qa, qb, qc, G, home, e, s, tol, max_iter, max_inc, out)


def _motor_mode(qm: np.ndarray, g: Geometry) -> str | None:
    """The assembly mode of motors (3,) read off their planes: E = d (1 - c_alpha) M^-1 (1, 1, 1) (None if M is
    singular): the side of E_x, and per leg the sign of sin q_K2 sin(alpha) = c_K1 h1 + s_K1 h2 with
    (h1, h2) = (-x, -(c_K y + s_K z)) / d (the leg's position equations, eq 101)."""
    s, c = np.sin(qm), np.cos(qm)
    ce, se = np.cos(np.asarray(g.eta)), np.sin(np.asarray(g.eta))
    m = np.stack([s, -c * ce, -c * se], axis=-1)
    try:
        e = np.linalg.solve(m, np.full(3, g.d * (1.0 - math.cos(g.alpha))))
    except np.linalg.LinAlgError:
        return None
    s2 = c * (-e[0] / g.d) + s * (-(ce * e[1] + se * e[2]) / g.d)
    return ("-" if e[0] < 0 else "+") + "".join("-" if v < 0 else "+" for v in s2)


def _motors_text(qs: Sequence[float]) -> str:
    return f"(q_A1, q_B1, q_C1) = ({qs[0]:.17g}, {qs[1]:.17g}, {qs[2]:.17g})"


def _fk_error(qs: Sequence[float], out: np.ndarray, status: int, mode: str, others: list[str], max_iter: int,
              max_inconsistency: float, g: Geometry) -> Exception:
    """The exception of a failed single :func:`fk` call (``out``, ``status``: the kernel's)."""
    motors = _motors_text(qs)
    ay, az, inconsistency = (float(v) for v in out)
    target = np.array(qs, dtype=float)
    if others:
        return AssemblyModeError(
            f"{motors} are consistent only in assembly mode(s) {', '.join(others)}, not in mode {mode}",
            target=target, modes=[{"mode": m} for m in others],
        )
    if status == ST_SINGULAR_PLANES:
        return SingularityError(
            f"{motors} are an actuation singularity: their planes have |det M| < DET_GUARD = {DET_GUARD:g} "
            "(nearly sharing a line): the motor angles do not determine the pose"
        )
    if status == ST_LEFT:  # diagnose at the planes' intersection (the start), as ik would there
        G = g._vector
        y0, z0, _ = _k_initial_guess(float(qs[0]), float(qs[1]), float(qs[2]), G)
        _, aux, st = ik_one(y0, z0, G, mode)
        if st != OK:
            exc = ik_single_error(np.float64(y0), np.float64(z0), G, mode, aux)
            exc.args = (f"{motors}: no pose found; their planes meet at {exc}",)  # keeps its data attributes
            return exc
        return UnreachableError(f"{motors}: the solver left the workspace; no pose was found", target=target)
    if status == ST_NOT_CONVERGED:
        return ConvergenceError(f"{motors}: Gauss-Newton did not converge in {max_iter} iterations (singular A_u?)")
    if status == ST_GAIN:
        return SingularityError(
            f"{motors}: at the pose (alpha_y, alpha_z) = ({ay:.17g}, {az:.17g}) the motors are too sensitive to the "
            f"orientation (|A_u| > GAIN_GUARD = {GAIN_GUARD:g}: a leg next to its boundary near the flip)"
        )
    if status == ST_OUTSIDE:
        return SingularityError(
            f"{motors}: the pose (alpha_y, alpha_z) = ({ay:.17g}, {az:.17g}) is on the workspace boundary or the "
            "platform singularity, where ik is undefined"
        )
    return UnreachableError(
        f"{motors} are inconsistent: no pose produces all three; the least-squares pose "
        f"(alpha_y, alpha_z) = ({ay:.17g}, {az:.17g}) misses them by {inconsistency:.3e} rad "
        f"(max_inconsistency = {max_inconsistency:.1e})",
        target=target,
        closest=np.array([ay, az]),
        distance=inconsistency,
    )


_SOLVED = np.asarray(True)  # the mask of a solved single call (read-only, shared)
_SOLVED.setflags(write=False)


def _fk_fast(qm: np.ndarray, args: tuple[Geometry, str, float, int, float]) -> tuple[np.ndarray, np.ndarray] | None:
    """One motor triple straight to the kernel: (alpha_y, alpha_z, inconsistency), True; None unless solved (and
    for ``mode="all"``, which the batch loop solves); ``args`` = (g, mode, tol, max_iter, max_inc)."""
    g, mode, tol, max_iter, max_inc = args
    if mode == "all":
        return None
    qa, qb, qc = qm.tolist()  # Python floats: numba dispatches them faster than numpy scalars
    out, st = _fk_one(qa, qb, qc, g._vector, mode, tol, max_iter, max_inc)
    return (out, _SOLVED) if st == OK else None


def _fk_batch(rows: np.ndarray, g: Geometry, mode: str, tol: float, max_iter: int,
              max_inc: float) -> tuple[np.ndarray, np.ndarray]:
    """The fk loop on motor rows (n, 3): out (n, [16,] 3) NaN where an item fails, ok (n, [16])."""
    homes, es, ss = modes_sel(mode)
    n, m = rows.shape[0], homes.shape[0]
    out, status = np.empty((n, m, 3)), np.empty((n, m), dtype=np.int64)
    FK_LOOP(rows, g._vector, homes, es, ss, tol, max_iter, max_inc, out, status)
    if mode == "all":
        return out, status == OK
    return out[:, 0], status[:, 0] == OK


def _fk_orientation_batch(rows: np.ndarray, g: Geometry, mode: str, tol: float, max_iter: int,
                          max_inc: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_fk_batch` without the inconsistency column: (alpha_y, alpha_z) only, so that a large batch, run by
    chunks, keeps no array of n items beyond its answer."""
    out, ok = _fk_batch(rows, g, mode, tol, max_iter, max_inc)
    return np.ascontiguousarray(out[..., :2]), ok


def _fk_fail(qm: np.ndarray, out: np.ndarray, ok: np.ndarray, g: Geometry, mode: str, tol: float, max_iter: int,
             max_inc: float) -> Exception:
    """The exception of a failed single :func:`fk` call (``mode="all"``: diagnosed in the home mode)."""
    qs = (float(qm[0]), float(qm[1]), float(qm[2]))
    m = HOME_MODE if mode == "all" else mode
    G = g._vector
    raw, st = _fk_one(*qs, G, m, tol, max_iter, max_inc)
    others = []
    if mode != "all" and st != ST_SINGULAR_PLANES:  # consistent motors fit the mode of their planes' E
        likely = _motor_mode(np.array(qs), g)
        for other in [likely] if likely else MODES:
            if other != mode and _fk_one(*qs, G, other, tol, max_iter, max_inc)[1] == OK:
                others.append(other)
                break
    return _fk_error(qs, raw, st, m, others, max_iter, max_inc, g)


def _options(mode: Any, tol: Any, max_iter: Any, max_inc: Any) -> tuple[str, float, int, float]:
    mode = checked_mode(mode, allow_all=True)
    if type(tol) is not float or not 0.0 <= tol <= 0.1:
        tol = check_number(tol, "tol", 0.0, 0.1)
    if type(max_iter) is not int or not 1 <= max_iter <= 10000:
        max_iter = check_integer(max_iter, "max_iter", 1, 10000)
    if type(max_inc) is not float or not 0.0 <= max_inc <= math.inf:
        if isinstance(max_inc, (float, np.floating)) and max_inc == math.inf:
            max_inc = math.inf
        else:
            max_inc = check_number(max_inc, "max_inconsistency", 0.0, None)
    return mode, tol, max_iter, max_inc


def _finish(out: np.ndarray, ok: np.ndarray, return_mask: bool, return_info: bool) -> Any:
    u = np.ascontiguousarray(out[..., :2])
    res: tuple[Any, ...] = (u,)
    if return_mask:
        res += (ok,)
    if return_info:
        inc = out[..., 2]
        res += (FKInfo(inconsistency=inc if inc.ndim else np.float64(inc)),)
    return res if len(res) > 1 else u


@overload
def fk(q: ArrayLike, *, mode: str = ..., geometry: Geometry | None = ..., tol: float = ..., max_iter: int = ...,
       max_inconsistency: float = ..., return_mask: Literal[False] = ...,
       return_info: Literal[False] = ...) -> np.ndarray: ...
@overload
def fk(q: ArrayLike, *, mode: str = ..., geometry: Geometry | None = ..., tol: float = ..., max_iter: int = ...,
       max_inconsistency: float = ..., return_mask: Literal[True],
       return_info: Literal[False] = ...) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def fk(q: ArrayLike, *, mode: str = ..., geometry: Geometry | None = ..., tol: float = ..., max_iter: int = ...,
       max_inconsistency: float = ..., return_mask: Literal[False] = ...,
       return_info: Literal[True]) -> tuple[np.ndarray, FKInfo]: ...
@overload
def fk(q: ArrayLike, *, mode: str = ..., geometry: Geometry | None = ..., tol: float = ..., max_iter: int = ...,
       max_inconsistency: float = ..., return_mask: Literal[True],
       return_info: Literal[True]) -> tuple[np.ndarray, np.ndarray, FKInfo]: ...
def fk(q: ArrayLike, *, mode: str = HOME_MODE, geometry: Geometry | None = None, tol: float = 1e-13,
       max_iter: int = 30, max_inconsistency: float = 1e-9, return_mask: bool = False,
       return_info: bool = False) -> Any:
    """Platform orientation (alpha_y, alpha_z) from the motor angles ``q = (q_A1, q_B1, q_C1)``: Gauss-Newton on
    :func:`ik` with :func:`jacobian`.

    Solves ``min_u |wrap(ik(u) - q)|`` over u = (alpha_y, alpha_z) (three equations, two unknowns):
    ``u <- u - pinv(A_u) r`` (the 3 x 2 least-squares step in closed form, see
    :mod:`legkin.tripod.forward_kernels`), from the closed-form start at the motor planes' intersection (not
    in the seed), until the step (or its image ``A_u du`` in the motors) is below ``tol``; from consistent motors
    the start is already exact to rounding and one iteration confirms it. The iterates are kept inside the
    workspace (a step that leaves it is halved). The result is reported with ``alpha_y`` in [-pi/2, pi/2]
    (``(pi - alpha_y, alpha_z + pi)`` is the same orientation) and ``alpha_z`` in (-pi, pi]. There is no
    ``q_start``: the closed-form start is exact for consistent motors, so no user start could do better.

    Assembly mode: the motors are those of :func:`ik` in ``mode`` (default :data:`HOME_MODE`, the mode the
    mechanism is built in). Motors from another mode are not consistent with any pose of this one: unsolved
    (batch: NaN, mask False; single call: ``AssemblyModeError`` naming the mode(s) in which they are consistent,
    in ``.modes`` as ``[{"mode": ...}]``). ``mode="all"`` solves in every mode: (..., 16, 2) in :data:`MODES`
    order, NaN where the motors do not fit that mode.

    Redundant actuation: three motor angles produced by no pose are not averaged silently. The inconsistency
    (rad, ``return_info=True``: :class:`FKInfo`) is the distance of the motors from the consistent set, to first
    order: the residual ``r`` at the reported pose less its projection on the range of A_u. Above
    ``max_inconsistency`` the call fails (single: ``UnreachableError`` carrying the least-squares pose in
    ``closest``; batch: NaN). Pass ``max_inconsistency=np.inf`` to get least-squares poses for noisy readings.

    Actuation singularity: motors whose planes have ``|det M| < DET_GUARD`` are refused (they fit two poses,
    or fix the pose only to ~2e-16 / |det M| rad); :func:`ik` refuses the same poses, so every pose ik returns
    is reproduced by fk and every pose fk returns is solved by ik.

    Args:
        q: motor angles (..., 3) = (q_A1, q_B1, q_C1) (rad).
        mode: assembly mode, one of :data:`MODES` or ``"all"``.
        geometry: the tripod's :class:`Geometry` (None: the default).
        tol: step-size tolerance (rad), in [0, 0.1]. max_iter: iteration cap, an integer in [1, 10000].
        max_inconsistency: largest accepted inconsistency (rad), in [0, inf].
        return_mask: (batch) also return the success mask. return_info: also return an :class:`FKInfo`.

    Returns:
        (..., 2) orientations (alpha_y, alpha_z); then the mask and the info, as asked.

    Raises:
        AssemblyModeError: (single) the motors are consistent only in other assembly modes.
        UnreachableError: (single) the motor angles are inconsistent beyond ``max_inconsistency`` (in every
            mode), or the iterate left the workspace.
        SingularityError: (single) an actuation singularity (``|det M| < DET_GUARD``), or the solution is on
            the workspace boundary (where :func:`ik` fails).
        ConvergenceError: (single) no convergence within ``max_iter``.
        InvalidInputError: non-finite, complex or wrongly shaped motors; InvalidParameterError: bad geometry,
            mode, tol, max_iter, max_inconsistency, return_mask or return_info.
    """
    mode, tol, max_iter, max_inc = _options(mode, tol, max_iter, max_inconsistency)
    return_mask = flag(return_mask, "return_mask")
    return_info = flag(return_info, "return_info")
    g = geometry_of(geometry)
    batch = _fk_batch if return_info else _fk_orientation_batch
    out, ok = dispatch(q, "q", (3,), _fk_fast, batch, _fk_fail, (g, mode, tol, max_iter, max_inc), True)
    if not return_mask and not return_info:  # the common call: the orientation only
        return np.ascontiguousarray(out[..., :2])
    return _finish(out, ok, return_mask, return_info)
