"""Group navigation: every agent steers the group's common motion along a mission, the TMEM law holds its shape.

Each agent ``i`` knows the mission (``[navigation]``, :mod:`tmem.terms.navigation_table`) and the
states its group's members broadcast, ``known[j]`` (their own measurements, as the sensing model
makes them).  From them it forms the group's centre, the mean of the law's states over the flying
agents::

    c = (1/N) sum_j x_j          (position, velocity, tilt, tilt rate per axis)            (N1)

and adds to its set-point the push of a velocity loop on that centre::

    U_nav = -K_n . (c_V - v_d, c_phi, c_omega),    |U_nav| <= share c_max               (N2)

``K_n`` places the loop of the centre's velocity, tilt and rate, ``(A, B)`` without the position, at
``-bandwidth`` and the law's own damped roots (``-r_l +- i im_l`` of (5) for a tilting multirotor,
``-1/tau`` for the ground robot); ``bandwidth`` is at most a quarter of the slowest of them, so the
tilt follows the velocity loop.  The wanted velocity ``v_d`` is the mission's: a ``velocity`` leg's
own; towards a leg's last point ``p`` (a ``goto`` target, a route's last waypoint, a ``hold``), with
``e = p - c_P``::

    v_d = min(s, k_p |e|, sqrt(2 a_b |e|)) e / |e|,   k_p = bandwidth / 4,  a_b = a_n / 2      (N3)

(a cruise at the leg's speed ``s``, a braking curve, and a critically damped approach: the loop
``s^2 + bandwidth s + bandwidth k_p`` has a double root); along a route's earlier segments, from
``f`` to ``p`` with unit tangent ``t``, ``v_d = s t + k_p (e - (e.t) t)`` (cruise, and a pull back onto
the segment), scaled to at most ``s``, turning to the next segment ``R_turn tan(theta/2)`` before ``p`` (``theta`` the turn,
``R_turn = s^2 / a_b``, at most half a segment).  ``a_n = share c_max`` times the vehicle's
acceleration per unit of input is what the mission may ask.

**What it does to the TMEM law.**  Every agent computes the same ``c`` from the same broadcast states,
so ``U_nav`` is the same for every agent: a common-mode push.  The relative state of a pair,
``e = x_j - x_i``, sees none of it; its loop ``A - 2 B K`` (S1), the flags (9), the pulls
(10)-(11) and the coupling window are those of a pair in free flight, exactly on a linear model as
long as no agent's set-point saturates (``share < 1`` leaves the pairs ``(1 - share) c_max``).
Navigation thus cannot feed the pairs' oscillation.  The centre, the mean of linear states under
pushes that cancel in pairs ((8), (10), (11), (S2) act equal and opposite), moves as one agent under
``U_nav``.  The speed synchronisation's energy term (S3) would hold each pair's mean square speed,
the group's motion included, and so fight every change of speed the mission asks; a scenario with
this term therefore damps the pairs' relative motion only (``interaction.keep_energy``): the RMS
velocity kept is the one about the group's mean motion, which a settled formation has none of.

**Obstacles.**  A ``goto`` or ``route`` leg with ``avoid = true`` flies a route planned around the
``[[obstacles]]`` (:func:`tmem.plan.route.plan_route`: a visibility graph over the circles grown
by the clearance), from where the leg before it ends (the group's centre at the start, for the first)::

    clearance = r_group + (R + R_w) + s K_V / K_P + R_turn (1 / cos(pi / 16) - 1)               (N4)

``r_group`` the group's largest distance from its centre at the start, ``R + R_w`` the obstacles'
reach (W1), ``s K_V / K_P`` how far ``P*`` (6) leads ``P`` at the speed ``s``, and the depth by which
the turn's arc (``R_turn = s^2 / a_b``) cuts into a corner of the 16-gon the route rounds each
obstacle with: no agent's ``P*`` comes within an obstacle's reach, so (W1) never pushes and no pair's
flag is touched by an obstacle.

**Assembly.**  An ``assemble`` leg flies each agent of a ``[formation]`` on its own straight line from
where it starts, ``f_i``, to its place ``p_i`` in the shape (assigned by CAPT when the agents are
scattered, :mod:`tmem.world.initial`), all arriving together at ``T``::

    v_d,i = (p_i - f_i) beta'(t/T) / T + k_p (f_i + beta(t/T) (p_i - f_i) - P_i),  beta = 3 tau^2 - 2 tau^3   (N5)

with (N2) on the agent's own state; ``T`` is the shortest that keeps every agent within the leg's
speed and ``a_b`` (:func:`tmem.plan.assignment.capt_duration`).  The pairs let go when the leg starts and
couple at ``T``, each agent at its place (:func:`tmem.terms.navigation_plan.shape_commands`); from ``T`` on,
the group holds the shape's centre by (N1)-(N3) and the pairs settle.

**Reshape.**  A ``reshape`` leg flies each agent from where it is at the leg's start ``t_0`` to its place
``q_i`` in the new shape (CAPT from its place in the old one, :func:`tmem.terms.navigation_plan.shapes_flown`)
about the centre ``c_0``, the lines carried at the centre's velocity ``v_0`` then (both from (N1))::

    v_d,i = v_0 + (p_i - f_i) beta'(tau) / T + k_p (f_i + v_0 (t - t_0) + beta(tau) (p_i - f_i) - P_i),  p_i = c_0 + q_i   (N5')

and from ``t_0 + T`` the centre flies on, ``v_d = v_0 + k_p (c_0 + v_0 (t - t_0) - c_P)``.  The pairs change as
in an assembly, by the engine's ``reshape`` command (:func:`tmem.engine.stages.reshape`).

Each agent carries its own leg, waypoint and hold point in the record (a checkpoint saves them);
the centre costs ``O(N)`` per agent, ``O(N^2)`` per step: missions of a few thousand agents at most.
"""

