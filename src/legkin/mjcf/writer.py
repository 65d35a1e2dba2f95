"""The MJCF text of a legkin mechanism (:func:`to_mjcf`): bodies, joints, inertias, visuals, sites, loops."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np
import pinocchio as pin

from .._batch import check_number
from ..errors import InvalidParameterError, LegkinError
from ._base import _AXES, _MESH_EXTENSIONS, DEFAULTS, _num, _options, _robot, _set_pose, _vec

if TYPE_CHECKING:  # pragma: no cover
    from ..robot import Robot


# ------------------------------------------------------------------------------------------ joints
@dataclass(frozen=True)
class _Joint:
    """One Pinocchio joint as a MuJoCo joint."""

    name: str
    kind: str  # hinge, slide, ball, free, hinge_rub (continuous: cos/sin in Pinocchio)
    axis: tuple[float, ...]
    idx_q: int
    nq: int
    idx_v: int
    nv: int


def _joint(model: pin.Model, i: int) -> _Joint:
    jm = model.joints[i]
    short = jm.shortname()
    kind = None
    axis: tuple[float, ...] = (0.0, 0.0, 1.0)
    for prefix, k in (("JointModelRUB", "hinge_rub"), ("JointModelR", "hinge"), ("JointModelP", "slide")):
        if short.startswith(prefix) and short[len(prefix):] in _AXES:
            kind, axis = k, _AXES[short[len(prefix):]]
    if short in ("JointModelRevoluteUnaligned", "JointModelRevoluteUnboundedUnaligned", "JointModelPrismaticUnaligned"):
        kind = {"R": "hinge", "P": "slide"}[short[10]]
        if "Unbounded" in short:
            kind = "hinge_rub"
        axis = tuple(float(a) for a in np.asarray(jm.extract().axis).ravel())
    elif short == "JointModelFreeFlyer":
        kind = "free"
    elif short == "JointModelSpherical":
        kind = "ball"
    if kind is None:
        raise LegkinError(f"joint {model.names[i]!r} is a {short}, which the MJCF export does not support")
    return _Joint(model.names[i], kind, axis, jm.idx_q, jm.nq, jm.idx_v, jm.nv)


# ------------------------------------------------------------------------------------------ inertia
def _inertial(inertia: pin.Inertia, moving: bool, o: Mapping[str, Any]) -> tuple[ET.Element, str | None]:
    """The ``<inertial>`` of a body and, if it had to be changed, why (for a comment)."""
    mass = float(inertia.mass)
    com = np.array(inertia.lever)
    mat = np.array(inertia.inertia)
    note = None
    if moving and mass < o["min_mass"]:
        note = f"mass {mass:g} kg < min_mass: a solid sphere of {o['min_mass']:g} kg, radius {o['min_radius']:g} m"
        mass = o["min_mass"]
        mat = 0.4 * mass * o["min_radius"] ** 2 * np.eye(3)
        if inertia.mass == 0.0:
            com = np.zeros(3)
    eig = np.linalg.eigvalsh(0.5 * (mat + mat.T))
    if moving and eig[-1] < 1e-12 * mass * o["min_radius"] ** 2:  # a point mass (icub's hips: 0 or 1e-18)
        note = f"rotational inertia {eig[-1]:.1e}: a solid sphere of {mass:g} kg, radius {o['min_radius']:g} m"
        mat = 0.4 * mass * o["min_radius"] ** 2 * np.eye(3)
        eig = np.linalg.eigvalsh(mat)
    if eig[0] < -1e-12 * max(eig[-1], 1e-300) or eig[0] + eig[1] < eig[2] * (1 - 1e-9):
        raise LegkinError(
            f"inertia with principal moments {eig} is not physically consistent (negative, or triangle "
            "inequality violated)"
        )
    el = ET.Element("inertial")
    el.set("pos", _vec(com))
    el.set("mass", _num(mass))
    el.set("fullinertia", _vec([mat[0, 0], mat[1, 1], mat[2, 2], mat[0, 1], mat[0, 2], mat[1, 2]]))
    return el, note


def _actuator_inertia(robot: "Robot", joints: Sequence[_Joint]) -> np.ndarray:
    """Inertia each actuated joint sees at ``q0``: loops closed, other actuated joints held, base fixed."""
    model = robot.model
    q = robot.q0
    mass = np.array(pin.crba(model, model.createData(), q))
    mass = np.triu(mass) + np.triu(mass, 1).T + np.diag(model.armature)
    keep = np.ones(model.nv, dtype=bool)
    for j in joints:
        if j.kind == "free":
            keep[j.idx_v : j.idx_v + j.nv] = False
    jac = robot.constraint_jacobian(q)[:, keep] if robot.loops else np.zeros((0, int(keep.sum())))
    if jac.shape[0]:
        _, s, vt = np.linalg.svd(jac)
        rank = int(np.sum(s > 1e-9 * s[0]))
        basis = vt[rank:].T
    else:
        basis = np.eye(int(keep.sum()))
    idx = np.flatnonzero(keep)
    act = [int(np.flatnonzero(idx == robot.idx_v(a))[0]) for a in robot.actuated_joints]
    sel = basis @ np.linalg.pinv(basis[act])  # actuated rates -> all (kept) rates
    reduced = sel.T @ mass[np.ix_(keep, keep)] @ sel
    return np.diag(reduced).copy()


# ------------------------------------------------------------------------------------------ geometry
def _geom(gobj, assets: dict[tuple[str, tuple[float, ...]], str], asset_el: ET.Element) -> ET.Element:
    geometry = gobj.geometry
    kind = type(geometry).__name__
    el = ET.Element("geom", name=gobj.name)
    if kind == "Box":
        el.set("type", "box")
        el.set("size", _vec(geometry.halfSide))
    elif kind in ("Cylinder", "Capsule"):
        el.set("type", kind.lower())
        el.set("size", _vec([geometry.radius, geometry.halfLength]))
    elif kind == "Sphere":
        el.set("type", "sphere")
        el.set("size", _num(geometry.radius))
    elif kind == "Ellipsoid":
        el.set("type", "ellipsoid")
        el.set("size", _vec(geometry.radii))
    elif kind.startswith("BVHModel") or kind == "Convex" or gobj.meshPath.lower().endswith(_MESH_EXTENSIONS):
        path = Path(gobj.meshPath)
        if path.suffix.lower() not in _MESH_EXTENSIONS:
            raise LegkinError(
                f"visual {gobj.name!r}: mesh {path} is not a format MuJoCo reads ({', '.join(_MESH_EXTENSIONS)})"
            )
        scale = tuple(float(s) for s in np.asarray(gobj.meshScale).ravel())
        key = (str(path.resolve()), scale)
        if key not in assets:
            assets[key] = f"mesh{len(assets)}_{path.stem}"
            mesh = ET.SubElement(asset_el, "mesh", name=assets[key], file=key[0])
            if scale != (1.0, 1.0, 1.0):
                mesh.set("scale", _vec(scale))
        el.set("type", "mesh")
        el.set("mesh", assets[key])
    else:
        raise LegkinError(f"visual {gobj.name!r} is a {kind}, which the MJCF export does not support")
    _set_pose(el, gobj.placement)
    el.set("rgba", _vec(np.round(np.asarray(gobj.meshColor, dtype=float), 4)))
    el.set("class", "visual")
    return el


# ------------------------------------------------------------------------------------------ the MJCF
def to_mjcf(robot_or_name: "Robot | str", **params: Any) -> str:
    """The MJCF text of a mechanism, with its loops as equality constraints.

    Args:
        robot_or_name: a :class:`legkin.Robot` (``legkin.load(name, floating=True)`` gives a free base),
            or a registered model name.
        **params: exporter options (keys of :data:`DEFAULTS`): ``timestep`` (s), ``integrator``,
            ``iterations``, ``tolerance`` (solver), ``eq_solref``, ``eq_solimp`` (the equalities),
            ``actuator_frequency`` (Hz), ``damping_ratio``, ``kp``, ``kv`` (a number or a mapping joint ->
            gain, overriding the computed gains), ``force_limits`` (URDF efforts as actuator force ranges),
            ``min_mass`` (kg), ``min_radius`` (m), ``floor`` (a visual ground plane), ``gravity``; with a
            model name, the other keywords are its xacro arguments (see ``legkin.load``).

    Raises:
        UnknownModelError: an unknown model name.
        InvalidParameterError: an unknown option or xacro argument, or a value out of range.
        LegkinError: a joint, visual or inertia the export cannot represent.
    """
    opts = {k: v for k, v in params.items() if k in DEFAULTS}
    robot = _robot(robot_or_name, {k: v for k, v in params.items() if k not in DEFAULTS})
    return _build_xml(robot, _options(opts))


def _gains(robot: "Robot", joints: Sequence[_Joint], o: Mapping[str, Any]) -> tuple[dict, dict]:
    inertia = _actuator_inertia(robot, joints)
    w = 2.0 * math.pi * o["actuator_frequency"]
    kp, kv = {}, {}
    for name, inert in zip(robot.actuated_joints, inertia):
        kp[name] = float(f"{inert * w * w:.3g}")
        kv[name] = float(f"{2.0 * o['damping_ratio'] * inert * w:.3g}")
    for gains, key in ((kp, "kp"), (kv, "kv")):
        given = o[key]
        if given is None:
            continue
        if isinstance(given, Mapping):
            for name, value in given.items():
                if name not in gains:
                    raise InvalidParameterError(f"{key}[{name!r}]: not an actuated joint ({', '.join(gains)})")
                gains[name] = check_number(value, f"{key}[{name!r}]", 0.0)
        else:
            value = check_number(given, key, 0.0)
            for name in gains:
                gains[name] = value
    return kp, kv


def _header(robot: "Robot", o: Mapping[str, Any]) -> tuple[ET.Element, ET.Element, ET.Element]:
    """The ``<mujoco>`` root with its compiler, option, visual and default classes; returns
    ``(root, asset, worldbody)`` (the asset element still empty)."""
    root = ET.Element("mujoco", model=robot.name)
    root.append(ET.Comment(
        f" legkin {robot.name}: written by legkin.mjcf.to_mjcf from {robot.urdf_path.name} "
        f"({len(robot.loops)} loop closures as equality constraints) "
    ))
    ET.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    ET.SubElement(
        root, "option", timestep=_num(o["timestep"]), integrator=o["integrator"], solver="Newton",
        iterations=str(o["iterations"]), tolerance=_num(o["tolerance"]), ls_iterations="50",
        jacobian="dense", gravity=_vec(o["gravity"]),
    )
    visual = ET.SubElement(root, "visual")
    ET.SubElement(visual, "global", offwidth="1600", offheight="1200")
    ET.SubElement(visual, "quality", shadowsize="8192")
    ET.SubElement(visual, "headlight", ambient="0.35 0.35 0.35", diffuse="0.6 0.6 0.6", specular="0.1 0.1 0.1")
    default = ET.SubElement(root, "default")
    vis = ET.SubElement(default, "default", {"class": "visual"})
    ET.SubElement(vis, "geom", contype="0", conaffinity="0", group="2")
    fr = ET.SubElement(default, "default", {"class": "frame"})
    ET.SubElement(fr, "site", size="0.004", group="4", rgba="1 0.2 0.2 1")
    asset = ET.SubElement(root, "asset")
    world = ET.SubElement(root, "worldbody")
    return root, asset, world


def _joint_element(body: ET.Element, model: pin.Model, j: _Joint) -> None:
    """The ``<freejoint>`` or ``<joint>`` of ``j`` in ``body``, with its axis, range, damping, friction, armature."""
    if j.kind == "free":
        ET.SubElement(body, "freejoint", name=j.name)
        return
    jel = ET.SubElement(body, "joint", name=j.name, type="hinge" if j.kind == "hinge_rub" else j.kind)
    if j.kind in ("hinge", "slide", "hinge_rub"):
        jel.set("axis", _vec(j.axis))
    if j.kind in ("hinge", "slide"):
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        if np.isfinite(lo) and np.isfinite(hi) and lo < hi and max(abs(lo), abs(hi)) < 1e10:
            jel.set("range", _vec([lo, hi]))
    dyn = (("damping", model.damping), ("frictionloss", model.friction), ("armature", model.armature))
    for attr, arr in dyn:
        val = float(np.max(arr[j.idx_v : j.idx_v + j.nv]))
        if val > 0:
            jel.set(attr, _num(val))


def _bodies(model: pin.Model, joints: Sequence[Any], world: ET.Element,
            o: Mapping[str, Any]) -> tuple[dict[int, ET.Element], list[str]]:
    """Bodies, one per joint, nested as the kinematic tree; returns ``(joint index -> body, inertia notes)``."""
    bodies: dict[int, ET.Element] = {0: world}
    link_of: dict[int, str] = {}
    for f in model.frames:
        if f.type == pin.FrameType.BODY and f.parentJoint > 0 and f.parentJoint not in link_of:
            parent_frame = model.frames[f.parentFrame]
            if parent_frame.type == pin.FrameType.JOINT and f.placement.isIdentity():
                link_of[f.parentJoint] = f.name
    notes = []
    for i in range(1, model.njoints):
        j = joints[i]
        body = ET.SubElement(bodies[model.parents[i]], "body", name=link_of.get(i, f"{j.name}_body"))
        _set_pose(body, model.jointPlacements[i])
        inertial, note = _inertial(model.inertias[i], True, o)
        if note:
            notes.append(f"{body.get('name')}: {note}")
            body.append(ET.Comment(f" {note} "))
        body.append(inertial)
        _joint_element(body, model, j)
        bodies[i] = body
    return bodies, notes


def _sites_and_visuals(robot: "Robot", bodies: Mapping[int, ET.Element], asset: ET.Element) -> dict[str, str]:
    """Sites at the body and operational frames (and at the joint frames a loop names, as ``<joint>_site``: a
    robot from a file may close a loop on a joint's origin), then the visuals; returns frame name -> site name."""
    model = robot.model
    seen: dict[str, str] = {}
    loop_frames = {name for lp in robot.loops for name in (lp.frame1, lp.frame2)}
    for f in model.frames:
        at_joint = f.type == pin.FrameType.JOINT and f.name in loop_frames
        if (f.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME) and not at_joint) or f.name in seen:
            continue
        seen[f.name] = f"{f.name}_site" if at_joint else f.name
        site = ET.SubElement(bodies[f.parentJoint], "site", name=seen[f.name])
        site.set("class", "frame")
        _set_pose(site, f.placement)
    mesh_assets: dict = {}
    for g in robot.visual_model.geometryObjects:
        bodies[g.parentJoint].append(_geom(g, mesh_assets, asset))
    return seen


