"""MuJoCo (MJCF) models of legkin's mechanisms, with the closed loops as equality constraints.

MuJoCo compiles legkin's URDFs only as open trees (it ignores ``<loop_closure>``) and refuses the hybrid
leg (massless links of its spherical-joint triples). :func:`to_mjcf` writes an MJCF of its own from the
Pinocchio model instead:

* one ``<body>`` per Pinocchio joint, placed by ``model.jointPlacements``, named after its URDF link, with
  a ``hinge`` (revolute), ``slide`` (prismatic), ``ball`` (spherical) or ``freejoint`` (free flyer; only
  for ``legkin.load(name, floating=True)``), axis and URDF limits; continuous joints become unlimited
  hinges. Fixed URDF links are merged into their parent body, as Pinocchio does.
* ``<inertial>`` from ``model.inertias`` (Pinocchio has already merged the fixed links). A moving body
  whose mass is below ``min_mass`` (the massless links inside the hybrid leg's revolute triples) gets a
  tiny solid sphere of ``min_mass`` kg and radius ``min_radius`` m: consistent (triangle inequality holds)
  and negligible next to the real links. The triples stay three hinges rather than one ``ball``: the
  ``qpos`` of the MJCF then matches Pinocchio's ``q`` joint by joint (and its URDF limits per angle).
* a ``<site>`` per Pinocchio body or operational frame (URDF links and extra frames), in the body of its
  parent joint, at its placement;
* every ``<loop_closure>`` as an equality: ``type="point"`` -> ``<connect site1 site2>`` (the two origins
  coincide), ``type="frame"`` -> ``<weld site1 site2>`` (the two frames coincide). The site form is used
  because it states both anchors: MuJoCo's body form computes body2's anchor (or the weld's ``relpose``)
  from ``qpos0`` (all joints 0), where the loops are not closed.
* visuals from ``robot.visual_model`` (boxes, cylinders, spheres, capsules, ellipsoids as MuJoCo
  primitives; meshes by absolute path), in geom group 2, with no contacts (``contype=conaffinity=0``);
* a ``<position>`` actuator per actuated joint (gains below), and a ``<key>`` per SRDF pose that closes
  the loops, the reference pose ``robot.q0`` first.

Actuator gains: each actuator is a critically damped (``damping_ratio``) second-order system of natural
frequency ``actuator_frequency`` Hz on the inertia that joint sees with the loops closed and the other
actuated joints held, at ``q0`` (the diagonal of the constrained joint-space mass matrix):
``kp = I w^2``, ``kv = 2 zeta I w``.

Solver: time step 0.2 ms, ``implicitfast`` integrator (the actuators' damping implicit), Newton solver
with ``iterations`` and ``tolerance``, dense Jacobians. The equalities get ``solimp = (0.9999, 0.9999,
0.001, 0.5, 2)`` (MuJoCo's largest impedance, 0.9999, at every violation) and ``solref = (2 timestep,
0.7)``: the shortest time constant MuJoCo allows (``2 timestep``) and a damping ratio under 1, which makes
the constraint stiffer (stiffness ``1 / (d^2 timeconst^2 ratio^2)``) at the same damping; 0.35 diverges.
A MuJoCo equality is soft: under a load its violation scales as ``timeconst^2`` (so as the time step
squared), which is why the time step is 0.2 ms (docs/mujoco.md has the measurements).

:func:`check_rows` returns the ``legkin check`` rows comparing the MuJoCo model with Pinocchio.
"""

from __future__ import annotations

import math
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Sequence

import numpy as np
import pinocchio as pin

from .errors import InvalidInputError, InvalidParameterError, LegkinError, LoopClosureError
from .loops import check_count, check_real

if TYPE_CHECKING:  # pragma: no cover
    import argparse

    from .robot import Robot
    from .validation import CheckResult

__all__ = [
    "DEFAULTS",
    "MujocoMechanism",
    "to_mjcf",
    "load_mujoco",
    "check_rows",
    "unavailable_reason",
    "render_png",
    "add_export_command",
    "run_export",
]

#: The exporter's options and their defaults (see :func:`to_mjcf`).
DEFAULTS: dict[str, Any] = {
    "timestep": 2e-4,
    "integrator": "implicitfast",
    "iterations": 100,
    "tolerance": 1e-10,
    "eq_solref": None,  # (2 timestep, 0.7)
    "eq_solimp": (0.9999, 0.9999, 0.001, 0.5, 2.0),
    "actuator_frequency": 10.0,
    "damping_ratio": 1.0,
    "kp": None,
    "kv": None,
    "force_limits": False,
    "min_mass": 1e-6,
    "min_radius": 0.005,
    "floor": True,
    "gravity": (0.0, 0.0, -9.81),
}

