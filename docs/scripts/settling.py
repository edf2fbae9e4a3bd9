"""The figures of "Formations that settle" in docs/swarms.md and of the settled hex in docs/vehicles.md,
over seeds of the formations' start.

Prints Markdown tables to standard output::

    python docs/scripts/settling.py              # every part, about 11 minutes on 2 cores once compiled
    python docs/scripts/settling.py formations   # the four *_settled formations on the linear model (2)
    python docs/scripts/settling.py chain_tail   # the chain's largest RMS change over seeds 1-60
    python docs/scripts/settling.py quadrotor    # the settled hex on the quadrotor, under each inner loop

Each formation is flown from :data:`SEEDS` jittered starts (``formation.seed``: every agent up to 1 m
off its place), with synchronisation and without, and every figure is given as its median and its
worst over them.  The figures are the summary's (:func:`tmem.analysis.metrics.summarize`):
``settling_time``, ``residual_error``, ``rms_change_peak_percent`` (the largest change of the RMS
velocity from the start, over the recorded times) and ``rms_change_percent`` (end against start).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from survive import on_quadrotor, tilt_loop  # noqa: E402

import tmem  # noqa: E402
from tmem.analysis.metrics import summarize  # noqa: E402
from tmem.scenario import with_changes  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent.parent.parent / "examples" / "swarm"
#: The seeds of the formations' start.
SEEDS = range(1, 21)
FORMATIONS = {"triangle": "triangle", "hex, 19 agents": "hex19", "chain of 5 (directions held)": "chain5",
              "ring of 8, agent 3 lost at 20 s": "ring8_loss"}  # fmt: skip


def _median_worst(values: list[float | None], form: str, size: bool = False) -> str:
    """``median / worst (seed s)`` of ``values``, one per seed of :data:`SEEDS`, the worst the largest in
    magnitude, the median of the magnitudes with ``size``; a value of None (never settled) is the
    worst, "never"."""
    if any(v is None for v in values):
        finite = [v for v in values if v is not None]
        median = form.format(np.median(finite)) if 2 * len(finite) > len(values) else "never"
        return f"{median} / never ({len(values) - len(finite)} of {len(values)} seeds)"
    k = int(np.argmax(np.abs(values)))
    median = np.median(np.abs(values) if size else values)
    return f"{form.format(median)} / {form.format(values[k])} (seed {SEEDS[k]})"


def _summaries(scenario, seeds=SEEDS) -> list[dict]:
    return [summarize(tmem.simulate(with_changes(scenario, {"formation.seed": seed}))) for seed in seeds]


def formations() -> None:
    """The four formations of docs/swarms.md, synchronised, and the same unsynchronised, on (2)."""
    print(f"Seeds {SEEDS.start}-{SEEDS.stop - 1} of the start; each cell: median / worst.\n")
    print("| formation | settled (every coupled pair within 0.1 m of d_t) (s) | residual error at 60 s (m) | "
          "largest RMS change on the way, size (%) | RMS change, end against start (%) | without synchronisation: "
          "end against start (%) |")  # fmt: skip
    print("| --- | --- | --- | --- | --- | --- |")
    for label, name in FORMATIONS.items():
        settled = tmem.load(EXAMPLES / f"{name}_settled.toml")
        synchronised = _summaries(settled)
        free = _summaries(with_changes(settled, {"interaction.synchronise": False}))
        formation = [s["formation"] for s in synchronised]
        print(f"| {label} | {_median_worst([f['settling_time'] for f in formation], '{:.1f}')} | "
              f"{_median_worst([f['residual_error'] for f in formation], '{:.4f}')} | "
              f"{_median_worst([s['rms_change_peak_percent'] for s in synchronised], '{:.2f}', size=True)} | "
              f"{_median_worst([s['rms_change_percent'] for s in synchronised], '{:+.3f}')} | "
              f"{_median_worst([s['rms_change_percent'] for s in free], '{:+.2f}')} |", flush=True)  # fmt: skip


def chain_tail() -> None:
    """The synchronised chain's largest RMS change on the way from more starts: the worst grows with them."""
    chain = tmem.load(EXAMPLES / "chain5_settled.toml")
    for seeds in (SEEDS, range(1, 61)):
        peaks = [s["rms_change_peak_percent"] for s in _summaries(chain, seeds)]
        k = int(np.argmax(np.abs(peaks)))
        print(f"chain of 5, seeds {seeds.start}-{seeds.stop - 1}: largest RMS change on the way, median of sizes "
              f"{np.median(np.abs(peaks)):.2f} %, worst {peaks[k]:+.2f} % (seed {seeds[k]})")  # fmt: skip


def quadrotor() -> None:
    """The settled hex on the linear model (2) and on the quadrotor, each inner loop (docs/vehicles.md)."""
    hex19 = tmem.load(EXAMPLES / "hex19_settled.toml")
    quad = on_quadrotor(hex19)
    runs = {"linear (2)": hex19, "quadrotor, tilt loop": tilt_loop(quad), "quadrotor, acceleration loop": quad}
    print(f"hex19_settled, seeds {SEEDS.start}-{SEEDS.stop - 1} of the start; each cell: median / worst.\n")
    print("| vehicle | settled at (s) | largest edge error, last 20 s (m) | edge error at 60 s (m) | RMS change (%) |")
    print("| --- | --- | --- | --- | --- |")
    for name, scenario in runs.items():
        summaries = _summaries(scenario)
        formation = [s["formation"] for s in summaries]
        print(f"| {name} | {_median_worst([f['settling_time'] for f in formation], '{:.1f}')} | "
              f"{_median_worst([f['distance_error_last_20s']['max'] for f in formation], '{:.3f}')} | "
              f"{_median_worst([f['residual_error'] for f in formation], '{:.3f}')} | "
              f"{_median_worst([s['rms_change_percent'] for s in summaries], '{:+.3f}')} |", flush=True)  # fmt: skip


if __name__ == "__main__":
    started = time.perf_counter()
    for part in [globals()[name] for name in sys.argv[1:]] or (formations, chain_tail, quadrotor):
        print(f"\n## {part.__name__}\n", flush=True)
        part()
    print(f"{time.perf_counter() - started:.0f} s", file=sys.stderr)
