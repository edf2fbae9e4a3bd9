"""The stages of one step that every variant shares: commands, ``P*`` (6) and the record.

Every stage is a Numba function inlined into the loop (:mod:`tmem.engine.loop`) except the
carrying out of commands, which is rare, and works on the records of :mod:`tmem.engine.records`
in place.  Nothing is allocated at a step: the work space comes in the records.

* :func:`apply_commands` — operator commands due at the step (:func:`commands_due`);
* :func:`corrected_positions` — ``P*`` (6) of every agent, and how far the lists have drifted;
* :func:`record` — the recorded step, with the set-points as the vehicles take them.

The stages that vary between runs are the knowledge's (:mod:`tmem.engine.knowledge`), the agent
terms' (:mod:`tmem.engine.terms`), the gas's observers (:mod:`tmem.engine.gas`) and the vehicle's.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law import coupling
from tmem.law.modal import corrected_position, gains_row, tilt_scale
from tmem.world.space import nearest_image
from tmem.engine.gas import limit_of, record_totals
from tmem.engine.gas_counts import clear
from tmem.engine.records import ADD, COUPLE, REMOVE, RESHAPE, TEMPERATURE, UNCOUPLE

@numba.njit(cache=True, inline="always")
def log_event(events, counters, k, kind, i, j, action, rule):
    """Append an event at step ``k`` (agents as slots, -1 for none; action and rule -1 for none).

    Parameters
    ----------
    events, counters
        The loop's records (:mod:`tmem.engine.records`), changed in place.
    k : int
        The step.
    kind : int
        Event kind (:data:`tmem.law.coupling.EVENT_KINDS`).
    i, j : int
        Slots of the agents, -1 for none.
    action : int
        Command code (:data:`tmem.engine.records.COMMANDS`), -1 for none.
    rule : int
        What released a pair (:data:`tmem.law.coupling.RELEASES`), -1 for none.
    """
    n = counters.n_events[0]
    events.step[n] = k
    events.kind[n] = kind
    events.i[n] = i
    events.j[n] = j
    events.action[n] = action
    events.rule[n] = rule
    counters.n_events[0] = n + 1


@numba.njit(cache=True, inline="always")
def commands_due(k, commands, counters):
    """Whether a command is due at step ``k`` (the check the loop makes at every step).

    Parameters
    ----------
    k : int
        The step.
    commands, counters
        The loop's records (:mod:`tmem.engine.records`).
    """
    c = counters.next_command[0]
    return c < commands.step.shape[0] and commands.step[c] <= k


@numba.njit(cache=True, inline="always")
def command_pair(k, e, kind, pairs):
    """A couple or uncouple command to formation pair ``e`` at step ``k``: arm or disarm it
    (:mod:`tmem.law.coupling`); an uncouple command also starts the energy rule's fallback time.

    Parameters
    ----------
    k : int
        The step.
    e : int
        The pair.
    kind : int
        ``COUPLE`` or ``UNCOUPLE`` (:data:`tmem.engine.records.COMMANDS`).
    pairs : Pairs
        The formation pairs, changed in place.
    """
    pairs.armed[e] = 1 if kind == COUPLE else 0
    if kind == UNCOUPLE:
        pairs.disarmed_at[e] = k  # the energy rule's fallback counts from here


@numba.njit(cache=True)
def reshape(k, members, direction, pairs, events, counters):
    """A mission's change of shape at step ``k``: the pairs ``members`` (indices) couple now, armed, as pairs
    that start coupled do (their energy rule's record and their synchronisation start afresh), each to
    hold its row of ``direction`` (NaN: a distance only); every other pair lets go now, disarmed, and
    pushes as an uncoupled pair (10)/(11).  Each change of flag is an event (an uncoupling's rule: ``reshape``).

    Parameters
    ----------
    k : int
        The step.
    members : ndarray of int
        The new shape's pairs.
    direction : ndarray, shape (members, axes)
        The unit direction each holds from ``i`` to ``j`` (NaN rows: none).
    pairs, events, counters
        The loop's records, changed in place.
    """
    for e in range(pairs.armed.shape[0]):
        pairs.armed[e] = 0
    for m in range(members.shape[0]):
        pairs.armed[members[m]] = 1
        for a in range(direction.shape[1]):
            pairs.direction[members[m], a] = direction[m, a]
    for e in range(pairs.armed.shape[0]):  # coupled where armed, an event at each change
        if pairs.armed[e] != pairs.flag[e]:
            kind = coupling.EVENT_COUPLE if pairs.armed[e] == 1 else coupling.EVENT_UNCOUPLE
            rule = -1 if pairs.armed[e] == 1 else coupling.RELEASE_RESHAPE
            log_event(events, counters, k, kind, pairs.i[e], pairs.j[e], -1, rule)
        pairs.flag[e] = pairs.armed[e]
        pairs.disarmed_at[e] = k
        pairs.coupled_gap[e] = np.nan
        pairs.coupled_energy[e] = np.nan
        pairs.kept_speed2[e] = np.nan


@numba.njit(cache=True)
def apply_commands(k, commands, agents, pairs, events, counters, gas):
    """Carry out the commands due at step ``k``; return whether the neighbour lists must be rebuilt.

    Commands are rare: the loop calls this only when :func:`commands_due`, and it is not inlined.
    Inlined, its code slowed every step of a two-agent run by a quarter.

    ``couple`` / ``uncouple`` arm or disarm pairs (:mod:`tmem.law.coupling`); ``remove`` stops an agent
    where it is (a lost vehicle), ``add`` puts it back at its start; ``temperature`` sets the
    thermostat's RMS velocity (:mod:`tmem.engine.gas`); ``reshape``, a mission's, sets which pairs are
    coupled (:func:`reshape`).

    Parameters
    ----------
    k : int
        The step.
    commands, agents, pairs, events, counters, gas
        The loop's records (:mod:`tmem.engine.records`); all but ``commands`` change in place.
    """
    rebuild = False
    while commands_due(k, commands, counters):
        c = counters.next_command[0]
        kind = commands.kind[c]
        first = commands.ptr[c]
        if kind == REMOVE or kind == ADD:
            i = commands.target[first]
            agents.active[i] = kind == ADD
            rebuild = True  # the pairs listed are those of flying agents
            if kind == ADD:
                for a in range(agents.state.shape[1]):
                    for m in range(agents.state.shape[2]):
                        agents.state[i, a, m] = agents.start[i, a, m]
                for m in range(agents.body.shape[1]):
                    agents.body[i, m] = agents.body_start[i, m]
                if gas.observe:  # what its last count set is stale: it starts as a free agent
                    gas.weight[i] = 1.0
                    gas.near_before[i] = 0.0
                    for c in range(gas.held.shape[1]):
                        gas.held[i, c] = 0.0
            else:
                agents.state[i, :, 1:] = 0.0
            log_event(events, counters, k, coupling.EVENT_COMMAND, i, -1, kind, -1)
        elif kind == RESHAPE:
            log_event(events, counters, k, coupling.EVENT_COMMAND, -1, -1, kind, -1)
            last = commands.ptr[c + 1]
            reshape(k, commands.target[first:last], commands.direction[first:last], pairs, events, counters)
        elif kind == TEMPERATURE:
            gas.target2[0] = commands.value[c] * commands.value[c]
            log_event(events, counters, k, coupling.EVENT_COMMAND, -1, -1, kind, -1)
        else:
            every = first == commands.ptr[c + 1]
            for t in range(pairs.armed.shape[0] if every else commands.ptr[c + 1] - first):
                e = t if every else commands.target[first + t]
                command_pair(k, e, kind, pairs)
            single = commands.ptr[c + 1] - first == 1
            i = pairs.i[commands.target[first]] if single else -1
            j = pairs.j[commands.target[first]] if single else -1
            log_event(events, counters, k, coupling.EVENT_COMMAND, i, j, kind, -1)
        counters.next_command[0] = c + 1
    return rebuild


@numba.njit(cache=True, error_model="numpy", inline="always")
def corrected_positions(known, agents, law, run, neighbours, gas, listed, counting):
    """``P* = x . K / K_P`` (6) of every agent as it knows itself, and its true ``P``, into
    ``agents.corrected``; clear the set-points (and, at a count of the gas, its counts:
    :func:`tmem.engine.gas_counts.clear`).

    Returns the largest squared shift of a flying agent's listed point (``P*``, or ``P`` with sensing)
    since the lists were built (0 without lists).

    Parameters
    ----------
    known : ndarray, shape (agents, axes, n_state)
        Each agent's own state as it measures it (:func:`tmem.world.sensing.measure`; the true states when
        exact).
    agents, law, run, neighbours, gas
        The loop's records (:mod:`tmem.engine.records`); ``agents`` and ``gas`` change in place.
    listed : int
        What the lists hold: 0, ``P*`` (the exact path), or 1, ``P`` (the sensed path, whose range
        is one of positions).
    counting : bool
        Whether the step is a count of the gas (:attr:`tmem.engine.records.Gas.every`): never when
        the gas is not observed.
    """
    box = run.box
    work = gas.work
    n_axes = len(box)
    use_lists = run.use_lists
    gains = law.gains
    state = agents.state
    corrected = agents.corrected
    setpoint = agents.setpoint
    active = agents.active
    p_ref = neighbours.p_ref
    block_shift2 = neighbours.block_shift2
    n_agents = known.shape[0]
    n_blocks = block_shift2.shape[0]
    per_block = (n_agents + n_blocks - 1) // n_blocks
    for b in numba.prange(n_blocks):  # each block's largest shift: a parallel reduction would allocate
        largest = 0.0
        for i in range(b * per_block, min(n_agents, (b + 1) * per_block)):
            row = gains_row(gains, i)
            shift2 = 0.0
            for a in range(n_axes):
                star = corrected_position(known, i, a, gains, row)
                position = known[i, a, 0] if listed == 0 else state[i, a, 0]  # exact path: known is the state
                corrected[i, a, 0] = star
                corrected[i, a, 1] = position
                setpoint[i, a] = 0.0  # the sum of pushes starts here
                if use_lists:
                    delta = nearest_image((star if listed == 0 else position) - p_ref[i, a], box[a])
                    shift2 += delta * delta
            if counting:
                clear(i, known, work, n_axes)
            if active[i]:
                largest = max(largest, shift2)
        block_shift2[b] = largest
    moved = 0.0
    for b in range(n_blocks):
        moved = max(moved, block_shift2[b])
    return moved


@numba.njit(cache=True, inline="always")
def is_recorded(k, run):
    """Whether step ``k`` is recorded: a multiple of ``record_every``, and the last step.

    Parameters
    ----------
    k : int
        The step.
    run : Run
        What stays fixed over the run.
    """
    return run.record_every > 0 and (k % run.record_every == 0 or k == run.n_steps)


@numba.njit(cache=True, error_model="numpy", inline="always")
def record(agents, pairs, records, c_max, run, counters, gas, sensed):
    """Record the step, before the vehicles move, with the saturated set-point applied over it.

    Parameters
    ----------
    agents, pairs, records, run, counters, gas
        The loop's records (:mod:`tmem.engine.records`); ``records`` and ``counters`` change in place.
    c_max : float
        Tilt limit (rad).
    sensed : bool
        The sensed path: a pair's ``|d|`` is the one its first agent measured (``pairs.r_before``;
        NaN where it measured none), not the one of the true states.
    """
    n_axes = len(run.box)
    q_record = counters.next_record[0]
    for q in range(records.slots.shape[0]):
        i = records.slots[q]
        for a in range(n_axes):
            for m in range(agents.state.shape[2]):
                records.state[q_record, q, a, m] = agents.state[i, a, m]
        for m in range(agents.body.shape[1]):
            records.body[q_record, q, m] = agents.body[i, m]
        records.active[q_record, q] = agents.active[i]
        scale = tilt_scale(agents.setpoint, i, n_axes, limit_of(i, gas, c_max)) if agents.active[i] else 0.0
        for a in range(n_axes):
            records.control[q_record, q, a] = agents.setpoint[i, a] * scale
    for e in range(pairs.i.shape[0]):
        records.flag[q_record, e] = pairs.flag[e]
        dist2 = 0.0
        r2 = 0.0
        for a in range(n_axes):
            delta = nearest_image(agents.state[pairs.j[e], a, 0] - agents.state[pairs.i[e], a, 0], run.box[a])
            dist2 += delta * delta
            delta = nearest_image(agents.corrected[pairs.j[e], a, 0] - agents.corrected[pairs.i[e], a, 0], run.box[a])
            r2 += delta * delta
        records.distance[q_record, e] = np.sqrt(dist2)
        records.measure[q_record, e] = pairs.r_before[e] if sensed else np.sqrt(r2)
    record_totals(agents, gas, records, q_record, n_axes)
    counters.next_record[0] = q_record + 1
