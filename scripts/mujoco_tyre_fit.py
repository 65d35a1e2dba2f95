"""Measure the wheel-leg's MuJoCo tyre (cylinders on the pitch arcs, legkin.wheel_leg.sim) against legkin's tyre
(legkin.wheel_leg.ground_contact) for several cylinder spacings: the table of docs/mujoco.md.

    PYTHONPATH=src python scripts/mujoco_tyre_fit.py [--samples 300]

Two sets of leg angles (leg FL, seed 0): ``wheel``, theta = 17 deg and a random beta (the lowest point on a pitch
arc: the worst case of the sampling), and ``any``, theta, beta uniform and half of them with |gamma| <= 0.3 rad.
Columns: cylinders per leg, MuJoCo's lowest height - legkin's (min, max; >= 0: inside the tyre), the bound
``R (1 - cos(phi / 2))`` with phi the largest angle between two cylinders, and the largest distance along x
between the two lowest points, with the CPU real-time factor of 1 s standing (one core).
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

import legkin
from legkin.mjcf.floating import load_ground
from legkin.wheel_leg.sim import WheelGround, tyre_contact_errors


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=300)
    n = parser.parse_args().samples
    rng = np.random.default_rng(0)
    wheel = np.column_stack([np.full(n, np.radians(17.0)), rng.uniform(-np.pi, np.pi, n), np.zeros(n)])
    anyq = np.column_stack([rng.uniform(np.radians(17.0), np.radians(160.0), n), rng.uniform(-np.pi, np.pi, n),
                            np.where(np.arange(n) < n // 2, 0.0, rng.uniform(-0.3, 0.3, n))])
    robot = legkin.load("wheel_leg", floating=True)
    print("| step | cylinders per leg | set | height min (m) | height max (m) | bound (m) | x max (m) | RTF stand |")
    print("|---|---|---|---|---|---|---|---|")
    for step in (0.016, 0.008, 0.004, 0.002):
        ground = WheelGround(robot, step)
        mech = load_ground(robot, ground=ground)
        per_leg = sum(1 for g in ground.geoms() if g.name.startswith("FL_"))
        mujoco.mj_resetDataKeyframe(mech.model, mech.data, 0)
        t0 = time.process_time()
        for _ in range(1000):
            mujoco.mj_step(mech.model, mech.data)
        rtf = 1000 * mech.model.opt.timestep / (time.process_time() - t0)
        phi = 2.0 * np.arcsin(min(step, 0.2) / (2.0 * robot.geometry.R))
        bound = robot.geometry.R * (1.0 - np.cos(phi / 2.0))
        for label, lq in (("wheel", wheel), ("any", anyq)):
            e = tyre_contact_errors(mech, lq)
            print(f"| {step * 1e3:g} mm | {per_leg} | {label} | {e[:, 0].min():.1e} | {e[:, 0].max():.2e} | "
                  f"{bound:.1e} | "
                  f"{np.abs(e[:, 1]).max():.2e} | {rtf:.1f} |")


if __name__ == "__main__":
    main()
