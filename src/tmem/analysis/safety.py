"""A run's safety and the field's figures, as ``summary.json`` holds them under ``"safety"``.

Where a scenario has a ``[safety]`` table (:mod:`tmem.scenario.safety_table`), the summary gives the
figures of :func:`tmem.analysis.field_metrics.field_summary` on the recorded states: near misses at
the safety radius (counted once per encounter, passes between two records included), collisions,
the smallest separation, the clearance to obstacles and walls, order, groups and algebraic
connectivity at the communication range, the formation's edge errors and its distance to the
target shape (translation and rotation aside), and the time the group's centre takes to reach a
mission's goal; beside them the safety radius and the closing-speed limit (M1).
"""

from __future__ import annotations

import numpy as np

from tmem.engine import Trajectory

#: How close the group's centre must come to a mission's goal, and stay, to have reached it (m).
GOAL_TOLERANCE = 2.0


def _goal(scenario) -> np.ndarray | None:
    """The last point of a mission's last leg that has one (``None`` without a mission)."""
    if getattr(scenario, "navigation", None) is None:
        return None
    from tmem.terms.navigation_plan import planned_points

    points = [p for _, _, p in planned_points(scenario) if len(p)]
    return points[-1][-1] if points else None


def _target(trajectory: Trajectory) -> np.ndarray | None:
    """The formation's shape at the end, agent by agent, where the run has a generated one and records every agent."""
    from tmem.world.formation import generate

    scenario, f = trajectory.scenario, trajectory.scenario.formation
    if f is None or f.kind == "edges" or len(trajectory.agents) != scenario.n_agents:
        return None
    if scenario.reshapes:
        from tmem.terms.navigation_plan import shapes_flown

        return shapes_flown(scenario)[-1].places
    return generate(f.kind, scenario.n_agents, f.d_t or scenario.interaction.d_t, scenario.space.axes, f.bearing).positions


def safety_summary(trajectory: Trajectory) -> dict | None:
    """``summary.json``'s ``"safety"``: the radius, the closing-speed limit (M1) and
    :func:`~tmem.analysis.field_metrics.field_summary`'s figures; ``None`` without a ``[safety]`` table.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    from tmem.analysis.field_metrics import field_summary
    from tmem.scenario.safety_table import closing_speed_limit
    from tmem.terms.navigation_plan import held_pairs

    scenario = trajectory.scenario
    safety = scenario.safety
    if safety is None:
        return None
    every_agent = len(trajectory.agents) == scenario.n_agents
    sensing_range = scenario.sensing.range if scenario.sensing is not None else None
    obstacles = scenario.obstacles
    goal = _goal(scenario)
    figures = field_summary(
        trajectory.model.position(trajectory.state), trajectory.model.velocity(trajectory.state), trajectory.time,
        trajectory.active,
        edges=trajectory.pairs if every_agent and len(trajectory.pairs) else None, d_t=trajectory.d_t,
        members=held_pairs(scenario, trajectory.pairs, trajectory.time)[0] if every_agent and scenario.shapes_change else None,
        target=_target(trajectory),
        obstacles=(np.array([o.center for o in obstacles]), np.array([o.radius for o in obstacles])) if obstacles else None,
        box=np.asarray(scenario.space.box, dtype=float) if scenario.space.walls else None,
        safety_radius=safety.radius, collision_radius=safety.collision_radius,
        communication_range=safety.range or sensing_range or scenario.interaction.reach,
        goal=goal, goal_tolerance=GOAL_TOLERANCE if goal is not None else None,
    )  # fmt: skip
    return {"radius": safety.radius, "closing_speed_limit": closing_speed_limit(scenario), **figures}
