"""The legged robots of example-robot-data (nine 12-DOF quadrupeds, six humanoids and the biped bolt), located
through the installed distribution's file list.

No absolute path is written here: every file is found with ``importlib.metadata.files("example-robot-data")``
(the pip / cmeel wheel installs the robots under ``cmeel.prefix/share/example-robot-data/robots``; a
``robots_loader`` module is not needed). Mesh URIs of these URDFs are ``package://example-robot-data/...``,
so the package directory is the folder holding ``example-robot-data``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidParameterError, UnknownModelError

__all__ = [
    "ErdRobot", "ERD_ROBOTS", "ERD_BIPEDS", "ERD_ALL", "erd_files", "load_erd",
    "reference_configuration",
]

_DIST = "example-robot-data"
_ROBOTS = "example-robot-data/robots/"


@dataclass(frozen=True)
class ErdRobot:
    """One robot of example-robot-data.

    Attributes:
        name: legkin's name for it.
        title: a one-line description.
        urdf: the URDF's path relative to example-robot-data's ``robots`` folder.
        srdf: the SRDF's relative path (None: the package ships none).
        reference_pose: the SRDF ``group_state`` used as the reference configuration (None without SRDF).
        free_flyer: the robot is loaded with a free-flyer root joint.
        standing_leg: for a robot without SRDF, the (HAA, HFE, KFE) of every leg in legkin's own "standing"
            pose (the neutral configuration puts laikago's knees outside their limits).
    """

    name: str
    title: str
    urdf: str
    srdf: str | None
    reference_pose: str | None = "standing"
    free_flyer: bool = True
    standing_leg: tuple[float, float, float] | None = None


#: The nine quadrupeds, by legkin name.
ERD_ROBOTS: dict[str, ErdRobot] = {
    r.name: r
    for r in (
        ErdRobot("solo12", "Solo-12 (ODRI)", "solo_description/robots/solo12.urdf", "solo_description/srdf/solo.srdf"),
        ErdRobot("anymal", "ANYmal B (ANYbotics)", "anymal_b_simple_description/robots/anymal.urdf",
                 "anymal_b_simple_description/srdf/anymal.srdf"),
        ErdRobot("anymal_c", "ANYmal C (ANYbotics)", "anymal_c_simple_description/urdf/anymal.urdf",
                 "anymal_c_simple_description/srdf/anymal.srdf"),
        ErdRobot("hyq", "HyQ (IIT)", "hyq_description/robots/hyq_no_sensors.urdf", "hyq_description/srdf/hyq.srdf"),
        ErdRobot("go1", "Go1 (Unitree)", "go1_description/urdf/go1.urdf", "go1_description/srdf/go1.srdf"),
        ErdRobot("go2", "Go2 (Unitree)", "go2_description/urdf/go2.urdf", "go2_description/srdf/go2.srdf"),
        ErdRobot("a1", "A1 (Unitree)", "a1_description/urdf/a1.urdf", "a1_description/srdf/a1.srdf"),
        ErdRobot("b1", "B1 (Unitree)", "b1_description/urdf/b1.urdf", "b1_description/srdf/b1.srdf"),
        # No SRDF: legkin's standing pose, the legs of Unitree's robots bent as a1's SRDF "standing" is.
        ErdRobot("laikago", "Laikago (Unitree)", "laikago_description/urdf/laikago.urdf", None, "standing",
                 standing_leg=(0.0, 0.8, -1.5)),
    )
}

#: The six humanoids (6-DOF legs, :class:`legkin.legs.Leg6`) and the 3-DOF biped bolt, by legkin name.
ERD_BIPEDS: dict[str, ErdRobot] = {
    r.name: r
    for r in (
        ErdRobot("talos", "TALOS humanoid (PAL Robotics)", "talos_data/robots/talos_reduced.urdf",
                 "talos_data/srdf/talos.srdf", "half_sitting"),
        ErdRobot("romeo", "Romeo humanoid (Aldebaran)", "romeo_description/urdf/romeo.urdf",
                 "romeo_description/srdf/romeo.srdf", "half_sitting"),
        ErdRobot("icub", "iCub humanoid (IIT)", "icub_description/robots/icub_reduced.urdf",
                 "icub_description/srdf/icub.srdf", "half_sitting"),
        ErdRobot("simple_humanoid", "Simple humanoid (LAAS)", "simple_humanoid_description/urdf/simple_humanoid.urdf",
                 "simple_humanoid_description/srdf/simple_humanoid.srdf", "half_sitting"),
        ErdRobot("alexander", "Alexander lower body (PAL Robotics)",
                 "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
                 "alexander_description/srdf/alexander.srdf", "default"),
        ErdRobot("g1", "G1 humanoid, 29 DOF (Unitree)", "g1_description/urdf/g1_29dof_rev_1_0.urdf", None, None),
        ErdRobot("bolt", "Bolt biped (ODRI)", "bolt_description/robots/bolt.urdf", "bolt_description/srdf/bolt.srdf"),
    )
}

#: Every legged robot of example-robot-data legkin knows: :data:`ERD_ROBOTS` then :data:`ERD_BIPEDS`.
ERD_ALL: dict[str, ErdRobot] = {**ERD_ROBOTS, **ERD_BIPEDS}


@functools.lru_cache(maxsize=1)
def _installed() -> dict[str, Path]:
    """``{path relative to robots/: absolute path}`` of example-robot-data's installed robot files."""
    import importlib.metadata as md

    try:
        files = md.files(_DIST)
    except md.PackageNotFoundError:
        raise InvalidParameterError(
            f"the {_DIST} distribution is not installed (pip install {_DIST})"
        ) from None
    out = {}
    for f in files or ():
        s = str(f).replace("\\", "/")
        i = s.find(_ROBOTS)
        if i >= 0 and s.endswith((".urdf", ".srdf")):
            out[s[i + len(_ROBOTS):]] = Path(f.locate()).resolve()
    return out


def _robot(name: str) -> ErdRobot:
    try:
        return ERD_ALL[name]
    except (KeyError, TypeError):
        raise UnknownModelError(
            f"unknown example-robot-data robot {name!r}; known: {', '.join(ERD_ALL)}",
            name=name,
            known=sorted(ERD_ALL),
        ) from None


def erd_files(name: str) -> tuple[Path, Path | None, list[str]]:
    """Where the files of an example-robot-data robot are, as installed.

    Args:
        name: the robot's name in :data:`ERD_ALL`.

    Returns:
        ``(urdf path, srdf path or None, package dirs)``: the package dirs resolve its ``package://`` mesh URIs.

    Raises:
        UnknownModelError: ``name`` is not one of :data:`ERD_ROBOTS`.
        InvalidParameterError: example-robot-data is not installed or lacks the file.
    """
    robot = _robot(name)
    files = _installed()
    try:
        urdf = files[robot.urdf]
    except KeyError:
        raise InvalidParameterError(f"example-robot-data has no {robot.urdf} (for {name})") from None
    srdf = files.get(robot.srdf) if robot.srdf else None
    if not urdf.is_file():
        raise InvalidParameterError(f"example-robot-data's {robot.urdf} is listed but missing at {urdf}")
    # urdf = <share>/example-robot-data/robots/<sub path>: package://example-robot-data/... resolves in <share>.
    robots_dir = urdf.parents[len(Path(robot.urdf).parts) - 1]
    share = robots_dir.parent.parent
    return urdf, srdf, [str(share), str(robots_dir)]


def standing_pose(model, name: str) -> np.ndarray | None:
    """legkin's standing configuration of ``model`` for a robot without SRDF (:attr:`ErdRobot.standing_leg`
    on every three-joint leg, the free flyer at the neutral placement), else None."""
    import pinocchio as pin

    robot = _robot(name)
    if robot.standing_leg is None:
        return None
    q = pin.neutral(model)
    legs = [j for j in model.joints[1:] if j.nq == 1]  # HAA, HFE, KFE of each leg, in model order
    for k, joint in enumerate(legs):
        q[joint.idx_q] = robot.standing_leg[k % 3]
    return q


def reference_configuration(model: Any, name: str) -> np.ndarray:
    """The robot's SRDF reference pose (legkin's :func:`standing_pose`, else ``model``'s neutral configuration,
    if it has none).

    Args:
        model: the robot's ``pinocchio.Model`` (as :func:`load_erd` builds it).
        name: the robot's name in :data:`ERD_ALL`.

    Returns:
        The configuration ``(model.nq,)`` (rad, m).
    """
    import pinocchio as pin

    robot = _robot(name)
    _, srdf, _ = erd_files(name)
    if srdf is None or robot.reference_pose is None:
        pose = standing_pose(model, name)
        return pin.neutral(model) if pose is None else pose
    pin.loadReferenceConfigurations(model, str(srdf), False)
    return np.array(model.referenceConfigurations[robot.reference_pose])


def load_erd(name: str, *, free_flyer: bool | None = None) -> tuple[Any, Path, list[str]]:
    """Load an example-robot-data legged robot with Pinocchio.

    Args:
        name: one of :data:`ERD_ALL`: the quadrupeds (``"solo12"``, ``"anymal"``, ``"anymal_c"``, ``"hyq"``,
            ``"go1"``, ``"go2"``, ``"a1"``, ``"b1"``, ``"laikago"``), the humanoids (``"talos"``, ``"romeo"``,
            ``"icub"``, ``"simple_humanoid"``, ``"alexander"``, ``"g1"``) and the biped ``"bolt"``.
        free_flyer: with a free-flyer root joint (default: the robot's :attr:`ErdRobot.free_flyer`, True).

    Returns:
        ``(pinocchio.Model, urdf path, package dirs)``; the SRDF reference pose, if any, is loaded into
        ``model.referenceConfigurations``.
    """
    import pinocchio as pin

    robot = _robot(name)
    urdf, srdf, dirs = erd_files(name)
    ff = robot.free_flyer if free_flyer is None else bool(free_flyer)
    try:
        if ff:
            model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
        else:
            model = pin.buildModelFromUrdf(str(urdf))
        if srdf is not None:
            pin.loadReferenceConfigurations(model, str(srdf), False)
    except Exception as exc:  # noqa: BLE001 - Pinocchio's parse errors become a legkin error
        raise InvalidParameterError(f"cannot load {name} from {urdf}: {exc}") from exc
    return model, urdf, dirs
