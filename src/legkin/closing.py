"""Closing the loops of a robot from a poor start, and telling why when they cannot be closed.

:func:`close_loops` runs the compiled solve (``fast``: minimum-norm Gauss-Newton, when the robot's joints allow
it) from the start given and from :data:`RESTARTS` random starts about it (uniform +-:data:`RESTART_SPREAD` rad/m
on every free coordinate, a seeded generator); then :func:`legkin.loops.levenberg_marquardt` from the start, a
homotopy from the start (the residual ``r(q) - (1 - t) r(q_start)``, ``t`` from 0 to 1 in :data:`HOMOTOPY_STEPS`
steps, each stage started from the last), and the random starts. Whether a configuration closes is decided by the
frames themselves (:func:`loop_errors`: the distance between the two origins, m, and the angle between the two
orientations, rad), never by the solver's residual.

:func:`diagnose` tries each loop alone, as declared and as a point (origins only): a loop that closes alone but
not with the others is a *hard start* (or an inconsistent set); a 6d loop whose origins meet but whose frames
never coincide from any start is *misaligned*: e.g. a frame flipped by 180 degrees, or a 6d cut where the
mechanism only lets the origins meet (a 3d loop declared 6d). With the compiled solve, the diagnosis runs before
Levenberg-Marquardt (each loop alone costs milliseconds): a misaligned loop cannot close with the others either,
so Levenberg-Marquardt (minutes on a robot of 60 joints) is skipped. :class:`LoopClosureError` then names each open
loop with its residual (m, rad) and this verdict.
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


def _random_starts(ls: LoopSet, q0: np.ndarray, free: np.ndarray, seed: int, n: int, spread: float = RESTART_SPREAD):
    """``n`` random starts about ``q0``: uniform +-``spread`` (rad or m) on every free coordinate, seeded."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        dq = np.zeros(ls.model.nv)
        dq[free] = rng.uniform(-spread, spread, int(free.sum()))
        yield pin.integrate(ls.model, q0, dq)


def _compiled_attempts(ls: LoopSet, q0: np.ndarray, free: np.ndarray, seed: int, restarts: int | None,
                       fast: Callable | None, loops: list[int] | None = None, point: bool = False):
    """The compiled solve from ``q0`` and, unless ``restarts == 0``, from the random starts (cheap: microseconds an
    iteration); yields (name, configuration reached, iterations). ``loops``, ``point``: as ``fast`` takes them."""
    if fast is None:
        return
    q, it = fast(q0, free, loops, point)
    yield "compiled", q, it
    n = RESTARTS if restarts is None else restarts
    for k, start in enumerate(_random_starts(ls, q0, free, seed, n)):
        q, it = fast(start, free, loops, point)
        yield f"compiled restart {k + 1}", q, it


def _lm_attempts(ls: LoopSet, q0: np.ndarray, free: np.ndarray, seed: int, restarts: int | None = None,
                 homotopy: bool = True):
    """Levenberg-Marquardt: direct, then the homotopy and the random starts; yields (name, configuration,
    iterations)."""
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
    n = RESTARTS if restarts is None else restarts
    for k, start in enumerate(_random_starts(ls, q0, free, seed, n)):
        q, it = _lm(ls, start, free)
        yield f"restart {k + 1}", q, it


def _attempts(ls: LoopSet, q0: np.ndarray, free: np.ndarray, seed: int, restarts: int | None = None,
              homotopy: bool = True, fast: Callable | None = None, lm: bool = True):
    """The strategies in turn: the compiled ones (with its restarts when ``homotopy``), then Levenberg-Marquardt's
    (when ``lm``); yields (name, configuration reached, iterations)."""
    yield from _compiled_attempts(ls, q0, free, seed, restarts if homotopy else 0, fast)
    if lm:
        yield from _lm_attempts(ls, q0, free, seed, restarts, homotopy)


