"""The figures of docs/missions.md: the shipped missions over seeds, each figure as its median and worst.

Prints Markdown tables to standard output::

    python docs/scripts/missions.py              # every part, about 40 minutes on 2 cores
    python docs/scripts/missions.py route        # the hex's 1 km route: linear model, quadrotor with sensing
    python docs/scripts/missions.py obstacles    # the hex through 20 random obstacle fields
    python docs/scripts/missions.py assembly     # 19 and 61 agents assembled from 20 random starts
    python docs/scripts/missions.py reshape      # the hex turned into a line and back in flight

Every figure is computed from the run's recorded states and its summary (``summary.json``'s
``safety``, :mod:`tmem.analysis.safety`): edge errors |P_j - P_i| - d_t of the formation pairs, near
misses at the 3 m safety radius (once per encounter, passes between records included), the least
clearance to an obstacle's edge, the distance of the group's centre to the goal at the end.
"""

from __future__ import annotations

import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import tmem
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

EXAMPLES = Path(__file__).resolve().parent.parent.parent / "examples" / "missions"
#: The seeds of the random parts: sensing noise, obstacle fields, scattered starts.
SEEDS = range(1, 21)
#: The seeds of the quadrotor's route (each run takes minutes).
QUADROTOR_SEEDS = range(1, 11)


def _median_worst(values: list[float], form: str, worst=max) -> str:
    """``median / worst`` of ``values`` (the worst by ``worst``)."""
    return f"{form.format(float(np.median(values)))} / {form.format(worst(values))}"


def _flown(scenario) -> dict:
    """What one run measured: the summary's safety figures, the edge errors, the end."""
    trajectory = tmem.simulate(scenario)
    summary = summarize(trajectory)
    errors = np.abs(trajectory.pair_distance - trajectory.d_t)
    within = np.flatnonzero(errors.max(axis=1) >= 0.1)
    return {"safety": summary["safety"], "edge_max": float(errors.max()), "edge_final": float(errors[-1].max()),
            "edge_within_0.1_from": float(trajectory.time[within[-1] + 1]) if within.size and within[-1] + 1 < len(trajectory.time)
            else (None if within.size else float(trajectory.time[0])),
            "coupled_end": summary["pairs_coupled_at_end"], "pairs": len(trajectory.pairs),
            "centre_end": trajectory.model.position(trajectory.final_state).mean(axis=0).tolist()}  # fmt: skip


def _run_all(scenarios: list) -> list[dict]:
    with ProcessPoolExecutor(max_workers=2) as pool:
        return list(pool.map(_flown, scenarios))


def route() -> None:
    """The hex's 1 km route with three turns at 5 m/s: (2) exactly known, and the quadrotor sensing at 100 Hz."""
    linear = _flown(tmem.load(EXAMPLES / "hex19_route.toml"))
    base = tmem.load(EXAMPLES / "hex19_route_quadrotor.toml")
    quad = _run_all([with_changes(base, {"sensing.seed": seed}) for seed in QUADROTOR_SEEDS])
    print("| model | largest edge error (m) | goal missed by (m) | near misses at 3 m | smallest separation (m) |")
    print("| --- | --- | --- | --- | --- |")
    for name, runs in (("linear (2), exact knowledge (no randomness: one run)", [linear]),
                       (f"quadrotor, sensing 100 Hz, 0.1 m noise, seeds {QUADROTOR_SEEDS.start}-{QUADROTOR_SEEDS.stop - 1}", quad)):
        missed = [float(np.linalg.norm(np.subtract(r["centre_end"], [500.0, 500.0]))) for r in runs]
        print(f"| {name} | {_median_worst([r['edge_max'] for r in runs], '{:.3g}')} | {_median_worst(missed, '{:.3g}')} | "
              f"{_median_worst([r['safety']['near_misses'] for r in runs], '{:.0f}')} | "
              f"{_median_worst([r['safety']['min_separation'] for r in runs], '{:.2f}', min)} |")  # fmt: skip


def obstacles() -> None:
    """The hex to a goal 1.6 km away through 20 random fields of 10 obstacles in a corridor 300 m wide."""
    from tmem.plan.fields import random_discs

    base = tmem.load(EXAMPLES / "hex19_obstacles.toml")
    scenarios = []
    for seed in SEEDS:
        centres, radii = random_discs(10, [300.0, -150.0], [1300.0, 150.0], (20.0, 60.0), gap=10.0, seed=seed)
        scenarios.append(with_changes(base, {"obstacles": [{"center": c.tolist(), "radius": float(r)} for c, r in zip(centres, radii)]}))
    runs = _run_all(scenarios)
    clearance = [r["safety"]["min_obstacle_clearance"] for r in runs]
    print(f"Fields of seeds {SEEDS.start}-{SEEDS.stop - 1}; each cell: median / worst.\n")
    print("| breaches | least clearance (m) | near misses at 3 m | largest edge error (m) | pairs uncoupled at the end | time to goal (s) |")
    print("| --- | --- | --- | --- | --- | --- |")
    print(f"| {sum(c < 0 for c in clearance)} of {len(runs)} runs | {_median_worst(clearance, '{:.2f}', min)} | "
          f"{_median_worst([r['safety']['near_misses'] for r in runs], '{:.0f}')} | {_median_worst([r['edge_max'] for r in runs], '{:.2g}')} | "
          f"{_median_worst([r['pairs'] - r['coupled_end'] for r in runs], '{:.0f}')} | "
          f"{_median_worst([r['safety']['time_to_goal'] for r in runs], '{:.1f}')} |")  # fmt: skip


