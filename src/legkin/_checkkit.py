"""The toolkit of the mechanisms' check modules: a check row (:class:`CheckResult`) and how one is made from
per-sample errors, Pinocchio's frames as the reference, in-limit samples, and the IK contract row.

``legkin check`` (:mod:`legkin.validation`) runs the rows; the mechanisms' ``checks`` modules and the MuJoCo
export's (:mod:`legkin.mjcf.checks`) make them from this module.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Iterable

import numpy as np

__all__ = [
    "CheckResult",
    "compare",
    "per_sample",
    "pinocchio_frames",
    "sample_within_limits",
    "REASONS",
    "IKRobustness",
    "classify_failures",
    "robustness_row",
]


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
    errors: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: the counts of an IK robustness row (:class:`IKRobustness`), else None.
    counts: object = field(default=None, repr=False, compare=False)

    def as_dict(self) -> dict[str, Any]:
        """The JSON row (per-sample errors left out)."""
        row = {k: getattr(self, k) for k in ("name", "samples", "max_error", "p99_error", "tolerance", "passed")}
        if self.counts is not None:
            row["counts"] = dict(vars(self.counts))
        return row


def compare(name: str, errors: Any, tolerance: float) -> CheckResult:
    """Summarise per-sample errors (any shape; NaN counts as a failure) into a row.

    Args:
        name: the row's name.
        errors: the per-sample errors (array-like of any shape; m, rad or the quantity's unit).
        tolerance: the bound every sample must meet (same unit).

    Returns:
        The row: passed when every error is finite and at most ``tolerance``.
    """
    e = np.abs(np.asarray(errors, dtype=float)).ravel()
    if e.size == 0:
        return CheckResult(name, 0, float("nan"), float("nan"), tolerance, False, e)
    finite = bool(np.all(np.isfinite(e)))
    emax = float(np.max(e)) if finite else float("nan")
    p99 = float(np.percentile(e, 99)) if finite else float("nan")
    return CheckResult(name, int(e.size), emax, p99, tolerance, finite and emax <= tolerance, e)


def per_sample(diff: Any, axis: int = -1) -> np.ndarray:
    """Euclidean norm of a difference along ``axis`` (per-sample error).

    Args:
        diff: the differences (array-like; m or rad).
        axis: the axis of the vector components.

    Returns:
        The norms, ``diff``'s shape without ``axis`` (same unit).
    """
    norms: np.ndarray = np.linalg.norm(np.asarray(diff, dtype=float), axis=axis)
    return norms


def pinocchio_frames(robot: Any, qs: np.ndarray, frames: list[str], jacobians: bool = False) -> tuple[np.ndarray, ...]:
    """Pinocchio's world placements (and LOCAL_WORLD_ALIGNED Jacobians) of ``frames`` for each row of ``qs``.

    Args:
        robot: a loaded :class:`legkin.Robot`.
        qs: ``(N, nq)`` configurations (rad, m).
        frames: the frames' names.
        jacobians: also return the frame Jacobians.

    Returns:
        ``(positions (N, F, 3), rotations (N, F, 3, 3))``, plus ``jacobians (N, F, 6, nv)`` if asked.
    """
    import pinocchio as pin

    model, data = robot.model, robot.data
    ids = [robot.frame_id(f) for f in frames]
    n = len(qs)
    pos = np.empty((n, len(ids), 3))
    rot = np.empty((n, len(ids), 3, 3))
    jac = np.empty((n, len(ids), 6, model.nv if jacobians else 0))
    for i, q in enumerate(qs):
        if jacobians:
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            placements = np.array([data.oMf[fid].homogeneous for fid in ids])
            for k, fid in enumerate(ids):
                jac[i, k] = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        else:  # only the frames asked, one Pinocchio call each (3-4x faster than copying them out of data.oMf)
            pin.forwardKinematics(model, data, q)
            placements = np.array([pin.updateFramePlacement(model, data, fid).homogeneous for fid in ids])
        pos[i] = placements[:, :3, 3]
        rot[i] = placements[:, :3, :3]
    return (pos, rot, jac) if jacobians else (pos, rot)


def sample_within_limits(robot: Any, n: int, rng: np.random.Generator, joints: list[str] | None = None) -> np.ndarray:
    """``n`` configurations: ``q0`` with the given 1-DOF joints (default: all) drawn uniformly in their limits.

    Args:
        robot: a loaded :class:`legkin.Robot`.
        n: how many configurations.
        rng: the random generator.
        joints: the joints to draw (default: every joint; those that are not 1-DOF keep their ``q0`` value).

    Returns:
        ``(n, nq)`` configurations (rad, m).
    """
    model = robot.model
    qs = np.tile(robot.q0, (n, 1))
    for name in joints or robot.joint_names:
        j = model.joints[robot.joint_id(name)]
        if j.nq != 1:
            continue
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        qs[:, j.idx_q] = rng.uniform(lo, hi, n)
    return qs


# ---------------------------------------------------------------- the IK contract row
#: Reasons a default IK may give for leaving a target unsolved, by the legkin error a single call raises.
REASONS = ("out of reach", "out of limits", "other mode")


@dataclass(frozen=True)
class IKRobustness:
    """Counts of one IK robustness run (see :func:`robustness_row`)."""

    targets: int
    made: int
    solved: int
    wrong: int
    missed: int
    reasons: dict[str, int]
    exceptions: int
    max_error: float

    def summary(self) -> str:
        why = ", ".join(f"{k} {v}" for k, v in self.reasons.items() if v) or "none"
        return (
            f"{self.targets} targets ({self.made} made by FK from in-limit joints): {self.solved} solved, "
            f"{self.wrong} not reproduced, {self.missed} FK-made targets missed, unsolved by reason: {why}; "
            f"{self.exceptions} foreign exceptions"
        )


def classify_failures(call: Callable[[int], object], indices: Iterable[int]) -> tuple[dict[str, int], int]:
    """Classify unsolved targets by the legkin error that a single call on each raises.

    ``call(i)`` runs the default IK on target ``i`` as a single call. Returns ``(reasons, exceptions)``:
    counts per reason (:data:`REASONS`; another legkin error counts under its class name, a single call that
    succeeds where the batch failed under ``"solved by a single call"``) and the number of non-legkin
    exceptions (each one a defect).
    """
    from .errors import AssemblyModeError, JointLimitError, LegkinError, UnreachableError

    reasons = {k: 0 for k in REASONS}
    exceptions = 0
    for i in indices:
        try:
            call(int(i))
        except AssemblyModeError:
            reasons["other mode"] += 1
        except JointLimitError:
            reasons["out of limits"] += 1
        except UnreachableError:
            reasons["out of reach"] += 1
        except LegkinError as exc:
            key = type(exc).__name__
            reasons[key] = reasons.get(key, 0) + 1
        except Exception:  # noqa: BLE001 - counting foreign exceptions is the point
            exceptions += 1
        else:
            reasons["solved by a single call"] = reasons.get("solved by a single call", 0) + 1
    return reasons, exceptions


def robustness_row(
    mechanism: str,
    *,
    made: np.ndarray,
    solved: np.ndarray,
    error: np.ndarray,
    reasons: dict[str, int],
    classified: int,
    exceptions: int,
    tolerance: float = 1e-9,
) -> CheckResult:
    """The IK contract row: "IK on N random targets in and around the workspace".

    Args:
        made: (N,) True for targets made by the default forward kinematics from in-limit joints (each must
            be solved).
        solved: (N,) the default batch IK's mask.
        error: (N,) ``|FK(IK(x)) - x|`` (default FK options) for the solved targets (ignored elsewhere).
        reasons: counts of the classified unsolved targets (:func:`classify_failures`).
        classified: how many unsolved targets were classified.
        exceptions: non-legkin exceptions seen (batch call included).

    Passes when every solved answer reproduces its target within ``tolerance``, every FK-made target is
    solved, no single call succeeds where the batch failed, and no foreign exception was raised.
    """
    made, solved = np.asarray(made, bool), np.asarray(solved, bool)
    err = np.abs(np.asarray(error, dtype=float))[solved]
    wrong = int(np.sum(~(err <= tolerance)))
    missed = int(np.sum(made & ~solved))
    counts = IKRobustness(
        targets=int(made.size), made=int(made.sum()), solved=int(solved.sum()), wrong=wrong, missed=missed,
        reasons=dict(reasons), exceptions=int(exceptions), max_error=float(err.max()) if err.size else 0.0,
    )
    unsolved = int(made.size - solved.sum())
    why = ", ".join(f"{k} {v}" for k, v in reasons.items() if v) or "none"
    name = (
        f"IK on {made.size} random targets in and around the workspace: {counts.solved} solved "
        f"({wrong} not reproduced), {unsolved} unsolved ({missed} of them FK-made; {classified} classified: "
        f"{why}), {exceptions} exceptions"
    )
    passed = (
        wrong == 0 and missed == 0 and exceptions == 0 and reasons.get("solved by a single call", 0) == 0
    )
    emax = counts.max_error
    p99 = float(np.percentile(err, 99)) if err.size else 0.0
    return CheckResult(name, int(made.size), emax, p99, tolerance, bool(passed), err, counts)
