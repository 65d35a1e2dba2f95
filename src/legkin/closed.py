"""Closed-loop kinematics of a robot given by its motors: ``closed_fk``, ``closed_jacobian``, ``closed_ik``.

The loops (``robot.loops``, residual ``r(q)``, Jacobian ``J_c = dr/dv``) tie the passive joints to the
actuated ones (``robot.actuated_joints``, one coordinate each). Split the velocity ``v`` into motor and
passive coordinates, ``J_c = [J_m  J_p]``:

* ``closed_fk(motors, q_near)``: ``q`` with the motor coordinates set to ``motors`` exactly and the passive
  ones solving ``r(q) = 0`` by Gauss-Newton from ``q_near`` with minimum-norm steps ``dq_p = -pinv(J_p) r``
  (:func:`legkin.loops.levenberg_marquardt`), so the solution is the one continuous with ``q_near`` and the
  idle mobility (a rod spinning about its axis between two ball joints: the null space of ``J_p``) does not
  move; if that does not close, the motors are moved from their ``q_near`` values in 2, 4, ... 64 steps.
* ``closed_jacobian(q, frame)``: ``J_p v_p = -J_m v_m``, ``v_p = -pinv(J_p) J_m v_m`` (minimum norm: the idle
  motion set to zero), so the frame's twist is ``(J_f,m - J_f,p pinv(J_p) J_m) v_m``, 6 x n_motors.
* ``closed_ik(frame, pose, q_near)``: the loops and the frame's error (``log6(pose^-1 oMf)``, or the position
  error for a 3-vector target) stacked, all joints free, minimum-norm Gauss-Newton from ``q_near``.

Every answer is checked on the frames themselves (:func:`legkin.closing.loop_errors`): loops to
:data:`legkin.closing.CLOSED_TOL` (1e-10 m and rad).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, overload

import numpy as np
import pinocchio as pin

from ._batch import as_input, check_flag, finish
from .closing import CLOSED_TOL, loop_errors
from .errors import InvalidInputError, LoopClosureError, UnreachableError
from .loops import levenberg_marquardt

__all__ = ["ClosedLoopMixin", "Tree", "tree_of", "pack"]

_STEPS = (1, 2, 4, 8, 16, 32, 64)
_MAX_ITER = 50
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class Tree:
    """A Pinocchio model and its loops as the arrays of :mod:`legkin._tree_kernels` (see there)."""

    parent: np.ndarray
    kind: np.ndarray
    axis: np.ndarray
    place_r: np.ndarray
    place_t: np.ndarray
    idx_q: np.ndarray
    idx_v: np.ndarray
    loop_j: np.ndarray
    loop_r: np.ndarray
    loop_t: np.ndarray
    loop_six: np.ndarray


def _from_lwa(jac: np.ndarray, placement: np.ndarray, reference) -> np.ndarray:
    """A ``LOCAL_WORLD_ALIGNED`` twist Jacobian (6 x n) of a frame at ``placement`` (4 x 4) in ``reference``."""
    if isinstance(reference, str):
        reference = dict(pin.ReferenceFrame.names)[reference]
    if reference == pin.LOCAL_WORLD_ALIGNED:
        return jac
    rot, p = placement[:3, :3], placement[:3, 3]
    if reference == pin.LOCAL:
        return np.vstack([rot.T @ jac[:3], rot.T @ jac[3:]])
    return np.vstack([jac[:3] - np.cross(jac[3:].T, p).T, jac[3:]])  # WORLD: v_O = v_p - w x p


_SOLVER: list[Any] = []
_NO_MOTORS = np.zeros(0)
_F64 = np.dtype(np.float64)


def _solver() -> Any:
    """:func:`legkin._tree_kernels.solve_passive`, imported on first use (``import legkin.robot`` stays numba-free)."""
    if not _SOLVER:
        from ._tree_kernels import solve_passive

        _SOLVER.append(solve_passive)
    return _SOLVER[0]


def _joint_kind(joint) -> tuple[int, tuple[float, ...]] | None:
    from ._tree_kernels import PRISMATIC, REVOLUTE, SPHERICAL

    name = joint.shortname()[len("JointModel"):]
    if name == "Spherical":
        return SPHERICAL, (0.0, 0.0, 0.0)
    if name in ("RX", "RY", "RZ", "PX", "PY", "PZ"):
        return (REVOLUTE if name[0] == "R" else PRISMATIC), _AXES[name[1]]
    if name in ("RevoluteUnaligned", "PrismaticUnaligned"):
        return (REVOLUTE if name[0] == "R" else PRISMATIC), tuple(joint.extract().axis)
    return None


def tree_of(model: pin.Model, loops) -> Tree | None:
    """The arrays of ``model`` and ``loops`` for the compiled solver, or None when a joint is of a kind it does not
    handle (a free flyer, a composite, a continuous joint: the Pinocchio path then solves)."""
    kinds = [(0, (0.0, 0.0, 0.0))] + [_joint_kind(j) for j in model.joints[1:]]
    if any(k is None for k in kinds):
        return None
    frames = [[model.frames[model.getFrameId(f)] for f in (lp.frame1, lp.frame2)] for lp in loops]
    return Tree(
        np.array(model.parents, dtype=np.int64), np.array([k[0] for k in kinds], dtype=np.int64),  # type: ignore
        np.array([k[1] for k in kinds], dtype=float),  # type: ignore[index]
        np.array([m.rotation for m in model.jointPlacements]), np.array([m.translation for m in model.jointPlacements]),
        np.array([j.idx_q for j in model.joints], dtype=np.int64),
        np.array([j.idx_v for j in model.joints], dtype=np.int64),
        np.array([[f.parentJoint for f in pair] for pair in frames], dtype=np.int64).reshape(-1, 2),
        np.array([[f.placement.rotation for f in pair] for pair in frames]).reshape(-1, 2, 3, 3),
        np.array([[f.placement.translation for f in pair] for pair in frames]).reshape(-1, 2, 3),
        np.array([lp.type == "frame" for lp in loops], dtype=np.bool_),
    )


def pack(tree: Tree, motor_q: np.ndarray, passive: np.ndarray, loops: Any = None,
         point: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``tree`` as the three arrays :func:`legkin._tree_kernels.solve_passive` takes (layout: its ``_unpack``).

    Args:
        tree: the model's arrays (:func:`tree_of`).
        motor_q: the motors' indices in ``q`` (int64; empty: no motor set).
        passive: boolean mask over the velocity coordinates the solve moves.
        loops: the indices of the loops to close (None: all).
        point: close them as point loops (origins only).

    Returns:
        ``(ints, floats, flags)``: int64, float64 (rad, m) and boolean vectors.
    """
    k = np.arange(len(tree.loop_j)) if loops is None else np.asarray(loops, dtype=np.int64)
    six = np.zeros(len(k), dtype=np.bool_) if point else tree.loop_six[k]
    nj = len(tree.parent)
    ints = np.concatenate([[nj, len(k), len(motor_q)], tree.parent, tree.kind, tree.idx_q, tree.idx_v,
                           tree.loop_j[k].ravel(), motor_q]).astype(np.int64)
    floats = np.concatenate([tree.axis.ravel(), tree.place_r.ravel(), tree.place_t.ravel(), tree.loop_r[k].ravel(),
                             tree.loop_t[k].ravel()])
    return ints, floats, np.concatenate([np.asarray(passive, dtype=np.bool_), six])


