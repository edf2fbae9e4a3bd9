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

The counts a pair adds to its agents (contacts, the thermostat's groups, the virial, encounters;
:mod:`tmem.engine.gas_counts`)
are taken every ``simulation.gas_period`` (a *count*, ``Gas.every`` steps apart), and what they set
is held between counts: the weights of the mean of pushes, the thermostat's group pushes.  The
walls, the thermostat's free part and the momentum the walls take act at every step.  The running
totals (per agent, summed at each record) are those of :data:`TOTALS`.

The gas's per-agent functions, here, in :mod:`tmem.engine.gas_counts` and in
:mod:`tmem.engine.thermostat`, take agent ``i``'s slot, ``known``, the states as measured (shape
(agents, axes, n_state): the true ones, since the gas's stages run only where sensing is exact),
and the number of axes ``n_axes``.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.scenario import ThermostatParams
from tmem.world.space import nearest_image
from tmem.engine.gas_counts import COMMON, CONTACT, NEAR, NEIGHBOUR_VELOCITY, SPEED2, VIRIAL, count_pair, virial_by_pairs
from tmem.engine.records import Gas
from tmem.law.interaction.kernels import with_reach
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


@numba.njit(cache=True, error_model="numpy", inline="always")
def gas_agent(i, known, agents, params, gas, box, counting, first):
    """Agent ``i``'s walls and obstacles (W1), thermostat (T1), (T3), then the walls' last word (W2),
    after every other push; at a count, the weights of the mean of pushes (C1), the thermostat's group
    push, and the neighbours that came within reach.  The gas's agent term: the last of the agent
    terms (:mod:`tmem.engine.terms`), bound only where the gas is observed.

    Parameters
    ----------
    i, known
        As every per-agent function of the gas takes them (module text).
    agents, gas
        The loop's records (:mod:`tmem.engine.records`); ``agents.setpoint`` and ``gas`` change in place.
    params : FunctionParams
        The interaction functions' parameters: a wall's repulsion (8) is the law's, with ``R + R_w``.
    box : tuple of float
        The periodic box's sides (0: open axis).
    counting : bool
        Whether the step is a count.
    first : bool
        Whether it is the first count (the neighbours present at the start are not encounters).
    """
    corrected, setpoint = agents.corrected, agents.setpoint
    wall_params = with_reach(params, gas.wall_reach)  # the repulsion (8), with R + R_w
    n_axes = len(box)
    walls, obstacles, pushed = gas.walls, gas.obstacles, gas.pushed  # the box's walls and obstacles, their pushes
    work, limit = gas.work, gas.limit
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


@numba.njit(cache=True, inline="always")
def limit_of(i, gas, c_max):
    """Agent ``i``'s tilt limit this step: ``c_max``, or, where the gas is observed, the limit its walls
    and thermostat set (:func:`tmem.world.walls.with_priority`, :mod:`tmem.engine.thermostat`).

    Parameters
    ----------
    i : int
        The agent's slot.
    gas : Gas
        The gas's record (``limit`` is empty when it is not observed).
    c_max : float
        The scenario's tilt limit (rad).
    """
    return gas.limit[i] if gas.observe else c_max


@numba.njit(cache=True, inline="always")
def tally(x, i, scale, work, totals, walls, obstacles, box, g_dt, dt, n_axes, sampled):
    """Add agent ``i``'s step to its totals, after its vehicle's step: the breaches at every step; at
    a count, the virial and the path, each as ``sampled`` steps of it (the walls' momentum is added
    where the walls push, :func:`gas_agent`).  Called in a parallel loop: it takes the record's
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


@numba.njit(inline="always")
def _count_every(k, gas):
    return k % gas.every == 0


@numba.njit(inline="always")
def _first_count(gas, counting):
    first = gas.first[0]
    if counting:
        gas.first[0] = False
    return first


@numba.njit(inline="always")
def _held_limit(i, gas, c_max):
    return gas.limit[i]


@numba.njit(cache=True, _nrt=False)
def _tally_step(x, i, scale, gas, box, n_axes, sampled):
    # Called, not inlined: it writes into the record's arrays from inside the vehicles' parallel
    # loop, and inlined there its writes were lost on threads (the totals stayed 0).
    tally(x, i, scale, gas.work, gas.totals, gas.walls, gas.obstacles, box, gas.g_dt, gas.dt, n_axes, sampled)


@numba.njit(inline="always")
def _never(k, gas):
    return False


@numba.njit(inline="always")
def _no_pair_count(e, agents, pairs, law, params, run, gas, counting):
    return False


@numba.njit(inline="always")
def _no_tally(x, i, scale, gas, box, n_axes, sampled):
    return False


@numba.njit(inline="always")
def _scenario_limit(i, gas, c_max):
    return c_max


#: What the loop binds for the gas's observers (:mod:`tmem.engine.loop`), observed or not: when the
#: counts are due, the count of a formation pair, an agent's tilt limit, the tally after its step,
#: and whether a count is the first.  A run without the gas's options steps its agents in a loop with
#: none of them (with their branches, the vehicles' step took a fifth longer on 3·10^4 agents).
OBSERVERS = {
    True: lambda: dict(counts_due=_count_every, count_pair=count_pair, tilt_limit=_held_limit, after_step=_tally_step,
                       first_count=_first_count),
    False: lambda: dict(counts_due=_never, count_pair=_no_pair_count, tilt_limit=_scenario_limit, after_step=_no_tally,
                        first_count=_never),
}  # fmt: skip
