"""``legkin.load``: a Pinocchio model of a registered mechanism, with its loops and poses."""

from __future__ import annotations

from pathlib import Path
from typing import Iterable, Mapping

import numpy as np
import pinocchio as pin

from ._generate import model_files
from ._registry import MODELS, get_spec
from .errors import InvalidInputError, InvalidParameterError, LegkinError
from .loops import LoopSet, LoopSolveInfo, parse_loops

__all__ = ["Robot", "load"]


class Robot:
    """A mechanism loaded in Pinocchio.

    Attributes:
        name: registry name.
        params: the full set of xacro arguments used.
        model, data: Pinocchio model and data (spanning tree of the mechanism).
        visual_model, collision_model: Pinocchio geometry models.
        loops: the loop declarations read from the URDF.
        constraint_models: Pinocchio constraint models closing the loops (empty for open chains).
        actuated_joints: names of the actuated joints.
        poses: named reference configurations from the SRDF (e.g. ``"standing"``).
        q0: the reference configuration (``poses[spec.reference_pose]``, else neutral).
        urdf_path, srdf_path: the files the model was built from.
        floating: whether a free-flyer root joint was added.
    """

    def __init__(self, name: str, params: Mapping[str, object], floating: bool = False):
        spec = get_spec(name)
        self.spec = spec
        self.name = name
        self.params = dict(params)
        self.floating = floating
        self.urdf_path, self.srdf_path = model_files(spec, self.params)
        if floating:
            self.model = pin.buildModelFromUrdf(str(self.urdf_path), pin.JointModelFreeFlyer())
        else:
            self.model = pin.buildModelFromUrdf(str(self.urdf_path))
        self.data = self.model.createData()
        pkg = [str(self.urdf_path.parent)]
        self.visual_model = pin.buildGeomFromUrdf(self.model, str(self.urdf_path), pin.VISUAL, package_dirs=pkg)
        self.collision_model = pin.buildGeomFromUrdf(
            self.model, str(self.urdf_path), pin.COLLISION, package_dirs=pkg
        )
        self.loops = parse_loops(self.urdf_path)
        self._loopset = LoopSet(self.model, self.loops)
        self.constraint_models = self._loopset.models
        self.constraint_datas = self._loopset.datas
        for j in spec.actuated_joints:
            self.joint_id(j)  # raises if the URDF and the registry disagree
        self.actuated_joints = spec.actuated_joints
        if self.srdf_path is not None:
            pin.loadReferenceConfigurations(self.model, str(self.srdf_path), False)
        self.poses = {e.key(): np.array(e.data()) for e in self.model.referenceConfigurations}
        self.q0 = self.poses.get(spec.reference_pose, pin.neutral(self.model)).copy()

    def __repr__(self) -> str:
        return (
            f"Robot({self.name!r}, nq={self.model.nq}, nv={self.model.nv}, loops={len(self.loops)}, "
            f"actuated={len(self.actuated_joints)}, floating={self.floating})"
        )

    # ----------------------------------------------------------------- joints and frames
    @property
    def joint_names(self) -> list[str]:
        """Names of the joints, universe excluded, in configuration order."""
        return list(self.model.names)[1:]

    def joint_id(self, name: str) -> int:
        if not self.model.existJointName(name):
            raise LegkinError(f"model {self.name!r} has no joint {name!r}; joints: {', '.join(self.joint_names)}")
        return self.model.getJointId(name)

    def idx_q(self, name: str) -> int:
        """Index of joint ``name``'s first coordinate in ``q``."""
        return self.model.joints[self.joint_id(name)].idx_q

    def idx_v(self, name: str) -> int:
        """Index of joint ``name``'s first coordinate in a velocity vector."""
        return self.model.joints[self.joint_id(name)].idx_v

    def frame_id(self, name: str) -> int:
        if not self.model.existFrame(name):
            raise LegkinError(f"model {self.name!r} has no frame {name!r}")
        return self.model.getFrameId(name)

    def configuration(self, values: Mapping[str, float] | None = None, base: np.ndarray | None = None) -> np.ndarray:
        """A configuration vector: ``base`` (default ``q0``) with the named 1-DOF joints set."""
        q = np.array(self.q0 if base is None else base, dtype=float)
        for name, value in (values or {}).items():
            q[self.idx_q(name)] = value
        return q

    def check_q(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.model.nq,):
            raise InvalidInputError(f"q must have shape ({self.model.nq},) for {self.name!r}, got {q.shape}")
        if not np.all(np.isfinite(q)):
            raise InvalidInputError(f"q must be finite, got {q}")
        return q

    def frame_placement(self, q, frame: str) -> pin.SE3:
        """World placement of ``frame`` at ``q`` (loops are not enforced)."""
        q = self.check_q(q)
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self.frame_id(frame)].copy()

    def frame_jacobian(self, q, frame: str, reference=pin.LOCAL_WORLD_ALIGNED) -> np.ndarray:
        """6 x nv Jacobian of ``frame`` of the tree (loops are not enforced)."""
        q = self.check_q(q)
        return pin.computeFrameJacobian(self.model, self.data, q, self.frame_id(frame), reference)

    # ----------------------------------------------------------------- closed loops
    def _free_mask(self, fixed: Iterable[str]) -> np.ndarray:
        free = np.ones(self.model.nv, dtype=bool)
        for name in fixed:
            j = self.model.joints[self.joint_id(name)]
            free[j.idx_v : j.idx_v + j.nv] = False
        return free

    def constraint_residual(self, q) -> np.ndarray:
        """Stacked loop-closure residual at ``q`` (empty for open chains); units m and rad."""
        return self._loopset.residual(self.check_q(q))

    def constraint_jacobian(self, q) -> np.ndarray:
        """Stacked loop-closure Jacobian (rows, nv) at ``q``."""
        return self._loopset.residual_and_jacobian(self.check_q(q))[1]

    def mobility(self, q, locked: Iterable[str] = (), tol: float = 1e-9) -> int:
        """Degrees of freedom left at ``q``: free velocity coordinates minus the constraint rank.

        Args:
            q: configuration (the loops should be closed).
            locked: joints held fixed (their velocity columns are removed).
            tol: singular values below ``tol`` times the largest count as zero.
        """
        return self._loopset.mobility(self.check_q(q), self._free_mask(locked), tol)

    def solve_loops(
        self,
        q_init=None,
        fixed: Mapping[str, float] | Iterable[str] | None = None,
        *,
        tol: float = 1e-12,
        max_iter: int = 100,
        return_info: bool = False,
    ) -> np.ndarray | tuple[np.ndarray, LoopSolveInfo]:
        """Assemble a configuration that closes every loop, with some joints held.

        Levenberg-Marquardt on the stacked constraint residuals, with Pinocchio's constraint
        Jacobians; rank-deficient stacks (redundant rows) are handled by a pseudo-inverse.

        Args:
            q_init: starting configuration (default ``q0``).
            fixed: joints held: a mapping name -> value (set first), or names held at ``q_init``.
            tol: stop when the residual norm is at most ``tol``.
            max_iter: iteration cap.
            return_info: also return a :class:`LoopSolveInfo` (iterations, residual).

        Raises:
            LoopClosureError: the residual did not reach ``tol`` (carries the residual reached).
        """
        q = self.check_q(self.q0 if q_init is None else q_init).copy()
        fixed = fixed or {}
        if isinstance(fixed, Mapping):
            for name, value in fixed.items():
                j = self.model.joints[self.joint_id(name)]
                q[j.idx_q : j.idx_q + j.nq] = value
        q, info = self._loopset.solve(q, self._free_mask(fixed), tol, max_iter)
        self.last_solve = info
        return (q, info) if return_info else q


def load(name: str, *, floating: bool = False, **params) -> Robot:
    """Load a registered mechanism in Pinocchio.

    Args:
        name: a name from :func:`legkin.list_models`.
        floating: add a free-flyer root joint (only for models where that makes sense).
        **params: xacro arguments; validated before any file is written.

    Raises:
        UnknownModelError: ``name`` is not registered.
        InvalidParameterError: an unknown argument or a value out of range.
    """
    spec = get_spec(name)
    args = spec.resolve_params(params)
    if floating and not spec.floating:
        floating_models = ", ".join(n for n, s in MODELS.items() if s.floating)
        raise InvalidParameterError(
            f"model {name!r} is fixed-base: floating=True is available only for {floating_models}"
        )
    return Robot(name, args, floating=floating)
