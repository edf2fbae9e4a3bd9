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

The package, one idea a module:

* :mod:`~tmem.analysis.coverage.metric` — :func:`~tmem.analysis.coverage.metric.coverage`, the metric, and its result
  :class:`~tmem.analysis.coverage.metric.Coverage`;
* :mod:`~tmem.analysis.coverage.grid` — the grid of cells and the field, from the box and the obstacles;
* :mod:`~tmem.analysis.coverage.paths` — the cells an agent visits at a record and on its way there;
* :mod:`~tmem.analysis.coverage.figure` — the map of first visits as a figure;
* :mod:`~tmem.analysis.coverage.runs` — the coverage of a run's walled box, and its summary.
"""

from __future__ import annotations

from tmem.analysis.coverage.figure import plot_coverage
from tmem.analysis.coverage.grid import MAX_CELLS
from tmem.analysis.coverage.metric import Coverage, coverage
from tmem.analysis.coverage.runs import coverage_summary, run_coverage

__all__ = ["MAX_CELLS", "Coverage", "coverage", "coverage_summary", "plot_coverage", "run_coverage"]
