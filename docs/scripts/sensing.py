"""Fig. 9 under sensing effects: the RMS velocity change and the coupling and uncoupling times.

The ``fig9`` preset (improved switching (11), dt = 1e-4 s, uncouple command at t = 29 s) is run
exactly, then with one effect at a time (``docs/sensing.md``): noise on the neighbour's position or
velocity (or the agent's own) heard 10 times a second, messages 10 times a second without noise, a
fixed delay of every message, and the loss of messages sent 10 times a second.  Each noisy or lossy case runs with several seeds; the table gives the mean and, in
brackets, the smallest and largest value over them.  Prints the Markdown tables of
``docs/sensing.md``::

    python docs/scripts/sensing.py

The total runtime goes to standard error.
"""

from __future__ import annotations

import sys
import time

import numpy as np

import tmem
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

SEEDS = range(1, 6)
#: (label, the [sensing] table, whether it draws random numbers), one row each.
CASES = [
    ("exact", {}, False),
    ("position noise 0.3 m, every step", {"position_noise": 0.3}, True),
    *[(f"position noise {s:g} m, 10 Hz", {"position_noise": s, "period": 0.1}, True) for s in (0.1, 0.3, 1.0)],
    *[(f"velocity noise {s:g} m/s, 10 Hz", {"velocity_noise": s, "period": 0.1}, True) for s in (0.1, 0.3)],
    ("own position noise 0.3 m, 10 Hz", {"own_position_noise": 0.3, "period": 0.1}, True),
    ("messages at 10 Hz, exact", {"period": 0.1}, False),
    *[(f"delay {d * 1000:g} ms", {"delay": d}, False) for d in (0.001, 0.01, 0.05, 0.1, 0.2, 0.3)],
    *[(f"loss {p:g}, 10 Hz", {"loss": p, "period": 0.1}, True) for p in (0.2, 0.5)],
]
DASH = "—"


def figures(sensing: dict, seed: int) -> dict:
    """One run's RMS change (%), coupling and uncoupling times (s) and smallest distance (m)."""
    scenario = tmem.preset("fig9")
    if sensing:
        scenario = with_changes(scenario, {"sensing": {**sensing, "seed": seed}})
    summary = summarize(tmem.simulate(scenario))
    pair = summary["pairs"][0]
    return {"rms": summary["rms_change_percent"], "couple": pair["coupled_at"], "uncouple": pair["uncoupled_at"],
            "distance": pair["min_distance"]}  # fmt: skip


def cell(values: list, digits: int) -> str:
    """The mean, and with several runs the range in brackets; a dash where a run has none."""
    if any(v is None for v in values):
        return f"{DASH} in {sum(v is None for v in values)} of {len(values)}" if len(values) > 1 else DASH
    mean = f"{np.mean(values):.{digits}f}"
    return mean if len(values) == 1 else f"{mean} [{min(values):.{digits}f}, {max(values):.{digits}f}]"


def main() -> None:
    started = time.perf_counter()
    print("| Sensing | RMS change (%) | couples at (s) | uncouples at (s) | smallest distance (m) |")
    print("| --- | --- | --- | --- | --- |")
    for label, sensing, random in CASES:
        runs = [figures(sensing, seed) for seed in (SEEDS if random else [1])]
        row = [cell([r[key] for r in runs], digits) for key, digits in (("rms", 2), ("couple", 2), ("uncouple", 2),
                                                                         ("distance", 2))]  # fmt: skip
        print(f"| {label} | " + " | ".join(row) + " |")
    print(f"\n{len(SEEDS)} seeds for each noisy or lossy row.", file=sys.stderr)
    print(f"total {time.perf_counter() - started:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
