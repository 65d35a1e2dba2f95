"""Closing the loops of a robot from a poor start, and telling why when they cannot be closed.

:func:`close_loops` runs :func:`legkin.loops.levenberg_marquardt` from the start given; when that stalls
short of the tolerance, a homotopy from the start (the residual ``r(q) - (1 - t) r(q_start)``, ``t`` from
0 to 1 in :data:`HOMOTOPY_STEPS` steps, each stage started from the last), then :data:`RESTARTS`
random starts about it (uniform +-:data:`RESTART_SPREAD` rad/m on every free coordinate, a seeded
generator). Whether a configuration closes is decided by the frames themselves (:func:`loop_errors`:
the distance between the two origins, m, and the angle between the two orientations, rad), never by the
solver's residual.

When no start closes, :func:`diagnose` tries each open loop alone, as declared and as a point (origins
only): a loop that closes alone but not with the others is a *hard start* (or an inconsistent set); a 6d
loop whose origins meet but whose orientations never align from any start (the angle left is the same
from every start) is *misaligned*: its frames cannot coincide, e.g. a frame flipped by 180 degrees, or a
6d cut where the mechanism only lets the origins meet (a 3d loop declared 6d). :class:`LoopClosureError`
then names each open loop with its residual (m, rad) and this verdict.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pinocchio as pin

from .errors import LoopClosureError
from .loops import LoopSet, LoopSpec, levenberg_marquardt

__all__ = ["ClosingInfo", "LoopError", "loop_errors", "close_loops", "diagnose", "CLOSED_TOL"]

#: Loops count as closed when every origin distance (m) and orientation angle (rad) is at most this.
CLOSED_TOL = 1e-10
HOMOTOPY_STEPS = 8
RESTARTS = 12
RESTART_SPREAD = 1.0
_MAX_ITER = 200


@dataclass(frozen=True)
class LoopError:
    """How far one loop is from closed: ``distance`` between the origins (m), ``angle`` between the
    orientations (rad; 0 for a point loop)."""

    name: str
    distance: float
    angle: float

    @property
    def worst(self) -> float:
        return max(self.distance, self.angle)


@dataclass(frozen=True)
class ClosingInfo:
    """What :func:`close_loops` did: the strategy that closed (``"compiled"``, ``"direct"``, ``"homotopy"``,
    ``"restart k"``), Levenberg-Marquardt ``iterations`` in all, the worst frame error reached (m or rad)."""

    strategy: str
    iterations: int
    error: float


def loop_errors(model: pin.Model, data: pin.Data, loops: list[LoopSpec], q: np.ndarray) -> list[LoopError]:
    """Each loop's error at ``q``, measured on the two frames' world placements."""
    pin.framesForwardKinematics(model, data, q)
    out = []
    for lp in loops:
        m1 = data.oMf[model.getFrameId(lp.frame1)]
        m2 = data.oMf[model.getFrameId(lp.frame2)]
        d = float(np.linalg.norm(m1.translation - m2.translation))
        a = float(np.linalg.norm(pin.log3(m1.rotation.T @ m2.rotation))) if lp.type == "frame" else 0.0
        out.append(LoopError(lp.name, d, a))
    return out


def _worst(errors: list[LoopError]) -> float:
    return max((e.worst for e in errors), default=0.0)


def _lm(ls: LoopSet, q: np.ndarray, free: np.ndarray, shift: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """Levenberg-Marquardt on ``r(q) - shift``; returns the configuration reached and the iterations."""
    def fun(x):
        r, jac = ls.residual_and_jacobian(x)
        return (r if shift is None else r - shift), jac

    q, it, _, _, _ = levenberg_marquardt(ls.model, fun, q, free, 1e-14, _MAX_ITER)
    return q, it


def _attempts(ls: LoopSet, q0: np.ndarray, free: np.ndarray, seed: int, restarts: int | None = None,
              homotopy: bool = True, fast: Callable | None = None, lm: bool = True):
    """The strategies in turn: yields (name, configuration reached, iterations)."""
    if fast is not None:
        q, it = fast(q0, free)
        yield "compiled", q, it
    if not lm:
        return
    q, it = _lm(ls, q0, free)
    yield "direct", q, it
    if not homotopy:
        return
    r0 = ls.residual(q0)
    q, total = q0.copy(), 0
    for t in np.linspace(0.0, 1.0, HOMOTOPY_STEPS + 1)[1:]:
        q, it = _lm(ls, q, free, (1.0 - t) * r0)
        total += it
    yield "homotopy", q, total
    rng = np.random.default_rng(seed)
    for k in range(RESTARTS if restarts is None else restarts):
        dq = np.zeros(ls.model.nv)
        dq[free] = rng.uniform(-RESTART_SPREAD, RESTART_SPREAD, int(free.sum()))
        q, it = _lm(ls, pin.integrate(ls.model, q0, dq), free)
        yield f"restart {k + 1}", q, it


def close_loops(ls: LoopSet, q0: np.ndarray, free: np.ndarray, *, tol: float = CLOSED_TOL, seed: int = 0,
                restarts: int | None = None, homotopy: bool = True, fast: Callable | None = None, lm: bool = True,
                diagnose_failure: bool = True) -> tuple[np.ndarray, ClosingInfo]:
    """Close every loop of ``ls`` from ``q0``, moving only the velocity coordinates ``free``.

    Args:
        ls: the loops.
        q0: the start (``model.nq``).
        free: boolean mask over the velocity coordinates that may move.
        tol: the largest frame error accepted (m and rad).
        seed: seed of the restarts.
        restarts: random starts tried after the direct and homotopy attempts (default :data:`RESTARTS`).
        homotopy: try the homotopy (and the restarts) after the direct attempt.
        fast: ``(q, free) -> (q, iterations)``, a compiled solve tried first (``Robot._tree_solve``: minimum-norm
            Gauss-Newton).
        lm: try the Levenberg-Marquardt strategies (direct, homotopy, restarts) after ``fast``.
        diagnose_failure: on failure, try each open loop alone to say why (:func:`diagnose`).

    Returns:
        The closed configuration and a :class:`ClosingInfo`.

    Raises:
        LoopClosureError: no strategy closed the loops; the message names each open loop with its distance
            (m) and angle (rad), and whether it is misaligned or a hard start.
    """
    data = ls.model.createData()
    best_q, best_err, iterations = q0, np.inf, 0
    for name, q, it in _attempts(ls, q0, free, seed, restarts, homotopy, fast, lm):
        iterations += it
        err = _worst(loop_errors(ls.model, data, ls.loops, q))
        if err <= tol:
            return q, ClosingInfo(name, iterations, err)
        if err < best_err:
            best_q, best_err = q, err
    errors = loop_errors(ls.model, data, ls.loops, best_q)
    verdicts = diagnose(ls, q0, free, [e.name for e in errors if e.worst > tol], seed) if diagnose_failure else {}
    parts = [f"{e.name} ({e.distance:.3g} m, {e.angle:.3g} rad{': ' + verdicts[e.name] if e.name in verdicts else ''})"
             for e in errors if e.worst > tol]
    raise LoopClosureError(
        f"could not close the loops from this start ({_tried(homotopy, restarts, fast, lm)}, {iterations} "
        f"iterations): {len(parts)} of {len(errors)} stay open: " + "; ".join(parts),
        residual=best_err, iterations=iterations, q=best_q, open_loops=errors,
    )


def _tried(homotopy: bool, restarts: int | None, fast: Callable | None, lm: bool) -> str:
    restarts = RESTARTS if restarts is None else restarts
    parts = ["compiled Gauss-Newton"] if fast is not None else []
    if lm:
        parts.append(f"Levenberg-Marquardt direct, homotopy and {restarts} random starts" if homotopy
                     else "Levenberg-Marquardt")
    return ", ".join(parts)


def _alone(ls: LoopSet, loop: LoopSpec, q0, free, seed) -> list[LoopError]:
    """The error each strategy leaves on ``loop`` alone, up to the first that closes it."""
    one = LoopSet(ls.model, [loop])
    data = ls.model.createData()
    out = []
    for _, q, _ in _attempts(one, q0, free, seed):
        out.append(loop_errors(ls.model, data, [loop], q)[0])
        if out[-1].worst <= CLOSED_TOL:
            break
    return out


def diagnose(ls: LoopSet, q0: np.ndarray, free: np.ndarray, names: list[str], seed: int = 0) -> dict[str, str]:
    """Why each loop of ``names`` stays open: a verdict per loop name.

    ``"closes alone: ..."`` (a hard start, or loops that contradict each other), ``"misaligned: ..."`` (a 6d
    loop whose origins meet when it is a point loop, but which stays open as a 6d loop from every start: the
    distances and angles left are given), or ``"cannot close even alone ..."``.
    """
    out = {}
    for lp in ls.loops:
        if lp.name not in names:
            continue
        alone = _alone(ls, lp, q0, free, seed)
        if alone[-1].worst <= CLOSED_TOL:
            out[lp.name] = "closes alone: a hard start or loops that contradict each other"
            continue
        point = _alone(ls, LoopSpec(lp.name, "point", lp.frame1, lp.frame2), q0, free, seed)
        if lp.type == "frame" and point[-1].worst <= CLOSED_TOL:
            dist, angle = [e.distance for e in alone], [e.angle for e in alone]
            out[lp.name] = (f"misaligned: its origins meet as a point loop, but as a 6d loop it stays {min(dist):.3g} "
                            f"to {max(dist):.3g} m and {min(angle):.3g} to {max(angle):.3g} rad open from {len(alone)} "
                            "starts (frames that cannot coincide)")
        else:
            out[lp.name] = f"cannot close even alone (origins {min(e.distance for e in point):.3g} m apart at best)"
    return out
