"""The swarm in space: every agent's path (``paths.png``) and the formation's shape at a few moments
(``shape.png``).

``paths.png``
    On one axis, each agent's position against time, as the paper draws it.  In the plane, each
    agent's path in (x, y), from a ring at its start to a dot at its end, numbered at its end.  In
    3-D, a 3-D view and the (x, y) projection side by side.  A removed agent's path stops where it
    was removed.  In a periodic box a path that leaves by one side and comes back by the other is
    broken there, not drawn across the box.  Every recorded agent up to
    :data:`tmem.figures.drawing.MAX_LINES`; past that, that many spread over where the swarm started
    (:func:`tmem.figures.drawing.spread_agents`), and the title says so.
``shape.png`` (2-D and 3-D runs)
    Every recorded agent and every pair between them at the moments of :func:`moments`, side by
    side in views of one size and scale, each centred on the agents at its moment: coupled pairs (``F_en = 1``) as solid lines coloured by their strain
    ``|P_j - P_i| / d_t - 1``, uncoupled pairs as dashed grey lines, flying agents as dots,
    numbered when there are at most :data:`tmem.figures.drawing.MAX_NUMBERED`.  The strain colour scale is
    fitted to the run: symmetric about 0, reaching the largest ``|strain|`` of a coupled pair over
    every record (:func:`tmem.figures.drawing.strain_limit`, at least 1 %).  In 3-D, each moment is a 3-D
    view.

Positions are drawn as recorded; in a periodic box, a pair across the box's edge is drawn across it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from tmem.figures.drawing import (
    MAX_LEGEND, MAX_NUMBERED, STRAIN_LABEL, agent_colors, agent_label, agents_legend, columns_of, draw_region, run_title,
    spread_agents, strain, strain_colormap, strain_limit, strain_norm,
)  # fmt: skip

if TYPE_CHECKING:  # the animation draws its 3-D view with space_view, without the engine
    from tmem.engine import Trajectory

#: Most moments drawn in ``shape.png``.
MAX_MOMENTS = 4


def _flying_positions(trajectory: Trajectory) -> np.ndarray:
    """Positions (time, agent, axis) of the recorded agents, NaN where an agent is not flying."""
    position = trajectory.model.position(trajectory.state)
    return np.where(trajectory.active[..., None], position, np.nan)


def _limits(points: np.ndarray, trajectory: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """Low and high corners covering ``points`` (n, axes) and a walled box, with a margin of ``R``."""
    points = points[np.isfinite(points).all(axis=1)]
    box = trajectory.scenario.space.box
    if trajectory.scenario.space.walls and box is not None:
        points = np.concatenate([points, np.zeros((1, points.shape[1])), [box]])
    low, high = (points.min(axis=0), points.max(axis=0)) if len(points) else (np.zeros(points.shape[1]),) * 2
    margin = max(trajectory.scenario.interaction.radius, 0.02 * float((high - low).max(initial=0.0)))
    return low - margin, high + margin


def _windows(flying: np.ndarray, trajectory: Trajectory) -> list[tuple[np.ndarray, np.ndarray]]:
    """One view per moment (``flying``: moment, agent, axis), all of one size, each centred on that
    moment's agents: the formation as large as the largest moment allows, wherever it has flown."""
    bounds = [_limits(points, trajectory) for points in flying]
    size = np.max([high - low for low, high in bounds], axis=0)
    return [(0.5 * (low + high - size), 0.5 * (low + high + size)) for low, high in bounds]


def _plane(ax, trajectory: Trajectory, low: np.ndarray, high: np.ndarray) -> None:
    """An (x, y) view: limits, equal scale, labels, the walls and the obstacles."""
    scenario = trajectory.scenario
    ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), aspect="equal", xlabel="x, m", ylabel="y, m")
    ax.grid(alpha=0.3)
    draw_region(ax, scenario.space.box, scenario.space.walls, [(o.center, o.radius) for o in scenario.obstacles])


#: How much of its panel a 3-D view's box fills: less than matplotlib's 1, so that the axes' labels
#: fall inside the panel, not under the next one (the layout does not make room for them).
SPACE_ZOOM = 0.7


def space_view(ax, low: np.ndarray, high: np.ndarray) -> None:
    """Set up a 3-D view: limits, equal scale, labels clear of the tick values, all inside its panel.

    Parameters
    ----------
    ax : matplotlib Axes3D
        The view.
    low, high : ndarray, shape (3,)
        The corners of the space shown (m).
    """
    ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), zlim=(low[2], high[2]))
    for axis, name in zip((ax.xaxis, ax.yaxis, ax.zaxis), "xyz"):
        axis.set_label_text(f"{name}, m")
        axis.labelpad = 10
    ax.set_aspect("equal")
    ax.set_box_aspect(None, zoom=SPACE_ZOOM)


