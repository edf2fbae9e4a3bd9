"""Figures of a run, in the layout of the paper's Figs. 5, 7 and 9.

``velocity.png``: each agent's velocity (speed, on several axes) and the
RMS velocity against time.  ``distance.png``: pair distances against time
with ``R + R_j`` and ``d_t`` marked and the coupling events, above the flags
``F_en``.  ``formation.png`` (formations only): the distance error of the
formation's pairs against time.  ``gas.png`` (runs that observe their gas):
the RMS velocity of every flying agent and the thermostat's set-point against
time.  ``field.png`` (2-D walled boxes): the coverage map, with the walls and
obstacles (:mod:`tmem.coverage`).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure  # not pyplot: writing a file needs no window and no figure manager

from . import metrics
from .engine import Trajectory
from .observables import temperature

#: Matplotlib's warning for a character its font lacks (a name in CJK, an emoji).
MISSING_GLYPH = r"Glyph \d+ .* missing from font"
#: Most agents or pairs drawn one by one in a figure.
MAX_DRAWN = 8
_EVENT_STYLE = {"couple": ("tab:green", "-"), "uncouple": ("tab:red", "-"), "command": ("0.4", ":")}


def _title(trajectory: Trajectory) -> str:
    """The figure title; set it with ``parse_math=False``: a ``$`` in the scenario's name is a dollar, not mathtext."""
    s = trajectory.scenario
    name = f"{s.name}: " if s.name else ""
    return f"{name}{s.interaction.function} function, c_max = {s.interaction.c_max:g} rad"


def _mark_events(ax, trajectory: Trajectory) -> None:
    events = trajectory.events if len(trajectory.events) <= 4 * MAX_DRAWN else [
        e for e in trajectory.events if e.kind == "command"
    ]  # fmt: skip
    seen = set()
    for e in events:
        color, style = _EVENT_STYLE[e.kind]
        ax.axvline(e.time, color=color, linestyle=style, linewidth=1, label=None if e.kind in seen else e.kind)
        seen.add(e.kind)


def velocity_figure(trajectory: Trajectory):
    """Velocities of (up to MAX_DRAWN) agents and the RMS velocity against time.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.subplots()
    t = trajectory.time
    velocity = trajectory.model.velocity(trajectory.state)
    one_axis = velocity.shape[2] == 1
    for q in range(min(MAX_DRAWN, velocity.shape[1])):
        value = velocity[:, q, 0] if one_axis else np.linalg.norm(velocity[:, q], axis=1)
        ax.plot(t, value, linewidth=1.2, label=f"{'V' if one_axis else '|V|'}{trajectory.agents[q]}")
    rms = metrics.rms_velocity(velocity, trajectory.active)
    ax.plot(t, rms, color="k", linestyle="--", linewidth=1.5, label="RMS velocity")
    _mark_events(ax, trajectory)
    ax.set_xlabel("time, s")
    ax.set_ylabel("velocity, m/s" if one_axis else "speed, m/s")
    ax.set_title(_title(trajectory), parse_math=False)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig


def distance_figure(trajectory: Trajectory):
    """Distances of (up to MAX_DRAWN of the closest) pairs with ``R + R_j`` and ``d_t``, above ``F_en``.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    fig = Figure(figsize=(8, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1))
    t = trajectory.time
    ia = trajectory.scenario.interaction
    for p in np.argsort(trajectory.min_distance)[:MAX_DRAWN]:
        i, j = trajectory.pairs[p]
        top.plot(t, trajectory.pair_distance[:, p], linewidth=1.2, label=f"|P{j} - P{i}|")
        bottom.step(t, trajectory.flag[:, p], where="post", linewidth=1.2, label=f"pair {i}-{j}")
    top.axhline(ia.reach, color="tab:purple", linestyle="--", linewidth=1, label=f"R + R_j = {ia.reach:g} m")
    for d_t in np.unique(trajectory.d_t)[:3]:
        top.axhline(d_t, color="tab:olive", linestyle="--", linewidth=1, label=f"d_t = {d_t:g} m")
    _mark_events(top, trajectory)
    top.set_ylabel("distance, m")
    top.set_title(_title(trajectory), parse_math=False)
    top.grid(alpha=0.3)
    top.legend(loc="best", fontsize=8)
    bottom.set_ylabel("F_en")
    bottom.set_yticks([0, 1])
    bottom.set_ylim(-0.1, 1.1)
    bottom.set_xlabel("time, s")
    bottom.grid(alpha=0.3)
    return fig


