"""MJCF models that stand on the ground (:func:`to_ground_mjcf`, :func:`load_ground`): a free-joint base, contact
geometry from the mechanism's :class:`~legkin.mjcf.ground.GroundModel` and its URDF collision shapes, a floor
that collides, and the reference pose standing on it as keyframe 0 with the position actuators holding it.

Contacts are only between the robot and the floor: robot geoms have ``contype=1, conaffinity=0``, the floor
``contype=0, conaffinity=1`` (MuJoCo makes a pair when ``contype & conaffinity`` of either side is nonzero), so
no pair of robot bodies (the linkage's bars and rims touch each other by design) is ever tested.
"""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

import pinocchio as pin

from .._batch import check_number
from ..errors import InvalidParameterError
from ._base import _MESH_EXTENSIONS, DEFAULTS, _options, _robot, _set_pose, _vec
from .ground import GroundModel, ground_model
from .mechanism import MujocoMechanism, load_mujoco
from .writer import _build_xml, _geom, _joint, _qpos

if TYPE_CHECKING:  # pragma: no cover
    from ..robot import Robot

__all__ = ["GROUND_DEFAULTS", "to_ground_mjcf", "load_ground", "GroundMechanism"]

#: Contact options of the ground export and their defaults (docs/mujoco.md gives the measurements behind them).
GROUND_DEFAULTS: dict[str, Any] = {
    "friction": (1.0, 0.005, 0.0001),
    "condim": 3,
    "contact_solref": (0.002, 1.0),
    "contact_solimp": (0.95, 0.99, 0.001, 0.5, 2.0),
    "timestep": 1e-3,
    "actuator_frequency": 30.0,
}


