"""How long ``tmem export`` takes, and how large its files are, for a run directory.

Times, in one interpreter after the libraries are loaded: reading the run back
(:func:`tmem.files.exchange.recording.read_recording`), writing the MCAP file
(:func:`tmem.files.exchange.foxglove.write_mcap`) and the CSV files
(:func:`tmem.files.exchange.crazyswarm.write_csv_files`); the median of ``--repeat``
rounds.  Printed with the sizes of ``trajectory.nc``, the MCAP file and the CSV
files, the records and agents, and the machine's load average (the machine is
shared: a busy one slows every figure).

Usage::

    python benchmarks/bench_export.py out/hex19 [--repeat 3]
    python benchmarks/bench_export.py --scenario examples/swarm/gas2d.toml [--duration 10]
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path


def _median_seconds(action, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        action()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _size(path: Path) -> int:
    return path.stat().st_size if path.is_file() else sum(p.stat().st_size for p in path.iterdir())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run_dir", nargs="?", type=Path, help="a directory written by tmem run")
    parser.add_argument("--scenario", type=Path, help="simulate this scenario first (its trajectory.nc only)")
    parser.add_argument("--duration", type=float, help="with --scenario: the run's duration (s)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    import tmem
    from tmem.files.exchange.crazyswarm import write_csv_files
    from tmem.files.exchange.foxglove import write_mcap
    from tmem.files.exchange.recording import read_recording
    from tmem.files.io import write_netcdf

    with tempfile.TemporaryDirectory() as work:
        work = Path(work)
        run_dir = args.run_dir
        if run_dir is None:
            scenario = tmem.load(args.scenario)
            if args.duration:
                scenario = tmem.scenario.with_changes(scenario, {"simulation.duration": args.duration})
            run_dir = work / "run"
            run_dir.mkdir()
            write_netcdf(tmem.simulate(scenario), run_dir / "trajectory.nc")
        recording = read_recording(run_dir)
        (work / "csv").mkdir()
        read = _median_seconds(lambda: read_recording(run_dir), args.repeat)
        mcap = _median_seconds(lambda: write_mcap(recording, work / "run.mcap"), args.repeat)
        csv = _median_seconds(lambda: write_csv_files(recording, work / "csv"), args.repeat)
        print(f"run: {run_dir}  records: {len(recording.time)}  agents: {len(recording.agents)}  "
              f"pairs: {len(recording.pairs)}  axes: {recording.n_axes}")  # fmt: skip
        print(f"read trajectory.nc: {read:8.3f} s   {_size(run_dir / 'trajectory.nc') / 1e6:8.2f} MB")
        print(f"write MCAP:         {mcap:8.3f} s   {_size(work / 'run.mcap') / 1e6:8.2f} MB")
        print(f"write CSV:          {csv:8.3f} s   {_size(work / 'csv') / 1e6:8.2f} MB")
        print(f"median of {args.repeat}; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