def formation_figure(trajectory: Trajectory):
    """Distance error ``| |P_j - P_i| - d_t |`` of the coupled formation pairs: mean, RMS and largest.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.subplots()
    coupled = trajectory.flag == 1
    error = np.where(coupled, np.abs(trajectory.pair_distance - trajectory.d_t), 0.0)
    count = coupled.sum(axis=1)
    some = count > 0
    t = trajectory.time[some]
    ax.plot(t, error[some].max(axis=1), color="tab:red", linewidth=1.2, label="largest")
    ax.plot(t, np.sqrt((error[some] ** 2).sum(axis=1) / count[some]), color="k", linewidth=1.5, label="RMS")
    ax.plot(t, error[some].sum(axis=1) / count[some], color="tab:blue", linewidth=1.2, label="mean")
    _mark_events(ax, trajectory)
    ax.set_xlabel("time, s")
    ax.set_ylabel("| distance - d_t |, m (coupled pairs)")
    ax.set_title(f"formation of {len(trajectory.pairs)} pairs; " + _title(trajectory), parse_math=False)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig


def draw_region(ax, box, walls: bool, obstacles) -> None:
    """Draw the walls of a 2-D box (from 0 to ``box``) and the obstacles' circles on ``ax``.

    Parameters
    ----------
    ax : matplotlib Axes
    box : sequence of float or None
        The box's sides (m).
    walls : bool
        Whether the box is walled (else nothing is drawn of it).
    obstacles : sequence of (center, radius)
        The obstacles (m).
    """
    from matplotlib.patches import Circle, Rectangle

    if walls and box is not None:
        ax.add_patch(Rectangle((0.0, 0.0), box[0], box[1], fill=False, edgecolor="k", linewidth=1.5))
    for center, radius in obstacles:
        ax.add_patch(Circle(tuple(center[:2]), radius, facecolor="0.6", edgecolor="k", linewidth=1.0))


def gas_figure(trajectory: Trajectory):
    """The RMS velocity of every flying agent against time, and the thermostat's set-point.

    Parameters
    ----------
    trajectory : Trajectory
        A run that observed its gas.
    """
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.subplots()
    ax.plot(trajectory.time, temperature(trajectory), color="k", linewidth=1.5, label="RMS velocity, all agents")
    scenario = trajectory.scenario
    settings = [(0.0, scenario.thermostat.rms_velocity if scenario.thermostat else None)]
    settings += [(c.time, c.value) for c in sorted(scenario.commands, key=lambda c: c.time) if c.action == "temperature"]
    if any(value is not None for _, value in settings):
        steps = [(t, v if v is not None else np.nan) for t, v in settings] + [(trajectory.time[-1], np.nan)]
        times = [t for t, _ in steps]
        values = [v for _, v in steps[:-1]] + [steps[-2][1]]
        ax.step(times, values, where="post", color="tab:red", linestyle="--", label="set-point")
    _mark_events(ax, trajectory)
    ax.set_xlabel("time, s")
    ax.set_ylabel("RMS velocity, m/s")
    ax.set_title(_title(trajectory), parse_math=False)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig


def field_figure(trajectory: Trajectory):
    """The coverage map of a 2-D walled box: when each cell was first visited, the walls, the obstacles.

    Parameters
    ----------
    trajectory : Trajectory
        A 2-D run in a walled box.
    """
    from .coverage import plot_coverage, run_coverage

    found = run_coverage(trajectory)
    scenario = trajectory.scenario
    obstacles = [(o.center, o.radius) for o in scenario.obstacles]
    title = f"{_title(trajectory)}\n{100 * found.share[-1]:.1f} % of the field covered"
    fig = plot_coverage(found, obstacles=obstacles, title=title)
    draw_region(fig.axes[0], scenario.space.box, True, ())
    return fig


def write_figures(trajectory: Trajectory, directory: Path) -> list[Path]:
    """Write ``velocity.png`` (if agents were recorded), ``distance.png`` (if pairs), ``formation.png``,
    ``gas.png`` and ``field.png``.

    ``formation.png`` only for a scenario with a formation; ``gas.png`` for a run that observed its
    gas; ``field.png`` for a 2-D walled box.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    directory : Path
        An existing directory.

    Returns
    -------
    list of Path
        The files written.
    """
    makers = []
    if trajectory.state.shape[1]:  # some agents recorded
        makers.append(("velocity.png", velocity_figure))
    if len(trajectory.pairs):
        makers.append(("distance.png", distance_figure))
    if trajectory.scenario.formation is not None and len(trajectory.pairs):
        makers.append(("formation.png", formation_figure))
    if trajectory.gas.shape[1]:
        makers.append(("gas.png", gas_figure))
    if trajectory.scenario.space.walls and trajectory.scenario.space.axes == 2 and trajectory.state.shape[1]:
        makers.append(("field.png", field_figure))
    paths = []
    if not len(trajectory.time):
        return paths
    for name, make in makers:
        fig = make(trajectory)
        path = Path(directory) / name
        with warnings.catch_warnings():  # a name in a script the font lacks is drawn as boxes, without a warning per glyph
            warnings.filterwarnings("ignore", message=MISSING_GLYPH, category=UserWarning)
            fig.savefig(path, dpi=120)
        paths.append(path)
    return paths