from __future__ import annotations

from functools import cache
from typing import NamedTuple

import numpy as np

from tmem.scenario.tables import FieldError
from tmem.terms.base import AgentTerm
from tmem.terms.navigation_plan import braking, flown, shape_centre, shapes_flown, turns
from tmem.terms.navigation_table import NavigationParams

#: Kinds of leg, as the kernel reads them.
VELOCITY, POINTS, ASSEMBLE, RESHAPE = 0, 1, 2, 3
KINDS = {"velocity": VELOCITY, "assemble": ASSEMBLE, "reshape": RESHAPE}


class Navigated(NamedTuple):
    """The record of (N1)-(N5): the mission as arrays, the loop's numbers, each agent's progress.

    ``leg_step``, ``leg_kind``, ``leg_first``, ``leg_stop``, ``leg_velocity``, ``leg_span`` (legs; the
    span is an ``assemble`` or ``reshape`` leg's ``T`` (s)); ``place`` (legs, agents by slot, axes: each
    agent's place in an ``assemble`` leg's shape, or about the centre in a ``reshape`` leg's, (N5));
    ``waypoint``, ``speed``, ``turn`` (points: position, speed towards it, distance before it to turn);
    ``gain`` (``K_n``), ``k_p``, ``a_b``, ``u_max``, ``dt``; per agent: ``leg_now``, ``point_now``,
    ``leg_from`` (the centre when the leg started), ``line_from`` (the agent's own position then),
    ``drift`` (the centre's velocity then, which a reshape moves on with), and work space ``centre``,
    ``wanted``, ``push``.
    """

    leg_step: np.ndarray
    leg_kind: np.ndarray
    leg_first: np.ndarray
    leg_stop: np.ndarray
    leg_velocity: np.ndarray
    leg_span: np.ndarray
    place: np.ndarray
    waypoint: np.ndarray
    speed: np.ndarray
    turn: np.ndarray
    gain: np.ndarray
    k_p: float
    a_b: float
    u_max: float
    dt: float
    leg_now: np.ndarray
    point_now: np.ndarray
    leg_from: np.ndarray
    line_from: np.ndarray
    drift: np.ndarray
    centre: np.ndarray
    wanted: np.ndarray
    push: np.ndarray


