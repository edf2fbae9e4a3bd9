"""The mission as the navigation flies it: each leg's points and speeds, routes planned around obstacles (N4),
an assembly's or a reshape's places and span (N5), the formation's shapes and their pairs, the turns along a
route (N3).

Planning runs once, when a run's record is built (:func:`tmem.terms.navigation.navigation_record`);
:func:`planned_points` gives the same legs to figures and the viewer.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from tmem.scenario.tables import FieldError

if TYPE_CHECKING:
    from tmem.terms.navigation_table import NavigationParams

#: The waypoint rows of a ``hold`` without a target: where the group is when the leg starts.
HERE = np.nan
#: The sides of the polygon a route plans round each obstacle with (:func:`tmem.plan.route.plan_route`).
SIDES = 16


def braking(scenario) -> float:
    """``a_b`` of (N3), half of what the mission may ask: ``share c_max`` times the vehicle's acceleration per input (m/s^2).

    Parameters
    ----------
    scenario : Scenario
        Its ``[navigation]`` share, tilt limit and vehicle.
    """
    from tmem.vehicles import vehicle_class

    per_input = vehicle_class(scenario.model.kind)(scenario.model).acceleration_per_input()
    return 0.5 * scenario.navigation.share * scenario.interaction.c_max * per_input


def _planned(settings: NavigationParams, scenario, start: np.ndarray, r_group: float, lead: float, a_b: float):
    """Each leg's points, speeds and planned start (None where the group's place is not known then: after
    a velocity leg), the avoiding legs' routes planned around the obstacles (N4)."""
    obstacles = np.array([o.center for o in scenario.obstacles], dtype=float).reshape(-1, scenario.space.axes)
    radii = np.array([o.radius for o in scenario.obstacles], dtype=float)
    here, legs = start, []
    for k, leg in enumerate(settings.legs):
        points, speeds = [np.asarray(p, dtype=float) for p in leg.points()], leg.speeds()
        if leg.action == "assemble":  # then the group holds the shape's centre (N5)
            here = shape_centre(scenario, leg)
            legs.append(([here], [float(leg.speed)], None))
            continue
        if leg.action == "reshape":  # about the centre where it starts, moving on with the group (N5)
            legs.append(([np.full(scenario.space.axes, HERE)], [float(leg.speed)], here))
            continue
        if leg.avoid:
            if here is None:
                raise FieldError(f"navigation.legs[{k}].avoid", "follows a velocity leg: there is no point to plan from")
            from tmem.plan.route import plan_route

            fastest = max(speeds)  # the turn's arc cuts into a corner of the polygon by R_turn (1/cos(pi/m) - 1)
            clearance = r_group + scenario.wall_reach + lead * fastest + fastest**2 / a_b * (1 / np.cos(np.pi / SIDES) - 1)
            routed, routed_speeds, origin = [], [], here
            for point, speed in zip(points, speeds):
                try:
                    path = plan_route(origin, point, obstacles, radii, clearance, SIDES)
                except ValueError as error:
                    raise FieldError(f"navigation.legs[{k}].avoid", f"{error} (clearance {clearance:.4g} m, (N4))") from None
                routed += list(path[1:])
                routed_speeds += [speed] * (len(path) - 1)
                origin = point
            points, speeds = routed, routed_speeds
        if leg.action == "hold" and not points:
            points, speeds = [np.full(scenario.space.axes, HERE)], [np.inf]
        legs.append((points, speeds, here))
        here = None if leg.action == "velocity" or np.isnan(points[-1][0]) else points[-1]
    return legs


def shape_centre(scenario, leg) -> np.ndarray:
    """Where an ``assemble`` leg puts the centre of the formation's shape: its ``target``, or ``[formation] center``.

    Parameters
    ----------
    scenario : Scenario
        Its ``[formation]``.
    leg : Leg
        The ``assemble`` leg.
    """
    f = scenario.formation
    return np.asarray(leg.target if leg.target is not None else (f.center or [0.0] * scenario.space.axes), dtype=float)


