"""The animation's figure: drawn once, with the artists that move from frame to frame.

A run on one axis is drawn on the line ``y = 0`` of a view along x, as the paper's Figs. 5, 7 and 9
fly it: each agent with its interaction circle, the pair between them.  A 2-D run is one (x, y) view.  A 3-D run is a 3-D view beside its (x, y) projection; the
interaction circles, the agents' numbers and the walls are drawn in the projection.  The views are
fixed for the whole animation (equal scale, limits covering every drawn position with a margin of
``R``, at least 2 % of the extent).
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.colors import to_rgba_array
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from tmem.figures.drawing import MAX_NUMBERED, STRAIN_LABEL, draw_region, strain, strain_colormap, strain_limit, strain_norm
from tmem.figures.animate.frames import Frames
from tmem.figures.shape_plot import space_view

#: Most agents drawn with their interaction circles.
MAX_CIRCLES = 2000


def positions(run: Frames) -> tuple[np.ndarray, np.ndarray]:
    """Positions of the flying agents (NaN otherwise), and of removed agents (inactive after having
    been active), which stay as crosses where last seen flying (NaN otherwise); each (frame, agent, axes).

    Parameters
    ----------
    run : Frames
        What is drawn.
    """
    frame = np.arange(len(run.time))[:, None]
    last = np.maximum.accumulate(np.where(run.active, frame, -1), axis=0)
    seen_last = run.pos[np.maximum(last, 0), np.arange(run.pos.shape[1])]
    cross = np.where((~run.active & (last >= 0))[..., None], seen_last, np.nan)
    shown = np.where(run.active[..., None], run.pos, np.nan)
    return shown, cross


def edges_at(run: Frames, f: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs at frame ``f``: their ends (edge, 2, axes), which are coupled and which uncoupled.

    Parameters
    ----------
    run : Frames
        What is drawn.
    f : int
        The frame.
    """
    ends = np.stack([run.pos[f, run.col_i], run.pos[f, run.col_j]], axis=1)
    flying = run.active[f, run.col_i] & run.active[f, run.col_j]
    return ends, flying & (run.flag[f] == 1), flying & (run.flag[f] == 0)


def frames_strain_limit(run: Frames) -> float:
    """The strain colour scale's end: the largest ``|strain|`` of a coupled pair in the frames drawn
    (:func:`tmem.figures.drawing.strain_limit`).

    Parameters
    ----------
    run : Frames
        What is drawn.
    """
    largest = [0.0]
    for f in range(len(run.time)):
        ends, coupled, _ = edges_at(run, f)
        values = strain(np.linalg.norm(ends[coupled, 1] - ends[coupled, 0], axis=-1), run.d_t[coupled])
        largest.append(np.nanmax(np.abs(values), initial=0.0))
    return strain_limit(np.array(largest))


def _limits(run: Frames, shown: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    seen = shown[np.isfinite(shown).all(axis=-1)]
    if run.box is not None:  # the whole walled box
        corners = np.zeros((2, run.n_axes))
        corners[1, : len(run.box)] = run.box
        seen = np.concatenate([seen, corners])
    low, high = (seen.min(axis=0), seen.max(axis=0)) if len(seen) else (np.zeros(run.n_axes), np.zeros(run.n_axes))
    margin = max(run.radius, 0.02 * (high - low).max())  # R, or enough that no dot is cut at the edge
    return low - margin, high + margin


def _views(run: Frames, shown: np.ndarray, dpi: int) -> tuple[Figure, object, object | None]:
    """The figure, its (x, y) view and, for a 3-D run, its 3-D view."""
    three = run.n_axes == 3
    fig = Figure(figsize=(12, 6) if three else (9, 3.6) if run.line else (7, 6), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    space = fig.add_subplot(1, 2, 1, projection="3d") if three else None
    plane = fig.add_subplot(1, 2, 2) if three else fig.add_subplot()
    low, high = _limits(run, shown)
    plane.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), aspect="equal", xlabel="x, m", ylabel="y, m")
    plane.grid(alpha=0.3)
    if run.line:  # one axis: y means nothing
        plane.set(ylabel="", yticks=[])
    draw_region(plane, run.box, run.box is not None, run.obstacles)
    if space is not None:
        space_view(space, low, high)
        plane.set_title("projection on (x, y)")
    drawn = f"{len(run.agents)} agents" if not run.agents_note else run.agents_note
    fig.suptitle(f"{run.name + ': ' if run.name else ''}{drawn}, R = {run.radius:g} m", parse_math=False)
    return fig, plane, space


def _plane_artists(run: Frames, plane, shown: np.ndarray, colors, norm) -> dict:
    n_drawn = shown.shape[1]
    xy = shown[0, :, :2]
    artists = {
        "circles": EllipseCollection(
            2 * run.radius, 2 * run.radius, 0, units="xy", offsets=xy, offset_transform=plane.transData,
            facecolors=to_rgba_array(colors, 0.06), edgecolors=to_rgba_array(colors, 0.4), linewidths=0.6,
            visible=n_drawn <= MAX_CIRCLES,
        ),
        "dashed": plane.plot([], [], color="0.5", linewidth=0.8, linestyle="--", alpha=0.5)[0],
        "coupled": LineCollection([], cmap=strain_colormap(), norm=norm, linewidths=2),
        "crosses": plane.scatter([], [], s=30, marker="x", c="0.5"),
        "dots": plane.scatter(xy[:, 0], xy[:, 1], s=16 if n_drawn <= 200 else 4, c=colors),
        "clock": plane.text(
            0.02, 0.97, "", transform=plane.transAxes, va="top", family="monospace",
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"},
        ),
    }  # fmt: skip
    for key in ("circles", "coupled"):
        plane.add_collection(artists[key], autolim=False)
    if n_drawn <= MAX_NUMBERED:
        for q, agent in enumerate(run.agents):
            artists[f"number {q}"] = plane.annotate(str(agent + 1), (0.0, 0.0), xytext=(4, 4), textcoords="offset points", fontsize=8)
    return artists


