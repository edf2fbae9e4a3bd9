"""The swarm as a gas: the stages that combine pushes in crowds, hold a temperature, keep agents off
walls and obstacles, and keep the totals the gas's observables come from.

The derivations are in ``docs/gas.md``; equation labels below refer to it.

* **Mean of pushes (C1).**  An agent pushed by ``n`` neighbours held still sees the closed loop
  ``A - n B K``, whose slow pair leaves the imaginary axis for ``n != 1`` and grows for ``n >= 4``.
  With ``interaction.combine = "mean"`` the push of a pair is divided by the larger of its two
  agents' contacts, as each broadcast them at the step before: pushes stay equal and opposite, and
  no agent's gains add up to much more than one ``K``.  The modes of a crowd are then
  ``A - lambda B K`` with ``lambda`` in ``[0, 2]``, on which the slow pair stays within
  ``6e-6 / s`` of the imaginary axis.  A contact counts by the size of its push over ``c_max``
  (from 0 at the edge of reach to 1 at saturation), so that a neighbour coming within reach changes
  the weights smoothly: counted whole at once, each arrival would jolt the others' pushes and heat
  the gas.  With one neighbour nothing changes.
* **Thermostat (T1)-(T2).**  Each agent estimates the temperature from what it knows: its own
  energy and its neighbours' within reach, each ``|V|^2`` plus the energy its pushes hold,
  ``(g |U| / omega)^2`` with ``omega`` its slow mode's frequency (T2).  It tilts along its velocity
  so that ``dV/dt = (T* / T_i - 1) V / (2 tau)``: Berendsen's weak coupling, applied per agent.
* **Walls and obstacles (W1)-(W2).**  A wall or an obstacle is a neighbour held still: the
  repulsion (8) acts on the distance from the agent's ``P*`` (6) to its nearest point, with
  ``R + R_w`` for ``R + R_j``.  Held still, it is the case the modal gains were designed for.  A
  wall has the last word (W2): within its reach, the part of the agent's other pushes that points
  into it is dropped, and the others get what the tilt limit leaves after the walls' pushes.

The running totals (per agent, summed at each record) are those of :data:`TOTALS`.
"""

from __future__ import annotations

import numba
import numpy as np

from .. import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from ..interaction.kernels import FunctionParams, repulsion
from ..scenario import ThermostatParams
from ..space import nearest_image
from .records import Gas

#: The running totals of each agent, in the columns of ``Gas.totals``: momentum given to the box's
#: walls per unit mass (m/s), the same weighted by the agent's distance from the wall (m^2/s), the
#: virial of the pushes integrated over time (m^2/s), encounters (neighbours that came within reach:
#: the rises of the agent's count of them, step to step), path flown (m), and steps spent beyond a
#: wall or inside an obstacle.
TOTALS = ("wall_momentum", "wall_virial", "virial", "encounters", "path", "breaches")
#: Long name and units of each column of a record (:data:`TOTALS` then :data:`SNAPSHOT`), running
#: totals over every agent since the start, per unit agent mass.
COLUMNS = {
    "wall_momentum": ("momentum given to the walls", "m s-1"),
    "wall_virial": ("momentum given to the walls times the distance from them", "m2 s-1"),
    "virial": ("virial of the pushes, integrated", "m2 s-1"),
    "encounters": ("neighbours that came within reach", "1"),
    "path": ("path flown", "m"),
    "breaches": ("agent-steps beyond a wall or inside an obstacle", "1"),
    "speed2_sum": ("sum of |V|^2 over flying agents", "m2 s-2"),
    "flying": ("agents flying", "1"),
    "moment": ("sum of (P - box centre) . V over walled axes", "m2 s-1"),
}
#: What a record holds besides the totals summed over agents: the sum of ``|V|^2`` of the flying
#: agents, their number, and ``sum_i (P_i - c) . V_i`` over the walled axes (``c`` the box's centre;
#: the virial theorem's boundary term, m^2/s).
SNAPSHOT = ("speed2_sum", "flying", "moment")


