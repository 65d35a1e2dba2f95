"""Closed kinematic loops: their URDF declaration, Pinocchio constraint models, and the loop solver.

A loop is declared inside the xacro (and so inside the generated URDF) with an
element of legkin's own, which URDF parsers (Pinocchio, yourdfpy) ignore::

    <loop_closure name="B" type="frame" frame1="A_ee" frame2="B_ee"/>

``frame1`` and ``frame2`` are URDF links (or frames of fixed joints) that
coincide when the loop is closed. ``type="point"`` makes their origins coincide
(3 rows: a spherical joint at the cut, or a revolute cut on a planar loop);
``type="frame"`` makes the whole placements coincide (6 rows: a rigid cut).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ._batch import as_input, check_integer, check_number
from .errors import InvalidInputError, LegkinError, LoopClosureError

__all__ = [
    "LoopSpec",
    "LoopSolveInfo",
    "parse_loops",
    "build_constraint",
    "LoopSet",
    "levenberg_marquardt",
]

_TYPES = ("point", "frame")

#: Initial Levenberg-Marquardt damping of :func:`levenberg_marquardt`.
DEFAULT_DAMPING = 1e-6


@dataclass(frozen=True)
class LoopSpec:
    """One loop-closure declaration read from the URDF."""

    name: str
    type: str
    frame1: str
    frame2: str


@dataclass(frozen=True)
class LoopSolveInfo:
    """What :meth:`legkin.Robot.solve_loops` did."""

    iterations: int
    residual: float


def parse_loops(urdf_path: str | Path) -> list[LoopSpec]:
    """Read every ``<loop_closure>`` element of a URDF file."""
    root = ET.parse(urdf_path).getroot()
    loops = []
    for el in root.iter("loop_closure"):
        missing = [a for a in ("name", "type", "frame1", "frame2") if a not in el.attrib]
        if missing:
            raise LegkinError(f"{urdf_path}: <loop_closure> lacks attribute(s) {', '.join(missing)}")
        if el.get("type") not in _TYPES:
            raise LegkinError(
                f"{urdf_path}: loop {el.get('name')!r} has type {el.get('type')!r}; valid: {', '.join(_TYPES)}"
            )
        a = el.attrib
        loops.append(LoopSpec(a["name"], a["type"], a["frame1"], a["frame2"]))
    return loops


def build_constraint(model: pin.Model, loop: LoopSpec):
    """The Pinocchio constraint model closing ``loop`` (PointAnchor or FrameAnchor)."""
    anchors = []
    for frame in (loop.frame1, loop.frame2):
        if not model.existFrame(frame):
            raise LegkinError(f"loop {loop.name!r} names frame {frame!r}, which the model does not have")
        f = model.frames[model.getFrameId(frame)]
        anchors += [f.parentJoint, f.placement]
    cls = pin.PointAnchorConstraintModel if loop.type == "point" else pin.FrameAnchorConstraintModel
    cm = cls(model, *anchors)
    cm.name = loop.name
    return cm


class LoopSet:
    """The stacked loop constraints of a model: residual, Jacobian, mobility and solver."""

    def __init__(self, model: pin.Model, loops: list[LoopSpec]):
        self.model = model
        self.data = model.createData()
        self.loops = list(loops)
        self.models = [build_constraint(model, lp) for lp in self.loops]
        self.datas = [cm.createData() for cm in self.models]
        self.rows = sum(3 if lp.type == "point" else 6 for lp in self.loops)
        self._v0 = np.zeros(model.nv)

    def residual_and_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Stacked residual (rows,) and Jacobian (rows, nv) at ``q``."""
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, q, self._v0, self._v0)
        pin.computeJointJacobians(model, data, q)
        rs, js = [], []
        for cm, cd in zip(self.models, self.datas):
            cm.calc(model, data, cd)
            rs.append(np.array(cd.constraint_position_error).ravel())
            js.append(np.array(cm.jacobian(model, data, cd)))
        if not rs:
            return np.zeros(0), np.zeros((0, model.nv))
        return np.concatenate(rs), np.vstack(js)

    def residual(self, q: np.ndarray) -> np.ndarray:
        return self.residual_and_jacobian(q)[0]

    def _check(self, q, free) -> tuple[np.ndarray, np.ndarray]:
        """The solver's and :meth:`mobility`'s inputs, checked (shape, finiteness, kind)."""
        nq, nv = self.model.nq, self.model.nv
        q = as_input(q, "q")
        if q.shape != (nq,):
            raise InvalidInputError(f"q must have shape ({nq},), got shape {q.shape}")
        free = np.asarray(free)
        if free.dtype != bool or free.shape != (nv,):
            raise InvalidInputError(f"free must be a boolean mask of shape ({nv},), got {free.dtype} {free.shape}")
        return q, free

    def mobility(self, q: np.ndarray, free: np.ndarray, tol: float) -> int:
        """Number of free velocity coordinates minus the rank of the constraint Jacobian on them.

        The rank counts singular values above ``tol`` times the largest one (relative tolerance, in [0, 1)).
        """
        q, free = self._check(q, free)
        tol = check_number(tol, "tol", 0.0, 1.0, high_open=True)
        _, jac = self.residual_and_jacobian(q)
        jac = jac[:, free]
        if jac.size == 0:
            return int(free.sum())
        if not np.all(np.isfinite(jac)):
            raise LegkinError("the loop-closure Jacobian is not finite at this configuration")
        s = np.linalg.svd(jac, compute_uv=False)
        rank = int(np.sum(s > tol * max(s[0], 1e-300)))
        return int(free.sum()) - rank

    def solve(
        self, q: np.ndarray, free: np.ndarray, tol: float, max_iter: int, damping: float = DEFAULT_DAMPING
    ) -> tuple[np.ndarray, LoopSolveInfo]:
        """:func:`levenberg_marquardt` on the stacked loop residual; raises if the loops do not close.

        Raises:
            InvalidInputError: ``q`` of the wrong shape or not finite, ``tol`` or ``damping`` not a finite
                positive number, ``max_iter`` not an integer >= 0.
            LoopClosureError: the residual did not reach ``tol``.
        """
        q, free = self._check(q, free)
        tol = check_number(tol, "tol", 0.0, low_open=True)
        max_iter = check_integer(max_iter, "max_iter", 0)
        damping = check_number(damping, "damping", 0.0, low_open=True)
        try:
            q, it, _, converged, err = levenberg_marquardt(
                self.model, self.residual_and_jacobian, q, free, tol, max_iter, damping=damping
            )
        except np.linalg.LinAlgError as exc:  # a non-finite residual or Jacobian on the way (overflow)
            raise LoopClosureError(f"could not close the loops: the iteration broke down ({exc})") from None
        if converged:
            return q, LoopSolveInfo(it, err)
        raise LoopClosureError(
            f"could not close the loops: residual {err:.3e} after {it} iterations (tolerance {tol:.1e})",
            residual=err,
            iterations=it,
            q=q,
        )


