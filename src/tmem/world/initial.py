"""From a validated scenario to the arrays the engine starts from.

The agents' initial states, shaped ``(agents, axes, 4)``, come from the
scenario's one source of agents: ``[[agents]]``, a ``[formation]`` shape
placed at ``center`` and moving with ``velocity`` (each agent displaced by up
to ``jitter`` m at random), or a random ``[swarm]``.  The formation pairs
come with their set distances, required directions and starting flags.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tmem.vehicles import vehicle_class
from tmem.world.formation import generate
from tmem.scenario import Scenario


@dataclass(frozen=True)
class InitialArrays:
    """Initial arrays of a run.

    Attributes
    ----------
    state : ndarray, shape (agents, axes, 4)
        ``(P, V, phi, omega)`` per agent and axis.
    active : ndarray, shape (agents,), bool
        Agents flying at the start (an inactive one can be added by a command).
    edges : ndarray, shape (pairs, 2)
        The pairs handled one by one (:meth:`Scenario.pairs`), ``(i, j)``, ``i < j``.
    d_t : ndarray, shape (pairs,)
        Set distance of each pair (m).
    direction : ndarray, shape (pairs, axes)
        Required unit direction from ``i`` to ``j``; NaN rows where none is held.
    flag : ndarray, shape (pairs,), int
        ``F_en`` at the start.
    box : ndarray, shape (axes,)
        Sides of the periodic box (m); zeros when space is not periodic.
    """

    state: np.ndarray
    active: np.ndarray
    edges: np.ndarray
    d_t: np.ndarray
    direction: np.ndarray
    flag: np.ndarray
    box: np.ndarray


def _vector(value: float | list[float], axes: int) -> np.ndarray:
    return np.asarray(value, dtype=float) * np.ones(axes)


def _listed_agents(scenario: Scenario, axes: int) -> tuple[np.ndarray, np.ndarray]:
    state = np.array(
        [
            np.stack([_vector(getattr(a, name), axes) for name in ("position", "velocity", "tilt", "tilt_rate")], axis=1)
            for a in scenario.agents
        ]
    )
    return state, np.array([a.active for a in scenario.agents])


def _random_swarm(scenario: Scenario, axes: int) -> np.ndarray:
    """Agents uniform in the region, numbered in cell order.

    In a walled box the region lies inside the walls' reach ``R + R_w`` (by default it is the box
    less that reach on every side), and no agent starts within that reach of an obstacle: no agent
    starts already pushed by a wall it may be flying into.

    The agents are numbered cell by cell over a grid of side ``R + R_j``
    (last axis slowest), so that neighbours have nearby numbers: recorded
    subsets (``record_agents``) then pick out patches, not scattered agents.
    The step loop orders agents in space by itself, whatever their numbers.
    """
    swarm = scenario.swarm
    rng = np.random.default_rng(swarm.seed)
    inset = scenario.wall_reach if scenario.space.walls else 0.0
    region = np.asarray(swarm.region or np.asarray(scenario.space.box) - 2.0 * inset, dtype=float)
    state = np.zeros((swarm.n, axes, 4))
    if swarm.min_spacing is not None:
        state[:, :, 0] = spaced_swarm(scenario, inset, region)
    else:
        state[:, :, 0] = inset + rng.uniform(0.0, 1.0, (swarm.n, axes)) * region
    # Agents within reach of an obstacle are drawn again until clear of every one (the obstacles
    # cover at most half the region: Scenario checks it).
    while len(near := np.flatnonzero(_near_obstacle(state[:, :, 0], scenario.obstacles, scenario.wall_reach))):
        state[near, :, 0] = inset + rng.uniform(0.0, 1.0, (len(near), axes)) * region
    # Each velocity component normal with variance speed_rms^2 / axes: E|v|^2 = speed_rms^2.
    state[:, :, 1] = rng.normal(0.0, swarm.speed_rms / np.sqrt(axes), (swarm.n, axes))
    cells = np.floor(state[:, :, 0] / scenario.interaction.reach).astype(np.int64)
    return state[np.lexsort(cells.T)]


def _scattered(places: np.ndarray, f, axes: int) -> np.ndarray:
    """Starts at random in the region ``scatter`` centred on the formation, ``min_spacing`` apart
    (Poisson-disk sampling), each given to the agent whose place CAPT assigns it: the sum of the
    squared distances from start to place is the least (Turpin et al. 2014, :mod:`tmem.plan.assignment`)."""
    from tmem.plan.assignment import assign
    from tmem.plan.starts import spaced_points

    centre, half = _vector(f.center or 0.0, axes), 0.5 * _vector(f.scatter, axes)
    starts = spaced_points(len(places), centre - half, centre + half, f.min_spacing, f.seed)
    scattered = np.empty_like(places)
    scattered[assign(starts, places)] = starts
    return scattered


def spaced_swarm(scenario: Scenario, inset: float, region: np.ndarray) -> np.ndarray:
    """A swarm's starts ``swarm.min_spacing`` apart in its region and clear of every obstacle's reach:
    a Poisson-disk sample (:func:`tmem.plan.starts.spaced_points`), the points near an obstacle left out.

    Parameters
    ----------
    scenario : Scenario
        Its ``[swarm]`` and obstacles.
    inset : float
        The region's offset from the origin on every axis (m): the walls' reach in a walled box.
    region : ndarray, shape (axes,)
        The region's sides (m).

    Raises
    ------
    ValueError
        Where the region holds fewer such starts than the swarm's agents.
    """
    from tmem.plan.starts import spaced_points

    swarm = scenario.swarm
    wanted = swarm.n
    for _ in range(8):  # each round asks for as many more as fell near an obstacle
        points = spaced_points(wanted, np.full(len(region), inset), inset + region, swarm.min_spacing, swarm.seed)
        clear = points[~_near_obstacle(points, scenario.obstacles, scenario.wall_reach)]
        if len(clear) >= swarm.n:
            return clear[: swarm.n]
        wanted += swarm.n - len(clear)
    raise ValueError(f"the region holds {len(clear)} starts {swarm.min_spacing:g} m apart clear of the obstacles, "
                     f"fewer than the swarm's {swarm.n}")  # fmt: skip


def _near_obstacle(positions: np.ndarray, obstacles, reach: float) -> np.ndarray:
    """Whether each position lies within ``reach`` of an obstacle (or inside it)."""
    near = np.zeros(len(positions), dtype=bool)
    for obstacle in obstacles:
        near |= np.linalg.norm(positions - np.asarray(obstacle.center), axis=1) < obstacle.radius + reach
    return near


def formation_positions(scenario: Scenario) -> np.ndarray:
    """Where the agents of a generated ``[formation]`` start (m, shape (agents, axes)): their places in the
    shape about its ``center``, moved by the ``jitter``, or ``scatter``-ed with each at the start CAPT gives it.

    Parameters
    ----------
    scenario : Scenario
        Its ``[formation]``.
    """
    f, n, axes = scenario.formation, scenario.n_agents, scenario.space.axes
    shape = generate(f.kind, n, scenario.interaction.d_t if f.d_t is None else f.d_t, axes)
    rng = np.random.default_rng(f.seed)
    positions = shape.positions + _vector(f.center or 0.0, axes)
    positions += rng.uniform(-f.jitter, f.jitter, (n, axes)) if f.jitter > 0 else 0.0
    return _scattered(positions, f, axes) if f.scatter is not None else positions


def _in_first_shape(scenario: Scenario, edges: np.ndarray) -> np.ndarray:
    """Whether each of ``edges`` is a pair of the formation's own shape, where a mission changes it."""
    first = {tuple(edge) for edge in generate(scenario.formation.kind, scenario.n_agents, 1.0, scenario.space.axes).edges.tolist()}
    return np.array([tuple(edge) in first for edge in edges.tolist()], dtype=bool)


