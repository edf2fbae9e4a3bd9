"""Old against new in one run: the speed of tmem's core workloads, from two source trees side by side.

``--old REF`` is a git commit (checked out into a temporary worktree,
removed at the end); ``--new`` is a directory holding ``src/tmem`` (by
default this tree) or another commit.  Every measurement runs in a fresh
interpreter with ``PYTHONPATH`` at one side's ``src``.  For each workload,
one untimed run of each side fills its Numba on-disk cache; then ``--repeat``
rounds each run old, then new, so that a drift in the machine's load falls
on both alike.  Printed: each workload's median on both sides, the
throughput ratio new / old (> 1: new is faster; for wall times, old / new),
the machine's cores and load average, the command and the repeats.

Workloads (as benchmarks/bench_gas.py, bench_paper.py and bench_sweep.py
define them):

* ``gas-1e5``, ``gas-1e6``: gas-N in 2-D (bench_gas.py's scenario; 1000 and
  200 steps of 0.01 s, nothing recorded), agent-steps/s of one
  ``tmem.simulate`` after a 2-step run of the same swarm has loaded the loop;
  the set-up of the swarm and the neighbour lists are timed, as there;
* ``fig9-60k``: the 60 s two-agent run of Fig. 9 at dt = 1 ms (60 000 steps,
  every 10th recorded), steps/s, the median of 20 runs after one warm-up;
* ``encounters``: examples/sweeps/encounters.toml's first 2000 random starts
  under both functions (4000 of its 20 000 cases), drawn as ``tmem sweep``
  draws them, cases/s of ``tmem.batch.encounters.run_batch`` (no Dask);
* ``paper-cold``, ``paper-warm``: ``tmem paper`` end to end; cold runs a
  copy of the side's ``src`` without ``__pycache__`` with a new, empty
  ``NUMBA_CACHE_DIR`` (compilation included), warm the side's own tree
  with its filled cache;
* ``help``, ``run-help``: ``tmem --help`` and ``tmem run --help``.

``--quick`` does one round of gas-1e5, fig9-60k, paper-warm and the two help
commands, to smoke-test the script.  The machine is shared: a busy machine
slows Numba's threaded loops far more than its serial ones (set
``NUMBA_NUM_THREADS=1`` to compare the serial code alone), and the load
average is printed with each workload so that a noisy figure can be told.

Usage::

    python benchmarks/bench_core.py --old 38da709 [--new /path/to/tree | --new REF] [--repeat 5] \\
        [--workloads gas-1e5 fig9-60k] [--quick] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
STUDY = ROOT / "examples" / "sweeps" / "encounters.toml"
GAS_STEPS = {100_000: 1000, 1_000_000: 200}
ENCOUNTER_DRAWS = 2000
FIG9_RUNS = 20


# --- measurements inside a child interpreter (``bench_core.py --child NAME``) ----------------------


def child_gas(n: int) -> float:
    """Agent-steps per second of one run of gas-N in 2-D, after a 2-step run has loaded the loop."""
    import tmem
    from pin_results import gas_toml

    steps = GAS_STEPS[n]
    tmem.simulate(tmem.loads(gas_toml(n, 2, 2, seed=1)), record=False)
    scenario = tmem.loads(gas_toml(n, 2, steps, seed=1))
    started = time.perf_counter()
    tmem.simulate(scenario, record=False)
    return n * steps / (time.perf_counter() - started)


def child_fig9() -> float:
    """Steps per second of the 60 s Fig. 9 run at dt = 1 ms: the median of :data:`FIG9_RUNS` runs."""
    import tmem
    from tmem.scenario import with_changes

    scenario = with_changes(tmem.preset("fig9"), {"simulation.dt": 1e-3, "simulation.record_every": 10})
    tmem.simulate(scenario)
    times = []
    for _ in range(FIG9_RUNS):
        started = time.perf_counter()
        tmem.simulate(scenario)
        times.append(time.perf_counter() - started)
    return 60_000 / statistics.median(times)


def child_encounters() -> float:
    """Cases per second of ``run_batch`` on the study's first :data:`ENCOUNTER_DRAWS` starts, both functions."""
    import numpy as np
    from pin_results import sweep_cases
    from tmem.scenario import with_changes

    try:
        from tmem.batch.encounters import run_batch
    except ImportError:  # a tree from before the packages by role: tmem/batch.py
        from tmem.batch import run_batch

    base, points = sweep_cases(STUDY)
    runs = []
    for setting, cases in points:
        draws = [draw for _, draw in cases[:ENCOUNTER_DRAWS]]
        starts = np.array(
            [[[d.get(f"agents.{a}.{q}", getattr(base.agents[a], q)) for q in ("position", "velocity")] for a in (0, 1)]
             for d in draws]
        )  # fmt: skip
        runs.append((with_changes(base, setting), starts[:, :, 0], starts[:, :, 1]))
    run_batch(runs[0][0], runs[0][1][:16], runs[0][2][:16])  # load the compiled loop
    started = time.perf_counter()
    for scenario, positions, velocities in runs:
        run_batch(scenario, positions, velocities)
    return sum(len(p) for _, p, _ in runs) / (time.perf_counter() - started)


