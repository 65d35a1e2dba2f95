"""Ground scenarios of a floating mechanism (or a fixed one pressing) in MuJoCo, measured against legkin
(:func:`run_scenario`).

* ``stand``: dropped from ``drop`` (1 cm) above its standing height in a pose, after ``seconds`` (2 s): the base
  height against legkin's prediction (:meth:`~legkin.mjcf.ground.GroundModel.standing_height`), each centre of
  pressure against legkin's contact point at MuJoCo's configuration, and the deepest penetration.
* ``roll`` (wheels only): after 0.5 s standing, every wheel turned by ``angle`` in ``seconds``; the base travel
  against ``rolling_radius x angle`` (relative error).
* ``squat``: after 0.5 s standing, the base lowered by ``depth`` (5 cm) and raised back (a cosine), the joints
  from legkin's IK holding the contacts on their ground points (:meth:`~legkin.mjcf.ground.GroundModel.hold`);
  the slip (largest horizontal drift of a centre of pressure) and the base height against the commanded one.
* ``press`` (a fixed mechanism only, :attr:`~legkin.mjcf.ground.GroundModel.fixed_base`: the hybrid leg): the
  foot on the floor under it, its IK target moved 5 mm into the floor; the centre of pressure against legkin's
  contact at MuJoCo's configuration, and the deepest penetration (no feedforward, no integral term).

The controller is the export's position actuators with an offset holding the weight: where the ground model
knows the static joint torques (:meth:`~legkin.mjcf.ground.GroundModel.static_torques`: legs), ``tau / kp`` is
added to every target (feedforward); otherwise (the wheel-leg, whose loops carry the load) an integral term on
each actuator's error (time constant 0.5 s) finds it. Either removes the static sag of the actuators under the
body's weight (the pose is the one legkin predicts for, not that pose minus a sag). Each figure is a
:class:`legkin._checkkit.CheckResult` row; the result also carries the real-time factor (simulated / CPU seconds,
one core) and optional frames.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..errors import InvalidParameterError
from ._base import _mujoco
from .floating import GroundMechanism, load_ground
from .ground import HELD_TILT_DAMPING

if TYPE_CHECKING:  # pragma: no cover
    from .._checkkit import CheckResult

__all__ = ["SCENARIOS", "ScenarioResult", "run_scenario", "TOL_HEIGHT", "TOL_CONTACT", "TOL_PENETRATION",
           "TOL_ROLL", "TOL_SLIP"]

SCENARIOS = ("stand", "roll", "squat", "press")
#: Tolerances of the rows (the figures measured on each model: docs/mujoco.md). Base height (m): after the stand
#: against legkin's prediction, after the squat against the start.
TOL_HEIGHT = 2e-3
#: Centre of pressure against legkin's contact point (or line) at MuJoCo's configuration (m).
TOL_CONTACT = 2e-3
#: Deepest penetration over the run (m).
TOL_PENETRATION = 1e-3
#: Roll: base travel / (rolling radius x rim angle) - 1 (relative).
TOL_ROLL = 0.02
#: Squat: slip of each contact, the largest horizontal drift of its centre of pressure (m).
TOL_SLIP = 2e-3


@dataclass
class ScenarioResult:
    """What a scenario measured.

    Attributes:
        scenario, model: names.
        rows: the figures as check rows (error, tolerance, pass).
        simulated: simulated time (s); wall: CPU time of the stepping and the controller (s; one core: MuJoCo is
            single-threaded, and CPU time does not count the other processes of a shared machine); rtf:
            simulated / wall, the real-time factor on one core.
        frames: ``qpos`` every ``1 / fps`` s when recorded, else empty.
    """

    scenario: str
    model: str
    rows: list["CheckResult"]
    simulated: float
    wall: float
    rtf: float
    frames: list[np.ndarray] = field(default_factory=list, repr=False)


# ----------------------------------------------------------------- timing of the runs
#: Integral time constant (s) of the actuators' integral term.
_TAU_I = 0.5
#: Steps between two samples (:meth:`_Runner._sample`: slip tracking, frames): 5 ms at the ground
#: export's 1 ms step; the slip over 2 s did not change (3.442e-4 m, wheel-leg squat) from 2 steps to 5.
_SAMPLE_EVERY = 5
#: Seconds of holding after the squat before the base height is compared with the start. go2 is 1.99e-3 m lower
#: after 1 s and still 1.94e-3 m after 2 s: not the integral term settling but the feet, which slid 0.7 mm and
#: stay where friction holds them (the same joint angles on a slightly different stance).
_SETTLE_AFTER = 1.0
#: Seconds over which the feedforward comes in once every contact touches (in the air it would bend the legs
#: away from the pose they land in: anymal's feet then splayed and stood 3 mm high).
_RAMP = 0.05
#: Seconds of standing before ``roll`` and ``squat`` start moving.
_SETTLE = 0.5


class _Runner:
    """Steps a :class:`GroundMechanism` with its actuators holding the targets (feedforward or integral term,
    module docstring), timing the steps (CPU time), tracking penetration and slip, recording frames."""

    def __init__(self, mech: GroundMechanism, fps: float | None) -> None:
        self.mujoco = _mujoco()
        self.mech, self.fps = mech, fps
        self.adr = mech.model.jnt_qposadr[mech.model.actuator_trnid[:, 0]]
        self.integral = np.zeros(mech.model.nu)
        self.integrate = True
        self.feedforward = np.zeros(mech.model.nu)
        self.feet = 0
        self.landed = 0.0  # the feedforward's share: 0 in the air, ramped to 1 over _RAMP s once every foot touches
        self.target = np.zeros(mech.model.nu)
        self.wall, self.time, self.steps = 0.0, 0.0, 0
        self.frames: list[np.ndarray] = []
        self.penetration = 0.0
        self.slip_points: np.ndarray | None = None  # world points grouping the contacts whose slip is tracked
        self.slip = np.zeros((0, 2))
        self.slip_max = np.zeros(0)
        self._material: dict[int, list[tuple[float, int, np.ndarray, np.ndarray]]] = {}

    def start(self, key: int, drop: float, q: np.ndarray | None = None) -> None:
        """Keyframe ``key`` (or configuration ``q`` standing on the floor), the base raised by ``drop`` (m)."""
        m, d = self.mech.model, self.mech.data
        self.mujoco.mj_resetDataKeyframe(m, d, key)
        if q is not None:
            d.qpos[:] = self.mech.qpos(q)
            d.qpos[2] = self.mech.ground.standing_height(q)
            d.ctrl[:] = self.mech.ctrl(q)
        d.qpos[2] += drop
        self.landed = 0.0 if drop > 0.0 else 1.0  # standing on the floor from the start: the full feedforward
        self.target = d.ctrl.copy()
        tau = self.mech.ground.static_torques(self.mech.q(d.qpos))
        if tau is not None:  # a fixed offset holding the weight (feedforward) instead of the integral term
            vadr = m.jnt_dofadr[m.actuator_trnid[:, 0]]
            gain = m.actuator_gainprm[:, 0]  # 0 for a joint carrying no inertia (romeo's fingers): no offset
            self.feedforward = np.divide(tau[vadr], gain, out=np.zeros(m.nu), where=gain > 0.0)
            self.integrate = False
        self.mujoco.mj_forward(m, d)

    def run(self, seconds: float, target: Callable[[float], np.ndarray] | None = None) -> None:
        """Step ``seconds``, the actuated joints' targets from ``target(time)`` (default: kept)."""
        m, d = self.mech.model, self.mech.data
        dt = m.opt.timestep
        gain, adr, step = dt / _TAU_I if self.integrate else 0.0, self.adr, self.mujoco.mj_step
        if self.feet == 0:
            self.feet = len(self.mech.ground.contact_frames(self.mech.robot.q0))
        t0 = time.process_time()
        for _ in range(int(round(seconds / dt))):
            if target is not None:
                self.target = target(self.time)
            self.integral += gain * (self.target - d.qpos[adr])
            if self.landed < 1.0 and d.ncon >= self.feet:
                self.landed = min(1.0, self.landed + dt / _RAMP)
            d.ctrl[:] = self.target + self.integral + self.landed * self.feedforward
            if self.mech.ground.held_tilt:
                self._hold_tilt()
            step(m, d)
            self.time += dt
            self.steps += 1
            if d.ncon:
                self.penetration = max(self.penetration, -float(d.contact.dist[: d.ncon].min()))
            if self.steps % _SAMPLE_EVERY == 0:
                self._sample()
        self.wall += time.process_time() - t0

    def _hold_tilt(self) -> None:
        """The base's torque of :attr:`~legkin.mjcf.ground.GroundModel.held_tilt`: turning its z axis back to the
        vertical, damping its angular velocity about the horizontal axes (world frame; applied in the free
        joint's rotational coordinates, the base frame)."""
        d = self.mech.data
        k = self.mech.ground.held_tilt
        rot = d.xmat[self.mech.body_ids[1]].reshape(3, 3)
        omega = rot @ d.qvel[3:6]
        omega[2] = 0.0
        torque = k * np.cross(rot[:, 2], [0.0, 0.0, 1.0]) - k * HELD_TILT_DAMPING * omega
        d.qfrc_applied[3:6] = rot.T @ torque

    def _sample(self) -> None:
        """Every ``_SAMPLE_EVERY`` steps: the slip tracking, a video frame."""
        d = self.mech.data
        if self.slip_points is not None:
            self._track_slip()
        if self.fps and (len(self.frames) == 0 or self.time >= len(self.frames) / self.fps):
            self.frames.append(d.qpos.copy())

    def track_slip(self, points: np.ndarray) -> None:
        """Start tracking the slip of the contacts nearest each world point (:meth:`_track_slip`)."""
        self.slip_points = np.asarray(points, dtype=float)
        self.slip = np.zeros((len(points), 2))
        self.slip_max = np.zeros(len(points))
        self._material = {}
        self._track_slip()

    def _track_slip(self) -> None:
        """Every ``_SAMPLE_EVERY`` steps: move the material points (robot-body points) under the previous call's
        contacts with their bodies and add each group's force-weighted mean horizontal displacement to its slip (a
        rolling contact's material point moves only to second order over the interval; the two halves of the
        wheel-leg's toe, on two links turning opposite ways, slide opposite ways and cancel: the contact stays),
        then take the new contacts' material points."""
        d = self.mech.data
        assert self.slip_points is not None
        for k, points in self._material.items():
            total = sum(w for w, _, _, _ in points)
            if total <= 0.0:
                continue
            moved = sum(w * (d.xpos[b] + d.xmat[b].reshape(3, 3) @ loc - pos) for w, b, loc, pos in points)
            self.slip[k] += moved[:2] / total
            self.slip_max[k] = max(self.slip_max[k], float(np.linalg.norm(self.slip[k])))
        self._material = {}
        for k, fz, b, pos in self._contacts(self.slip_points):
            local = d.xmat[b].reshape(3, 3).T @ (pos - d.xpos[b])
            self._material.setdefault(k, []).append((fz, b, local, pos))

    def _contacts(self, points: np.ndarray) -> list[tuple[int, float, int, np.ndarray]]:
        """MuJoCo's contacts as ``(index of the nearest world point (horizontally), normal force (N), robot body,
        position)``."""
        m, d = self.mech.model, self.mech.data
        n = d.ncon
        if n == 0:
            return []
        contact = d.contact  # one view of the arrays (d.contact[i] builds a struct per call)
        pos = np.array(contact.pos[:n])
        bodies = m.geom_bodyid[np.asarray(contact.geom[:n])].max(axis=1)  # the floor is the world body 0
        nearest = np.argmin(np.linalg.norm(points[None, :, :2] - pos[:, None, :2], axis=2), axis=1)
        force = np.zeros(6)
        out = []
        for i in range(n):
            self.mujoco.mj_contactForce(m, d, i, force)
            out.append((int(nearest[i]), float(force[0]), int(bodies[i]), pos[i]))
        return out

    def pressure(self, points: np.ndarray) -> np.ndarray:
        """(k, 3) force-weighted centre of MuJoCo's contacts nearest each world point (NaN: no contact)."""
        sums, weights = np.zeros((len(points), 3)), np.zeros(len(points))
        for k, fz, _, pos in self._contacts(points):
            sums[k] += fz * pos
            weights[k] += fz
        with np.errstate(invalid="ignore", divide="ignore"):
            return sums / weights[:, None]

    def predicted(self) -> np.ndarray:
        """legkin's contact points at MuJoCo's configuration, in the world (MuJoCo's base pose)."""
        d = self.mech.data
        q = self.mech.q(d.qpos)
        if self.mech.ground.fixed_base:  # the base frame is the world's
            return self.mech.ground.contacts(q)
        rot = d.xmat[self.mech.body_ids[1]].reshape(3, 3)
        return self.mech.ground.contacts(q) @ rot.T + d.qpos[:3]


