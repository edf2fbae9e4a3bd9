"""Throughput and memory of tmem on the "gas-N" case, beside jax-md: prints figures, writes JSON.

The case (issue "Swarms in 2-D and 3-D", item 9): N agents uniform at random in
a 2-D periodic square box whose side L = sqrt(N pi (R + R_j)^2 / 6) gives each
agent 6 neighbours within R + R_j on average; random velocities with RMS speed
3 m/s; repulsion (8); Table 1 parameters; dt = 0.01 s; 1000 steps; nothing
recorded.

For each N, in a fresh child process (so that its peak memory is its own):
one short run compiles the loop, then ``--repeat`` runs of ``tmem.simulate``
are timed.  Reported: agent-steps per second (N x steps / wall seconds, the
median over the runs; setting up the random swarm and building the neighbour
lists are inside the timed call), neighbour-list builds, and the peak
resident memory of the child, in total and per agent above the baseline after
``import tmem`` and the compile run.

With ``--jaxmd-python PY`` (a Python with jax-md; see benchmarks/jaxmd_gas.py
for the pins), the same N run in jax-md through benchmarks/jaxmd_gas.py and
the throughput ratios are printed.

Usage::

    python benchmarks/bench_gas.py --n 1000 10000 100000 1000000 --repeat 3 \\
        [--jaxmd-python /tmp/jaxvenv/bin/python] [--json benchmarks/results/gas.json]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).parent
STEPS = 1000
DT = 0.01
REACH = 40.0


def gas(n: int, steps: int = STEPS, skin: float = 4.0):
    """The gas-N scenario."""
    import numpy as np

    from tmem.scenario import from_dict

    side = float(np.sqrt(n * np.pi * REACH**2 / 6))
    return from_dict(
        {
            "name": f"gas-{n}",
            "interaction": {"function": "repulsion"},
            "space": {"axes": 2, "periodic": True, "box": [side, side]},
            "swarm": {"n": n, "seed": 1, "speed_rms": 3.0},
            "neighbors": {"method": "verlet", "skin": skin},
            "simulation": {"dt": DT, "duration": steps * DT, "record_every": steps},
        }
    )


def _rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def run_case(n: int, steps: int, repeat: int, skin: float) -> dict:
    """Time ``repeat`` runs of gas-N in this process (call in a fresh child for the memory figure)."""
    import tmem
    from tmem.engine import driver as engine

    # Compile or load both step loops on a small swarm: the serial one and, by lowering the threshold
    # for this one run, the threaded one that large N use.
    tmem.simulate(gas(min(n, 2000), steps=5, skin=skin), record=False)
    threshold, engine.THREADED_SWARM = engine.THREADED_SWARM, 0
    tmem.simulate(gas(min(n, 2000), steps=5, skin=skin), record=False)
    engine.THREADED_SWARM = threshold
    baseline = _rss_bytes()
    scenario = gas(n, steps, skin)
    times, builds = [], 0
    for _ in range(repeat):
        started = time.perf_counter()
        trajectory = tmem.simulate(scenario, record=False)
        times.append(time.perf_counter() - started)
        builds = trajectory.list_builds
    median = statistics.median(times)
    peak = _rss_bytes()
    return {
        "n": n,
        "steps": steps,
        "skin": skin,
        "agent_steps_per_s": n * steps / median,
        "median_s": median,
        "min_s": min(times),
        "max_s": max(times),
        "list_builds": builds,
        "peak_mb": peak / 2**20,
        "bytes_per_agent": (peak - baseline) / n,
    }


def measure(n: int, steps: int, repeat: int, skin: float) -> dict:
    """:func:`run_case` in a fresh child process."""
    code = (
        "import json, sys; sys.path.insert(0, sys.argv[1]); import bench_gas; "
        "n, steps, repeat, skin = int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), float(sys.argv[5]); "
        "print('RESULT ' + json.dumps(bench_gas.run_case(n, steps, repeat, skin)))"
    )
    args = [sys.executable, "-c", code, str(HERE), str(n), str(steps), str(repeat), str(skin)]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return json.loads(next(line for line in out.splitlines() if line.startswith("RESULT "))[7:])


def jaxmd(python: str, ns: list[int], steps: int, repeat: int) -> dict[int, dict]:
    """jax-md's figures for the same cases, from benchmarks/jaxmd_gas.py run with ``python``."""
    out = HERE / ".jaxmd_gas.json"
    subprocess.run(
        [python, str(HERE / "jaxmd_gas.py"), "--n", *map(str, ns), "--steps", str(steps),
         "--repeat", str(repeat), "--json", str(out)],
        check=True,
    )  # fmt: skip
    data = json.loads(out.read_text())
    out.unlink()
    return {int(row["n"]): row for row in data["cases"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[1000, 10000, 100000, 1000000])
    parser.add_argument("--steps", type=int, default=STEPS)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--skin", type=float, default=4.0, help="Verlet skin, m")
    parser.add_argument(
        "--jaxmd-python",
        default=sys.executable if importlib.util.find_spec("jax_md") else None,
        help="a Python with jax-md, to run the same cases (default: this one, if it has jax-md)",
    )
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args()

    machine = {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()}
    print(f"gas-N, {args.steps} steps of {DT} s, median of {args.repeat}; {machine['cpus']} CPUs")
    print(f"{'N':>9} {'agent-steps/s':>14} {'s/run':>8} {'builds':>7} {'peak MB':>8} {'B/agent':>8}")
    rows = []
    for n in args.n:
        r = measure(n, args.steps, args.repeat, args.skin)
        rows.append(r)
        print(f"{n:>9} {r['agent_steps_per_s']:>14.3g} {r['median_s']:>8.3f} {r['list_builds']:>7} "
              f"{r['peak_mb']:>8.0f} {r['bytes_per_agent']:>8.0f}")  # fmt: skip
    by_n = {r["n"]: r for r in rows}
    if 10000 in by_n and 1000000 in by_n:
        print(f"linearity: throughput at 1e6 / at 1e4 = "
              f"{by_n[1000000]['agent_steps_per_s'] / by_n[10000]['agent_steps_per_s']:.2f} (target >= 0.5)")  # fmt: skip
    reference = {}
    if args.jaxmd_python:
        reference = jaxmd(args.jaxmd_python, [n for n in args.n if n <= 100000], args.steps, args.repeat)
        for n, ref in reference.items():
            ratio = by_n[n]["agent_steps_per_s"] / ref["agent_steps_per_s"]
            print(f"jax-md N = {n}: {ref['agent_steps_per_s']:.3g} agent-steps/s, "
                  f"{ref['bytes_per_agent']:.0f} B/agent; tmem / jax-md = {ratio:.2f}")  # fmt: skip
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        payload = {"machine": machine, "tmem": rows, "jaxmd": list(reference.values())}
        args.json.write_text(json.dumps(payload, indent=2) + "\n")


if __name__ == "__main__":
    main()
