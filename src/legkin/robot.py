"""``legkin.load``: a Pinocchio model of a registered mechanism, with its loops and poses."""

from __future__ import annotations

import difflib
import importlib
import os
from types import ModuleType
from typing import Any, Iterable, Literal, Mapping, overload

import numpy as np
import pinocchio as pin

from ._batch import as_input, check_flag, check_integer, check_number
from ._generate import model_files
from ._registry import MODELS, ModelSpec, get_spec
from .closed import ClosedLoopMixin
from .errors import InvalidInputError, InvalidParameterError
from .loops import DEFAULT_DAMPING, LoopSet, LoopSolveInfo, parse_loops

__all__ = ["Robot", "load"]

_REFERENCE_FRAMES = dict(pin.ReferenceFrame.names)


def _names(name: str, value) -> list[str]:
    """A collection of joint names (a list, tuple, set or the keys of a mapping; None for none; a lone string
    is refused)."""
    if value is None:
        return []
    if isinstance(value, (str, bytes)):
        raise InvalidInputError(
            f"{name} must be a collection of joint names, got the string {value!r} (write [{value!r}])"
        )
    try:
        names = list(value)
    except TypeError:
        raise InvalidInputError(f"{name} must be a collection of joint names, got {value!r}") from None
    return names


class Robot(ClosedLoopMixin):
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
        geometry: the mechanism's ``Geometry`` for these parameters (what its kinematic functions take as
            ``geometry=``), e.g. ``legkin.load("tripod", alpha=0.8).geometry.alpha == 0.8``.
        kinematics: the mechanism's package (``legkin.<name>``: ``fk``, ``ik``, ``jacobian``, ...).
    """

    def __init__(self, name: str | ModelSpec, params: Mapping[str, object], floating: bool = False):
        spec = name if isinstance(name, ModelSpec) else get_spec(name)
        self.spec = spec
        self.name = spec.name
        self.params = dict(params)
        self.floating = floating
        if spec.locate is not None:  # a distribution's installed URDF
            self.urdf_path, self.srdf_path, pkg = spec.locate(spec.name)
        else:
            self.urdf_path, self.srdf_path = model_files(spec, self.params)
            pkg = [str(self.urdf_path.parent)]
        if floating:
            self.model = pin.buildModelFromUrdf(str(self.urdf_path), pin.JointModelFreeFlyer())
        else:
            self.model = pin.buildModelFromUrdf(str(self.urdf_path))
        self.data = self.model.createData()
        self.visual_model = pin.buildGeomFromUrdf(self.model, str(self.urdf_path), pin.VISUAL, package_dirs=pkg)
        self.collision_model = pin.buildGeomFromUrdf(
            self.model, str(self.urdf_path), pin.COLLISION, package_dirs=pkg
        )
        self.loops = parse_loops(self.urdf_path)
        self._loopset = LoopSet(self.model, self.loops)
        self.constraint_models = self._loopset.models
        self.constraint_datas = self._loopset.datas
        for j in spec.actuated_joints or ():
            self.joint_id(j)  # raises if the URDF and the registry disagree
        self.actuated_joints: tuple[str, ...] = spec.actuated_joints or ()
        if spec.actuated_joints is None:  # an open tree: every one-coordinate joint is driven
            self.actuated_joints = tuple(
                n for n, j in zip(self.model.names[1:], self.model.joints[1:]) if j.nq == 1 and j.nv == 1
            )
        if self.srdf_path is not None:
            pin.loadReferenceConfigurations(self.model, str(self.srdf_path), False)
        self.poses = {e.key(): np.array(e.data()) for e in self.model.referenceConfigurations}
        if spec.default_pose is not None and spec.reference_pose and spec.reference_pose not in self.poses:
            pose = spec.default_pose(self.model, spec.name)  # a robot without SRDF: legkin's own standing pose
            if pose is not None:
                self.poses[spec.reference_pose] = pose
        self.q0 = self.poses.get(spec.reference_pose, pin.neutral(self.model)).copy()

    @property
    def kinematics(self) -> ModuleType:
        """The mechanism's package, ``legkin.<name>`` (its analytic kinematics)."""
        return importlib.import_module(self.spec.package)

    @property
    def geometry(self) -> Any:
        """``legkin.<name>.Geometry.from_params(self.params)``: the geometry this model was generated with.

        A registry entry may say otherwise (:attr:`ModelSpec.geometry`): for a robot of :mod:`legkin.legs`, the
        legs measured from its model, ``legkin.legs.from_model(self.model)``, a dict ``{leg name: Leg}``.
        """
        if self.spec.geometry is not None:
            return self.spec.geometry(self)
        return self.kinematics.Geometry.from_params(self.params)

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
        """Pinocchio id of joint ``name``.

        Args:
            name: a joint of the model.

        Returns:
            Its index in ``model.joints`` (unitless; the universe is 0).

        Raises:
            InvalidInputError: ``name`` is not a string or not a joint of the model (the message lists them).
        """
        if not isinstance(name, str):
            joints = ", ".join(self.joint_names)
            raise InvalidInputError(f"a joint name must be a string, got {name!r}; joints: {joints}")
        if not self.model.existJointName(name):
            raise InvalidInputError(f"model {self.name!r} has no joint {name!r}; joints: {', '.join(self.joint_names)}")
        return self.model.getJointId(name)

    def idx_q(self, name: str) -> int:
        """Index of joint ``name``'s first coordinate in ``q``.

        Args:
            name: a joint of the model.

        Returns:
            The index in a configuration vector (whose entries are rad or m, by joint type).
        """
        return self.model.joints[self.joint_id(name)].idx_q

    def idx_v(self, name: str) -> int:
        """Index of joint ``name``'s first coordinate in a velocity vector.

        Args:
            name: a joint of the model.

        Returns:
            The index in a velocity vector (whose entries are rad/s or m/s, by joint type).
        """
        return self.model.joints[self.joint_id(name)].idx_v

    def frame_id(self, name: str) -> int:
        """Pinocchio id of frame ``name``.

        Args:
            name: a frame of the model.

        Returns:
            Its index in ``model.frames`` (unitless).

        Raises:
            InvalidInputError: ``name`` is not a string or not a frame of the model (with close matches).
        """
        if not isinstance(name, str):
            raise InvalidInputError(f"a frame name must be a string, got {name!r}")
        if not self.model.existFrame(name):
            frames = [f.name for f in self.model.frames]
            close = difflib.get_close_matches(name, frames, n=5)
            hint = f"; did you mean {', '.join(close)}?" if close else f"; it has {len(frames)} frames"
            raise InvalidInputError(f"model {self.name!r} has no frame {name!r}{hint}")
        return self.model.getFrameId(name)

    def _joint_value(self, what: str, name: str, value) -> tuple[slice, np.ndarray]:
        """The ``q`` slice of joint ``name`` and ``value`` checked for it (a number for a 1-coordinate joint)."""
        j = self.model.joints[self.joint_id(name)]
        x = as_input(value, what)
        if j.nq == 1 and x.shape in ((), (1,)):
            x = x.reshape(1)
        elif x.shape != (j.nq,):
            want = "a number" if j.nq == 1 else f"{j.nq} coordinates"
            raise InvalidInputError(f"{what} must be {want} (joint {name!r} has nq = {j.nq}), got shape {x.shape}")
        return slice(j.idx_q, j.idx_q + j.nq), x

    def configuration(self, values: Mapping[str, float] | None = None, base: np.ndarray | None = None) -> np.ndarray:
        """A configuration vector: ``base`` (default ``q0``) with the named joints set.

        Args:
            values: joint name -> value (rad or m; a vector of its ``nq`` coordinates for a multi-coordinate joint).
            base: the configuration to start from (default :attr:`q0`).

        Returns:
            The configuration, shape ``(nq,)`` (rad, m).

        Raises:
            InvalidInputError: an unknown joint, a value that is not a finite number (or, for a joint of several
                coordinates, not a vector of its ``nq`` coordinates), or ``base`` not a valid configuration.
        """
        q = self.check_q(self.q0 if base is None else base, "base").copy()
        if values is None:
            return q
        if not isinstance(values, Mapping):
            raise InvalidInputError(f"values must be a mapping joint name -> value, got {values!r}")
        for name, value in values.items():
            sl, x = self._joint_value(f"values[{name!r}]", name, value)
            q[sl] = x
        return q

    def check_q(self, q: Any, name: str = "q") -> np.ndarray:
        """``q`` as a float vector of shape ``(nq,)``, finite and real.

        Args:
            q: a configuration (array-like; rad, m).
            name: its name in the error message.

        Returns:
            ``q`` as a float64 array of shape ``(nq,)``.

        Raises:
            InvalidInputError: (a ``ValueError``) a wrong shape, NaN/inf entries (named by joint), complex,
                string, ragged or other non-numeric input.
        """
        arr = as_input(q, name, allow_nan=True)
        nq = self.model.nq
        if arr.shape != (nq,):
            raise InvalidInputError(f"{name} must have shape ({nq},) for {self.name!r}, got shape {arr.shape}")
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            i = int(bad[0])
            joint = next(n for n in reversed(self.joint_names) if self.idx_q(n) <= i)
            raise InvalidInputError(
                f"{name} must be finite: {bad.size} entr{'y is' if bad.size == 1 else 'ies are'} not, "
                f"first {name}[{i}] = {arr[i]} (joint {joint!r})"
            )
        return arr

    def frame_placement(self, q: Any, frame: str) -> pin.SE3:
        """World placement of ``frame`` at ``q`` (loops are not enforced).

        Args:
            q: a configuration, shape ``(nq,)`` (rad, m).
            frame: a frame of the model.

        Returns:
            The frame's placement in the world frame (translation in m).
        """
        q = self.check_q(q)
        fid = self.frame_id(frame)
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[fid].copy()

    def frame_jacobian(self, q: Any, frame: str, reference: Any = pin.LOCAL_WORLD_ALIGNED) -> np.ndarray:
        """6 x nv Jacobian of ``frame`` of the tree (loops are not enforced).

        Args:
            q: a configuration, shape ``(nq,)`` (rad, m).
            frame: a frame of the model.
            reference: a ``pinocchio.ReferenceFrame`` or its name (``"LOCAL"``, ``"WORLD"``, ``"LOCAL_WORLD_ALIGNED"``).

        Returns:
            ``(6, nv)``: linear rows (m per unit of velocity coordinate) then angular rows (rad per unit).
        """
        q = self.check_q(q)
        fid = self.frame_id(frame)
        if isinstance(reference, str) and reference in _REFERENCE_FRAMES:
            reference = _REFERENCE_FRAMES[reference]
        if not isinstance(reference, pin.ReferenceFrame):
            raise InvalidInputError(
                f"reference must be a pinocchio.ReferenceFrame or one of {', '.join(_REFERENCE_FRAMES)}, "
                f"got {reference!r}"
            )
        return pin.computeFrameJacobian(self.model, self.data, q, fid, reference)

    # ----------------------------------------------------------------- closed loops
    def _free_mask(self, fixed: Iterable[str], what: str = "fixed") -> np.ndarray:
        free = np.ones(self.model.nv, dtype=bool)
        for name in _names(what, fixed):
            j = self.model.joints[self.joint_id(name)]
            free[j.idx_v : j.idx_v + j.nv] = False
        return free

    def constraint_residual(self, q: Any) -> np.ndarray:
        """Stacked loop-closure residual at ``q`` (empty for open chains).

        Args:
            q: a configuration, shape ``(nq,)`` (rad, m).

        Returns:
            The residuals of every loop, stacked: 3 per point loop (m), 6 per frame loop (m, then rad).
        """
        return self._loopset.residual(self.check_q(q))

    def constraint_jacobian(self, q: Any) -> np.ndarray:
        """Stacked loop-closure Jacobian at ``q``.

        Args:
            q: a configuration, shape ``(nq,)`` (rad, m).

        Returns:
            ``(rows, nv)``: the derivative of :meth:`constraint_residual` per velocity coordinate.
        """
        return self._loopset.residual_and_jacobian(self.check_q(q))[1]

    def mobility(self, q: Any, locked: Iterable[str] = (), tol: float = 1e-9) -> int:
        """Degrees of freedom left at ``q``: free velocity coordinates minus the constraint rank.

        Args:
            q: configuration (the loops should be closed).
            locked: joints held fixed (their velocity columns are removed), a collection of names.
            tol: singular values below ``tol`` times the largest count as zero; in [0, 1).

        Returns:
            The number of independent velocities the loops leave (unitless).

        Raises:
            InvalidInputError: a bad ``q``, an unknown joint in ``locked``, ``tol`` outside [0, 1).
        """
        q = self.check_q(q)
        free = self._free_mask(locked, "locked")
        return self._loopset.mobility(q, free, check_number(tol, "tol", 0.0, 1.0, high_open=True))

    @overload
    def solve_loops(self, q_init: Any = ..., fixed: Mapping[str, float] | Iterable[str] | None = ..., *,
                    tol: float = ..., max_iter: int = ..., damping: float = ...,
                    return_info: Literal[False] = ...) -> np.ndarray: ...
    @overload
    def solve_loops(self, q_init: Any = ..., fixed: Mapping[str, float] | Iterable[str] | None = ..., *,
                    tol: float = ..., max_iter: int = ..., damping: float = ...,
                    return_info: Literal[True]) -> tuple[np.ndarray, LoopSolveInfo]: ...
    def solve_loops(
        self,
        q_init: Any = None,
        fixed: Mapping[str, float] | Iterable[str] | None = None,
        *,
        tol: float = 1e-12,
        max_iter: int = 100,
        damping: float = DEFAULT_DAMPING,
        return_info: bool = False,
    ) -> np.ndarray | tuple[np.ndarray, LoopSolveInfo]:
        """Assemble a configuration that closes every loop, with some joints held.

        Levenberg-Marquardt on the stacked constraint residuals, with Pinocchio's constraint
        Jacobians; rank-deficient stacks (redundant rows) are handled by a pseudo-inverse.

        Args:
            q_init: starting configuration (default ``q0``).
            fixed: joints held: a mapping name -> value (set first), or a collection of names held at ``q_init``.
            tol: stop when the residual norm is at most ``tol`` (a finite number > 0).
            max_iter: iteration cap (an integer >= 0; 0 only tests whether ``q_init`` closes).
            damping: the smallest Levenberg-Marquardt damping tried when the Gauss-Newton step fails (> 0).
            return_info: also return a :class:`LoopSolveInfo` (iterations, residual).

        Returns:
            The closed configuration ``(nq,)`` (rad, m), and the :class:`LoopSolveInfo` if asked.

        Raises:
            InvalidInputError: (a ``ValueError``) a bad ``q_init`` (shape, NaN/inf, complex), an unknown joint
                in ``fixed`` or a held value that is not a finite number, or a keyword out of its range.
            LoopClosureError: the residual did not reach ``tol`` (carries the residual reached).
        """
        q = self.check_q(self.q0 if q_init is None else q_init, "q_init").copy()
        tol = check_number(tol, "tol", 0.0, low_open=True)
        max_iter = check_integer(max_iter, "max_iter", 0)
        damping = check_number(damping, "damping", 0.0, low_open=True)
        return_info = check_flag(return_info, "return_info")
        if fixed is None:
            fixed = ()
        if isinstance(fixed, Mapping):
            for name, value in fixed.items():
                sl, x = self._joint_value(f"fixed[{name!r}]", name, value)
                q[sl] = x
        free = self._free_mask(fixed)
        q, info = self._loopset.solve(q, free, tol, max_iter, damping)
        return (q, info) if return_info else q


