"""Compiled closed-loop forward kinematics of a kinematic tree with loops (``Robot.closed_fk``'s inner solve).

The tree is a Pinocchio model flattened into arrays (:class:`legkin.closed.Tree`): per joint its parent, kind
(:data:`REVOLUTE`, :data:`PRISMATIC` about/along a unit ``axis`` of the joint frame, :data:`SPHERICAL`: a unit
quaternion ``(x, y, z, w)`` in ``q``, its velocity the angular velocity in the joint frame, as Pinocchio), its
placement in the parent joint's frame (``R``, ``t``), and ``idx_q`` / ``idx_v``. Pinocchio numbers a parent before
its children, so one forward pass gives every joint's world placement ``oM_j = oM_parent place_j M(q_j)``.

A loop closes frame 1 (placement ``M1`` in joint ``j1``) on frame 2: residual ``[p1 - p2]`` (3d) and, for a 6d
loop, ``log3(R1 R2^T)`` (world axes): the two origins' distance (m) and the angle between the orientations (rad)
are the norms of its parts, so the solver's stopping test is the frames' own error. The Jacobian column of a joint
``k`` on the path of frame ``f`` (world axis ``w`` through the joint origin ``o_k``) is ``[w x (p_f - o_k); w]``
(revolute; each of the 3 axes of a spherical joint's frame) or ``[w; 0]`` (prismatic); the angular rows use
``d log3 ~ w1 - w2`` (exact at closure, where the iteration ends).

Gauss-Newton on the passive coordinates, minimum-norm steps ``dv = -J^T y``, ``J J^T y = r`` solved by an
``LDL^T`` factorisation that skips the zero pivots (the redundant rows of planar loops make ``J J^T`` singular),
halved while the residual grows. No LAPACK: numba's ``np.linalg`` needs SciPy, which legkin does not require.
"""

from __future__ import annotations

import numpy as np

from ._kernels import OK, kernel

REVOLUTE, PRISMATIC, SPHERICAL = 1, 2, 3
#: Status of a solve that stopped above the tolerance.
OPEN = 1
#: The solve iterates until the frames' error is below this, or stops decreasing (round-off), whatever ``tol``:
#: ``closed_fk``'s answers are then accurate to round-off, which central differences of it need.
POLISH = 1e-15


@kernel(inline=True)
def _mm3(a, b, out):
    """``out = a b`` for 3 x 3 matrices (explicit loops: numba's ``@`` calls BLAS, slow at this size)."""
    for i in range(3):
        for j in range(3):
            out[i, j] = a[i, 0] * b[0, j] + a[i, 1] * b[1, j] + a[i, 2] * b[2, j]


@kernel(inline=True)
def _mv3(a, v, out):
    for i in range(3):
        out[i] = a[i, 0] * v[0] + a[i, 1] * v[1] + a[i, 2] * v[2]


@kernel
def _rot_axis(axis, angle, out):  # Rodrigues
    c, s = np.cos(angle), np.sin(angle)
    x, y, z = axis[0], axis[1], axis[2]
    out[0, 0], out[0, 1], out[0, 2] = c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s
    out[1, 0], out[1, 1], out[1, 2] = y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s
    out[2, 0], out[2, 1], out[2, 2] = z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)


@kernel
def _rot_quat(x, y, z, w, out):
    out[0, 0], out[0, 1], out[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    out[1, 0], out[1, 1], out[1, 2] = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    out[2, 0], out[2, 1], out[2, 2] = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)


@kernel
def _fk(q, parent, kind, axis, place_r, place_t, idx_q, o_r, o_t, mats, vecs):
    """World placements ``(o_r[j], o_t[j])`` of every joint at ``q`` (``mats``, ``vecs``: work arrays)."""
    m, rp, v = mats[0], mats[1], vecs[0]
    for j in range(1, parent.shape[0]):
        p = parent[j]
        _mm3(o_r[p], place_r[j], rp)
        _mv3(o_r[p], place_t[j], v)
        for a in range(3):
            o_t[j, a] = v[a] + o_t[p, a]
        i = idx_q[j]
        if kind[j] == PRISMATIC:
            _mv3(rp, axis[j], v)
            for a in range(3):
                o_t[j, a] += v[a] * q[i]
                for b in range(3):
                    o_r[j, a, b] = rp[a, b]
            continue
        if kind[j] == REVOLUTE:
            _rot_axis(axis[j], q[i], m)
        else:
            _rot_quat(q[i], q[i + 1], q[i + 2], q[i + 3], m)
        _mm3(rp, m, o_r[j])


