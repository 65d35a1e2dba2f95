"""The score of a leg's joint answer in ``legkin bench`` (:mod:`legkin.legs.bench` for 3-DOF legs,
:mod:`legkin.legs.bench6` for 6-DOF legs): Pinocchio's foot frame at the leg's joints against the target, and
the joint limits."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._benchkit import SOLVE_TOL, Score


class _LegFrame:
    """Pinocchio's foot frame of one leg (the other joints at ``q_base``) and the score of a joint answer: the
    error of a subclass's :meth:`_value` of the frame placement against the target, and the joint limits."""

    shape: tuple[int, ...] = ()

    def __init__(self, model, leg, q_base: np.ndarray) -> None:
        self.model, self.data = model, model.createData()
        self.fid = model.getFrameId(leg.foot_frame)
        self.iq, self.iv = list(leg.idx_q), list(leg.idx_v)
        self.leg, self.lower, self.upper, self.q_ref = leg, leg.lower, leg.upper, leg.q_ref
        self.q_base = q_base

    def __call__(self, qleg: np.ndarray) -> np.ndarray:
        """Pinocchio's foot value at each row of leg joints (NaN for a row with a NaN)."""
        import pinocchio as pin

        out = np.full((len(qleg),) + self.shape, np.nan)
        q = self.q_base.copy()
        for k in np.flatnonzero(np.isfinite(qleg).all(axis=-1)):
            q[self.iq] = qleg[k]
            pin.forwardKinematics(self.model, self.data, q)
            out[k] = self._value(pin.updateFramePlacement(self.model, self.data, self.fid))
        return out

    def _value(self, placement: Any) -> np.ndarray:
        raise NotImplementedError

    def _error(self, got: np.ndarray, targets: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def score(self, targets: np.ndarray, q, iters=None) -> Score:
        q = np.asarray(q, dtype=float)
        err = self._error(self(q), targets)  # NaN where there is no answer
        inside = np.all((q >= self.lower) & (q <= self.upper), axis=-1)  # False on NaN
        reached = err <= SOLVE_TOL
        return Score(error=err, solved=reached & inside, reached=reached, iterations=iters)

    def score_iter(self, targets, out) -> Score:
        return self.score(targets, out[0], out[1])
