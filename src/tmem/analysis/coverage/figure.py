"""The coverage map as a figure (:mod:`tmem.analysis.coverage`): the time of each cell's first visit, cells
never visited in grey, obstacles outlined.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tmem.analysis.coverage.grid import Obstacle, check_obstacles
from tmem.analysis.coverage.metric import Coverage


def plot_coverage(cov: Coverage, ax=None, obstacles: Sequence[Obstacle] = (), title: str | None = None):
    """Draw the map of first-visit times, never-visited cells in light grey, obstacles outlined.

    Parameters
    ----------
    cov : Coverage
        A result of :func:`~tmem.analysis.coverage.metric.coverage`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; a new figure (no pyplot, no window) by default.
    obstacles : sequence of (center, radius)
        Circles to outline, as given to :func:`~tmem.analysis.coverage.metric.coverage`.
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
    for center, radius in check_obstacles(obstacles, dims):
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