_INTEGRATORS = ("Euler", "implicit", "implicitfast", "RK4")
_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_MESH_EXTENSIONS = (".stl", ".obj", ".msh")
#: Tolerances of the rows of :func:`check_rows`.
TOL_PLACEMENT = 1e-12
TOL_EQUALITY = 1e-12
TOL_GRAVITY = 1e-4
TOL_CLIP = 1e-3


# ------------------------------------------------------------------------------------------ helpers
def unavailable_reason() -> str | None:
    """Why the MuJoCo features cannot run here (``None`` when ``import mujoco`` works)."""
    try:
        import mujoco  # noqa: F401
    except ImportError as exc:
        return f"mujoco is not installed ({exc}): pip install mujoco"
    return None


def _mujoco():
    try:
        import mujoco
    except ImportError as exc:
        raise LegkinError(f"this needs MuJoCo, which is not installed ({exc}): pip install mujoco") from None
    return mujoco


def _num(x: float) -> str:
    """Shortest text that reads back as the same double (``repr``), ``0`` for zeros."""
    x = float(x)
    if x == 0.0:
        return "0"
    s = repr(x)
    return s[:-2] if s.endswith(".0") else s


def _vec(xs: Iterable[float]) -> str:
    return " ".join(_num(x) for x in xs)


def _quat(rotation: np.ndarray) -> np.ndarray:
    """MuJoCo quaternion (w, x, y, z) of a rotation matrix."""
    x, y, z, w = pin.Quaternion(np.asarray(rotation)).normalized().coeffs()
    return np.array([w, x, y, z])


def _set_pose(el: ET.Element, placement: pin.SE3) -> None:
    p = placement.translation
    if np.any(p != 0.0):
        el.set("pos", _vec(p))
    if not np.array_equal(placement.rotation, np.eye(3)):
        el.set("quat", _vec(_quat(placement.rotation)))


def _robot(robot_or_name, params: Mapping[str, Any]) -> "Robot":
    from .robot import Robot, load

    if isinstance(robot_or_name, Robot):
        if params:
            raise InvalidParameterError(
                f"unknown MJCF option(s) {', '.join(params)}; options: {', '.join(DEFAULTS)} (xacro arguments "
                f"go with a model name: {robot_or_name.name!r} is already loaded)"
            )
        return robot_or_name
    if not isinstance(robot_or_name, str):
        raise InvalidInputError(f"expected a legkin.Robot or a model name, got {robot_or_name!r}")
    return load(robot_or_name, **params)


def _options(options: Mapping[str, Any]) -> dict[str, Any]:
    try:
        return _checked_options(options)
    except InvalidInputError as exc:
        raise InvalidParameterError(str(exc)) from None


