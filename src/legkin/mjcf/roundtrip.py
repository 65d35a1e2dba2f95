"""The MJCF round trip: legkin's export of a model read back by Pinocchio's MJCF parser (:mod:`.reader`) has the
same loops, closed at the same configurations (a row of ``legkin check``, :func:`legkin.mjcf.check_rows`)."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..closing import loop_errors
from .reader import read_mjcf
from .writer import to_mjcf

if TYPE_CHECKING:
    from ..robot import Robot

__all__ = ["mjcf_round_trip_error"]


def mjcf_round_trip_error(robot: Robot, qs: np.ndarray | None = None) -> float:
    """The largest loop error of ``robot``'s MJCF export read back by Pinocchio's MJCF parser.

    Args:
        robot: a loaded robot with loops.
        qs: closed configurations of ``robot`` (rad, m), besides ``robot.q0``; joints are matched by name.

    Returns:
        The largest loop error of the read-back model (m or rad) at ``robot.q0`` and ``qs``; inf when the
        loops' count or types, or the actuated joints, differ.
    """
    with tempfile.TemporaryDirectory(prefix="legkin-roundtrip-") as tmp:
        path = Path(tmp) / f"{robot.name}.xml"
        path.write_text(to_mjcf(robot))
        back = read_mjcf(path)
    if [lp.type for lp in back.loops] != [lp.type for lp in robot.loops] or tuple(back.actuated) != tuple(
            robot.actuated_joints):
        return float("inf")
    data = back.model.createData()
    worst = 0.0
    for q_robot in [robot.q0, *([] if qs is None else qs)]:
        q = pin.neutral(back.model)
        for name in robot.joint_names:
            j = robot.model.joints[robot.joint_id(name)]
            jb = back.model.joints[back.model.getJointId(name)]
            q[jb.idx_q: jb.idx_q + j.nq] = q_robot[j.idx_q: j.idx_q + j.nq]
        worst = max([worst] + [e.worst for e in loop_errors(back.model, data, back.loops, q)])
    return worst