def loop_gains(scenario, bandwidth: float) -> np.ndarray:
    """``K_n`` of (N2): the gains on ``(V, phi, omega)`` (the law's states but the position).

    Parameters
    ----------
    scenario : Scenario
        Its vehicle and roots (5).
    bandwidth : float
        The velocity loop's root is ``-bandwidth`` (1/s).

    Raises
    ------
    FieldError
        ``navigation.bandwidth`` above a quarter of the slowest damped root of the law's loop.
    """
    from scipy.signal import place_poles

    from tmem.vehicles import vehicle_class

    model = vehicle_class(scenario.model.kind)(scenario.model)
    a, b = model.linearisation()
    c = scenario.controller
    closed = np.linalg.eigvals(a - np.outer(b, model.gains(c.r_l, c.im_l, c.im_r)))
    damped = closed[closed.real < -1e-9 * np.abs(closed).max()]
    slowest = float(np.min(-damped.real))
    if bandwidth > slowest / 4.0:
        raise FieldError("navigation.bandwidth", f"{bandwidth:g} /s is above a quarter of the law's slowest damped root, "
                         f"{slowest:.4g} /s: the tilt would not follow the velocity loop (at most {slowest / 4:.4g})")  # fmt: skip
    real = [z.real for z in damped if abs(z.imag) <= 1e-12 * abs(z)]
    upper = [z for z in damped if z.imag > 1e-12 * abs(z)]
    poles = np.array([-bandwidth, *real, *[w for z in upper for w in (z, np.conj(z))]])
    return place_poles(a[1:, 1:], b[1:, None], poles).gain_matrix[0]


def navigation_record(settings: NavigationParams, scenario, gains) -> Navigated:
    """The record of (N1)-(N5) for a run of ``scenario`` (see :class:`Navigated`).

    Parameters
    ----------
    settings : NavigationParams
        The ``[navigation]`` table.
    scenario : Scenario
        The whole scenario.
    gains : ndarray
        ``K`` of the law: ``K_V / K_P`` is the lead of ``P*`` (N4).
    """
    from tmem.engine.driver import slot_order

    axes = scenario.space.axes
    initial, legs = flown(scenario, gains)
    u_max = settings.share * scenario.interaction.c_max
    a_b = braking(scenario)
    n, n_law = initial.state.shape[0], len(gains)
    waypoint, speed, turn, first, stop = [], [], [], [], []
    place, span = np.full((len(legs), n, axes), np.nan), np.zeros(len(legs))
    for k, (leg, (points, speeds, here)) in enumerate(zip(settings.legs, legs)):
        first.append(len(waypoint))
        turn += turns(points, speeds, here, a_b)
        waypoint += points
        speed += speeds
        stop.append(len(waypoint))
    for shape in shapes_flown(scenario)[1:] if scenario.shapes_change else []:  # an assembly's places are absolute
        centre = shape_centre(scenario, settings.legs[shape.leg]) if settings.legs[shape.leg].action == "assemble" else 0.0
        place[shape.leg], span[shape.leg] = shape.places + centre, shape.span
    place = place[:, slot_order(scenario, initial, gains)]  # the kernel's agent i is the run's slot i
    velocity = np.array([leg.velocity if leg.velocity is not None else [0.0] * axes for leg in settings.legs], dtype=float)
    return Navigated(
        leg_step=np.array([scenario.simulation.step_of(leg.time) for leg in settings.legs], dtype=np.int64),
        leg_kind=np.array([KINDS.get(leg.action, POINTS) for leg in settings.legs], dtype=np.int64),
        leg_first=np.array(first, dtype=np.int64), leg_stop=np.array(stop, dtype=np.int64), leg_velocity=velocity,
        leg_span=span, place=place, dt=scenario.simulation.dt,
        waypoint=np.array(waypoint, dtype=float).reshape(-1, axes), speed=np.array(speed, dtype=float),
        turn=np.array(turn, dtype=float), gain=loop_gains(scenario, settings.bandwidth), k_p=settings.bandwidth / 4.0,
        a_b=float(a_b), u_max=float(u_max), leg_now=np.full(n, -1, dtype=np.int64), point_now=np.zeros(n, dtype=np.int64),
        leg_from=np.zeros((n, axes)), line_from=np.zeros((n, axes)), drift=np.zeros((n, axes)),
        centre=np.zeros((n, axes, n_law)), wanted=np.zeros((n, axes)), push=np.zeros((n, axes)),
    )  # fmt: skip


def _centre(i, known, active, centre):
    """(N1): agent ``i``'s estimate of its group's centre, the mean of the flying agents' law states."""
    n_axes, n_law = centre.shape[1], centre.shape[2]
    count = 0
    for a in range(n_axes):
        for s in range(n_law):
            centre[i, a, s] = 0.0
    for j in range(known.shape[0]):
        if active[j]:
            count += 1
            for a in range(n_axes):
                for s in range(n_law):
                    centre[i, a, s] += known[j, a, s]
    for a in range(n_axes):
        for s in range(n_law):
            centre[i, a, s] /= max(count, 1)


