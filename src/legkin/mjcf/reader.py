"""A Pinocchio model and loops from an MJCF file with ``<equality><connect|weld>`` constraints.

Pinocchio 4.1 parses MJCF (``buildModelAndConstraintsFromMJCF``), with two traits worked around here:

* it keeps only the first top-level ``<body>`` of ``<worldbody>``: the bodies are read through a copy of the
  file in which they hang from one fixed root body (``legkin_root``, 1e-9 kg);
* its keyframes must match its model's size: the copy leaves them out (:func:`read_mjcf_keys` reads them).

Each equality becomes a loop: ``connect`` -> ``type="point"``, ``weld`` -> ``type="frame"``. The site form
(``site1``/``site2``) names its two frames directly (MJCF sites are Pinocchio frames). The body form
(``body1``/``body2``) takes the anchors Pinocchio computed (the second at ``qpos0``, MuJoCo's rule) and adds
them to the model as frames ``<name>_1`` / ``<name>_2``. The actuated joints are those of ``<actuator>``.
"""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError
from ..loops import LoopSpec

__all__ = ["MjcfModels", "read_mjcf"]

_ROOT = "legkin_root"


class MjcfModels:
    """What :func:`read_mjcf` returns: ``model``, ``visual_model``, ``collision_model``, ``loops``,
    ``actuated`` (joint names) and ``keys`` (keyframe name -> qpos)."""

    def __init__(self, model, visual_model, collision_model, loops, actuated, keys):
        self.model = model
        self.visual_model = visual_model
        self.collision_model = collision_model
        self.loops: list[LoopSpec] = loops
        self.actuated: list[str] = actuated
        self.keys: dict[str, np.ndarray] = keys


def _prepared(root: ET.Element, path: Path) -> ET.Element:
    """The tree Pinocchio reads: one top-level body, no keyframes, asset paths made absolute."""
    wb = root.find("worldbody")
    if wb is None:
        raise InvalidInputError(f"{path}: an MJCF needs a <worldbody>")
    bodies = [b for b in wb if b.tag == "body"]
    if len(bodies) > 1:
        wrap = ET.Element("body", name=_ROOT)
        ET.SubElement(wrap, "inertial", pos="0 0 0", mass="1e-9", diaginertia="1e-12 1e-12 1e-12")
        for b in bodies:
            wb.remove(b)
            wrap.append(b)
        wb.append(wrap)
    for kf in root.findall("keyframe"):
        root.remove(kf)
    compiler = root.find("compiler")
    base = path.parent
    if compiler is not None and compiler.get("meshdir"):
        compiler.set("meshdir", str((base / compiler.get("meshdir", "")).resolve()))
    elif compiler is None or not compiler.get("meshdir"):
        for mesh in root.iter("mesh"):
            if mesh.get("file") and not Path(mesh.get("file", "")).is_absolute():
                mesh.set("file", str((base / mesh.get("file", "")).resolve()))
    return root


def _anchor_frames(model: pin.Model, cm, name: str) -> tuple[str, str]:
    """Add the two anchors of a Pinocchio constraint model as frames; returns their names."""
    names = (f"{name}_1", f"{name}_2")
    for fname, jid, placement in zip(names, (cm.joint1_id, cm.joint2_id), (cm.joint1_placement, cm.joint2_placement)):
        model.addFrame(pin.Frame(fname, jid, placement, pin.FrameType.OP_FRAME), False)
    return names


def _loops(root: ET.Element, model: pin.Model, point_cms, frame_cms, path: Path) -> list[LoopSpec]:
    eq = root.find("equality")
    loops: list[LoopSpec] = []
    counters = {"connect": 0, "weld": 0}
    for i, el in enumerate([] if eq is None else list(eq)):
        if el.tag not in counters:
            raise InvalidInputError(
                f"{path}: <equality> element {i} is <{el.tag}>: legkin reads <connect> and <weld> loops only"
            )
        name = el.get("name") or f"{el.tag}{i + 1}"
        kind = "point" if el.tag == "connect" else "frame"
        cms = point_cms if el.tag == "connect" else frame_cms
        k = counters[el.tag]
        counters[el.tag] += 1
        if el.get("site1") and el.get("site2"):
            f1, f2 = el.get("site1", ""), el.get("site2", "")
            for key, f in (("site1", f1), ("site2", f2)):
                if not model.existFrame(f):
                    raise InvalidInputError(f"{path}: equality {name!r}: {key}={f!r} is not a site of the model")
        elif k < len(cms):
            f1, f2 = _anchor_frames(model, cms[k], name)
        else:
            raise InvalidInputError(f"{path}: equality {name!r}: Pinocchio made no constraint of it")
        loops.append(LoopSpec(name, kind, f1, f2))
    return loops


def read_mjcf_keys(root: ET.Element, nq: int) -> dict[str, np.ndarray]:
    """The keyframes' ``qpos`` of the right size (``nq``), by name (``key<i>`` for a nameless one)."""
    keys = {}
    for kf in root.iter("keyframe"):
        for i, key in enumerate(kf.findall("key")):
            q = np.array(key.get("qpos", "").split(), dtype=float)
            if q.shape == (nq,):
                keys[key.get("name") or f"key{i}"] = q
    return keys


def read_mjcf(path: Path) -> MjcfModels:
    """The model, geometry, loops, actuated joints and keyframes of an MJCF file.

    Raises:
        InvalidInputError: a file that is not XML, that Pinocchio cannot parse, or an equality that is not a
            ``connect`` / ``weld`` (the message names the file and the element).
    """
    try:
        original = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise InvalidInputError(f"{path}: cannot read the MJCF ({exc})") from None
    root = _prepared(ET.fromstring(ET.tostring(original)), path)
    with tempfile.TemporaryDirectory(prefix="legkin-mjcf-") as tmp:
        copy = Path(tmp) / path.name
        copy.write_text(ET.tostring(root, encoding="unicode"))
        try:
            model, point_cms, frame_cms = pin.buildModelAndConstraintsFromMJCF(str(copy))
            visual = pin.buildGeomFromMJCF(model, str(copy), pin.VISUAL)
            collision = pin.buildGeomFromMJCF(model, str(copy), pin.COLLISION)
        except (ValueError, RuntimeError) as exc:
            raise InvalidInputError(f"{path}: Pinocchio cannot read it: {' '.join(str(exc).split())}") from None
    loops = _loops(root, model, list(point_cms), list(frame_cms), path)
    actuated = [a.get("joint", "") for a in root.iter("actuator") for a in a if a.get("joint")]
    return MjcfModels(model, visual, collision, loops, actuated, read_mjcf_keys(original, model.nq))
