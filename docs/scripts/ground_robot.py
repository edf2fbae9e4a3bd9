"""Print every figure of docs/ground_robot.md: the ground robot's runs, and what placing r_l would do.

Usage: python docs/scripts/ground_robot.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.signal import place_poles

import tmem
from tmem.scenario import with_changes
from tmem.vehicles import vehicle_class

ROOT = Path(__file__).resolve().parents[2]


def repulsion(tau: float, place_r_l: bool) -> float:
    """ΔRMS (%) of the repulsion preset's head-on encounter on the robot; with ``place_r_l``, gains
    placing ``-r_l`` (Table 1's 12 /s) instead of the drive's ``-1/tau``."""
    scenario = with_changes(tmem.preset("repulsion"), {"model": {"kind": "ground_robot", "tau": tau},
                                                       "interaction.c_max": 0.98, "simulation.dt": 0.001})  # fmt: skip
    robot = vehicle_class("ground_robot")
    original = robot.gains
    if place_r_l:
        def placed(self, r_l, im_l, im_r):
            a, b = self.linearisation()
            return place_poles(a, b[:, None], [-r_l, -1j * im_r, 1j * im_r]).gain_matrix[0]

        robot.gains = placed
    try:
        return tmem.summarize(tmem.simulate(scenario))["rms_change_percent"]
    finally:
        robot.gains = original


def main() -> None:
    print("Head-on repulsion, ΔRMS (%): tau (s), with (R2), with -r_l placed")
    for tau in (0.02, 0.1, 0.5):
        print(f"  {tau:5.2f}  {repulsion(tau, False):+.3f}  {repulsion(tau, True):+.3f}")
    fig9 = tmem.simulate(tmem.load(ROOT / "examples/robots/fig9.toml"))
    s = tmem.summarize(fig9)
    print(f"fig9 on the robot: couples at {s['couple_time']:.2f} s, uncouples at {s['uncouple_time']:.2f} s, "
          f"ΔRMS {s['rms_change_percent']:+.3f} %")  # fmt: skip
    hexes = []
    for seed in range(1, 6):
        scenario = with_changes(tmem.load(ROOT / "examples/robots/hex19.toml"), {"formation.seed": seed})
        run = tmem.simulate(scenario)
        error = np.abs(run.pair_distance - run.initial.d_t[None, :])
        drift = np.abs(run.state[-1, :, :, 1].mean(axis=0) - [3.0, 0.0]).max()
        hexes.append((seed, error.max(), error[-1].max(), drift))
    print("hex19 on the robot, 60 s, seeds 1-5: largest edge error over the run, at the end (m); mean velocity's drift (m/s)")
    for seed, worst, end, drift in hexes:
        print(f"  seed {seed}: {worst:.3f}  {end:.3f}  {drift:.2e}")
    worst = np.array([h[1] for h in hexes])
    print(f"  median {np.median(worst):.3f} m, worst {worst.max():.3f} m")


if __name__ == "__main__":
    main()
