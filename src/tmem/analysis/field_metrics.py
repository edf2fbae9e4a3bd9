"""The metrics the flocking literature reports, on recorded arrays: order, separation, near misses, collisions,
groups, algebraic connectivity, clearance, formation errors, shape, time to a goal.

Pure NumPy/SciPy functions of what any simulator records: ``positions`` (records, agents, axes) in m,
``velocities`` (records, agents, axes) in m/s, ``times`` (records,) in s, ``active`` (records, agents), bool,
the agents that count (``None``: all).  Per-record values are NaN where undefined (too few agents).  The RMS
velocity is :func:`tmem.analysis.rms.rms_velocity`.  Sources, each function saying where it differs:
SwarmLab (Soria et al., arXiv:2005.02769; ``compute_swarm_performance.m`` of github.com/lis-epfl/swarmlab at
3574ded) and Vásárhelyi et al., Sci. Robot. 3, eaat3536 (2018), "Order parameters" (its simulator's
statistics: ``src/algo_spp_evol_stat.c`` of github.com/csviragh/robotsim).

:func:`field_summary` returns a flat dict of JSON-ready values, ``None`` where the input is not given or the
value undefined:

* ``order_mean`` (1): :func:`order`'s mean over the records of the run's second half (by ``times``);
  ``order_min`` (1): its least.  ``min_separation`` (m): :func:`min_separation`.
* ``near_misses`` (count), ``safety_share_max`` and ``safety_share_mean`` (1), ``closest_pass`` (m):
  :func:`near_misses` at ``safety_radius``: its ``count``, the largest and the mean of its
  ``pairs_within_share``, its ``closest_pass``.  ``collisions`` (count): :func:`collisions`.
* ``union_max`` (count): the most groups at once (:func:`union`); ``algebraic_connectivity_min`` (1):
  the least :func:`algebraic_connectivity` over the records it evaluates (every ``connectivity_every``-th),
  ``None`` with over :data:`MAX_CONNECTIVITY_AGENTS` agents.
* ``min_obstacle_clearance`` and ``min_wall_clearance`` (m): the least :func:`obstacle_clearance` and
  :func:`wall_clearance`.  ``shape_distance_final`` (m): :func:`shape_distance` at the last record.
* ``edge_error_max`` and ``edge_error_rms`` (m): the largest ``|e|`` and the RMS of :func:`edge_errors`
  over every record and edge the formation holds then (``members``; every edge by default);
  ``edge_error_max_final`` and ``edge_error_rms_final`` (m): at the last.  ``time_to_goal`` (s): :func:`time_to_goal`.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigvalsh
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

__all__ = ["order", "separations", "min_separation", "near_misses", "collisions", "union", "algebraic_connectivity",
           "obstacle_clearance", "wall_clearance", "edge_errors", "shape_distance", "time_to_goal", "field_summary"]  # fmt: skip

#: The most active agents :func:`algebraic_connectivity` takes (a dense eigenvalue problem a record).
MAX_CONNECTIVITY_AGENTS = 2000


def _flying(active: np.ndarray | None, shape: tuple[int, ...]) -> np.ndarray:
    """``active`` as a bool array of ``shape``, every agent where it is ``None``."""
    return np.ones(shape, bool) if active is None else np.broadcast_to(np.asarray(active, bool), shape)


def _reduce(values, how=np.min) -> float | None:
    """``how`` (the smallest by default) of the finite ``values`` as a float, ``None`` where none is finite."""
    values = np.asarray(values, float)
    values = values[np.isfinite(values)]
    return float(how(values)) if values.size else None


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values**2)))


def order(velocities: np.ndarray, active: np.ndarray | None = None) -> np.ndarray:
    """Velocity correlation at each record: the mean of ``v_i . v_j / (|v_i| |v_j|)`` over pairs ``i != j``.

    The all-pairs form of Vásárhelyi et al.'s velocity correlation: 1 when all fly one way, ``-1/(n-1)`` at
    the least.  SwarmLab's "order" averages each agent's correlation with its neighbours within ``r`` only
    (1 for one without any); robotsim's, over the pairs of one communication cluster.  Agents at rest are
    left out; NaN where fewer than two move.  O(n) from the sum ``U`` of unit vectors: ``(|U|^2 - n) / (n (n - 1))``.

    Parameters
    ----------
    velocities, active : the recorded arrays (module docstring)
    """
    v = np.asarray(velocities, float)
    speed = np.linalg.norm(v, axis=-1)
    moving = _flying(active, speed.shape) & (speed > 0)
    total = (np.where(moving[..., None], v, 0.0) / np.where(moving, speed, 1.0)[..., None]).sum(axis=-2)
    n = moving.sum(axis=-1).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n >= 2, (np.sum(total * total, axis=-1) - n) / (n * (n - 1)), np.nan)


def separations(positions: np.ndarray, active: np.ndarray | None = None) -> np.ndarray:
    """The smallest distance between two active agents at each record (m); NaN with fewer than two.

    Parameters
    ----------
    positions, active : the recorded arrays (module docstring)
    """
    p = np.asarray(positions, float)
    flying = _flying(active, p.shape[:2])
    out = np.full(len(p), np.nan)
    for t in range(len(p)):
        points = p[t, flying[t]]
        if len(points) >= 2:
            out[t] = cKDTree(points).query(points, k=2)[0][:, 1].min()
    return out


def min_separation(positions: np.ndarray, active: np.ndarray | None = None) -> float | None:
    """The smallest of :func:`separations` over the run (m); ``None`` where no record has two agents.

    Parameters
    ----------
    positions, active : the recorded arrays (module docstring)
    """
    return _reduce(separations(positions, active))


def _passes(before: np.ndarray, after: np.ndarray, both: np.ndarray, tree: cKDTree, index: np.ndarray, radius: float):
    """For the pairs flying at a record (``after``; ``tree`` of agents ``index``) that may have come within ``radius``
    since the record ``before``: the distance ``now``, ``then`` (inf for a pair not flying at ``both``: no pass), the
    ``least`` on the pass and the fraction of the interval at which it first came within ``radius`` (``enter``).

    On a straight pass the squared distance is a convex quadratic in that fraction, least at ``clip(-r0.w / |w|^2, 0, 1)``
    (``r0`` the separation before, ``w`` its change).  A pair that comes within ``radius`` is within
    ``radius + |d_i| + |d_j|`` at the end (``d`` the moves).
    """
    moves = np.linalg.norm(after[both] - before[both], axis=-1)
    reach = radius + 2.0 * moves.max(initial=0.0)
    pairs = index[tree.query_pairs(reach, output_type="ndarray")].reshape(-1, 2)
    i, j = pairs[:, 0], pairs[:, 1]
    start, end = before[j] - before[i], after[j] - after[i]
    w = end - start
    ww, rw = np.sum(w * w, axis=-1), np.sum(start * w, axis=-1)
    s = np.clip(np.divide(-rw, ww, out=np.zeros_like(ww), where=ww > 0), 0.0, 1.0)
    paired = both[i] & both[j]
    now = np.linalg.norm(end, axis=-1)
    then = np.where(paired, np.linalg.norm(start, axis=-1), np.inf)
    least = np.where(paired, np.linalg.norm(start + s[:, None] * w, axis=-1), now)
    root = np.sqrt(np.maximum(rw * rw - ww * (np.sum(start * start, axis=-1) - radius**2), 0.0))
    enter = np.where(paired, np.divide(-rw - root, ww, out=np.ones_like(ww), where=ww > 0), 1.0)
    return now, then, least, np.clip(enter, 0.0, 1.0)


def near_misses(positions: np.ndarray, times: np.ndarray, safety_radius: float, active: np.ndarray | None = None) -> dict:
    """Encounters closer than ``safety_radius``, the share of pairs that close at each record, the closest pass.

    An encounter, a pair's stay closer than the radius from entering to leaving, counts once; so does a
    pair inside at the first record or when it starts flying.  Between records the agents flying at
    both move in straight lines: a pass that enters and leaves between two records counts too.
    SwarmLab's "safety" is one minus ``pairs_within_share`` (at ``safety_radius = 2 r_coll``).  Near
    O(n log n) a record: a k-d tree is asked for the pairs within the radius plus twice the largest move.

    Parameters
    ----------
    positions, times, active : the recorded arrays (module docstring)
    safety_radius : float
        The distance below which two agents are in an encounter (m).

    Returns
    -------
    dict
        ``count`` (int); ``pairs_within_share`` (records,), NaN with fewer than two agents; ``closest_pass``
        (m), the least distance at the records and on the passes (exact below the radius), ``None``
        without two agents; ``first_time`` (s), when the first encounter began, ``None`` without one.
    """
    p, times = np.asarray(positions, float), np.asarray(times, float)
    flying = _flying(active, p.shape[:2])
    share = np.full(len(p), np.nan)
    count, closest, first = 0, np.inf, None
    for t in range(len(p)):
        index = np.flatnonzero(flying[t])
        tree = cKDTree(p[t, index])
        both = flying[t - 1] & flying[t] if t else np.zeros(p.shape[1], bool)
        now, then, least, enter = _passes(p[t - 1] if t else p[t], p[t], both, tree, index, safety_radius)
        new = (then >= safety_radius) & (least < safety_radius)
        if first is None and new.any():
            start = times[t - 1] if t else times[t]
            first = float(start + enter[new].min() * (times[t] - start))
        count += int(new.sum())
        if len(index) >= 2:
            share[t] = np.count_nonzero(now < safety_radius) / (len(index) * (len(index) - 1) / 2)
            closest = min(closest, tree.query(p[t, index], k=2)[0][:, 1].min(), least.min(initial=np.inf))
    return {"count": count, "pairs_within_share": share, "closest_pass": _reduce(closest), "first_time": first}


def collisions(positions: np.ndarray, times: np.ndarray, collision_radius: float, active: np.ndarray | None = None) -> int:
    """The number of encounters closer than ``collision_radius``: :func:`near_misses`'s ``count`` at it.

    Parameters
    ----------
    positions, times, active : the recorded arrays (module docstring)
    collision_radius : float
        The distance between centres below which two agents collide (m): twice a body's radius.
    """
    return near_misses(positions, times, collision_radius, active)["count"]


def _graph(points: np.ndarray, reach: float) -> coo_matrix:
    """The graph joining the ``points`` closer than ``reach`` to each other, one entry a pair."""
    pairs = cKDTree(points).query_pairs(reach, output_type="ndarray").reshape(-1, 2)
    pairs = pairs[np.linalg.norm(points[pairs[:, 1]] - points[pairs[:, 0]], axis=-1) < reach]
    return coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(points), len(points)))


def union(positions: np.ndarray, communication_range: float, active: np.ndarray | None = None) -> np.ndarray:
    """The number of connected groups at each record (int; 0 without agents), agents closer than the range joined.

    SwarmLab reports it normalised, ``(n - groups) / (n - 1)``, over a graph of each agent's nearest
    neighbours within range; here it is the count, over every pair within range (robotsim's clusters).

    Parameters
    ----------
    positions, active : the recorded arrays (module docstring)
    communication_range : float, m
    """
    p = np.asarray(positions, float)
    flying = _flying(active, p.shape[:2])
    out = np.zeros(len(p), int)
    for t in range(len(p)):
        if flying[t].any():
            out[t] = connected_components(_graph(p[t, flying[t]], communication_range), directed=False)[0]
    return out


def algebraic_connectivity(positions: np.ndarray, communication_range: float, active: np.ndarray | None = None,
                           every: int = 1) -> np.ndarray:  # fmt: skip
    """The second-smallest eigenvalue of the graph Laplacian ``L = D - A`` at each record (Fiedler 1973).

    ``A`` joins the agents closer than ``communication_range``, unweighted: 0 when the graph is
    disconnected, ``n`` when complete.  SwarmLab divides it by ``n``; not here.  A dense eigenvalue
    problem a record: at most :data:`MAX_CONNECTIVITY_AGENTS` agents.  NaN with fewer than two.

    Parameters
    ----------
    positions, active : the recorded arrays (module docstring)
    communication_range : float, m
    every : int
        Evaluate the records 0, ``every``, 2 ``every``, ... only; NaN at the others.
    """
    p = np.asarray(positions, float)
    flying = _flying(active, p.shape[:2])
    if flying.sum(axis=1).max(initial=0) > MAX_CONNECTIVITY_AGENTS:
        raise ValueError(f"algebraic_connectivity takes at most {MAX_CONNECTIVITY_AGENTS} active agents")
    out = np.full(len(p), np.nan)
    for t in range(0, len(p), every):
        points = p[t, flying[t]]
        graph = _graph(points, communication_range)
        if len(points) >= 2 and connected_components(graph, directed=False)[0] > 1:
            out[t] = 0.0
        elif len(points) >= 2:
            adjacency = (graph + graph.T).toarray()
            out[t] = eigvalsh(np.diag(adjacency.sum(axis=1)) - adjacency, subset_by_index=[1, 1])[0]
    return out


def _least_over_flying(values: np.ndarray, flying: np.ndarray) -> np.ndarray:
    """The least of ``values`` (records, agents) over the agents flying at each record; NaN where none flies."""
    least = np.where(flying, values, np.inf).min(axis=-1, initial=np.inf)
    return np.where(np.isfinite(least), least, np.nan)


def obstacle_clearance(positions: np.ndarray, centers: np.ndarray, radii: float | np.ndarray,
                       active: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """The smallest ``|p - c| - r`` over active agents and obstacles at each record (m); negative inside one.

    Spheres (discs in the plane) where ``centers`` has every axis of ``positions``; vertical cylinders,
    as SwarmLab's, where it has fewer: the distance is over its axes.  SwarmLab's ``min_d_obs`` is this
    per agent.

    Parameters
    ----------
    positions, active : the recorded arrays (module docstring)
    centers : ndarray (obstacles, axes or fewer), m
    radii : float or ndarray (obstacles,), m
    """
    p = np.asarray(positions, float)
    centers = np.atleast_2d(np.asarray(centers, float))
    gap = np.full(p.shape[:2], np.inf)
    for center, radius in zip(centers, np.broadcast_to(np.asarray(radii, float), len(centers))):
        square = sum((p[..., a] - center[a]) ** 2 for a in range(len(center)))
        np.minimum(gap, np.sqrt(square) - radius, out=gap)
    return _least_over_flying(gap, _flying(active, p.shape[:2]))


def wall_clearance(positions: np.ndarray, box: np.ndarray, active: np.ndarray | None = None) -> np.ndarray:
    """The smallest distance from an active agent to a face of the box ``[0, box_a]`` at each record (m).

    Negative outside the box.  An axis whose side is 0 is open: no walls across it.

    Parameters
    ----------
    positions, active : the recorded arrays (module docstring)
    box : ndarray (axes,), m
    """
    p, box = np.asarray(positions, float), np.asarray(box, float)
    walled = np.flatnonzero(box > 0)
    if not walled.size:
        raise ValueError("wall_clearance needs a box with walls across at least one axis")
    gap = np.min([np.minimum(p[..., a], box[a] - p[..., a]) for a in walled], axis=0)
    return _least_over_flying(gap, _flying(active, p.shape[:2]))


def edge_errors(positions: np.ndarray, edges: np.ndarray, d_t: float | np.ndarray) -> np.ndarray:
    """The distance error ``|p_j - p_i| - d_t`` of each formation edge ``(i, j)`` at each record (m), shape (records, edges).

    Parameters
    ----------
    positions : the recorded array (module docstring)
    edges : ndarray, int (edges, 2)
    d_t : float or ndarray (edges,), m
    """
    p, edges = np.asarray(positions, float), np.asarray(edges, int).reshape(-1, 2)
    return np.linalg.norm(p[:, edges[:, 1]] - p[:, edges[:, 0]], axis=-1) - np.asarray(d_t, float)


def shape_distance(positions: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The RMS distance (m) at each record between the agents and the ``target`` shape after its best
    translation and rotation: ``sqrt(mean_k |R x_k + t - y_k|^2)`` at the best ``R`` and ``t``.

    Agent ``k`` goes with target point ``k``; 2 or 3 axes.  A proper rotation (no reflection), no scaling: Kabsch's
    (Acta Cryst. A32, 922, 1976; A34, 827, 1978), from the SVD ``U S V^T`` of the cross-covariance ``sum_k x_k y_k^T``
    of the centred points: ``R = V diag(1, .., 1, d) U^T`` with ``d = sign det(V U^T)``.

    Parameters
    ----------
    positions : the recorded array (module docstring)
    target : ndarray (agents, axes), m
    """
    p = np.asarray(positions, float)
    x = p - p.mean(axis=1, keepdims=True)
    y = np.asarray(target, float)
    y = y - y.mean(axis=0)
    u, _, vt = np.linalg.svd(np.einsum("tka,kb->tab", x, y))
    vt[:, -1] *= np.where(np.linalg.det(u) * np.linalg.det(vt) < 0, -1.0, 1.0)[:, None]
    residual = x @ (u @ vt) - y  # rows (R x_k)^T - y_k^T: R^T = U diag(1, .., d) V^T
    return np.sqrt(np.mean(np.sum(residual**2, axis=-1), axis=-1))


def time_to_goal(positions: np.ndarray, times: np.ndarray, goal: np.ndarray, tolerance: float,
                 active: np.ndarray | None = None) -> float | None:  # fmt: skip
    """The time of the first record from which the centroid of the active agents stays within ``tolerance``
    of ``goal`` to the end (s); ``None`` where it is away at the last record.

    Parameters
    ----------
    positions, times, active : the recorded arrays (module docstring); a record without active agents is away
    goal : ndarray (axes,), m
    tolerance : float, m
    """
    p = np.asarray(positions, float)
    flying = _flying(active, p.shape[:2])
    with np.errstate(invalid="ignore"):
        centroid = np.where(flying[..., None], p, 0.0).sum(axis=1) / flying.sum(axis=1)[:, None]
    near = np.linalg.norm(centroid - np.asarray(goal, float), axis=-1) <= tolerance
    if not len(near) or not near[-1]:
        return None
    away = np.flatnonzero(~near)
    return float(np.asarray(times, float)[away[-1] + 1 if away.size else 0])


def field_summary(positions: np.ndarray, velocities: np.ndarray, times: np.ndarray, active: np.ndarray | None = None, *,
                  edges: np.ndarray | None = None, d_t: float | np.ndarray | None = None, members: np.ndarray | None = None,
                  target: np.ndarray | None = None,
                  obstacles: tuple[np.ndarray, np.ndarray] | None = None, box: np.ndarray | None = None,
                  safety_radius: float | None = None, collision_radius: float | None = None,
                  communication_range: float | None = None, connectivity_every: int = 1,
                  goal: np.ndarray | None = None, goal_tolerance: float | None = None) -> dict:  # fmt: skip
    """The run's metrics as a flat dict of JSON-ready values: the keys and units of the module's docstring.

    Parameters
    ----------
    positions, velocities, times, active : the recorded arrays (module docstring); edges and shape take every agent
    edges, d_t : :func:`edge_errors`'s, optional
    members : ndarray (records, edges), bool, optional: the edges held at each record (module text)
    target : :func:`shape_distance`'s, optional
    obstacles : (centers, radii), :func:`obstacle_clearance`'s, optional
    box : :func:`wall_clearance`'s, optional
    safety_radius, collision_radius : float, :func:`near_misses`'s and :func:`collisions`'s (m), optional
    communication_range, connectivity_every : :func:`algebraic_connectivity`'s range (m; :func:`union`'s too) and ``every``
    goal, goal_tolerance : :func:`time_to_goal`'s ``goal`` and ``tolerance``, optional
    """
    p, times = np.asarray(positions, float), np.asarray(times, float)
    flying = _flying(active, p.shape[:2])
    if goal is not None and goal_tolerance is None:
        raise ValueError("field_summary needs goal_tolerance with a goal")
    phi = order(velocities, flying)
    found = {} if safety_radius is None else near_misses(p, times, safety_radius, flying)
    share = found.get("pairs_within_share", ())
    wide = communication_range is None or flying.sum(axis=1).max() > MAX_CONNECTIVITY_AGENTS
    errors = np.abs(edge_errors(p, edges, d_t)) if edges is not None else np.zeros((1, 0))
    errors = errors if members is None else np.where(members, errors, np.nan)
    return {
        "order_mean": _reduce(phi[times >= (times[0] + times[-1]) / 2], np.mean), "order_min": _reduce(phi),
        "min_separation": min_separation(p, flying), "near_misses": found.get("count"),
        "safety_share_max": _reduce(share, np.max), "safety_share_mean": _reduce(share, np.mean),
        "closest_pass": found.get("closest_pass"),
        "collisions": None if collision_radius is None else collisions(p, times, collision_radius, flying),
        "union_max": None if communication_range is None else int(union(p, communication_range, flying).max()),
        "algebraic_connectivity_min": None if wide else _reduce(
            algebraic_connectivity(p, communication_range, flying, connectivity_every)),
        "min_obstacle_clearance": None if obstacles is None else _reduce(obstacle_clearance(p, *obstacles, flying)),
        "min_wall_clearance": None if box is None else _reduce(wall_clearance(p, box, flying)),
        "edge_error_max": _reduce(errors, np.max), "edge_error_rms": _reduce(errors, _rms),
        "edge_error_max_final": _reduce(errors[-1], np.max), "edge_error_rms_final": _reduce(errors[-1], _rms),
        "shape_distance_final": None if target is None else _reduce(shape_distance(p[-1:], target)),
        "time_to_goal": None if goal is None else time_to_goal(p, times, goal, goal_tolerance, flying),
    }  # fmt: skip