@numba.njit(cache=True, inline="always")
def clear(i, known, gas, n_axes):
    """Start agent ``i``'s step: nothing counted yet; its own ``|V|^2`` as known.

    Parameters
    ----------
    i : int
        The agent's slot.
    known : ndarray, shape (agents, axes, n_state)
        The states as measured.
    gas : Gas
        The record (:class:`tmem.engine.records.Gas`), changed in place.
    n_axes : int
        Number of axes.
    """
    speed2 = 0.0
    for a in range(n_axes):
        speed2 += known[i, a, 1] * known[i, a, 1]
    gas.speed2[i] = speed2
    gas.energy[i] = speed2 + gas.stored[i]
    gas.near[i] = 0.0
    gas.contact[i] = 0.0
    gas.near_energy[i] = 0.0
    gas.virial[i] = 0.0
    gas.wall_push[i] = 0.0
    gas.wall_moment[i] = 0.0
    gas.limit[i] = gas.c_max


@numba.njit(cache=True, inline="always")
def _obstacle_gap(i, o, corrected, obstacles, box, n_axes):
    """Distance from agent ``i``'s ``P*`` to the centre of obstacle ``o``, and to its surface (m)."""
    r2 = 0.0
    for a in range(n_axes):
        delta = nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a])
        r2 += delta * delta
    centre = np.sqrt(r2)
    return centre, centre - obstacles[o, n_axes]


@numba.njit(cache=True, inline="always")
def _wall_pushes(i, corrected, pushed, walls, obstacles, box, wall_params, n_axes):
    """The pushes (8) of the walls and obstacles within reach of agent ``i``'s ``P*`` (W1), summed into
    ``pushed[i]``; return how many pushed, the sum of their sizes in units of ``c_max`` (C1), the
    size of the box walls' pushes (rad), and their sum weighted by the agent's distance ``P`` from
    each wall (rad m)."""
    contacts = 0
    pressing = 0.0
    on_walls = 0.0
    moment = 0.0
    reach = wall_params.reach
    for a in range(n_axes):
        pushed[i, a] = 0.0
        if walls[a] > 0.0:
            low = corrected[i, a, 0]
            high = walls[a] - low
            if low < reach:  # the wall at 0 lies at d = -low: its push points along +a
                u = repulsion(max(low, 0.0), 0, wall_params)
                pushed[i, a] -= u
                on_walls -= u
                moment -= u * corrected[i, a, 1]
                contacts += 1
                pressing -= u / wall_params.c_max
            if high < reach:
                u = repulsion(max(high, 0.0), 0, wall_params)
                pushed[i, a] += u
                on_walls -= u
                moment -= u * (walls[a] - corrected[i, a, 1])
                contacts += 1
                pressing -= u / wall_params.c_max
    for o in range(obstacles.shape[0]):
        centre, gap = _obstacle_gap(i, o, corrected, obstacles, box, n_axes)
        if gap < reach and centre > 0.0:
            u = repulsion(max(gap, 0.0), 0, wall_params)
            for a in range(n_axes):
                pushed[i, a] += u * nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a]) / centre
            contacts += 1
            pressing -= u / wall_params.c_max
    return contacts, pressing, on_walls, moment


