"""Inverse kinematics of the rim contact point: :func:`ik` (the default answer), :func:`ik_all` (every solution).

Methods (``method=``):

* ``"radial"`` (default): gamma and beta in closed form, theta from the 1-D equation ``|c(theta, alpha)| = r``
  by a bracketed Newton (:mod:`legkin.wheel_leg.ik_radial`); every solution is found.
* ``"damped"``: Gauss-Newton on the 3x3 system with the analytic Jacobian and Levenberg-Marquardt damping.
* ``"gauss_newton_fd"``: seed 2.2-2.3 as printed, forward-difference Jacobian, full
  steps (the baseline). Both iterative methods are in :mod:`legkin.wheel_leg.ik_iterative`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Literal, NamedTuple, overload

import numpy as np
from numpy.typing import ArrayLike

from .. import _batch
from .._batch import as_input, check_choice, check_flag, check_integer, check_number, finish, in_chunks
from ..errors import InvalidInputError, InvalidParameterError, UnreachableError
from . import ik_iterative
from ._common import _LIMITS, _SCALARS, _SOLVED, Leg, Rim, _check_alpha, _check_theta, _check_w, rim_name
from .frames import _context, _fk, _kctx_cached
from .geometry import (
    _DEFAULT_GEOMETRY,
    _LIMIT_ROUNDING,
    ABAD_LIMIT,
    THETA_MAX,
    THETA_MIN,
    Geometry,
    _geometry,
    _leg,
    abad_limit_error,
)
from .ik_radial import _NO_Q0, _RADIAL_SOLS, _ik_radial, _k_ik_radial, _radial_table
from .rim import _k_select

Method = Literal["radial", "damped", "gauss_newton_fd"]
METHODS = ("radial", "damped", "gauss_newton_fd")


@dataclass(frozen=True)
class IKOptions:
    """Solver tuning of :func:`ik` and :func:`ik_all` (validated on construction).

    Attributes:
        tol: position tolerance (m), in (0, 1e-3]: solved means ``|fk(q) - target| <= tol``.
        max_iter: iteration bound, an integer in [1, 100000]; None: the method's default (radial: 60 Newton
            steps per root; damped: 60 per start; gauss_newton_fd: 100 per start).
        delta: forward-difference step (rad) of ``method="gauss_newton_fd"``, in (0, 0.1].
    """

    tol: float = 1e-12
    max_iter: int | None = None
    delta: float = 1e-6

    def __post_init__(self) -> None:
        object.__setattr__(self, "tol", check_number(self.tol, "tol", 0.0, 1e-3, low_open=True))
        if self.max_iter is not None:
            object.__setattr__(self, "max_iter", check_integer(self.max_iter, "max_iter", 1, 100_000))
        object.__setattr__(self, "delta", check_number(self.delta, "delta", 0.0, 0.1, low_open=True))


_DEFAULT_OPTIONS = IKOptions()


class IKInfo(NamedTuple):
    """What :func:`ik` did, per target (arrays of the batch shape).

    Attributes:
        iterations: iterations used, restarts included (radial: Newton and bracketing steps summed over the
            target's roots).
        error: final position error ``|fk(q) - target|`` (m).
        solutions: ``method="radial"`` only (else None): (..., S, 3), every solution found, NaN-padded: the
            branch ``y_L <= 0`` by increasing theta, then the branch ``y_L > 0`` (as :func:`ik_all`).
        evaluations: linkage evaluations per target: rows of the contact FK (with or without its Jacobian)
            for the iterative methods; radial: evaluations of the leg-plane closed form with its
            theta-derivative (Newton and extremum steps) plus the final contact FK that checks the answer
            (the grid and start tables are not counted).
    """

    iterations: np.ndarray
    error: np.ndarray
    solutions: np.ndarray | None = None
    evaluations: np.ndarray | None = None


def _options(options: object) -> IKOptions:
    if options is None:
        return _DEFAULT_OPTIONS
    if not isinstance(options, IKOptions):
        raise InvalidParameterError(f"options must be a wheel_leg.IKOptions, got {type(options).__name__}")
    return options


# ---------------------------------------------------------------- single-target fast paths
@lru_cache(maxsize=64, typed=True)  # typed: leg=1 must not admit leg=True or 1.0 (issue 25)
def _single_ctx(leg, rim, radius, geo: Geometry, method: str):
    """The contact kernels' constants and the method's tables for one keyword set (validated)."""
    kc = _kctx_cached(leg, rim, radius, geo)
    if method == "radial":
        return kc, _radial_table(geo.R, kc[0])
    return kc, ik_iterative.guess_table(geo.R, kc[0])


def _single(target, alpha, w, leg, rim, radius, geo, method, opts, return_mask, return_info, limits=True,
            q0=None):
    """One target (numbers and float64 (3,) arrays): the method's kernel called directly; ``q0``: q_near
    (radial) or the start (iterative methods). None (the general path then decides, and raises) unless
    solved."""
    if not (abs(alpha) <= math.pi + 1e-12 and abs(w) <= geo.T / 2 + 1e-15):
        return None
    if q0 is not None and not (THETA_MIN - 1e-12 <= q0[0] <= THETA_MAX + 1e-12 and math.isfinite(q0[1])
                               and math.isfinite(q0[2])):
        return None
    try:
        kc, tables = _single_ctx(leg, rim, radius, geo, method)
    except Exception:  # noqa: BLE001 - the general path raises the documented error
        return None
    seed, rho, K, KC, s, dwheel, _half_T, o0, o1, o2 = kc
    upper, right, e = _k_select(alpha, seed, rho, K[0])
    q = np.empty(3)
    a = dwheel + s * w
    sols = None
    if method == "radial":
        max_iter = 60 if opts.max_iter is None else opts.max_iter
        sols = np.empty((_RADIAL_SOLS, 3))
        q_near = _NO_Q0[0] if q0 is None else q0
        its, err, reason, _nr, nsol = _k_ik_radial(target, upper, right, e, a, seed, K, KC, s, o0, o1, o2, *tables,
                                                   opts.tol, max_iter, q_near, q0 is not None, limits, q, sols)
        ev = its + 1
        if reason == _SOLVED and return_info and nsol > _RADIAL_SOLS:
            sols = np.empty((nsol, 3))
            _k_ik_radial(target, upper, right, e, a, seed, K, KC, s, o0, o1, o2, *tables, opts.tol, max_iter,
                         q_near, q0 is not None, limits, np.empty(3), sols)
        sols = sols[:nsol]
    else:
        max_iter = ik_iterative.DEFAULT_MAX_ITER[method] if opts.max_iter is None else opts.max_iter
        its, err, reason, ev = ik_iterative._k_ik_iterative(
            target, upper, right, e, a, seed, K, KC, s, o0, o1, o2, *tables, ik_iterative.METHOD_IDS[method],
            ik_iterative._STARTS[method], opts.tol, max_iter, opts.delta,
            ik_iterative._NO_START[0] if q0 is None else q0, q0 is not None, limits, q)
    if reason != _SOLVED:
        return None
    out = (q, np.array(True)) if return_mask else q
    if not return_info:
        return out
    info = IKInfo(np.array(its), np.array(err), sols, np.array(ev))
    return (*out, info) if return_mask else (out, info)


# ---------------------------------------------------------------- the general path
class _Run(NamedTuple):
    q: np.ndarray  # (..., 3), NaN where not solved
    ok: np.ndarray
    reason: np.ndarray
    info: IKInfo
    target: np.ndarray
    closest: np.ndarray | None  # single unsolved target: the point reached


def _broadcast(target, alpha, w, q_near, q_start):
    """Inputs checked and broadcast together: (target, alpha, w, q_near, q_start, shape)."""
    target = as_input(target, "target", (3,))
    alpha, w = as_input(alpha, "alpha"), as_input(w, "w")
    q_near = None if q_near is None else as_input(q_near, "q_near", (3,))
    q_start = None if q_start is None else as_input(q_start, "q_start", (3,))
    extra = [x for x in (q_near, q_start) if x is not None]
    try:
        shape = np.broadcast_shapes(target.shape[:-1], alpha.shape, w.shape, *(x.shape[:-1] for x in extra))
    except ValueError as exc:
        names = f"target{target.shape}, alpha{alpha.shape}, w{w.shape}" + "".join(
            f", {n}{x.shape}" for n, x in (("q_near", q_near), ("q_start", q_start)) if x is not None)
        raise InvalidInputError(f"inputs do not broadcast together: {names}") from exc
    n = int(np.prod(shape, dtype=int))

    def rows(x, name):
        if x is None:
            return None
        x = np.array(np.broadcast_to(x, shape + (3,)), dtype=float)
        _check_theta(x[..., 0], f"theta ({name}[..., 0])")
        return x.reshape(n, 3)

    target = np.broadcast_to(target, shape + (3,)).astype(float)
    alpha, w = np.broadcast_to(alpha, shape).astype(float), np.broadcast_to(w, shape).astype(float)
    return target, alpha, w, rows(q_near, "q_near"), rows(q_start, "q_start"), shape


def _run(target, alpha, w, leg, q_near, q_start, method, rim, radius, limits, opts, geo, all_solutions=False):
    limits = check_flag(limits, "limits")
    target, alpha, w, q_near, q_start, shape = _broadcast(target, alpha, w, q_near, q_start)
    _check_alpha(alpha)
    _check_w(w, geo)
    check_choice(method, "method", METHODS)
    _leg(leg)
    if method == "radial" and q_start is not None:
        raise InvalidParameterError("q_start is the start of an iteration (methods 'damped', 'gauss_newton_fd'); "
                                    "the radial method takes q_near (the configuration to stay near)")
    n = int(np.prod(shape, dtype=int))
    ctx = _context(alpha.reshape(n), w.reshape(n), leg, rim, geo, radius)  # validated once
    flat = target.reshape(n, 3)
    solutions = None
    if method == "radial":
        q, it, err, ok, solutions, reason = _ik_radial(flat, ctx, opts.tol, opts.max_iter, q_near, limits)
        solutions = solutions.reshape(shape + solutions.shape[1:])
        ev = it + 1
    else:
        start = q_start if q_start is not None else q_near
        q, it, err, ok, reason, ev = ik_iterative.solve(flat, ctx, start, method, opts.tol, opts.max_iter,
                                                        opts.delta, limits)
    q = q.reshape(shape + (3,))
    it, err, ok, reason, ev = (x.reshape(shape) for x in (it, err, ok, reason, ev))
    closest = None
    if shape == () and not bool(ok) and not all_solutions:
        with np.errstate(invalid="ignore"):
            qc = q.copy()
            qc[0] = np.clip(qc[0], THETA_MIN, THETA_MAX)
            closest = _fk(qc, ctx.take(0), False)[0] if np.all(np.isfinite(qc)) else None
    q_out = np.where(ok[..., None], q, np.nan)
    return _Run(q_out, ok, reason, IKInfo(it, err, solutions, ev), target, closest), q


def _error(run: _Run, q_raw, leg, alpha, w, method, tol) -> Exception:
    target = np.asarray(run.target).reshape(3)
    where = f"target {target.tolist()} for leg {leg!r} (alpha={float(alpha)!r}, w={float(w)!r})"
    if int(run.reason) == _LIMITS:
        return abad_limit_error(
            f"{where} is reachable only with the ABAD angle outside its limits [-pi/2, pi/2] "
            f"(gamma={float(q_raw[2]):.6g} rad); pass limits=False to accept it",
            leg, target, float(q_raw[2]), run.closest,
        )
    closest = run.closest
    distance = math.nan if closest is None else float(np.linalg.norm(closest - target))
    return UnreachableError(
        f"{where} not reached with method {method!r}: final error {float(run.info.error):.3e} m after "
        f"{int(run.info.iterations)} iterations (tolerance {tol:.1e} m, theta in [17, 160] deg); closest point "
        f"reached {None if closest is None else closest.tolist()} ({distance:.3g} m away)",
        target=target, closest=closest, distance=distance,
    )


# ---------------------------------------------------------------- public
@overload
def ik(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, q_near: ArrayLike | None = None,
       q_start: ArrayLike | None = None, method: Method = "radial", rim: Rim = "continuous",
       radius: float | None = None, limits: bool = True, options: IKOptions | None = None,
       geometry: Geometry | None = None, return_mask: Literal[False] = False,
       return_info: Literal[False] = False) -> np.ndarray: ...
@overload
def ik(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, q_near: ArrayLike | None = None,
       q_start: ArrayLike | None = None, method: Method = "radial", rim: Rim = "continuous",
       radius: float | None = None, limits: bool = True, options: IKOptions | None = None,
       geometry: Geometry | None = None, return_mask: Literal[True],
       return_info: Literal[False] = False) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def ik(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, q_near: ArrayLike | None = None,
       q_start: ArrayLike | None = None, method: Method = "radial", rim: Rim = "continuous",
       radius: float | None = None, limits: bool = True, options: IKOptions | None = None,
       geometry: Geometry | None = None, return_mask: Literal[False] = False,
       return_info: Literal[True]) -> tuple[np.ndarray, IKInfo]: ...
@overload
def ik(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, q_near: ArrayLike | None = None,
       q_start: ArrayLike | None = None, method: Method = "radial", rim: Rim = "continuous",
       radius: float | None = None, limits: bool = True, options: IKOptions | None = None,
       geometry: Geometry | None = None, return_mask: Literal[True],
       return_info: Literal[True]) -> tuple[np.ndarray, np.ndarray, IKInfo]: ...
def ik(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, q_near: ArrayLike | None = None,
       q_start: ArrayLike | None = None, method: Method = "radial", rim: Rim = "continuous",
       radius: float | None = None, limits: bool = True, options: IKOptions | None = None,
       geometry: Geometry | None = None, return_mask: bool = False, return_info: bool = False) -> Any:
    """(theta, beta, gamma) placing the rim point (alpha, w) of ``leg`` at ``target`` in {R} (seed 2).

    ``method="radial"`` (default) finds every theta in [17 deg, 160 deg] that reaches the target, for both
    signs of the out-of-plane square root (:func:`ik_all` lists them: the branch ``y_L <= 0`` by increasing
    theta, then ``y_L > 0``). Without ``q_near`` it returns the first of them whose gamma is inside the ABAD
    limits; with ``q_near`` the usable one nearest ``q_near`` (distance ``sqrt(dtheta^2 + dbeta^2 +
    dgamma^2)``, angle differences wrapped), beta shifted by a multiple of 2 pi to lie within pi of
    ``q_near``'s. The iterative methods (``"damped"``, ``"gauss_newton_fd"``) start from ``q_start`` (else
    ``q_near``, else geometric guesses: gamma exact, theta from a grid; the damped method restarts a failed
    target from the next guesses and then from the other out-of-plane branch).

    The contract (docs/wheel_leg.md): every answer marked solved is reproduced by :func:`fk` with the same
    ``alpha, w, leg, rim, radius`` to ``options.tol``; with ``limits=True`` (default) its gamma lies inside the
    ABAD joint's URDF limits [-pi/2, pi/2] (:data:`ABAD_LIMIT`) and theta in [17 deg, 160 deg]; the default
    method solves every target that :func:`fk` makes from such joints.

    Args:
        target: (..., 3) points in {R}; alpha (rad), w (m), q_near, q_start broadcast with its leading shape.
        leg: "FL", "FR", "RR", "RL" or 0-3.
        q_near: (..., 3) the configuration to stay near.
        q_start: (..., 3) the start of the iteration (iterative methods only).
        method: ``"radial"``, ``"damped"`` or ``"gauss_newton_fd"``.
        rim, radius: the rim model and arc radius, as in :func:`fk`.
        limits: keep only answers inside the ABAD joint limits (False: any gamma).
        options: :class:`IKOptions` (tolerance, iteration bound, forward-difference step).
        return_mask: also return the mask of solved targets (batch).
        return_info: also return an :class:`IKInfo`.

    Returns:
        (..., 3) joint angles (theta, beta, gamma) (rad), NaN where a batch item is not solved; then the mask
        and the :class:`IKInfo`, as asked.

    Raises:
        JointLimitError: single target reachable, but only with gamma outside the ABAD limits.
        UnreachableError: single target not reached (``closest`` = the point reached).
        InvalidInputError: NaN/inf, complex or wrong shapes, alpha or w out of range.
        InvalidParameterError: unknown ``method``, ``rim`` or ``leg``; a keyword out of its range.
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    opts = _options(options)
    rim_ = rim_name(rim)
    if (type(target) is np.ndarray and target.shape == (3,) and target.dtype == np.float64 and type(alpha) in _SCALARS
            and type(w) in _SCALARS and type(method) is str and method in METHODS and type(limits) is bool
            and type(return_mask) is bool and type(return_info) is bool):
        start = q_start if q_near is None else (q_near if q_start is None else None)
        both = q_near is not None and q_start is not None
        if not both and (start is None or (type(start) is np.ndarray and start.shape == (3,)
                                           and start.dtype == np.float64 and (q_start is None or method != "radial"))):
            out = _single(target, float(alpha), float(w), leg, rim_, radius, geo, method, opts, return_mask,
                          return_info, limits, start)
            if out is not None:
                return out
    return_mask = check_flag(return_mask, "return_mask")
    return_info = check_flag(return_info, "return_info")
    if not return_info and _large_batch(target, alpha, w, q_near, q_start):
        return _ik_in_chunks(np.asarray(target), leg, alpha, w, q_near, q_start, return_mask, method=method, rim=rim_,
                             radius=radius, limits=limits, options=opts, geometry=geo)
    run, q_raw = _run(target, alpha, w, leg, q_near, q_start, method, rim_, radius, limits, opts, geo)
    out = finish(run.q, run.ok, run.ok.shape == (), return_mask,
                 lambda: _error(run, q_raw, leg, alpha, w, method, opts.tol))
    if return_info:
        return (*out, run.info) if isinstance(out, tuple) else (out, run.info)
    return out