def _point(i, w, nav, a):
    """Coordinate ``a`` of point ``w`` of agent ``i``'s leg: the waypoint, or where its hold began."""
    return nav.leg_from[i, a] if np.isnan(nav.waypoint[w, 0]) else nav.waypoint[w, a]


def _start(i, w, leg, nav, a):
    """Coordinate ``a`` of where the segment to point ``w`` of agent ``i``'s leg begins."""
    return nav.waypoint[w - 1, a] if w > nav.leg_first[leg] else nav.leg_from[i, a]


def _segment(i, w, leg, nav, n_axes):
    """The segment to point ``w``: its length, and how far the centre has still to go along it (m)."""
    length2, along = 0.0, 0.0
    for a in range(n_axes):
        tangent = point(i, w, nav, a) - start(i, w, leg, nav, a)  # noqa: F821  (bound)
        length2 += tangent * tangent
        along += tangent * (point(i, w, nav, a) - nav.centre[i, a, 0])  # noqa: F821  (bound)
    length = np.sqrt(length2)
    return length, along / length if length > 0.0 else 0.0


def _towards(i, leg, nav, n_axes):
    """(N3): the wanted velocity ``v_d`` towards agent ``i``'s current point, into ``nav.wanted[i]``;
    on to the next segment ``turn`` before a route's point."""
    w = nav.point_now[i]
    length, along = segment(i, w, leg, nav, n_axes)  # noqa: F821  (bound)
    while w < nav.leg_stop[leg] - 1 and along < nav.turn[w]:
        w += 1
        length, along = segment(i, w, leg, nav, n_axes)  # noqa: F821  (bound)
    nav.point_now[i] = w
    distance2 = 0.0
    for a in range(n_axes):
        distance2 += (point(i, w, nav, a) - nav.centre[i, a, 0]) ** 2  # noqa: F821  (bound)
    distance = np.sqrt(distance2)
    speed = min(nav.speed[w], nav.k_p * distance, np.sqrt(2.0 * nav.a_b * distance))
    straight = w == nav.leg_stop[leg] - 1 or length == 0.0  # the leg's last point: straight at it, braking
    for a in range(n_axes):
        gap = point(i, w, nav, a) - nav.centre[i, a, 0]  # noqa: F821  (bound)
        if straight:
            nav.wanted[i, a] = speed * gap / distance if distance > 0.0 else 0.0
        else:  # cruise along the segment, pulled back onto it, no faster than the leg's speed
            tangent = (point(i, w, nav, a) - start(i, w, leg, nav, a)) / length  # noqa: F821  (bound)
            nav.wanted[i, a] = nav.speed[w] * tangent + nav.k_p * (gap - along * tangent)
    if not straight:
        size2 = 0.0
        for a in range(n_axes):
            size2 += nav.wanted[i, a] ** 2
        for a in range(n_axes):
            nav.wanted[i, a] *= min(1.0, nav.speed[w] / np.sqrt(size2)) if size2 > 0.0 else 1.0


def _lines(i, k, leg, nav, n_axes):
    """(N5), (N5'): the wanted velocity of agent ``i`` on its straight line to its place, ``beta = 3 tau^2 - 2 tau^3``,
    the line carried at the ``drift`` the group had when the leg started (a reshape's; none for an assembly)."""
    elapsed = (k - nav.leg_step[leg]) * nav.dt
    tau = min(1.0, elapsed / nav.leg_span[leg])
    beta, slope = tau * tau * (3.0 - 2.0 * tau), 6.0 * tau * (1.0 - tau) / nav.leg_span[leg]
    for a in range(n_axes):
        place = nav.place[leg, i, a] + (nav.leg_from[i, a] if nav.leg_kind[leg] == RESHAPE else 0.0)
        line = place - nav.line_from[i, a]
        on_line = nav.line_from[i, a] + nav.drift[i, a] * elapsed + beta * line
        nav.wanted[i, a] = nav.drift[i, a] + slope * line + nav.k_p * (on_line - nav.centre[i, a, 0])