def places(scenario, leg, starts: np.ndarray, a_b: float) -> tuple[np.ndarray, float]:
    """(N5): each agent's place in the formation's shape and the leg's span ``T`` (s), the shortest over which
    the cubic time scaling keeps every agent within the leg's speed and the braking acceleration.

    Parameters
    ----------
    scenario : Scenario
        Its ``[formation]`` and time step.
    leg : Leg
        The ``assemble`` leg: its target and speed.
    starts : ndarray, shape (agents, axes)
        Where the agents start (m), agent ``k`` flying to place ``k``.
    a_b : float
        The acceleration the lines may ask (m/s^2).
    """
    from tmem.plan.assignment import capt_duration
    from tmem.world.formation import generate

    f = scenario.formation
    d_t = scenario.interaction.d_t if f.d_t is None else f.d_t
    slots = generate(f.kind, len(starts), d_t, scenario.space.axes, f.bearing).positions + shape_centre(scenario, leg)
    span = capt_duration(starts, slots, np.arange(len(starts)), float(leg.speed), a_b)
    return slots, max(span, scenario.simulation.dt)


class Shape(NamedTuple):
    """One shape a formation takes in a mission.

    Attributes
    ----------
    leg : int or None
        The ``assemble`` or ``reshape`` leg that takes it (``None``: the formation's own shape, from the start).
    places : ndarray, shape (agents, axes)
        Each agent's place, about the shape's centre (m).
    edges : ndarray, shape (edges, 2), int
        The shape's pairs, ``(i, j)`` with ``i < j``, as agents.
    span : float
        The leg's ``T`` (s): its pairs couple at its end (0 for the first shape).
    """

    leg: int | None
    places: np.ndarray
    edges: np.ndarray
    span: float


def shapes_flown(scenario) -> list[Shape]:
    """The formation's shapes, from its own to each ``assemble`` and ``reshape`` leg's: an assembly's places
    are the formation's own (each agent starts where CAPT sends it to its place, :mod:`tmem.world.initial`);
    each agent's place in a reshape's shape is the one CAPT assigns it from its place in the shape before
    (the least sum of squared distances), and the new shape's edges join the agents placed at its
    neighbouring slots.

    Parameters
    ----------
    scenario : Scenario
        A scenario with a generated ``[formation]``; its ``[navigation]`` legs, if any.
    """
    from tmem.plan.assignment import assign, capt_duration
    from tmem.world.formation import generate
    from tmem.world.initial import formation_positions

    f, n, axes = scenario.formation, scenario.n_agents, scenario.space.axes
    d_t = scenario.interaction.d_t if f.d_t is None else f.d_t
    first = generate(f.kind, n, d_t, axes)
    shapes = [Shape(None, first.positions, first.edges, 0.0)]
    legs = scenario.navigation.legs if getattr(scenario, "navigation", None) is not None else []
    for k, leg in enumerate(legs):
        if leg.action == "assemble":
            shapes.append(Shape(k, first.positions, first.edges, places(scenario, leg, formation_positions(scenario), braking(scenario))[1]))
        if leg.action != "reshape":
            continue
        new, before = generate(leg.shape, n, d_t, axes), shapes[-1].places
        slot = assign(before, new.positions)  # agent a takes slot slot[a]
        agent = np.argsort(slot)  # slot s is taken by agent agent[s]
        edges = np.sort(agent[new.edges], axis=1)
        edges = edges[np.lexsort((edges[:, 1], edges[:, 0]))]
        places_now = new.positions[slot]
        span = capt_duration(before, places_now, np.arange(n), float(leg.speed), braking(scenario))
        shapes.append(Shape(k, places_now, edges, max(span, scenario.simulation.dt)))
    return shapes


def shape_commands(scenario) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """When the formation's pairs change in a mission that shapes it, and to what: ``(time (s), the pairs that
    couple then (agents, shape (m, 2)), the direction each holds (NaN rows: a distance only))``; every other
    pair lets go at that time (:func:`tmem.engine.stages.reshape`).

    The formation's own shape at the start (its pairs coupled if ``formation.coupled``); at each ``assemble``
    or ``reshape`` leg's start, none (the agents fly their lines free of the springs, TMEM's push keeping
    passing agents apart); at the end of its lines, ``T`` later, the leg's shape, each agent at its place.

    Parameters
    ----------
    scenario : Scenario
        A scenario whose mission assembles or reshapes its formation.
    """
    axes, legs = scenario.space.axes, scenario.navigation.legs
    none = (np.empty((0, 2), dtype=np.int64), np.empty((0, axes)))
    found = []
    for shape in shapes_flown(scenario):
        delta = shape.places[shape.edges[:, 1]] - shape.places[shape.edges[:, 0]]
        held = delta / np.linalg.norm(delta, axis=1, keepdims=True) if scenario.formation.bearing else np.nan * delta
        if shape.leg is None:
            found.append((0.0, *((shape.edges, held) if scenario.formation.coupled else none)))
        else:
            found += [(legs[shape.leg].time, *none), (legs[shape.leg].time + shape.span, shape.edges, held)]
    return found


