"""Robots from their own files: URDF + YAML sidecar (Gepetto's example-parallel-robots), xacro/URDF with
``<loop_closure>``, MJCF with ``<equality>`` constraints; and conversion between the three loop forms.

``legkin.load(path)`` calls :func:`load_file`.
"""

from .robot import REFERENCE_POSE, FileRobot, load_file
from .sidecar import JOINT_TYPES, Sidecar, parse_sidecar, read_sidecar, sidecar_text

__all__ = ["FileRobot", "load_file", "REFERENCE_POSE", "Sidecar", "parse_sidecar", "read_sidecar", "sidecar_text",
           "JOINT_TYPES"]
