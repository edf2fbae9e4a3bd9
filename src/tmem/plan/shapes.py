"""Target shapes for a formation mission: slot offsets about their centroid, and the neighbouring pairs.

Each function returns :class:`Slots`: the offsets of ``n`` slots from the shape's centroid (m, in
the x-y plane of ``axes`` axes) and its edges, the pairs of slots exactly ``spacing`` apart, found
by :meth:`scipy.spatial.cKDTree.query_pairs` within ``spacing (1 + 1e-9)`` (every other pair of
these shapes is at least ``sqrt(2) spacing`` apart, so the margin only absorbs rounding).

The hexagonal patch, the line and the ring are the places of the formations scenarios already fly,
from :mod:`tmem.world.formation` (:func:`~tmem.world.formation.hex_patch`,
:func:`~tmem.world.formation.chain`, :func:`~tmem.world.formation.ring`); the line is turned to a
heading here, and the rectangular grid is added.

* hexagonal patch: the triangular (hexagonal) lattice's points nearest the centre [1]_; full hexagons of ``k``
  rings hold ``3 k (k + 1) + 1`` = 1, 7, 19, 37, 61 ... slots and ``3 k (3 k + 1)`` edges (0, 12,
  42, 90, 156 ...: each of the ``3 k (k - 1) + 1`` inner slots has six neighbours, and the hexagon's
  ``6 k`` boundary slots share ``6 k`` boundary edges);
* line: ``n - 1`` edges; ring (a regular ``n``-gon of side ``spacing``): ``n`` edges (its sides;
  the shortest diagonal is ``2 cos(pi / n) spacing``); grid of ``r x c``: ``2 r c - r - c`` edges.

References
----------
.. [1] J. H. Conway and N. J. A. Sloane, "Sphere Packings, Lattices and Groups", 3rd ed., Springer
   (1999), ch. 1: the hexagonal lattice A2 and its kissing number 6.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from tmem.world import formation

__all__ = ["Slots", "grid_slots", "hex_count", "hex_slots", "line_slots", "ring_slots", "slot_edges"]


class Slots(NamedTuple):
    """A target shape.

    Attributes
    ----------
    offsets : ndarray, shape (n, axes)
        Each slot's offset from the shape's centroid (m); their mean is zero.
    edges : ndarray of int64, shape (E, 2)
        The pairs ``(i, j)``, ``i < j``, of slots ``spacing`` apart, sorted.
    """

    offsets: np.ndarray
    edges: np.ndarray


def _check(spacing: float, axes: int) -> None:
    if not (math.isfinite(spacing) and spacing > 0.0):
        raise ValueError(f"spacing must be a finite distance > 0 m, got {spacing}")
    if axes not in (1, 2, 3):
        raise ValueError(f"axes must be 1, 2 or 3, got {axes}")


def _count(name: str, value: int, least: int) -> int:
    if isinstance(value, bool) or int(value) != value or value < least:
        raise ValueError(f"{name} must be an integer >= {least}, got {value}")
    return int(value)


def slot_edges(offsets: np.ndarray, spacing: float) -> np.ndarray:
    """The pairs of slots at most ``spacing (1 + 1e-9)`` apart, sorted (cKDTree ``query_pairs``).

    Parameters
    ----------
    offsets : ndarray, shape (n, axes)
        Slot places (m).
    spacing : float
        The neighbour distance (m).

    Returns
    -------
    ndarray of int64, shape (E, 2)
        Pairs ``(i, j)``, ``i < j``, in lexicographic order.
    """
    from scipy.spatial import cKDTree

    pairs = cKDTree(offsets).query_pairs(spacing * (1.0 + 1e-9), output_type="ndarray").astype(np.int64).reshape(-1, 2)
    pairs.sort(axis=1)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def _slots(offsets: np.ndarray, spacing: float) -> Slots:
    return Slots(offsets, slot_edges(offsets, spacing))


def hex_count(rings: int) -> int:
    """The number of slots of a full hexagon of ``rings`` rings about one centre slot: ``3 k (k + 1) + 1``.

    Parameters
    ----------
    rings : int
        ``k`` >= 0.
    """
    rings = _count("rings", rings, 0)
    return 3 * rings * (rings + 1) + 1


def hex_slots(n: int | None = None, spacing: float = 1.0, *, rings: int | None = None, axes: int = 2) -> Slots:
    """A hexagonal patch: the ``n`` triangular-lattice points nearest the centre (a full hexagon of ``rings``).

    The places are :func:`tmem.world.formation.hex_patch`'s (ties in distance broken by angle).

    Parameters
    ----------
    n : int, optional
        The number of slots, >= 1; 1, 7, 19, 37, 61 ... make full hexagons.
    spacing : float
        Nearest-neighbour distance (m).
    rings : int, optional, keyword only
        Instead of ``n``: the full hexagon of ``rings`` rings, ``n = 3 rings (rings + 1) + 1``.
    axes : int
        1, 2 or 3 (the patch is planar: 2 or 3).

    Returns
    -------
    Slots
        Offsets and edges (the lattice neighbours).
    """
    if (n is None) == (rings is None):
        raise ValueError("give either n (slots) or rings, not both and not neither")
    n = hex_count(rings) if rings is not None else _count("n", n, 1)
    _check(spacing, axes)
    return _slots(formation.hex_patch(n, spacing, axes).positions, spacing)


def line_slots(n: int, spacing: float, heading: float = 0.0, axes: int = 2) -> Slots:
    """``n`` slots on a line, ``spacing`` apart, along ``heading`` (rad from x towards y).

    The places are :func:`tmem.world.formation.chain`'s, turned by ``heading``.

    Parameters
    ----------
    n : int
        The number of slots, >= 1.
    spacing : float
        The distance between consecutive slots (m).
    heading : float
        The line's direction in the x-y plane (rad, from the x axis); 0 on one axis.
    axes : int
        1, 2 or 3.

    Returns
    -------
    Slots
        Offsets and the ``n - 1`` edges between consecutive slots.
    """
    n = _count("n", n, 1)
    _check(spacing, axes)
    if axes == 1 and math.sin(heading) != 0.0:
        raise ValueError(f"on one axis the heading must be 0 or pi, got {heading}")
    offsets = formation.chain(n, spacing, axes).positions
    if axes > 1:
        turn = np.array([[math.cos(heading), math.sin(heading)], [-math.sin(heading), math.cos(heading)]])
        offsets[:, :2] = offsets[:, :2] @ turn
    elif math.cos(heading) < 0.0:
        offsets = -offsets
    return _slots(offsets, spacing)


def ring_slots(n: int, spacing: float, axes: int = 2) -> Slots:
    """A regular ``n``-gon of side ``spacing`` (:func:`tmem.world.formation.ring`'s places).

    Parameters
    ----------
    n : int
        The number of slots, >= 3.
    spacing : float
        The side (m); the circumradius is ``spacing / (2 sin(pi / n))``.
    axes : int
        2 or 3.

    Returns
    -------
    Slots
        Offsets and the ``n`` sides as edges.
    """
    n = _count("n", n, 3)
    _check(spacing, axes)
    return _slots(formation.ring(n, spacing, axes).positions, spacing)


def grid_slots(rows: int, cols: int, spacing: float, axes: int = 2) -> Slots:
    """A rectangular grid of ``rows x cols`` slots, ``spacing`` apart along x (columns) and y (rows).

    Slot ``r cols + c`` is in row ``r`` and column ``c``.

    Parameters
    ----------
    rows : int
        Rows along y, >= 1.
    cols : int
        Columns along x, >= 1.
    spacing : float
        The distance between neighbouring slots in a row or a column (m).
    axes : int
        2 or 3; 1 for a single row.

    Returns
    -------
    Slots
        Offsets and the ``2 rows cols - rows - cols`` edges.
    """
    rows, cols = _count("rows", rows, 1), _count("cols", cols, 1)
    _check(spacing, axes)
    if axes == 1 and rows > 1:
        raise ValueError(f"a grid of {rows} rows needs at least 2 axes")
    y, x = np.divmod(np.arange(rows * cols), cols)
    offsets = np.zeros((rows * cols, axes))
    offsets[:, 0] = spacing * (x - (cols - 1) / 2.0)
    if axes > 1:
        offsets[:, 1] = spacing * (y - (rows - 1) / 2.0)
    return _slots(offsets, spacing)