@numba.njit(cache=True, inline="always")
def _keep_off(i, corrected, setpoint, walls, obstacles, box, reach, n_axes):
    """Drop from agent ``i``'s other pushes the part that points into a wall or an obstacle within
    reach of its ``P*`` (W2): neighbours, formation pulls and the thermostat never push it through.
    The wall takes what is dropped: return its size on the box's walls (rad), and its sum weighted
    by the agent's distance ``P`` from each wall (rad m), as :func:`_wall_pushes` does."""
    held = 0.0
    moment = 0.0
    for a in range(n_axes):
        if walls[a] > 0.0:
            if corrected[i, a, 0] < reach and setpoint[i, a] < 0.0:
                held -= setpoint[i, a]
                moment -= setpoint[i, a] * corrected[i, a, 1]
                setpoint[i, a] = 0.0
            if walls[a] - corrected[i, a, 0] < reach and setpoint[i, a] > 0.0:
                held += setpoint[i, a]
                moment += setpoint[i, a] * (walls[a] - corrected[i, a, 1])
                setpoint[i, a] = 0.0
    for o in range(obstacles.shape[0]):
        centre, gap = _obstacle_gap(i, o, corrected, obstacles, box, n_axes)
        if gap < reach and centre > 0.0:
            inward = 0.0  # the component along the unit vector from P* to the obstacle's centre
            for a in range(n_axes):
                inward += setpoint[i, a] * nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a]) / centre
            if inward > 0.0:
                for a in range(n_axes):
                    setpoint[i, a] -= inward * nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a]) / centre
    return held, moment


@numba.njit(cache=True, error_model="numpy", inline="always")
def _with_priority(i, setpoint, pushed, c_max, n_axes):
    """Agent ``i``'s set-point as the walls' pushes plus ``alpha`` times the others, ``alpha`` the
    largest in ``[0, 1]`` that keeps it within the tilt limit (W2).  Each wall's push is saturated
    on its own, and walls do not share the limit: in a corner the tilt may reach the larger of
    ``c_max`` and the walls' pushes together (at most ``sqrt(axes) c_max`` in a box's corner), so
    that each wall stops the agent as it would alone.  Return ``alpha`` and the limit."""
    ww = 0.0
    wr = 0.0
    rr = 0.0
    for a in range(n_axes):
        ww += pushed[i, a] * pushed[i, a]
        wr += pushed[i, a] * setpoint[i, a]
        rr += setpoint[i, a] * setpoint[i, a]
    limit2 = max(c_max * c_max, ww)
    alpha = 1.0
    if ww + 2.0 * wr + rr > limit2:  # |w + alpha r| = limit at the root in [0, 1]
        alpha = (-wr + np.sqrt(max(wr * wr - rr * (ww - limit2), 0.0))) / rr
    for a in range(n_axes):
        setpoint[i, a] = pushed[i, a] + alpha * setpoint[i, a]
    return alpha, np.sqrt(limit2)


@numba.njit(cache=True, inline="always")
def _stiffness(near, crowd, mean):
    """``omega^2 / im_r^2`` of the slow mode an agent with ``near`` neighbours and ``crowd`` contacts
    oscillates in (T2): 1 against walls alone (``A - B K``), 2 for a pair (``A - 2 B K``, within 3 %),
    ``w + 1 / near`` in general with ``w`` its summed weights, 1 under the mean of pushes, else
    ``crowd``."""
    if near == 0.0:
        return max(1.0, crowd)
    return (1.0 if mean else crowd) + 1.0 / near


