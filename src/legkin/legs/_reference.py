"""Pinocchio's foot poses and Jacobians: the reference that the check rows of every leg (3- and 6-DOF) compare
with (:mod:`.checks`, :mod:`.checks6`)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["pinocchio_poses"]


def pinocchio_poses(model: Any, legs: dict, qs: np.ndarray, jacobians: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's foot poses and Jacobians, the reference of every leg's check rows.

    Args:
        model: the robot's ``pinocchio.Model``.
        legs: its legs (``Leg`` or ``Leg6``), by name.
        qs: configurations (N, nq) (rad, m).
        jacobians: also compute the Jacobians.

    Returns:
        The foot poses (N, L, 4, 4) in the world frame (m), and the LOCAL_WORLD_ALIGNED Jacobians (N, L, 6, dof)
        of each leg's columns (empty (0, L, 6, dof) without ``jacobians``).
    """
    import pinocchio as pin

    data = model.createData()
    fids = [model.getFrameId(leg.foot_frame) for leg in legs.values()]
    cols = [list(leg.idx_v) for leg in legs.values()]
    dof = len(cols[0])
    poses = np.empty((len(qs), len(fids), 4, 4))
    jac = np.empty((len(qs) if jacobians else 0, len(fids), 6, dof))
    for i, q in enumerate(qs):
        if jacobians:
            pin.computeJointJacobians(model, data, q)
        else:
            pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        for k, fid in enumerate(fids):
            poses[i, k] = data.oMf[fid].homogeneous
            if jacobians:
                jac[i, k] = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:, cols[k]]
    return poses, jac
