"""The figures of a run, in the layout of the paper's Figs. 5, 7 and 9, and where they are written.

Time series (this module):

* ``velocity.png``: each agent's velocity (its speed on several axes) and the RMS velocity against
  time;
* ``distance.png``: each pair's distance against time with ``R + R_j`` and ``d_t`` marked and the
  coupling events, above the flags ``F_en``;
* ``formation.png`` (formations): the distance error over the formation's pairs against time;
* ``gas.png`` (runs that observe their gas): the RMS velocity of every flying agent and the
  thermostat's set-point against time;
* ``field.png`` (2-D walled boxes): the coverage map, with the walls and obstacles
  (:mod:`tmem.analysis.coverage`).

The swarm in space (:mod:`tmem.figures.shape_plot`): ``paths.png``, every agent's path, and ``shape.png``
(2-D and 3-D runs), the agents and pairs at a few moments, pairs coloured by strain.

Agents are numbered from 1, as in the paper; which agents and pairs a figure draws, and the strain
colour scale, are :mod:`tmem.figures.drawing`'s.  :func:`write_figures` writes them at the end of ``tmem
run``; :func:`redraw` writes them again from a saved run (``tmem plot``), through the same function.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure  # not pyplot: writing a file needs no window and no figure manager

from tmem.analysis import metrics
from tmem.figures.drawing import (
    MAX_LEGEND, agent_colors, agent_label, agents_legend, closest_pairs, draw_region, first_agents, pair_label, run_title,
)  # fmt: skip
from tmem.engine import Trajectory
from tmem.analysis.observables import temperature
from tmem.files.outputs import check_directory, replace_directory, update_files
from tmem.files.saved import read_run
from tmem.figures.shape_plot import paths_figure, shape_figure
from tmem.files.trajectory_file import run_directory

#: Matplotlib's warning for a character its font lacks (a name in CJK, an emoji).
MISSING_GLYPH = r"Glyph \d+ .* missing from font"
#: Beyond this many events, only the operator's commands are marked.
MAX_EVENTS_MARKED = 32
_EVENT_STYLE = {"couple": ("tab:green", "-"), "uncouple": ("tab:red", "-"), "command": ("0.4", ":")}


def _mark_events(ax, trajectory: Trajectory) -> None:
    events = trajectory.events if len(trajectory.events) <= MAX_EVENTS_MARKED else [
        e for e in trajectory.events if e.kind == "command"
    ]  # fmt: skip
    seen = set()
    for e in events:
        color, style = _EVENT_STYLE[e.kind]
        ax.axvline(e.time, color=color, linestyle=style, linewidth=1, label=None if e.kind in seen else e.kind)
        seen.add(e.kind)


def _time_figure():
    """A figure of one plot against time, ``(fig, ax)``, as the velocity, formation and gas figures draw."""
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    return fig, fig.subplots()


def _finish_time_plot(ax, trajectory: Trajectory, ylabel: str, title: str, legend: bool = True) -> None:
    """The run's events marked on ``ax``, its axes labelled (time along x), ``title`` above it, a grid
    and, if ``legend``, the legend of its lines."""
    _mark_events(ax, trajectory)
    ax.set_xlabel("time, s")
    ax.set_ylabel(ylabel)
    ax.set_title(title, parse_math=False)
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(loc="best", fontsize=8)


def velocity_figure(trajectory: Trajectory):
    """Each agent's velocity (speed, on several axes) and the RMS velocity against time.

    Every recorded agent up to :data:`tmem.figures.drawing.MAX_LINES`, labelled ``agent 1``, ``agent 2``
    ...; past that, the first ones, and the title says so.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    fig, ax = _time_figure()
    t = trajectory.time
    velocity = trajectory.model.velocity(trajectory.state)
    one_axis = velocity.shape[2] == 1
    chosen = first_agents(velocity.shape[1])
    colors, mappable = agent_colors(trajectory.agents[chosen.index])
    for q, color in zip(chosen.index, colors):
        value = velocity[:, q, 0] if one_axis else np.linalg.norm(velocity[:, q], axis=1)
        ax.plot(t, value, color=color, linewidth=1.2 if mappable is None else 0.8, label=agent_label(trajectory.agents[q]))
    rms = metrics.rms_velocity(velocity, trajectory.active)
    ax.plot(t, rms, color="k", linestyle="--", linewidth=1.5, label="RMS velocity, every recorded agent")
    ylabel = "velocity V, m/s" if one_axis else "speed |V|, m/s"
    _finish_time_plot(ax, trajectory, ylabel, run_title(trajectory, chosen.note), legend=False)
    agents_legend(ax, mappable)
    return fig


