"""The swarm as a gas: the stages that combine pushes in crowds, hold a temperature, keep agents off
walls and obstacles, and keep the totals the gas's observables come from.

The derivations are in ``docs/gas.md``; equation labels below refer to it.

* **Mean of pushes (C1).**  An agent pushed by ``n`` neighbours held still sees the closed loop
  ``A - n B K``, whose slow pair leaves the imaginary axis for ``n != 1`` and grows for ``n >= 4``.
  With ``interaction.combine = "mean"`` the push of a pair is divided by the larger of its two
  agents' contacts, as each broadcast them at the last count: pushes stay equal and opposite, and
  no agent's gains add up to much more than one ``K``.  The modes of a crowd are then
  ``A - lambda B K`` with ``lambda`` in ``[0, 2]``, on which the slow pair stays within
  ``6e-6 / s`` of the imaginary axis.  A contact counts by the square of its push's size over
  ``c_max`` (from 0 at the edge of reach to 1 at saturation), so that a neighbour coming within
  reach changes the weights smoothly: counted whole at once, each arrival would jolt the others'
  pushes.  With one neighbour nothing changes.
* **Thermostat (T1), (T3)**: :mod:`tmem.engine.thermostat`.
* **Walls and obstacles (W1)-(W2)** are neighbours held still, with the last word on the
  set-point: :mod:`tmem.world.walls`.

The counts a pair adds to its agents (contacts, the thermostat's groups, the virial, encounters)
are taken every ``simulation.gas_period`` (a *count*, ``Gas.every`` steps apart), and what they set
is held between counts: the weights of the mean of pushes, the thermostat's group pushes.  The
walls, the thermostat's free part and the momentum the walls take act at every step.  The running
totals (per agent, summed at each record) are those of :data:`TOTALS`.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.scenario import ThermostatParams
from tmem.world.space import nearest_image
from tmem.engine.gas_columns import COMMON, CONTACT, NEAR, NEIGHBOUR_SPEED2, NEIGHBOUR_VELOCITY, SPEED2, VIRIAL
from tmem.engine.records import Gas
from tmem.engine.thermostat import add_thermostat_push, hold_group_push
from tmem.world.walls import keep_off, wall_pushes, with_priority

#: Long name and units of each column of a record, per unit agent mass: first the running totals
#: of every agent since the start (:data:`TOTALS`), then what a record adds (:data:`SNAPSHOT`).
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
#: The running totals of each agent, the columns of ``Gas.totals``: momentum given to the box's walls
#: (m/s), the same weighted by the agent's distance from the wall (m^2/s), the virial of the pushes
#: integrated over time (m^2/s, sampled at the counts), encounters (neighbours that came within
#: reach: the rises of the agent's count of them, count to count), path flown (m, sampled at the
#: counts), and steps spent beyond a wall or inside an obstacle.
TOTALS = tuple(COLUMNS)[:6]
WALL_MOMENTUM, WALL_VIRIAL, VIRIAL_TOTAL, ENCOUNTERS, PATH, BREACHES = range(len(TOTALS))
#: What a record holds besides the totals summed over agents: the sum of ``|V|^2`` of the flying
#: agents, their number, and ``sum_i (P_i - c) . V_i`` over the walled axes (``c`` the box's centre;
#: the virial theorem's boundary term, m^2/s).
SNAPSHOT = tuple(COLUMNS)[len(TOTALS):]


@numba.njit(cache=True, inline="always")
def clear(i, known, work, n_axes):
    """Start agent ``i``'s count: nothing counted yet, and its own ``|V|^2`` as known.

    Called in a parallel loop: it takes the record's arrays, not the record.

    Parameters
    ----------
    i : int
        The agent's slot.
    known : ndarray, shape (agents, axes, n_state)
        The states as measured.
    work : ndarray
        ``Gas.work`` (:class:`tmem.engine.records.Gas`), changed in place.
    n_axes : int
        Number of axes.
    """
    speed2 = 0.0
    for a in range(n_axes):
        speed2 += known[i, a, 1] * known[i, a, 1]
    for c in range(work.shape[1]):
        work[i, c] = 0.0
    work[i, SPEED2] = speed2


@numba.njit(cache=True, inline="always")
def pair_share(i, j, weight):
    """The weight (C1) of the push of the pair ``(i, j)``: one over the larger of its agents' contacts
    (at least one), the smaller of their weights.  Each agent inverts its contacts once a step, so
    that no pair divides.

    Parameters
    ----------
    i, j : int
        The agents' slots.
    weight : ndarray, shape (agents,)
        ``Gas.weight``.
    """
    return min(weight[i], weight[j])


@numba.njit(cache=True, inline="always")
def virial_by_pairs(walls):
    """Whether the virial (G1) is summed pair by pair, ``(P_i - P_j) . u_ij``: in a box without walls.
    A walled box takes each agent's ``(P_i - c) . u_i`` about its centre ``c`` instead.

    Parameters
    ----------
    walls : ndarray, shape (axes,)
        ``Gas.walls``: the walled box's sides, 0 without walls.
    """
    return walls[0] == 0.0


@numba.njit(cache=True, inline="always")
def add_contact(i, j, near, pressing, virial, pair_virial, work, known):
    """Count the pair ``(i, j)`` for both agents: whether it is within reach, its push's squared size
    over ``c_max^2``, the other's ``|V|^2`` and velocity weighted by it (T3) and, when ``pair_virial``,
    the pair's virial ``(P_i - P_j) . u_ij`` (rad m).

    Parameters
    ----------
    i, j : int
        The agents' slots.
    near : float
        1 if the pair is within reach, else 0 (its push and virial are then 0 too).
    pressing : float
        The pair's push's squared size over ``c_max^2``.
    virial : float
        ``(P_i - P_j) . u_ij``, the push on ``i`` as applied.
    pair_virial : bool
        Whether the virial is the pairs' (G1): in a periodic box, not a walled one.
    work : ndarray
        ``Gas.work``, changed in place; both agents' ``|V|^2`` already in it (:func:`clear`).
    known : ndarray, shape (agents, axes, n_state)
        The states as known: the true ones, since the gas's stages run only where sensing is exact.
    """
    work[i, NEAR] += near
    work[j, NEAR] += near
    work[i, CONTACT] += pressing
    work[j, CONTACT] += pressing
    work[i, NEIGHBOUR_SPEED2] += pressing * work[j, SPEED2]
    work[j, NEIGHBOUR_SPEED2] += pressing * work[i, SPEED2]
    for a in range(known.shape[1]):
        work[i, NEIGHBOUR_VELOCITY + a] += pressing * known[j, a, 1]
        work[j, NEIGHBOUR_VELOCITY + a] += pressing * known[i, a, 1]
    if pair_virial:
        work[i, VIRIAL] += virial
        work[j, VIRIAL] += virial


@numba.njit(cache=True, error_model="numpy", inline="always")
def _gas_agent(i, known, corrected, setpoint, gas, wall_params, box, counting, first):
    """Agent ``i``'s part of :func:`gas_pushes`."""
    n_axes = len(box)
    walls = gas.walls
    obstacles = gas.obstacles
    work = gas.work
    limit = gas.limit
    pushed = gas.pushed
    bounded = obstacles.shape[0] > 0
    for a in range(n_axes):
        bounded = bounded or walls[a] > 0.0
    contacts = 0
    pressing = 0.0
    on_walls = 0.0
    moment = 0.0
    obstacles_virial = 0.0
    if bounded:
        contacts, pressing, on_walls, moment, obstacles_virial = wall_pushes(i, corrected, pushed, walls, obstacles, box,
                                                                             wall_params, n_axes)  # fmt: skip
    thermostat = gas.rate > 0.0 and gas.target2[0] > 0.0
    if counting:
        gas.weight[i] = 1.0 / max(1.0, work[i, CONTACT] + pressing)
        if not first:  # the neighbours present at the start are not encounters
            gas.totals[i, ENCOUNTERS] += max(work[i, NEAR] - gas.near_before[i], 0.0)
        gas.near_before[i] = work[i, NEAR]
        if thermostat:
            hold_group_push(i, known, work, gas.held, gas.rate, gas.target2[0], gas.inv_g, n_axes)
    pushes_scale = 1.0  # the factor that saturated the pushes here, not in the vehicle's step
    if thermostat and contacts == 0:  # within a wall's reach, the wall's bounce is left as it is
        pushes_scale = add_thermostat_push(i, known, setpoint, gas.held, limit, gas.rate, gas.target2[0], gas.inv_g,
                                           gas.c_max, n_axes)  # fmt: skip
    else:
        limit[i] = gas.c_max
    if counting and not virial_by_pairs(walls):  # the virial of every push but the walls', about the box's centre (G1)
        own = 0.0
        for a in range(n_axes):
            own += (corrected[i, a, 1] - 0.5 * walls[a]) * setpoint[i, a]
        work[i, VIRIAL] = own
    elif counting:  # each pair's half, of the pushes as saturated
        work[i, VIRIAL] *= 0.5 * pushes_scale
    if contacts > 0:  # what the walls drop of the others becomes the walls' own push (W2)
        held, held_moment, dropped_virial = keep_off(i, corrected, setpoint, walls, obstacles, box, wall_params.reach,
                                                      n_axes)  # fmt: skip
        others, limit[i] = with_priority(i, setpoint, pushed, wall_params.c_max, n_axes)
        # the set-point is now within its limit and is applied as it stands: the walls take this
        gas.totals[i, WALL_MOMENTUM] += gas.g_dt * (on_walls + others * held)
        gas.totals[i, WALL_VIRIAL] += gas.g_dt * (moment + others * held_moment)
        if counting:
            work[i, VIRIAL] = others * (work[i, VIRIAL] + dropped_virial) + obstacles_virial