def _drifting(i, k, leg, nav, n_axes):
    """After a reshape (N5'): the wanted velocity that carries the centre on at the group's ``drift``, from
    where it was when the leg started (a hold where the group was at rest)."""
    elapsed = (k - nav.leg_step[leg]) * nav.dt
    for a in range(n_axes):
        nav.wanted[i, a] = nav.drift[i, a] + nav.k_p * (nav.leg_from[i, a] + nav.drift[i, a] * elapsed - nav.centre[i, a, 0])


def _push(i, k, known, agents, box, nav):
    """(N1)-(N3), (N5) on agent ``i`` at step ``k``: the velocity loop on its estimate of the group's centre
    (or, on an assembly's or a reshape's lines, on its own state), saturated at ``u_max``, added to its set-point."""
    leg = -1
    for m in range(nav.leg_step.shape[0]):
        if nav.leg_step[m] <= k:
            leg = m
    if leg < 0:
        return
    n_axes = len(box)
    kind = nav.leg_kind[leg]
    on_lines = (kind == ASSEMBLE or kind == RESHAPE) and (k - nav.leg_step[leg]) * nav.dt < nav.leg_span[leg]
    if nav.leg_now[i] != leg or not on_lines:  # on the lines the centre is needed only where they start: O(N) saved
        centre(i, known, agents.active, nav.centre)  # noqa: F821  (bound)
    if nav.leg_now[i] != leg:  # the leg starts: from here, at its first point
        nav.leg_now[i] = leg
        nav.point_now[i] = nav.leg_first[leg]
        for a in range(n_axes):
            nav.leg_from[i, a] = nav.centre[i, a, 0]
            nav.line_from[i, a] = known[i, a, 0]
            nav.drift[i, a] = nav.centre[i, a, 1] if kind == RESHAPE else 0.0
    if on_lines:  # its own state, towards its own place
        for a in range(n_axes):
            for s in range(nav.centre.shape[2]):
                nav.centre[i, a, s] = known[i, a, s]
        lines(i, k, leg, nav, n_axes)  # noqa: F821  (bound)
    elif kind == VELOCITY:
        for a in range(n_axes):
            nav.wanted[i, a] = nav.leg_velocity[leg, a]
    elif kind == RESHAPE:
        drifting(i, k, leg, nav, n_axes)  # noqa: F821  (bound)
    else:  # and an assembly, placed: the group holds the shape's centre
        towards(i, leg, nav, n_axes)  # noqa: F821  (bound)
    size2 = 0.0
    for a in range(n_axes):
        push = 0.0
        for s in range(1, nav.centre.shape[2]):
            push -= nav.gain[s - 1] * (nav.centre[i, a, s] - (nav.wanted[i, a] if s == 1 else 0.0))
        nav.push[i, a] = push
        size2 += push * push
    scale = min(1.0, nav.u_max / np.sqrt(size2)) if size2 > 0.0 else 1.0
    for a in range(n_axes):
        agents.setpoint[i, a] += scale * nav.push[i, a]


class Navigation(AgentTerm):
    """(N1)-(N5): a group flying a mission (module text)."""

    name = "navigation"
    table = NavigationParams
    local = False
    steers_group = True
    rebuilt = {
        **{field: "a number of the mission, fixed for the run" for field in Navigated._fields[:15]},
        **{field: "work space, written before it is read at every step" for field in ("centre", "wanted", "push")},
    }

    @classmethod
    def record(cls, settings: NavigationParams, scenario, gains) -> Navigated:
        """The record of (N1)-(N5) for a run of ``scenario`` (:func:`navigation_record`).

        Parameters
        ----------
        settings : NavigationParams
            The ``[navigation]`` table.
        scenario : Scenario
            The whole scenario.
        gains : ndarray
            ``K`` of the law.
        """
        return navigation_record(settings, scenario, gains)

    @classmethod
    @cache
    def kernel(cls):
        """The compiled (N1)-(N3), :func:`_push` (compiled on first use)."""
        from tmem.engine.variants import bound

        options = {"inline": "always", "error_model": "numpy"}
        geometry = {"point": bound(_point, "navigation_point", options), "start": bound(_start, "navigation_start", options)}
        segment = bound(_segment, "navigation_segment", options, **geometry)
        towards = bound(_towards, "navigation_towards", options, segment=segment, **geometry)
        return bound(_push, "navigation_push", options, centre=bound(_centre, "navigation_centre", options), towards=towards,
                     lines=bound(_lines, "navigation_lines", options),
                     drifting=bound(_drifting, "navigation_drifting", options))  # fmt: skip
