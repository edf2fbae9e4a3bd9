"""The grid of the coverage metric (:mod:`tmem.analysis.coverage`): square cells of side ``cell`` over the
box's first two axes, and the field, the cells whose centre lies outside every obstacle; the checks
of the box, cell, sensor radius and obstacles they are built from.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: Most cells a grid may have (its first-visit map alone takes 8 bytes a cell).
MAX_CELLS = 50_000_000
#: Most cells of a map whose cell is not given (``[coverage] cell``): more than the 720 x 600 pixels
#: of ``field.png`` (6 x 5 in at 120 dpi), so that a finer map would show nothing more.
DEFAULT_CELLS = 1_000_000

Obstacle = tuple[Sequence[float], float]


def check_sizes(box, cell, sensor_radius, axes: int) -> tuple[np.ndarray, float, float]:
    """The box sides as an array, the cell side and the sensor radius, checked.

    Parameters
    ----------
    box : sequence of float
        The region's side per axis (m), as given to :func:`tmem.analysis.coverage.coverage`.
    cell : float
        The cell side (m).
    sensor_radius : float
        The sensor range (m).
    axes : int
        Axes of the positions (1 to 3); the first two at most are covered.

    Raises
    ------
    ValueError
        Naming the argument that is out of range, or the cell when the grid would exceed
        :data:`MAX_CELLS`.
    """
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


def finest_cell(sides, cell: float, most: int = DEFAULT_CELLS) -> float:
    """``cell``, or, where it would cut the sides into more than ``most`` cells, the smallest cell
    side (m) that cuts them into at most that many.

    Parameters
    ----------
    sides : sequence of float
        The sides of the covered axes (m): a walled box's first two at most.
    cell : float
        The cell side wanted (m).
    most : int
        The most cells (:data:`DEFAULT_CELLS`, for a map whose cell is not given).
    """
    sides = [float(s) for s in sides]
    count = lambda c: math.prod(math.ceil(s / c) for s in sides)  # noqa: E731 (the schema's count, unrounded)
    if count(cell) <= most:
        return cell
    coarser = (math.prod(sides) / most) ** (1.0 / len(sides))
    while count(coarser) > most:  # the ceilings add a part of a cell per axis: a step or two
        coarser *= 1.0 + 1e-6
    return coarser


def check_obstacles(obstacles, dims: int) -> list[tuple[np.ndarray, float]]:
    """Each obstacle as (its first ``dims`` centre coordinates, radius), checked.

    Parameters
    ----------
    obstacles : sequence of (center, radius)
        Circles (intervals with one axis), as given to :func:`tmem.analysis.coverage.coverage`.
    dims : int
        Covered axes, 1 or 2.

    Raises
    ------
    ValueError
        Naming the obstacle that is not a (center, radius) pair of finite numbers.
    """
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


def grid_shape(sides: np.ndarray, cell: float) -> tuple[int, ...]:
    """Cells per covered axis: enough to hold the side (rounded to 9 decimals first, so 0.3 / 0.1 is 3).

    Parameters
    ----------
    sides : ndarray, shape (dims,)
        The sides of the covered axes (m).
    cell : float
        The cell side (m).
    """
    return tuple(max(1, int(n)) for n in np.ceil(np.round(sides / cell, 9)))


def _centres(shape: tuple[int, ...], cell: float) -> list[np.ndarray]:
    """The cell centres' coordinates, one open-mesh array per axis."""
    return [(index + 0.5) * cell for index in np.ix_(*(np.arange(n) for n in shape))]


def field_cells(shape: tuple[int, ...], cell: float, circles: list[tuple[np.ndarray, float]]) -> np.ndarray:
    """The cells whose centre lies outside every obstacle (strictly inside one: out of the field).

    Parameters
    ----------
    shape : tuple of int
        Cells per covered axis (:func:`grid_shape`).
    cell : float
        The cell side (m).
    circles : list of (ndarray, float)
        The obstacles as :func:`check_obstacles` gives them.

    Returns
    -------
    ndarray, bool, shape ``shape``
        ``True`` for the cells of the field.

    Raises
    ------
    ValueError
        When the obstacles cover every cell.
    """
    centres = _centres(shape, cell)
    field = np.ones(shape, dtype=bool)
    for center, radius in circles:
        field &= sum((c - x) ** 2 for c, x in zip(centres, center)) >= radius**2
    if not field.any():
        raise ValueError("obstacles: they cover every cell of the box; no field is left")
    return field
