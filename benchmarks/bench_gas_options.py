"""Throughput of the gas-N case with the gas's options on, against the plain gas-N, in one run.

The plain case is benchmarks/bench_gas.py's gas-N (2-D periodic box, six neighbours within
R + R_j on average, repulsion, dt = 0.01 s, 1000 steps, nothing recorded).  The cases with options
put the same agents in a walled box of the same side and hold them at their 3 m/s with the
thermostat, which turns on every gas stage: the neighbour counts (every ``simulation.gas_period``,
0.1 s: every 10th step), walls, thermostat and running totals; the last also averages their pushes
(``interaction.combine = "mean"``).  ``--each`` adds walls and the thermostat with the gas counted
at every step, and each option on its own: the gas observed and nothing else, the periodic box
with the mean of pushes, with the thermostat, and the walled box.
The cases alternate, after one compile run each; each figure is the median of ``--repeat`` runs, in
agent-steps per second, and each ratio is that of the medians.

Usage::

    python benchmarks/bench_gas_options.py --n 100000 --repeat 5 [--each] [--json benchmarks/results/gas_options.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

from bench_gas import DT, STEPS, gas

import tmem
from tmem.scenario import with_changes


def with_options(n: int, *, mean: bool, steps: int = STEPS):
    """gas-N in a walled box with the thermostat, and the mean of pushes if ``mean``."""
    plain = gas(n, steps)
    return with_changes(plain, {"space.periodic": False, "space.walls": True, "thermostat": {"rms_velocity": 3.0},
                                "interaction.combine": "mean" if mean else "sum"})  # fmt: skip


def each_option(n: int) -> dict:
    """gas-N with walls and the thermostat counted at every step, then with one option at a time."""
    plain = gas(n)
    walled = {"space.periodic": False, "space.walls": True}
    return {"walls + thermostat, counted every step": with_changes(with_options(n, mean=False), {"simulation.gas_period": DT}),
            "observe_gas": with_changes(plain, {"simulation.observe_gas": True}),
            "periodic, mean of pushes": with_changes(plain, {"interaction.combine": "mean"}),
            "periodic, thermostat": with_changes(plain, {"thermostat": {"rms_velocity": 3.0}}),
            "walls": with_changes(plain, walled)}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[100_000])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--each", action="store_true", help="also each option on its own")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    rows = []
    for n in args.n:
        cases = {"plain": gas(n), "walls + thermostat": with_options(n, mean=False),
                 "walls + thermostat + mean": with_options(n, mean=True), **(each_option(n) if args.each else {})}  # fmt: skip
        for scenario in cases.values():  # compile, or load from the cache
            tmem.simulate(with_changes(scenario, {"simulation.duration": 5 * DT, "simulation.record_every": 5}), record=False)
        seconds = {name: [] for name in cases}
        for _ in range(args.repeat):  # alternate, so that the machine's load falls on both alike
            for name, scenario in cases.items():
                start = time.perf_counter()
                tmem.simulate(scenario, record=False)
                seconds[name].append(time.perf_counter() - start)
        rates = {name: n * STEPS / statistics.median(s) for name, s in seconds.items()}
        ratios = {name: rate / rates["plain"] for name, rate in rates.items() if name != "plain"}
        for name, rate in rates.items():
            print(f"N = {n:>8}  {name:<38} {rate:.3g} agent-steps/s  (runs: {', '.join(f'{s:.2f}' for s in seconds[name])} s)")
        for name, ratio in ratios.items():
            print(f"N = {n:>8}  ratio ({name} / plain): {ratio:.3f}")
        rows.append({"n": n, "rates": rates, "seconds": seconds, "ratios": ratios})
    if args.json:
        args.json.write_text(json.dumps({"machine": platform.platform(), "repeat": args.repeat, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
