"""The wheel-leg's ground model (:func:`ground_model`, found by :func:`legkin.mjcf.ground.ground_model`).

Contact geometry: the tyre (:mod:`.tyre`: the pitch curve swept by a disk of radius ``r`` = 0.0345 m, extruded over
the width T) as cylinders of radius ``r`` and length T whose axes are the leg-plane normal, centred on the pitch
arcs of the four rim links (:data:`.tyre.PIECE_LINKS`) at most ``step`` apart, both ends of every arc included
(once where two arcs meet: :data:`_ARCS`).
The union of these cylinders is the swept tyre sampled along the pitch curve: it is exact at the samples, the
caps at the tips and the fillets at the hinges (those are the end cylinders), and between two samples it lies
inside the true surface by at most ``R (1 - cos(phi/2))``, phi the angle between two neighbours on the pitch circle
of radius R (2.0e-5 m for the default 4 mm), and its lowest point is off legkin's by up to half the spacing along
the ground (1.99e-3 m measured; docs/mujoco.md has the table of scripts/mujoco_tyre_fit.py).
The arcs are read from the URDF's frames (centre U or L, ends H, F, G) at the reference pose.

Predicted contacts: :func:`.ground.ground_contact` per leg; holding them: :func:`.stance.stance_ik`; rolling:
every leg's beta turned (:func:`.linkage.motor_angles`: phi_L and phi_R together).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from ..mjcf.ground import ContactGeom, GroundModel
from .configuration import configuration
from .geometry import LEGS, THETA_MAX, THETA_MIN, TYRE_THICKNESS
from .ground import ground_contact
from .linkage import theta_beta
from .stance import stance_ik, stance_ik_all
from .tyre import PIECE_LINKS, tyre_pieces

__all__ = ["ground_model", "WheelGround", "TYRE_STEP", "TIMESTEP"]

#: Largest distance (m) between two tyre cylinders along the pitch curve (module docstring): 4 mm keeps MuJoCo's
#: lowest point within 2 mm (half the spacing) of legkin's along the ground and 2e-5 m in height
#: (scripts/mujoco_tyre_fit.py; 8 mm: 3.96e-3 m and 7.8e-5 m, and a loaded centre of pressure 3.1e-3 m off).
TYRE_STEP = 0.004
#: The export's time step (s): the squat's real-time factor 9.0 at 1 ms, 11.8 at 1.5 ms, 15.6 at 2 ms (one core,
#: CPU time), every row within its tolerance at each (deepest penetration 1.3e-4, 2.4e-4, 8.1e-4 m of the 1e-3 m
#: allowed; roll 3.6e-3, 3.4e-3, 3.3e-3 of 0.02; squat slip 3.4e-4, 3.5e-4, 4.5e-4 m of 2e-3): 1.5 ms keeps
#: the penetration a quarter of its tolerance.
TIMESTEP = 1.5e-3
#: |gamma| (rad) under which a tyre counts as flat across its width (:meth:`WheelGround.contacts`).
_LEVEL = 1e-3
#: The pitch arcs of a leg: (rim link, centre frame, first end, second end), ``<leg>_`` omitted; the lower rims'
#: hinge end F is their link frame. Where two arcs meet (the hinges F_L, F_R; the toe G = G_cut) one cylinder is
#: exported, on the first arc: the coincident pair doubled those contacts (16 in the squat, 12 without) and
#: measured (scripts/mujoco_tyre_fit.py rows unchanged; 1.5 ms step) squat 13.6 -> 15.9 x real time, stand
#: centre of pressure 6.4e-4 -> 5.9e-5 m from legkin's, squat slip 3.5e-4 -> 6.6e-4 m, roll 3.4e-3 -> 3.1e-3.
_ARCS = (
    ("rim_upper_L", "U_L", "H_L", "F_L"),
    ("rim_lower_L", "L_L", "rim_lower_L", "G"),
    ("rim_lower_R", "L_R", "rim_lower_R", "G_cut"),
    ("rim_upper_R", "U_R", "H_R", "F_R"),
)


def _rotation_z(axis: np.ndarray) -> np.ndarray:
    """A rotation whose third column is the unit ``axis``."""
    z = axis / np.linalg.norm(axis)
    x = np.cross([0.0, 1.0, 0.0] if abs(z[1]) < 0.9 else [1.0, 0.0, 0.0], z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


class WheelGround(GroundModel):
    """The wheel-leg's tyres, contacts, stance IK and rolling (module docstring).

    Args:
        robot: ``legkin.load("wheel_leg", floating=True)``.
        step: largest distance (m) between tyre cylinders along the pitch curve.
    """

    def __init__(self, robot: Any, step: float = TYRE_STEP) -> None:
        self.robot, self.step = robot, float(step)
        self.geometry = robot.geometry
        self.rolling_radius = self.geometry.R + TYRE_THICKNESS
        self.line_half_width = 0.5 * self.geometry.T
        self.rolls_sideways = False
        self.timestep = TIMESTEP
        self.stand_angle = 0.0
        self.geoms()  # sets stand_angle
        self.squat_pose = "leg"  # theta = 160 deg: the reference pose ("wheel") cannot go 5 cm lower
        self.squat_start = 0.02  # the leg pose is at full stretch, where d theta / d height is unbounded
        self.collision_skip = frozenset(
            g.name for g in robot.collision_model.geometryObjects if "_rim_" in g.name
        )

    def leg_q(self, q: np.ndarray) -> np.ndarray:
        """(4, 3) (theta, beta, gamma) of the legs (:data:`LEGS` order) in ``q``; theta clipped to its range (a
        simulated wheel closes a few 1e-4 rad past 17 deg under load)."""
        r = self.robot
        out = np.empty((4, 3))
        for k, leg in enumerate(LEGS):
            th, be = theta_beta(q[r.idx_q(f"{leg}_phi_L")], q[r.idx_q(f"{leg}_phi_R")])
            out[k] = float(th), float(be), q[r.idx_q(f"{leg}_abad")]
        out[:, 0] = np.clip(out[:, 0], THETA_MIN, THETA_MAX)
        return out

    def _q(self, q: np.ndarray, leg_q: np.ndarray) -> np.ndarray:
        out = configuration(self.robot, leg_q)
        out[:7] = q[:7]
        return out

    def geoms(self) -> list[ContactGeom]:
        """The tyre cylinders of every leg (module docstring)."""
        model = self.robot.model
        data = model.createData()
        pin.framesForwardKinematics(model, data, self.robot.q0)
        half = 0.5 * self.geometry.T
        out = []
        for leg in LEGS:
            for link, centre, a, b in _ARCS:
                fid = model.getFrameId(f"{leg}_{link}")
                joint = model.frames[fid].parentJoint
                to_joint = data.oMi[joint].inverse()
                c, pa, pb = (to_joint.act(data.oMf[model.getFrameId(f"{leg}_{n}")].translation) for n in (centre, a, b))
                u, v = pa - c, pb - c
                normal = np.cross(u, v)
                span = float(np.arctan2(np.linalg.norm(normal), u @ v))
                radius = float(np.linalg.norm(u))
                rot = _rotation_z(normal)
                n = max(1, int(np.ceil(span * radius / self.step)))
                if link == "rim_lower_L":
                    self.stand_angle = 0.5 * span / n  # the contact between two cylinders: the worst case
                first, last = (1, n - 1) if link == "rim_lower_R" else (1, n) if link == "rim_lower_L" else (0, n)
                for i in range(first, last + 1):  # a hinge's or the toe's cylinder once (_ARCS)
                    p = c + pin.AngleAxis(span * i / n, normal / np.linalg.norm(normal)).matrix() @ u
                    out.append(ContactGeom(f"{leg}_{link}_tyre{i}", joint, "cylinder", (TYRE_THICKNESS, half),
                                           pin.SE3(rot, p)))
        return out

    def contacts(self, q: np.ndarray) -> np.ndarray:
        """:func:`.ground.ground_contact` of every leg (robot frame); where the tyre lies flat across its width
        (|gamma| < :data:`_LEVEL`) the centre of that line contact (the lowest point is then an edge only by a
        tilt of under 4e-5 m across the width, which a loaded contact does not resolve)."""
        lq = self.leg_q(q)
        out = []
        for k, leg in enumerate(LEGS):
            gc = ground_contact(lq[k], leg, geometry=self.geometry)
            flat = abs(lq[k, 2]) < _LEVEL
            out.append(gc.point - (float(gc.w) if flat else 0.0) * np.array([0.0, 1.0, 0.0]))  # z_L = y_R at gamma 0
        return np.array(out)

    def contact_frames(self, q: np.ndarray) -> list[tuple[tuple[str, ...], float]]:
        """The rim links carrying each leg's ground contact (:data:`.tyre.PIECE_LINKS` of its piece: both lower
        rims for the toe fillet about G) and the radius of that tyre piece."""
        lq = self.leg_q(q)
        out = []
        for k, leg in enumerate(LEGS):
            gc = ground_contact(lq[k], leg, geometry=self.geometry)
            radius = tyre_pieces(lq[k, 0], lq[k, 1], geometry=self.geometry).radius[int(gc.piece)]
            links = dict.fromkeys(PIECE_LINKS[str(gc.piece_name)])
            out.append((tuple(f"{leg}_{n}" for n in links), float(radius)))
        return out

    def hold(self, q: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """Per leg, the :func:`.stance.stance_ik_all` solution (in the joint limits) whose ABAD angle gamma is
        nearest to its value in ``q``, then nearest in (theta, beta): the tyres keep their tilt (level stays
        level). Plain nearest (:func:`.stance.stance_ik` with ``q_near``) would rather tilt a fully stretched leg
        (theta = 160 deg) by 0.05 rad than bend it, putting the contact on the tyre's edge."""
        lq = self.leg_q(q)
        new = np.empty((4, 3))
        for k, (leg, t) in enumerate(zip(LEGS, targets)):
            sols = stance_ik_all(np.asarray(t, dtype=float), leg, geometry=self.geometry)
            sols = sols[np.all(np.isfinite(sols), axis=1)]
            if not len(sols):
                stance_ik(np.asarray(t, dtype=float), leg, geometry=self.geometry)  # raises why
            d = np.abs(sols - lq[k])
            new[k] = sols[np.lexsort((d[:, :2].max(axis=1), np.round(d[:, 2], 9)))[0]]
        return self._q(q, new)

    def roll(self, q: np.ndarray, angle: float) -> np.ndarray:
        """Every leg's beta increased by ``angle`` (rad)."""
        lq = self.leg_q(q)
        lq[:, 1] += angle
        return self._q(q, lq)