def _flags(ax, trajectory: Trajectory, chosen) -> None:
    """``F_en`` of each drawn pair when they are few, else how many pairs are coupled."""
    t = trajectory.time
    if len(chosen.index) <= MAX_LEGEND:
        for p in chosen.index:
            ax.step(t, trajectory.flag[:, p], where="post", linewidth=1.2, label=pair_label(*trajectory.pairs[p]))
        ax.set_ylabel("F_en")
        ax.set_yticks([0, 1])
        ax.set_ylim(-0.1, 1.1)
        return
    total = trajectory.flag.shape[1]
    ax.step(t, np.sum(trajectory.flag == 1, axis=1), where="post", color="k", linewidth=1.2)
    ax.set_ylabel(f"pairs coupled\n(of {total})")
    ax.set_ylim(-0.05 * total, 1.05 * total)


def distance_figure(trajectory: Trajectory):
    """Each pair's distance with ``R + R_j`` and ``d_t``, above ``F_en``.

    Every pair up to :data:`tmem.figures.drawing.MAX_LINES`, labelled ``agents 1-2`` ...; past that, the
    ones that came closest, and the title says so.  Below, ``F_en`` of each pair, or, for more than
    :data:`tmem.figures.drawing.MAX_LEGEND` pairs, how many are coupled.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    fig = Figure(figsize=(8, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1))
    t = trajectory.time
    ia = trajectory.scenario.interaction
    chosen = closest_pairs(trajectory.min_distance)
    few = len(chosen.index) <= MAX_LEGEND
    for p in chosen.index:
        top.plot(t, trajectory.pair_distance[:, p], linewidth=1.2 if few else 0.7, label=pair_label(*trajectory.pairs[p]))
    top.axhline(ia.reach, color="tab:purple", linestyle="--", linewidth=1, label=f"R + R_j = {ia.reach:g} m")
    for d_t in np.unique(trajectory.d_t)[:3]:
        top.axhline(d_t, color="tab:olive", linestyle="--", linewidth=1, label=f"d_t = {d_t:g} m")
    _mark_events(top, trajectory)
    top.set_ylabel("distance |P_j - P_i|, m")
    note = chosen.note or ("" if few else f"all {chosen.total} pairs")
    top.set_title(run_title(trajectory, note), parse_math=False)
    top.grid(alpha=0.3)
    handles = [h for h in top.get_legend_handles_labels()[0] if few or not h.get_label().startswith("agents ")]
    top.legend(handles=handles, loc="best", fontsize=8)
    _flags(bottom, trajectory, chosen)
    bottom.set_xlabel("time, s")
    bottom.grid(alpha=0.3)
    return fig


def formation_figure(trajectory: Trajectory):
    """Distance error ``| |P_j - P_i| - d_t |`` over every coupled formation pair: mean, RMS and largest.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    fig, ax = _time_figure()
    coupled = trajectory.flag == 1
    error = np.where(coupled, np.abs(trajectory.pair_distance - trajectory.d_t), 0.0)
    count = coupled.sum(axis=1)
    some = count > 0
    t = trajectory.time[some]
    ax.plot(t, error[some].max(axis=1), color="tab:red", linewidth=1.2, label="largest")
    ax.plot(t, np.sqrt((error[some] ** 2).sum(axis=1) / count[some]), color="k", linewidth=1.5, label="RMS")
    ax.plot(t, error[some].sum(axis=1) / count[some], color="tab:blue", linewidth=1.2, label="mean")
    title = run_title(trajectory, f"over all {len(trajectory.pairs)} pairs of the formation, while coupled")
    _finish_time_plot(ax, trajectory, "| distance - d_t |, m (coupled pairs)", title)
    return fig


def gas_figure(trajectory: Trajectory):
    """The RMS velocity of every flying agent against time, and the thermostat's set-point.

    Parameters
    ----------
    trajectory : Trajectory
        A run that observed its gas.
    """
    fig, ax = _time_figure()
    ax.plot(trajectory.time, temperature(trajectory), color="k", linewidth=1.5, label="RMS velocity, all agents")
    scenario = trajectory.scenario
    settings = [(0.0, scenario.thermostat.rms_velocity if scenario.thermostat else None)]
    settings += [(c.time, c.value) for c in sorted(scenario.commands, key=lambda c: c.time) if c.action == "temperature"]
    if any(value is not None for _, value in settings):
        steps = [(t, v if v is not None else np.nan) for t, v in settings] + [(trajectory.time[-1], np.nan)]
        times = [t for t, _ in steps]
        values = [v for _, v in steps[:-1]] + [steps[-2][1]]
        ax.step(times, values, where="post", color="tab:red", linestyle="--", label="set-point")
    _finish_time_plot(ax, trajectory, "RMS velocity, m/s", run_title(trajectory))
    return fig