def _checked_options(options: Mapping[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(options) - set(DEFAULTS))
    if unknown:
        raise InvalidParameterError(
            f"unknown MJCF option(s) {', '.join(unknown)}; options: {', '.join(DEFAULTS)}"
        )
    o = {**DEFAULTS, **options}
    o["timestep"] = check_real("timestep", o["timestep"], 0.0, 0.1, low_open=True)
    if o["integrator"] not in _INTEGRATORS:
        raise InvalidParameterError(f"integrator must be one of {', '.join(_INTEGRATORS)}, got {o['integrator']!r}")
    o["iterations"] = check_count("iterations", o["iterations"], 1)
    o["tolerance"] = check_real("tolerance", o["tolerance"], 0.0)
    if o["eq_solref"] is None:
        o["eq_solref"] = (2.0 * o["timestep"], 0.7)
    o["eq_solref"] = tuple(check_real(f"eq_solref[{i}]", v) for i, v in enumerate(o["eq_solref"]))
    o["eq_solimp"] = tuple(check_real(f"eq_solimp[{i}]", v) for i, v in enumerate(o["eq_solimp"]))
    if len(o["eq_solref"]) != 2 or len(o["eq_solimp"]) not in (3, 5):
        raise InvalidParameterError("eq_solref takes 2 numbers and eq_solimp 3 or 5")
    o["actuator_frequency"] = check_real("actuator_frequency", o["actuator_frequency"], 0.0, low_open=True)
    o["damping_ratio"] = check_real("damping_ratio", o["damping_ratio"], 0.0)
    o["min_mass"] = check_real("min_mass", o["min_mass"], 0.0, low_open=True)
    o["min_radius"] = check_real("min_radius", o["min_radius"], 0.0, low_open=True)
    o["gravity"] = tuple(check_real(f"gravity[{i}]", v) for i, v in enumerate(o["gravity"]))
    for flag in ("force_limits", "floor"):
        if not isinstance(o[flag], (bool, np.bool_)):
            raise InvalidParameterError(f"{flag} must be True or False, got {o[flag]!r}")
    return o


# ------------------------------------------------------------------------------------------ joints
@dataclass(frozen=True)
class _Joint:
    """One Pinocchio joint as a MuJoCo joint."""

    name: str
    kind: str  # hinge, slide, ball, free, hinge_rub (continuous: cos/sin in Pinocchio)
    axis: tuple[float, float, float]
    idx_q: int
    nq: int
    idx_v: int
    nv: int


def _joint(model: pin.Model, i: int) -> _Joint:
    jm = model.joints[i]
    short = jm.shortname()
    kind = None
    axis = (0.0, 0.0, 1.0)
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
                gains[name] = check_real(f"{key}[{name!r}]", value, 0.0)
        else:
            value = check_real(key, given, 0.0)
            for name in gains:
                gains[name] = value
    return kp, kv


def _build_xml(robot: "Robot", o: Mapping[str, Any]) -> str:
    model = robot.model
    joints = [None] + [_joint(model, i) for i in range(1, model.njoints)]
    root = ET.Element("mujoco", model=robot.name)
    root.append(ET.Comment(
        f" legkin {robot.name}: written by legkin.mujoco_export.to_mjcf from {robot.urdf_path.name} "
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

    # bodies, one per joint, nested as the kinematic tree
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
        if j.kind == "free":
            ET.SubElement(body, "freejoint", name=j.name)
        else:
            jel = ET.SubElement(body, "joint", name=j.name, type="hinge" if j.kind == "hinge_rub" else j.kind)
            if j.kind in ("hinge", "slide", "hinge_rub"):
                jel.set("axis", _vec(j.axis))
            if j.kind in ("hinge", "slide"):
                lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
                if np.isfinite(lo) and np.isfinite(hi) and lo < hi and max(abs(lo), abs(hi)) < 1e10:
                    jel.set("range", _vec([lo, hi]))
            for attr, arr in (("damping", model.damping), ("frictionloss", model.friction), ("armature", model.armature)):
                val = float(np.max(arr[j.idx_v : j.idx_v + j.nv]))
                if val > 0:
                    jel.set(attr, _num(val))
        bodies[i] = body

    # sites at the body and operational frames, then the visuals
    seen = set()
    for f in model.frames:
        if f.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME) or f.name in seen:
            continue
        seen.add(f.name)
        site = ET.SubElement(bodies[f.parentJoint], "site", name=f.name)
        site.set("class", "frame")
        _set_pose(site, f.placement)
    mesh_assets: dict = {}
    for g in robot.visual_model.geometryObjects:
        bodies[g.parentJoint].append(_geom(g, mesh_assets, asset))
    if o["floor"]:
        ET.SubElement(asset, "texture", name="grid", type="2d", builtin="checker", width="512", height="512",
                      rgb1="0.82 0.84 0.86", rgb2="0.72 0.74 0.77")
        ET.SubElement(asset, "material", name="grid", texture="grid", texrepeat="8 8", reflectance="0.05")
        low = _lowest_point(robot)
        ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 0.05", material="grid",
                      pos=_vec([0, 0, low]), contype="0", conaffinity="0", group="0")
        ET.SubElement(world, "light", name="sun", pos="0 0 3", dir="0.3 0.2 -1", directional="true",
                      diffuse="0.5 0.5 0.5", castshadow="true")
    if not len(asset):
        root.remove(asset)

    # loop closures
    if robot.loops:
        eq = ET.SubElement(root, "equality")
        for lp in robot.loops:
            for fname in (lp.frame1, lp.frame2):
                if fname not in seen:
                    raise LegkinError(f"loop {lp.name!r}: frame {fname!r} is not a body or operational frame")
            ET.SubElement(
                eq, "connect" if lp.type == "point" else "weld", name=lp.name, site1=lp.frame1, site2=lp.frame2,
                solref=_vec(o["eq_solref"]), solimp=_vec(o["eq_solimp"]),
            )

    # actuators and keyframes
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
    keys = ET.SubElement(root, "keyframe")
    poses = {robot.spec.reference_pose: robot.q0, **robot.poses}
    for pose_name, q in poses.items():
        if robot.loops and np.max(np.abs(robot.constraint_residual(q))) > 1e-9:
            continue  # a pose of the open tree only: MuJoCo would snap it shut on the first step
        ET.SubElement(keys, "key", name=pose_name, qpos=_vec(_qpos(joints, q)),
                      ctrl=_vec(q[robot.idx_q(a)] for a in robot.actuated_joints))
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


def _qpos(joints: Sequence[_Joint | None], q: np.ndarray) -> np.ndarray:
    """MuJoCo ``qpos`` (joints in the same depth-first order) of a Pinocchio configuration."""
    out = []
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


# ------------------------------------------------------------------------------------------ loaded model
@dataclass
class MujocoMechanism:
    """A legkin mechanism loaded in MuJoCo, with the maps between its ``qpos`` and Pinocchio's ``q``.

    Attributes:
        robot: the legkin robot (Pinocchio model).
        xml: the MJCF text.
        model, data: MuJoCo's ``MjModel`` and ``MjData``.
        body_ids: MuJoCo body id of each Pinocchio joint (index 0: the world).
        sites: ``(Pinocchio frame id, MuJoCo site id)`` of every frame exported as a site.
        loop_sites: ``(site1, site2)`` ids of each loop closure, in ``robot.loops`` order.
        actuator_q: index in ``q`` of each actuator's joint (actuators in ``robot.actuated_joints`` order).
    """

    robot: "Robot"
    xml: str
    model: Any
    data: Any
    joints: list = field(repr=False)
    body_ids: list[int] = field(repr=False)
    sites: list[tuple[int, int]] = field(repr=False)
    loop_sites: list[tuple[int, int]] = field(repr=False)
    actuator_q: list[int] = field(repr=False)

    def qpos(self, q) -> np.ndarray:
        """MuJoCo ``qpos`` of the Pinocchio configuration ``q``."""
        q = self.robot.check_q(q)
        qpos = np.empty(self.model.nq)
        qpos[self._qposadr] = _qpos(self.joints, q)
        return qpos

    def q(self, qpos) -> np.ndarray:
        """Pinocchio configuration of the MuJoCo ``qpos``."""
        x = np.asarray(qpos, dtype=float)[self._qposadr]
        out = np.empty(self.robot.model.nq)
        k = 0
        for j in self.joints[1:]:
            if j.kind == "hinge_rub":
                out[j.idx_q : j.idx_q + 2] = math.cos(x[k]), math.sin(x[k])
                k += 1
            elif j.kind == "free":
                out[j.idx_q : j.idx_q + 7] = [*x[k : k + 3], *x[k + 4 : k + 7], x[k + 3]]
                k += 7
            elif j.kind == "ball":
                out[j.idx_q : j.idx_q + 4] = [*x[k + 1 : k + 4], x[k]]
                k += 4
            else:
                out[j.idx_q : j.idx_q + j.nq] = x[k : k + j.nq]
                k += j.nq
        return out

    def ctrl(self, q) -> np.ndarray:
        """Actuator targets holding the actuated joints at their values in ``q``."""
        return np.asarray(q, dtype=float)[self.actuator_q]

    def set_configuration(self, q, forward: bool = True) -> None:
        """``qpos`` from ``q``, zero velocity, ``ctrl`` holding it; then ``mj_forward`` (or only kinematics)."""
        mujoco = _mujoco()
        self.data.qpos[:] = self.qpos(q)
        self.data.qvel[:] = 0.0
        self.data.ctrl[:] = self.ctrl(q)
        (mujoco.mj_forward if forward else mujoco.mj_kinematics)(self.model, self.data)

    def loop_residuals(self) -> np.ndarray:
        """Per loop, the distance between its two sites (point) or ``sqrt(|dp|^2 + angle^2)`` (frame), in m
        and rad, at the current ``data`` (after ``mj_kinematics``)."""
        d = self.data
        out = np.empty(len(self.loop_sites))
        for k, ((s1, s2), lp) in enumerate(zip(self.loop_sites, self.robot.loops)):
            dp = float(np.linalg.norm(d.site_xpos[s1] - d.site_xpos[s2]))
            if lp.type == "frame":
                r = d.site_xmat[s1].reshape(3, 3).T @ d.site_xmat[s2].reshape(3, 3)
                s = 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
                angle = math.atan2(float(np.linalg.norm(s)), 0.5 * (np.trace(r) - 1.0))
                dp = math.hypot(dp, angle)
            out[k] = dp
        return out

    def equality_residuals(self) -> np.ndarray:
        """MuJoCo's own equality rows of ``efc_pos`` (after ``mj_forward``)."""
        mujoco = _mujoco()
        n = self.data.nefc
        kind = np.asarray(self.data.efc_type[:n])
        return np.asarray(self.data.efc_pos[:n])[kind == mujoco.mjtConstraint.mjCNSTR_EQUALITY].copy()

    def __post_init__(self) -> None:
        self._qposadr = np.concatenate([
            np.arange(self.model.jnt_qposadr[self._jid(j.name)], self.model.jnt_qposadr[self._jid(j.name)] + n)
            for j in self.joints[1:]
            for n in [{"free": 7, "ball": 4, "hinge_rub": 1}.get(j.kind, j.nq)]
        ]).astype(int) if len(self.joints) > 1 else np.zeros(0, dtype=int)

    def _jid(self, name: str) -> int:
        mujoco = _mujoco()
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)


