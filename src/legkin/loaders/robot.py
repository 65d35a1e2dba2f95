"""``FileRobot``: a :class:`legkin.Robot` built from a user's own files (URDF + YAML, xacro/URDF with
``<loop_closure>``, MJCF with equalities)."""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np
import pinocchio as pin

from .._batch import check_number
from .._registry import ModelSpec
from ..closing import CLOSED_TOL, ClosingInfo, close_loops
from ..errors import InvalidInputError, LegkinError, LoopClosureError
from ..loops import LoopSet, LoopSpec, parse_loops
from ..mjcf.reader import read_mjcf
from ..robot import Robot
from .sidecar import Sidecar, read_sidecar
from .urdf import build_urdf_models, urdf_text

__all__ = ["FileRobot", "load_file", "REFERENCE_POSE"]

#: Name of the closed reference pose of a robot loaded from a file (``robot.poses["closed"]``, ``robot.q0``).
REFERENCE_POSE = "closed"
#: Gauss-Newton iterations of the closing of ``q0`` at load (the nine Gepetto robots that close need 3-11).
_LOAD_ITER = 100


def _robot_name(path: Path) -> str:
    stem = path.name.split(".")[0]
    return path.parent.name if stem == "robot" and path.parent.name else stem


def _check_frames(model: pin.Model, loops: Iterable[LoopSpec], where: str) -> None:
    for i, lp in enumerate(loops):
        for k, frame in enumerate((lp.frame1, lp.frame2)):
            if not model.existFrame(frame):
                raise InvalidInputError(
                    f"{where}: key 'closed_loop[{i}][{k}]' (loop {lp.name!r}): the model has no frame {frame!r}"
                )


def _check_motors(model: pin.Model, motors: Iterable[str], where: str) -> None:
    for i, name in enumerate(motors):
        if not model.existJointName(name):
            raise InvalidInputError(
                f"{where}: key 'name_mot[{i}]': the model has no joint {name!r}; joints: {', '.join(model.names[1:])}"
            )