def _interpolator(t0: float, ticks: np.ndarray, values: list[np.ndarray]) -> Callable[[float], np.ndarray]:
    """The actuator targets at time t: ``values`` (at the evenly spaced ``ticks`` after ``t0``) interpolated
    linearly, the last one after the end."""
    v = np.array(values)
    step = float(ticks[1] - ticks[0])

    def target(t: float) -> np.ndarray:
        x = min(max((t - t0) / step, 0.0), len(ticks) - 1.0)
        i = min(int(x), len(ticks) - 2)
        return v[i] + (x - i) * (v[i + 1] - v[i])

    return target


def _key(mech: GroundMechanism, pose: str | None) -> tuple[int, np.ndarray]:
    mujoco = _mujoco()
    robot = mech.robot
    pose = robot.spec.reference_pose if pose is None else pose
    key = mujoco.mj_name2id(mech.model, mujoco.mjtObj.mjOBJ_KEY, pose) if pose else 0  # g1: no SRDF, key 0 is q0
    if key < 0:
        raise InvalidParameterError(f"{robot.name} has no pose {pose!r}; poses: {', '.join(robot.poses)}")
    return key, mech.ground.pose({**robot.poses, robot.spec.reference_pose: robot.q0}[pose])


def _label(mech: GroundMechanism) -> str:
    """The robot's name in its rows, saying when its base is held (:attr:`.GroundModel.held_tilt`)."""
    return f"{mech.robot.name} (base held in roll and pitch)" if mech.ground.held_tilt else mech.robot.name


