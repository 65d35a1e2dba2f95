"""Registry entries of the robots whose leg kinematics :mod:`legkin.legs` measures from their URDF.

One shared package serves them all (``ModelSpec.package == "legkin.legs"``): their URDF and SRDF are the installed
distribution's (:func:`legkin.legs.erd.erd_files`), every one-coordinate joint is driven, and
:attr:`legkin.Robot.geometry` is the legs measured from the model (:func:`legkin.legs.from_model`).
"""

from __future__ import annotations

from typing import Any

from .._registry import ModelSpec
from .erd import ERD_ALL, erd_files, standing_pose

__all__ = ["SPECS"]

def _legs(robot: Any) -> Any:
    """The legs of a loaded robot, ``{leg name: Leg}``."""
    from .extract import from_model

    return from_model(robot.model)


def _foot_frame(robot: Any) -> str:
    """The foot frame of the benched leg (:data:`legkin.legs.bench.LEG`, else the first)."""
    from .bench import LEG

    legs = robot.geometry
    return str(legs[LEG if LEG in legs else next(iter(legs))].foot_frame)


SPECS = [
    ModelSpec(
        name=r.name,
        title=f"{r.title}: leg kinematics measured from its URDF (legkin.legs)",
        seed="",
        actuated_joints=None,
        floating=True,
        reference_pose=r.reference_pose or "",
        source="example-robot-data",
        package="legkin.legs",
        locate=erd_files,
        default_pose=standing_pose,
        geometry=_legs,
        yardstick_frame=_foot_frame,
        mjcf=False,  # their meshes are .dae, which MuJoCo does not read
    )
    for r in ERD_ALL.values()
]
