"""Coverage of a bounded field by a swarm, for terrain monitoring.

The region ``[0, box[0]] x [0, box[1]]`` (a line ``[0, box[0]]`` with one
axis; with three axes only x and y count) is cut into square cells of side
``cell``; cell ``(i, j)`` spans ``[i cell, (i + 1) cell) x [j cell, (j + 1) cell)``
and has its centre at ``((i + 1/2) cell, (j + 1/2) cell)``.  Where a side is
not a multiple of ``cell`` the last cell along it reaches past the box.  The
*field* is every cell whose centre lies outside all obstacles (circles): the
others can be neither covered nor counted.

An active agent visits, at each record, the cell that contains it (with
``sensor_radius = 0``) or every cell whose centre is within ``sensor_radius``
of it.  Between two records it is taken to move in a straight line, and it
visits what it passes on the way: with ``sensor_radius = 0`` exactly the cells
the segment crosses (found from where it crosses the grid lines), otherwise
the cells seen from points along the segment at most ``cell / 2`` apart.  So
the result does not depend on how often the run was recorded.  No segment is
drawn where the agent is inactive at either end, where a position is not
finite, or, in a periodic box (the default), where it moves more than half a
box side along an axis between two records (a wrap, not a flight across the
field); pass ``periodic=False`` for an open field, where no move is a wrap.  Positions outside
the region visit nothing.

``first_visit`` holds, per cell, the time the swarm first reached it (along a
segment, interpolated between the two record times), and ``share[k]`` the
fraction of the field's cells with ``first_visit <= time[k]``.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["MAX_CELLS", "Coverage", "coverage", "coverage_summary", "plot_coverage", "run_coverage"]

#: Most cells a grid may have (its first-visit map alone takes 8 bytes a cell).
MAX_CELLS = 50_000_000
#: Most (point, candidate cell) pairs held at once when a sensor radius is swept.
_CHUNK = 1 << 20
#: Tolerance on a share when looking for the first time it is reached.
_SHARE_TOL = 1e-12

Obstacle = tuple[Sequence[float], float]


@dataclass(frozen=True, eq=False)
class Coverage:
    """How much of a field a swarm covered, and when.

    Attributes
    ----------
    time : ndarray, shape (n_records,)
        The record times (s).
    share : ndarray, shape (n_records,)
        Share of the field's cells visited at or before each record, in ``[0, 1]``, never decreasing.
    first_visit : ndarray, float, shape (nx,) or (nx, ny)
        Time (s) each cell was first visited, indexed ``[i]`` or ``[i, j]`` along x then y;
        NaN for cells never visited and cells outside the field.
    field : ndarray, bool, same shape as ``first_visit``
        The cells that count: centre outside every obstacle.
    cell : float
        The cell side (m).
    box : tuple of float
        The region's sides (m), one per axis of the positions.
    """

    time: np.ndarray
    share: np.ndarray
    first_visit: np.ndarray
    field: np.ndarray
    cell: float
    box: tuple[float, ...]

    def time_to(self, share: float) -> float | None:
        """The time at which the covered share first reaches ``share``: the first visit of the cell
        that brings it there (interpolated between records, as ``first_visit`` is).

        Parameters
        ----------
        share : float
            The share sought, in ``[0, 1]``.

        Returns
        -------
        float or None
            The time (s), or ``None`` if the share is never reached.
        """
        if not math.isfinite(share):
            raise ValueError(f"share: must be a finite number, got {share!r}")
        visits = np.sort(self.first_visit[self.field & np.isfinite(self.first_visit)])
        needed = max(1, math.ceil((share - _SHARE_TOL) * int(self.field.sum())))
        return float(visits[needed - 1]) if needed <= visits.size else None


def coverage(
    positions: np.ndarray,
    time: np.ndarray,
    active: np.ndarray,
    box: Sequence[float],
    cell: float,
    obstacles: Sequence[Obstacle] = (),
    sensor_radius: float = 0.0,
    *,
    periodic: bool = True,
) -> Coverage:
    """The coverage of the field in ``box`` by a swarm's recorded positions.

    Memory is the grid plus, per record, the agents times the points of one
    segment; the records are gone through one at a time.

    Parameters
    ----------
    positions : ndarray, shape (n_records, n_agents, axes)
        Agent positions (m); 1 to 3 axes, of which the first two at most are used.
    time : ndarray, shape (n_records,)
        Record times (s), not decreasing.
    active : ndarray, bool, shape (n_records, n_agents)
        Which agents fly at each record; inactive agents visit nothing.
    box : sequence of float
        The region's side per axis (m); the region is ``[0, box[a]]``.  Sides on the
        covered axes must be positive; a third side (not covered) may be 0.
    cell : float
        The cell side (m).
    obstacles : sequence of (center, radius)
        Circles (intervals with one axis): ``center`` the first coordinates (m), ``radius`` (m).
        Cells whose centre lies inside one are not part of the field.
    sensor_radius : float
        Range (m) within which an agent sees a cell's centre; 0 (the default): the cell it is in.
    periodic : bool
        Whether the positions were kept in a periodic box (the default): then a move of more
        than half a side between two records is a wrap, and no segment is drawn for it.
        ``False`` for an open field: every segment between active records is drawn.

    Returns
    -------
    Coverage
        The share against time and the map of first visits.

    Raises
    ------
    ValueError
        Naming the argument, for shapes that do not match, a non-positive or non-finite
        cell, side or radius, decreasing times, too many cells, or no field left.
    """
    positions, time, active = _check_records(positions, time, active)
    dims = min(positions.shape[2], 2)
    sides, cell, sensor_radius = _check_sizes(box, cell, sensor_radius, positions.shape[2])
    circles = _check_obstacles(obstacles, dims)
    shape = _grid_shape(sides[:dims], cell)
    field = _field(shape, cell, circles)
    first = np.full(field.size, np.nan)
    longest = sides[:dims] / 2 if periodic else np.full(dims, np.inf)
    for k in range(len(time)):
        for index, when in _record_visits(positions, time, active, k, sides[:dims], longest, cell, shape, sensor_radius):
            np.fmin.at(first, index, when)
    first[~field.ravel()] = np.nan
    visited = np.sort(first[np.isfinite(first)])
    share = np.searchsorted(visited, time, side="right") / np.count_nonzero(field)
    first_visit = first.reshape(shape)
    for array in (time, share, first_visit, field):
        array.setflags(write=False)
    return Coverage(time, share, first_visit, field, cell, tuple(float(s) for s in sides))


def _check_records(positions, time, active) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``positions``, ``time`` and ``active`` as float, float and bool arrays of matching shapes."""
    positions = np.asarray(positions, dtype=float)
    if positions.ndim != 3 or not 1 <= positions.shape[2] <= 3:
        raise ValueError(f"positions: must have shape (n_records, n_agents, axes) with 1 to 3 axes, got {positions.shape}")
    n_records, n_agents = positions.shape[:2]
    if n_records == 0:
        raise ValueError("positions: no records")
    time = np.array(time, dtype=float)
    if time.shape != (n_records,):
        raise ValueError(f"time: must have shape ({n_records},) to match positions, got {time.shape}")
    if not np.all(np.isfinite(time)):
        raise ValueError("time: must be finite")
    if np.any(np.diff(time) < 0):
        raise ValueError("time: must not decrease")
    active = np.asarray(active)
    if active.shape != (n_records, n_agents):
        raise ValueError(f"active: must have shape ({n_records}, {n_agents}) to match positions, got {active.shape}")
    return positions, time, active.astype(bool, copy=False)


