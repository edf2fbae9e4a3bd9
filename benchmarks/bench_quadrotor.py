"""Speed of the quadrotor model in the step loop, beside the linear model: prints figures.

Two cases, each after a short run that compiles (or loads) its loop, timed as
the median of ``--repeat`` runs of ``tmem.simulate`` with nothing recorded:

* hex19: examples/vehicles/hex19.toml, 19 agents in a hexagonal patch, 60 s at
  dt = 1 ms (the flight controller every step);
* gas-N: benchmarks/bench_gas.py's gas of N agents in a periodic square,
  repulsion (8), 1000 steps of dt = 0.01 s (five sub-steps of 2 ms each); N
  agents step on threads from N = 10^4 on.

Usage::

    python benchmarks/bench_quadrotor.py [--n 10000] [--repeat 3] [--inner-period 0.002 0.01]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

import bench_gas  # noqa: E402

import tmem  # noqa: E402
from tmem.engine import driver  # noqa: E402
from tmem.scenario import from_dict, load  # noqa: E402

HEX19 = HERE.parent / "examples" / "vehicles" / "hex19.toml"


def with_model(scenario, model: dict):
    """``scenario`` with its ``[model]`` table replaced."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    data["model"] = model
    return from_dict(data)


def timed(scenario, repeat: int) -> float:
    """The median wall time of ``repeat`` runs (s)."""
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        tmem.simulate(scenario, record=False)
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def warm(scenario, threaded: bool) -> None:
    """Compile or load the loop ``scenario`` runs with, on a few steps."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    data["simulation"].update(duration=5 * data["simulation"]["dt"], record_every=5)
    threshold = driver.THREADED_SWARM
    driver.THREADED_SWARM = 0 if threaded else threshold
    tmem.simulate(from_dict(data), record=False)
    driver.THREADED_SWARM = threshold


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--inner-period", type=float, nargs="+", default=[0.002])
    args = parser.parse_args()
    print(f"{os.cpu_count()} CPUs, median of {args.repeat}")

    hex19 = load(HEX19)
    linear = with_model(hex19, {"kind": "linear"})
    for name, scenario in (("quadrotor", hex19), ("linear", linear)):
        warm(scenario, threaded=False)
        seconds = timed(scenario, args.repeat)
        steps = scenario.simulation.n_steps
        print(f"hex19 {name:>9}: {seconds:.2f} s for 60 s at dt = 1 ms ({19 * steps / seconds:.3g} agent-steps/s)")

    for n in args.n:
        gas = bench_gas.gas(n)
        models = [("linear", {"kind": "linear"})] + [
            (f"quadrotor, inner {period:g} s", {"kind": "quadrotor", "inner_period": period}) for period in args.inner_period
        ]
        for name, model in models:
            scenario = with_model(gas, model)
            warm(scenario, threaded=n >= driver.THREADED_SWARM)
            seconds = timed(scenario, args.repeat)
            print(f"gas-{n} {name:>24}: {n * bench_gas.STEPS / seconds:.3g} agent-steps/s ({seconds:.2f} s)")


if __name__ == "__main__":
    main()
