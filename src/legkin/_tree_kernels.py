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
halved, then damped (``J J^T + mu I``, ``mu`` growing), while the residual grows. ``J J^T`` is sparse: a
loop's rows only meet the columns of the joints that move its two frames, so its blocks are summed over the
columns two loops share, and loops that share none (two legs) leave zero blocks that its factor keeps outside its
envelope (:func:`_structure`). The Jacobian is assembled only at the configurations the iteration steps from (the
residual alone decides a trial step). No LAPACK: numba's ``np.linalg`` needs SciPy, which legkin does not
require.
"""

from __future__ import annotations

import numpy as np

from ._kernels import OK, kernel

REVOLUTE, PRISMATIC, SPHERICAL = 1, 2, 3
#: Status of a solve that stopped above the tolerance.
OPEN = 1
#: Status of a solve given a non-finite ``q`` or motor value (nothing solved).
BAD = 2
#: The solve iterates until the frames' error is below this (m and rad), or stops decreasing (round-off),
#: whatever ``tol``: Gauss-Newton converges quadratically, so the next step would move ``q`` by about this much
#: (``closed_fk``'s answers are then accurate to what central differences of it need, and no step is spent on
#: round-off).
FINE = 1e-14


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
def _residual(q, parent, kind, axis, place_r, place_t, idx_q, loop_j, loop_r, loop_t, loop_six, o_r, o_t, pts, res,
              mats, vecs):
    """Forward kinematics at ``q`` (``o_r``, ``o_t``), each loop's two frame origins (``pts[k, 0]``, ``pts[k, 1]``)
    and the stacked residual ``res``; returns the worst loop error, max over loops of the origins' distance (m) and
    the orientations' angle (rad). ``mats`` (5, 3, 3) and ``vecs`` (4, 3): work arrays."""
    _fk(q, parent, kind, axis, place_r, place_t, idx_q, o_r, o_t, mats, vecs)
    row, worst = 0, 0.0
    e, r1, r2, rel = vecs[0], mats[2], mats[3], mats[4]
    for k in range(loop_j.shape[0]):
        j1, j2, p1, p2 = loop_j[k, 0], loop_j[k, 1], pts[k, 0], pts[k, 1]
        _mv3(o_r[j1], loop_t[k, 0], p1)
        _mv3(o_r[j2], loop_t[k, 1], p2)
        dist = 0.0
        for a in range(3):
            p1[a] += o_t[j1, a]
            p2[a] += o_t[j2, a]
            res[row + a] = p1[a] - p2[a]
            dist += res[row + a] ** 2
        worst = max(worst, np.sqrt(dist))
        if loop_six[k]:
            _mm3(o_r[j1], loop_r[k, 0], r1)
            _mm3(o_r[j2], loop_r[k, 1], r2)
            _mm3(r1, r2.T, rel)
            _log3(rel, e)
            for a in range(3):
                res[row + 3 + a] = e[a]
            worst = max(worst, np.sqrt(e[0] ** 2 + e[1] ** 2 + e[2] ** 2))
        row += 6 if loop_six[k] else 3
    return worst


@kernel
def _jacobian(parent, kind, axis, idx_v, loop_j, loop_six, o_r, o_t, pts, jac, w):
    """The loops' Jacobian ``jac`` (rows x nv) at the state :func:`_residual` left (``w``: a work vector)."""
    jac[:, :] = 0.0
    row = 0
    for k in range(loop_j.shape[0]):
        six = loop_six[k]
        _add_columns(jac, row, 1.0, loop_j[k, 0], pts[k, 0], parent, kind, axis, idx_v, o_r, o_t, six, w)
        _add_columns(jac, row, -1.0, loop_j[k, 1], pts[k, 1], parent, kind, axis, idx_v, o_r, o_t, six, w)
        row += 6 if six else 3


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
def _structure(loop_j, loop_six, parent, kind, idx_v, passive, touch, lists, counts, row0, first):
    """The sparsity of the passive loop Jacobian ``J_p``: ``touch[k, v]`` (the passive column ``v`` moves a frame of
    loop ``k``: its joint is on a path root -> frame), ``lists[k, :counts[k]]`` those columns, ``row0[k]`` loop
    ``k``'s first row, ``first[i]`` the first row of the first loop sharing a column with row ``i``'s loop: the
    envelope of ``J_p J_p^T``, which its ``LDL^T`` factor keeps."""
    row = 0
    for k in range(loop_j.shape[0]):
        touch[k, :] = False
        counts[k] = 0
        row0[k] = row
        row += 6 if loop_six[k] else 3
        for s in range(2):
            j = loop_j[k, s]
            while j > 0:
                for c in range(3 if kind[j] == SPHERICAL else 1):
                    v = idx_v[j] + c
                    if passive[v] and not touch[k, v]:
                        touch[k, v] = True
                        lists[k, counts[k]] = v
                        counts[k] += 1
                j = parent[j]
    for k in range(loop_j.shape[0]):
        f = k
        for m in range(k):
            for c in range(counts[k]):
                if touch[m, lists[k, c]]:
                    f = m
                    break
            if f < k:
                break
        for i in range(6 if loop_six[k] else 3):
            first[row0[k] + i] = row0[f]