def _stand(run: _Runner, pose: str | None, seconds: float, drop: float) -> list["CheckResult"]:
    from .._checkkit import compare

    mech = run.mech
    key, q = _key(mech, pose)
    if mech.ground.stand_angle:
        q = mech.ground.roll(q, mech.ground.stand_angle)
    run.start(key, drop, q)
    run.run(seconds)
    height = mech.ground.standing_height(q)
    pred = run.predicted()
    cop = run.pressure(pred)
    name = _label(mech)
    gap = cop - pred
    gap[:, 1] = np.sign(gap[:, 1]) * np.maximum(np.abs(gap[:, 1]) - mech.ground.line_half_width, 0.0)
    return [
        compare(f"{name} stand: dropped {drop:g} m, base height after {seconds:g} s - legkin's (m)",
                np.array([run.mech.data.qpos[2] - height]), TOL_HEIGHT),
        compare(f"{name} stand: centre of pressure - legkin's contact point (or line), per contact (m)",
                np.linalg.norm(gap, axis=1), TOL_CONTACT),
        compare(f"{name} stand: deepest penetration over the run (m)", np.array([run.penetration]), TOL_PENETRATION),
    ]


def _roll(run: _Runner, pose: str | None, seconds: float, angle: float) -> list["CheckResult"]:
    from .._checkkit import compare

    mech = run.mech
    radius = mech.ground.rolling_radius
    if radius is None:
        raise InvalidParameterError(f"{mech.robot.name} has no wheels: scenarios stand and squat only")
    key, q = _key(mech, pose)
    run.start(key, 0.0)
    run.run(_SETTLE)
    x0, t0 = mech.data.qpos[:2].copy(), run.time
    ticks = np.linspace(0.0, seconds, 201)
    target = _interpolator(t0, ticks, [mech.ctrl(mech.ground.roll(q, angle * t / seconds)) for t in ticks])

    run.run(seconds, target)
    run.run(0.3, target)
    travel = float(np.linalg.norm(mech.data.qpos[:2] - x0)) * np.sign(mech.data.qpos[0] - x0[0])
    want = radius * angle
    return [compare(f"{mech.robot.name} roll: rims turned {angle:g} rad, travel / (rolling radius {radius:g} m "
                    f"x angle) - 1", np.array([travel / want - 1.0]), TOL_ROLL)]


