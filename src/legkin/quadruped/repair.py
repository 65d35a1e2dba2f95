"""The clip-into-limits repair of :func:`legkin.quadruped.ik`: a branch a hair outside the joint limits is
clipped onto them and the other joints re-solved by Gauss-Newton on the foot position (rare path).

A branch may come back up to :data:`~legkin.quadruped.LIMIT_SLACK` outside the limits: targets made at a limit
return a rounding error outside it, and near the abduction singularity (rho -> 0) the joints err by up to
~rho / y12 along the singular direction while the foot stays exact. The repaired branch is kept only if it
reproduces the target within :data:`~legkin.quadruped.CLIP_TOL`.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels import kernel
from .constants import CLIP_TOL, HI, LO, RCOND
from .forward import _foot_k, _jacobian_k


@kernel
def _pinv_solve_k(a, r, step) -> None:
    """``step = pinv(a) r`` for a (3, 3) matrix ``a`` (overwritten), numpy's ``rcond`` = :data:`RCOND`.

    One-sided Jacobi SVD (Hestenes): column rotations ``a V`` until the columns are orthogonal, then
    ``a V = U S`` and ``pinv(a) r = sum_k V_k (A_k . r) / s_k^2`` over the singular values ``s_k > rcond max s``.
    """
    v = np.eye(3)
    for _sweep in range(60):
        rotated = False
        for i in range(2):
            for j in range(i + 1, 3):
                alpha = a[0, i] * a[0, i] + a[1, i] * a[1, i] + a[2, i] * a[2, i]
                beta = a[0, j] * a[0, j] + a[1, j] * a[1, j] + a[2, j] * a[2, j]
                gamma = a[0, i] * a[0, j] + a[1, i] * a[1, j] + a[2, i] * a[2, j]
                if gamma == 0.0 or abs(gamma) <= 1e-17 * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for k in range(3):
                    ai, aj = a[k, i], a[k, j]
                    a[k, i], a[k, j] = c * ai - s * aj, s * ai + c * aj
                    vi, vj = v[k, i], v[k, j]
                    v[k, i], v[k, j] = c * vi - s * vj, s * vi + c * vj
        if not rotated:
            break
    s2 = np.empty(3)
    big = 0.0
    for k in range(3):
        s2[k] = a[0, k] * a[0, k] + a[1, k] * a[1, k] + a[2, k] * a[2, k]
        big = max(big, s2[k])
    cut = RCOND * RCOND * big  # s_k > rcond max s  <=>  s_k^2 > rcond^2 max s^2
    step[0] = step[1] = step[2] = 0.0
    for k in range(3):
        if s2[k] > cut and s2[k] > 0.0:
            w = (a[0, k] * r[0] + a[1, k] * r[1] + a[2, k] * r[2]) / s2[k]
            step[0] += v[0, k] * w
            step[1] += v[1, k] * w
            step[2] += v[2, k] * w


@kernel
def _clip_repair_k(qc, q, p, li, foot_z, best) -> bool:
    """Branch ``q`` (3,) clipped into the limits (``qc``, modified): re-solve the unclipped joints for the foot ``p``.

    Up to three Gauss-Newton steps on the foot position over the joints that clipping left alone (the clipped
    ones stay on their limit), keeping the best iterate (the clipped branch itself when clipping moved it by a
    rounding error only). Near the abduction singularity the branch's error lies along the singular direction
    of the Jacobian, which the free joints absorb. Writes the joints (inside the limits) into ``best`` and
    returns whether they reproduce ``p`` within :data:`CLIP_TOL`.
    """
    free = np.empty(3, dtype=np.bool_)
    for k in range(3):
        free[k] = qc[k] == q[k]
    best_err = np.inf
    jac = np.empty((3, 3))
    r = np.empty(3)
    step = np.empty(3)
    for it in range(4):
        fx, fy, fz = _foot_k(qc[0], qc[1], qc[2], li, foot_z)
        r[0], r[1], r[2] = p[0] - fx, p[1] - fy, p[2] - fz
        err = np.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
        if err < best_err:  # keep the best iterate: near rho -> 0 a step can only add rounding
            best_err = err
            best[0], best[1], best[2] = qc[0], qc[1], qc[2]
        if it == 3 or best_err <= 0.5 * CLIP_TOL:
            break
        _jacobian_k(qc[0], qc[1], qc[2], li, foot_z, jac)
        for k in range(3):
            if not free[k]:
                jac[0, k] = jac[1, k] = jac[2, k] = 0.0
        _pinv_solve_k(jac, r, step)
        for k in range(3):
            moved = qc[k] + step[k]
            qc[k] = min(max(moved, LO[k]), HI[k])
            free[k] = free[k] and qc[k] == moved  # a joint pushed onto its limit by the step stays there
    return best_err <= CLIP_TOL


@kernel(inline=True)
def _clipped_k(q1, q2, q3, p, li, foot_z):
    """A branch a hair outside the limits, clipped into them and repaired (:func:`_clip_repair_k`):
    (kept, q1, q2, q3). The rare path: its scratch arrays are allocated here."""
    q = np.empty(3)
    q[0], q[1], q[2] = q1, q2, q3
    qc = np.empty(3)
    for j in range(3):
        qc[j] = min(max(q[j], LO[j]), HI[j])
    fixed = np.empty(3)
    good = _clip_repair_k(qc, q, p, li, foot_z, fixed)
    return good, fixed[0], fixed[1], fixed[2]