@kernel
def _log3(r, out):
    """The rotation vector of ``r`` (rad)."""
    c = min(1.0, max(-1.0, 0.5 * (r[0, 0] + r[1, 1] + r[2, 2] - 1.0)))
    theta = np.arccos(c)
    v0, v1, v2 = r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]
    if theta < 1e-6:
        f = 0.5 + theta * theta / 12.0
    elif theta > np.pi - 1e-6:  # the axis from the diagonal, its sign from the skew part
        for k in range(3):
            out[k] = theta * np.sqrt(max(0.0, (r[k, k] - c) / (1.0 - c)))
        if v0 * out[0] + v1 * out[1] + v2 * out[2] < 0.0:
            for k in range(3):
                out[k] = -out[k]
        return
    else:
        f = theta / (2.0 * np.sin(theta))
    out[0], out[1], out[2] = f * v0, f * v1, f * v2


@kernel
def _add_columns(jac, row, sign, j, p, parent, kind, axis, idx_v, o_r, o_t, angular, w):
    """Add ``sign`` times the columns of the joints on the path root -> ``j`` of a point ``p`` to ``jac`` (``w``: a
    work vector)."""
    while j > 0:
        v = idx_v[j]
        n = 3 if kind[j] == SPHERICAL else 1
        for c in range(n):
            if kind[j] == SPHERICAL:
                w[0], w[1], w[2] = o_r[j, 0, c], o_r[j, 1, c], o_r[j, 2, c]
            else:
                _mv3(o_r[j], axis[j], w)
            if kind[j] == PRISMATIC:
                for a in range(3):
                    jac[row + a, v + c] += sign * w[a]
                continue
            d0, d1, d2 = p[0] - o_t[j, 0], p[1] - o_t[j, 1], p[2] - o_t[j, 2]
            jac[row, v + c] += sign * (w[1] * d2 - w[2] * d1)
            jac[row + 1, v + c] += sign * (w[2] * d0 - w[0] * d2)
            jac[row + 2, v + c] += sign * (w[0] * d1 - w[1] * d0)
            if angular:
                for a in range(3):
                    jac[row + 3 + a, v + c] += sign * w[a]
        j = parent[j]


@kernel
def residual_jacobian(q, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six,
                      o_r, o_t, res, jac, mats, vecs):
    """The stacked loop residual ``res`` and its Jacobian ``jac`` (rows x nv) at ``q``; returns the worst loop
    error, max over loops of the origins' distance (m) and the orientations' angle (rad). ``mats`` (5, 3, 3) and
    ``vecs`` (4, 3): work arrays."""
    _fk(q, parent, kind, axis, place_r, place_t, idx_q, o_r, o_t, mats, vecs)
    jac[:, :] = 0.0
    row, worst = 0, 0.0
    e, p1, p2, w = vecs[0], vecs[1], vecs[2], vecs[3]
    r1, r2, rel = mats[2], mats[3], mats[4]
    for k in range(loop_j.shape[0]):
        j1, j2 = loop_j[k, 0], loop_j[k, 1]
        _mv3(o_r[j1], loop_t[k, 0], p1)
        _mv3(o_r[j2], loop_t[k, 1], p2)
        dist = 0.0
        for a in range(3):
            p1[a] += o_t[j1, a]
            p2[a] += o_t[j2, a]
            res[row + a] = p1[a] - p2[a]
            dist += res[row + a] ** 2
        worst = max(worst, np.sqrt(dist))
        six = loop_six[k]
        _add_columns(jac, row, 1.0, j1, p1, parent, kind, axis, idx_v, o_r, o_t, six, w)
        _add_columns(jac, row, -1.0, j2, p2, parent, kind, axis, idx_v, o_r, o_t, six, w)
        if six:
            _mm3(o_r[j1], loop_r[k, 0], r1)
            _mm3(o_r[j2], loop_r[k, 1], r2)
            _mm3(r1, r2.T, rel)
            _log3(rel, e)
            for a in range(3):
                res[row + 3 + a] = e[a]
            worst = max(worst, np.sqrt(e[0] ** 2 + e[1] ** 2 + e[2] ** 2))
        row += 6 if six else 3
    return worst