def _check_sizes(box, cell, sensor_radius, axes: int) -> tuple[np.ndarray, float, float]:
    """The box sides as an array, the cell side and the sensor radius, checked."""
    sides = np.asarray(box, dtype=float)
    dims = min(axes, 2)
    if sides.shape != (axes,):
        raise ValueError(f"box: must give one side per axis of the positions ({axes}), got {sides.tolist()}")
    if not (np.all(np.isfinite(sides)) and np.all(sides[:dims] > 0) and np.all(sides >= 0)):
        raise ValueError(f"box: the sides of the covered axes must be positive and finite, got {sides.tolist()}")
    cell = float(cell)
    if not (math.isfinite(cell) and cell > 0):
        raise ValueError(f"cell: must be positive and finite, got {cell!r}")
    cells = math.prod(float(n) for n in np.ceil(np.round(sides[:dims] / cell, 9)))
    if cells > MAX_CELLS:
        raise ValueError(
            f"cell: {cell:g} m cuts the box into {cells:.3g} cells, more than {MAX_CELLS:.0e}; take a larger cell"
        )
    sensor_radius = float(sensor_radius)
    if not (math.isfinite(sensor_radius) and sensor_radius >= 0):
        raise ValueError(f"sensor_radius: must be finite and not negative, got {sensor_radius!r}")
    return sides, cell, sensor_radius


def _check_obstacles(obstacles, dims: int) -> list[tuple[np.ndarray, float]]:
    """Each obstacle as (its first ``dims`` centre coordinates, radius), checked."""
    circles = []
    for n, obstacle in enumerate(obstacles):
        try:
            center, radius = obstacle
            center = np.asarray(center, dtype=float).ravel()
            radius = float(radius)
        except (TypeError, ValueError) as error:
            raise ValueError(f"obstacles[{n}]: must be a (center, radius) pair, got {obstacle!r}") from error
        if center.size < dims or not np.all(np.isfinite(center[:dims])):
            raise ValueError(f"obstacles[{n}]: center must have {dims} finite coordinates, got {center.tolist()}")
        if not (math.isfinite(radius) and radius >= 0):
            raise ValueError(f"obstacles[{n}]: radius must be finite and not negative, got {radius!r}")
        circles.append((center[:dims], radius))
    return circles