def _split(options: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """(exporter options, contact options) with the ground defaults filled in and checked."""
    unknown = sorted(set(options) - set(DEFAULTS) - set(GROUND_DEFAULTS))
    if unknown:
        raise InvalidParameterError(
            f"unknown ground option(s) {', '.join(unknown)}; options: {', '.join([*DEFAULTS, *GROUND_DEFAULTS])}"
        )
    c = {**GROUND_DEFAULTS, **options}
    o = _options({k: c[k] for k in set(c) & set(DEFAULTS)})
    c["friction"] = tuple(check_number(v, f"friction[{i}]", 0.0) for i, v in enumerate(c["friction"]))
    if c["condim"] not in (1, 3, 4, 6) or len(c["friction"]) != 3:
        raise InvalidParameterError(f"condim must be 1, 3, 4 or 6 and friction 3 numbers, got {c['condim']!r}")
    c["contact_solref"] = tuple(check_number(v, "contact_solref") for v in c["contact_solref"])
    c["contact_solimp"] = tuple(check_number(v, "contact_solimp") for v in c["contact_solimp"])
    return o, c


def _ascii_stl(path: str) -> bool:
    """Whether an ``.stl`` file is ASCII (its size is not a binary STL's 84 + 50 x its triangle count), which
    MuJoCo does not read (simple_humanoid's ``box.stl``)."""
    file = Path(path)
    if file.suffix.lower() != ".stl" or not file.is_file():
        return False
    with file.open("rb") as f:
        head = f.read(84)
    return len(head) < 84 or file.stat().st_size != 84 + 50 * int.from_bytes(head[80:84], "little")


def _unreadable(g: Any) -> bool:
    """Whether a geometry object is a mesh MuJoCo does not read (``.dae``, ASCII ``.stl``)."""
    return bool(g.meshPath) and type(g.geometry).__name__.startswith(("BVH", "Convex")) and (
        not g.meshPath.lower().endswith(_MESH_EXTENSIONS) or _ascii_stl(g.meshPath))


def _readable(model: pin.GeometryModel) -> pin.GeometryModel:
    """A copy of a geometry model without the objects MuJoCo cannot read."""
    out = pin.GeometryModel()
    for g in model.geometryObjects:
        if not _unreadable(g):
            out.addGeometryObject(g)
    return out


def _visual_robot(robot: "Robot") -> "Robot":
    """``robot``, or a shallow copy whose visuals MuJoCo reads when some visual mesh is a format it does not (the
    example-robot-data robots' ``.dae``): the collision shapes it reads (go2's ``.stl``), else the readable
    visuals (hyq: only its primitives)."""
    if not any(_unreadable(g) for g in robot.visual_model.geometryObjects):
        return robot
    out = copy.copy(robot)
    collision = _readable(robot.collision_model)
    out.visual_model = collision if collision.ngeoms else _readable(robot.visual_model)
    return out


def _floating(robot_or_name: "Robot | str") -> "Robot":
    """The robot, loaded floating when given by name (fixed when its registry spec is: the hybrid leg)."""
    if isinstance(robot_or_name, str):
        from .._registry import get_spec
        from ..robot import load

        return load(robot_or_name, floating=get_spec(robot_or_name).floating)
    return _robot(robot_or_name, {})


def _contact_class(root: ET.Element, c: Mapping[str, Any]) -> None:
    default = root.find("default")
    assert default is not None
    cls = ET.SubElement(default, "default", {"class": "contact"})
    ET.SubElement(cls, "geom", contype="1", conaffinity="0", group="3", condim=str(c["condim"]),
                  friction=_vec(c["friction"]), solref=_vec(c["contact_solref"]),
                  solimp=_vec(c["contact_solimp"]), rgba="0.9 0.5 0.1 0.6")


def _add_geoms(root: ET.Element, robot: "Robot", ground: GroundModel) -> int:
    """The ground model's geoms and the other URDF collision shapes in their bodies; returns their number."""
    bodies = {j.get("name"): b for b in root.iter("body") for j in b if j.tag in ("joint", "freejoint")}
    by_joint = {i: bodies[robot.model.names[i]] for i in range(1, robot.model.njoints)}
    asset = root.find("asset")
    assert asset is not None
    n = 0
    for g in ground.geoms():
        el = ET.SubElement(by_joint[g.joint], "geom", name=g.name, type=g.kind, size=_vec(g.size))
        el.set("class", "contact")
        _set_pose(el, g.placement)
        n += 1
    meshes = {(str(m.get("file")), tuple(float(x) for x in m.get("scale", "1 1 1").split())): str(m.get("name"))
              for m in asset.findall("mesh")}  # the visuals' meshes, reused
    for gobj in robot.collision_model.geometryObjects:
        if gobj.name in ground.collision_skip or gobj.parentJoint == 0 or _unreadable(gobj):
            continue
        el = _geom(gobj, meshes, asset)
        el.set("name", f"{gobj.name}_collision")
        el.set("class", "contact")
        del el.attrib["rgba"]
        by_joint[gobj.parentJoint].append(el)
        n += 1
    return n


def _floor_and_key(root: ET.Element, robot: "Robot", ground: GroundModel, c: Mapping[str, Any]) -> float:
    """The floor at z = 0 made to collide, keyframe 0 standing on it; returns the standing height (m). A fixed
    base: the floor at the lowest predicted contact of the reference pose instead, the keyframes as they are;
    returns the floor's height (m)."""
    asset = root.find("asset")
    assert asset is not None
    ET.SubElement(asset, "texture", name="sky", type="skybox", builtin="gradient", rgb1="0.75 0.82 0.9",
                  rgb2="1 1 1", width="256", height="256")
    floor = next(g for g in root.iter("geom") if g.get("name") == "floor")
    floor.attrib.update(pos="0 0 0", contype="0", conaffinity="1", condim=str(c["condim"]),
                        friction=_vec(c["friction"]), solref=_vec(c["contact_solref"]),
                        solimp=_vec(c["contact_solimp"]))
    if ground.fixed_base:
        floor.set("pos", _vec([0.0, 0.0, -ground.standing_height(robot.q0)]))
        return -ground.standing_height(robot.q0)
    poses = {**robot.poses, robot.spec.reference_pose: robot.q0}
    joints = [None] + [_joint(robot.model, i) for i in range(1, robot.model.njoints)]
    for key in root.iter("key"):
        q = ground.pose(poses[key.get("name")])
        qpos = _qpos(joints, q)
        qpos[2] = ground.standing_height(q)
        key.set("qpos", _vec(qpos))
        key.set("ctrl", _vec(q[robot.idx_q(a)] for a in robot.actuated_joints))
    return ground.standing_height(ground.pose(robot.q0))


def to_ground_mjcf(robot_or_name: "Robot | str", *, ground: GroundModel | None = None, **options: Any) -> str:
    """The MJCF of a floating mechanism that stands on a floor (module docstring).

    Args:
        robot_or_name: ``legkin.load(name, floating=True)`` or a model name (loaded floating).
        ground: the ground model (default :func:`~legkin.mjcf.ground.ground_model` of the robot; e.g.
            ``legkin.wheel_leg.sim.ground_model(robot, step=0.004)`` for finer tyre cylinders).
        **options: the exporter's (:data:`~legkin.mjcf.DEFAULTS`) and the contact options of
            :data:`GROUND_DEFAULTS`: ``friction`` (sliding, torsional, rolling), ``condim``, ``contact_solref``
            (s, damping ratio), ``contact_solimp``; the ground defaults replace ``timestep`` (1 ms) and
            ``actuator_frequency`` (30 Hz).

    Returns:
        The MJCF text; keyframe 0 is the reference pose with the base at the height where legkin's lowest
        predicted contact touches z = 0.

    Raises:
        InvalidParameterError: an unknown or bad option, a model without a ground model.
    """
    robot = _floating(robot_or_name)
    ground = ground_model(robot) if ground is None else ground
    o, c = _split({"timestep": ground.timestep or GROUND_DEFAULTS["timestep"], **options})
    root = ET.fromstring(_build_xml(_visual_robot(robot), {**o, "floor": True}))
    _contact_class(root, c)
    n = _add_geoms(root, robot, ground)
    gains = {} if "kp" in options else ground.stiffness()  # the ground model's smallest gains (flat feet)
    for act in root.iter("position"):
        kp = gains.get(str(act.get("joint")), 0.0)
        if kp > float(act.get("kp", "0")):
            act.set("kp", f"{kp:.3g}")
    height = _floor_and_key(root, robot, ground, c)
    where = (f"fixed base, floor at z = {height:.6f} m under the lowest contact (legkin's prediction)"
             if ground.fixed_base else
             f"floor at z = 0, keyframe 0 standing at base height {height:.6f} m (legkin's prediction)")
    if ground.held_tilt:
        where += (f"; legkin's scenarios hold the base's roll and pitch by a torque of {ground.held_tilt:.4g} N m / rad"
                  " (GroundModel.held_tilt), this file does not: on its point feet it falls without a controller")
    root.insert(1, ET.Comment(f" ground export: {n} contact geoms (class contact), {where} "))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


class GroundMechanism(MujocoMechanism):
    """A :class:`~legkin.mjcf.MujocoMechanism` standing on a floor, with its ground model.

    Attributes:
        ground: the mechanism's :class:`~legkin.mjcf.ground.GroundModel`.
        height: legkin's standing height of the base (m) at ``robot.q0``.
    """

    ground: GroundModel
    height: float


def load_ground(robot_or_name: "Robot | str", *, ground: GroundModel | None = None,
                **options: Any) -> GroundMechanism:
    """Compile :func:`to_ground_mjcf` in MuJoCo (arguments as there).

    Raises:
        LegkinError: MuJoCo is not installed or refused the model.
    """
    robot = _floating(robot_or_name)
    ground = ground_model(robot) if ground is None else ground
    xml = to_ground_mjcf(robot, ground=ground, **options)
    mech = load_mujoco(robot, xml=xml)
    out = GroundMechanism.__new__(GroundMechanism)
    out.__dict__.update(mech.__dict__)
    out.ground = ground
    out.height = out.ground.standing_height(ground.pose(robot.q0))
    return out


def write_ground_mjcf(robot_or_name: "Robot | str", path: str | Path, **options: Any) -> Path:
    """Write :func:`to_ground_mjcf` to ``path``; returns it."""
    path = Path(path)
    path.write_text(to_ground_mjcf(robot_or_name, **options))
    return path
