"""The cells an agent visits (:mod:`tmem.analysis.coverage`): at a record, and on its straight way there from
the last record, clipped to the region; the cells it crosses (sensor radius 0) or sees from points
along the way at most half a cell apart.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

#: Most (point, candidate cell) pairs held at once when a sensor radius is swept.
_CHUNK = 1 << 20


def record_visits(
    positions, time, active, k, sides, longest, cell, shape, radius
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """``(flat cell index, time)`` pairs visited at record ``k`` and on the way from record ``k - 1``.

    Parameters
    ----------
    positions : ndarray, shape (n_records, n_agents, axes)
        Agent positions (m).
    time : ndarray, shape (n_records,)
        Record times (s).
    active : ndarray, bool, shape (n_records, n_agents)
        Which agents fly at each record.
    k : int
        The record.
    sides : ndarray, shape (dims,)
        The sides of the covered axes (m).
    longest : ndarray, shape (dims,)
        The longest move along each axis between two records that is a flight, not a wrap (m).
    cell : float
        The cell side (m).
    shape : tuple of int
        Cells per covered axis.
    radius : float
        The sensor range (m); 0: the cell a point is in.
    """
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
