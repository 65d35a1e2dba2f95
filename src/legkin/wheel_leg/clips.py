"""Wheel-leg clips: every frame in closed form (loops closed by :func:`~.configuration.configuration`).

* ``transform``: all four legs from wheel mode to leg mode and back, beta = 0, base fixed.
* ``roll_and_step``: rolling in wheel mode, transforming to leg mode on the ground, then a crawl gait (one leg
  lifted and moved forward at a time), the stance tyres on the ground z = 0 (:func:`roll_and_step_plan`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._rotations import wrap
from . import kinematics as wl
from .configuration import configuration, uniform_configuration
from .geometry import _DEFAULT_GEOMETRY, LEGS, THETA0, TYRE_THICKNESS, Geometry, _geometry
from .ground import ground_contact
from .stance import stance_ik, stance_ik_all


def transform(robot, frames: int = 90) -> list[np.ndarray]:
    """Wheel mode (theta = 17 deg) to leg mode (theta = 160 deg) and back, beta = 0, all four legs.

    ``theta(t) = 17 deg + (160 deg - 17 deg) (1 - cos 2 pi t) / 2`` over one period (eased at both ends),
    so the clip loops seamlessly.
    """
    t = np.arange(frames) / frames
    theta = wl.THETA_MIN + (wl.THETA_MAX - wl.THETA_MIN) * 0.5 * (1.0 - np.cos(2.0 * math.pi * t))
    return list(uniform_configuration(robot, theta))


#: roll_and_step: leg opening of the leg-mode half (rad), step length (m), swing height (m), gait order.
THETA_LEG = math.radians(120.0)
STEP_LENGTH = 0.12
SWING_HEIGHT = 0.04
GAIT = ("RR", "FR", "RL", "FL")


class Plan(NamedTuple):
    """The motion of :func:`roll_and_step_plan`, per frame f.

    Attributes:
        leg_q: (F, 4, 3) (theta, beta, gamma) of the legs in :data:`~legkin.wheel_leg.LEGS` order.
        base: (F, 3) base position in the world (identity orientation); the ground is z = 0.
        stance: (F, 4) True where the leg is on the ground (its ground contact on z = 0).
        phase: (F,) "roll", "transform" or "step".
    """

    leg_q: np.ndarray
    base: np.ndarray
    stance: np.ndarray
    phase: np.ndarray


def _height(q: np.ndarray, geo: Geometry) -> float:
    """Base height putting the lowest of the four legs' ground contacts (leg q (4, 3), n = z) on z = 0."""
    return -min(float(ground_contact(q[k], leg, geometry=geo).point[2]) for k, leg in enumerate(LEGS))


def _solve(target: np.ndarray, leg: str, prev: np.ndarray, geo: Geometry) -> np.ndarray:
    """The stance IK solution of ``target`` in the leg plane (gamma = 0: the targets keep the lateral position of
    the gamma = 0 contacts) nearest ``prev``; else :func:`stance_ik`'s nearest (any gamma)."""
    sols = stance_ik_all(target, leg, limits=True, geometry=geo)
    planar = sols[np.abs(sols[:, 2]) <= 1e-9]
    if planar.shape[0] == 0:
        return stance_ik(target, leg, q_near=prev, geometry=geo)
    d = planar - prev
    d[:, 1:] = wrap(d[:, 1:])
    return planar[int(np.argmin(np.abs(d).max(axis=1)))]