def _is_path(name: object) -> bool:
    """A file name rather than a registry name: it has a path separator or a model file's suffix."""
    import os

    return isinstance(name, (str, os.PathLike)) and (
        not isinstance(name, str) or "/" in name or os.sep in name or name.lower().endswith((".urdf", ".xacro", ".xml"))
    )


def load(name: str | os.PathLike[str], *, floating: bool = False, **params: Any) -> Robot:
    """Load a registered mechanism, or a robot from its own files, in Pinocchio.

    Args:
        name: a name from :func:`legkin.list_models`, or a path (``str`` with a ``/`` or a ``.urdf``, ``.xacro``
            or ``.xml`` suffix, or a ``pathlib.Path``): a robot from its own files, read by
            :func:`legkin.loaders.load_file` (its keyword ``loops=``: a YAML sidecar path).
        floating: add a free-flyer root joint (only for models where that makes sense).
        **params: xacro arguments (in the units of the model's :class:`~legkin._registry.Param`, m or rad);
            validated before any file is written.

    Returns:
        The loaded :class:`Robot` (its model, loops, poses and geometry).

    Raises:
        UnknownModelError: ``name`` is not registered.
        InvalidParameterError: an unknown argument, a value out of range or of the wrong kind (a string
            argument given a non-string, a number given a bool, an array or a complex), ``floating`` not a bool.
    """
    if not isinstance(floating, (bool, np.bool_)):
        raise InvalidParameterError(f"floating must be True or False, got {floating!r}")
    if _is_path(name):
        import importlib  # the file loader sits above this module (it subclasses Robot): found by name, at run time

        load_file = importlib.import_module("legkin.loaders").load_file
        unknown = sorted(set(params) - {"loops"})
        if unknown:
            raise InvalidParameterError(f"unknown argument(s) {', '.join(unknown)} for a robot file; known: loops")
        return load_file(name, floating=bool(floating), **params)
    spec = get_spec(name)
    floating = bool(floating)
    args = spec.resolve_params(params)
    if floating and not spec.floating:
        floating_models = ", ".join(n for n, s in MODELS.items() if s.floating)
        raise InvalidParameterError(
            f"model {name!r} is fixed-base: floating=True is available only for {floating_models}"
        )
    return Robot(spec, args, floating=floating)
