"""TMEM beside Olfati-Saber's and Vásárhelyi's flocking laws on the missions' tasks (docs/missions.md).

Prints Markdown tables to standard output, each cell the median / worst over 20 seeds::

    python docs/scripts/compare_missions.py              # every task, about 17 minutes on 2 cores
    python docs/scripts/compare_missions.py route        # the hex's 1 km route (starts jittered by up to 1 m)
    python docs/scripts/compare_missions.py obstacles    # 20 random fields of 10 obstacles
    python docs/scripts/compare_missions.py assembly     # 19 agents from 20 random starts

The TMEM law flies the shipped missions (examples/missions/: hex19_route, hex19_obstacles,
hex19_assemble). The flocking laws fly the same agents from the same starts on the same vehicle and
time step, alone (``interaction.function = "none"``; the engine's obstacle push (W1) reaches 0.25 m),
each led by a reference that flies the mission: Olfati-Saber's γ-agent (OS 24, c1 = 0.05 /s^2,
c2 = 3 /s; its α-lattice at d = d_t = 35 m) and Vásárhelyi's goal (SwarmLab's goal mode, v_flock =
6 m/s; repulsion from r0_rep = d_t = 35 m, robotsim's other parameters), flying the route at 5 m/s;
for the obstacle field, the route TMEM's mission plans round it (N4) (their own β-agents and shill
agents keep them off the obstacles); for the assembly, fixed at the shape's centre.

Every figure is computed the same way for every law, from the recorded states: near misses at 3 m
(once per encounter) and the least separation; groups at most at once at the
communication range of 100 m (robotsim's), and the groups at the end; the order (velocity
correlation) from 20 s until the reference arrives (none for the assembly, whose agents end at
rest); the least clearance to an obstacle; the time the group's
centre comes within 2 m of the goal and stays; and the spacing error at the end, the largest
|d_nn - 35 m| of an agent's nearest neighbour (0 for a perfect hex or α-lattice at 35 m).
"""

from __future__ import annotations

import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import tmem
from tmem.analysis.field_metrics import order, time_to_goal, union
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

EXAMPLES = Path(__file__).resolve().parent.parent.parent / "examples" / "missions"
SEEDS = range(1, 21)
SPEED = 5.0  # m/s, the missions' speed
D_T = 35.0  # m
LAWS = ("TMEM (11), (N1)-(N5)", "Olfati-Saber, γ-agent on the mission", "Vásárhelyi, goal on the mission")
MEASURED = {"safety.range": 100.0}


def _flocking(base, law: int, starts: np.ndarray, route: list, duration: float):
    """``base`` flown by flocking law ``law`` (1: Olfati-Saber, 2: Vásárhelyi) from ``starts``, led along ``route``."""
    settings = [
        ("olfati_saber", {"d": D_T, "c1": 0.05, "c2": 3.0, "route": route, "route_speed": SPEED}),
        ("vasarhelyi", {"r0_rep": D_T, "r0_frict": D_T + 10.0, "v_flock": 6.0, "route": route, "route_speed": SPEED}),
    ][law - 1]
    return with_changes(base, {
        "formation": None, "navigation": None, "interaction.function": "none", "interaction.radius": 0.25,
        "interaction.d_t": 0.25, "space.wall_radius": 0.001, "agents": [{"position": p.tolist()} for p in starts],
        "simulation.duration": duration, settings[0]: settings[1], **MEASURED,
    })  # fmt: skip


def _scenarios(base, law: int, route: list, duration: float):
    """The scenario law ``law`` (0: TMEM) flies: the mission as shipped, or a flocking law from its starts."""
    from tmem.world.initial import formation_positions

    if law == 0:
        return with_changes(base, {"simulation.duration": duration, **MEASURED})
    return _flocking(base, law, formation_positions(base), route, duration)


def _measured(job) -> dict:
    """One run's figures (module text)."""
    scenario, goal, flying = job
    trajectory = tmem.simulate(scenario)
    safety = summarize(trajectory)["safety"]
    p = trajectory.model.position(trajectory.state)
    gaps = np.linalg.norm(p[-1][:, None] - p[-1][None], axis=-1) + np.diag(np.full(p.shape[1], np.inf))
    reached = time_to_goal(p, trajectory.time, np.asarray(goal, float), 2.0)
    return {"near": safety["near_misses"], "separation": safety["min_separation"], "groups": safety["union_max"],
            "groups_end": int(union(p[-1:], 100.0)[0]),
            "order": _order_while_flying(trajectory, flying), "clearance": safety["min_obstacle_clearance"],
            "goal": np.inf if reached is None else reached, "spacing": float(np.abs(gaps.min(axis=1) - D_T).max())}  # fmt: skip


