"""The coverage metric (:mod:`tmem.analysis.coverage`): the share of the field visited against time, and the
time of each cell's first visit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tmem.analysis.coverage.grid import Obstacle, check_obstacles, check_sizes, field_cells, grid_shape
from tmem.analysis.coverage.paths import record_visits

#: Tolerance on a share when looking for the first time it is reached.
_SHARE_TOL = 1e-12


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
    sides, cell, sensor_radius = check_sizes(box, cell, sensor_radius, positions.shape[2])
    shape = grid_shape(sides[:dims], cell)
    field = field_cells(shape, cell, check_obstacles(obstacles, dims))
    longest = sides[:dims] / 2 if periodic else np.full(dims, np.inf)
    first_visit, share = _visits(positions, time, active, sides[:dims], longest, cell, field, sensor_radius)
    for array in (time, share, first_visit, field):
        array.setflags(write=False)
    return Coverage(time, share, first_visit, field, cell, tuple(float(s) for s in sides))


def _visits(positions, time, active, sides, longest, cell, field, radius) -> tuple[np.ndarray, np.ndarray]:
    """Each cell's first visit (NaN: never, or not in the field) and the share of the field visited
    at each record, going through the records one at a time (:func:`record_visits`)."""
    first = np.full(field.size, np.nan)
    for k in range(len(time)):
        for index, when in record_visits(positions, time, active, k, sides, longest, cell, field.shape, radius):
            np.fmin.at(first, index, when)
    first[~field.ravel()] = np.nan
    visited = np.sort(first[np.isfinite(first)])
    share = np.searchsorted(visited, time, side="right") / np.count_nonzero(field)
    return first.reshape(field.shape), share


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
