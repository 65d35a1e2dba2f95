"""Run every ground scenario of some models and print the rows of docs/mujoco.md's tables: each scenario's figures
(max error of each row) and its real-time factor over ``--runs`` runs (simulated / CPU seconds, one core).

    PYTHONPATH=src python scripts/mujoco_scenarios.py [MODEL ...] [--runs 3]

Default models: wheel_leg, quadruped, go2, the humanoids, bolt and the hybrid leg.
"""

from __future__ import annotations

import argparse

from legkin.mjcf.floating import load_ground
from legkin.mjcf.scenarios import SCENARIOS, run_scenario

MODELS = ("wheel_leg", "quadruped", "go2", "talos", "romeo", "icub", "alexander", "g1", "simple_humanoid",
          "bolt", "hybrid_leg")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("models", nargs="*", default=MODELS)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print("| model | scenario | figures (m; roll: relative) | RTF |")
    print("|---|---|---|---|")
    for name in args.models:
        mech = load_ground(name)
        ground = mech.ground
        for scenario in SCENARIOS:
            if (scenario == "press") != ground.fixed_base or (scenario == "roll" and ground.rolling_radius is None):
                continue
            if scenario == "squat" and ground.no_squat:
                print(f"| {name} | squat | none: {ground.no_squat} | |")
                continue
            runs = [run_scenario(mech, scenario) for _ in range(args.runs)]
            rtf = sorted(r.rtf for r in runs)
            figures = ", ".join(f"{r.max_error:.2e}{'' if r.passed else ' FAIL'}" for r in runs[0].rows)
            print(f"| {name} | {scenario} | {figures} | {rtf[0]:.1f}-{rtf[-1]:.1f} |", flush=True)


if __name__ == "__main__":
    main()
