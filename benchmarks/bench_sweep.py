"""Speed of the encounter study on the local Dask cluster: prints figures and writes them as JSON.

The whole study (issue "Sweeps on Dask", item 7): ``tmem sweep
examples/sweeps/encounters.toml`` (10 000 encounters × 2 functions = 20 000
cases of 60 s at dt = 1e-4 s) end to end in a fresh interpreter, into a new
directory each run: starting the local cluster, running every case,
writing the table, summary and figures.  The first run also fills Numba's
cache (its time is reported apart); the median is over the runs after it.
Target: <= 120 s on the project's 2-core machine.

Usage::

    python benchmarks/bench_sweep.py [--repeat 3] [--json benchmarks/results/sweep.json]
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

import pandas as pd

STUDY = Path(__file__).resolve().parents[1] / "examples" / "sweeps" / "encounters.toml"


def time_study(out: Path, sweep: Path) -> float:
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "tmem", "sweep", str(sweep), "--out", str(out)], check=True, capture_output=True)
    seconds = time.perf_counter() - started
    table = pd.read_parquet(out / "results.parquet")
    assert table["case"].is_unique and table["error"].isna().all(), "the study must end with one good row per case"
    return seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="timed runs after the first")
    parser.add_argument("--sweep", type=Path, default=STUDY)
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        first = time_study(Path(tmp) / "first", args.sweep)
        times = [time_study(Path(tmp) / f"run{k}", args.sweep) for k in range(args.repeat)]
        cases = len(pd.read_parquet(Path(tmp) / "first" / "results.parquet"))
    results = {
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "sweep": str(args.sweep.name),
        "cases": cases,
        "first_run_s": first,
        "runs_s": times,
        "median_s": statistics.median(times),
        "cases_per_s": cases / statistics.median(times),
    }
    print(f"machine: {results['machine']['cpus']} CPUs, {results['machine']['platform']}")
    print(f"{args.sweep.name}: {cases} cases; first run (Numba cache filled) {first:.1f} s")
    print(
        f"end to end, median of {len(times)} runs: {results['median_s']:.1f} s "
        f"({', '.join(f'{t:.1f}' for t in times)}), {results['cases_per_s']:.0f} cases/s, target <= 120 s"
    )
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
