"""Size and write time of a run's checkpoint on the gas-N case, and the time to read it back: prints figures.

The case is benchmarks/bench_gas.py's gas-N (N agents in a 2-D periodic square, 6 neighbours within
reach each on average, Verlet lists, dt = 0.01 s), run for ``--steps`` steps with a checkpoint every
``--every`` steps (:mod:`tmem.engine.checkpoint`); every agent is recorded at the start and at the
end, so a checkpoint holds one recorded row of every agent.  Reported for each N: the file's size
(MB, and bytes per agent), the wall time of writing it (the median over the run's checkpoints:
arrays gathered, written, fsync'd and renamed into place), the time to read it back and check it
(:meth:`~tmem.engine.checkpoint.Checkpoints.start`), and for scale the wall time of one step
without checkpoints (from runs of ``--steps`` and twice as many steps, recording nothing: the
difference over ``--steps``, so that setting up and listing neighbours do not count).

The file is written under ``--folder`` (default: the current directory), whose file system decides
what fsync costs; the script names it.

Usage::

    python benchmarks/bench_checkpoint.py --n 10000 100000 [--folder DIR] [--json benchmarks/results/checkpoint.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))

from bench_gas import gas  # noqa: E402  (the gas-N scenario)

import tmem  # noqa: E402
from tmem.engine import Checkpoints  # noqa: E402
from tmem.engine import driver as engine  # noqa: E402


@dataclass
class TimedCheckpoints(Checkpoints):
    """Checkpoints that time each write."""

    seconds: list = field(default_factory=list, init=False)

    def save(self, step, state, list_builds):
        """Write the checkpoint (:meth:`Checkpoints.save`) and keep its wall time.

        Parameters
        ----------
        step, state, list_builds
            As :meth:`Checkpoints.save` takes them.
        """
        started = time.perf_counter()
        super().save(step, state, list_builds)
        self.seconds.append(time.perf_counter() - started)


def file_system(folder: Path) -> str:
    """The type of the file system holding ``folder`` (``df --output=fstype``), or "?"."""
    try:
        return subprocess.run(["df", "--output=fstype", str(folder)], capture_output=True, text=True).stdout.split()[-1]
    except (OSError, IndexError):
        return "?"


def step_seconds(n: int, steps: int) -> float:
    """The wall time of one step of gas-N, without checkpoints or records."""
    times = []
    for count in (steps, 2 * steps):
        started = time.perf_counter()
        tmem.simulate(gas(n, count), record=False)
        times.append(time.perf_counter() - started)
    return (times[1] - times[0]) / steps


def run_case(n: int, steps: int, every: int, folder: Path) -> dict:
    """Run gas-N with checkpoints into ``folder``; return the figures."""
    scenario = gas(n, steps)
    path = folder / f".gas-{n}.tmem-checkpoint.npz"
    path.unlink(missing_ok=True)
    checkpoints = TimedCheckpoints(path, every * scenario.simulation.dt)
    tmem.simulate(scenario, checkpoints=checkpoints)
    size = path.stat().st_size
    started = time.perf_counter()
    saved = Checkpoints(path, every * scenario.simulation.dt).start(scenario)
    read_s = time.perf_counter() - started
    assert saved.step == steps
    path.unlink()
    return {
        "n": n,
        "steps": steps,
        "checkpoints": len(checkpoints.seconds),
        "size_mb": size / 2**20,
        "bytes_per_agent": size / n,
        "write_s": statistics.median(checkpoints.seconds),
        "write_max_s": max(checkpoints.seconds),
        "read_s": read_s,
        "step_s": step_seconds(n, steps),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--steps", type=int, default=40)
    parser.add_argument("--every", type=int, default=10, help="steps between checkpoints")
    parser.add_argument("--folder", type=Path, default=Path.cwd())
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    # Compile or load both step loops on a small swarm first (the threaded one by lowering the threshold).
    tmem.simulate(gas(2000, steps=5), record=False)
    threshold, engine.THREADED_SWARM = engine.THREADED_SWARM, 0
    tmem.simulate(gas(2000, steps=5), record=False)
    engine.THREADED_SWARM = threshold
    with tempfile.TemporaryDirectory(dir=args.folder) as folder:
        where = file_system(Path(folder))
        rows = [run_case(n, args.steps, args.every, Path(folder)) for n in args.n]
    print(f"checkpoints of gas-N on {where} ({platform.machine()}, {platform.python_version()})")
    print(f"{'N':>8} {'size (MB)':>10} {'B/agent':>8} {'write (s)':>10} {'read (s)':>9} {'one step (s)':>13}")
    for r in rows:
        print(f"{r['n']:>8} {r['size_mb']:>10.1f} {r['bytes_per_agent']:>8.0f} {r['write_s']:>10.3f} {r['read_s']:>9.3f} {r['step_s']:>13.4f}")
    if args.json:
        args.json.write_text(json.dumps({"file_system": where, "cases": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
