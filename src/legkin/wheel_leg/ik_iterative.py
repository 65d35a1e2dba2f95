"""The iterative IK methods on the 3x3 system, per-target compiled loops with early exit.

* ``method="gauss_newton_fd"``: seed 2.2-2.3 as printed, Gauss-Newton with the
  forward-difference Jacobian, full steps, no bounds (:func:`_k_ik_gauss_newton_fd`).
* ``method="damped"``: Gauss-Newton with the analytic Jacobian, Levenberg-Marquardt damping, theta projected
  onto its domain (:func:`_k_ik_damped`).

Both start from geometric guesses (:func:`_k_starts`: gamma exact, theta from a 64-node grid, beta from the
direction) or from ``q_start``, and restart a failed target from the next guess (:func:`_k_ik_iterative`).
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import as_rows, batch_kernel, kernel
from .._rotations import wrap_k
from ._common import _LIMITS, _SOLVED, _UNREACHABLE, _k_clip
from .frames import _Ctx, _k_fk
from .geometry import _LIMIT_ROUNDING, ABAD_LIMIT, THETA_MAX, THETA_MIN, TYRE_THICKNESS
from .ik_radial import _arc_table
from .linkage import _kconst
from .rim import _k_plane

#: The iterative methods by kernel id.
METHOD_IDS = {"gauss_newton_fd": 0, "damped": 1}
#: Default iteration bound per start.
DEFAULT_MAX_ITER = {"gauss_newton_fd": 100, "damped": 60}
#: Starts per out-of-plane branch: the seed's method takes the best guess of each branch, the damped method
#: the grid's three best.
_STARTS = {"gauss_newton_fd": 1, "damped": 3}

_GUESS_NODES = 64
# half a grid cell inside the domain: a start on a bound of theta can stall the projected iteration there
# (seen: theta = 160 deg start, solution at 158.5 deg, error stuck at 2.8e-5 m)
_START_MARGIN = 0.5 * (THETA_MAX - THETA_MIN) / (_GUESS_NODES - 1)


@kernel(entry=True)
def _k_starts(tgt, upper, right, e, a, seed, K, KC, o0, o1, o2, s, grid, table, branch, count, starts):
    """Geometric starts for one target on the out-of-plane branch ``sign(y_L) = branch``, best first, into
    ``starts`` (count, 3).

    Out of the plane (exact): in {M} before the ABAD rotation the contact point is ``(a, y_L, -+x_L)``,
    ``a = d_wheel + s w``; ``Rz(gamma)`` keeps the coordinate along z_M (``x_L = -(target - o)_x``) and the
    distance from that axis, so ``y_L = branch sqrt(x_M^2 + y_M^2 - a^2)`` (clipped at 0) and gamma is the
    angle from ``(a, y_L)`` to ``(x_M, y_M)``. In the plane, on the 64-node theta grid, the signed residual
    ``|z(theta, alpha)| - |x_L + i y_L|`` (:func:`~legkin.wheel_leg.ik_radial._arc_table`: several theta can give
    the same radius): first the cells where it changes sign (each holds a root of the in-plane radius), started at
    the secant root, by increasing residual of the cell's better node; then the local minima of its magnitude
    outside those cells, by increasing residual; then the other nodes in grid order. theta is kept half a cell
    inside its domain and beta rotates ``z`` onto the target. (The local minima alone missed a root next to a
    second one beyond the domain: the start sat between them and the iteration stalled on the bound, issue 25.)
    """
    d0, d1, d2 = tgt[0] - o0, tgt[1] - o1, tgt[2] - o2
    m = complex(s * d1, d2)
    yabs = math.sqrt(max(m.real * m.real + m.imag * m.imag - a * a, 0.0))
    y = branch * yabs
    gamma = wrap_k(math.atan2(m.imag, m.real) - math.atan2(y, a))
    t = complex(-d0, y)
    r = abs(t)
    nodes = grid.shape[0]
    ee = e.real * e.real + e.imag * e.imag
    base = 0 if upper else 4
    sd = np.empty(nodes)
    for k in range(nodes):
        f = table[base, k] + ee * table[base + 1, k] + 2.0 * e.real * table[base + 2, k] - 2.0 * e.imag * table[
            base + 3, k]
        sd[k] = math.sqrt(max(f, 0.0)) - r
    key, theta = _k_start_keys(sd, grid)
    for c in range(count):
        best = 0
        for k in range(1, nodes):  # the smallest key left (first on ties)
            if key[k] < key[best]:
                best = k
        key[best] = math.inf
        z, _dz = _k_plane(theta[best], upper, right, e, seed, K, KC, False, True)
        zk = 1j * z  # exp(i (beta + pi/2)) at beta = 0
        ratio = t / zk
        starts[c, 0] = _k_clip(theta[best], THETA_MIN + _START_MARGIN, THETA_MAX - _START_MARGIN)
        starts[c, 1] = math.atan2(ratio.imag, ratio.real)
        starts[c, 2] = gamma


@kernel(inline=True)
def _k_start_keys(sd, grid):
    """The order of the starts (:func:`_k_starts`) from the signed residual ``sd`` on the grid: per node a key
    (smaller first) and a theta. A cell [k, k + 1] where sd changes sign puts its secant root on its better node
    (key: that node's residual - 2, first), a local minimum of |sd| elsewhere its node (key: its residual, next),
    every other node its own (key: 1 + its index / nodes, last; the residuals are below 1 m)."""
    nodes = grid.shape[0]
    key = np.empty(nodes)
    theta = grid.copy()
    for k in range(nodes):
        res = abs(sd[k])
        local = (k == 0 or res <= abs(sd[k - 1])) and (k == nodes - 1 or res <= abs(sd[k + 1]))
        key[k] = res if local else 1.0 + k / nodes
    for k in range(nodes - 1):
        if (sd[k] < 0.0) != (sd[k + 1] < 0.0):
            j, o = (k, k + 1) if abs(sd[k]) <= abs(sd[k + 1]) else (k + 1, k)
            theta[j] = grid[k] + sd[k] / (sd[k] - sd[k + 1]) * (grid[k + 1] - grid[k])
            key[j] = abs(sd[j]) - 2.0
            key[o] = max(key[o], 1.0 + o / nodes)  # not again as a local minimum
    return key, theta


@kernel
def _k_solve3(M, b, x):
    """``x = M^-1 b`` for a 3x3 system by LU with partial pivoting (as LAPACK's getrf/getrs); returns the
    determinant (0: singular, x untouched)."""
    A = M.copy()
    y = b.copy()
    det = 1.0
    for c in range(3):
        piv = c
        for r in range(c + 1, 3):
            if abs(A[r, c]) > abs(A[piv, c]):
                piv = r
        if A[piv, c] == 0.0:
            return 0.0
        if piv != c:
            det = -det
            for k in range(3):
                A[c, k], A[piv, k] = A[piv, k], A[c, k]
            y[c], y[piv] = y[piv], y[c]
        det *= A[c, c]
        for r in range(c + 1, 3):
            f = A[r, c] / A[c, c]
            for k in range(c, 3):
                A[r, k] -= f * A[c, k]
            y[r] -= f * y[c]
    for r in range(2, -1, -1):
        acc = y[r]
        for k in range(r + 1, 3):
            acc -= A[r, k] * x[k]
        x[r] = acc / A[r, r]
    return det


@kernel
def _k_ik_gauss_newton_fd(q, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter, delta):
    """The seed's Gauss-Newton (seed 2.2-2.3) for one target from ``q`` (3,, updated in place): forward-difference
    Jacobian ``(FK(q + delta e_k) - FK(q)) / delta``, full steps ``-(J^T J)^-1 J^T E``, no bounds; stops at
    ``|E| <= tol``, a non-finite error, a singular ``J^T J`` (NaN step) or ``max_iter``. Returns (iterations,
    error, converged, FK evaluations)."""
    p = np.empty(3)
    pk = np.empty(3)
    J = np.empty((3, 3))
    JtJ = np.empty((3, 3))
    JtE = np.empty(3)
    dq = np.empty(3)
    qk = np.empty(3)
    _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, p, p)
    ev = 1
    err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)
    it = 0
    while True:
        if err <= tol:
            return it, err, True, ev
        if not math.isfinite(err) or it >= max_iter:
            return it, err, False, ev
        for k in range(3):
            qk[0], qk[1], qk[2] = q[0], q[1], q[2]
            qk[k] += delta
            _k_fk(qk[0], qk[1], qk[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, pk, pk)
            for r in range(3):
                J[r, k] = (pk[r] - p[r]) / delta
        ev += 3
        for i in range(3):
            JtE[i] = J[0, i] * (p[0] - tgt[0]) + J[1, i] * (p[1] - tgt[1]) + J[2, i] * (p[2] - tgt[2])
            for k in range(3):
                JtJ[i, k] = J[0, i] * J[0, k] + J[1, i] * J[1, k] + J[2, i] * J[2, k]
        det = _k_solve3(JtJ, JtE, dq)
        if not abs(det) > 1e-300:
            dq[0], dq[1], dq[2] = math.nan, math.nan, math.nan
        for k in range(3):
            q[k] -= dq[k]
        it += 1
        _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, p, p)
        ev += 1
        err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)


@kernel
def _k_ik_damped(q, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter):
    """The damped method for one target from ``q`` (3,, updated in place): Gauss-Newton with the analytic
    Jacobian (:func:`_k_fk`), Levenberg-Marquardt damping ``(J^T J + lam tr(J^T J) I)`` raised 100x while a
    step does not lower ``|E|`` (10 trials) and lowered 10x when it does, theta projected onto [17, 160] deg;
    once ``|E| <= tol`` one more step is taken if it lowers ``|E|``. Returns (iterations, error, FK evaluations)."""
    p = np.empty(3)
    pn = np.empty(3)
    J = np.empty(9)
    Jn = np.empty(9)
    M = np.empty((3, 3))
    JtE = np.empty(3)
    dq = np.empty(3)
    qn = np.empty(3)
    best = np.empty(3)
    JtJ = np.empty((3, 3))
    q[0] = _k_clip(q[0], THETA_MIN, THETA_MAX)
    _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, True, p, J)
    ev = 1
    err = math.sqrt((p[0] - tgt[0]) ** 2 + (p[1] - tgt[1]) ** 2 + (p[2] - tgt[2]) ** 2)
    active = err > tol
    polish = not active
    mu = 1e-16
    it = 0
    for _ in range(max_iter):
        if not active:
            break
        for i in range(3):
            JtE[i] = J[i] * (p[0] - tgt[0]) + J[3 + i] * (p[1] - tgt[1]) + J[6 + i] * (p[2] - tgt[2])
            for k in range(3):
                JtJ[i, k] = J[i] * J[k] + J[3 + i] * J[3 + k] + J[6 + i] * J[6 + k]
        scale = max(JtJ[0, 0] + JtJ[1, 1] + JtJ[2, 2], 1e-300)
        best[0], best[1], best[2] = q[0], q[1], q[2]
        best_err = err
        improved = False
        lam = mu
        for _trial in range(10):
            if improved:
                break
            for i in range(3):
                for k in range(3):
                    M[i, k] = JtJ[i, k] + (lam * scale if i == k else 0.0)
            det = _k_solve3(M, JtE, dq)
            if not (math.isfinite(det) and det != 0.0):
                dq[0], dq[1], dq[2] = math.nan, math.nan, math.nan
            qn[0] = _k_clip(q[0] - dq[0], THETA_MIN, THETA_MAX)
            qn[1], qn[2] = q[1] - dq[1], q[2] - dq[2]
            _k_fk(qn[0], qn[1], qn[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, False, pn, Jn)
            ev += 1
            en = math.sqrt((pn[0] - tgt[0]) ** 2 + (pn[1] - tgt[1]) ** 2 + (pn[2] - tgt[2]) ** 2)
            if en < err:
                improved = True
                best[0], best[1], best[2] = qn[0], qn[1], qn[2]
                best_err = en
                lam = max(lam / 10.0, 1e-16)
            else:
                lam *= 100.0
        q[0], q[1], q[2] = best[0], best[1], best[2]
        err = best_err
        mu = lam
        it += 1
        _k_fk(q[0], q[1], q[2], upper, right, e, seed, K, KC, s, a, o0, o1, o2, True, p, J)
        ev += 1
        done = err <= tol
        active = ((not done) or (not polish)) and improved
        polish = polish or done
    return it, err, ev


@kernel(entry=True)
def _k_ik_iterative(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, method, count, tol, max_iter,
                    delta, q_start, use_start, limits, q):
    """One target by an iterative method (0: :func:`_k_ik_gauss_newton_fd`, 1: :func:`_k_ik_damped`) into
    ``q`` (3,): from ``q_start`` if ``use_start``, else from the ``count`` best starts of the branch
    ``y_L <= 0`` and then of ``y_L > 0`` (:func:`_k_starts`), each start only while the target is not solved
    (converged with theta in its domain and, if ``limits``, gamma inside the ABAD limits). ``q`` is the
    solution, else the answer of smallest error. Returns (iterations, error, reason, FK evaluations),
    iterations and evaluations summed over the starts."""
    starts = np.empty((count, 3))
    qs = np.empty(3)
    q[0], q[1], q[2] = math.nan, math.nan, math.nan
    err = math.inf
    its, ev = 0, 0
    solved, outside = False, False
    n_starts = 1 if use_start else 2 * count
    for k in range(n_starts):
        if use_start:
            qs[0], qs[1], qs[2] = q_start[0], q_start[1], q_start[2]
        else:
            if k % count == 0:
                _k_starts(tgt, upper, right, e, a, seed, K, KC, o0, o1, o2, s, grid, table,
                          -1.0 if k < count else 1.0, count, starts)
            qs[0], qs[1], qs[2] = starts[k % count, 0], starts[k % count, 1], starts[k % count, 2]
        if method == 0:
            it, ek, conv, evk = _k_ik_gauss_newton_fd(qs, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol,
                                                      max_iter, delta)
        else:
            it, ek, evk = _k_ik_damped(qs, tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, tol, max_iter)
            conv = ek <= tol
        its += it
        ev += evk
        inside = (qs[0] >= THETA_MIN - 1e-12 and qs[0] <= THETA_MAX + 1e-12 and math.isfinite(qs[0])
                  and math.isfinite(qs[1]) and math.isfinite(qs[2]))
        if limits and inside:
            inside = abs(qs[2]) <= ABAD_LIMIT + _LIMIT_ROUNDING
            if inside:  # within rounding of a limit counts as on it
                qs[2] = _k_clip(qs[2], -ABAD_LIMIT, ABAD_LIMIT)
        good = conv and inside
        outside = outside or (conv and not inside)
        if good or ek < err:
            q[0], q[1], q[2] = qs[0], qs[1], qs[2]
            err = ek
        if good:
            solved = True
            break
    reason = _SOLVED if solved else (_LIMITS if outside else _UNREACHABLE)
    return its, err, reason, ev


@batch_kernel(rows="tgt upper right e a q_start q its err reason ev", min_parallel=256)
def _k_ik_iterative_batch(tgt, upper, right, e, a, seed, K, KC, s, o0, o1, o2, grid, table, method, count, tol,
                          max_iter, delta, q_start, use_start, limits, q, its, err, reason, ev):
    """:func:`_k_ik_iterative` over targets (n, 3) (``q_start`` (n, 3), or (1, 3) unused) into q (n, 3),
    its, err, reason, ev (n,)."""
    for i in range(tgt.shape[0]):
        i0 = i if use_start else i - i  # (same integer type as i)
        its[i], err[i], reason[i], ev[i] = _k_ik_iterative(
            tgt[i], upper[i], right[i], e[i], a[i], seed, K, KC, s, o0, o1, o2, grid, table, method, count, tol,
            max_iter, delta, q_start[i0], use_start, limits, q[i])


_NO_START = np.zeros((1, 3))


def guess_table(R: float, three_arc: bool) -> tuple[np.ndarray, np.ndarray]:
    """The 64-node theta grid and its ``|c|^2`` coefficient table for the starts (cached per geometry)."""
    return _arc_table(R, three_arc, _GUESS_NODES)


def starts(target: np.ndarray, ctx: _Ctx, count: int = 1, branch: float = -1.0) -> np.ndarray:
    """(count, n, 3) geometric starts of the targets (n, 3) on one out-of-plane branch (:func:`_k_starts`)."""
    n = target.shape[0]
    upper, right, e, a = ctx.items((n,))
    K, KC = _kconst(ctx.c.R, ctx.geo.R + TYRE_THICKNESS)
    grid, table = guess_table(ctx.geo.R, ctx.seed)
    o = ctx.origin
    tgt = as_rows(target, 3)
    out = np.empty((n, count, 3))
    for i in range(n):
        _k_starts(tgt[i], upper[i], right[i], e[i], a[i], ctx.seed, K, KC, float(o[0]), float(o[1]), float(o[2]),
                  ctx.s, grid, table, float(branch), int(count), out[i])
    return np.ascontiguousarray(out.transpose(1, 0, 2))


def solve(target, ctx: _Ctx, q_start, method: str, tol: float, max_iter: int | None, delta: float, limits: bool):
    """The iterative methods on a batch (n, 3): :func:`_k_ik_iterative` per target (compiled loop).
    Returns (q, iterations, error, solved, reason, evaluations)."""
    n = target.shape[0]
    upper, right, e, a = ctx.items((n,))
    K, KC = _kconst(ctx.c.R, ctx.geo.R + TYRE_THICKNESS)
    grid, table = guess_table(ctx.geo.R, ctx.seed)
    o = ctx.origin
    q = np.empty((n, 3))
    its, reason, ev = (np.empty(n, dtype=np.int64) for _ in range(3))
    err = np.empty(n)
    max_iter = DEFAULT_MAX_ITER[method] if max_iter is None else max_iter
    qs = _NO_START if q_start is None else as_rows(q_start, 3)
    _k_ik_iterative_batch(as_rows(target, 3), upper, right, e, a, ctx.seed, K, KC, ctx.s, float(o[0]), float(o[1]),
                          float(o[2]), grid, table, METHOD_IDS[method], _STARTS[method], float(tol), int(max_iter),
                          float(delta), qs, q_start is not None, bool(limits), q, its, err, reason, ev)
    return q, its, err, reason == _SOLVED, reason, ev