def _space_artists(space, shown: np.ndarray, colors, norm) -> dict:
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    n_drawn = shown.shape[1]
    coupled = Line3DCollection([], cmap=strain_colormap(), norm=norm, linewidths=2)
    space.add_collection3d(coupled, autolim=False)
    return {
        "space dashed": space.plot([], [], [], color="0.5", linewidth=0.8, linestyle="--", alpha=0.5)[0],
        "space coupled": coupled,
        "space crosses": space.scatter([], [], [], s=30, marker="x", c="0.5", depthshade=False),
        "space dots": space.scatter(*shown[0].T, s=16 if n_drawn <= 200 else 4, c=colors, depthshade=False),
    }


def _legend(fig, run: Frames, n_drawn: int, moving: dict) -> None:
    handles = [Line2D([], [], ls="", marker="o", color="C0", label="agent")]
    if n_drawn <= MAX_CIRCLES:
        handles.append(Line2D([], [], ls="", marker="o", mfc="none", ms=12, color="C0", label=f"R = {run.radius:g} m"))
    if not run.active.all():
        handles.append(Line2D([], [], ls="", marker="x", color="0.5", label="removed"))
    if run.flag.size:
        handles.append(Line2D([], [], color="k", lw=2, label="coupled (F_en = 1)"))
        handles.append(Line2D([], [], color="0.5", ls="--", label="uncoupled pair"))
        fig.colorbar(moving["coupled"], ax=fig.axes, shrink=0.6, label=STRAIN_LABEL)
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)


def scene(run: Frames, shown: np.ndarray, dpi: int) -> tuple[Figure, dict]:
    """The static figure, drawn once, and its moving artists by name (not yet drawn).

    Agents are coloured one by one up to 20 of them, numbered from 1 up to
    :data:`tmem.figures.drawing.MAX_NUMBERED`; coupled pairs are coloured by strain on the scale of
    :func:`frames_strain_limit`.

    Parameters
    ----------
    run : Frames
        What is drawn.
    shown : ndarray, shape (frame, agent, axes)
        The flying agents' positions (:func:`positions`).
    dpi : int
        Resolution.
    """
    fig, plane, space = _views(run, shown, dpi)
    n_drawn = shown.shape[1]
    colors = [f"C{i % 10}" for i in range(n_drawn)] if n_drawn <= 20 else "tab:blue"
    norm = strain_norm(frames_strain_limit(run))
    moving = _plane_artists(run, plane, shown, colors, norm)  # drawn in this order over the static background
    if space is not None:
        moving |= _space_artists(space, shown, colors, norm)
    for artist in moving.values():
        artist.set_animated(True)
    _legend(fig, run, n_drawn, moving)
    fig.canvas.draw()
    fig.set_layout_engine("none")  # keep the layout of this first draw
    return fig, moving


def _polyline(segments: np.ndarray) -> np.ndarray:
    """Segments (n, 2, axes) as one line broken by NaN rows: one path to draw, not n."""
    gaps = np.full((len(segments), 1, segments.shape[2]), np.nan)
    return np.concatenate([segments, gaps], axis=1).reshape(-1, segments.shape[2])


def update(moving: dict, run: Frames, f: int, shown: np.ndarray, cross: np.ndarray, draw_dashed: bool) -> None:
    """Move the artists to frame ``f``: coupled pairs coloured by strain, uncoupled ones dashed, agents, clock.

    Parameters
    ----------
    moving : dict
        The moving artists of :func:`scene`.
    run : Frames
        What is drawn.
    f : int
        The frame.
    shown, cross : ndarray, shape (frame, agent, axes)
        Flying and removed agents' positions (:func:`positions`).
    draw_dashed : bool
        Whether uncoupled pairs are drawn.
    """
    ends, on, off = edges_at(run, f)
    dashed = ends[off] if draw_dashed else ends[:0]
    values = strain(np.linalg.norm(ends[on, 1] - ends[on, 0], axis=-1), run.d_t[on])
    moving["coupled"].set_segments(ends[on, :, :2])
    moving["coupled"].set_array(values)
    moving["dashed"].set_data(*_polyline(dashed[..., :2]).T)
    moving["circles"].set_offsets(shown[f, :, :2])
    moving["dots"].set_offsets(shown[f, :, :2])
    moving["crosses"].set_offsets(cross[f, :, :2])
    moving["clock"].set_text(f"t = {run.time[f]:.1f} s")
    for q in range(shown.shape[1]):
        number = moving.get(f"number {q}")
        if number is not None:
            number.xy = tuple(shown[f, q, :2])
            number.set_visible(bool(np.isfinite(shown[f, q]).all()))
    if "space dots" in moving:
        moving["space coupled"].set_segments(ends[on])
        moving["space coupled"].set_array(values)
        moving["space dashed"].set_data_3d(*_polyline(dashed).T)
        for key, points in (("space dots", shown[f]), ("space crosses", cross[f])):
            moving[key].set_offsets(points[:, :2])
            moving[key].set_3d_properties(points[:, 2], "z")
