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
from .._batch import F64, as_input, check_choice, check_flag, check_integer, check_number, dispatch, in_chunks
from .._kernels import OK
from ..errors import InvalidInputError, InvalidParameterError, UnreachableError
from . import ik_iterative
from ._common import _LIMITS, _SCALARS, _SOLVED, Leg, Rim, _check_alpha, _check_theta, _check_w, rim_name
from .frames import _NO_JAC, _context, _Ctx, _k_contact, _kctx, _writeable
from .geometry import (
    _DEFAULT_GEOMETRY,
    _LIMIT_ROUNDING,
    ABAD_LIMIT,
    THETA_MAX,
    THETA_MIN,
    Geometry,
    _geometry,
    abad_limit_error,
)
from .ik_radial import _NO_Q0, _RADIAL_SOLS, _ik_radial, _k_ik_radial, _radial_table
from .rim import _k_select, _select

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


# ---------------------------------------------------------------- the context, built once per keyword set
class _IKCtx(NamedTuple):
    """What :func:`ik` and :func:`ik_all` need besides the targets, validated and built once per keyword set."""

    base: _Ctx  # the contact FK's context (leg, rim, radius, geometry); its per-item rim choice is set per batch
    kc: tuple  # the contact kernels' constants (:func:`.frames._kctx`)
    packed: tuple  # and packed for :func:`.frames._k_contact`
    tables: tuple  # the method's tables (radial: :func:`.ik_radial._radial_table`; iterative: the start grid)
    leg: Any
    w_max: float  # |w| <= T / 2, within rounding (m)


@lru_cache(maxsize=64, typed=True)  # typed: leg=1 must not admit leg=True or 1.0 (issue 25)
def _ik_ctx_cached(leg, rim, radius, geometry, method) -> _IKCtx:
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    rim = rim_name(rim)
    check_choice(method, "method", METHODS)
    base = _context(np.zeros(0), np.zeros(0), leg, rim, geo, radius)
    kc, packed = _kctx(leg, rim, radius, geo)
    tables = _radial_table(geo.R, kc[0]) if method == "radial" else ik_iterative.guess_table(geo.R, kc[0])
    return _IKCtx(base, kc, packed, tables, leg, geo.T / 2 + 1e-15)


def _ik_ctx(leg: object, rim: object, radius: object, geometry: object, method: object) -> _IKCtx:
    """The keywords of :func:`ik` / :func:`ik_all` checked, and their context (:func:`_ik_ctx_cached`, an
    unhashable value named by the checks)."""
    try:
        return _ik_ctx_cached(leg, rim, radius, geometry, method)
    except TypeError:
        geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
        check_choice(method, "method", METHODS)
        _context(np.zeros(0), np.zeros(0), leg, rim_name(rim), geo, radius)
        raise


# ---------------------------------------------------------------- one target: the method's kernel
#: alpha's range (rad), within rounding.
_ALPHA_MAX = math.pi + 1e-12


def _ik_one(target, args):
    """One float64 target straight to the method's kernel (the fast path of :func:`ik`): q (3,) if solved, else None
    (the general path then decides, and raises).

    ``args`` = (a, b, near, start, ctx, method, opts, limits, sink): alpha ``a``, w ``b`` numbers; ``near``,
    ``start``: q_near, q_start, (3,) or None; ``sink``: None, or a list that gets (q, iterations, error, reason,
    evaluations, solutions) ((S, 3) every radial solution; iterative methods: None), solved or not (the info; the
    failure path's reason).
    """
    a, b, near, start, ctx, method, opts, limits, sink = args
    if type(a) is not float or not (abs(a) <= _ALPHA_MAX and abs(b) <= ctx.w_max):
        return None
    q0 = near if method == "radial" or start is None else start
    if q0 is not None and not (THETA_MIN - 1e-12 <= q0[0] <= THETA_MAX + 1e-12 and math.isfinite(q0[1])
                               and math.isfinite(q0[2])):
        return None
    seed, rho, K, KC, s, dwheel, _half_T, o0, o1, o2 = ctx.kc
    upper, right, e = _k_select(a, seed, rho, K[0])
    aw = dwheel + s * b
    q = np.empty(3)
    sols = None
    if method == "radial":
        max_iter = 60 if opts.max_iter is None else opts.max_iter
        sols = np.empty((_RADIAL_SOLS, 3))
        q_near = _NO_Q0[0] if q0 is None else q0
        its, err, reason, _nr, nsol = _k_ik_radial(target, upper, right, e, aw, seed, K, KC, s, o0, o1, o2,
                                                   *ctx.tables, opts.tol, max_iter, q_near, q0 is not None, limits, q,
                                                   sols)
        if sink is not None and reason == _SOLVED and nsol > _RADIAL_SOLS:  # keep every solution
            sols = np.empty((nsol, 3))
            _k_ik_radial(target, upper, right, e, aw, seed, K, KC, s, o0, o1, o2, *ctx.tables, opts.tol, max_iter,
                         q_near, q0 is not None, limits, np.empty(3), sols)
        sols, ev = sols[:nsol], its + 1
    else:
        max_iter = ik_iterative.DEFAULT_MAX_ITER[method] if opts.max_iter is None else opts.max_iter
        its, err, reason, ev = ik_iterative._k_ik_iterative(
            target, upper, right, e, aw, seed, K, KC, s, o0, o1, o2, *ctx.tables, ik_iterative.METHOD_IDS[method],
            ik_iterative._STARTS[method], opts.tol, max_iter, opts.delta,
            ik_iterative._NO_START[0] if q0 is None else q0, q0 is not None, limits, q)
    if sink is not None:
        sink.append((q, its, err, reason, ev, sols))
    return q if reason == _SOLVED else None