class _Best:
    """The closest configuration seen over the attempts (:func:`close_loops`)."""

    def __init__(self, ls: LoopSet, q0: np.ndarray) -> None:
        self.ls, self.data = ls, ls.model.createData()
        self.q, self.err, self.iterations = q0, np.inf, 0

    def first_closed(self, attempts, tol: float) -> tuple[np.ndarray, ClosingInfo] | None:
        """The first attempt that closes every loop to ``tol`` (m and rad), or None."""
        for name, q, it in attempts:
            self.iterations += it
            err = _worst(loop_errors(self.ls.model, self.data, self.ls.loops, q))
            if err <= tol:
                return q, ClosingInfo(name, self.iterations, err)
            if err < self.err:
                self.q, self.err = q, err
        return None


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
        homotopy: try the homotopy and the restarts after the direct attempt.
        fast: ``(q, free, loops, point) -> (q, iterations)``, a compiled solve tried first, from ``q0`` and (with
            ``homotopy``) from the random starts (``Robot._tree_solve``: minimum-norm Gauss-Newton; ``loops``: the
            indices of the loops to close, None for all; ``point``: close them as point loops).
        lm: try the Levenberg-Marquardt strategies (direct, homotopy, restarts) after ``fast``, unless ``fast``
            finds the loops misaligned (:func:`orientation_stuck`).
        diagnose_failure: on failure, try each open loop alone to say why (:func:`diagnose`).

    Returns:
        The closed configuration and a :class:`ClosingInfo`.

    Raises:
        LoopClosureError: no strategy closed the loops; the message names each open loop with its distance
            (m) and angle (rad), and whether it is misaligned or a hard start.
    """
    best = _Best(ls, q0)
    done = best.first_closed(_compiled_attempts(ls, q0, free, seed, restarts if homotopy else 0, fast), tol)
    verdicts: dict[str, str] | None = None
    if done is None and lm and fast is not None and homotopy:
        # each 6d loop alone, compiled (cheap): one whose origins meet but whose frames never align from any start
        # cannot close with the others either (Levenberg-Marquardt would spend minutes on it, on 60 joints)
        verdicts = diagnose(ls, q0, free, [lp.name for lp in ls.loops], seed, fast)
    misaligned = sorted(n for n, v in (verdicts or {}).items() if v.startswith("misaligned"))
    if done is None and lm and not misaligned:
        done = best.first_closed(_lm_attempts(ls, q0, free, seed, restarts, homotopy), tol)
    if done is not None:
        return done
    errors = loop_errors(ls.model, best.data, ls.loops, best.q)
    names = [e.name for e in errors if e.worst > tol]
    if verdicts is None and diagnose_failure:
        verdicts = diagnose(ls, q0, free, names, seed, fast)
    verdicts = verdicts or {}
    parts = [f"{e.name} ({e.distance:.3g} m, {e.angle:.3g} rad{': ' + verdicts[e.name] if e.name in verdicts else ''})"
             for e in errors if e.worst > tol]
    raise LoopClosureError(
        f"could not close the loops from this start ({_tried(homotopy, restarts, fast, lm, misaligned)}, "
        f"{best.iterations} iterations): {len(parts)} of {len(errors)} stay open: " + "; ".join(parts),
        residual=best.err, iterations=best.iterations, q=best.q, open_loops=errors,
    )


def _tried(homotopy: bool, restarts: int | None, fast: Callable | None, lm: bool, misaligned: list[str]) -> str:
    restarts = RESTARTS if restarts is None else restarts
    parts = []
    if fast is not None:
        parts.append(f"compiled Gauss-Newton from {restarts + 1} starts" if homotopy else "compiled Gauss-Newton")
    if misaligned:
        parts.append(f"then each loop alone: {', '.join(misaligned)} cannot close even alone while their origins meet:"
                     " misaligned frames, not a hard start (Levenberg-Marquardt skipped)")
    elif lm:
        parts.append(f"Levenberg-Marquardt direct, homotopy and {restarts} random starts" if homotopy
                     else "Levenberg-Marquardt")
    return ", ".join(parts)


def _alone(ls: LoopSet, loop: LoopSpec, q0, free, seed, fast: Callable | None = None,
           index: int = 0) -> list[LoopError]:
    """The error each strategy leaves on ``loop`` alone, up to the first that closes it (with ``fast``: the
    compiled solve of loop ``index`` from every start, as declared or, for a point ``loop``, as a point loop)."""
    one = LoopSet(ls.model, [loop])
    data = ls.model.createData()
    out = []
    runs = (_compiled_attempts(one, q0, free, seed, None, fast, [index], loop.type == "point") if fast is not None
            else _attempts(one, q0, free, seed))
    for _, q, _ in runs:
        out.append(loop_errors(ls.model, data, [loop], q)[0])
        if out[-1].worst <= CLOSED_TOL:
            break
    return out


def diagnose(ls: LoopSet, q0: np.ndarray, free: np.ndarray, names: list[str], seed: int = 0,
             fast: Callable | None = None) -> dict[str, str]:
    """Why each loop of ``names`` stays open: a verdict per loop name (each loop tried alone from ``q0`` and the
    random starts; with ``fast``, by the compiled solve only, as :func:`close_loops` takes it).

    ``"closes alone: ..."`` (a hard start, or loops that contradict each other), ``"misaligned: ..."`` (a 6d
    loop whose origins meet when it is a point loop, but which stays open as a 6d loop from every start: the
    distances and angles left are given), or ``"cannot close even alone ..."``.
    """
    out = {}
    for k, lp in enumerate(ls.loops):
        if lp.name not in names:
            continue
        alone = _alone(ls, lp, q0, free, seed, fast, k)
        if alone[-1].worst <= CLOSED_TOL:
            out[lp.name] = "closes alone: a hard start or loops that contradict each other"
            continue
        point = _alone(ls, LoopSpec(lp.name, "point", lp.frame1, lp.frame2), q0, free, seed, fast, k)
        if lp.type == "frame" and point[-1].worst <= CLOSED_TOL:
            dist, angle = [e.distance for e in alone], [e.angle for e in alone]
            out[lp.name] = (f"misaligned: its origins meet as a point loop, but as a 6d loop it stays {min(dist):.3g} "
                            f"to {max(dist):.3g} m and {min(angle):.3g} to {max(angle):.3g} rad open from {len(alone)} "
                            "starts (frames that cannot coincide)")
        else:
            out[lp.name] = f"cannot close even alone (origins {min(e.distance for e in point):.3g} m apart at best)"
    return out