@kernel
def _integrate(q, dv, kind, idx_q, idx_v, out):
    for i in range(q.shape[0]):
        out[i] = q[i]
    for j in range(1, kind.shape[0]):
        i, v = idx_q[j], idx_v[j]
        if kind[j] != SPHERICAL:
            out[i] = q[i] + dv[v]
            continue
        a = np.sqrt(dv[v] ** 2 + dv[v + 1] ** 2 + dv[v + 2] ** 2)  # q (x) exp(dv): local angular step
        s = 0.5 if a < 1e-12 else np.sin(0.5 * a) / a
        bx, by, bz, bw = s * dv[v], s * dv[v + 1], s * dv[v + 2], np.cos(0.5 * a)
        x, y, z, w = q[i], q[i + 1], q[i + 2], q[i + 3]
        nx, ny = w * bx + x * bw + y * bz - z * by, w * by - x * bz + y * bw + z * bx
        nz, nw = w * bz + x * by - y * bx + z * bw, w * bw - x * bx - y * by - z * bz
        n = np.sqrt(nx * nx + ny * ny + nz * nz + nw * nw)
        out[i], out[i + 1], out[i + 2], out[i + 3] = nx / n, ny / n, nz / n, nw / n


@kernel
def _solve_psd(a, b, out):
    """A solution of ``a y = b`` for a positive semi-definite ``a`` (``LDL^T``, pivots below 1e-15 times the largest
    diagonal entry treated as 0: the redundant rows of planar loops): ``out = y``."""
    n = a.shape[0]
    low, d = np.zeros((n, n)), np.zeros(n)
    eps = 0.0
    for k in range(n):
        eps = max(eps, a[k, k])
    eps *= 1e-15
    for k in range(n):
        dk = a[k, k]
        for j in range(k):
            dk -= low[k, j] * low[k, j] * d[j]
        low[k, k] = 1.0
        if dk <= eps:
            continue
        d[k] = dk
        for i in range(k + 1, n):
            x = a[i, k]
            for j in range(k):
                x -= low[i, j] * low[k, j] * d[j]
            low[i, k] = x / dk
    for i in range(n):  # L z = b, then w = z / D (0 where D is), then L^T y = w
        x = b[i]
        for j in range(i):
            x -= low[i, j] * out[j]
        out[i] = x
    for i in range(n):
        out[i] = out[i] / d[i] if d[i] > 0.0 else 0.0
    for i in range(n - 1, -1, -1):
        x = out[i]
        for j in range(i + 1, n):
            x -= low[j, i] * out[j]
        out[i] = x


@kernel
def _step(jac, res, cols, jp, a, y, dv):
    """Minimum-norm Gauss-Newton step on the passive columns ``cols``: ``dv = -J^T y`` with ``J J^T y = r``
    (``jp``, ``a``, ``y``: work arrays of shapes (rows, len(cols)), (rows, rows), (rows,))."""
    rows, n = jp.shape
    for i in range(rows):
        for c in range(n):
            jp[i, c] = jac[i, cols[c]]
    for i in range(rows):
        for k in range(i + 1):
            x = 0.0
            for c in range(n):
                x += jp[i, c] * jp[k, c]
            a[i, k] = x
            a[k, i] = x
    _solve_psd(a, res, y)
    for v in range(dv.shape[0]):
        dv[v] = 0.0
    for c in range(n):
        x = 0.0
        for i in range(rows):
            x -= jp[i, c] * y[i]
        dv[cols[c]] = x


@kernel(inline=True)
def _passive_columns(passive):
    """The indices of the ``passive`` (True) velocity coordinates, in order (int64)."""
    n_free = 0
    for v in range(passive.shape[0]):
        n_free += 1 if passive[v] else 0
    cols, k = np.empty(n_free, dtype=np.int64), 0
    for v in range(passive.shape[0]):
        if passive[v]:
            cols[k] = v
            k += 1
    return cols


