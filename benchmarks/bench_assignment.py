"""CAPT's assignment at scale: the time to assign N agents in the plane to a hexagonal patch of N slots.

For each N (default 10^2, 10^3, 10^4) the goals are :func:`tmem.plan.shapes.hex_slots` of N slots
``--spacing`` apart and the starts N uniform random points in the square twice as wide as the
patch, about the same centre (seeded).  Prints the median over ``--repeat`` runs of
:func:`tmem.plan.assignment.assign` (the dense N x N matrix of squared distances, then
:func:`scipy.optimize.linear_sum_assignment`) and of the matrix alone (the solver: the difference),
the peak memory of the first run as :mod:`tracemalloc` sees it (NumPy reports its arrays to it),
and at the end the process's largest resident set.  The cost matrix alone is ``8 N^2`` bytes,
800 MB at N = 10^4.

Measured on 2 cores (NumPy 2.4, SciPy 1.17), one run each, the machine shared (load average 3.7
to 5): N = 10^4 took 427 s and 559 s (the matrix 0.24-0.27 s, the rest the solver), a traced peak
of 800 MB and a resident set of 868-871 MB; N = 10^3 0.25-0.66 s; N = 10^2 0.6-0.7 ms.  The
solver's time grew about as N^3 here (starts spread over four times the patch's area): at 10^4
agents and beyond, a sparse matching on each start's nearest goals is the way, at the price of
optimality.

Usage::

    PYTHONPATH=src python benchmarks/bench_assignment.py [--sizes 100 1000 10000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import time
import tracemalloc

import numpy as np
from scipy.spatial.distance import cdist

from tmem.plan.assignment import assign
from tmem.plan.shapes import hex_slots


def _case(n: int, spacing: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """N random starts and the N slots of a hexagonal patch (m)."""
    goals = hex_slots(n, spacing).offsets
    half = np.abs(goals).max()
    starts = np.random.default_rng(seed).uniform(-2 * half, 2 * half, (n, 2))
    return starts, goals


def _timed(starts: np.ndarray, goals: np.ndarray, trace: bool) -> tuple[float, float, int]:
    """Seconds of one ``assign`` and of building its cost matrix alone; the traced peak (bytes) if ``trace``."""
    if trace:
        tracemalloc.start()
    try:
        begin = time.perf_counter()
        assign(starts, goals)
        whole = time.perf_counter() - begin
        peak = tracemalloc.get_traced_memory()[1] if trace else 0
    finally:
        if trace:
            tracemalloc.stop()
    begin = time.perf_counter()
    cdist(starts, goals, "sqeuclidean")
    return whole, time.perf_counter() - begin, peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 1000, 10_000], help="numbers of agents")
    parser.add_argument("--repeat", type=int, default=3, help="runs per size; the median is printed")
    parser.add_argument("--spacing", type=float, default=5.0, help="the hex patch's spacing (m)")
    parser.add_argument("--seed", type=int, default=1, help="the starts' seed")
    args = parser.parse_args()
    assign(*_case(7, args.spacing, args.seed))  # imports SciPy's solver outside the timings and the traced peak
    print(f"{os.cpu_count()} CPUs; NumPy {np.__version__}; median of {args.repeat} runs")
    print(f"{'N':>7} {'assign (s)':>11} {'matrix (s)':>11} {'solver (s)':>11} {'matrix (MB)':>12} {'peak (MB)':>10}")
    for n in args.sizes:
        starts, goals = _case(n, args.spacing, args.seed)
        runs = [_timed(starts, goals, trace=k == 0) for k in range(args.repeat)]
        whole, matrix = (statistics.median(part) for part in list(zip(*runs))[:2])
        solver, peak = whole - matrix, runs[0][2]
        print(f"{n:>7} {whole:>11.4f} {matrix:>11.4f} {solver:>11.4f} {8 * n * n / 1e6:>12.1f} {peak / 1e6:>10.1f}", flush=True)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3  # kB on Linux
    print(f"largest resident set of the process: {rss:.0f} MB")


if __name__ == "__main__":
    main()