def _floor(robot: "Robot", asset: ET.Element, world: ET.Element) -> None:
    """A visual checkered ground plane a little under the model, and a sun light."""
    ET.SubElement(asset, "texture", name="grid", type="2d", builtin="checker", width="512", height="512",
                  rgb1="0.82 0.84 0.86", rgb2="0.72 0.74 0.77")
    ET.SubElement(asset, "material", name="grid", texture="grid", texrepeat="8 8", reflectance="0.05")
    low = _lowest_point(robot)
    ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 0.05", material="grid",
                  pos=_vec([0, 0, low]), contype="0", conaffinity="0", group="0")
    ET.SubElement(world, "light", name="sun", pos="0 0 3", dir="0.3 0.2 -1", directional="true",
                  diffuse="0.5 0.5 0.5", castshadow="true")


def _equalities(root: ET.Element, robot: "Robot", seen: Mapping[str, str], o: Mapping[str, Any]) -> None:
    """The loop closures as ``<connect>`` (point) or ``<weld>`` equalities between sites."""
    if not robot.loops:
        return
    eq = ET.SubElement(root, "equality")
    for lp in robot.loops:
        for fname in (lp.frame1, lp.frame2):
            if fname not in seen:
                raise LegkinError(f"loop {lp.name!r}: frame {fname!r} is not a body or operational frame")
        ET.SubElement(
            eq, "connect" if lp.type == "point" else "weld", name=lp.name, site1=seen[lp.frame1], site2=seen[lp.frame2],
            solref=_vec(o["eq_solref"]), solimp=_vec(o["eq_solimp"]),
        )