def field_figure(trajectory: Trajectory):
    """The coverage map of a 2-D walled box: when each cell was first visited, the walls, the obstacles.

    Parameters
    ----------
    trajectory : Trajectory
        A 2-D run in a walled box.
    """
    from tmem.analysis.coverage import plot_coverage, run_coverage

    found = run_coverage(trajectory)
    scenario = trajectory.scenario
    obstacles = [(o.center, o.radius) for o in scenario.obstacles]
    title = f"{run_title(trajectory)}\n{100 * found.share[-1]:.1f} % of the field covered"
    fig = plot_coverage(found, obstacles=obstacles, title=title)
    draw_region(fig.axes[0], scenario.space.box, True, ())
    return fig


def figures_of(trajectory: Trajectory) -> dict[str, Callable[[Trajectory], Figure]]:
    """The figures a run has, by file name, each with the function that draws it.

    ``velocity.png`` and ``paths.png`` when agents were recorded; ``distance.png`` when the run has
    pairs; ``formation.png`` for a formation; ``shape.png`` for 2-D and 3-D runs; ``gas.png`` for a
    run that observed its gas; ``field.png`` for a 2-D walled box.  None for a run that recorded no
    time.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`, or :func:`tmem.files.saved.read_run`).
    """
    scenario = trajectory.scenario
    agents = trajectory.state.shape[1] > 0 and len(trajectory.time) > 0
    pairs = len(trajectory.pairs) > 0 and len(trajectory.time) > 0
    wanted = {
        "velocity.png": (agents, velocity_figure),
        "distance.png": (pairs, distance_figure),
        "formation.png": (pairs and scenario.formation is not None, formation_figure),
        "paths.png": (agents, paths_figure),
        "shape.png": (agents and scenario.space.axes >= 2, shape_figure),
        "gas.png": (trajectory.gas.shape[1] > 0 and len(trajectory.time) > 0, gas_figure),
        "field.png": (agents and scenario.space.walls and scenario.space.axes == 2, field_figure),
    }
    return {name: draw for name, (has, draw) in wanted.items() if has}


def write_figures(trajectory: Trajectory, directory: Path) -> list[Path]:
    """Write the run's figures (:func:`figures_of`) into ``directory``.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`, or :func:`tmem.files.saved.read_run`).
    directory : Path
        An existing directory.

    Returns
    -------
    list of Path
        The files written.
    """
    paths = []
    for name, draw in figures_of(trajectory).items():
        fig = draw(trajectory)
        path = Path(directory) / name
        with warnings.catch_warnings():  # a name in a script the font lacks is drawn as boxes, without a warning per glyph
            warnings.filterwarnings("ignore", message=MISSING_GLYPH, category=UserWarning)
            fig.savefig(path, dpi=120)
        paths.append(path)
    return paths


def redraw(run_dir: str | Path, out: str | Path | None = None) -> list[Path]:
    """Draw a saved run's figures again (``tmem plot``): into the run directory, or into ``out``.

    The run is read back (:func:`tmem.files.saved.read_run`) and drawn by :func:`write_figures`, as at the
    end of ``tmem run``.  Into the run directory, the figures replace their namesakes all at once
    and are added to its manifest (:func:`tmem.files.outputs.update_files`); into ``out``, a directory
    of their own, written whole as any output (:func:`tmem.files.outputs.replace_directory`, marked as a
    ``plot`` output).  An error or an interruption leaves both as they were.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``tmem run`` (or a run of ``tmem paper``'s).
    out : str or Path, optional
        Where to write the figures instead; default: ``run_dir``.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    ValueError
        In one line: a folder that is not a run, a damaged file, an ``out`` that may not be written
        (:class:`tmem.files.trajectory_file.RunReadError`, :class:`tmem.files.outputs.OutputError`).
    """
    run_dir = run_directory(run_dir, "plot")
    in_place = out is None or Path(out).resolve() == run_dir.resolve()
    if not in_place:
        check_directory(out, "plot")
    trajectory = read_run(run_dir, "plot")
    target = run_dir if in_place else Path(out)
    writing = update_files(run_dir) if in_place else replace_directory(out, "plot")
    with writing as tmp:
        names = [path.name for path in write_figures(trajectory, tmp)]
    return [target / name for name in names]