def _closest(q_raw, alpha, w, ctx):
    """The contact point of an unsolved answer, theta clipped into its range (None if not finite)."""
    qc = q_raw.copy()
    qc[0] = min(max(qc[0], THETA_MIN), THETA_MAX)
    p = np.empty(3)
    return p if _k_contact(qc, alpha, w, *ctx.packed, False, p, _NO_JAC) == OK else None


def _ik_fail(target, out, ok, alpha, w, near, start, ctx: _IKCtx, method, opts, limits, sink) -> Exception:
    """Why the single target was not solved: it is solved again (the failure path only) for its reason."""
    one: list[tuple] = []
    _ik_one(target, (alpha, w, near, start, ctx, method, opts, limits, one))
    q, its, err, reason, _ev, _sols = one[0]
    closest = _closest(q, alpha, w, ctx)
    where = f"target {target.tolist()} for leg {ctx.leg!r} (alpha={alpha!r}, w={w!r})"
    if reason == _LIMITS:
        return abad_limit_error(
            f"{where} is reachable only with the ABAD angle outside its limits [-pi/2, pi/2] "
            f"(gamma={float(q[2]):.6g} rad); pass limits=False to accept it",
            ctx.leg, target, float(q[2]), closest,
        )
    distance = math.nan if closest is None else float(np.linalg.norm(closest - target))
    return UnreachableError(
        f"{where} not reached with method {method!r}: final error {err:.3e} m after "
        f"{its} iterations (tolerance {opts.tol:.1e} m, theta in [17, 160] deg); closest point "
        f"reached {None if closest is None else closest.tolist()} ({distance:.3g} m away)",
        target=target, closest=closest, distance=distance,
    )


# ---------------------------------------------------------------- the inputs besides the target
def _broadcast(target, alpha, w, q_near, q_start):
    """Inputs checked and broadcast together: (target (..., 3), alpha, w, q_near, q_start), the last four numbers /
    (3,) rows for one target, else one per target ((n,), (n, 3), the targets' batch flattened)."""
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

    def items(x, core):
        if x is None:
            return None
        # a copy only where it broadcasts or is not a writeable C-contiguous float64 array (no n-sized copy of the
        # caller's per-target arrays)
        x = _writeable(x if x.shape == shape + core else np.broadcast_to(x, shape + core))
        return x if not shape else x.reshape((-1,) + core)

    a, b = items(alpha, ()), items(w, ())
    return (items(target, (3,)).reshape(shape + (3,)), float(a) if not shape else a, float(b) if not shape else b,
            items(q_near, (3,)), items(q_start, (3,)))


def _targets(target, alpha, w, q_near, q_start):
    """(target, alpha, w, q_near, q_start) for :func:`legkin._batch.dispatch`: as they are when alpha, w are numbers
    and q_near, q_start None or float64 (3,) arrays (the fast path), else :func:`_broadcast`."""
    if type(alpha) in _SCALARS and type(w) in _SCALARS and (q_near is None or _row3(q_near)) and (
            q_start is None or _row3(q_start)):
        return target, float(alpha), float(w), q_near, q_start
    return _broadcast(target, alpha, w, q_near, q_start)


def _row3(x: object) -> bool:
    return type(x) is np.ndarray and x.dtype is F64 and x.shape == (3,)


