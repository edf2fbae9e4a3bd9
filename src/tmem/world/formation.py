"""Formations as coupling graphs, and generators for the common shapes.

A formation is a set of edges ``(i, j, d_t)``, each with an optional required
direction from agent ``i`` to agent ``j`` (the paper's problem statement:
keep "the distance and direction to a neighbouring agent").  Agents interact
through the switching function (10) or (11) with their formation neighbours
and through the repulsion (8) with everyone else.

Generators return the agents' places in the formation (centred on the
origin, in the x-y plane) with the edges between lattice neighbours:

* ``chain``    — n agents on a line, d_t apart (Fig. 1 is a chain of three);
* ``ring``     — a regular polygon of n agents with side d_t;
* ``triangle`` — the ring of three;
* ``hex``      — a hexagonal patch: the n points of a triangular lattice of
  spacing d_t nearest its centre, each joined to its lattice neighbours.

Every generator takes the number of agents ``n`` (int), the set distance ``d_t`` of each coupled
pair (float, m), the number of ``axes`` (1, 2 or 3: the shape lies in the x-y plane, on the x axis
in 1-D) and ``bearing`` (bool: whether each pair also holds its direction ``P_j - P_i``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KINDS = ("chain", "ring", "triangle", "hex", "edges")


@dataclass(frozen=True)
class Formation:
    """Agents' places and the coupling graph.

    Attributes
    ----------
    positions : ndarray, shape (n, axes)
        Places in the formation, centred on the origin (m).
    edges : ndarray, shape (m, 2)
        Agent pairs ``(i, j)``, ``i < j``.
    d_t : ndarray, shape (m,)
        Set distance of each edge (m).
    direction : ndarray, shape (m, axes)
        Required unit direction from ``i`` to ``j``, or NaN rows where only the
        distance is held.
    """

    positions: np.ndarray
    edges: np.ndarray
    d_t: np.ndarray
    direction: np.ndarray


def _place(points: np.ndarray, axes: int) -> np.ndarray:
    """Planar ``points`` in an ``axes``-dimensional space, centred on the origin."""
    if axes == 1 and np.any(points[:, 1] != 0.0):
        raise ValueError("this formation is planar and needs at least 2 axes")
    out = np.zeros((len(points), axes))
    out[:, : min(axes, 2)] = points[:, : min(axes, 2)]
    return out - out.mean(axis=0)


def _with_edges(positions: np.ndarray, edges: list[tuple[int, int]], d_t: float, bearing: bool) -> Formation:
    edges_array = np.array(sorted((min(i, j), max(i, j)) for i, j in edges), dtype=np.int64).reshape(-1, 2)
    delta = positions[edges_array[:, 1]] - positions[edges_array[:, 0]]
    direction = delta / np.linalg.norm(delta, axis=1, keepdims=True)
    if not bearing:
        direction = np.full_like(direction, np.nan)
    return Formation(positions, edges_array, np.full(len(edges_array), float(d_t)), direction)


def chain(n: int, d_t: float, axes: int = 2, bearing: bool = False) -> Formation:
    """``n`` agents along x, ``d_t`` apart, each coupled to the next.

    Parameters
    ----------
    n, d_t, axes, bearing
        As every generator takes them (module text).
    """
    points = np.stack([np.arange(n) * d_t, np.zeros(n)], axis=1)
    return _with_edges(_place(points, axes), [(k, k + 1) for k in range(n - 1)], d_t, bearing)


def ring(n: int, d_t: float, axes: int = 2, bearing: bool = False) -> Formation:
    """A regular ``n``-gon of side ``d_t``, each agent coupled to both its neighbours.

    Parameters
    ----------
    n, d_t, axes, bearing
        As every generator takes them (module text).
    """
    if n < 3:
        raise ValueError(f"a ring needs at least 3 agents, got {n}")
    radius = d_t / (2.0 * np.sin(np.pi / n))
    angle = 2.0 * np.pi * np.arange(n) / n
    points = radius * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    return _with_edges(_place(points, axes), [(k, (k + 1) % n) for k in range(n)], d_t, bearing)


def triangle(d_t: float, axes: int = 2, bearing: bool = False) -> Formation:
    """Three agents, all coupled (Fig. 1).

    Parameters
    ----------
    d_t, axes, bearing
        As every generator takes them (module text); the ring's ``n`` is 3.
    """
    return ring(3, d_t, axes, bearing)


def hex_patch(n: int, d_t: float, axes: int = 2, bearing: bool = False) -> Formation:
    """The ``n`` points of a triangular lattice of spacing ``d_t`` nearest the centre.

    For n = 7, 19, 37, ... this is a full hexagon.  Ties in distance are
    broken by angle, so the patch is the same on every machine.  Lattice
    point ``(a, b)`` sits at ``d_t (a + b / 2, b sqrt(3) / 2)``; its six
    neighbours differ by one of :data:`_HEX_NEIGHBOURS`.

    Parameters
    ----------
    n, d_t, axes, bearing
        As every generator takes them (module text).
    """
    span = int(np.ceil(np.sqrt(n))) + 2
    a, b = (g.ravel() for g in np.meshgrid(np.arange(-span, span + 1), np.arange(-span, span + 1)))
    points = np.stack([a + 0.5 * b, b * np.sqrt(3) / 2], axis=1)
    radius = np.round(np.hypot(points[:, 0], points[:, 1]), 9)
    angle = np.round(np.mod(np.arctan2(points[:, 1], points[:, 0]), 2 * np.pi), 9)
    chosen = np.lexsort((angle, radius))[:n]
    index = {(int(a[k]), int(b[k])): m for m, k in enumerate(chosen)}
    edges = [
        (m, index[(int(a[k]) + da, int(b[k]) + db)])
        for m, k in enumerate(chosen)
        for da, db in _HEX_NEIGHBOURS
        if (int(a[k]) + da, int(b[k]) + db) in index
    ]
    return _with_edges(_place(points[chosen] * d_t, axes), edges, d_t, bearing)


#: Lattice offsets to three of a point's six neighbours; the other three find it in turn.
_HEX_NEIGHBOURS = ((1, 0), (0, 1), (-1, 1))


def generate(kind: str, n: int, d_t: float, axes: int, bearing: bool = False) -> Formation:
    """The formation ``kind`` (``chain``, ``ring``, ``triangle`` or ``hex``) of ``n`` agents.

    Parameters
    ----------
    kind : str
        ``"chain"``, ``"ring"``, ``"triangle"`` (``n`` ignored: 3) or ``"hex"``.
    n, d_t, axes, bearing
        As every generator takes them (module text).
    """
    if kind == "chain":
        return chain(n, d_t, axes, bearing)
    if kind == "ring":
        return ring(n, d_t, axes, bearing)
    if kind == "triangle":
        return triangle(d_t, axes, bearing)
    if kind == "hex":
        return hex_patch(n, d_t, axes, bearing)
    raise ValueError(f"unknown formation kind {kind!r}; choose from {', '.join(KINDS[:-1])}")