def levenberg_marquardt(
    model: pin.Model, residual_and_jacobian, q: np.ndarray, free: np.ndarray, tol: float, max_iter: int,
    *, damping: float = DEFAULT_DAMPING,
):
    """Levenberg-Marquardt on a stacked residual over the velocity coordinates ``free`` of ``model``.

    Each iteration tries the Gauss-Newton step ``dq = -pinv(J_free) r`` (pseudo-inverse: redundant rows of
    planar loops make the stack rank-deficient); if it does not reduce ``|r|``, damped steps
    ``-(J^T J + mu I)^-1 J^T r`` with growing ``mu`` are tried; configurations are updated with
    ``pin.integrate``. Stops at ``|r| <= tol``, after ``max_iter`` iterations, or when no step reduces ``|r|``.
    The inputs are not checked here (the benches call it in their timed loops): :meth:`LoopSet.solve` does.

    Args:
        residual_and_jacobian: ``q -> (r (rows,), J (rows, nv))``.
        damping: the smallest damping ``mu`` tried (then ``mu * 10**k``, k < 12).

    Returns:
        ``(q, iterations, residual evaluations, converged, |r|)``.
    """
    r, jac = residual_and_jacobian(q)
    evals = 1
    err = float(np.linalg.norm(r))
    mu = damping
    it = 0
    for it in range(max_iter + 1):
        if err <= tol:
            return q, it, evals, True, err
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
            break  # no step reduces the residual: a local minimum that does not close
        q, r, jac, err = q_new, r_new, jac_new, err_new
    return q, it, evals, False, err