def assembly() -> None:
    """19 and 61 agents at rest, at random in a 500 m square, assembled into the hex."""
    print(f"Starts of seeds {SEEDS.start}-{SEEDS.stop - 1}; each cell: median / worst.\n")
    print("| agents | every edge within 0.1 m of d_t from (s) | runs within 180 s | near misses at 3 m | smallest separation (m) "
          "| pairs coupled at the end |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name in ("hex19_assemble", "hex61_assemble"):
        base = with_changes(tmem.load(EXAMPLES / f"{name}.toml"), {"simulation.duration": 300.0})
        runs = _run_all([with_changes(base, {"formation.seed": seed}) for seed in SEEDS])
        times = [r["edge_within_0.1_from"] if r["edge_within_0.1_from"] is not None else np.inf for r in runs]
        print(f"| {base.n_agents} | {_median_worst(times, '{:.1f}')} | {sum(t <= 180.0 for t in times)} of {len(runs)} | "
              f"{_median_worst([r['safety']['near_misses'] for r in runs], '{:.0f}')} | "
              f"{_median_worst([r['safety']['min_separation'] for r in runs], '{:.2f}', min)} | "
              f"{_median_worst([r['coupled_end'] for r in runs], '{:.0f}', min)} of {runs[0]['pairs']} |")  # fmt: skip


def _reshaped(scenario) -> dict:
    """One reshaping run: for each shape taken, when its edges are all within 0.1 m of d_t for good (s after
    the leg's start), its largest edge error and direction error at the end of the shape's time."""
    from tmem.terms.navigation_plan import held_pairs, shapes_flown

    trajectory = tmem.simulate(scenario)
    members, directions = held_pairs(scenario, trajectory.pairs, trajectory.time)
    p = trajectory.model.position(trajectory.state)
    delta = p[:, trajectory.pairs[:, 1]] - p[:, trajectory.pairs[:, 0]]
    error = np.where(members, np.abs(np.linalg.norm(delta, axis=-1) - trajectory.d_t), 0.0)
    angle = np.degrees(np.arccos(np.clip(np.sum(delta * np.nan_to_num(directions), axis=-1) / np.linalg.norm(delta, axis=-1), -1, 1)))
    angle = np.where(members & ~np.isnan(directions[..., 0]), angle, 0.0)
    legs, shapes = scenario.navigation.legs, shapes_flown(scenario)[1:]
    found = []
    for k, shape in enumerate(shapes):
        start = legs[shape.leg].time
        end = legs[shapes[k + 1].leg].time if k + 1 < len(shapes) else trajectory.time[-1]
        during = (trajectory.time >= start) & (trajectory.time < end - 1e-9) | (trajectory.time == trajectory.time[-1]) & (k + 1 == len(shapes))
        outside = np.flatnonzero(during & (error.max(axis=1) >= 0.1))
        last = np.flatnonzero(during)[-1]
        settled = trajectory.time[outside[-1] + 1] - start if outside.size and outside[-1] < last else (np.inf if outside.size else 0.0)
        found.append({"shape": legs[shape.leg].shape, "span": shape.span, "settled": float(settled),
                      "edge_end": float(error[last].max()), "angle_end": float(angle[last].max())})
    summary = summarize(trajectory)["safety"]
    return {"shapes": found, "near_misses": summary["near_misses"], "min_separation": summary["min_separation"]}


def reshape() -> None:
    """The hex flying east turns into a line and back: (2) exactly known, and with sensing at 100 Hz, 0.1 m of noise."""
    base = tmem.load(EXAMPLES / "hex19_reshape.toml")
    noisy = {"period": 0.01, "position_noise": 0.1, "own_position_noise": 0.1}
    exact = [_reshaped(base)]
    with ProcessPoolExecutor(max_workers=2) as pool:
        sensed = list(pool.map(_reshaped, [with_changes(base, {"sensing": {**noisy, "seed": seed}}) for seed in SEEDS]))
    print("| knowledge | shape | lines' span T (s) | every edge within 0.1 m of d_t from (s after the leg starts) | largest edge error at the shape's end (m) "
          "| largest direction error then (deg) | near misses at 3 m (whole run) | smallest separation (m) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, runs in (("exact (one run)", exact), (f"sensing 100 Hz, 0.1 m noise, seeds {SEEDS.start}-{SEEDS.stop - 1}", sensed)):
        for k, shape in enumerate(runs[0]["shapes"]):
            cells = [[r["shapes"][k][key] for r in runs] for key in ("settled", "edge_end", "angle_end")]
            print(f"| {name} | {shape['shape']} | {shape['span']:.1f} | {_median_worst(cells[0], '{:.1f}')} | "
                  f"{_median_worst(cells[1], '{:.3g}')} | {_median_worst(cells[2], '{:.3g}')} | "
                  f"{_median_worst([r['near_misses'] for r in runs], '{:.0f}')} | "
                  f"{_median_worst([r['min_separation'] for r in runs], '{:.2f}', min)} |")  # fmt: skip


PARTS = {"route": route, "obstacles": obstacles, "assembly": assembly, "reshape": reshape}

if __name__ == "__main__":
    for part in sys.argv[1:] or PARTS:
        print(f"\n## {part}\n")
        PARTS[part]()