def load_mujoco(robot_or_name: "Robot | str", *, xml: str | None = None, **params: Any) -> MujocoMechanism:
    """Compile :func:`to_mjcf` (or the given ``xml``, e.g. an edited copy) in MuJoCo.

    Raises:
        LegkinError: MuJoCo is not installed, or refused the model (its message included).
    """
    mujoco = _mujoco()
    opts = {k: v for k, v in params.items() if k in DEFAULTS}
    robot = _robot(robot_or_name, {k: v for k, v in params.items() if k not in DEFAULTS})
    if xml is None:
        xml = _build_xml(robot, _options(opts))
    try:
        mj_model = mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        raise LegkinError(f"MuJoCo refused the MJCF of {robot.name!r}: {exc}") from None
    model = robot.model
    joints = [None] + [_joint(model, i) for i in range(1, model.njoints)]

    def oid(kind, name):
        return mujoco.mj_name2id(mj_model, kind, name)

    bodies = [0]
    for i in range(1, model.njoints):
        jid = oid(mujoco.mjtObj.mjOBJ_JOINT, model.names[i])
        if jid < 0:
            raise LegkinError(f"the MJCF has no joint {model.names[i]!r}")
        bodies.append(int(mj_model.jnt_bodyid[jid]))
    sites = []
    for fid, f in enumerate(model.frames):
        sid = oid(mujoco.mjtObj.mjOBJ_SITE, f.name)
        if sid >= 0 and f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME):
            sites.append((fid, sid))
    loop_sites = [
        (oid(mujoco.mjtObj.mjOBJ_SITE, lp.frame1), oid(mujoco.mjtObj.mjOBJ_SITE, lp.frame2)) for lp in robot.loops
    ]
    act_q = []
    for k, name in enumerate(robot.actuated_joints):
        aid = oid(mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        if aid != k:
            raise LegkinError(f"the MJCF's actuator {k} is not on joint {name!r}")
        act_q.append(robot.idx_q(name))
    return MujocoMechanism(robot, xml, mj_model, mujoco.MjData(mj_model), joints, bodies, sites, loop_sites, act_q)


# ------------------------------------------------------------------------------------------ the checks
def independent_actuated(robot: "Robot", q: np.ndarray | None = None) -> list[str]:
    """The actuated joints that, held, each remove one degree of freedom at ``q`` (default ``q0``).

    All of them for most mechanisms; fewer for a redundantly actuated one (the tripod: three actuators on
    a two-DOF platform), whose remaining actuated joints follow from the loops.
    """
    q = robot.q0 if q is None else q
    held: list[str] = []
    dof = robot.mobility(q)
    for name in robot.actuated_joints:
        m = robot.mobility(q, locked=held + [name])
        if m < dof:
            held.append(name)
            dof = m
    return held


def closed_configurations(robot: "Robot", n: int, rng: np.random.Generator) -> list[np.ndarray]:
    """``q0`` and ``n`` closed configurations from random actuated values in their limits.

    The independent actuated joints (:func:`independent_actuated`) are drawn uniformly in their limits
    (within pi of ``q0``) and held while :meth:`legkin.Robot.solve_loops` closes the loops from ``q0``; a
    draw that does not close is pulled towards ``q0`` (halfway, a quarter, ...) and solved again. A model
    without loops gets every 1-DOF joint drawn in its limits.
    """
    model = robot.model
    out = [robot.q0.copy()]
    names = independent_actuated(robot) if robot.loops else [
        nm for nm in robot.joint_names if model.joints[robot.joint_id(nm)].nq == 1
    ]
    idx = [robot.idx_q(nm) for nm in names]
    lo, hi = model.lowerPositionLimit[idx], model.upperPositionLimit[idx]
    lo, hi = np.maximum(lo, robot.q0[idx] - math.pi), np.minimum(hi, robot.q0[idx] + math.pi)
    attempts = 0
    while len(out) < n + 1:
        attempts += 1
        if attempts > 20 * (n + 1):
            raise LoopClosureError(f"{robot.name}: only {len(out) - 1} of {n} random configurations closed")
        draw = rng.uniform(lo, hi)
        if not robot.loops:
            q = robot.q0.copy()
            q[idx] = draw
            out.append(q)
            continue
        for t in (1.0, 0.5, 0.25, 0.125, 0.0625):
            vals = robot.q0[idx] + t * (draw - robot.q0[idx])
            try:
                out.append(robot.solve_loops(fixed=dict(zip(names, vals)), tol=1e-13, max_iter=100))
                break
            except LoopClosureError:
                continue
    return out


def placement_errors(mech: MujocoMechanism, qs: Sequence[np.ndarray]) -> np.ndarray:
    """Per configuration, the largest distance between a MuJoCo body (site) position after
    ``mj_kinematics`` and its Pinocchio joint (frame) placement, in m."""
    mujoco = _mujoco()
    robot = mech.robot
    data = robot.model.createData()
    bodies = np.array(mech.body_ids[1:])
    fids = [int(f) for f, _ in mech.sites]
    sids = np.array([s for _, s in mech.sites], dtype=int)
    out = np.empty(len(qs))
    for k, q in enumerate(qs):
        mech.data.qpos[:] = mech.qpos(q)
        mujoco.mj_kinematics(mech.model, mech.data)
        pin.framesForwardKinematics(robot.model, data, q)
        pj = np.array([data.oMi[i].translation for i in range(1, robot.model.njoints)])
        pf = np.array([data.oMf[f].translation for f in fids])
        eb = np.linalg.norm(mech.data.xpos[bodies] - pj, axis=1)
        es = np.linalg.norm(mech.data.site_xpos[sids] - pf, axis=1)
        out[k] = max(eb.max(initial=0.0), es.max(initial=0.0))
    return out


def equality_errors(mech: MujocoMechanism, qs: Sequence[np.ndarray]) -> np.ndarray:
    """Per configuration, the largest ``|efc_pos|`` of MuJoCo's equality rows after ``mj_forward``."""
    rows = sum(3 if lp.type == "point" else 6 for lp in mech.robot.loops)
    out = np.empty(len(qs))
    for k, q in enumerate(qs):
        mech.set_configuration(q)
        r = mech.equality_residuals()
        out[k] = np.max(np.abs(r), initial=0.0) if r.size == rows else np.nan  # a row missing: a failure
    return out


def hold_under_gravity(mech: MujocoMechanism, seconds: float = 2.0) -> dict[str, np.ndarray]:
    """Simulate ``seconds`` from ``q0`` with the actuators holding it.

    Returns:
        ``{"loop": (steps, loops) loop residuals (m, rad), "joint": (steps,) largest |q - q0| over the
        actuated joints (rad or m), "time": (steps,)}``; NaN from the first step whose state is not finite
        or that MuJoCo warned about (unstable acceleration).
    """
    mujoco = _mujoco()
    mech.set_configuration(mech.robot.q0)
    steps = int(round(seconds / mech.model.opt.timestep))
    loops = np.full((steps, len(mech.loop_sites)), np.nan)
    joint = np.full(steps, np.nan)
    ref = mech.data.qpos.copy()
    adr = mech.model.jnt_qposadr[mech.model.actuator_trnid[:, 0]]
    warned0 = int(mech.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number)
    for k in range(steps):
        mujoco.mj_step(mech.model, mech.data)
        bad = int(mech.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number) > warned0
        if bad or not np.all(np.isfinite(mech.data.qpos)):
            break
        loops[k] = mech.loop_residuals()
        joint[k] = np.max(np.abs(mech.data.qpos[adr] - ref[adr]), initial=0.0)
    return {"loop": loops, "joint": joint, "time": np.arange(1, steps + 1) * mech.model.opt.timestep}


def passive_joints(robot: "Robot", q: np.ndarray) -> tuple[list[str], list[str]]:
    """The 1-DOF joints that are not actuated: ``(driven by the loops, idle)``.

    Idle joints (their column of the loop Jacobian is zero at ``q``, e.g. a rod's spin about its own axis
    between two spherical joints) are left free by the loops: neither MuJoCo nor Pinocchio fixes them.
    """
    jac = robot.constraint_jacobian(q) if robot.loops else np.zeros((0, robot.model.nv))
    scale = max(float(np.abs(jac).max(initial=0.0)), 1e-300)
    driven, idle = [], []
    for name in robot.joint_names:
        j = robot.model.joints[robot.joint_id(name)]
        if j.nv != 1 or name in robot.actuated_joints:
            continue
        col = jac[:, j.idx_v]
        (driven if np.abs(col).max(initial=0.0) > 1e-9 * scale else idle).append(name)
    return driven, idle


def drive_clip(mech: MujocoMechanism, qs: Sequence[np.ndarray], frame_time: float = 0.02) -> dict[str, np.ndarray]:
    """Drive the actuators through the clip ``qs`` and compare the passive joints with Pinocchio.

    The simulation starts at rest at ``qs[0]``; the actuator targets go linearly from one frame's actuated
    values to the next in ``frame_time`` seconds. At the end of each frame, Pinocchio's loop solver closes
    the loops from MuJoCo's configuration with the actuated joints held at MuJoCo's values (the angles
    MuJoCo reached, not the commanded ones: the comparison is about the loops, not about tracking; only the
    independent ones, :func:`independent_actuated`, for a redundantly actuated mechanism).

    Returns:
        ``{"passive": (frames-1, passive) |q_mujoco - q_pinocchio| of the loop-driven passive joints,
        "tracking": (frames-1, actuated) |q_mujoco - q_clip| of the actuated joints, "loop": (frames-1, loops)
        loop residuals, "passive_joints": names}``; NaN rows where the state is not finite or a solve failed.
    """
    mujoco = _mujoco()
    robot = mech.robot
    qs = [robot.check_q(q) for q in qs]
    driven, _ = passive_joints(robot, qs[0])
    held = independent_actuated(robot, qs[0])
    pidx = np.array([robot.idx_q(n) for n in driven], dtype=int)
    aidx = np.array(mech.actuator_q, dtype=int)
    steps = max(1, int(round(frame_time / mech.model.opt.timestep)))
    mech.set_configuration(qs[0])
    n = len(qs) - 1
    passive = np.full((n, pidx.size), np.nan)
    tracking = np.full((n, aidx.size), np.nan)
    loops = np.full((n, len(mech.loop_sites)), np.nan)
    for k in range(n):
        c0, c1 = mech.ctrl(qs[k]), mech.ctrl(qs[k + 1])
        for s in range(steps):
            a = (s + 1) / steps
            mech.data.ctrl[:] = (1 - a) * c0 + a * c1
            mujoco.mj_step(mech.model, mech.data)
        if not np.all(np.isfinite(mech.data.qpos)):
            break
        q_mj = mech.q(mech.data.qpos)
        loops[k] = mech.loop_residuals()
        tracking[k] = np.abs(q_mj[aidx] - qs[k + 1][aidx])
        try:
            q_pin = robot.solve_loops(q_mj, fixed=held, tol=1e-13, max_iter=50)
        except LoopClosureError:
            continue
        passive[k] = np.abs(q_mj[pidx] - q_pin[pidx])
    return {"passive": passive, "tracking": tracking, "loop": loops, "passive_joints": driven}


def _clip_frames(robot: "Robot") -> tuple[str | None, list[np.ndarray]]:
    """The first clip of the model (name, configurations), or ``(None, [])``."""
    try:
        from legkin.clips import available, frames
    except ImportError:
        from legkin.animations import available, frames
    clips = available(robot.name)
    if not clips:
        return None, []
    name = sorted(clips)[0]
    return name, [np.asarray(q, dtype=float) for q in frames(robot, name)]


def check_rows(
    name: str,
    samples: int = 10,
    rng: np.random.Generator | None = None,
    *,
    seconds: float = 2.0,
    frame_time: float = 0.02,
    mech: MujocoMechanism | None = None,
) -> list["CheckResult"]:
    """The ``legkin check`` rows of the MuJoCo model of ``name`` against Pinocchio.

    1. at ``q0`` and ``samples`` random closed configurations (:func:`closed_configurations`), MuJoCo's body
       and site positions (``mj_kinematics``) equal Pinocchio's joint and frame placements (1e-12 m);
    2. MuJoCo's equality residuals there (``efc_pos`` after ``mj_forward``) are 0 (1e-12; models with loops);
    3. 2 s under gravity from ``q0`` with the actuators holding it: a finite state, every loop residual
       under 1e-4 (m, rad); for a model without loops, the state stays finite (its actuated joints' largest
       drift from ``q0`` is the row's error, tolerance 0.05 rad);
    4. driving the actuators along the model's first clip: the loop-driven passive joints equal Pinocchio's
       loop solution at MuJoCo's actuated angles within 1e-3 rad (models with passive joints).

    Args:
        name: a registered model.
        samples: random closed configurations of rows 1-2 (an integer >= 0).
        rng: random generator (default ``numpy.random.default_rng(0)``).
        seconds: simulated time of row 3.
        frame_time: seconds per clip frame in row 4.
        mech: a :class:`MujocoMechanism` to check instead of ``load_mujoco(name)`` (e.g. an edited MJCF).

    Raises:
        LegkinError: MuJoCo is not installed (:func:`unavailable_reason` says so without raising).
        UnknownModelError: ``name`` is not registered.
    """
    from .validation import compare

    _mujoco()
    samples = check_count("samples", samples)
    seconds = check_real("seconds", seconds, 0.0, low_open=True)
    frame_time = check_real("frame_time", frame_time, 0.0, low_open=True)
    rng = np.random.default_rng(0) if rng is None else rng
    mech = load_mujoco(name) if mech is None else mech
    robot = mech.robot
    qs = closed_configurations(robot, samples, rng)
    rows = [compare(
        f"MuJoCo body/site positions = Pinocchio joint/frame placements (q0 + {samples} closed configurations, m)",
        placement_errors(mech, qs), TOL_PLACEMENT,
    )]
    if robot.loops:
        rows.append(compare(
            f"MuJoCo equality residuals efc_pos at closed configurations ({len(robot.loops)} loops, m/rad)",
            equality_errors(mech, qs), TOL_EQUALITY,
        ))
    hold = hold_under_gravity(mech, seconds)
    if robot.loops:
        rows.append(compare(
            f"MuJoCo {seconds:g} s under gravity, actuators holding q0: loop residuals (m/rad)",
            hold["loop"], TOL_GRAVITY,
        ))
    else:
        rows.append(compare(
            f"MuJoCo {seconds:g} s under gravity, actuators holding q0: finite, joint drift from q0 (rad)",
            hold["joint"], 0.05,
        ))
    driven, _ = passive_joints(robot, robot.q0)
    if driven:
        clip, frames = _clip_frames(robot)
        if clip is not None:
            res = drive_clip(mech, frames, frame_time)
            rows.append(compare(
                f"MuJoCo clip {clip!r} ({len(frames)} frames x {frame_time:g} s): {len(driven)} passive joints = "
                "Pinocchio's loop solution at MuJoCo's actuated angles (rad)",
                res["passive"], TOL_CLIP,
            ))
    return rows


# ------------------------------------------------------------------------------------------ pictures
def render_png(
    mech: MujocoMechanism,
    path: str | Path,
    q: np.ndarray | None = None,
    *,
    width: int = 800,
    height: int = 600,
    azimuth: float = 135.0,
    elevation: float = -20.0,
    zoom: float = 1.0,
    lookat: Sequence[float] | None = None,
) -> Path:
    """Render configuration ``q`` (default: the current ``data``) with MuJoCo's own renderer to a PNG.

    Headless machines need ``MUJOCO_GL=egl`` (or ``osmesa``) in the environment before ``import mujoco``.
    The camera looks at ``lookat`` (default: the centre of the model's visuals) from ``azimuth``/``elevation``
    (degrees), at a distance 1.6 times the visuals' extent divided by ``zoom``.

    Raises:
        LegkinError: no OpenGL context (the message says which ``MUJOCO_GL`` to try), or Pillow missing.
    """
    mujoco = _mujoco()
    try:
        from PIL import Image
    except ImportError:
        raise LegkinError("render_png needs Pillow: pip install pillow") from None
    width, height = check_count("width", width, 1), check_count("height", height, 1)
    if q is not None:
        mech.set_configuration(q, forward=False)
    mujoco.mj_forward(mech.model, mech.data)
    geoms = [g for g in range(mech.model.ngeom) if mech.model.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE]
    pts = mech.data.geom_xpos[geoms] if geoms else mech.data.xpos
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    cam = mujoco.MjvCamera()
    cam.lookat[:] = 0.5 * (lo + hi) if lookat is None else np.asarray(lookat, dtype=float)
    cam.distance = 1.6 * max(float(np.linalg.norm(hi - lo)), 0.05) / zoom
    cam.azimuth, cam.elevation = azimuth, elevation
    try:
        renderer = mujoco.Renderer(mech.model, height, width)
    except Exception as exc:  # noqa: BLE001 - MuJoCo raises several kinds when there is no GL context
        raise LegkinError(f"no OpenGL context for MuJoCo's renderer ({exc}); try MUJOCO_GL=egl or osmesa") from None
    try:
        renderer.update_scene(mech.data, camera=cam)
        pixels = renderer.render()
    finally:
        renderer.close()
    path = Path(path)
    Image.fromarray(pixels).save(path)
    return path


# ------------------------------------------------------------------------------------------ command line
def add_export_command(subparsers: "argparse._SubParsersAction") -> "argparse.ArgumentParser":
    """Add ``legkin mjcf MODEL [-o FILE] [--floating] [--timestep S] [--png FILE]`` to ``legkin``'s parser."""
    p = subparsers.add_parser("mjcf", help="write a MuJoCo MJCF of a model, loops as equality constraints")
    p.add_argument("model")
    p.add_argument("-o", "--output", metavar="PATH", help="write the MJCF to PATH (default: stdout)")
    p.add_argument("--floating", action="store_true", help="a free base (models that walk only)")
    p.add_argument("--timestep", type=float, default=DEFAULTS["timestep"], help="simulation step, s (default %(default)g)")
    p.add_argument("--png", metavar="PATH", help="also render q0 with MuJoCo to PATH (needs MUJOCO_GL=egl headless)")
    p.set_defaults(func=run_export)
    return p


def run_export(args: "argparse.Namespace") -> int:
    """Run ``legkin mjcf``: write the MJCF (compiled once by MuJoCo first, when it is installed)."""
    from .robot import load

    robot = load(args.model, floating=bool(args.floating))
    xml = to_mjcf(robot, timestep=args.timestep)
    if unavailable_reason() is None:
        mech = load_mujoco(robot, xml=xml)  # MuJoCo accepts it, or a LegkinError says why
        if args.png:
            print(f"wrote {render_png(mech, args.png, robot.q0)}")
    elif args.png:
        raise LegkinError(unavailable_reason())
    if args.output:
        Path(args.output).write_text(xml)
        print(f"wrote {args.output}")
    else:
        print(xml, end="")
    return 0
