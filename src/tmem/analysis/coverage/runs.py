"""The coverage of a run (:mod:`tmem.analysis.coverage`): the metric on a run's walled box with its
``[coverage]`` table, and the figures of it written to ``summary.json``.
"""

from __future__ import annotations

from tmem.analysis.coverage.metric import Coverage, coverage


def run_coverage(trajectory) -> Coverage | None:
    """The coverage of a run's walled box (:func:`~tmem.analysis.coverage.metric.coverage` on its recorded
    agents), with the cell and sensor radius of its ``[coverage]`` table (default: cells of side
    ``R``, coarser where ``R`` would cut the box into more than
    :data:`~tmem.analysis.coverage.grid.DEFAULT_CELLS` cells: :attr:`tmem.scenario.Scenario.coverage_cell`;
    sensor radius 0); ``None`` when the run has no walled box or recorded nothing.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    scenario = trajectory.scenario
    if not scenario.space.walls or not len(trajectory.time) or not trajectory.state.shape[1]:
        return None
    settings = scenario.coverage
    cell = scenario.coverage_cell
    radius = 0.0 if settings is None else settings.sensor_radius
    obstacles = [(o.center[:2], o.radius) for o in scenario.obstacles]
    return coverage(trajectory.state[..., 0], trajectory.time, trajectory.active, scenario.space.box, cell,
                    obstacles, radius, periodic=False)  # fmt: skip


def coverage_summary(trajectory) -> dict | None:
    """The share of the field covered at the end and the times to cover half and 90 % of it, as
    written to ``summary.json``; ``None`` where :func:`run_coverage` is.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    found = run_coverage(trajectory)
    if found is None:
        return None
    return {
        "cell": found.cell,
        "cells": int(found.field.sum()),
        "share_final": float(found.share[-1]),
        "time_to_50": found.time_to(0.5),
        "time_to_90": found.time_to(0.9),
    }