CHILDREN: dict[str, Callable[[], float]] = {
    "gas-1e5": lambda: child_gas(100_000),
    "gas-1e6": lambda: child_gas(1_000_000),
    "fig9-60k": child_fig9,
    "encounters": child_encounters,
}


# --- the workloads, as run from the parent -------------------------------------------------------


def _run(command: list[str], src: Path, cwd: Path, **extra: str) -> str:
    """Run ``command`` with ``src`` first on the path; its output, or exit with its error output."""
    env = {**os.environ, "PYTHONPATH": str(src), **extra}
    done = subprocess.run(command, env=env, cwd=cwd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {shlex.join(command)} with PYTHONPATH={src}\n{done.stderr[-3000:]}")
    return done.stdout


def in_child(name: str) -> Callable[[Path, Path], float]:
    """A workload measured inside a fresh interpreter by ``CHILDREN[name]``."""

    def run(src: Path, scratch: Path) -> float:
        out = _run([sys.executable, str(Path(__file__).resolve()), "--child", name], src, scratch)
        return float(next(line for line in out.splitlines() if line.startswith("RESULT "))[7:])

    return run


def wall(args: list[str], cold: bool = False) -> Callable[[Path, Path], float]:
    """A workload timed end to end: ``python -m tmem ARGS`` (``{out}`` becomes a new directory)."""

    def run(src: Path, scratch: Path) -> float:
        work = Path(tempfile.mkdtemp(dir=scratch))
        extra = {}
        if cold:  # a fresh clone's first run: no compiled cache anywhere
            src = Path(shutil.copytree(src, work / "src", ignore=shutil.ignore_patterns("__pycache__")))
            extra["NUMBA_CACHE_DIR"] = str(work / "numba-cache")
        command = [sys.executable, "-m", "tmem", *(a.replace("{out}", str(work / "out")) for a in args)]
        started = time.perf_counter()
        _run(command, src, work, **extra)
        seconds = time.perf_counter() - started
        shutil.rmtree(work)
        return seconds

    return run


@dataclass(frozen=True)
class Workload:
    """A named measurement: its unit, whether more is better, whether ``--quick`` runs it, how to run it."""

    name: str
    unit: str
    rate: bool
    quick: bool
    run: Callable[[Path, Path], float]
    warm_up: bool = True


WORKLOADS = (
    Workload("gas-1e5", "agent-steps/s", True, True, in_child("gas-1e5")),
    Workload("gas-1e6", "agent-steps/s", True, False, in_child("gas-1e6")),
    Workload("fig9-60k", "steps/s", True, True, in_child("fig9-60k")),
    Workload("encounters", "cases/s", True, False, in_child("encounters")),
    Workload("paper-cold", "s", False, False, wall(["paper", "--out", "{out}"], cold=True), warm_up=False),
    Workload("paper-warm", "s", False, True, wall(["paper", "--out", "{out}"])),
    Workload("help", "s", False, True, wall(["--help"])),
    Workload("run-help", "s", False, True, wall(["run", "--help"])),
)


# --- the two sides -------------------------------------------------------------------------------


def git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], check=True, capture_output=True, text=True).stdout.strip()


def checkout(ref: str, scratch: Path, label: str) -> tuple[Path, str]:
    """A detached worktree of ``ref`` under ``scratch``: its ``src`` and the commit."""
    commit = git("rev-parse", "--verify", f"{ref}^{{commit}}")
    tree = scratch / label
    git("worktree", "add", "--detach", str(tree), commit)
    return tree / "src", commit


