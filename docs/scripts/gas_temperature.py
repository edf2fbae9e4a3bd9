"""The RMS velocity ("temperature") of a random 2-D gas against time, at two densities.

400 agents, repulsion (8), a periodic box sized for 1 or 6 neighbours within R + R_j on
average, RMS speed 3 m/s at the start, dt = 1 ms.  Prints a Markdown table; the figures are
quoted in docs/swarms.md::

    python docs/scripts/gas_temperature.py
"""

from __future__ import annotations

import numpy as np

import tmem
from tmem.analysis.metrics import rms_velocity
from tmem.scenario import with_changes

TIMES = (0, 2, 5, 10, 20, 40, 60, 90, 120)


def main() -> None:
    base = tmem.load("examples/swarm/gas2d.toml")
    print("| neighbours | " + " | ".join(f"t = {t} s" for t in TIMES) + " |")
    print("| --- |" + " --- |" * len(TIMES))
    for neighbours in (1.0, 6.0):
        side = float(np.sqrt(base.swarm.n * np.pi * base.interaction.reach**2 / neighbours))
        scenario = with_changes(
            base,
            {
                "space.box": [side, side],
                "simulation.dt": 0.001,
                "simulation.duration": float(TIMES[-1]),
                "simulation.record_every": 1000,
            },
        )
        trajectory = tmem.simulate(scenario)
        rms = rms_velocity(trajectory.state[..., 1], trajectory.active)
        row = [f"{rms[np.searchsorted(trajectory.time, t)]:.2f}" for t in TIMES]
        print(f"| {neighbours:g} | " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
