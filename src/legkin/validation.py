"""``legkin check``: analytic kinematics against Pinocchio, one row per comparison."""

from __future__ import annotations

import importlib
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._registry import get_spec, list_models

__all__ = ["CheckResult", "compare", "run_checks", "format_table", "write_json"]


@dataclass(frozen=True)
class CheckResult:
    """One row of ``legkin check``.

    Attributes:
        name: what was compared (e.g. ``"LF foot position"``).
        samples: how many samples were compared.
        max_error, p99_error: largest and 99th-percentile error over the samples.
        tolerance: the bound every sample must meet.
        passed: ``max_error <= tolerance`` and no sample was NaN.
    """

    name: str
    samples: int
    max_error: float
    p99_error: float
    tolerance: float
    passed: bool
    errors: np.ndarray = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict:
        """The JSON row (per-sample errors left out)."""
        return {k: getattr(self, k) for k in ("name", "samples", "max_error", "p99_error", "tolerance", "passed")}


def compare(name: str, errors, tolerance: float) -> CheckResult:
    """Summarise per-sample errors (any shape; NaN counts as a failure) into a row."""
    e = np.abs(np.asarray(errors, dtype=float)).ravel()
    if e.size == 0:
        return CheckResult(name, 0, float("nan"), float("nan"), tolerance, False, e)
    finite = bool(np.all(np.isfinite(e)))
    emax = float(np.max(e)) if finite else float("nan")
    p99 = float(np.percentile(e, 99)) if finite else float("nan")
    return CheckResult(name, int(e.size), emax, p99, tolerance, finite and emax <= tolerance, e)


def per_sample(diff, axis=-1):
    """Euclidean norm of a difference along ``axis`` (per-sample error)."""
    return np.linalg.norm(np.asarray(diff, dtype=float), axis=axis)


def run_checks(models: list[str] | None = None, samples: int = 10_000, seed: int = 0):
    """Run every check of each model; returns ``{model: (rows, seconds)}``."""
    out = {}
    for name in models or list_models():
        spec = get_spec(name)
        rng = np.random.default_rng(seed)
        t0 = time.perf_counter()
        rows = importlib.import_module(spec.checks).run(samples, rng)
        out[name] = (rows, time.perf_counter() - t0)
    return out


def format_table(results) -> str:
    lines = []
    for name, (rows, seconds) in results.items():
        lines.append(f"{name}  ({seconds:.1f} s)")
        width = max([len(r.name) for r in rows] + [5])
        lines.append(f"  {'check':<{width}}  {'samples':>8}  {'max error':>10}  {'p99 error':>10}  {'tolerance':>9}  result")
        for r in rows:
            lines.append(
                f"  {r.name:<{width}}  {r.samples:>8d}  {r.max_error:>10.2e}  {r.p99_error:>10.2e}  "
                f"{r.tolerance:>9.0e}  {'pass' if r.passed else 'FAIL'}"
            )
        lines.append("")
    return "\n".join(lines)


def all_passed(results) -> bool:
    return all(r.passed for rows, _ in results.values() for r in rows)


def write_json(results, path: str | Path) -> None:
    doc = {
        "passed": all_passed(results),
        "models": {
            name: {"seconds": seconds, "checks": [r.as_dict() for r in rows]}
            for name, (rows, seconds) in results.items()
        },
    }
    Path(path).write_text(json.dumps(doc, indent=2, allow_nan=True) + "\n")


def pinocchio_frames(robot, qs, frames: list[str], jacobians: bool = False):
    """Pinocchio's world placements (and LOCAL_WORLD_ALIGNED Jacobians) of ``frames`` for each row of ``qs``.

    Returns:
        ``(positions (N, F, 3), rotations (N, F, 3, 3))``, plus ``jacobians (N, F, 6, nv)`` if asked.
    """
    import pinocchio as pin

    model, data = robot.model, robot.data
    ids = [robot.frame_id(f) for f in frames]
    n = len(qs)
    pos = np.empty((n, len(ids), 3))
    rot = np.empty((n, len(ids), 3, 3))
    jac = np.empty((n, len(ids), 6, model.nv)) if jacobians else None
    for i, q in enumerate(qs):
        if jacobians:
            pin.computeJointJacobians(model, data, q)
        else:
            pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        for k, fid in enumerate(ids):
            pos[i, k] = data.oMf[fid].translation
            rot[i, k] = data.oMf[fid].rotation
            if jacobians:
                jac[i, k] = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
    return (pos, rot, jac) if jacobians else (pos, rot)


def sample_within_limits(robot, n: int, rng: np.random.Generator, joints: list[str] | None = None) -> np.ndarray:
    """``n`` configurations: ``q0`` with the given 1-DOF joints (default: all) drawn uniformly in their limits."""
    model = robot.model
    qs = np.tile(robot.q0, (n, 1))
    for name in joints or robot.joint_names:
        j = model.joints[robot.joint_id(name)]
        if j.nq != 1:
            continue
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        qs[:, j.idx_q] = rng.uniform(lo, hi, n)
    return qs
