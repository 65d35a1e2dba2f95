"""Registry entry of the wheel-leg robot (Corgi leg-wheel quadruped, seed 001) and its rim meshes."""

from __future__ import annotations

import math
import struct

import numpy as np

from .._registry import ModelSpec, Param

#: The tyre thickness (m), one constant for one surface: the tyre surface of :mod:`legkin.wheel_leg.tyre` is
#: the pitch curve (radius R) offset by it; it is the foot radius minus the pitch radius of the seed's rim formula
#: (0.02225 + 0.01225 m: R + 0.0345 = 0.1345 m) and the outer radius of the rim meshes (R + TYRE_THICKNESS).
TYRE_THICKNESS = 0.0345

LEGS = ("FL", "FR", "RR", "RL")

#: Rim section of the visual/collision meshes: inner radius 0.9 R, outer radius R + TYRE_THICKNESS (0.0345 m,
#: the tyre surface of :mod:`.tyre`).
RIM_INNER = 0.9


SPEC = ModelSpec(
    name="wheel_leg",
    title="Corgi leg-wheel quadruped: closed-chain leg linkages (4 loops per leg), rim contact IK",
    seed="001",
    params={
        "R": Param(0.1, "wheel pitch radius; every linkage length scales with it (m)", 0.0, 1.0, low_open=True),
        "L_body": Param(0.51, "wheel base: front to rear module origins (m)", 0.0, 5.0, low_open=True),
        "W_body": Param(0.24, "hip-to-hip width: left to right module origins (m)", 0.0, 5.0, low_open=True),
        "chassis_length": Param(0.694, "chassis box length (m)", 0.0, 5.0, low_open=True),
        "chassis_width": Param(0.352, "chassis box width (m)", 0.0, 5.0, low_open=True),
        "chassis_height": Param(0.138, "chassis box height (m)", 0.0, 5.0, low_open=True),
        "d_abad": Param(0.057166, "height of the module (ABAD) origins above the robot frame (m)", 0.0, 1.0,
                        low_open=True),
        "d_wheel": Param(0.091675, "offset of the leg plane from the module origin, outward (m)", 0.0, 1.0,
                         low_open=True),
        "T": Param(0.04, "rim thickness; contact coordinate w in [-T/2, T/2] (m)", 0.0, 0.5, low_open=True),
    },
    # The two coaxial motors of each leg and its ABAD motor (all motor driven).
    actuated_joints=tuple(f"{leg}_{j}" for leg in LEGS for j in ("abad", "phi_L", "phi_R")),
    floating=True,
    reference_pose="wheel",
    yardstick_frame="FL_rim_upper_L",  # the bench's Pinocchio yardstick calls (legkin.bench)
)


def annular_sector(r1: float, r2: float, half: float, thickness: float, segments: int) -> np.ndarray:
    """Triangles (n, 3, 3) of a closed annular-sector prism: radii r1 < r2, angles [-half, half] about
    +x, z in [-thickness/2, thickness/2]; counter-clockwise seen from outside."""
    a = np.linspace(-half, half, segments + 1)
    c, s = np.cos(a), np.sin(a)
    h = thickness / 2

    def ring(r, z):
        return np.stack([r * c, r * s, np.full_like(a, z)], -1)

    ib, it, ob, ot = ring(r1, -h), ring(r1, h), ring(r2, -h), ring(r2, h)
    tris = []
    for k in range(segments):
        j = k + 1
        tris += [(ob[k], ob[j], ot[j]), (ob[k], ot[j], ot[k])]  # outer face
        tris += [(ib[k], it[j], ib[j]), (ib[k], it[k], it[j])]  # inner face
        tris += [(it[k], ot[k], ot[j]), (it[k], ot[j], it[j])]  # top
        tris += [(ib[k], ob[j], ob[k]), (ib[k], ib[j], ob[j])]  # bottom
    e = segments
    tris += [(ib[0], ob[0], ot[0]), (ib[0], ot[0], it[0])]  # end at -half
    tris += [(ib[e], ot[e], ob[e]), (ib[e], it[e], ot[e])]  # end at +half
    return np.array(tris, dtype=float)


def stl_bytes(triangles: np.ndarray, name: str) -> bytes:
    """Binary STL with a fixed header (no timestamp): byte-deterministic."""
    tri = np.asarray(triangles, dtype=np.float64)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    rec = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"], rec["v"] = n, tri
    header = f"legkin {name}".encode()[:80].ljust(80, b" ")
    return header + struct.pack("<I", len(tri)) + rec.tobytes()


def rim_meshes(args: dict) -> dict[str, bytes]:
    """The two rim-arc meshes for the xacro arguments ``args`` (paths relative to ``urdf/``).

    Upper rim: 130 deg arc, lower rim: 50 deg arc, both centred on the arc centre and symmetric about +x
    (the URDF rotates them into place); section from ``0.9 R`` to ``R + TYRE_THICKNESS`` (0.0345 m), thickness ``T``.
    """
    R, T = float(args["R"]), float(args["T"])
    r1, r2 = RIM_INNER * R, R + TYRE_THICKNESS
    out = {}
    for name, deg, seg in (("rim_upper", 130.0, 52), ("rim_lower", 50.0, 20)):
        tris = annular_sector(r1, r2, math.radians(deg) / 2, T, seg)
        out[f"meshes/wheel_leg_{name}.stl"] = stl_bytes(tris, f"wheel_leg {name} R={R!r} T={T!r}")
    return out


#: The generated files beside the URDF (found by the registry rule: ``legkin.<name>.spec.assets``).
assets = rim_meshes
