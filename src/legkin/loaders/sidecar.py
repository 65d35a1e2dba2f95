"""The YAML sidecar of Gepetto's example-parallel-robots (``robot.yaml`` beside ``robot.urdf``): read and write.

Keys (BSD-3 format of Gepetto's ``example-parallel-robots``; semantics only, no code taken):

* ``closed_loop``: a list of ``[frame1, frame2]`` pairs, two frames of the URDF that coincide when the loop is
  closed;
* ``type``: one per loop, ``6d`` (the two placements coincide; also written ``6D``) or ``3d`` (the two origins
  coincide; ``3D``); missing: every loop is ``6d``;
* ``name_mot``: the actuated joints;
* ``joint_name`` / ``joint_type`` (optional, same length): joints replaced before the model is built,
  ``SPHERICAL`` (a ball joint at the joint's origin), ``UJOINT_XY`` (a universal joint: rotation about the
  joint frame's x axis, then about the rotated y axis, as two revolute joints ``<name>`` and ``<name>_y``;
  ``UJOINT_YX`` the other order, ``<name>`` and ``<name>_x``; ``CARDAN`` is Gepetto's older name of
  ``UJOINT_XY``) or ``FIXED`` (the joint is locked at 0).

legkin's :class:`~legkin.loops.LoopSpec` names a 6d loop ``type="frame"`` and a 3d loop ``type="point"``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InvalidInputError
from ..loops import LoopSpec

__all__ = ["Sidecar", "JOINT_TYPES", "read_sidecar", "parse_sidecar", "sidecar_text"]

#: Joint replacements the sidecar may ask for (``joint_type`` values).
JOINT_TYPES = ("SPHERICAL", "UJOINT_XY", "UJOINT_YX", "CARDAN", "FIXED")
_LOOP_TYPES = {"6d": "frame", "3d": "point"}
_KEYS = ("closed_loop", "type", "name_mot", "joint_name", "joint_type")


@dataclass(frozen=True)
class Sidecar:
    """What a ``robot.yaml`` declares.

    Attributes:
        loops: the loop closures, named ``loop1``, ``loop2``, ... in file order.
        actuated: the actuated joint names (``name_mot``).
        joint_types: joint name -> replacement type (``SPHERICAL``, ``UJOINT_XY``, ``UJOINT_YX``, ``FIXED``).
        path: the file read (None for text).
    """

    loops: tuple[LoopSpec, ...]
    actuated: tuple[str, ...]
    joint_types: dict[str, str] = field(default_factory=dict)
    path: Path | None = None


def _fail(where: str, key: str, value: Any, why: str) -> InvalidInputError:
    return InvalidInputError(f"{where}: key {key!r}: {why}, got {value!r}")


def _strings(where: str, key: str, value: Any) -> list[str]:
    if value is None:
        return []
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(where, key, value, "must be a list of names")
    return list(value)


def _loops(where: str, doc: dict) -> tuple[LoopSpec, ...]:
    pairs = doc.get("closed_loop") or []
    if not isinstance(pairs, list):
        raise _fail(where, "closed_loop", pairs, "must be a list of [frame1, frame2] pairs")
    types = doc.get("type")
    types = ["6d"] * len(pairs) if types is None else types
    if not isinstance(types, list) or len(types) != len(pairs):
        raise _fail(where, "type", types, f"must be a list of {len(pairs)} loop types (one per closed_loop pair)")
    loops = []
    for i, (pair, kind) in enumerate(zip(pairs, types)):
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(p, str) for p in pair)):
            raise _fail(where, f"closed_loop[{i}]", pair, "must be a pair [frame1, frame2] of frame names")
        kind_key = str(kind).lower()
        if kind_key not in _LOOP_TYPES:
            raise _fail(where, f"type[{i}]", kind, "unknown loop type; valid: 6d, 6D, 3d, 3D")
        loops.append(LoopSpec(f"loop{i + 1}", _LOOP_TYPES[kind_key], pair[0], pair[1]))
    return tuple(loops)


def _joint_types(where: str, doc: dict) -> dict[str, str]:
    names = _strings(where, "joint_name", doc.get("joint_name"))
    types = _strings(where, "joint_type", doc.get("joint_type"))
    if len(names) != len(types):
        raise _fail(where, "joint_type", types, f"must list one type per joint_name entry ({len(names)})")
    for i, t in enumerate(types):
        if t.upper() not in JOINT_TYPES:
            raise _fail(where, f"joint_type[{i}]", t, f"unknown joint type; valid: {', '.join(JOINT_TYPES)}")
    return {n: "UJOINT_XY" if t.upper() == "CARDAN" else t.upper() for n, t in zip(names, types)}


def parse_sidecar(text: str, where: str = "<robot.yaml>") -> Sidecar:
    """A :class:`Sidecar` from the text of a ``robot.yaml``.

    Args:
        text: the YAML text.
        where: the file name the messages give.

    Returns:
        The loops, actuated joints and joint replacements declared.

    Raises:
        InvalidInputError: malformed YAML, an unknown key, or a key whose value is not what it must be (the
            message names the file, the key and the value).
    """
    import yaml

    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise InvalidInputError(f"{where}: not valid YAML: {' '.join(str(exc).split())}") from None
    if doc is None:
        doc = {}
    if not isinstance(doc, dict):
        raise InvalidInputError(f"{where}: must be a mapping of keys {', '.join(_KEYS)}, got {type(doc).__name__}")
    unknown = sorted(str(k) for k in doc if k not in _KEYS)
    if unknown:
        raise _fail(where, unknown[0], doc[unknown[0]], f"unknown key; valid keys: {', '.join(_KEYS)}")
    actuated = _strings(where, "name_mot", doc.get("name_mot"))
    return Sidecar(_loops(where, doc), tuple(actuated), _joint_types(where, doc))


def read_sidecar(path: str | Path) -> Sidecar:
    """:func:`parse_sidecar` of the file ``path`` (its messages name the file).

    Raises:
        InvalidInputError: the file cannot be read, or its contents are invalid.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{path}: cannot read the loop file ({exc})") from None
    s = parse_sidecar(text, str(path))
    return Sidecar(s.loops, s.actuated, s.joint_types, path)


def sidecar_text(loops: list[LoopSpec] | tuple[LoopSpec, ...], actuated: list[str] | tuple[str, ...],
                 joint_types: dict[str, str] | None = None) -> str:
    """The ``robot.yaml`` text declaring ``loops``, ``actuated`` and the joint replacements ``joint_types``."""
    import yaml

    back = {v: k for k, v in _LOOP_TYPES.items()}
    doc: dict[str, Any] = {
        "closed_loop": [[lp.frame1, lp.frame2] for lp in loops],
        "type": [back[lp.type] for lp in loops],
        "name_mot": list(actuated),
    }
    if joint_types:
        doc["joint_name"] = list(joint_types)
        doc["joint_type"] = list(joint_types.values())
    return str(yaml.safe_dump(doc, default_flow_style=None, sort_keys=False))