def _order_while_flying(trajectory, flying: float | None) -> float:
    """The mean order (velocity correlation) from 20 s until the reference arrives at ``flying`` (s); NaN for none."""
    if flying is None:
        return float("nan")
    window = (trajectory.time >= 20.0) & (trajectory.time <= flying)
    return float(np.nanmean(order(trajectory.model.velocity(trajectory.state)[window])))


def _cell(values, form: str, worst=max) -> str:
    """``median / worst`` of ``values``; a dash where none is measured."""
    if all(np.isnan(v) for v in values):
        return "—"
    return f"{form.format(float(np.median(values)))} / {form.format(worst(values))}"


def _table(jobs_per_law: list[list], obstacles: bool) -> None:
    with ProcessPoolExecutor(max_workers=2) as pool:
        runs = [list(pool.map(_measured, jobs)) for jobs in jobs_per_law]
    head = ["law", "near misses at 3 m", "least separation (m)", "most groups", "groups at the end", "order while flying",
            "time to goal (s)", "spacing error at the end (m)"]
    head += ["breaches", "least obstacle clearance (m)"] if obstacles else []
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * len(head))
    for name, found in zip(LAWS, runs):
        cells = [_cell([r["near"] for r in found], "{:.0f}"), _cell([r["separation"] for r in found], "{:.2f}", min),
                 _cell([r["groups"] for r in found], "{:.0f}"), _cell([r["groups_end"] for r in found], "{:.0f}"),
                 _cell([r["order"] for r in found], "{:.2f}", min),
                 _cell([r["goal"] for r in found], "{:.1f}"), _cell([r["spacing"] for r in found], "{:.2f}")]  # fmt: skip
        if obstacles:
            clearance = [r["clearance"] for r in found]
            cells += [f"{sum(c < 0 for c in clearance)} of {len(found)}", _cell(clearance, "{:.1f}", min)]
        print(f"| {name} | " + " | ".join(cells) + " |")


def route() -> None:
    """The hex's 1 km route with three turns at 5 m/s, its starts jittered by up to 1 m (seeds 1-20), 400 s."""
    base = tmem.load(EXAMPLES / "hex19_route.toml")
    waypoints = [list(w) for w in base.navigation.legs[0].waypoints]
    route = [[0.0, 0.0], *waypoints]
    flying = float(np.sum(np.linalg.norm(np.diff(route, axis=0), axis=1))) / SPEED
    jobs = [[(_scenarios(with_changes(base, {"formation.jitter": 1.0, "formation.seed": seed}), law, route, 400.0),
              waypoints[-1], flying) for seed in SEEDS] for law in range(3)]  # fmt: skip
    print(f"Starts jittered by up to 1 m, seeds {SEEDS.start}-{SEEDS.stop - 1}; each cell: median / worst.\n")
    _table(jobs, obstacles=False)


def obstacles() -> None:
    """To a goal 1.6 km away through 20 random fields of 10 obstacles in a corridor 300 m wide, 600 s."""
    from tmem.plan.fields import random_discs
    from tmem.terms.navigation_plan import planned_points

    base = tmem.load(EXAMPLES / "hex19_obstacles.toml")
    goal = list(base.navigation.legs[0].target)
    jobs = [[], [], []]
    for seed in SEEDS:
        centres, radii = random_discs(10, [300.0, -150.0], [1300.0, 150.0], (20.0, 60.0), gap=10.0, seed=seed)
        field = with_changes(base, {"obstacles": [{"center": c.tolist(), "radius": float(r)} for c, r in zip(centres, radii)]})
        planned = [[0.0, 0.0], *planned_points(field)[0][2].tolist()]  # TMEM's route round the field (N4)
        flying = float(np.sum(np.linalg.norm(np.diff(planned, axis=0), axis=1))) / SPEED
        for law in range(3):
            jobs[law].append((_scenarios(field, law, planned, 600.0), goal, flying))
    print(f"Fields of seeds {SEEDS.start}-{SEEDS.stop - 1}; each cell: median / worst.\n")
    _table(jobs, obstacles=True)


def assembly() -> None:
    """19 agents at rest from random starts in a 500 m square (seeds 1-20) to the hex at the origin, 400 s."""
    base = tmem.load(EXAMPLES / "hex19_assemble.toml")
    centre = list(base.formation.center)
    jobs = [[(_scenarios(with_changes(base, {"formation.seed": seed}), law, [centre], 400.0), centre, None) for seed in SEEDS]
            for law in range(3)]  # fmt: skip
    print(f"Starts of seeds {SEEDS.start}-{SEEDS.stop - 1}; each cell: median / worst.\n")
    _table(jobs, obstacles=False)


PARTS = {"route": route, "obstacles": obstacles, "assembly": assembly}

if __name__ == "__main__":
    for part in sys.argv[1:] or PARTS:
        print(f"\n## {part}\n")
        PARTS[part]()