def _large_batch(target, alpha, w, q_near, q_start) -> bool:
    """True for a batch of more than ``CHUNK`` float64 targets with alpha and w numbers or one per target, and
    q_near / q_start None or one row per target: :func:`ik` then solves it by chunks (the radial method's
    temporaries take ~310 B a target, 13x the answer)."""
    if not (type(target) is np.ndarray and target.dtype == np.float64 and target.ndim >= 2
            and target.shape[-1] == 3 and target.size > 3 * _batch.CHUNK):
        return False
    rows_ok = all(x is None or (type(x) is np.ndarray and x.shape == target.shape) for x in (q_near, q_start))
    items_ok = all(type(x) in _SCALARS or (type(x) is np.ndarray and x.shape == target.shape[:-1]) for x in (alpha, w))
    return rows_ok and items_ok


def _ik_in_chunks(target: np.ndarray, leg: Leg, alpha, w, q_near, q_start, return_mask: bool, **keywords):
    """:func:`ik` of a large batch (:func:`_large_batch`), ``CHUNK`` targets at a time (``legkin._batch.in_chunks``):
    its working memory beyond the answer stays ~20 MB. The inputs are checked whole first, so that an error names
    the row in the whole batch."""
    shape = target.shape[:-1]
    rows = _chunk_rows(target, alpha, w, q_near, q_start)

    def solve(t, a, ww, qn, qs):
        a = float(alpha) if a is None else a
        ww = float(w) if ww is None else ww
        return ik(t, leg, alpha=a, w=ww, q_near=qn, q_start=qs, return_mask=True, **keywords)

    q, ok = in_chunks(solve, rows)
    return finish(q.reshape(shape + (3,)), ok.reshape(shape), False, return_mask, lambda: AssertionError())