@kernel(inline=True)
def _sparsity(loop_j, loop_six, parent, kind, idx_v, passive):
    """:func:`_structure`'s arrays, allocated and filled: ``(touch, lists, counts, row0, first, rows)``."""
    nl, nv = loop_j.shape[0], passive.shape[0]
    touch, lists = np.empty((nl, nv), dtype=np.bool_), np.empty((nl, nv), dtype=np.int64)
    counts, row0 = np.empty(nl, dtype=np.int64), np.empty(nl, dtype=np.int64)
    rows = 0
    for k in range(nl):
        rows += 6 if loop_six[k] else 3
    first = np.empty(rows, dtype=np.int64)
    _structure(loop_j, loop_six, parent, kind, idx_v, passive, touch, lists, counts, row0, first)
    return touch, lists, counts, row0, first, rows


@kernel
def _gram(jac, loop_six, touch, lists, counts, row0, a):
    """``a = J_p J_p^T`` from the loops' shared columns only (:func:`_structure`; unsigned indices, see
    :func:`_solve_psd`)."""
    a[:, :] = 0.0
    for k in range(row0.shape[0]):
        nk, rk = (6 if loop_six[k] else 3), np.uint64(row0[k])
        for m in range(k + 1):
            nm, rm = (6 if loop_six[m] else 3), np.uint64(row0[m])
            for c in range(counts[k]):
                v = np.uint64(lists[k, c])
                if touch[m, v]:
                    for i in range(np.uint64(nk)):
                        x = jac[rk + i, v]
                        for i2 in range(np.uint64(nm)):
                            a[rk + i, rm + i2] += x * jac[rm + i2, v]
            if m < k:
                for i in range(np.uint64(nk)):
                    for i2 in range(np.uint64(nm)):
                        a[rm + i2, rk + i] = a[rk + i, rm + i2]


@kernel
def _solve_psd(a, b, first, d, ld, out):
    """A solution of ``a y = b`` for a positive semi-definite ``a`` whose row ``i`` is zero left of ``first[i]``:
    ``out = y``. ``LDL^T`` within that envelope, ``L`` in place in ``a``'s lower triangle, ``ld = L D`` kept
    (rows x rows) so that each entry is one plain dot product; pivots below 1e-15 times the largest diagonal entry
    are treated as 0 (the redundant rows of planar loops). ``d``: a work vector. (The inner loops run over unsigned
    indices: numba checks a signed index for a negative, wrap-around value at each access, which halves the speed
    of these loops.)"""
    n, one = np.uint64(a.shape[0]), np.uint64(1)
    eps = 0.0
    for k in range(n):
        eps = max(eps, a[k, k])
    eps *= 1e-15
    for k in range(n):
        fk = first[k]
        dk = a[k, k]
        for j in range(np.uint64(fk), np.uint64(k)):
            dk -= a[k, j] * ld[k, j]
        d[k] = dk if dk > eps else 0.0
        for i in range(k + one, n):
            if first[i] > k:
                continue
            x = 0.0
            if d[k] > 0.0:
                x = a[i, k]
                for j in range(np.uint64(max(first[i], fk)), np.uint64(k)):
                    x -= a[i, j] * ld[k, j]
            ld[i, k] = x
            a[i, k] = x / dk if d[k] > 0.0 else 0.0
    for i in range(n):  # L z = b, then w = z / D (0 where D is), then L^T y = w
        x = b[i]
        for j in range(np.uint64(first[i]), i):
            x -= a[i, j] * out[j]
        out[i] = x
    for i in range(n):
        out[i] = out[i] / d[i] if d[i] > 0.0 else 0.0
    for jj in range(one, n):
        j = n - jj
        x = out[j]
        for i in range(np.uint64(first[j]), j):
            out[i] -= a[j, i] * x