def roll_and_step_plan(frames: int = 180, *, geometry: Geometry | None = None) -> Plan:
    """Roll in wheel mode, transform to leg mode, crawl: the world motion of a floating-base wheel-leg on z = 0.

    * **roll** (the first half of the frames): theta = 17 deg, gamma = 0, beta advancing over one turn
      (0 -> 2 pi) on every leg; the base moves forward by ``(R + r) dbeta`` (r = ``TYRE_THICKNESS``), so the tyre
      (a circle of radius R + r about O in wheel mode) rolls on z = 0 without slipping; base height from
      :func:`~legkin.wheel_leg.ground_contact` (R + r - d_abad).
    * **transform** (a sixth): theta 17 deg -> :data:`THETA_LEG` (eased), beta = gamma = 0, the base rising so that
      the lowest tyre points (the fillets about the toes G) stay on z = 0.
    * **step** (the rest, four equal swings): the crawl :data:`GAIT`, one leg at a time; the base moves forward
      :data:`STEP_LENGTH` / 4 per swing at constant height; the swinging leg's lowest tyre point goes
      :data:`STEP_LENGTH` forward along ``SWING_HEIGHT sin(pi s)``; the stance legs keep their contact points
      fixed on z = 0 (the tyre pivots about its toe fillet). Every leg by the stance IK
      (:func:`~legkin.wheel_leg.stance_ik_all`: of the solutions with gamma = 0, in the leg plane, the nearest to
      the previous frame: no branch jumps) on its target relative to the base.
    """
    geo = _DEFAULT_GEOMETRY if geometry is None else _geometry(geometry)
    n_roll = frames // 2
    n_trans = frames // 6
    n_swing = (frames - n_roll - n_trans) // 4
    if n_roll < 2 or n_trans < 2 or n_swing < 2:
        raise ValueError(f"roll_and_step needs at least 24 frames, got {frames}")
    rho = geo.R + TYRE_THICKNESS
    qs, base, stance, phase = [], [], [], []
    for k in range(n_roll):
        beta = 2.0 * math.pi * k / n_roll
        q = np.array([[THETA0, beta, 0.0]] * 4)
        qs.append(q)
        base.append([rho * beta, 0.0, _height(q, geo)])
        stance.append([True] * 4)
        phase.append("roll")
    x = rho * 2.0 * math.pi
    for k in range(n_trans):
        u = (k + 1) / n_trans
        theta = THETA0 + (THETA_LEG - THETA0) * 0.5 * (1.0 - math.cos(math.pi * u))
        q = np.array([[theta, 0.0, 0.0]] * 4)
        qs.append(q)
        base.append([x, 0.0, _height(q, geo)])
        stance.append([True] * 4)
        phase.append("transform")
    q = qs[-1].copy()
    b = np.array(base[-1])
    feet = {leg: b + ground_contact(q[k], leg, geometry=geo).point for k, leg in enumerate(LEGS)}
    for leg in GAIT:
        start = feet[leg].copy()
        b0 = b.copy()
        for j in range(n_swing):
            s = (j + 1) / n_swing  # the last frame of a swing has the foot down at its new place
            b = b0 + np.array([STEP_LENGTH / 4 * s, 0.0, 0.0])
            swing = start + np.array([STEP_LENGTH * s, 0.0, SWING_HEIGHT * math.sin(math.pi * s)])
            if j == n_swing - 1:
                swing = feet[leg] = start + np.array([STEP_LENGTH, 0.0, 0.0])
            new = q.copy()
            for k, name in enumerate(LEGS):
                target = (swing if name == leg else feet[name]) - b
                new[k] = _solve(target, name, q[k], geo)
            q = new
            qs.append(q)
            base.append(b.copy())
            stance.append([name != leg or j == n_swing - 1 for name in LEGS])
            phase.append("step")
    return Plan(np.array(qs), np.array(base), np.array(stance), np.array(phase))


def roll_and_step(robot, frames: int = 180) -> list[np.ndarray]:
    """:func:`roll_and_step_plan` as configurations of ``robot`` (every loop closed in closed form).

    A floating-base robot (``legkin.load("wheel_leg", floating=True)``) gets the plan's base motion (free flyer
    = base position, identity orientation): the stance tyres touch z = 0. A fixed-base robot (what
    ``legkin view wheel_leg --animate roll_and_step`` passes) shows the legs' motion relative to the body, its
    base at the origin: the stance contacts are then on the plane ``z = -base_z(t)`` of the body frame (the
    plan's base height: 0.077334 m while rolling, rising to the leg-mode height while transforming, constant
    while stepping), and the forward motion is not shown; the viewer's ground plane (at minus the SRDF
    reference pose's base height, 0.077334 m) is under the tyres in the rolling half.
    """
    plan = roll_and_step_plan(frames, geometry=Geometry.from_params(robot.params))
    q = configuration(robot, plan.leg_q)
    if robot.floating:
        i = robot.idx_q("root_joint")
        q[:, i:i + 3] = plan.base
        q[:, i + 3:i + 7] = (0.0, 0.0, 0.0, 1.0)
    return list(q)


ANIMATIONS = {"transform": transform, "roll_and_step": roll_and_step}