def _number(ax, trajectory: Trajectory, points: np.ndarray, columns: np.ndarray) -> None:
    """Write each agent's number beside its point in the plane, when they are few enough."""
    if len(columns) > MAX_NUMBERED:
        return
    for q in columns:
        if np.isfinite(points[q, :2]).all():
            ax.annotate(str(trajectory.agents[q] + 1), points[q, :2], xytext=(4, 4), textcoords="offset points", fontsize=8)


def _flying_end(flying: np.ndarray, first: bool) -> np.ndarray:
    """Each agent's first (or last) flying position (agent, axis): where its path starts (ends); NaN
    if it never flew."""
    seen = np.isfinite(flying).all(axis=-1)
    k = np.argmax(seen, axis=0) if first else len(flying) - 1 - np.argmax(seen[::-1], axis=0)
    return np.where(seen.any(axis=0)[:, None], flying[k, np.arange(flying.shape[1])], np.nan)


def broken_at_wraps(values: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Positions over time (time, ...) with a NaN between two records where a periodic coordinate
    jumps by more than half the box (the agent left by one side and came back by the other), so
    that a line drawn through them stops at one side and starts again at the other.

    Parameters
    ----------
    values : ndarray, shape (time, ..., axes)
        Positions (m); NaN where an agent is not flying.
    box : ndarray, shape (axes,)
        The periodic box's sides (m); 0 on an open axis.

    Returns
    -------
    ndarray, shape (2 time - 1, ..., axes)
        The records, each but the first after a copy of itself, or after NaN where it wrapped;
        ``values`` itself where no axis is periodic.
    """
    box = np.asarray(box, dtype=float)
    if not np.any(box > 0):
        return values
    jump = (np.abs(np.diff(values, axis=0)) > np.where(box > 0, box / 2, np.inf)).any(axis=-1)
    out = np.empty((2 * len(values) - 1, *values.shape[1:]))
    out[0::2] = values
    out[1::2] = np.where(jump[..., None], np.nan, values[1:])
    return out


def paths_figure(trajectory: Trajectory):
    """Every agent's path: against time on one axis, in (x, y) in the plane, in 3-D and (x, y) in space.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`, or :func:`tmem.files.saved.read_run`).
    """
    n_axes = trajectory.scenario.space.axes
    box = np.asarray(trajectory.initial.box, dtype=float)
    everyone = _flying_positions(trajectory)
    chosen = spread_agents(_flying_end(everyone, first=True), box)
    colors, mappable = agent_colors(trajectory.agents[chosen.index])
    flying = everyone[:, chosen.index]
    drawn = broken_at_wraps(flying, box)
    fig = Figure(figsize=(13, 6) if n_axes == 3 else (8, 6) if n_axes == 2 else (8, 4.5), layout="constrained")
    if n_axes == 1:
        ax = fig.subplots()
        time = np.repeat(trajectory.time, 2)[1:] if len(drawn) > len(flying) else trajectory.time  # see broken_at_wraps
        for q, color in enumerate(colors):
            ax.plot(time, drawn[:, q, 0], color=color, linewidth=1.2, label=agent_label(trajectory.agents[chosen.index[q]]))
        ax.set(xlabel="time, s", ylabel="position x, m")
        ax.grid(alpha=0.3)
    else:
        ax = fig.add_subplot(1, 2, 2) if n_axes == 3 else fig.add_subplot()
        low, high = _limits(flying.reshape(-1, n_axes), trajectory)
        _plane(ax, trajectory, low, high)
        views = [ax]
        if n_axes == 3:
            views.append(fig.add_subplot(1, 2, 1, projection="3d"))
            space_view(views[1], low, high)
            ax.set_title("projection on (x, y)")
        starts = _flying_end(flying, first=True)
        ends = _flying_end(flying, first=False)
        for view in views:
            for q, color in enumerate(colors):
                view.plot(*drawn[:, q].T[: 3 if view.name == "3d" else 2], color=color, linewidth=1.0,
                          label=agent_label(trajectory.agents[chosen.index[q]]))  # fmt: skip
            dims = slice(0, 3 if view.name == "3d" else 2)
            view.scatter(*starts[:, dims].T, s=20, facecolors="none", edgecolors=colors)
            view.scatter(*ends[:, dims].T, s=16, c=colors)
        _number(ax, trajectory, ends, np.arange(len(chosen.index)))
    fig.suptitle(run_title(trajectory, chosen.note), parse_math=False)
    markers = [] if n_axes == 1 else [
        Line2D([], [], ls="", marker="o", mfc="none", mec="k", label="start"),
        Line2D([], [], ls="", marker="o", color="k", ms=4, label="end"),
    ]  # fmt: skip
    agents_legend(ax, mappable, markers)
    return fig


def moments(trajectory: Trajectory) -> list[tuple[str, int]]:
    """The moments ``shape.png`` shows, as ``(name, record index)``, in time order, none twice.

    The start; the first coupling after the start, or the middle of the run when no pair couples
    after the start; the first uncoupling, when a pair uncouples; the end.  An event's moment is
    the first record at or after it.

    Parameters
    ----------
    trajectory : Trajectory
        A run with at least one record.
    """
    time = trajectory.time
    couple = next((e.time for e in trajectory.events if e.kind == "couple" and e.time > time[0]), None)
    uncouple = next((e.time for e in trajectory.events if e.kind == "uncouple"), None)
    wanted = [("start", time[0])]
    wanted.append(("first coupling", couple) if couple is not None else ("middle", 0.5 * (time[0] + time[-1])))
    if uncouple is not None:
        wanted.append(("first uncoupling", uncouple))
    wanted.append(("end", time[-1]))
    found: dict[int, str] = {}
    for name, at in sorted(wanted, key=lambda w: w[1]):
        found.setdefault(min(int(np.searchsorted(time, at - 1e-9 * max(1.0, abs(at)))), len(time) - 1), name)
    return [(name, index) for index, name in sorted(found.items())][:MAX_MOMENTS]


def _pair_columns(trajectory: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs whose agents are both recorded, and the columns of their two agents."""
    col_i, ok_i = columns_of(trajectory.agents, trajectory.pairs[:, 0])
    col_j, ok_j = columns_of(trajectory.agents, trajectory.pairs[:, 1])
    kept = np.flatnonzero(ok_i & ok_j)
    return kept, col_i[kept], col_j[kept]


def _segments(points: np.ndarray, col_i: np.ndarray, col_j: np.ndarray, on: np.ndarray, dims: int) -> np.ndarray:
    return np.stack([points[col_i[on], :dims], points[col_j[on], :dims]], axis=1)


def _draw_moment(ax, trajectory: Trajectory, moment: tuple[str, int], pairs: tuple, norm, colors) -> None:
    """One moment: pairs (coupled coloured by strain, others dashed), agents, their numbers."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    name, record = moment
    kept, col_i, col_j = pairs
    points = _flying_positions(trajectory)[record]
    three = ax.name == "3d"
    dims = 3 if three else 2
    both = np.isfinite(points[col_i]).all(axis=1) & np.isfinite(points[col_j]).all(axis=1)
    coupled = both & (trajectory.flag[record, kept] == 1)
    lines = Line3DCollection if three else LineCollection
    dashed = lines(_segments(points, col_i, col_j, both & ~coupled, dims), colors="0.5", linestyles="--", linewidths=0.8)
    solid = lines(_segments(points, col_i, col_j, coupled, dims), cmap=strain_colormap(), norm=norm, linewidths=2)
    solid.set_array(strain(trajectory.pair_distance[record, kept[coupled]], trajectory.d_t[kept[coupled]]))
    for collection in (dashed, solid):
        if three:
            ax.add_collection3d(collection, autolim=False)
        else:
            ax.add_collection(collection, autolim=False)
    shown = np.flatnonzero(np.isfinite(points).all(axis=1))
    ax.scatter(*points[shown, :dims].T, s=18 if len(points) <= 200 else 4, c=[colors[q] for q in shown], zorder=3)
    if not three:
        _number(ax, trajectory, points, shown)
    ax.set_title(f"{name}, t = {trajectory.time[record]:.1f} s")


def shape_figure(trajectory: Trajectory):
    """The agents and pairs at the run's :func:`moments`, coupled pairs coloured by strain.

    Parameters
    ----------
    trajectory : Trajectory
        A 2-D or 3-D run (:func:`tmem.simulate`, or :func:`tmem.files.saved.read_run`).
    """
    n_axes = trajectory.scenario.space.axes
    shown = moments(trajectory)
    flying = _flying_positions(trajectory)[[record for _, record in shown]]
    windows = _windows(flying, trajectory)
    size = windows[0][1] - windows[0][0]
    panel = 4.2  # inches wide; as high as the view is in the plane, within reason
    height = 5.8 if n_axes == 3 else 1.8 + float(np.clip(panel * size[1] / size[0], 2.0, 6.0))
    fig = Figure(figsize=(panel * len(shown) + 1.2, height), layout="constrained")
    pairs = _pair_columns(trajectory)
    norm = strain_norm(strain_limit(strain(trajectory.pair_distance, trajectory.d_t)[trajectory.flag == 1]))
    n_agents = trajectory.state.shape[1]
    colors = agent_colors(trajectory.agents)[0] if n_agents <= MAX_LEGEND else ["0.25"] * n_agents
    for k, ((name, record), (low, high)) in enumerate(zip(shown, windows)):
        ax = fig.add_subplot(1, len(shown), k + 1, projection="3d" if n_axes == 3 else None, label=name)
        if n_axes == 3:
            space_view(ax, low, high)
        else:
            _plane(ax, trajectory, low, high)
        _draw_moment(ax, trajectory, (name, record), pairs, norm, colors)
    if len(pairs[0]):
        fig.colorbar(ScalarMappable(norm, strain_colormap()), ax=fig.axes, label=STRAIN_LABEL, shrink=0.8)
    counted = f"{n_agents} agents" + (f" and {len(pairs[0])} pairs" if len(pairs[0]) else "")
    fig.suptitle(run_title(trajectory, counted), parse_math=False)
    return fig