@kernel
def _step(jac, res, loop_six, touch, lists, counts, row0, first, mu, a, ld, d, y, dv):
    """Minimum-norm Gauss-Newton step on the passive columns: ``dv = -J_p^T y`` with ``(J_p J_p^T + mu m I) y = r``
    (``m`` the largest diagonal entry of ``J_p J_p^T``; ``mu`` = 0: Gauss-Newton, ``mu`` > 0: a damped step, a
    descent direction even where ``J_p`` is rank-deficient and ``r`` outside its range); the structure from
    :func:`_structure`; ``a``, ``ld`` (rows x rows), ``d``, ``y`` (rows,): work arrays."""
    _gram(jac, loop_six, touch, lists, counts, row0, a)
    if mu > 0.0:
        m = 0.0
        for i in range(a.shape[0]):
            m = max(m, a[i, i])
        for i in range(a.shape[0]):
            a[i, i] += mu * m
    _solve_psd(a, res, first, d, ld, y)
    dv[:] = 0.0
    for k in range(row0.shape[0]):
        for c in range(counts[k]):
            v, x = lists[k, c], 0.0
            for i in range(row0[k], row0[k] + (6 if loop_six[k] else 3)):
                x += jac[i, v] * y[i]
            dv[v] -= x


@kernel(inline=True)
def _unpack(ints, floats, flags):
    """The tree's arrays, views of the three that :func:`legkin.closed.pack` makes (one argument each instead of
    thirteen: numba's dispatch of a call costs about 60 ns an argument): ``ints`` = ``[nj, nl, nm]``, ``parent``,
    ``kind``, ``idx_q``, ``idx_v`` (nj each), ``loop_j`` (nl x 2), ``motor_q`` (nm); ``floats`` = ``axis``
    (nj x 3), ``place_r`` (nj x 3 x 3), ``place_t`` (nj x 3), ``loop_r`` (nl x 2 x 3 x 3), ``loop_t`` (nl x 2 x 3);
    ``flags`` = ``passive`` (nv), ``loop_six`` (nl)."""
    nj, nl, nm = ints[0], ints[1], ints[2]
    o = 3 + 4 * nj + 2 * nl
    nv = flags.shape[0] - nl
    return (ints[3:3 + nj], ints[3 + nj:3 + 2 * nj], floats[:3 * nj].reshape((nj, 3)),
            floats[3 * nj:12 * nj].reshape((nj, 3, 3)), floats[12 * nj:15 * nj].reshape((nj, 3)),
            ints[3 + 2 * nj:3 + 3 * nj], ints[3 + 3 * nj:3 + 4 * nj], ints[3 + 4 * nj:o].reshape((nl, 2)),
            floats[15 * nj:15 * nj + 18 * nl].reshape((nl, 2, 3, 3)),
            floats[15 * nj + 18 * nl:15 * nj + 24 * nl].reshape((nl, 2, 3)), flags[nv:], flags[:nv], ints[o:o + nm])


@kernel(entry=True)
def solve_passive(q, motors, ints, floats, flags, tol, max_iter, q_out, info):
    """Close the loops from ``q`` with the motors (``q[motor_q]``) set to ``motors`` (none: empty arrays) moving the
    ``passive`` velocity coordinates only (the tree packed by :func:`legkin.closed.pack`, see :func:`_unpack`);
    ``q_out`` the result, ``info`` the Gauss-Newton iterations, the frames' worst error (m or rad) and the residual
    evaluations (:func:`_solve`).

    Returns:
        :data:`legkin._kernels.OK` when every loop's frames end within ``tol`` (m and rad), :data:`OPEN` if not,
        :data:`BAD` for a non-finite ``q`` or ``motors`` (nothing solved).
    """
    parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six, passive, motor_q = _unpack(
        ints, floats, flags)
    for i in range(q.shape[0]):
        if not np.isfinite(q[i]):
            return BAD
        q_out[i] = q[i]
    for i in range(motors.shape[0]):
        if not np.isfinite(motors[i]):
            return BAD
        q_out[motor_q[i]] = motors[i]
    worst = _solve(q_out, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six,
                   passive, tol, max_iter, info)
    return OK if worst <= tol else OPEN