def _rows(rows: np.ndarray, a, b, near, start, ctx: _IKCtx):
    """The per-target inputs of a batch of n targets, range-checked: alpha, w (n,) or numbers; q_near, q_start (n, 3)
    or None."""
    n = rows.shape[0]
    _check_alpha(np.array([a]) if type(a) is float else a)
    _check_w(np.array([b]) if type(b) is float else b, ctx.base.geo)
    out = [a, b]  # a number stays a number (expanded per chunk by _solve_rows: no n-sized copy)
    for x, name in ((near, "q_near"), (start, "q_start")):
        if x is not None:  # finite (InvalidInputError), theta in range
            x = np.ascontiguousarray(np.broadcast_to(as_input(x, name, (3,)), (n, 3)))
            _check_theta(x[:, 0], f"theta ({name}[..., 0])")
        out.append(x)
    return out


def _solve_rows(rows, alpha, w, near, start, ctx: _IKCtx, method: str, opts: IKOptions, limits: bool):
    """The method's compiled loop on targets (n, 3): (q, iterations, error, solved, solutions, evaluations)."""
    alpha = np.full(rows.shape[0], alpha) if type(alpha) is float else alpha
    w = np.full(rows.shape[0], w) if type(w) is float else w
    sel = _select(alpha, ctx.kc[0], ctx.kc[1], ctx.base.geo.R)
    c = ctx.base._replace(sel=sel, w=w)
    if method == "radial":
        q, it, err, ok, sols, _reason = _ik_radial(rows, c, opts.tol, opts.max_iter, near, limits)
        return q, it, err, ok, sols, it + 1
    q, it, err, ok, _reason, ev = ik_iterative.solve(rows, c, start if start is not None else near, method, opts.tol,
                                                     opts.max_iter, opts.delta, limits)
    return q, it, err, ok, None, ev


# ---------------------------------------------------------------- ik on legkin._batch.dispatch
def _ik_batch(rows, a, b, near, start, ctx: _IKCtx, method, opts, limits, sink) -> tuple[np.ndarray, np.ndarray]:
    """The compiled loop on targets (n, 3): a large batch without ``return_info`` :data:`~legkin._batch.CHUNK`
    targets at a time (:func:`legkin._batch.in_chunks`: the radial method's temporaries take ~310 B a target)."""
    alpha, w, near, start = _rows(rows, a, b, near, start, ctx)
    if sink is None and rows.shape[0] > _batch.CHUNK:
        def solve(r, al, ww, nr, st):  # a number alpha or w is passed whole (None in the sliced rows)
            q, _it, _err, ok, _sols, _ev = _solve_rows(r, alpha if al is None else al, w if ww is None else ww, nr,
                                                       st, ctx, method, opts, limits)
            return q, ok

        per_row = [None if type(x) is float else x for x in (alpha, w)]
        q, ok = in_chunks(solve, [rows, *per_row, near, start])
    else:
        q, it, err, ok, sols, ev = _solve_rows(rows, alpha, w, near, start, ctx, method, opts, limits)
        if sink is not None:
            sink.append(IKInfo(it, err, sols, ev))
    q[~ok] = np.nan
    return q, ok


def _with_info(res: Any, info: Any, return_mask: bool) -> Any:
    """``res`` of :func:`ik` with its :class:`IKInfo`: one target's (:func:`_ik_one`'s tuple), or a batch's rows
    reshaped to the targets' batch shape."""
    if type(info) is tuple:
        _q, its, err, _reason, ev, sols = info
        info = IKInfo(np.array(its), np.array(err), sols, np.array(ev))
    else:
        shape = (res[0] if return_mask else res).shape[:-1]
        sols = info.solutions
        info = IKInfo(info.iterations.reshape(shape), info.error.reshape(shape),
                      None if sols is None else sols.reshape(shape + sols.shape[-2:]), info.evaluations.reshape(shape))
    return (*res, info) if return_mask else (res, info)


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
    opts = _options(options)
    if limits is not True and limits is not False:
        limits = check_flag(limits, "limits")
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    if return_info is not False and return_info is not True:
        return_info = check_flag(return_info, "return_info")
    ctx = _ik_ctx(leg, rim, radius, geometry, method)
    if method == "radial" and q_start is not None:
        raise InvalidParameterError("q_start is the start of an iteration (methods 'damped', 'gauss_newton_fd'); "
                                    "the radial method takes q_near (the configuration to stay near)")
    if type(alpha) in _SCALARS and type(w) in _SCALARS and q_near is None and q_start is None:  # the common call
        a, b, near, start = float(alpha), float(w), None, None  # type: ignore[arg-type]
    else:
        target, a, b, near, start = _targets(target, alpha, w, q_near, q_start)
    sink: list[Any] | None = [] if return_info else None
    res = dispatch(target, "target", (3,), _ik_one, _ik_batch, _ik_fail, (a, b, near, start, ctx, method, opts,
                                                                          limits, sink), return_mask,
                   chunks=False)  # _ik_batch runs its own chunks: alpha, w, q_near, q_start are per target
    return res if sink is None else _with_info(res, sink[-1], return_mask)