def _actuators(root: ET.Element, robot: "Robot", joints: Sequence[Any], o: Mapping[str, Any]) -> None:
    """One position actuator per actuated joint, with its gains, control range and force range."""
    model = robot.model
    kp, kv = _gains(robot, [j for j in joints if j is not None], o)
    act = ET.SubElement(root, "actuator")
    for name in robot.actuated_joints:
        j = joints[robot.joint_id(name)]
        if j.kind not in ("hinge", "slide", "hinge_rub"):
            raise LegkinError(f"actuated joint {name!r} is a {j.kind} joint; position actuators need 1 DOF")
        a = ET.SubElement(act, "position", name=name, joint=name, kp=_num(kp[name]), kv=_num(kv[name]))
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        if j.kind != "hinge_rub" and np.isfinite(lo) and np.isfinite(hi) and lo < hi:
            a.set("ctrlrange", _vec([lo, hi]))
        effort = float(model.effortLimit[j.idx_v])
        if o["force_limits"] and 0 < effort < 1e10:
            a.set("forcerange", _vec([-effort, effort]))


def _keyframes(root: ET.Element, robot: "Robot", joints: Sequence[Any]) -> None:
    """The reference pose and the SRDF poses whose loops are closed, as keyframes."""
    keys = ET.SubElement(root, "keyframe")
    poses = {robot.spec.reference_pose: robot.q0, **robot.poses}
    for pose_name, q in poses.items():
        if robot.loops and np.max(np.abs(robot.constraint_residual(q))) > 1e-9:
            continue  # a pose of the open tree only: MuJoCo would snap it shut on the first step
        ET.SubElement(keys, "key", name=pose_name, qpos=_vec(_qpos(joints, q)),
                      ctrl=_vec(q[robot.idx_q(a)] for a in robot.actuated_joints))


