"""Bench modules, one per model: ``build(n, rng, quick) -> legkin.bench.ModelBench``; shared helpers here."""

from __future__ import annotations

import contextlib
import importlib.util
import os
import sys

import numpy as np

__all__ = ["missing", "quiet_stdout", "pinocchio_positions", "levenberg_marquardt", "rotation_error", "SOLVE_TOL"]

#: A target counts as solved when the method's result is within this distance (m or rad) of it.
SOLVE_TOL = 1e-9


#: Peers outside the ``bench`` extra, with why (pip would build them from source where no wheel exists).
NOT_IN_EXTRA = {"pytracik": "not in the bench extra: needs Boost, Eigen, orocos-KDL and NLopt where no wheel exists"}


def missing(dist: str, module: str | None = None) -> str | None:
    """None if ``module`` (default: ``dist``) imports, else the skip reason naming the install command."""
    if importlib.util.find_spec(module or dist) is None:
        if dist in NOT_IN_EXTRA:
            return f"{dist} is not installed (pip install {dist}; {NOT_IN_EXTRA[dist]})"
        return f"{dist} is not installed (pip install {dist}, or pip install -e '.[bench]')"
    return None


@contextlib.contextmanager
def quiet_stdout():
    """Silence C/C++ code printing to file descriptor 1 (e.g. KDL's URDF parser warnings)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def pinocchio_positions(model, data, frame_id: int, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World position (N, 3) and rotation (N, 3, 3) of one frame for each configuration row of ``qs``.

    Rows containing NaN give NaN.
    """
    import pinocchio as pin

    n = len(qs)
    pos = np.full((n, 3), np.nan)
    rot = np.full((n, 3, 3), np.nan)
    finite = np.all(np.isfinite(qs), axis=-1)
    for i in np.flatnonzero(finite):
        pin.framesForwardKinematics(model, data, qs[i])
        oMf = data.oMf[frame_id]
        pos[i] = oMf.translation
        rot[i] = oMf.rotation
    return pos, rot


def levenberg_marquardt(model, residual_and_jacobian, q: np.ndarray, free: np.ndarray, tol: float, max_iter: int):
    """The iteration of :meth:`legkin.Robot.solve_loops` on any stacked residual (Pinocchio-only solvers).

    Each iteration tries the Gauss-Newton step ``dq = -pinv(J_free) r``, then damped steps
    ``-(J^T J + mu I)^-1 J^T r`` with growing ``mu`` until ``|r|`` decreases; stops at ``|r| <= tol``.

    Returns:
        ``(q, iterations, residual evaluations, converged)``.
    """
    import pinocchio as pin

    r, jac = residual_and_jacobian(q)
    evals = 1
    err = float(np.linalg.norm(r))
    mu = 1e-6
    for it in range(max_iter + 1):
        if err <= tol:
            return q, it, evals, True
        if it == max_iter:
            break
        jf = jac[:, free]
        steps = [-np.linalg.pinv(jf, rcond=1e-12) @ r]
        jtj, jtr = jf.T @ jf, jf.T @ r
        for k in range(12):
            steps.append(-np.linalg.solve(jtj + mu * 10.0**k * np.eye(jf.shape[1]), jtr))
        for step in steps:
            dq = np.zeros(model.nv)
            dq[free] = step
            q_new = pin.integrate(model, q, dq)
            r_new, jac_new = residual_and_jacobian(q_new)
            evals += 1
            err_new = float(np.linalg.norm(r_new))
            if err_new < err:
                break
        else:
            break
        q, r, jac, err = q_new, r_new, jac_new, err_new
    return q, it, evals, False


def rotation_error(r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """Geodesic angle (rad) between rotation matrices (..., 3, 3); NaN where either is NaN."""
    rel = np.einsum("...ji,...jk->...ik", r1, r2)
    tr = np.trace(rel, axis1=-2, axis2=-1)
    # atan2 form: accurate near 0 (acos of the trace loses half the digits)
    skew = np.stack(
        [rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0], rel[..., 1, 0] - rel[..., 0, 1]], -1
    )
    return np.arctan2(0.5 * np.linalg.norm(skew, axis=-1), 0.5 * (tr - 1.0))
