"""A group's route around circular obstacles in the plane: the shortest path in a visibility graph.

The group (its formation's circumradius plus a margin) is to keep ``clearance`` from every obstacle
``k`` (a disc of centre ``c_k`` and radius ``r_k``), i.e. its route's centre line stays outside
the *inflated* discs of radius ``rho_k = r_k + clearance`` (the configuration-space obstacles of a
disc robot: Lozano-Perez and Wesley 1979 [1]_).

Each inflated disc is replaced by its circumscribed regular ``m``-gon (vertex radius
``rho_k / cos(pi / m)``, so the polygon contains the disc and its sides touch it).  The graph's
nodes are the start, the goal and the polygons' vertices that lie outside every inflated disc; two
nodes are joined when the segment between them stays outside every inflated disc (the
segment-to-centre distance in closed form: the centre's projection on the segment, clipped to its
ends).  The shortest path is found by :func:`scipy.sparse.csgraph.dijkstra`.  Visibility graphs
give the shortest paths among polygons ([1]_; de Berg et al. [2]_, ch. 15); here the edges are
tested against the discs, which the polygons contain, so:

* every segment of the route keeps at least ``clearance`` from every obstacle, and
* the route is no shorter than the true shortest path ``L*`` around the inflated discs and no
  longer than ``L* / cos(pi / m)``: it is at most the shortest path around the polygons, itself
  at most the shortest path around the discs of radius ``rho_k / cos(pi / m)``, and a path's
  length around discs grows no faster than their radius (for one disc,
  ``dL / d rho = phi <= L / rho``, ``phi`` the angle of the arc) — 2 % for ``m = 16``.

A gap between two inflated discs narrower than the polygons' corners reach past them,
``rho (1 / cos(pi / m) - 1)``, may be missed (its vertices fall inside the other disc): raise
``sides`` to find it.

References
----------
.. [1] T. Lozano-Perez and M. A. Wesley, "An algorithm for planning collision-free paths among
   polyhedral obstacles", Communications of the ACM 22(10), 560-570 (1979).
.. [2] M. de Berg, O. Cheong, M. van Kreveld and M. Overmars, "Computational Geometry: Algorithms
   and Applications", 3rd ed., Springer (2008), ch. 15 "Visibility Graphs".
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["plan_route", "polygon_vertices", "route_clearance", "route_length", "segment_distances"]

#: Relative slack of the tests against an inflated disc: a polygon's side touches its disc, and a
#: segment that touches a disc within rounding still counts as outside it.
TOLERANCE = 1e-9

#: Pairs of nodes times discs tested at once (memory: about 40 bytes each).
_BLOCK = 2_000_000


def segment_distances(p: np.ndarray, q: np.ndarray, centers: np.ndarray) -> np.ndarray:
    """The distance from each segment ``p_s q_s`` to each point ``c_k`` (closed form).

    The nearest point of a segment to ``c`` is ``p + t (q - p)`` with
    ``t = clip((c - p) . (q - p) / |q - p|^2, 0, 1)`` (``t = 0`` for a segment of zero length).

    Parameters
    ----------
    p, q : ndarray, shape (S, 2)
        The segments' ends (m).
    centers : ndarray, shape (K, 2)
        The points (m).

    Returns
    -------
    ndarray, shape (S, K)
        Distances (m).
    """
    p, q, centers = (np.asarray(v, dtype=float) for v in (p, q, centers))
    along = q - p
    length2 = np.einsum("sd,sd->s", along, along)[:, None]
    to_center = centers[None, :, :] - p[:, None, :]
    dot = np.einsum("skd,sd->sk", to_center, along)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.where(length2 > 0.0, dot / length2, 0.0), 0.0, 1.0)
    return np.linalg.norm(to_center - t[..., None] * along[:, None, :], axis=2)


def polygon_vertices(centers: np.ndarray, inflated: np.ndarray, sides: int = 16) -> np.ndarray:
    """The vertices of each disc's circumscribed regular ``sides``-gon, at radius ``rho / cos(pi / sides)``.

    Parameters
    ----------
    centers : ndarray, shape (K, 2)
        The discs' centres (m).
    inflated : ndarray, shape (K,)
        Their radii ``rho`` (m).
    sides : int
        ``m`` >= 3.

    Returns
    -------
    ndarray, shape (K * sides, 2)
        Disc ``k``'s vertices are rows ``k sides`` to ``(k + 1) sides - 1``, counter-clockwise from +x.
    """
    angle = 2.0 * np.pi * np.arange(sides) / sides
    unit = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    reach = np.asarray(inflated, dtype=float)[:, None, None] / math.cos(math.pi / sides)
    return (np.asarray(centers, dtype=float)[:, None, :] + reach * unit[None, :, :]).reshape(-1, 2)


def route_length(waypoints: np.ndarray) -> float:
    """The length of the polyline through ``waypoints`` (m).

    Parameters
    ----------
    waypoints : ndarray, shape (W, 2)
        The route's corners, start and goal included (m).
    """
    waypoints = np.asarray(waypoints, dtype=float)
    return float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1)))


def route_clearance(waypoints: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> float:
    """The least distance from the polyline through ``waypoints`` to any obstacle's edge (m; ``inf`` if none).

    Parameters
    ----------
    waypoints : ndarray, shape (W, 2)
        The route's corners (m).
    centers : ndarray, shape (K, 2)
        Obstacle centres (m).
    radii : ndarray, shape (K,)
        Obstacle radii (m).
    """
    waypoints = np.asarray(waypoints, dtype=float)
    if len(centers) == 0:
        return math.inf
    gaps = segment_distances(waypoints[:-1], waypoints[1:], centers) - np.asarray(radii, dtype=float)[None, :]
    return float(gaps.min(initial=math.inf))


def _obstacles(start: object, goal: object, centers: object, radii: object, clearance: float) -> tuple[np.ndarray, ...]:
    """The checked inputs: start, goal (2,), centres (K, 2) and inflated radii (K,)."""
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    centers = np.asarray(centers, dtype=float).reshape(-1, 2) if np.size(centers) else np.zeros((0, 2))
    radii = np.asarray(radii, dtype=float).reshape(-1)
    if start.shape != (2,) or goal.shape != (2,):
        raise ValueError(f"start and goal must be points (x, y), got shapes {start.shape} and {goal.shape}")
    if len(radii) != len(centers):
        raise ValueError(f"{len(centers)} obstacle centres but {len(radii)} radii")
    if not (np.all(np.isfinite(centers)) and np.all(np.isfinite(radii)) and np.all(radii >= 0.0)):
        raise ValueError("obstacle centres must be finite and radii finite and >= 0 m")
    if not (math.isfinite(clearance) and clearance >= 0.0):
        raise ValueError(f"clearance must be a finite distance >= 0 m, got {clearance}")
    inflated = radii + clearance
    for name, point in (("start", start), ("goal", goal)):
        if not np.all(np.isfinite(point)):
            raise ValueError(f"{name} must be finite, got {point.tolist()}")
        distance = np.linalg.norm(centers - point, axis=1)
        inside = np.nonzero(distance < inflated * (1.0 - TOLERANCE))[0]
        if len(inside):
            k = int(inside[np.argmin(distance[inside] - inflated[inside])])
            raise ValueError(
                f"{name} ({point[0]:g}, {point[1]:g}) is {distance[k]:.6g} m from obstacle {k}'s centre, within its"
                f" radius + clearance = {radii[k]:g} + {clearance:g} = {inflated[k]:.6g} m"
            )
    return start, goal, centers, inflated


def _visible(nodes: np.ndarray, centers: np.ndarray, inflated: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs ``(i, j)``, ``i < j``, of nodes whose segment stays outside every inflated disc, and its length."""
    i, j = np.triu_indices(len(nodes), 1)
    keep = np.ones(len(i), dtype=bool)
    block = max(1, _BLOCK // max(1, len(centers)))
    for lo in range(0, len(i), block):
        part = slice(lo, lo + block)
        if len(centers):
            distance = segment_distances(nodes[i[part]], nodes[j[part]], centers)
            keep[part] = np.all(distance >= inflated[None, :] * (1.0 - TOLERANCE), axis=1)
    i, j = i[keep], j[keep]
    return i, j, np.linalg.norm(nodes[j] - nodes[i], axis=1)


def plan_route(
    start: object, goal: object, centers: object, radii: object, clearance: float, sides: int = 16
) -> np.ndarray:
    """The shortest route from ``start`` to ``goal`` keeping ``clearance`` from circular obstacles (module text).

    Parameters
    ----------
    start, goal : array_like, shape (2,)
        The route's ends (m); each must lie outside every obstacle inflated by ``clearance``.
    centers : array_like, shape (K, 2)
        Obstacle centres (m); K may be 0.
    radii : array_like, shape (K,)
        Obstacle radii (m), >= 0.
    clearance : float
        The least distance to keep from every obstacle (m), >= 0.
    sides : int
        ``m``, the sides of each inflated disc's circumscribed polygon (>= 3; default 16): the route
        is at most ``1 / cos(pi / m)`` times the shortest.

    Returns
    -------
    ndarray, shape (W, 2)
        Waypoints from ``start`` to ``goal``, both included; :func:`route_length` gives its length.

    Raises
    ------
    ValueError
        When ``start`` or ``goal`` lies within an obstacle's radius + clearance, or when no route
        clears the obstacles.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    if isinstance(sides, bool) or int(sides) != sides or sides < 3:
        raise ValueError(f"sides must be an integer >= 3, got {sides}")
    start, goal, centers, inflated = _obstacles(start, goal, centers, radii, clearance)
    direct = segment_distances(start[None], goal[None], centers)
    if np.all(direct >= inflated[None, :] * (1.0 - TOLERANCE)):
        return np.stack([start, goal])
    corners = polygon_vertices(centers, inflated, int(sides))
    outside = np.all(np.linalg.norm(corners[:, None, :] - centers[None], axis=2) >= inflated * (1.0 - TOLERANCE), axis=1)
    nodes = np.concatenate([start[None], goal[None], corners[outside]])
    i, j, length = _visible(nodes, centers, inflated)
    graph = coo_matrix((length, (i, j)), shape=(len(nodes), len(nodes))).tocsr()
    distance, previous = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not math.isfinite(distance[1]):
        raise ValueError(
            f"no route from start to goal keeps {clearance:g} m from the obstacles: they close every way"
            f" (or a gap is narrower than the {sides}-gons' corners; try more sides)"
        )
    path = [1]
    while path[-1] != 0:
        path.append(int(previous[path[-1]]))
    return nodes[path[::-1]]
