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
    """:func:`legkin.loops.levenberg_marquardt` (the iteration of ``Robot.solve_loops``) on any residual.

    Returns:
        ``(q, iterations, residual evaluations, converged)``.
    """
    from .loops import levenberg_marquardt as lm

    return lm(model, residual_and_jacobian, q, free, tol, max_iter)[:4]


def sizes(n: int | None, quick: bool, full: tuple[int, int, int], small: tuple[int, int, int]) -> tuple[int, int, int]:
    """(batch targets, scalar-loop targets, iterative-solver targets): ``full`` or, with ``quick``, ``small``;
    ``n`` overrides the batch size and caps the others."""
    batch, scalar, iterative = small if quick else full
    n = n or batch
    return n, min(n, scalar), min(n, iterative)


def rotation_error(r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """Geodesic angle (rad) between rotation matrices (..., 3, 3); NaN where either is NaN."""
    rel = np.einsum("...ji,...jk->...ik", r1, r2)
    tr = np.trace(rel, axis1=-2, axis2=-1)
    # atan2 form: accurate near 0 (acos of the trace loses half the digits)
    skew = np.stack(
        [rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0], rel[..., 1, 0] - rel[..., 0, 1]], -1
    )
    return np.arctan2(0.5 * np.linalg.norm(skew, axis=-1), 0.5 * (tr - 1.0))
