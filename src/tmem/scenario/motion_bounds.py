"""The bounds of a scenario's motion: its starts' tilts and speeds against the model (1)-(2), the
coupling window, the reach and the tilt limit; a formation's jitter; the sensing's delays, range
and noise (the figures are :mod:`tmem.scenario.bounds`'s, derived in ``docs/parameters.md``).

:func:`check_motion` raises :class:`~tmem.scenario.tables.FieldError` on a value beyond a bound
and gives back the :class:`~tmem.scenario.bounds.Doubt` of each doubtful one.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from tmem.law.interaction.registry import pushes, uses_coupling
from tmem.scenario.bounds import SMALL_ANGLE_ERROR, SMALL_ANGLE_TILT, Doubt, peak_tilt, stopping_speed
from tmem.scenario.tables import FieldError

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario

#: Most listed agents whose every pair's closing speed is taken (n^2 differences); beyond, the two
#: largest speeds' sum, an upper bound.
PAIRWISE = 200


class Speed(NamedTuple):
    """A speed a scenario sets: the field that sets it, the velocity (m/s, one entry per axis) or,
    for a random or held swarm, the RMS speed (``rms``), and what it is, in words."""

    field: str
    velocity: tuple[float, ...]
    rms: float
    what: str


def speeds(scenario: Scenario) -> list[Speed]:
    """The speeds ``scenario`` sets: each listed agent's velocity, a formation's, a swarm's RMS speed
    at the start, the thermostat's and the ``temperature`` commands' RMS speeds, and a mission's.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid.
    """
    axes, found = scenario.space.axes, []
    for k, agent in enumerate(scenario.agents):
        velocity = tuple(float(v) for v in np.ravel(agent.velocity) * np.ones(axes))
        found.append(Speed(f"agents[{k}].velocity", velocity, 0.0, f"agents[{k}]"))
    f = scenario.formation
    if f is not None and f.kind != "edges" and f.velocity is not None:
        found.append(Speed("formation.velocity", tuple(f.velocity), 0.0, "the formation"))
    if scenario.swarm is not None:
        found.append(Speed("swarm.speed_rms", (0.0,) * axes, scenario.swarm.speed_rms, "the swarm's RMS speed"))
    if scenario.thermostat is not None and scenario.thermostat.rms_velocity is not None:
        found.append(Speed("thermostat.rms_velocity", (0.0,) * axes, scenario.thermostat.rms_velocity, "the RMS speed held"))
    for k, command in enumerate(scenario.commands):
        if command.action == "temperature" and command.value is not None:
            found.append(Speed(f"commands[{k}].value", (0.0,) * axes, command.value, "the RMS speed set"))
    return found + _mission_speeds(scenario)


def _mission_speeds(scenario: Scenario) -> list[Speed]:
    """The speeds a ``[navigation]`` mission asks of its group: a leg's ``velocity``, and each ``speed`` as a
    velocity straight into the constant wind (its direction is the route's, so the worst is taken)."""
    nav = getattr(scenario, "navigation", None)
    if nav is None:
        return []
    axes = scenario.space.axes
    wind = np.array(scenario.wind.mean()[:axes]) if scenario.wind is not None else np.zeros(axes)
    into = -wind / np.linalg.norm(wind) if np.any(wind) else np.eye(axes)[0]
    found = []
    for k, leg in enumerate(nav.legs):
        if leg.velocity is not None:
            found.append(Speed(f"navigation.legs[{k}].velocity", tuple(leg.velocity), 0.0, f"the mission's leg {k}"))
        for speed in sorted(set(leg.speeds())):
            if math.isfinite(speed):
                found.append(Speed(f"navigation.legs[{k}].speed", tuple(speed * into), 0.0, f"the mission's leg {k}"))
    return found


def closing_speed(scenario: Scenario) -> tuple[float, str, str]:
    """``(v, field, what)``: the largest speed at which two of the scenario's agents close at the start.

    Listed agents: the largest ``|V_j - V_i|`` of any two (beyond :data:`PAIRWISE` agents, the sum
    of the two largest speeds, its upper bound); a formation's agents share their velocity; an RMS
    speed ``s`` (a swarm's, a thermostat's): ``2 s``, two agents at that speed head-on.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid.
    """
    best = (0.0, "", "")
    listed = [s for s in speeds(scenario) if s.field.startswith("agents[")]
    if 1 < len(listed) <= PAIRWISE:
        v = np.array([s.velocity for s in listed])
        gaps = np.linalg.norm(v[:, None, :] - v[None, :, :], axis=2)
        i, j = np.unravel_index(int(np.argmax(gaps)), gaps.shape)
        i, j = min(i, j), max(i, j)
        faster = max((i, j), key=lambda k: float(np.linalg.norm(v[k])))  # the field named: the faster one's
        best = (float(gaps[i, j]), listed[faster].field, f"{listed[i].what} and {listed[j].what} close at")
    elif listed:
        norms = sorted(((math.hypot(*s.velocity), s) for s in listed), key=lambda x: x[0])[-2:]
        best = (sum(n for n, _ in norms), norms[-1][1].field, "two listed agents may close at (their two largest speeds)")
    for s in speeds(scenario):
        if s.rms > 0.0 and 2.0 * s.rms > best[0]:
            best = (2.0 * s.rms, s.field, f"two agents at {s.what} ({s.rms:g} m/s) head-on close at")
    return best


def check_motion(scenario: Scenario) -> list[Doubt]:
    """The motion's bounds (module text); raise :class:`FieldError` beyond one, give back the doubts.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid and checked against each other.
    """
    doubts = _check_tilts(scenario) if scenario.model.kind == "linear" else []  # the others check their own
    doubts += _check_speeds(scenario)
    _check_jitter(scenario)
    return doubts + _check_sensing(scenario)


def _check_tilts(scenario: Scenario) -> list[Doubt]:
    """The small-angle model (1)-(2): a tilt within +-pi/2, doubtful beyond :data:`SMALL_ANGLE_TILT`;
    the start's tilts, the peaks their tilt rates carry them to, and the tilt limit."""
    model, doubts = scenario.model, []
    where = f"(2)'s g phi stands for g tan(phi), the horizontal acceleration with the height held, which it is off by more than {SMALL_ANGLE_ERROR:.0%} beyond {SMALL_ANGLE_TILT:.4g} rad"  # fmt: skip
    c_max = scenario.interaction.c_max
    if c_max > SMALL_ANGLE_TILT:  # a limit, not a tilt: only the tilts the law commands near it leave (2)
        past = ", past the horizontal at +-pi/2 = 1.571 rad," if c_max >= math.pi / 2 else ""
        doubts.append(Doubt("interaction.c_max", f"{c_max:g} rad lets the law command tilts{past} where (2) no longer "
                            f"holds: {where}"))  # fmt: skip
    for k, tilts, rates in _start_tilts(scenario):
        start, peak = max(abs(t) for t in tilts), _peak(model, tilts, rates)
        for name, tilt in (("tilt", start), ("tilt_rate", peak)):
            if tilt >= math.pi / 2:
                what = (f"{per_axis_values(tilts)} rad tilts the thrust" if name == "tilt"
                        else f"{per_axis_values(rates)} rad/s carries the tilt to {tilt:.4g} rad under (1),")  # fmt: skip
                raise FieldError(f"agents[{k}].{name}", f"{what} past the horizontal: the small-angle model (1)-(2) "
                                 "holds for tilts within +-pi/2 = 1.571 rad only (g phi and g tan(phi) agree in sign)")  # fmt: skip
        if peak > SMALL_ANGLE_TILT:
            name = "tilt" if start > SMALL_ANGLE_TILT else "tilt_rate"
            doubts.append(Doubt(f"agents[{k}].{name}", f"the tilt reaches {peak:.4g} rad: {where}"))
    return doubts


def _start_tilts(scenario: Scenario):
    """``(k, tilts, rates)`` of each listed agent that starts tilted or turning (per axis, rad, rad/s)."""
    axes = scenario.space.axes
    for k, agent in enumerate(scenario.agents):
        tilts = np.ravel(agent.tilt) * np.ones(axes)
        rates = np.ravel(agent.tilt_rate) * np.ones(axes)
        if np.any(tilts != 0.0) or np.any(rates != 0.0):
            yield k, tilts.tolist(), rates.tolist()


def per_axis_values(values: list[float]) -> str:
    """Per-axis values as a scenario file gives them: one number, or a list.

    Parameters
    ----------
    values : list of float
        One value per axis.
    """
    return f"{values[0]:g}" if len(values) == 1 else "[" + ", ".join(f"{v:g}" for v in values) + "]"


def _peak(model, tilts: list[float], rates: list[float]) -> float:
    """The largest tilt on any axis under (1) from the start (the start's tilt, without the model's gains)."""
    kp, kd = getattr(model, "kp", None), getattr(model, "kd", None)
    if kp is None or kd is None:
        return max(abs(t) for t in tilts)
    return max(peak_tilt(t, r, kp, kd) for t, r in zip(tilts, rates))


def _check_speeds(scenario: Scenario) -> list[Doubt]:
    """The closing speed of the starts against one step and the reach, the coupling window and the
    tilt limit's stopping distance."""
    v, field, what = closing_speed(scenario)
    if v == 0.0:
        return []
    ia, dt, doubts = scenario.interaction, scenario.simulation.dt, []
    walled = scenario.space.walls or bool(scenario.obstacles)
    reaches = {"R + R_j": ia.reach} if pushes(ia.function) else {}  # "none": the law holds no pair apart
    reaches |= {"R + R_w": scenario.wall_reach} if walled else {}
    if not reaches:
        return []
    farthest = max(reaches.values())  # the farthest anything acts on an agent
    said = " and ".join(f"{name} = {reach:g} m" for name, reach in reaches.items())
    if v * dt >= farthest:
        raise FieldError(field, f"{what} {v:.4g} m/s, {v * dt:.4g} m in one step of dt = {dt:g} s: not less than "
                         f"{said}, the farthest anything acts on an agent; between two steps they may pass "
                         f"through all of it (at most {farthest / dt:.4g} m/s)")  # fmt: skip
    if "R + R_j" not in reaches:
        return doubts
    if v * dt >= ia.reach:
        doubts.append(Doubt(field, f"{what} {v:.4g} m/s, {v * dt:.4g} m in one step of dt = {dt:g} s: not less than "
                            f"R + R_j = {ia.reach:g} m, they may pass through each other between two steps"))  # fmt: skip
    stop = stopping_speed(scenario.model.largest_acceleration(ia.c_max), ia.reach)
    if v > stop:
        doubts.append(Doubt(field, f"{what} {v:.4g} m/s, more than the {stop:.4g} m/s their tilt limits stop within "
                            f"R + R_j = {ia.reach:g} m (sqrt(4 a (R + R_j)), a the largest acceleration the law asks): they may pass "
                            "through each other"))  # fmt: skip
    if uses_coupling(ia.function):
        step = v * dt  # what |d| moves in one step at that speed
        if 2.0 * ia.eps < step:
            raise FieldError("interaction.eps", f"{ia.eps:g} m: the window (9), 2 eps wide, is narrower than the "
                             f"{step:.4g} m |d| moves in one step of dt = {dt:g} s ({what} {v:.4g} m/s), so a crossing "
                             f"of d_t may fall between two steps (at least {step / 2:.4g} m)")  # fmt: skip
        if ia.eps < step:
            doubts.append(Doubt("interaction.eps", f"{ia.eps:g} m is less than the {step:.4g} m |d| moves in one step "
                                f"of dt = {dt:g} s ({what} {v:.4g} m/s): a crossing of d_t is caught in the window (9) "
                                "once at most"))  # fmt: skip
    return doubts


def _check_jitter(scenario: Scenario) -> None:
    """A formation's pairs start apart and, coupled, within the reach: jitter and listed edges."""
    f, ia, axes = scenario.formation, scenario.interaction, scenario.space.axes
    if f is None:
        return
    coupled = f.coupled and uses_coupling(ia.function)
    if f.kind != "edges" and f.jitter > 0.0:
        d_t, spread = f.d_t or ia.d_t, 2.0 * f.jitter * math.sqrt(axes)
        what = (f"{f.jitter:g} m moves each agent up to {f.jitter:g} m on each of {axes} axes, so a pair's distance "
                f"by up to 2 jitter sqrt(axes) = {spread:.4g} m")  # fmt: skip
        if spread >= d_t:
            raise FieldError("formation.jitter", f"{what}, not less than d_t = {d_t:g} m: a pair may start on top of each other")
        if coupled and spread >= ia.reach - d_t:
            raise FieldError("formation.jitter", f"{what}, not less than R + R_j - d_t = {ia.reach - d_t:g} m: a pair "
                             f"may start coupled beyond the reach R + R_j = {ia.reach:g} m, where nothing pulls it")  # fmt: skip
    if f.kind == "edges" and coupled:
        places = [np.ravel(a.position) * np.ones(axes) for a in scenario.agents]
        for k, edge in enumerate(f.edges):
            gap = float(np.linalg.norm(places[edge[1]] - places[edge[0]]))
            if gap >= ia.reach:
                raise FieldError(f"formation.edges[{k}]", f"agents {edge[0]} and {edge[1]} start {gap:.4g} m apart, "
                                 f"coupled beyond the reach R + R_j = {ia.reach:g} m, where nothing pulls them "
                                 "(place them nearer, or set formation.coupled = false)")  # fmt: skip


def _check_sensing(scenario: Scenario) -> list[Doubt]:
    """The delays and the period against the run's duration and the slow roots (5); the range and
    the noise against the set distance and the reach."""
    sensing, doubts = scenario.sensing, []
    if sensing is None or sensing.exact:
        return doubts
    duration, ia = scenario.simulation.duration, scenario.interaction
    low, high = sensing.delays
    if low >= duration:
        raise FieldError("sensing.delay", f"{low:g} s is not shorter than the run ({duration:g} s): no message sent "
                         "in the run reaches anyone in it, and the agents never measure each other")  # fmt: skip
    if sensing.period is not None and sensing.period >= duration:
        raise FieldError("sensing.period", f"{sensing.period:g} s is not shorter than the run ({duration:g} s): "
                         "each agent sends one message, at the start")  # fmt: skip
    quarter = math.pi / (2.0 * scenario.controller.im_r)
    if high > quarter:
        doubts.append(Doubt("sensing.delay", f"{high:g} s is more than a quarter period of the slow roots (5), "
                            f"pi / (2 im_r) = {quarter:.4g} s: a pull arrives in phase with the motion it should restore"))  # fmt: skip
    pairs = uses_coupling(ia.function)  # a formation has pairs; without one, every pair is one
    if sensing.range is not None:
        farthest = _largest_set_distance(scenario) if pairs else 0.0
        if sensing.range <= farthest:
            raise FieldError("sensing.range", f"{sensing.range:g} m is not more than the set distance d_t = "
                             f"{farthest:g} m: a formation pair at its set distance cannot measure each other")  # fmt: skip
        if sensing.range < ia.reach:
            doubts.append(Doubt("sensing.range", f"{sensing.range:g} m is less than R + R_j = {ia.reach:g} m: "
                                "neighbours within the reach but out of range push nothing"))  # fmt: skip
    noise = math.hypot(sensing.position_noise, sensing.own_position_noise)
    own = sensing.own_position_noise > sensing.position_noise
    if noise >= ia.reach:
        raise FieldError("sensing.own_position_noise" if own else "sensing.position_noise", f"the noise on d, at least hypot(position_noise, own_position_noise) = "
                         f"{noise:.4g} m, is not less than R + R_j = {ia.reach:g} m: what an agent measures of "
                         "another is mostly noise")  # fmt: skip
    if pairs and noise > ia.reach - _largest_set_distance(scenario):
        margin = ia.reach - _largest_set_distance(scenario)
        doubts.append(Doubt("sensing.own_position_noise" if own else "sensing.position_noise", f"the noise on d, at least {noise:.4g} m, is more than "
                            f"R + R_j - d_t = {margin:.4g} m: a pair at its set distance is measured beyond the reach "
                            "a sixth of the time or more"))  # fmt: skip
    return doubts


def _largest_set_distance(scenario: Scenario) -> float:
    """The largest set distance of the scenario's formation pairs (m)."""
    f, d_t = scenario.formation, scenario.interaction.d_t
    if f is None:
        return d_t
    if f.kind == "edges":
        return max(float(e[2]) if len(e) == 3 else d_t for e in f.edges)
    return f.d_t or d_t
