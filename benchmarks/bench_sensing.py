"""The cost of sensing: the same runs on the exact path and on the sensed path, in one process.

Two workloads, each run exactly and under three ``[sensing]`` tables (docs/sensing.md):

* ``fig9``: the Fig. 9 preset (two agents, 600 000 steps of 1e-4 s, every 100th recorded), steps/s;
* ``gas``: a 2-D periodic gas of ``--n`` agents under repulsion (8), 6 neighbours within
  ``R + R_j`` on average, 300 steps of 0.01 s, nothing recorded, on all pairs (``--n`` up to a few
  hundred) or on Verlet lists, agent-steps/s.

The sensing tables: ``noise`` (position and velocity noise, own noise; no buffer), ``delay``
(a random delay of 20 to 50 ms and messages every step: a ring buffer and one draw a pair), and
``all`` (noise, random delay, loss 0.2, a hold of 0.1 s, messages every step).  The sensed path
always has a range (``--range``, required with lists).  Each figure is the median of ``--repeat``
runs after one that compiles the loop; the rounds alternate between the cases so that a drift in
the machine's load falls on all alike.

Usage::

    python benchmarks/bench_sensing.py [--n 10000] [--repeat 5] [--range 60]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

import tmem
from tmem.scenario import from_dict, with_changes

TABLES = {
    "exact": None,
    "noise": {"position_noise": 0.3, "velocity_noise": 0.1, "own_position_noise": 0.1, "own_velocity_noise": 0.05},
    "delay": {"delay": [0.02, 0.05]},
    "all": {"position_noise": 0.3, "velocity_noise": 0.1, "own_position_noise": 0.1, "own_velocity_noise": 0.05,
            "delay": [0.02, 0.05], "loss": 0.2, "hold": 0.1},
}  # fmt: skip


def gas(n: int) -> tmem.Scenario:
    """The 2-D periodic gas of ``n`` agents (bench_gas.py's box), 300 steps, nothing recorded."""
    side = float(np.sqrt(n * np.pi * 40.0**2 / 6))
    return from_dict({"interaction": {"function": "repulsion"}, "space": {"axes": 2, "periodic": True, "box": [side, side]},
                      "swarm": {"n": n, "seed": 1, "speed_rms": 3.0},
                      "simulation": {"dt": 0.01, "duration": 3.0, "record_every": 300, "record_agents": [0]}})  # fmt: skip


def with_table(scenario: tmem.Scenario, table: dict | None, reach: float) -> tmem.Scenario:
    """``scenario`` with the ``[sensing]`` table ``table`` and the range ``reach`` (m); as it is for None."""
    return scenario if table is None else with_changes(scenario, {"sensing": {**table, "range": reach}})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000, help="agents of the gas")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--range", type=float, default=60.0, help="the sensing range of the sensed runs (m)")
    args = parser.parse_args()
    workloads = {"fig9": (tmem.preset("fig9"), 600_000, "steps/s"), "gas": (gas(args.n), 300 * args.n, "agent-steps/s")}
    times: dict[tuple[str, str], list[float]] = {}
    for work, (scenario, units, _) in workloads.items():
        cases = {name: with_table(scenario, table, args.range) for name, table in TABLES.items()}
        for name, case in cases.items():
            short = {"simulation.duration": case.simulation.dt * 10, "simulation.record_every": 1, "commands": []}
            tmem.simulate(with_changes(case, short))  # compiles the loop
        for _ in range(args.repeat):
            for name, case in cases.items():
                started = time.perf_counter()
                tmem.simulate(case)
                times.setdefault((work, name), []).append(units / (time.perf_counter() - started))
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; gas of {args.n} agents; "
          f"median of {args.repeat} runs; sensing range {args.range:g} m")  # fmt: skip
    print(f"{'workload':10s}{'unit':15s}" + "".join(f"{name:>12s}" for name in TABLES) + "   (sensed / exact)")
    for work, (_, _, unit) in workloads.items():
        rates = [statistics.median(times[(work, name)]) for name in TABLES]
        ratios = " ".join(f"{rate / rates[0]:.2f}" for rate in rates[1:])
        print(f"{work:10s}{unit:15s}" + "".join(f"{rate:12.4g}" for rate in rates) + f"   ({ratios})")


if __name__ == "__main__":
    main()
