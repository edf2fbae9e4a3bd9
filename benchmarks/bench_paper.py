"""Speed of the paper reproduction: prints figures and writes them as JSON.

Two measurements of `tmem paper`:

1. The 60 s two-agent scenario (Table 2, improved switching (11)) at
   dt = 1 ms, 60 000 steps: wall time of ``tmem.simulate`` after warm-up,
   median of ``--repeat`` runs.
2. ``tmem paper`` end to end in a fresh interpreter (three runs at the default
   dt = 1e-4 s, figures, datasets, report): median of ``--repeat`` runs, both
   with an empty Numba cache (a fresh clone's first run, compilation included)
   and with the cache filled by the run before.

Usage::

    python benchmarks/bench_paper.py [--repeat 5] [--json benchmarks/results/paper.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import tmem
from tmem.scenario import with_changes


def time_simulate(repeat: int) -> dict:
    scenario = with_changes(tmem.preset("fig9"), {"simulation.dt": 1e-3, "simulation.record_every": 10})
    tmem.simulate(scenario)  # warm-up: compile or load the compiled loop
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        tmem.simulate(scenario)
        times.append(time.perf_counter() - started)
    steps = scenario.simulation.n_steps
    median = statistics.median(times)
    return {"steps": steps, "median_s": median, "min_s": min(times), "ns_per_step": 1e9 * median / steps}


def time_paper(repeat: int, cold: bool) -> dict:
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeat):
            env = dict(os.environ)
            if cold:  # an empty cache: Numba compiles the loop and functions again
                env["NUMBA_CACHE_DIR"] = str(Path(tmp) / f"cache{k}")
            else:
                env["NUMBA_CACHE_DIR"] = str(Path(tmp) / "warm-cache")
            out = Path(tmp) / f"paper{k}"
            started = time.perf_counter()
            subprocess.run([sys.executable, "-m", "tmem", "paper", "--out", str(out)], env=env, check=True,
                           capture_output=True)  # fmt: skip
            times.append(time.perf_counter() - started)
    if not cold:
        times = times[1:] or times  # the first run filled the cache
    return {"runs": len(times), "median_s": statistics.median(times), "min_s": min(times), "max_s": max(times)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args()

    results = {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "simulate_60s_dt1ms": time_simulate(max(args.repeat, 5)),
        "paper_cold_cache": time_paper(args.repeat, cold=True),
        "paper_warm_cache": time_paper(args.repeat + 1, cold=False),
    }
    sim = results["simulate_60s_dt1ms"]
    print(f"machine: {results['machine']['cpus']} CPUs, {results['machine']['platform']}")
    print(f"simulate, 60 s at dt = 1 ms ({sim['steps']} steps): median {sim['median_s'] * 1e3:.2f} ms "
          f"({sim['ns_per_step']:.0f} ns/step), target <= 100 ms")  # fmt: skip
    for key, label in (("paper_cold_cache", "empty Numba cache"), ("paper_warm_cache", "warm Numba cache")):
        r = results[key]
        print(f"tmem paper end to end, {label}: median {r['median_s']:.2f} s over {r['runs']} runs "
              f"(min {r['min_s']:.2f}, max {r['max_s']:.2f}), target <= 20 s")  # fmt: skip
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