class FileRobot(Robot):
    """A robot read from its own files; see :func:`load_file`.

    Attributes (besides :class:`legkin.Robot`'s):
        actuated: the actuated joint names (the same as ``actuated_joints``).
        missing_meshes: mesh files the URDF names that are not there (left out of the visual model).
        closing: how ``q0`` was closed (:class:`legkin.closing.ClosingInfo`), or the
            :class:`~legkin.errors.LoopClosureError` raised when it could not be (then ``q0`` is neutral;
            the load tries the compiled Gauss-Newton only, or a direct Levenberg-Marquardt for joint kinds it does not
            handle: ``solve_loops()`` adds a homotopy and restarts, and says why a loop stays open).
        load_seconds: wall time of the model's construction, s (the closing of ``q0`` excluded).
    """

    def __init__(self, path: Path, *, loops: Sidecar | None = None, floating: bool = False) -> None:
        t0 = time.perf_counter()
        self.urdf_path, self.srdf_path, self.floating, self.params = path, None, floating, {}
        self.name = _robot_name(path)
        self.missing_meshes: list[str] = []
        keys: dict[str, np.ndarray] = {}
        if path.suffix.lower() == ".xml":
            m = read_mjcf(path)
            model, visual, collision, loop_specs, motors, keys = (
                m.model, m.visual_model, m.collision_model, m.loops, m.actuated, m.keys)
            where = str(path)
        else:
            model, visual, collision, loop_specs, motors, where = self._from_urdf(path, loops, floating)
        _check_frames(model, loop_specs, where)
        _check_motors(model, motors, where)
        self.model, self.data = model, model.createData()
        self.visual_model, self.collision_model = visual, collision
        self.loops = list(loop_specs)
        self._loopset = LoopSet(model, self.loops)
        self.constraint_models, self.constraint_datas = self._loopset.models, self._loopset.datas
        self.actuated_joints = tuple(motors)
        self.spec = ModelSpec(name=self.name, title=f"{self.name} (from {path.name})", seed="",
                              actuated_joints=self.actuated_joints, reference_pose=REFERENCE_POSE, source=str(path))
        self.poses = dict(keys)
        self.load_seconds = time.perf_counter() - t0
        self.q0 = pin.neutral(model)
        self.closing: ClosingInfo | LoopClosureError
        fast, lm = self._fast()
        try:
            self.q0, self.closing = close_loops(self._loopset, self.q0, np.ones(model.nv, dtype=bool), fast=fast,
                                                lm=lm, homotopy=False, diagnose_failure=False)
            self.poses[REFERENCE_POSE] = self.q0.copy()
        except LoopClosureError as exc:
            self.closing = exc

    def _from_urdf(self, path: Path, sidecar: Sidecar | None, floating: bool):
        text = urdf_text(path)
        if sidecar is None:
            yaml_path = path.parent / "robot.yaml"
            if not yaml_path.exists():
                yaml_path = path.with_suffix(".yaml")
            sidecar = read_sidecar(yaml_path) if yaml_path.exists() else None
        where = str(sidecar.path) if sidecar is not None and sidecar.path else str(path)
        built = build_urdf_models(text, path, sidecar.joint_types if sidecar else None, floating=floating, where=where)
        self.missing_meshes = built.missing_meshes
        if sidecar is not None:
            return built.model, built.visual_model, built.collision_model, sidecar.loops, sidecar.actuated, where
        import io

        try:
            specs = parse_loops(io.StringIO(text))  # type: ignore[arg-type]
        except LegkinError as exc:
            raise InvalidInputError(f"{path}: {exc}") from None
        motors = [j.get("name", "") for j in ET.fromstring(text).iterfind("transmission/joint")]
        return built.model, built.visual_model, built.collision_model, specs, motors, str(path)

    def _fast(self) -> tuple[Any, bool]:
        """The compiled solve for :func:`legkin.closing.close_loops` (None when a joint kind is not supported) and
        whether the Levenberg-Marquardt strategies must run (only without it)."""
        if self._tree() is None:
            return None, True

        def fast(q, free, loops=None, point=False):
            q, _, iterations, _ = self._tree_solve(q, np.asarray(free, dtype=np.bool_), _LOAD_ITER, loops=loops,
                                                   point=point)
            return q, iterations

        return fast, False

    @property
    def actuated(self) -> tuple[str, ...]:
        """The actuated joint names (``name_mot`` of the YAML, the MJCF's actuators)."""
        return tuple(self.actuated_joints)

    @property
    def kinematics(self) -> Any:
        raise LegkinError(f"{self.name!r} is a robot from a file: it has no analytic kinematics package")

    @property
    def geometry(self) -> Any:
        raise LegkinError(f"{self.name!r} is a robot from a file: it has no analytic geometry")

    def solve_loops(  # type: ignore[override]
        self, q_init=None, fixed: Mapping[str, float] | Iterable[str] | None = None, *, tol: float = CLOSED_TOL,
        seed: int = 0, return_info: bool = False, **_ignored: Any,
    ):
        """Close every loop from ``q_init`` (default neutral): direct, homotopy, then random restarts
        (:func:`legkin.closing.close_loops`), checked on the frames themselves.

        Args:
            q_init: the start (default the neutral configuration).
            fixed: joints held: a mapping name -> value (set first), or a collection of names held at ``q_init``.
            tol: the largest frame error accepted, m and rad (a finite number > 0).
            seed: the restarts' random seed.
            return_info: also return a :class:`legkin.closing.ClosingInfo`.

        Raises:
            InvalidInputError: a bad ``q_init``, joint name, held value or ``tol``.
            LoopClosureError: no strategy closes; the message names each open loop, its distance (m) and angle
                (rad), and whether it is misaligned (its frames can never coincide) or a hard start.
        """
        q = self.check_q(pin.neutral(self.model) if q_init is None else q_init, "q_init").copy()
        tol = check_number(tol, "tol", 0.0, low_open=True)
        fixed = () if fixed is None else fixed
        if isinstance(fixed, Mapping):
            for name, value in fixed.items():
                sl, x = self._joint_value(f"fixed[{name!r}]", name, value)
                q[sl] = x
        fast = self._fast()[0]
        q, info = close_loops(self._loopset, q, self._free_mask(fixed), tol=tol, seed=seed, fast=fast)
        return (q, info) if return_info else q


def load_file(path: str | Path, *, loops: str | Path | None = None, floating: bool = False) -> FileRobot:
    """Load a robot from its own files.

    Args:
        path: a URDF (loops from a ``robot.yaml`` beside it, or ``<name>.yaml``, else its ``<loop_closure>``
            elements and the joints of its ``<transmission>`` elements as the motors), a xacro (``.xacro``,
            run without arguments), or an MJCF (``.xml``, loops from its
            ``<equality>`` constraints).
        loops: a YAML sidecar to use instead of the one beside the URDF.
        floating: add a free-flyer root joint (URDF only).

    Returns:
        A :class:`FileRobot` (a :class:`legkin.Robot`) with ``q0`` closed from neutral when possible.

    Raises:
        InvalidInputError: a missing or unreadable file, malformed YAML, a frame or motor that does not exist,
            an unknown loop or joint type (the message names the file, the key and the value).
    """
    path = Path(path)
    if not path.is_file():
        raise InvalidInputError(f"{path}: no such file")
    sidecar = None
    if loops is not None:
        if path.suffix.lower() == ".xml":
            raise InvalidInputError(f"loops={str(loops)!r}: an MJCF declares its loops itself (<equality>)")
        sidecar = read_sidecar(loops)
    if floating and path.suffix.lower() == ".xml":
        raise InvalidInputError(f"{path}: floating=True applies to a URDF (an MJCF has its own <freejoint>)")
    return FileRobot(path, loops=sidecar, floating=bool(floating))
