"""A Pinocchio model from a user's URDF or xacro: joint replacements, meshes that may be missing.

Meshes are resolved as Pinocchio does (``package://`` against the package directories, here the URDF's
directory and its parent; a relative path against the URDF's directory); a mesh that is not there is left out
of the visual and collision models (the kinematics do not need it) and listed in ``missing_meshes``, which
``legkin view`` prints.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from ..errors import InvalidInputError

__all__ = ["UrdfModels", "urdf_text", "resolve_mesh", "build_urdf_models", "replace_joints"]


@dataclass
class UrdfModels:
    """The Pinocchio models built from one URDF text.

    Attributes:
        model: the kinematic tree (joints replaced as asked).
        visual_model, collision_model: geometry models (meshes that are missing left out).
        missing_meshes: the mesh file names that could not be found (sorted, no repeats).
    """

    model: pin.Model
    visual_model: pin.GeometryModel
    collision_model: pin.GeometryModel
    missing_meshes: list[str]


def urdf_text(path: Path) -> str:
    """The URDF text of ``path``: the file itself, or xacro's output for a ``.xacro`` file.

    Raises:
        InvalidInputError: the file cannot be read, or xacro fails (the message names the file).
    """
    try:
        if path.suffix == ".xacro":
            import xacro

            return str(xacro.process_file(str(path)).toxml())  # type: ignore[attr-defined]
        return path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{path}: cannot read ({exc})") from None
    except Exception as exc:  # noqa: BLE001 - xacro raises its own and plain exceptions for a bad file
        raise InvalidInputError(f"{path}: xacro failed: {exc}") from None


def resolve_mesh(filename: str, urdf_dir: Path) -> Path | None:
    """The file a URDF mesh name refers to, or None when it is not there.

    ``package://NAME/rest`` and ``package:///rest`` are looked up in the URDF's directory and its parent
    (Pinocchio's package directories here); ``file://`` and relative names against the URDF's directory.
    """
    if filename.startswith("package://"):
        rest = filename[len("package://"):]
        candidates = [urdf_dir / rest.lstrip("/"), urdf_dir.parent / rest.lstrip("/")]
        if "/" in rest.lstrip("/"):
            candidates.append(urdf_dir / rest.lstrip("/").split("/", 1)[1])
    else:
        name = filename[len("file://"):] if filename.startswith("file://") else filename
        candidates = [urdf_dir / name]
    return next((c for c in candidates if c.is_file()), None)


def _strip_missing(root: ET.Element, urdf_dir: Path) -> list[str]:
    """Remove every ``<visual>``/``<collision>`` whose mesh is missing; returns the missing file names."""
    missing: set[str] = set()
    for link in root.iter("link"):
        for kind in ("visual", "collision"):
            for el in list(link.findall(kind)):
                mesh = el.find("geometry/mesh")
                if mesh is not None and resolve_mesh(mesh.get("filename", ""), urdf_dir) is None:
                    missing.add(mesh.get("filename", ""))
                    link.remove(el)
    return sorted(missing)


def _add(new: pin.Model, model: pin.Model, jid: int, parent: int, joint, placement: pin.SE3, name: str,
         keep_limits: bool) -> int:
    if not keep_limits:
        return int(new.addJoint(parent, joint, placement, name))
    j = model.joints[jid]
    sl, vs = slice(j.idx_q, j.idx_q + j.nq), slice(j.idx_v, j.idx_v + j.nv)
    return int(new.addJoint(parent, joint, placement, name, model.effortLimit[vs], model.velocityLimit[vs],
                            model.lowerPositionLimit[sl], model.upperPositionLimit[sl]))


def _add_replaced(new: pin.Model, model: pin.Model, jid: int, parent: int, kind: str) -> int:
    """Add joint ``jid`` of ``model`` to ``new`` as ``kind``; returns the id of the joint carrying its body.

    ``UJOINT_XY`` is two revolute joints at the same origin: ``<name>`` about x, then ``<name>_y`` about the
    rotated y (``UJOINT_YX``: ``<name>`` about y, ``<name>_x`` about x), the body on the second, so that every
    joint stays a plain revolute (the MJCF export writes two hinges).
    """
    name, placement = model.names[jid], model.jointPlacements[jid]
    if kind in ("KEEP", "FIXED"):  # FIXED: kept here, locked by build_urdf_models
        return _add(new, model, jid, parent, model.joints[jid], placement, name, True)
    if kind == "SPHERICAL":
        return _add(new, model, jid, parent, pin.JointModelSpherical(), placement, name, False)
    first, second, suffix = ((pin.JointModelRX(), pin.JointModelRY(), "_y") if kind == "UJOINT_XY"
                             else (pin.JointModelRY(), pin.JointModelRX(), "_x"))
    mid = _add(new, model, jid, parent, first, placement, name, False)
    return _add(new, model, jid, mid, second, pin.SE3.Identity(), name + suffix, False)


def replace_joints(model: pin.Model, joint_types: dict[str, str], where: str) -> pin.Model:
    """``model`` with the named joints replaced (``SPHERICAL``, ``UJOINT_XY``, ``UJOINT_YX``; ``FIXED`` is
    applied by :func:`build_urdf_models`), names, frames and inertias kept (frames re-attached to the new ids).

    Raises:
        InvalidInputError: a joint name that the model does not have (naming ``where``, the key and the name).
    """
    for i, name in enumerate(joint_types):
        if not model.existJointName(name):
            raise InvalidInputError(
                f"{where}: key 'joint_name[{i}]': the URDF has no joint {name!r}; joints: {', '.join(model.names[1:])}"
            )
    new = pin.Model()
    new.name = model.name
    ids = {0: 0}
    for jid in range(1, model.njoints):
        ids[jid] = _add_replaced(new, model, jid, ids[model.parents[jid]], joint_types.get(model.names[jid], "KEEP"))
        new.appendBodyToJoint(ids[jid], model.inertias[jid], pin.SE3.Identity())
    for f in list(model.frames)[1:]:
        parent_frame = new.getFrameId(model.frames[f.parentFrame].name) if f.parentFrame else 0
        new.addFrame(pin.Frame(f.name, ids[f.parentJoint], parent_frame, f.placement, f.type, f.inertia), False)
    return new


def _geometry(model: pin.Model, text: str, urdf_dir: Path, kind) -> pin.GeometryModel:
    return pin.buildGeomFromUrdfString(model, text, kind, package_dirs=[str(urdf_dir), str(urdf_dir.parent)])


def build_urdf_models(text: str, path: Path, joint_types: dict[str, str] | None = None, *,
                      floating: bool = False, where: str | None = None) -> UrdfModels:
    """Pinocchio's model and geometry models of a URDF text, joints replaced as ``joint_types`` asks.

    Args:
        text: the URDF (xacro already run).
        path: the file it came from (meshes are resolved against its directory).
        joint_types: joint name -> ``SPHERICAL``, ``UJOINT_XY``, ``UJOINT_YX`` or ``FIXED`` (locked at 0).
        floating: add a free-flyer root joint.
        where: the file named by the messages about ``joint_types`` (default ``path``).

    Raises:
        InvalidInputError: a URDF Pinocchio cannot parse, or a replaced joint that does not exist.
    """
    joint_types = dict(joint_types or {})
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise InvalidInputError(f"{path}: not valid XML ({exc})") from None
    missing = _strip_missing(root, path.parent)
    text = ET.tostring(root, encoding="unicode")
    try:
        model = (pin.buildModelFromXML(text, pin.JointModelFreeFlyer()) if floating else pin.buildModelFromXML(text))
        if joint_types:
            model = replace_joints(model, joint_types, where or str(path))
        visual = _geometry(model, text, path.parent, pin.VISUAL)  # found by link (frame) name
        collision = _geometry(model, text, path.parent, pin.COLLISION)
    except (ValueError, RuntimeError) as exc:
        raise InvalidInputError(f"{path}: Pinocchio cannot build the model: {' '.join(str(exc).split())}") from None
    locked = [model.getJointId(n) for n, k in joint_types.items() if k == "FIXED"]
    if locked:
        model, (visual, collision) = pin.buildReducedModel(model, [visual, collision], locked, pin.neutral(model))
    return UrdfModels(model, visual, collision, missing)