def held_pairs(scenario, pairs: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which of ``pairs`` a formation whose mission shapes it holds at each of ``times``, and the direction
    each holds, as :func:`shape_commands` sets them.

    Parameters
    ----------
    scenario : Scenario
        A scenario whose mission assembles or reshapes its formation.
    pairs : ndarray, shape (pairs, 2)
        The run's pairs, ``(i, j)`` agents.
    times : ndarray, shape (records,)
        The recorded times (s).

    Returns
    -------
    members : ndarray, shape (records, pairs), bool
    directions : ndarray, shape (records, pairs, axes)
        The unit direction from ``i`` to ``j`` (NaN where the pair is not held, or the formation holds distances only).
    """
    index = {(int(i), int(j)): e for e, (i, j) in enumerate(pairs)}
    members = np.zeros((len(times), len(pairs)), dtype=bool)
    directions = np.full((len(times), len(pairs), scenario.space.axes), np.nan)
    sim = scenario.simulation
    for time, edges, held in shape_commands(scenario):
        now = times >= sim.step_of(time) * sim.dt - 1e-9
        chosen = [index[tuple(edge)] for edge in edges.tolist()]
        members[now] = False
        members[np.ix_(now, chosen)] = True
        directions[now] = np.nan
        directions[np.ix_(now, chosen)] = held
    return members, directions


def turns(points: list[np.ndarray], speeds: list[float], start: np.ndarray | None, a_b: float) -> list[float]:
    """Distance before each point where the group turns to the next segment (module text); 0 at the last.

    Parameters
    ----------
    points : list of ndarray
        A leg's points (m).
    speeds : list of float
        The speed towards each (m/s).
    start : ndarray or None
        Where the leg starts (m); ``None`` where unknown (no turn before the first point).
    a_b : float
        The braking acceleration (m/s^2): ``R_turn = s^2 / a_b``.
    """
    turns = []
    for w, point in enumerate(points[:-1]):
        before = points[w - 1] if w else start
        if before is None:
            turns.append(0.0)
            continue
        inward, outward = point - before, points[w + 1] - point
        lengths = np.linalg.norm(inward), np.linalg.norm(outward)
        cosine = float(inward @ outward / (lengths[0] * lengths[1])) if min(lengths) > 0 else 1.0
        theta = np.arccos(np.clip(cosine, -1.0, 1.0))
        radius = max(speeds[w], speeds[w + 1]) ** 2 / a_b
        turns.append(float(min(radius * np.tan(min(theta, 0.99 * np.pi) / 2), 0.5 * min(lengths))))
    return turns + [0.0] if points else []


def flown(scenario, gains):
    """The run's initial arrays, and each leg's points, speeds and planned start (:func:`_planned`).

    Parameters
    ----------
    scenario : Scenario
        A scenario with a ``[navigation]`` table.
    gains : ndarray
        ``K`` of the law: ``K_V / K_P`` is the lead of ``P*`` (N4).
    """
    from tmem.world.initial import build

    initial = build(scenario)
    positions = initial.state[initial.active, :, 0]
    start = positions.mean(axis=0)
    r_group = float(np.max(np.linalg.norm(positions - start, axis=1))) if len(positions) else 0.0
    return initial, _planned(scenario.navigation, scenario, start, r_group, float(gains[1] / gains[0]), braking(scenario))


def planned_points(scenario) -> list[tuple[float, str, np.ndarray]]:
    """The mission as flown: each leg's start time (s), action and points (m, shape (W, axes); the
    routes of ``avoid`` legs as planned (N4), an ``assemble`` leg's shape centre; none for ``velocity``
    and for a ``hold`` where the group is), for figures and the viewer.

    Parameters
    ----------
    scenario : Scenario
        A scenario with a ``[navigation]`` table.
    """
    from tmem.vehicles import vehicle_class

    c = scenario.controller
    _, legs = flown(scenario, vehicle_class(scenario.model.kind)(scenario.model).gains(c.r_l, c.im_l, c.im_r))
    axes = scenario.space.axes
    return [(leg.time, leg.action, np.array([q for q in points if not np.isnan(q[0])], dtype=float).reshape(-1, axes))
            for leg, (points, _, _) in zip(scenario.navigation.legs, legs)]  # fmt: skip