def _squat(run: _Runner, pose: str | None, seconds: float, depth: float) -> list["CheckResult"]:
    from .._checkkit import compare

    mech = run.mech
    key, q = _key(mech, pose)
    if mech.ground.squat_start > 0.0:  # start that far below the pose (the wheel-leg's full stretch)
        q = mech.ground.hold(q, mech.ground.contacts(q) + np.array([0.0, 0.0, mech.ground.squat_start]))
    run.start(key, 0.0, q)
    run.run(_SETTLE)
    base0 = mech.data.qpos[:3].copy()
    ground = mech.ground.contacts(q)  # base frame, at the standing height
    t0 = run.time
    slip = []

    def lowered(t: float) -> float:
        return 0.5 * depth * (1.0 - np.cos(2.0 * np.pi * min(1.0, (t - t0) / seconds)))

    ticks = np.linspace(0.0, seconds, 201)  # legkin's IK every 10 ms of a 2 s squat, interpolated between
    target = _interpolator(t0, ticks, [mech.ctrl(mech.ground.hold_rolling(
        q, ground + np.array([0.0, 0.0, lowered(t0 + t)]))) for t in ticks])
    run.track_slip(run.predicted())

    for _ in range(20):
        run.run(seconds / 20, target)
        slip.append(run.slip_max.copy())
    run.run(_SETTLE_AFTER, target)
    name = _label(mech)
    return [
        compare(f"{name} squat: base {depth:g} m down and up in {seconds:g} s, slip of each contact (m)",
                np.array(slip), TOL_SLIP),
        compare(f"{name} squat: base height {_SETTLE_AFTER:g} s after - before (m)",
                np.array([mech.data.qpos[2] - base0[2]]), TOL_HEIGHT),
    ]


