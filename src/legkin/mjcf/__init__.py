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

On the ground (docs/mujoco.md): :func:`load_ground` / :func:`to_ground_mjcf` export a floating model with contact
geometry from the mechanism's :class:`GroundModel` and a floor that collides; :func:`run_scenario` runs ``stand``,
``roll`` and ``squat`` and measures them against legkin (:func:`ground_rows`: their ``legkin check`` rows).
"""

from ._base import DEFAULTS, unavailable_reason
from .checks import (
    TOL_CLIP,
    TOL_EQUALITY,
    TOL_GRAVITY,
    TOL_PLACEMENT,
    check_rows,
    closed_configurations,
    drive_clip,
    equality_errors,
    hold_under_gravity,
    independent_actuated,
    passive_joints,
    placement_errors,
)
from .cli import add_export_command, run_export
from .floating import GROUND_DEFAULTS, GroundMechanism, load_ground, to_ground_mjcf
from .ground import ContactGeom, FootGround, GroundModel, ground_model
from .mechanism import MujocoMechanism, load_mujoco
from .render import render_png
from .scenarios import SCENARIOS, ScenarioResult, ground_rows, run_scenario
from .writer import to_mjcf

__all__ = [
    "DEFAULTS",
    "MujocoMechanism",
    "to_mjcf",
    "load_mujoco",
    "check_rows",
    "closed_configurations",
    "placement_errors",
    "equality_errors",
    "hold_under_gravity",
    "drive_clip",
    "independent_actuated",
    "passive_joints",
    "unavailable_reason",
    "render_png",
    "add_export_command",
    "run_export",
    "TOL_PLACEMENT",
    "TOL_EQUALITY",
    "TOL_GRAVITY",
    "TOL_CLIP",
    # on the ground (issue 28): docs/mujoco.md
    "GROUND_DEFAULTS",
    "GroundMechanism",
    "load_ground",
    "to_ground_mjcf",
    "GroundModel",
    "FootGround",
    "ContactGeom",
    "ground_model",
    "SCENARIOS",
    "ScenarioResult",
    "run_scenario",
    "ground_rows",
]
