"""Analytic kinematics of the parallel tripod (seed 000): the public API in one namespace.

Conventions:
    * Base frame: origin at the base centre O; the legs are placed at the angles ``eta_K`` about the x axis.
      At the home pose the platform centre is E = (-L, 0, 0) with ``L = d sqrt(2 (1 - cos alpha))`` (eq 18).
    * Leg K (joints ``K_q1..K_q4``, ``eta = eta_K``), with ``P(eta) = Rx(eta) Rz(pi)``::

          T_K = P(eta) Rz(q1) Ry(q2) [Tr(0, d, 0) Rx(-alpha) Tr(0, -d, 0)] Ry(q3) Rz(-q4) Rx(pi - eta)

    * Platform orientation ``R = Rz(alpha_z) Ry(alpha_y) Rx(alpha_x)`` (eq 5) with
      ``alpha_x = atan2(s_y s_z, c_y + c_z)`` (eq 15, two-argument form: see :func:`alpha_x`).
    * ``ik(target)``: target (..., 2) = (alpha_y, alpha_z) -> motors (..., 3) = (q_A1, q_B1, q_C1);
      ``fk(q)``: motors (..., 3) -> (..., 2); ``jacobian(target)``: A_u = d motors / d target (..., 3, 2).
    * Joint vectors of the whole mechanism (:func:`ik_joints`) are ordered A_q1..A_q4, B_q1..B_q4, C_q1..C_q4 (the
      Pinocchio order). Branch: q_K2 in (0, pi), q_K3 = q_K2, q_K4 = q_K1 (the constant-velocity assembly).
    * Angles in radians, lengths in metres. A single input raises on failure, a batch returns NaN where an item
      fails (``return_mask=True`` adds the mask).

The implementation, by concept: :mod:`.geometry` (``Geometry``), :mod:`.legs` (open-chain legs, eqs 10-12),
:mod:`.platform` (the platform's pose, eqs 5, 15, 64), :mod:`.closure` (the kernels of eqs 98, 102, 103-105),
:mod:`.inverse` (``ik``, ``ik_all``, ``ik_joints``, ``jacobian``), :mod:`.forward_kernels` and :mod:`.forward`
(``fk``), :mod:`.reachable` (``workspace``).
"""

from __future__ import annotations

from ._common import DET_GUARD, GAIN_GUARD, HOME_MODE, LEGS, MODES
from .forward import FKInfo, fk
from .geometry import ALPHA, ETA, D, Geometry
from .inverse import ik, ik_all, ik_joints, jacobian
from .legs import leg_transform, leg_transform_cv
from .platform import alpha_x, orientation_from_axis, platform_axis, platform_position, platform_rotation
from .reachable import Workspace, workspace

__all__ = [
    "Geometry",
    "LEGS",
    "ETA",
    "D",
    "ALPHA",
    "MODES",
    "HOME_MODE",
    "DET_GUARD",
    "GAIN_GUARD",
    "leg_transform",
    "leg_transform_cv",
    "alpha_x",
    "platform_rotation",
    "platform_position",
    "platform_axis",
    "orientation_from_axis",
    "ik",
    "ik_all",
    "ik_joints",
    "jacobian",
    "fk",
    "FKInfo",
    "workspace",
    "Workspace",
]