@numba.njit(cache=True, error_model="numpy", inline="always")
def gas_pushes(known, agents, gas, wall_params, run):
    """Walls and obstacles (W1)-(W2) and the thermostat (T1)-(T2), agent by agent, after the
    neighbour pushes and the formation pairs; count the neighbours that came within reach.

    (Parallel loops take plain arrays and numbers: the records' fields are read out before them.)

    Parameters
    ----------
    known : ndarray, shape (agents, axes, n_state)
        The states as measured.
    agents, gas, run
        The loop's records (:mod:`tmem.engine.records`); ``agents`` and ``gas`` change in place.
    wall_params : FunctionParams
        The repulsion's parameters with ``R + R_w`` for its reach.
    """
    box = run.box
    n_axes = len(box)
    corrected = agents.corrected
    setpoint = agents.setpoint
    active = agents.active
    walls = gas.walls
    obstacles = gas.obstacles
    near = gas.near
    near_before = gas.near_before
    crowd = gas.crowd
    contact = gas.contact
    bounded = obstacles.shape[0] > 0
    for a in range(n_axes):
        bounded = bounded or walls[a] > 0.0
    pushed = gas.pushed
    limit = gas.limit
    virial = gas.virial
    walled = walls[0] > 0.0
    wall_push = gas.wall_push
    wall_moment = gas.wall_moment
    totals = gas.totals
    mean = gas.mean
    rate = gas.rate
    target2 = gas.target2[0]
    inv_g = gas.inv_g
    speed2 = gas.speed2
    stored = gas.stored
    energy_scale = gas.energy_scale
    near_energy = gas.near_energy
    reach = wall_params.reach
    c_max = wall_params.c_max
    for i in numba.prange(known.shape[0]):
        if not active[i]:
            continue
        contacts = 0
        pressing = 0.0
        if bounded:
            contacts, pressing, wall_push[i], wall_moment[i] = _wall_pushes(i, corrected, pushed, walls, obstacles,
                                                                            box, wall_params, n_axes)  # fmt: skip
        crowd[i] = contact[i] + pressing
        totals[i, 3] += max(near[i] - near_before[i], 0.0)
        near_before[i] = near[i]
        if rate > 0.0 and target2 > 0.0:
            pushed2 = 0.0
            for a in range(n_axes):
                total = setpoint[i, a] + (pushed[i, a] if contacts > 0 else 0.0)
                pushed2 += total * total
            stored[i] = energy_scale * pushed2 / _stiffness(near[i], crowd[i], mean)
            temperature = (speed2[i] + stored[i] + near_energy[i]) / (1.0 + near[i])
            push = rate * (target2 / temperature - 1.0) * inv_g if temperature > 0.0 else 0.0
            for a in range(n_axes):
                setpoint[i, a] += push * known[i, a, 1]
        if walled:  # the virial of every push but the walls', about the box's centre (G1)
            own = 0.0
            for a in range(n_axes):
                own += (corrected[i, a, 1] - 0.5 * walls[a]) * setpoint[i, a]
            virial[i] = own
        else:  # each pair's half
            virial[i] *= 0.5
        if contacts > 0:  # what the walls drop of the others becomes the walls' own push (W2)
            held, held_moment = _keep_off(i, corrected, setpoint, walls, obstacles, box, reach, n_axes)
            others, limit[i] = _with_priority(i, setpoint, pushed, c_max, n_axes)
            wall_push[i] += others * held
            wall_moment[i] += others * held_moment
            virial[i] *= others


@numba.njit(cache=True, inline="always")
def tilt_limit(gas, i, c_max):
    """Agent ``i``'s tilt limit this step: ``c_max``, or more in a corner (:func:`_with_priority`).

    Parameters
    ----------
    gas : Gas
        The record.
    i : int
        The agent's slot.
    c_max : float
        The scenario's tilt limit (rad).
    """
    return gas.limit[i] if gas.observe else c_max


@numba.njit(cache=True, inline="always")
def tally(x, i, scale, gas, n_axes):
    """Add agent ``i``'s step to its totals, after its vehicle's step; ``scale`` is the factor that
    saturated its set-point.

    Parameters
    ----------
    x : ndarray, shape (agents, axes, n_state)
        The true states, after the step.
    i : int
        The agent's slot.
    scale : float
        The saturation factor of its set-point this step (:func:`tmem.control.tilt_scale`).
    gas : Gas
        The record, changed in place.
    n_axes : int
        Number of axes.
    """
    applied = scale * gas.g_dt
    gas.totals[i, 0] += applied * gas.wall_push[i]
    gas.totals[i, 1] += applied * gas.wall_moment[i]
    gas.totals[i, 2] += applied * gas.virial[i]
    gas.totals[i, 4] += np.sqrt(gas.speed2[i]) * gas.dt
    outside = False
    for a in range(n_axes):
        if gas.walls[a] > 0.0 and not 0.0 <= x[i, a, 0] <= gas.walls[a]:
            outside = True
    for o in range(gas.obstacles.shape[0]):
        r2 = 0.0
        for a in range(n_axes):
            r2 += (x[i, a, 0] - gas.obstacles[o, a]) ** 2
        if r2 < gas.obstacles[o, n_axes] ** 2:
            outside = True
    if outside:
        gas.totals[i, 5] += 1.0