@kernel
def _solve(q_out, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six, passive,
           tol, max_iter, info):
    """Minimum-norm Gauss-Newton on the ``passive`` coordinates from ``q_out``, in place; returns the frames' worst
    error (m or rad). A step that does not reduce the residual is halved, up to 5 times (near a singularity the
    Gauss-Newton direction is still the one to follow), then damped (:func:`_step`), more and more, until one does
    (not once the loops are within ``tol``: a step that no longer reduces the error is round-off); the
    Jacobian is assembled only where the iteration goes on. It stops at :data:`FINE` (quadratic convergence: the
    next step would change ``q`` by about the error), or when no step reduces the residual."""
    nj, nl, nv = parent.shape[0], loop_j.shape[0], passive.shape[0]
    touch, lists, counts, row0, first, rows = _sparsity(loop_j, loop_six, parent, kind, idx_v, passive)
    o_r, o_t, pts, res = np.empty((2, nj, 3, 3)), np.zeros((2, nj, 3)), np.empty((2, nl, 2, 3)), np.empty((2, rows))
    o_r[:, 0] = np.eye(3)
    jac, a, ld, dy = np.empty((rows, nv)), np.empty((rows, rows)), np.empty((rows, rows)), np.empty((2, rows))
    dv, trial, mats, vecs = np.empty(nv), np.empty_like(q_out), np.empty((5, 3, 3)), np.empty((4, 3))
    s = 0  # the state of q_out: o_r[s], o_t[s], pts[s], res[s]; 1 - s: the trial's
    worst = _residual(q_out, parent, kind, axis, place_r, place_t, idx_q, loop_j, loop_r, loop_t, loop_six, o_r[s],
                      o_t[s], pts[s], res[s], mats, vecs)
    info[0], info[1], info[2] = 0.0, worst, 1.0
    for it in range(max_iter):
        if worst <= FINE:
            break
        _jacobian(parent, kind, axis, idx_v, loop_j, loop_six, o_r[s], o_t[s], pts[s], jac, vecs[3])
        norm, reduced, w2 = np.sqrt(np.sum(res[s] ** 2)), False, worst
        for k in range(16):  # Gauss-Newton, halved 5 times, then damped steps (damping 1e-9 to 10, relative)
            if k == 0 or k > 5:
                _step(jac, res[s], loop_six, touch, lists, counts, row0, first, 0.0 if k == 0 else 10.0 ** (k - 15),
                      a, ld, dy[0], dy[1], dv)
            else:
                dv *= 0.5
            _integrate(q_out, dv, kind, idx_q, idx_v, trial)
            w2 = _residual(trial, parent, kind, axis, place_r, place_t, idx_q, loop_j, loop_r, loop_t, loop_six,
                           o_r[1 - s], o_t[1 - s], pts[1 - s], res[1 - s], mats, vecs)
            info[2] += 1.0
            reduced = np.sqrt(np.sum(res[1 - s] ** 2)) < norm
            if reduced or worst <= tol:
                break
        if not reduced:
            break  # round-off level (or a local minimum): the tolerance decides
        q_out[:] = trial
        s, worst = 1 - s, w2
        info[0], info[1] = it + 1.0, worst
    return worst


@kernel(entry=True)
def closed_jacobian_k(q, parent, kind, axis, place_r, place_t, idx_q, idx_v, loop_j, loop_r, loop_t, loop_six,
                      passive, motor_v, frame_j, frame_r, frame_t, out, placement):
    """The twist of a frame (joint ``frame_j``, placement ``frame_r``, ``frame_t``) per motor velocity through the
    loops, ``LOCAL_WORLD_ALIGNED`` (linear: the frame origin's velocity, world axes; angular: world axes), into
    ``out`` (6 x n_motors): ``J_f,m - J_f,p J_p^T (J_p J_p^T)^+ J_m`` (passive velocities of minimum norm);
    ``placement`` (4 x 4) receives the frame's world placement."""
    nj, nl, nv = parent.shape[0], loop_j.shape[0], passive.shape[0]
    touch, lists, counts, row0, first, rows = _sparsity(loop_j, loop_six, parent, kind, idx_v, passive)
    o_r, o_t, pts = np.zeros((nj, 3, 3)), np.zeros((nj, 3)), np.empty((nl, 2, 3))
    o_r[0] = np.eye(3)
    res, jac, jf = np.zeros(rows), np.zeros((rows, nv)), np.zeros((6, nv))
    mats, vecs = np.empty((5, 3, 3)), np.empty((4, 3))
    _residual(q, parent, kind, axis, place_r, place_t, idx_q, loop_j, loop_r, loop_t, loop_six, o_r, o_t, pts, res,
              mats, vecs)
    _jacobian(parent, kind, axis, idx_v, loop_j, loop_six, o_r, o_t, pts, jac, vecs[3])
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
    a2, ld, d, y = np.empty((rows, rows)), np.empty((rows, rows)), np.empty(rows), np.empty(rows)
    dv, ddv = np.zeros(nv), np.empty(nv)
    for m in range(motor_v.shape[0]):
        dv[:] = 0.0
        for _refine in range(3):  # J_p dv_p = -J_m e_m, minimum norm; refined twice (J_p J_p^T squares the
            for i in range(rows):  # condition number: near a singularity one solve loses digits)
                x = jac[i, motor_v[m]]
                for c in range(nv):
                    if passive[c]:
                        x += jac[i, c] * dv[c]
                res[i] = x
            _step(jac, res, loop_six, touch, lists, counts, row0, first, 0.0, a2, ld, d, y, ddv)
            dv += ddv
        for r in range(6):
            x = jf[r, motor_v[m]]
            for c in range(nv):
                if passive[c]:
                    x += jf[r, c] * dv[c]
            out[r, m] = x