def _in_limits(sols: np.ndarray) -> np.ndarray:
    """Mask (..., S) of solutions with gamma inside the ABAD limits (within rounding, as :func:`ik`; those are
    clipped onto the limit in place)."""
    with np.errstate(invalid="ignore"):
        inside = np.abs(sols[..., 2]) <= ABAD_LIMIT + _LIMIT_ROUNDING
    sols[..., 2] = np.where(inside, np.clip(sols[..., 2], -ABAD_LIMIT, ABAD_LIMIT), sols[..., 2])
    return inside


def _all_fast(target, args: tuple) -> Any:
    """One float64 target: every radial solution from the kernel, with its mask if asked (None if none: the general
    path then raises); ``args`` = (a, b, ctx, opts, limits, return_mask)."""
    a, b, ctx, opts, limits, return_mask = args
    one: list[tuple] = []
    if _ik_one(target, (a, b, None, None, ctx, "radial", opts, False, one)) is None:
        return None
    sols = one[0][5]
    sols = sols[_in_limits(sols)] if limits else sols
    if not len(sols):
        return None
    return (sols, np.ones(len(sols), dtype=bool)) if return_mask else sols


def _all_batch(rows, a, b, ctx: _IKCtx, opts: IKOptions, limits: bool, _mask: bool) -> tuple[np.ndarray, np.ndarray]:
    """Every radial solution of targets (n, 3): (n, S, 3), the kept ones first in their order, NaN-padded; mask.

    By chunks of :data:`~legkin._batch.CHUNK` targets: the padded answer is allocated once and widened when a
    chunk has more solutions than those before, so that the memory beyond the answer is one chunk's (it was
    ~370 B a target, 7x the answer)."""
    alpha, w, _near, _start = _rows(rows, a, b, None, None, ctx)
    n, chunk = rows.shape[0], _batch.CHUNK
    sols, keep = np.full((n, 0, 3), np.nan), np.zeros((n, 0), dtype=bool)
    for lo in range(0, n, chunk):
        part = slice(lo, lo + chunk)
        s, k = _all_rows(rows[part], alpha if type(alpha) is float else alpha[part],
                         w if type(w) is float else w[part], ctx, opts, limits)
        if s.shape[1] > sols.shape[1]:  # more solutions than any chunk before: widen (NaN, mask False)
            wider = np.full((n, s.shape[1], 3), np.nan)
            wider[:, : sols.shape[1]] = sols
            sols, keep = wider, np.pad(keep, ((0, 0), (0, s.shape[1] - keep.shape[1])))
        sols[part, : s.shape[1]], keep[part, : s.shape[1]] = s, k
    return sols, keep


def _all_rows(rows, alpha, w, ctx: _IKCtx, opts: IKOptions, limits: bool) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_all_batch` on one chunk: the solutions (m, S, 3) with the kept ones first, and their mask."""
    sols = _solve_rows(rows, alpha, w, None, None, ctx, "radial", opts, False)[4]
    keep = np.isfinite(sols).all(axis=-1)
    if limits:
        keep &= _in_limits(sols)
    order = np.argsort(~keep, axis=-1, kind="stable")  # the kept ones first, in their order
    sols = np.take_along_axis(np.where(keep[..., None], sols, np.nan), order[..., None], axis=-2)
    width = int(keep.sum(axis=-1).max()) if len(rows) else 0
    return sols[:, :width], np.take_along_axis(keep, order, axis=-1)[:, :width]


def _all_fail(target, out, ok, a, b, ctx: _IKCtx, opts: IKOptions, limits: bool, _mask: bool) -> Exception:
    return UnreachableError(f"target {target.tolist()} for leg {ctx.leg!r} has no solution"
                            + (" inside the ABAD limits" if limits else ""), target=target)


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
    opts = _options(options)
    if return_mask is not False and return_mask is not True:
        return_mask = check_flag(return_mask, "return_mask")
    if limits is not True and limits is not False:
        limits = check_flag(limits, "limits")
    ctx = _ik_ctx(leg, rim, radius, geometry, "radial")
    if type(alpha) in _SCALARS and type(w) in _SCALARS:  # the common call
        a, b = float(alpha), float(w)  # type: ignore[arg-type]
    else:
        target, a, b, _near, _start = _broadcast(target, alpha, w, None, None)
    return dispatch(target, "target", (3,), _all_fast, _all_batch, _all_fail, (a, b, ctx, opts, limits, return_mask),
                    return_mask, chunks=False)  # type: ignore[no-any-return] # _all_batch runs its own chunks