def _chunk_rows(target: np.ndarray, alpha, w, q_near=None, q_start=None) -> list[np.ndarray | None]:
    """The rows of a large batch (:func:`_large_batch`) checked whole, so that an error names the row in the whole
    batch: target (n, 3), alpha and w (n,) or None (a number), q_near and q_start (n, 3) or None."""
    rows: list[np.ndarray | None] = [as_input(target, "target", (3,)).reshape(-1, 3)]
    rows += [as_input(x, name).reshape(-1) if type(x) is np.ndarray else None
             for x, name in ((alpha, "alpha"), (w, "w"))]
    rows += [as_input(x, name, (3,)).reshape(-1, 3) if x is not None else None
             for x, name in ((q_near, "q_near"), (q_start, "q_start"))]
    return rows


def _ik_all_in_chunks(target: np.ndarray, leg: Leg, alpha, w, return_mask: bool, **keywords):
    """:func:`ik_all` of a large batch, ``CHUNK`` targets at a time: the solutions of n targets padded to the
    largest count S are allocated once (widened if a later chunk has more solutions), so that the memory beyond
    the answer is one chunk's (it was ~370 B a target, 7x the answer)."""
    shape, rows = target.shape[:-1], _chunk_rows(target, alpha, w)
    n, chunk = rows[0].shape[0], _batch.CHUNK  # type: ignore[union-attr]
    sols: np.ndarray = np.full((n, 0, 3), np.nan)
    mask: np.ndarray = np.zeros((n, 0), dtype=bool)
    for lo in range(0, n, chunk):
        t, a, ww = (None if x is None else x[lo:lo + chunk] for x in rows[:3])
        s, m = ik_all(t, leg, alpha=float(alpha) if a is None else a, w=float(w) if ww is None else ww,
                      return_mask=True, **keywords)  # type: ignore[call-overload]
        if s.shape[1] > sols.shape[1]:  # more solutions than any chunk before: widen (NaN, mask False)
            wider = np.full((n, s.shape[1], 3), np.nan)
            wider[:, : sols.shape[1]] = sols
            sols, mask = wider, np.pad(mask, ((0, 0), (0, s.shape[1] - mask.shape[1])))
        sols[lo:lo + chunk, : s.shape[1]], mask[lo:lo + chunk, : s.shape[1]] = s, m
    sols, mask = sols.reshape(shape + sols.shape[1:]), mask.reshape(shape + mask.shape[1:])
    return (sols, mask) if return_mask else sols