def _build_xml(robot: "Robot", o: Mapping[str, Any]) -> str:
    model = robot.model
    joints: list[Any] = [None] + [_joint(model, i) for i in range(1, model.njoints)]  # 0: the universe
    root, asset, world = _header(robot, o)
    bodies, notes = _bodies(model, joints, world, o)
    seen = _sites_and_visuals(robot, bodies, asset)
    if o["floor"]:
        _floor(robot, asset, world)
    if not len(asset):
        root.remove(asset)
    _equalities(root, robot, seen, o)
    _actuators(root, robot, joints, o)
    _keyframes(root, robot, joints)
    if notes:
        root.insert(1, ET.Comment(" inertias raised: " + "; ".join(notes) + " "))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _lowest_point(robot: "Robot") -> float:
    """A floor height a little under the model at ``q0`` (its frames and visual centres)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.q0)
    zs = [m.translation[2] for m in data.oMf]
    gdata = pin.GeometryData(robot.visual_model)
    pin.updateGeometryPlacements(robot.model, data, robot.visual_model, gdata)
    zs += [m.translation[2] for m in gdata.oMg]
    return float(f"{min(zs) - 0.05:.3g}")


def _qpos(joints: Sequence[Any], q: np.ndarray) -> np.ndarray:
    """MuJoCo ``qpos`` (joints in the same depth-first order) of a Pinocchio configuration."""
    out: list[Any] = []
    for j in joints[1:]:
        x = q[j.idx_q : j.idx_q + j.nq]
        if j.kind == "hinge_rub":
            out.append([math.atan2(x[1], x[0])])
        elif j.kind == "free":
            out.append([x[0], x[1], x[2], x[6], x[3], x[4], x[5]])
        elif j.kind == "ball":
            out.append([x[3], x[0], x[1], x[2]])
        else:
            out.append(x)
    return np.concatenate(out) if out else np.zeros(0)