def _grid_shape(sides: np.ndarray, cell: float) -> tuple[int, ...]:
    """Cells per covered axis: enough to hold the side (rounded to 9 decimals first, so 0.3 / 0.1 is 3)."""
    return tuple(max(1, int(n)) for n in np.ceil(np.round(sides / cell, 9)))


def _centres(shape: tuple[int, ...], cell: float) -> list[np.ndarray]:
    """The cell centres' coordinates, one open-mesh array per axis."""
    return [(index + 0.5) * cell for index in np.ix_(*(np.arange(n) for n in shape))]


def _field(shape: tuple[int, ...], cell: float, circles: list[tuple[np.ndarray, float]]) -> np.ndarray:
    """The cells whose centre lies outside every obstacle (strictly inside one: out of the field)."""
    centres = _centres(shape, cell)
    field = np.ones(shape, dtype=bool)
    for center, radius in circles:
        field &= sum((c - x) ** 2 for c, x in zip(centres, center)) >= radius**2
    if not field.any():
        raise ValueError("obstacles: they cover every cell of the box; no field is left")
    return field


def _record_visits(
    positions, time, active, k, sides, longest, cell, shape, radius
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """``(flat cell index, time)`` pairs visited at record ``k`` and on the way from record ``k - 1``."""
    dims = len(sides)
    now = positions[k, active[k], :dims]
    points, times = [now], [np.full(len(now), time[k])]
    if k > 0:
        start, end = positions[k - 1, :, :dims], positions[k, :, :dims]
        jump = np.abs(end - start)
        ok = active[k - 1] & active[k] & np.all(np.isfinite(start) & np.isfinite(end), axis=1)
        ok &= np.all(jump <= longest, axis=1)  # further: a periodic wrap
        start, end, s_in, s_out = _clip(start[ok], end[ok], sides)
        if len(start):
            on_way = _crossings if radius == 0 else _samples
            where, s, row = on_way(start, end, cell)
            s = s_in[row] + s * (s_out - s_in)[row]  # along the clipped part -> along the whole segment
            points.append(where)
            times.append(np.clip(time[k - 1] + s * (time[k] - time[k - 1]), time[k - 1], time[k]))
    yield from _cells_seen(np.concatenate(points), np.concatenate(times), sides, cell, shape, radius)


def _clip(start: np.ndarray, end: np.ndarray, sides: np.ndarray) -> tuple[np.ndarray, ...]:
    """The parts of the segments inside the region, and where on each segment they begin and end.

    Liang-Barsky clipping, so that a long segment costs no more than the grid it crosses.
    Segments that miss the region are dropped.  Returns start, end ``(m, dims)``, s_in, s_out ``(m,)``.
    """
    delta = end - start
    moving = delta != 0
    with np.errstate(divide="ignore", invalid="ignore"):
        low, high = -start / delta, (sides - start) / delta
    s_in = np.maximum(np.max(np.where(moving, np.minimum(low, high), -np.inf), axis=1), 0.0)
    s_out = np.minimum(np.min(np.where(moving, np.maximum(low, high), np.inf), axis=1), 1.0)
    keep = (s_in <= s_out) & np.all(moving | ((start >= 0) & (start <= sides)), axis=1)
    start, delta, s_in, s_out = start[keep], delta[keep], s_in[keep], s_out[keep]
    return start + s_in[:, None] * delta, start + s_out[:, None] * delta, s_in, s_out


def _crossings(start: np.ndarray, end: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A point inside each cell the segments cross, the segment parameter where each is entered, the segment.

    The parameters where a segment meets a grid line cut it into pieces, each within one cell;
    a piece's midpoint names the cell and its start the time of entry.  Shapes: start, end
    ``(m, dims)``; returned ``(p, dims)``, ``(p,)`` and ``(p,)`` (row of start).
    """
    delta = end - start
    below = np.floor(np.minimum(start, end) / cell)
    count = np.maximum(np.ceil(np.maximum(start, end) / cell) - 1 - below, 0).astype(np.int64)
    steps = np.arange(int(count.max(initial=0)))
    lines = (below[..., None] + 1 + steps) * cell  # (m, dims, K): the grid lines strictly between the ends
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (lines - start[..., None]) / delta[..., None]
    s = np.where(steps < count[..., None], s, 1.0).reshape(len(start), -1)
    s = np.sort(np.concatenate([np.zeros((len(s), 1)), s, np.ones((len(s), 1))], axis=1), axis=1)
    entry, leave = s[:, :-1], s[:, 1:]
    piece = leave - entry > 1e-12
    middle = (entry + leave) / 2
    points = start[:, None, :] + middle[..., None] * delta[:, None, :]
    row = np.broadcast_to(np.arange(len(start))[:, None], piece.shape)
    return points[piece], entry[piece], row[piece]


def _samples(start: np.ndarray, end: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points along the segments at most ``cell / 2`` apart (the start left out), their parameters, their row."""
    delta = end - start
    steps = max(1, math.ceil(float(np.linalg.norm(delta, axis=1).max()) / (cell / 2)))
    s = np.arange(1, steps + 1) / steps
    points = start[:, None, :] + s[None, :, None] * delta[:, None, :]
    return points.reshape(-1, start.shape[1]), np.tile(s, len(start)), np.repeat(np.arange(len(start)), steps)


def _cells_seen(points, times, sides, cell, shape, radius) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """``(flat cell index, time)`` of the cells seen from ``points`` in the region, in chunks."""
    inside = np.all((points >= 0) & (points <= sides), axis=1)
    points, times = points[inside], times[inside]
    limit = np.array(shape)
    if radius == 0:
        index = np.minimum(np.floor(points / cell).astype(np.int64), limit - 1)  # a point on the far side: last cell
        yield np.ravel_multi_index(tuple(index.T), shape), times
        return
    reach = math.ceil(radius / cell) + 1
    span = [np.arange(-reach, reach + 1)] * len(shape)
    offsets = np.stack(np.meshgrid(*span, indexing="ij"), -1).reshape(-1, len(shape))
    chunk = max(1, _CHUNK // len(offsets))
    for at in range(0, len(points), chunk):
        p, t = points[at : at + chunk], times[at : at + chunk]
        candidate = np.floor(p / cell).astype(np.int64)[:, None, :] + offsets
        near = np.sum(((candidate + 0.5) * cell - p[:, None, :]) ** 2, axis=2) <= radius**2
        near &= np.all((candidate >= 0) & (candidate < limit), axis=2)
        yield np.ravel_multi_index(tuple(candidate[near].T), shape), np.broadcast_to(t[:, None], near.shape)[near]


def plot_coverage(cov: Coverage, ax=None, obstacles: Sequence[Obstacle] = (), title: str | None = None):
    """Draw the map of first-visit times, never-visited cells in light grey, obstacles outlined.

    Parameters
    ----------
    cov : Coverage
        A result of :func:`coverage`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure (no pyplot, no window) by default.
    obstacles : sequence of (center, radius)
        Circles to outline, as given to :func:`coverage`.
    title : str, optional
        The axes' title, drawn as typed; by default the final share and time.

    Returns
    -------
    matplotlib.figure.Figure
        The figure holding ``ax``.
    """
    from matplotlib import colormaps
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Rectangle

    if ax is None:
        ax = Figure(figsize=(6, 5), layout="constrained").subplots()
    fig = ax.figure
    dims = cov.first_visit.ndim
    grid = cov.first_visit if dims == 2 else cov.first_visit[:, None]
    height = grid.shape[1] * cov.cell
    cmap = colormaps["viridis"].with_extremes(bad="lightgrey")
    image = ax.imshow(
        np.ma.masked_invalid(grid.T), origin="lower", cmap=cmap, extent=(0, grid.shape[0] * cov.cell, 0, height),
        aspect="equal" if dims == 2 else "auto", interpolation="nearest",
    )  # fmt: skip
    fig.colorbar(image, ax=ax, label="first visit (s)")
    for center, radius in _check_obstacles(obstacles, dims):
        outline = dict(fill=False, edgecolor="k", linewidth=1.2)
        if dims == 2:
            ax.add_patch(Circle(center, radius, **outline))
        else:
            ax.add_patch(Rectangle((center[0] - radius, 0), 2 * radius, height, **outline))
    ax.set_xlim(0, cov.box[0])
    ax.set_ylim(0, cov.box[1] if dims == 2 else height)
    ax.set_xlabel("x (m)")
    if dims == 2:
        ax.set_ylabel("y (m)")
    else:
        ax.set_yticks([])
    default = f"coverage {cov.share[-1]:.1%} at t = {cov.time[-1]:g} s"
    ax.set_title(default if title is None else title, parse_math=False)
    return fig


def run_coverage(trajectory) -> Coverage | None:
    """The coverage of a run's walled box (:func:`coverage` on its recorded agents), with the cell
    and sensor radius of its ``[coverage]`` table (default: cells of side ``R``, sensor radius 0);
    ``None`` when the run has no walled box, recorded nothing, or its box would need more than
    :data:`MAX_CELLS` cells of side ``R``.

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
    if math.prod(math.ceil(side / cell) for side in scenario.space.box[:2]) > MAX_CELLS:
        return None  # a field too fine to map by default (a [coverage] table this fine is refused)
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