@kernel(entry=True)
def solve_passive(q, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six,
                  passive, tol, max_iter, q_out, info):
    """Close the loops from ``q`` moving the ``passive`` velocity coordinates only; ``q_out`` the result,
    ``info[0]`` the Gauss-Newton iterations done, ``info[1]`` the frames' worst error (m or rad).

    Returns:
        :data:`legkin._kernels.OK` when every loop's frames end within ``tol`` (m and rad), else :data:`OPEN`.
    """
    nj, nv, rows = parent.shape[0], passive.shape[0], 0
    for k in range(loop_six.shape[0]):
        rows += 6 if loop_six[k] else 3
    o_r, o_t = np.zeros((nj, 3, 3)), np.zeros((nj, 3))
    o_r[0] = np.eye(3)
    res, jac, dv = np.zeros(rows), np.zeros((rows, nv)), np.zeros(nv)
    res2, jac2, trial = np.zeros(rows), np.zeros((rows, nv)), np.empty_like(q)
    cols = _passive_columns(passive)
    n_free = cols.shape[0]
    jp, a, y = np.empty((rows, n_free)), np.empty((rows, rows)), np.empty(rows)
    mats, vecs = np.empty((5, 3, 3)), np.empty((4, 3))
    for i in range(q.shape[0]):
        q_out[i] = q[i]
    worst = residual_jacobian(q_out, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t,
                              loop_six, o_r, o_t, res, jac, mats, vecs)
    info[0], info[1] = 0.0, worst
    for it in range(max_iter):
        if worst <= POLISH:
            break
        _step(jac, res, cols, jp, a, y, dv)
        norm = np.sqrt(np.sum(res * res))
        reduced = False
        for _half in range(12):
            _integrate(q_out, dv, kind, idx_q, idx_v, trial)
            w2 = residual_jacobian(trial, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r,
                                   loop_t, loop_six, o_r, o_t, res2, jac2, mats, vecs)
            if np.sqrt(np.sum(res2 * res2)) < norm:
                reduced = True
                break
            for i in range(nv):
                dv[i] *= 0.5
        if not reduced:
            break  # round-off level (or a local minimum): the tolerance decides
        for i in range(q_out.shape[0]):
            q_out[i] = trial[i]
        res, res2 = res2, res
        jac, jac2 = jac2, jac
        worst = w2
        info[0], info[1] = it + 1.0, worst
    return OK if worst <= tol else OPEN


@kernel(entry=True)
def closed_jacobian_k(q, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six,
                      passive, motor_v, frame_j, frame_r, frame_t, out, placement):
    """The twist of a frame (joint ``frame_j``, placement ``frame_r``, ``frame_t``) per motor velocity through the
    loops, ``LOCAL_WORLD_ALIGNED`` (linear: the frame origin's velocity, world axes; angular: world axes), into
    ``out`` (6 x n_motors): ``J_f,m - J_f,p J_p^T (J_p J_p^T)^+ J_m`` (passive velocities of minimum norm);
    ``placement`` (4 x 4) receives the frame's world placement."""
    nj, nv, rows = parent.shape[0], passive.shape[0], 0
    for k in range(loop_six.shape[0]):
        rows += 6 if loop_six[k] else 3
    o_r, o_t = np.zeros((nj, 3, 3)), np.zeros((nj, 3))
    o_r[0] = np.eye(3)
    res, jac, jf = np.zeros(rows), np.zeros((rows, nv)), np.zeros((6, nv))
    mats, vecs = np.empty((5, 3, 3)), np.empty((4, 3))
    residual_jacobian(q, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six,
                      o_r, o_t, res, jac, mats, vecs)
    p, w = np.empty(3), np.empty(3)
    _mv3(o_r[frame_j], frame_t, p)
    for a in range(3):
        p[a] += o_t[frame_j, a]
    _add_columns(jf, 0, 1.0, frame_j, p, parent, kind, axis, idx_v, o_r, o_t, True, w)
    _mm3(o_r[frame_j], frame_r, mats[0])
    for a in range(3):
        for b in range(3):
            placement[a, b] = mats[0][a, b]
        placement[a, 3] = p[a]
        placement[3, a] = 0.0
    placement[3, 3] = 1.0
    cols = _passive_columns(passive)
    n_free = cols.shape[0]
    jp, a2, y = np.empty((rows, n_free)), np.empty((rows, rows)), np.empty(rows)
    dv, ddv = np.zeros(nv), np.empty(nv)
    for m in range(motor_v.shape[0]):
        for v in range(nv):
            dv[v] = 0.0
        for _refine in range(3):  # J_p dv_p = -J_m e_m, minimum norm; refined twice (J_p J_p^T squares the
            for i in range(rows):  # condition number: near a singularity one solve loses digits)
                x = jac[i, motor_v[m]]
                for c in range(n_free):
                    x += jac[i, cols[c]] * dv[cols[c]]
                res[i] = x
            _step(jac, res, cols, jp, a2, y, ddv)
            for v in range(nv):
                dv[v] += ddv[v]
        for r in range(6):
            x = jf[r, motor_v[m]]
            for c in range(n_free):
                x += jf[r, cols[c]] * dv[cols[c]]
            out[r, m] = x