@numba.njit(cache=True, error_model="numpy", inline="always")
def gas_pushes(known, agents, gas, wall_params, run, n_blocks, counting):
    """Walls and obstacles (W1), the thermostat (T1), (T3), then the walls' last word (W2), agent by
    agent (:func:`_gas_agent`), after the neighbour pushes and the formation pairs; at a count, the
    weights of the mean of pushes (C1), the thermostat's group pushes, and the neighbours that came
    within reach.

    Parameters
    ----------
    known : ndarray, shape (agents, axes, n_state)
        The states as measured.
    agents, gas, run
        The loop's records (:mod:`tmem.engine.records`); ``agents`` and ``gas`` change in place.
    wall_params : tmem.law.interaction.kernels.FunctionParams
        The repulsion's parameters with ``R + R_w`` for its reach.
    n_blocks : int
        Blocks of agents the parallel loop shares out (those of :func:`tmem.engine.stages.corrected_positions`).
    counting : bool
        Whether the step is a count.
    """
    box = run.box
    first = gas.first[0]
    if counting:
        gas.first[0] = False
    n_agents = known.shape[0]
    per_block = (n_agents + n_blocks - 1) // n_blocks
    for b in numba.prange(n_blocks):
        _gas_block(b * per_block, min(n_agents, (b + 1) * per_block), known, agents, gas, wall_params, box, counting,
                   first)  # fmt: skip


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _gas_block(begin, end, known, agents, gas, wall_params, box, counting, first):
    """Agents ``begin:end`` of :func:`gas_pushes`, one after the other.

    Called, not inlined, once per block of agents: compiled once, the gas's code stays out of the
    step loop's compilation, and out of Numba's transform of the parallel loop.  Inlined in the
    parallel loop, the agent's code gave the threaded loop other totals than the serial one (Numba's
    diagnostics show constant assignments of that code moved out of the loop).  A call per agent
    cost more than the agent's work (its records passed each time); a call per block costs nothing."""
    for i in range(begin, end):
        if agents.active[i]:
            _gas_agent(i, known, agents.corrected, agents.setpoint, gas, wall_params, box, counting, first)