def side(spec: str, scratch: Path, label: str) -> tuple[Path, str, Path | None]:
    """``(src, description, worktree to remove or None)`` for a directory or a git ref."""
    path = Path(spec)
    if path.is_dir():
        src = path / "src" if (path / "src" / "tmem").is_dir() else path
        if not (src / "tmem").is_dir():
            sys.exit(f"{spec}: no src/tmem there")
        return src.resolve(), f"{path.resolve()} (working tree)", None
    src, commit = checkout(spec, scratch, label)
    return src, f"{spec} = {commit[:10]}", src.parent


# --- the run -------------------------------------------------------------------------------------


def measure(workload: Workload, sides: dict[str, Path], repeat: int, scratch: Path) -> dict:
    """Warm up both sides, then ``repeat`` rounds of old, new; the figures and the load average."""
    load = [os.getloadavg()[0]]
    if workload.warm_up:
        for src in sides.values():
            workload.run(src, scratch)
    values: dict[str, list[float]] = {label: [] for label in sides}
    for _ in range(repeat):
        for label, src in sides.items():
            values[label].append(workload.run(src, scratch))
    load.append(os.getloadavg()[0])
    old, new = (statistics.median(values[label]) for label in ("old", "new"))
    return {
        "workload": workload.name,
        "unit": workload.unit,
        "old": values["old"],
        "new": values["new"],
        "old_median": old,
        "new_median": new,
        "ratio": new / old if workload.rate else old / new,
        "load_1min": load,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--old", help="git ref of the old code")
    parser.add_argument("--new", default=str(ROOT), help="directory (with src/tmem) or git ref of the new code")
    parser.add_argument("--repeat", type=int, default=5, help="timed rounds of old and new per workload")
    parser.add_argument("--workloads", nargs="+", choices=[w.name for w in WORKLOADS], help="only these")
    parser.add_argument("--quick", action="store_true", help="one round of the small workloads (a smoke test)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    parser.add_argument("--child", choices=list(CHILDREN), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(f"RESULT {CHILDREN[args.child]()!r}")
        return
    if not args.old:
        parser.error("--old is required")
    repeat = 1 if args.quick else args.repeat
    chosen = [w for w in WORKLOADS if (not args.workloads or w.name in args.workloads) and (w.quick or not args.quick)]

    scratch = Path(tempfile.mkdtemp(prefix="bench_core-"))
    worktrees = []
    try:
        old_src, old_text, tree = side(args.old, scratch, "old")
        worktrees.append(tree)
        new_src, new_text, tree = side(args.new, scratch, "new")
        worktrees.append(tree)
        sides = {"old": old_src, "new": new_src}
        header = {
            "command": shlex.join([Path(sys.executable).name, *sys.argv]),
            "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version(),
                        "numba_num_threads": os.environ.get("NUMBA_NUM_THREADS")},
            "old": old_text,
            "new": new_text,
            "repeat": repeat,
        }  # fmt: skip
        print(f"old: {old_text}\nnew: {new_text}")
        print(f"machine: {os.cpu_count()} cores, {platform.platform()}; {repeat} round(s) of old, new per workload")
        print(f"command: {header['command']}\n")
        print(f"{'workload':<11} {'unit':<14} {'old median':>11} {'new median':>11} {'new/old':>8}  load avg")
        rows = []
        for workload in chosen:
            r = measure(workload, sides, repeat, scratch)
            rows.append(r)
            print(f"{r['workload']:<11} {r['unit']:<14} {r['old_median']:>11.4g} {r['new_median']:>11.4g} "
                  f"{r['ratio']:>8.3f}  {r['load_1min'][0]:.1f} -> {r['load_1min'][1]:.1f}", flush=True)  # fmt: skip
        print("\nnew/old is the throughput ratio: > 1 means new is faster (for times in s, old / new).")
        if args.json:
            args.json.parent.mkdir(parents=True, exist_ok=True)
            args.json.write_text(json.dumps({**header, "workloads": rows}, indent=2) + "\n")
    finally:
        for tree in worktrees:
            if tree is not None:
                git("worktree", "remove", "--force", str(tree))
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