def build(scenario: Scenario) -> InitialArrays:
    """The initial arrays of ``scenario``.

    Parameters
    ----------
    scenario : Scenario
        Its agents, swarm or formation, pairs and box set the arrays.
    """
    axes = scenario.space.axes
    n = scenario.n_agents
    f = scenario.formation
    d_t = scenario.interaction.d_t if f is None or f.d_t is None else f.d_t
    active = np.ones(n, dtype=bool)
    direction = None
    if scenario.swarm is not None:
        state = _random_swarm(scenario, axes)
    elif f is not None and f.kind != "edges":
        state = np.zeros((n, axes, 4))
        state[:, :, 0] = formation_positions(scenario)
        state[:, :, 1] = _vector(f.velocity or 0.0, axes)
        shape = generate(f.kind, n, d_t, axes, f.bearing)
        direction = None if scenario.reshapes else shape.direction  # a reshape sets its pairs' own (tmem.engine.stages)
    else:
        state, active = _listed_agents(scenario, axes)

    edges = scenario.pairs()
    d_ts = np.full(len(edges), float(d_t))
    if f is not None and f.kind == "edges":
        listed = {tuple(sorted(e[:2])): (e[2] if len(e) == 3 else d_t) for e in f.edges}
        d_ts = np.array([listed[(i, j)] for i, j in edges.tolist()], dtype=float)
    if direction is None:
        direction = np.full((len(edges), axes), np.nan)
        if f is not None and f.bearing:  # the direction the listed agents start in
            delta = state[edges[:, 1], :, 0] - state[edges[:, 0], :, 0]
            direction = delta / np.linalg.norm(delta, axis=1, keepdims=True)
    flag = np.full(len(edges), 1 if f is not None and f.coupled else 0, dtype=np.int64)
    if scenario.reshapes:  # coupled: the pairs of the first shape only (tmem.terms.navigation_plan.shapes_flown)
        flag = (flag & _in_first_shape(scenario, edges)).astype(np.int64)
    box = np.asarray(scenario.space.box, dtype=float) if scenario.space.periodic else np.zeros(axes)
    if scenario.space.periodic:
        state[:, :, 0] %= box
    state = vehicle_class(scenario.model.kind).initial_state(state)  # the vehicle's own per-axis state
    return InitialArrays(state, active, edges, d_ts, direction, flag, box)