@numba.njit(cache=True, inline="always")
def tilt_limit(observe, limit, i, c_max):
    """Agent ``i``'s tilt limit this step: ``c_max``, or more in a corner (:func:`tmem.world.walls.with_priority`).

    Parameters
    ----------
    observe : bool
        Whether the gas is observed (``Gas.observe``; else ``limit`` is empty).
    limit : ndarray, shape (agents,)
        ``Gas.limit``.
    i : int
        The agent's slot.
    c_max : float
        The scenario's tilt limit (rad).
    """
    return limit[i] if observe else c_max


@numba.njit(cache=True, inline="always")
def tally(x, i, scale, work, totals, walls, obstacles, box, g_dt, dt, n_axes, sampled):
    """Add agent ``i``'s step to its totals, after its vehicle's step: the breaches at every step; at
    a count, the virial and the path, each as ``sampled`` steps of it (the walls' momentum is added
    where the walls push, :func:`gas_pushes`).  Called in a parallel loop: it takes the record's
    arrays and numbers, not the record.

    Parameters
    ----------
    x : ndarray, shape (agents, axes, n_state)
        The true states, after the step.
    i : int
        The agent's slot.
    scale : float
        The saturation factor of its set-point this step (:func:`tmem.law.modal.tilt_scale`).
    work, totals, walls, obstacles : ndarray
        ``Gas.work``, ``Gas.totals`` (changed in place), ``Gas.walls``, ``Gas.obstacles``.
    box : tuple of float
        The periodic box's sides (0: open axis).
    g_dt, dt : float
        ``g dt`` and ``dt``.
    n_axes : int
        Number of axes.
    sampled : int
        The steps a count stands for (``Gas.every``, or those left in the run at its last count); 0 at
        a step that is not a count.
    """
    if sampled > 0:
        totals[i, VIRIAL_TOTAL] += sampled * scale * g_dt * work[i, VIRIAL]
        totals[i, PATH] += sampled * np.sqrt(work[i, SPEED2]) * dt
    outside = False
    for a in range(n_axes):
        if walls[a] > 0.0 and not 0.0 <= x[i, a, 0] <= walls[a]:
            outside = True
    for o in range(obstacles.shape[0]):
        r2 = 0.0
        for a in range(n_axes):
            delta = nearest_image(x[i, a, 0] - obstacles[o, a], box[a])
            r2 += delta * delta
        if r2 < obstacles[o, n_axes] ** 2:
            outside = True
    if outside:
        totals[i, BREACHES] += 1.0


@numba.njit(cache=True, _nrt=False)
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
        every=max(1, int(scenario.simulation.gas_period / dt + 0.5)),  # the nearest whole number of steps
        walls=walls,
        obstacles=obstacles,
        wall_reach=scenario.wall_reach,
        c_max=scenario.interaction.c_max,
        first=np.ones(1, dtype=np.bool_),
        work=np.zeros((size, NEIGHBOUR_VELOCITY + space.axes)),
        weight=np.ones(size),  # no contacts yet
        near_before=np.zeros(size),
        limit=np.zeros(size),
        held=np.zeros((size, COMMON + space.axes)),
        pushed=np.zeros((size, space.axes)),
        totals=np.zeros((size, len(TOTALS))),
    )
