"""``legkin convert IN OUT``: a robot's loops between the YAML sidecar, ``<loop_closure>`` and MJCF equalities.

The output form follows ``OUT``'s name:

* ``*.yaml`` / ``*.yml``: the sidecar (``closed_loop``, ``type``, ``name_mot``; ``joint_name`` /
  ``joint_type`` carried over from a sidecar input);
* ``*.urdf``: the input URDF with one ``<loop_closure name type frame1 frame2>`` per loop and a ROS
  ``<transmission>`` per motor (no other change), which ``legkin.load`` reads without a sidecar (the joint
  replacements of a sidecar cannot be written in a URDF: refused);
* ``*.xml``: legkin's MJCF export (:func:`legkin.mjcf.to_mjcf`), loops as ``<connect>`` / ``<weld>``
  between sites.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..errors import InvalidInputError
from .robot import FileRobot, load_file
from .sidecar import read_sidecar, sidecar_text
from .urdf import urdf_text

__all__ = ["convert"]


def _urdf_with_loops(robot: FileRobot) -> str:
    root = ET.fromstring(urdf_text(robot.urdf_path))
    for el in list(root.iter("loop_closure")):
        root.remove(el)
    for lp in robot.loops:
        ET.SubElement(root, "loop_closure", name=lp.name, type=lp.type, frame1=lp.frame1, frame2=lp.frame2)
    declared = {j.get("name") for j in root.iterfind("transmission/joint")}
    for name in robot.actuated:
        if name not in declared:  # the motors, as ROS transmissions (read back by legkin.load)
            tr = ET.SubElement(root, "transmission", name=f"{name}_transmission")
            ET.SubElement(tr, "type").text = "transmission_interface/SimpleTransmission"
            ET.SubElement(ET.SubElement(tr, "joint", name=name), "hardwareInterface").text = "PositionJointInterface"
            ET.SubElement(tr, "actuator", name=f"{name}_motor")
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


def _joint_types(robot: FileRobot, loops: str | Path | None) -> dict[str, str]:
    path = Path(loops) if loops is not None else robot.urdf_path.parent / "robot.yaml"
    if robot.urdf_path.suffix.lower() == ".xml" or not path.exists():
        return {}
    return dict(read_sidecar(path).joint_types)


def convert(src: str | Path, dst: str | Path, *, loops: str | Path | None = None) -> Path:
    """Write ``src``'s robot with its loops in the form ``dst``'s suffix asks for; returns ``dst``.

    Args:
        src: a robot file :func:`legkin.loaders.load_file` reads.
        dst: ``*.yaml``, ``*.urdf`` or ``*.xml``.
        loops: the sidecar of ``src``, if not beside it.

    Raises:
        InvalidInputError: an unknown output suffix, or a URDF output of a robot whose sidecar replaces joints.
    """
    src, dst = Path(src), Path(dst)
    robot = load_file(src, loops=loops)
    suffix = dst.suffix.lower()
    joint_types = _joint_types(robot, loops)
    if suffix in (".yaml", ".yml"):
        text = sidecar_text(robot.loops, robot.actuated, joint_types)
    elif suffix == ".urdf":
        if robot.urdf_path.suffix.lower() == ".xml":
            raise InvalidInputError(f"{dst}: an MJCF converts to .yaml or .xml (its model is not a URDF)")
        if joint_types:
            raise InvalidInputError(
                f"{dst}: the sidecar replaces joints ({', '.join(joint_types)}), which a URDF cannot say: "
                "convert to .xml (MJCF) or keep the sidecar"
            )
        text = _urdf_with_loops(robot)
    elif suffix == ".xml":
        from ..mjcf import to_mjcf

        text = to_mjcf(robot)
    else:
        raise InvalidInputError(f"{dst}: unknown output form {dst.suffix!r}; valid: .yaml, .yml, .urdf, .xml")
    dst.write_text(text)
    return dst