def ground_model(robot: Any, step: float = TYRE_STEP) -> WheelGround:
    """The :class:`WheelGround` of a floating wheel-leg.

    Args:
        robot: ``legkin.load("wheel_leg", floating=True)``.
        step: largest distance (m) between tyre cylinders along the pitch curve.
    """
    return WheelGround(robot, step)


def tyre_contact_errors(mech: Any, leg_q: np.ndarray, leg: str = "FL") -> np.ndarray:
    """MuJoCo's tyre against :func:`.ground.ground_contact` at the leg angles ``leg_q`` (n, 3).

    For each row, the other legs stay in the reference pose, the base level at the origin; MuJoCo's smallest
    distance (``mj_geomDistance``) from the floor plane lowered 1 m to the leg's tyre cylinders gives the tyre's
    lowest height and the point where it is reached.

    Args:
        mech: :func:`legkin.mjcf.floating.load_ground` of the wheel-leg.
        leg_q: (n, 3) (theta, beta, gamma) of ``leg``.
        leg: the leg.

    Returns:
        (n, 2): MuJoCo's lowest height - legkin's (m; >= 0: the cylinders lie inside the tyre), and the
        horizontal distance between the two lowest points along the leg's x (m; the lateral coordinate of a flat
        tyre's line contact is arbitrary and left out).
    """
    import mujoco

    ground: WheelGround = mech.ground
    robot = mech.robot
    floor = mech.model.geom("floor").id
    geoms = [g for g in range(mech.model.ngeom)
             if str(mech.model.geom(g).name).startswith(f"{leg}_rim_") and "_tyre" in str(mech.model.geom(g).name)]
    k = LEGS.index(leg)
    out = np.empty((len(leg_q), 2))
    fromto = np.zeros(6)
    for i, lq in enumerate(np.asarray(leg_q, dtype=float)):
        all_q = ground.leg_q(robot.q0)
        all_q[k] = lq
        q = ground._q(robot.q0, all_q)
        q[:3] = 0.0
        mech.data.qpos[:] = mech.qpos(q)
        mech.data.qpos[2] = 1.0  # the floor 1 m below the base
        mujoco.mj_forward(mech.model, mech.data)
        best, point = np.inf, np.zeros(3)
        for g in geoms:
            dist = mujoco.mj_geomDistance(mech.model, mech.data, floor, g, 2.0, fromto)
            if dist < best:
                best, point = dist, fromto[3:].copy()
        want = ground_contact(lq, leg, geometry=ground.geometry).point + np.array([0.0, 0.0, 1.0])
        out[i] = best - want[2], point[0] - want[0]
    return out