def _press(run: _Runner, pose: str | None, seconds: float, depth: float) -> list["CheckResult"]:
    """A fixed mechanism's foot on the floor under it (the reference pose), its IK target moved ``depth`` below the
    floor over 0.2 s and held: where it presses against legkin's contact, and the penetration."""
    from .._checkkit import compare

    mech = run.mech
    key, q = _key(mech, pose)
    run.start(key, 0.0)
    run.integrate = False  # an integral term would wind up against the floor
    run.run(_SETTLE)
    pressed = mech.ctrl(mech.ground.hold(q, mech.ground.contacts(q) - np.array([0.0, 0.0, depth])))
    run.run(seconds, _interpolator(run.time, np.array([0.0, 0.2]), [mech.ctrl(q), pressed]))
    pred = run.predicted()
    name = mech.robot.name
    return [
        compare(f"{name} press: foot commanded {depth:g} m into the floor, centre of pressure - legkin's contact at "
                "MuJoCo's motor angles (m)", np.linalg.norm(run.pressure(pred) - pred, axis=1), TOL_CONTACT),
        compare(f"{name} press: deepest penetration over the run (m)", np.array([run.penetration]), TOL_PENETRATION),
    ]


def run_scenario(model: "str | GroundMechanism", scenario: str, *, seconds: float = 2.0, pose: str | None = None,
                 fps: float | None = None, **options: Any) -> ScenarioResult:
    """Run one ground scenario (module docstring) and measure it.

    Args:
        model: a model name or a :class:`~legkin.mjcf.floating.GroundMechanism` (:func:`load_ground`).
        scenario: ``"stand"``, ``"roll"`` or ``"squat"``.
        seconds: the scenario's length (s): standing time, rolling time, squat period.
        pose: the SRDF pose to start from (default: the reference pose; the wheel-leg squats from ``"leg"``).
        fps: record ``qpos`` frames at this rate (for :func:`legkin.mjcf.record.write_video`).
        **options: :func:`~legkin.mjcf.floating.to_ground_mjcf` options (with a model name).

    Returns:
        :class:`ScenarioResult` (rows, real-time factor, frames).

    Raises:
        InvalidParameterError: an unknown scenario or pose, ``roll`` on a model without wheels.
    """
    if scenario not in SCENARIOS:
        raise InvalidParameterError(f"unknown scenario {scenario!r}; scenarios: {', '.join(SCENARIOS)}")
    mech = load_ground(model, **options) if isinstance(model, str) else model
    if (scenario == "press") != mech.ground.fixed_base:
        raise InvalidParameterError(f"{mech.robot.name}: scenario {scenario!r} is for "
                                    f"{'a fixed mechanism' if scenario == 'press' else 'a floating robot'}")
    if scenario == "squat" and mech.ground.no_squat:
        raise InvalidParameterError(f"{mech.robot.name} does not squat: {mech.ground.no_squat}")
    if scenario == "squat" and pose is None:
        pose = mech.ground.squat_pose
    run = _Runner(mech, fps)
    if scenario == "stand":
        rows = _stand(run, pose, seconds, 0.01)
    elif scenario == "roll":
        rows = _roll(run, pose, seconds, 2.0 * np.pi)
    elif scenario == "press":
        rows = _press(run, pose, seconds, 0.005)
    else:
        rows = _squat(run, pose, seconds, 0.05)
    return ScenarioResult(scenario, mech.robot.name, rows, run.time, run.wall, run.time / max(run.wall, 1e-9),
                          run.frames)


def ground_rows(name: str) -> list["CheckResult"]:
    """The ``legkin check`` rows of the ground scenarios of ``name``: ``stand``, ``roll`` (wheels) and ``squat``
    (unless the ground model says why not); ``press`` for a fixed mechanism (the hybrid leg); none for a model
    without a ground model."""
    from .ground import has_ground_model

    if not has_ground_model(name):
        return []
    mech = load_ground(name)
    if mech.ground.fixed_base:
        return run_scenario(mech, "press").rows
    rows: list["CheckResult"] = []
    for scenario in SCENARIOS[:3]:
        no_wheels = scenario == "roll" and mech.ground.rolling_radius is None
        if no_wheels or (scenario == "squat" and mech.ground.no_squat):
            continue
        rows += run_scenario(mech, scenario).rows
    return rows