class ClosedLoopMixin:
    """Closed-loop kinematics through the motors, for :class:`legkin.Robot` (needs ``model``, ``_loopset``,
    ``actuated_joints``, ``q0``, ``check_q``, ``frame_id``, ``idx_q``, ``idx_v``)."""

    model: pin.Model
    _loopset: Any
    actuated_joints: Any
    q0: np.ndarray

    # ------------------------------------------------------------------ helpers
    def _motor_index(self) -> tuple[np.ndarray, np.ndarray]:
        """The motors' ``q`` and ``v`` indices (each motor one coordinate)."""
        iq, iv = [], []
        for name in self.actuated_joints:
            j = self.model.joints[self.joint_id(name)]  # type: ignore[attr-defined]
            if j.nq != 1 or j.nv != 1:
                raise InvalidInputError(f"motor {name!r} has {j.nq} coordinates: closed_fk drives 1-coordinate motors")
            iq.append(j.idx_q)
            iv.append(j.idx_v)
        return np.array(iq, dtype=int), np.array(iv, dtype=int)

    def _closed(self, q: np.ndarray, tol: float = CLOSED_TOL) -> bool:
        errs = loop_errors(self.model, self._loopset.data, self._loopset.loops, q)
        return max((e.worst for e in errs), default=0.0) <= tol

    def _near(self, q_near) -> np.ndarray:
        return self.check_q(self.q0 if q_near is None else q_near, "q_near").copy()  # type: ignore[attr-defined]

    def idle_mobility(self, q=None, tol: float = 1e-9) -> int:
        """Degrees of freedom left with every motor held (0 for a fully actuated robot; a rod spinning about its
        own axis between two ball joints counts 1).

        Args:
            q: a closed configuration (default ``q0``).
            tol: relative singular-value threshold of the rank, in [0, 1).
        """
        return int(self.mobility(self.q0 if q is None else q, locked=self.actuated_joints, tol=tol))  # type: ignore

    # ------------------------------------------------------------------ closed_fk
    def _tree(self) -> Tree | None:
        """The compiled solver's arrays of the model and loops (None: the Pinocchio path), cached."""
        if "_tree_cache" not in self.__dict__:
            self.__dict__["_tree_cache"] = tree_of(self.model, self._loopset.loops)
        return self.__dict__["_tree_cache"]

    def _compiled(self) -> tuple[Tree | None, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_tree`, the motors' q and v indices and the passive mask (cached)."""
        cache = self.__dict__.get("_closed_cache")
        if cache is None:
            iq, iv = self._motor_index()
            passive = np.ones(self.model.nv, dtype=np.bool_)
            passive[iv] = False
            cache = (self._tree(), iq, iv, passive)
            self.__dict__["_closed_cache"] = cache
        return cache

    def _kernel_args(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:func:`legkin._tree_kernels.solve_passive`'s tree arguments for ``closed_fk`` (the motors' q indices, the
        passive mask), cached; needs :meth:`_tree`."""
        args = self.__dict__.get("_kernel_args_cache")
        if args is None:
            t, iq, _, passive = self._compiled()
            assert t is not None
            args = pack(t, iq, passive)
            self.__dict__["_kernel_args_cache"] = args
        return args

    def _tree_solve(
        self, q: np.ndarray, passive: np.ndarray, max_iter: int = _MAX_ITER, motors: np.ndarray | None = None,
        loops: Any = None, point: bool = False,
    ) -> tuple[np.ndarray, bool, int, float]:
        """The compiled solve (:func:`legkin._tree_kernels.solve_passive`: minimum-norm Gauss-Newton, its test the
        frames' own error) from ``q`` with the motors set to ``motors`` (None: as in ``q``), moving the velocity
        coordinates ``passive``, closing the loops of indices ``loops`` (None: all), as point loops if ``point``;
        returns the configuration, whether it closed, the iterations and the worst frame error (m or rad). Needs
        :meth:`_tree`."""
        t, iq = self._compiled()[:2]
        assert t is not None
        out, info = np.empty_like(q), np.zeros(3)
        if motors is None:
            motors, iq = _NO_MOTORS, _NO_MOTORS.astype(np.int64)
        status = _solver()(q, motors, *pack(t, iq, passive, loops, point), CLOSED_TOL, max_iter, out, info)
        return out, status == 0, int(info[0]), float(info[1])  # 0: legkin._kernels.OK

    def _fk_step(self, motors: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, bool]:
        """Gauss-Newton (minimum-norm steps) on the passive coordinates from ``q`` with the motors set: compiled, then
        Pinocchio's Levenberg-Marquardt if that stalls or for joint kinds the kernel does not know. Returns the
        configuration and whether it closed."""
        tree, iq, _, passive = self._compiled()
        q = q.copy()
        q[iq] = motors
        if tree is not None:
            qt, ok, _, worst = self._tree_solve(q, passive, motors=motors)
            if ok:
                return qt, True
            # stalled near closure (measured: robot_delta, 2 of 200 samples at ~3e-10): Pinocchio's damped LM
            # finishes from there; stalled far (a poor start): the damped LM starts again from q, as without the
            # kernel. (Not used to polish answers the kernel closed: LM's damped steps move the idle joints.)
            if worst <= 1e-6:
                q = qt
        q = levenberg_marquardt(self.model, self._loopset.residual_and_jacobian, q, passive, 1e-14, _MAX_ITER)[0]
        return q, self._closed(q)

    def _closed_fk_one(self, m: np.ndarray, q: np.ndarray, iq: np.ndarray) -> np.ndarray | None:
        """One closed_fk solve (directly, then by continuation in 2, 4, ... 64 motor steps from ``q``), or None."""
        qk, ok = self._fk_step(m, q)
        if ok:
            return qk
        start = q[iq].copy()
        for n in _STEPS[1:]:
            qk, ok = q, True
            for k in range(1, n + 1):
                qk, ok = self._fk_step(start + (k / n) * (m - start), qk)
                if not ok:
                    break
            if ok:
                return qk
        return None

    def _fk_lean(self, motors: Any, q_near: Any) -> np.ndarray | None:
        """The single call's lean path: float64 vectors of the right lengths go straight to the compiled solve (which
        checks their finiteness); None when the inputs are of another form or the solve does not close (the full
        path then checks them, continues from ``q_near`` or says why)."""
        lean = self.__dict__.get("_lean_cache")
        if lean is None:
            tree, iq, _, passive = self._compiled()
            lean = None if tree is None else (_solver(), (len(iq),), (self.model.nq,),
                                              (*self._kernel_args(), CLOSED_TOL, _MAX_ITER), np.empty(3))
            self.__dict__["_lean_cache"] = lean or ()
        if not lean or type(motors) is not np.ndarray or motors.dtype is not _F64 or motors.shape != lean[1]:
            return None
        if q_near is None:
            q_near = self.q0
        elif type(q_near) is not np.ndarray or q_near.dtype is not _F64 or q_near.shape != lean[2]:
            return None
        out = np.empty(lean[2])
        return out if lean[0](q_near, motors, *lean[3], out, lean[4]) == 0 else None  # 0: legkin._kernels.OK

    def _fk_error(self, m: np.ndarray, q: np.ndarray) -> LoopClosureError:
        errs = loop_errors(self.model, self._loopset.data, self._loopset.loops, self._fk_step(m, q)[0])
        worst = max(errs, key=lambda e: e.worst)
        return LoopClosureError(
            f"closed_fk: the loops do not close with motors {np.array2string(m, precision=4)} from q_near "
            f"(worst loop {worst.name}: {worst.worst:.3g} m or rad)", residual=worst.worst, open_loops=errs,
        )

    @overload
    def closed_fk(self, motors, q_near=..., *, return_mask: Literal[False] = ...) -> np.ndarray: ...

    @overload
    def closed_fk(self, motors, q_near=..., *, return_mask: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...

    def closed_fk(self, motors, q_near=None, *, return_mask: bool = False):
        """The closed configuration with the motors at ``motors``, continuous with ``q_near``.

        Args:
            motors: the actuated joints' values, in ``robot.actuated_joints`` order (rad or m), shape
                ``(..., n_motors)``.
            q_near: the configuration the answer is continuous with (default ``q0``): the branch a controller is
                on. Warm-start it with the last answer. Every row of a batch starts from it.
            return_mask: also return the mask of the rows solved.

        Returns:
            ``q`` (``(..., model.nq)``): motors exactly as given, every loop closed to 1e-10 m and rad; a batch has
            NaN rows where the loops do not close (and, with ``return_mask``, ``(q, mask)``).

        Raises:
            InvalidInputError: ``motors`` of the wrong shape or not finite, a bad ``q_near``.
            LoopClosureError: (single call) the loops do not close with these motor values (out of the workspace,
                or across a singularity from ``q_near``).
        """
        if return_mask is False:
            lean = self._fk_lean(motors, q_near)
            if lean is not None:
                return lean
        iq = self._compiled()[1]
        m = as_input(motors, "motors", (len(iq),))
        return_mask = check_flag(return_mask, "return_mask")
        q = self._near(q_near)
        if m.ndim == 1:
            out = self._closed_fk_one(m, q, iq)
            return finish(q if out is None else out, np.asarray(out is not None), True, return_mask,
                          lambda: self._fk_error(m, q))
        rows = m.reshape(-1, len(iq))
        qs = np.full((len(rows), self.model.nq), np.nan)
        for i, row in enumerate(rows):
            out = self._closed_fk_one(row, q, iq)
            if out is not None:
                qs[i] = out
        ok = ~np.isnan(qs[:, 0])
        return finish(qs.reshape(*m.shape[:-1], self.model.nq), ok.reshape(m.shape[:-1]), False, return_mask,
                      lambda: self._fk_error(m, q))

    # ------------------------------------------------------------------ closed_jacobian
    def _jacobian_one(self, q: np.ndarray, frame: str, reference) -> np.ndarray:
        tree, _, iv, passive = self._compiled()
        if tree is None:  # joint kinds the kernel does not handle: Pinocchio's Jacobians
            jf = self.frame_jacobian(q, frame, reference)  # type: ignore[attr-defined]
            jc = self._loopset.residual_and_jacobian(q)[1]
            dvp = -np.linalg.pinv(jc[:, passive], rcond=1e-10) @ jc[:, iv]
            return np.asarray(jf[:, iv] + jf[:, passive] @ dvp)
        from ._tree_kernels import closed_jacobian_k

        self.frame_jacobian(q, frame, reference)  # type: ignore[attr-defined]  # checks frame and reference
        f = self.model.frames[self.frame_id(frame)]  # type: ignore[attr-defined]
        t = tree
        out, m = np.empty((6, len(iv))), np.empty((4, 4))
        closed_jacobian_k(q, t.parent, t.kind, t.axis, t.place_r, t.place_t, t.idx_q, t.idx_v, t.loop_j, t.loop_r,
                          t.loop_t, t.loop_six, passive, iv, f.parentJoint, f.placement.rotation.copy(),
                          f.placement.translation.copy(), out, m)
        return _from_lwa(out, m, reference)

    def closed_jacobian(self, q, frame: str, reference=pin.LOCAL_WORLD_ALIGNED, *, return_mask: bool = False):
        """The twist of ``frame`` per motor velocity through the loops, 6 x n_motors.

        ``(J_f,m - J_f,p pinv(J_p) J_m)``: the passive velocities are the minimum-norm solution of the loops'
        velocity equation (idle motions set to zero).

        Args:
            q: a closed configuration, shape ``(..., model.nq)``.
            frame: a frame name.
            reference: as :meth:`legkin.Robot.frame_jacobian` (default ``LOCAL_WORLD_ALIGNED``: linear part the
                frame origin's velocity in world axes, m per rad (or per m); angular part rad/s, world axes).
            return_mask: also return the mask (every row of finite input is computed).

        Returns:
            ``(..., 6, n_motors)`` (and, with ``return_mask``, the mask).

        Raises:
            InvalidInputError: a bad ``q`` (shape, NaN/inf) or frame name.
        """
        return_mask = check_flag(return_mask, "return_mask")
        x = as_input(q, "q", (self.model.nq,))
        n = len(self._compiled()[1])
        rows = x.reshape(-1, self.model.nq)
        out = np.array([self._jacobian_one(self.check_q(r), frame, reference) for r in rows])  # type: ignore
        out = out.reshape(*x.shape[:-1], 6, n)
        ok = np.ones(x.shape[:-1], dtype=bool)
        return finish(out, ok, x.ndim == 1, return_mask, lambda: InvalidInputError("closed_jacobian: not computed"))

    # ------------------------------------------------------------------ closed_ik
    def _pose_target(self, pose) -> tuple[pin.SE3 | None, np.ndarray]:
        if isinstance(pose, pin.SE3):
            return pose, pose.translation
        x = np.asarray(pose, dtype=float)
        if x.shape == (3,):
            return None, x
        return pin.SE3(x), x[:3, 3]

    def _ik_compiled(self, fid: int, target: pin.SE3 | None, position: np.ndarray, q0: np.ndarray) -> np.ndarray | None:
        """The compiled solve of ``closed_ik``: the target as one more loop, from the frame to the world (joint 0) at
        the target (a point loop for a position), every joint free; the configuration if every loop and the target
        are met to :data:`CLOSED_TOL`, else None (no kernel for these joints, or a stall)."""
        t = self._tree()
        if t is None:
            return None
        f = self.model.frames[fid]
        rot = np.eye(3) if target is None else target.rotation
        ik = Tree(**{**t.__dict__, "loop_j": np.vstack([t.loop_j, [[f.parentJoint, 0]]]),
                     "loop_r": np.concatenate([t.loop_r, [[f.placement.rotation, rot]]]),
                     "loop_t": np.concatenate([t.loop_t, [[f.placement.translation, position]]]),
                     "loop_six": np.append(t.loop_six, target is not None)})
        out, info = np.empty_like(q0), np.zeros(3)
        status = _solver()(q0, _NO_MOTORS, *pack(ik, _NO_MOTORS.astype(np.int64), np.ones(self.model.nv, dtype=bool)),
                           CLOSED_TOL, 4 * _MAX_ITER, out, info)
        return out if status == 0 else None  # 0: legkin._kernels.OK

    def _ik_one(self, fid: int, pose, q0: np.ndarray) -> tuple[np.ndarray, float, float]:
        """The compiled Gauss-Newton (:meth:`_ik_compiled`), else Levenberg-Marquardt over Pinocchio, from ``q0`` on
        the loops and the frame's error; returns q, distance (m), angle (rad)."""
        target, position = self._pose_target(pose)
        model, data = self.model, self._loopset.data
        q = self._ik_compiled(fid, target, position, q0)
        if q is None:
            def fun(q):
                r, jc = self._loopset.residual_and_jacobian(q)
                pin.updateFramePlacements(model, data)
                om = data.oMf[fid]
                ref = pin.LOCAL if target is not None else pin.LOCAL_WORLD_ALIGNED
                jf = pin.getFrameJacobian(model, data, fid, ref)
                if target is None:
                    return np.concatenate([r, om.translation - position]), np.vstack([jc, jf[:3]])
                err = pin.log6(target.actInv(om)).vector
                return np.concatenate([r, err]), np.vstack([jc, pin.Jlog6(target.actInv(om)) @ jf])

            q = levenberg_marquardt(model, fun, q0, np.ones(model.nv, dtype=bool), 1e-14, 4 * _MAX_ITER)[0]
        pin.framesForwardKinematics(model, data, q)
        om = data.oMf[fid]
        dist = float(np.linalg.norm(om.translation - position))
        angle = 0.0 if target is None else float(np.linalg.norm(pin.log3(target.rotation.T @ om.rotation)))
        return q, dist, angle

    def closed_ik(self, frame: str, pose, q_near=None, *, return_mask: bool = False):
        """A closed configuration placing ``frame`` at ``pose``, continuous with ``q_near``.

        Args:
            frame: a frame name.
            pose: the target: a ``pinocchio.SE3``, a 4 x 4 matrix (placement) or a position (3,) (m); a batch of
                matrices ``(..., 4, 4)`` or of positions ``(..., 3)``.
            q_near: the start (default ``q0``); the answer is the one Gauss-Newton reaches from it.
            return_mask: also return the mask of the targets solved.

        Returns:
            ``q`` (``(..., model.nq)``) with every loop closed to 1e-10 and the frame on the target to 1e-10 m / rad
            (NaN rows of a batch where not); the motors are ``q`` at ``robot.actuated_joints``.

        Raises:
            InvalidInputError: a bad frame, pose or ``q_near``.
            UnreachableError: (single call) no closed configuration reached from ``q_near`` places the frame there
                (``closest``: the configuration reached, ``distance``: its position error, m).
        """
        return_mask = check_flag(return_mask, "return_mask")
        fid = self.frame_id(frame)  # type: ignore[attr-defined]
        q0 = self._near(q_near)
        core: tuple[int, ...] = ()
        shape: tuple[int, ...] = ()
        if isinstance(pose, pin.SE3):
            items: list[Any] = [pose]
        else:
            x = as_input(pose, "pose")
            core = (4, 4) if x.shape[-2:] == (4, 4) else (3,)
            if x.shape[x.ndim - len(core):] != core:
                raise InvalidInputError(
                    f"pose must be a pinocchio.SE3, a (..., 4, 4) matrix or a (..., 3) position, got shape {x.shape}"
                )
            shape = x.shape[: x.ndim - len(core)]
            items = list(x.reshape(-1, *core))
        qs = np.full((len(items), self.model.nq), np.nan)
        last = (q0, np.inf, np.inf)
        for i, item in enumerate(items):
            last = self._ik_one(fid, item, q0)
            if self._closed(last[0]) and max(last[1], last[2]) <= CLOSED_TOL:
                qs[i] = last[0]
        ok = ~np.isnan(qs[:, 0])

        def error() -> UnreachableError:
            return UnreachableError(
                f"closed_ik: frame {frame!r} does not reach the target from q_near: {last[1]:.3g} m and "
                f"{last[2]:.3g} rad off at the closest closed configuration found", target=pose, closest=last[0],
                distance=last[1],
            )

        return finish(qs.reshape(*shape, self.model.nq), ok.reshape(shape), shape == (), return_mask, error)
