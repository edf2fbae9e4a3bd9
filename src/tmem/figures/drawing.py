"""What the run's figures and its animation share: agents numbered as the paper numbers them, which
agents and pairs are drawn one by one (and the note that says so), the strain colour scale, the
walls and obstacles.

Numbering
---------
The paper numbers its agents from 1 (agents 1 and 2 of its Table 2); so does every figure, legend
and animation.  The files (the scenario's ``pair = [0, 1]``, ``summary.json``, ``trajectory.nc``)
index agents from 0: the agent of index ``i`` in a file is agent ``i + 1`` in a figure.

Which ones are drawn
--------------------
A figure draws every agent and every pair one by one up to :data:`MAX_LINES` of them; past that it
draws that many and says in its title which ones and why (``"100 of 400 agents: the first 100
recorded"``; in ``paths.png``, agents spread over where the swarm started, :func:`spread_agents`).  Up to :data:`MAX_LEGEND` lines get a legend entry each; more are coloured by agent
number, with a colour bar.

Strain
------
The strain of a coupled pair is ``|P_j - P_i| / d_t - 1``: 0 at the set distance.  Its colour
scale is symmetric about 0 and reaches the run's largest ``|strain|`` (:func:`strain_limit`), but
no less than :data:`STRAIN_FLOOR`: a formation held to a few millimetres is drawn black, not in
colours that magnify noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Colormap, LinearSegmentedColormap, Normalize

#: Most agents or pairs drawn one by one in a figure.
MAX_LINES = 100
#: Most lines given a legend entry each; more are coloured by number.
MAX_LEGEND = 10
#: Most agents written with their numbers beside them.
MAX_NUMBERED = 30
#: Smallest end of the strain colour scale: 1 %.
STRAIN_FLOOR = 0.01


def run_title(trajectory, note: str = "") -> str:
    """A figure's title: the run's name, function and ``c_max``, and ``note`` on a second line.

    Set it with ``parse_math=False``: a ``$`` in the scenario's name is a dollar, not mathtext.

    Parameters
    ----------
    trajectory : Trajectory
        A run.
    note : str
        Which agents or pairs the figure draws, when not all (:attr:`Chosen.note`).
    """
    s = trajectory.scenario
    name = f"{s.name}: " if s.name else ""
    title = f"{name}{s.interaction.function} function, c_max = {s.interaction.c_max:g} rad"
    return f"{title}\n{note}" if note else title


def agent_label(index: int) -> str:
    """The figure's name of the agent of file index ``index``: ``"agent 1"`` for index 0.

    Parameters
    ----------
    index : int
        The agent's index in the files (from 0).
    """
    return f"agent {int(index) + 1}"


def pair_label(i: int, j: int) -> str:
    """The figure's name of the pair of file indices ``(i, j)``: ``"agents 1-2"`` for ``(0, 1)``.

    Parameters
    ----------
    i, j : int
        The agents' indices in the files (from 0).
    """
    return f"agents {int(i) + 1}-{int(j) + 1}"


@dataclass(frozen=True)
class Chosen:
    """Which of ``total`` agents or pairs a figure draws one by one, and the note saying so.

    Attributes
    ----------
    index : ndarray of int
        Positions of the drawn ones among the ``total``.
    total : int
        How many there are.
    note : str
        ``""`` when every one is drawn, else which ones and why (``"100 of 400 agents: the first 100
        recorded"``).
    """

    index: np.ndarray
    total: int
    note: str


def _chosen(total: int, at_most: int | None, pick) -> Chosen:
    """Every one of ``total`` if they are no more than ``at_most`` (default :data:`MAX_LINES`), else
    ``pick(at_most)``'s positions and note."""
    at_most = MAX_LINES if at_most is None else at_most
    if total <= at_most:
        return Chosen(np.arange(total), total, "")
    index, note = pick(at_most)
    return Chosen(index, total, note)


def first_agents(total: int, at_most: int | None = None) -> Chosen:
    """The first ``at_most`` of ``total`` recorded agents.

    Parameters
    ----------
    total : int
        Agents recorded.
    at_most : int, optional
        Most drawn; default :data:`MAX_LINES`.
    """
    return _chosen(total, at_most, lambda m: (np.arange(m), f"{m} of {total} agents: the first {m} recorded"))


def spread_agents(starts: np.ndarray, box: np.ndarray | None = None, at_most: int | None = None) -> Chosen:
    """At most ``at_most`` agents spread over where the swarm started: each the farthest from those
    already chosen (farthest-point sampling), from the one nearest the middle of the starts.

    Agents numbered by where they were placed (rows or cells of a lattice, a random draw sorted
    into strips) would otherwise all be drawn from one part of the space.

    Parameters
    ----------
    starts : ndarray, shape (agents, axes)
        Each agent's first flying position (m); NaN for an agent that never flew (chosen last).
    box : ndarray, shape (axes,), optional
        The periodic box's sides (m), to measure across its edges; None or 0 on an open axis.
    at_most : int, optional
        Most chosen; default :data:`MAX_LINES`.
    """
    return _chosen(len(starts), at_most, lambda m: _farthest_points(starts, box, m))


def _farthest_points(starts: np.ndarray, box: np.ndarray | None, count: int) -> tuple[np.ndarray, str]:
    """``count`` agents by farthest-point sampling of ``starts`` (:func:`spread_agents`), and the note."""
    total = len(starts)
    flew = np.isfinite(starts).all(axis=1)
    points = np.where(flew[:, None], starts, 0.0)
    sides = np.zeros(starts.shape[1]) if box is None else np.asarray(box, dtype=float)

    def distances(point: np.ndarray) -> np.ndarray:
        delta = points - point
        delta = np.where(sides > 0, delta - sides * np.round(delta / np.where(sides > 0, sides, 1.0)), delta)
        return np.where(flew, np.linalg.norm(delta, axis=1), -1.0)

    middle = points[flew].mean(axis=0) if flew.any() else np.zeros(starts.shape[1])
    chosen = [int(np.argmin(np.where(flew, np.linalg.norm(points - middle, axis=1), np.inf)))]
    nearest = distances(points[chosen[0]])
    for _ in range(count - 1):
        k = int(np.argmax(nearest))
        if nearest[k] < 0:  # every agent that flew is chosen: the rest in their order
            k = int(np.flatnonzero(~np.isin(np.arange(total), chosen))[0])
        chosen.append(k)
        nearest = np.minimum(nearest, distances(points[k]))
        nearest[chosen] = -1.0
    return np.sort(np.array(chosen)), f"{count} of {total} agents: spread over where they started"


def closest_pairs(min_distance: np.ndarray, at_most: int | None = None) -> Chosen:
    """Every pair, or the ``at_most`` pairs that came closest (the ones that interacted most).

    Parameters
    ----------
    min_distance : ndarray, shape (pairs,)
        Each pair's smallest distance over the run (m).
    at_most : int, optional
        Most drawn; default :data:`MAX_LINES`.
    """
    total = len(min_distance)
    closest = lambda m: (np.sort(np.argsort(min_distance, kind="stable")[:m]), f"{m} of {total} pairs: the {m} that came closest")  # noqa: E731
    return _chosen(total, at_most, closest)


def evenly(total: int, at_most: int, noun: str) -> Chosen:
    """At most ``at_most`` of ``total``, evenly spread, the first and last kept.

    Parameters
    ----------
    total : int
        How many there are.
    at_most : int
        Most chosen.
    noun : str
        What they are, plural (``"agents"``), for the note.
    """
    if total <= at_most:
        return Chosen(np.arange(total), total, "")
    index = np.unique(np.round(np.linspace(0, total - 1, at_most)).astype(int))
    return Chosen(index, total, f"{len(index)} of {total} {noun}: evenly spread over their numbers")


def columns_of(ids: np.ndarray, wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where each of ``wanted`` (agent indices) is in ``ids`` (the recorded agents), and whether it is there.

    Parameters
    ----------
    ids : ndarray of int
        The recorded agents' indices, in their order.
    wanted : ndarray of int
        Agent indices to find (a pair's agents).
    """
    ids, wanted = np.asarray(ids), np.asarray(wanted)
    if not len(ids):
        return np.zeros(wanted.shape, int), np.zeros(wanted.shape, bool)
    order = np.argsort(ids)
    k = order[np.clip(np.searchsorted(ids, wanted, sorter=order), 0, len(ids) - 1)]
    return k, ids[k] == wanted


def agent_colors(indices: np.ndarray) -> tuple[list, ScalarMappable | None]:
    """A colour for each agent (by file index), and the colour bar's mappable when they are too many
    for a legend (``None`` otherwise).

    Parameters
    ----------
    indices : ndarray of int
        The drawn agents' file indices.
    """
    if len(indices) <= MAX_LEGEND:
        return [f"C{k % 10}" for k in range(len(indices))], None
    numbers = np.asarray(indices) + 1
    mappable = ScalarMappable(Normalize(numbers.min(), max(numbers.max(), numbers.min() + 1)), colormaps["viridis"])
    return list(mappable.to_rgba(numbers)), mappable


def agents_legend(ax, mappable: ScalarMappable | None, extra=()) -> None:
    """A legend entry per agent when they are few; else a colour bar of agent numbers and a legend of the rest.

    Parameters
    ----------
    ax : matplotlib Axes
        The axes whose lines are labelled ``agent 1``, ``agent 2`` ...
    mappable : ScalarMappable or None
        The colour bar's mappable of :func:`agent_colors` (None: a legend entry each).
    extra : sequence of Artist
        Further legend entries (markers of the start and end).
    """
    handles = [h for h in ax.get_legend_handles_labels()[0] if mappable is None or not h.get_label().startswith("agent ")]
    handles += list(extra)
    if handles:
        ax.legend(handles=handles, loc="best", fontsize=8)
    if mappable is not None:
        ax.figure.colorbar(mappable, ax=ax.figure.axes, label="agent", shrink=0.8)


def strain(distance: np.ndarray, d_t: np.ndarray) -> np.ndarray:
    """The strain ``|P_j - P_i| / d_t - 1`` of pairs.

    Parameters
    ----------
    distance : ndarray
        ``|P_j - P_i|`` (m).
    d_t : ndarray
        The pairs' set distances (m), broadcast against ``distance``.
    """
    return np.asarray(distance, dtype=float) / np.asarray(d_t, dtype=float) - 1.0


def strain_limit(values: np.ndarray) -> float:
    """The end of the strain colour scale: the largest finite ``|strain|`` in ``values``, at least
    :data:`STRAIN_FLOOR`.

    Parameters
    ----------
    values : ndarray
        Strains of coupled pairs (any shape; NaN entries are ignored).
    """
    values = np.abs(np.asarray(values, dtype=float))
    finite = values[np.isfinite(values)]
    return float(max(finite.max(initial=0.0), STRAIN_FLOOR))


def strain_norm(limit: float) -> Normalize:
    """The strain colour scale from ``-limit`` to ``limit``.

    Parameters
    ----------
    limit : float
        :func:`strain_limit` of the run.
    """
    return Normalize(-limit, limit)


def strain_colormap() -> Colormap:
    """Black at the set distance, blue when closer, red when farther; black where ``d_t`` is unknown."""
    return LinearSegmentedColormap.from_list("strain", ["tab:blue", "k", "tab:red"]).with_extremes(bad="k")


#: The colour bar's label for strain.
STRAIN_LABEL = "coupled pair strain |P_j - P_i| / d_t - 1"


def draw_region(ax, box, walls: bool, obstacles) -> None:
    """Draw the walls of a 2-D box (from 0 to ``box``) and the obstacles' circles on ``ax``.

    Parameters
    ----------
    ax : matplotlib Axes
        Axes in the (x, y) plane.
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