@numba.njit(cache=True, inline="always")
def record_totals(agents, gas, records, q, n_axes):
    """Sum every agent's totals, their ``|V|^2`` and the flying agents into row ``q`` of ``records.gas``.

    Parameters
    ----------
    agents, gas, records
        The loop's records; ``records`` changes in place.
    q : int
        The record's row.
    n_axes : int
        Number of axes.
    """
    if records.gas.shape[1] == 0:
        return
    for c in range(records.gas.shape[1]):
        records.gas[q, c] = 0.0
    n_totals = gas.totals.shape[1]
    for i in range(agents.state.shape[0]):
        for c in range(n_totals):
            records.gas[q, c] += gas.totals[i, c]
        if agents.active[i]:
            for a in range(n_axes):
                records.gas[q, n_totals] += agents.state[i, a, 1] * agents.state[i, a, 1]
                if gas.walls[a] > 0.0:
                    records.gas[q, n_totals + 2] += (agents.state[i, a, 0] - 0.5 * gas.walls[a]) * agents.state[i, a, 1]
            records.gas[q, n_totals + 1] += 1.0


def wall_params(params: FunctionParams, wall_reach: float) -> FunctionParams:
    """The repulsion's parameters for walls and obstacles: the law's, with ``R + R_w`` for the reach.

    Parameters
    ----------
    params : FunctionParams
        The interaction functions' parameters.
    wall_reach : float
        ``R + R_w`` (m).
    """
    return params._replace(reach=float(wall_reach))


def gas_record(scenario, acceleration_per_tilt: float, n_agents: int) -> Gas:
    """The :class:`~tmem.engine.records.Gas` record of a scenario, with its work space for ``n_agents``.

    Parameters
    ----------
    scenario : Scenario
        Its ``interaction.combine``, ``[thermostat]``, walls, ``[[obstacles]]`` and ``observe_gas``.
    acceleration_per_tilt : float
        ``g``: the acceleration a tilt of one radian gives (``A[1, 2]`` of the vehicle's linearisation).
    n_agents : int
        Agents of the run.
    """
    observe = scenario.gas_observed
    size = n_agents if observe else 0
    space, thermostat = scenario.space, scenario.thermostat
    walls = np.asarray(space.box, dtype=float) if space.walls else np.zeros(space.axes)
    obstacles = np.array([o.center + [o.radius] for o in scenario.obstacles], dtype=float).reshape(-1, space.axes + 1)
    rms = thermostat.rms_velocity if thermostat is not None else None
    tau = thermostat.tau if thermostat is not None else ThermostatParams().tau
    dt = scenario.simulation.dt
    return Gas(
        observe=observe,
        mean=scenario.interaction.combine == "mean",
        rate=0.5 / tau if observe else 0.0,
        target2=np.array([0.0 if rms is None else rms * rms]),
        inv_g=1.0 / acceleration_per_tilt,
        g_dt=acceleration_per_tilt * dt,
        dt=dt,
        walls=walls,
        obstacles=obstacles,
        wall_reach=scenario.wall_reach,
        near=np.zeros(size),
        near_energy=np.zeros(size),
        speed2=np.zeros(size),
        energy=np.zeros(size),
        stored=np.zeros(size),
        energy_scale=(acceleration_per_tilt / scenario.controller.im_r) ** 2,
        virial=np.zeros(size),
        wall_push=np.zeros(size),
        wall_moment=np.zeros(size),
        crowd=np.zeros(size),
        contact=np.zeros(size),
        pushed=np.zeros((size, space.axes)),
        limit=np.full(size, scenario.interaction.c_max),
        c_max=scenario.interaction.c_max,
        near_before=np.zeros(size),
        totals=np.zeros((size, len(TOTALS))),
    )