def _in_limits(sols: np.ndarray) -> np.ndarray:
    """Mask (..., S) of solutions with gamma inside the ABAD limits (within rounding, as :func:`ik`; those are
    clipped onto the limit in place)."""
    with np.errstate(invalid="ignore"):
        inside = np.abs(sols[..., 2]) <= ABAD_LIMIT + _LIMIT_ROUNDING
    sols[..., 2] = np.where(inside, np.clip(sols[..., 2], -ABAD_LIMIT, ABAD_LIMIT), sols[..., 2])
    return inside


@overload
def ik_all(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
           radius: float | None = None, limits: bool = False, options: IKOptions | None = None,
           geometry: Geometry | None = None, return_mask: Literal[False] = False) -> np.ndarray: ...
@overload
def ik_all(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
           radius: float | None = None, limits: bool = False, options: IKOptions | None = None,
           geometry: Geometry | None = None, return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...
def ik_all(target: ArrayLike, leg: Leg, *, alpha: ArrayLike = 0.0, w: ArrayLike = 0.0, rim: Rim = "continuous",
           radius: float | None = None, limits: bool = False, options: IKOptions | None = None,
           geometry: Geometry | None = None, return_mask: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Every (theta, beta, gamma) placing the rim point (alpha, w) of ``leg`` at ``target``: (..., S, 3).

    The radial method's solutions (:func:`ik`): for each root theta in [17 deg, 160 deg] by increasing theta
    the branch ``y_L <= 0``, then the same roots on the branch ``y_L > 0`` (absent when ``y_L = 0``); NaN
    rows (mask False) pad the batch to the largest count S. ``limits=True`` keeps only those with gamma inside
    the ABAD limits (in the same order). A single target without any solution raises :class:`UnreachableError`;
    in a batch its rows are all NaN (mask False).

    Args:
        target: (..., 3) points in {R} (m); leg, alpha, w, rim, radius, options, geometry: as :func:`ik`.
        limits: keep only the solutions with gamma inside the ABAD joint limits.
        return_mask: also return the mask (..., S) of the rows that are solutions.

    Returns:
        (..., S, 3) joint angles (theta, beta, gamma) (rad); then the mask, if asked.

    Raises:
        UnreachableError: (single) the target has no solution (inside the ABAD limits, with ``limits=True``).
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    opts = _options(options)
    return_mask = check_flag(return_mask, "return_mask")
    limits = check_flag(limits, "limits")
    rim_ = rim_name(rim)
    if type(target) is np.ndarray and target.shape == (3,) and target.dtype == np.float64 and isinstance(alpha, float) \
            and isinstance(w, float):
        out = _single(target, alpha, w, leg, rim_, radius, geo, "radial", opts, False, True, False)
        if out is not None:
            sols = out[1].solutions
            sols = sols[_in_limits(sols)] if limits else sols
            if len(sols):
                return (sols, np.ones(len(sols), dtype=bool)) if return_mask else sols
    if _large_batch(target, alpha, w, None, None):
        return _ik_all_in_chunks(np.asarray(target), leg, alpha, w, return_mask, rim=rim_, radius=radius,
                                 limits=limits, options=opts, geometry=geo)
    run, _q = _run(target, alpha, w, leg, None, None, "radial", rim_, radius, False, opts, geo, True)
    sols = run.info.solutions
    assert sols is not None
    keep = np.isfinite(sols).all(axis=-1)
    if limits:
        keep &= _in_limits(sols)
    order = np.argsort(~keep, axis=-1, kind="stable")  # the kept ones first, in their order
    sols = np.take_along_axis(np.where(keep[..., None], sols, np.nan), order[..., None], axis=-2)
    count = keep.sum(axis=-1)
    width = int(count.max()) if count.size else 0
    sols = sols[..., :width, :]
    mask = np.take_along_axis(keep, order, axis=-1)[..., :width]
    if count.shape == () and not count:
        t = np.asarray(run.target).reshape(3)
        raise UnreachableError(f"target {t.tolist()} for leg {leg!r} has no solution"
                               + (" inside the ABAD limits" if limits else ""), target=t)
    return (sols, mask) if return_mask else sols
