"""The compiled update of one agent's controller: the step loop's stages, run for one agent.

An :class:`~tmem.agent.controller.AgentController` keeps its agent's view of
the swarm as the engine's records (:mod:`tmem.engine.records`) of a small
swarm: row 0 is its own agent, row ``e + 1`` the neighbour of its ``e``-th
formation edge, and its edges are formation pairs ``(i, j)`` with ``i`` the
lower id, the orientation the engine gives them.  :func:`control` runs, for
that one agent, what the step loop runs for every agent:

1. ``P*`` (6) of the agent (:func:`tmem.law.modal.corrected_position`);
2. the pushes of the other neighbours, (8) or the scenario's function, each
   ``f(|d|) d / |d|`` (:func:`tmem.law.interaction.kernels.push_factor`), added in
   the order given;
3. each formation pair heard from: its flag ``F_en`` ((9), or the energy
   rule), its pull or push (10)/(11), its synchronisation (S2), by the
   engine's own :func:`tmem.engine.pairs.formation_pair`;
4. the sum saturated on its norm, ``|U| <= c_max`` (:func:`tmem.law.modal.tilt_scale`).

The sums run in the engine's order: the neighbours' pushes first, in the
order of the engine's numbering of the agents, then the formation pairs by
increasing id.  ``d`` is taken from the agent to its neighbour: for the pair's
second agent the engine takes it the other way and subtracts the push, and
``x - y * f`` is ``x + (-y) * f`` to the bit, so each agent's sum is the
engine's.

The law travels to the compiled code as its records (:class:`tmem.law.record.Law`,
:class:`tmem.law.interaction.kernels.FunctionParams`); the edges' and the events' records travel
as a few arrays and are rebuilt there (:func:`pairs_from`, :func:`events_from`): passed from
Python, a record of fourteen arrays cost 3 us per call to unpack, its three tables 1 us, and an
update is called for every agent at every step.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law.modal import corrected_position, tilt_scale
from tmem.engine.pairs import formation_pair
from tmem.engine.records import Agents, Counters, Events, Pairs
from tmem.law.interaction.kernels import FunctionParams, push_factor

#: The rows of the edges' tables: the integer and the real columns of :class:`tmem.engine.records.Pairs`.
PAIR_INTS = ("i", "j", "flag", "armed", "disarmed_at")
PAIR_FLOATS = ("d_t", "r_before", "min_distance", "coupled_gap", "coupled_energy", "entry_speed2", "kept_speed2")


@numba.njit(cache=True, inline="always")
def pairs_from(ints, floats, direction, d):
    """The :class:`~tmem.engine.records.Pairs` whose columns are the rows of ``ints`` and ``floats``
    (views: a change to one is a change to the other).  Called from Python too (``.py_func``).

    Parameters
    ----------
    ints : ndarray, shape (5, edges), int
        The rows :data:`PAIR_INTS`.
    floats : ndarray, shape (7, edges)
        The rows :data:`PAIR_FLOATS`.
    direction : ndarray, shape (edges, axes)
        Each pair's direction to hold from ``i`` to ``j`` (NaN rows: none).
    d : ndarray, shape (axes,)
        Work space.
    """
    return Pairs(ints[0], ints[1], floats[0], direction, ints[2], ints[3], floats[1], floats[2], floats[3], floats[4],
                 floats[5], floats[6], ints[4], d)  # fmt: skip


@numba.njit(cache=True, inline="always")
def events_from(table, counts):
    """The :class:`~tmem.engine.records.Events` in the rows of ``table`` and the
    :class:`~tmem.engine.records.Counters` in ``counts`` (views).  Called from Python too (``.py_func``).

    Parameters
    ----------
    table : ndarray, shape (6, capacity), int
        One row per field of ``Events``.
    counts : ndarray, shape (4,), int
        One entry per field of ``Counters``.
    """
    events = Events(table[0], table[1], table[2], table[3], table[4], table[5])
    return events, Counters(counts[0:1], counts[1:2], counts[2:3], counts[3:4])


@numba.njit(cache=True, error_model="numpy")
def message_vectors(own, gains, out):
    """What an agent broadcasts of its state into the rows of ``out``: ``P* = x . K / K_P`` (6), as the
    engine computes it, ``P`` and ``V``, on each axis.

    Parameters
    ----------
    own : ndarray, shape (1, axes, n_state)
        The agent's state, ``(P, V, phi, omega)`` first.
    gains : ndarray, shape (1, 4)
        The agent's ``K``.
    out : ndarray, shape (3, axes)
        Filled with ``P*`` (m), ``P`` (m) and ``V`` (m/s).
    """
    for a in range(own.shape[1]):
        out[0, a] = corrected_position(own, 0, a, gains, 0)
        out[1, a] = own[0, a, 0]
        out[2, a] = own[0, a, 1]


@numba.njit(cache=True, error_model="numpy")
def control(k, own, law, params, inbox, known, active, corrected, setpoint, pair_ints, pair_floats, direction, d, heard,
            others, event_table, counts, box, out):  # fmt: skip
    """One update of one agent at step ``k``: its saturated tilt set-point into ``out`` (see the module text).

    Parameters
    ----------
    k : int
        The step (the update's tick).
    own : ndarray, shape (axes, n_state)
        The agent's own state.
    law : Law
        The TMEM law (:func:`tmem.law.record.law_record`), the agent's gains in its one row.
    params : FunctionParams
        The interaction functions' parameters.
    inbox : ndarray, shape (neighbours + 1, 3, axes)
        Row ``e + 1``: ``P*``, ``P`` and ``V`` of the last message of the ``e``-th formation neighbour.
    known, active, corrected, setpoint : ndarray
        The fields of the agent's :class:`~tmem.engine.records.Agents`, row 0 itself, then its
        formation neighbours (``known`` and ``corrected`` filled here from ``inbox``; ``active``:
        whether each flies).
    pair_ints, pair_floats, direction, d : ndarray
        The edges (:func:`pairs_from`), changed in place.
    heard : ndarray, shape (edges,), bool
        Whether each formation neighbour's message came with this update; an edge not heard from
        is left as it is and pushes nothing.
    others : ndarray, shape (senders, axes)
        ``P*`` of the other flying neighbours, in the order their pushes are added.
    event_table, counts : ndarray
        The events logged (:func:`events_from`).
    box : tuple of float
        Zeros, one per axis (open space).
    out : ndarray, shape (axes,)
        Filled with ``U`` (rad), ``|U| <= c_max``.
    """
    no_body = setpoint[:, :0]  # the pair rules read no body state: a view with no columns, nothing allocated
    agents = Agents(known, known, active, corrected, setpoint, no_body, no_body)
    pairs = pairs_from(pair_ints, pair_floats, direction, d)
    events, counters = events_from(event_table, counts)
    n_axes = len(box)
    for a in range(n_axes):
        for m in range(known.shape[2]):  # (P, V, phi, omega): what the law reads of a state
            known[0, a, m] = own[a, m]
        corrected[0, a, 0] = corrected_position(known, 0, a, law.gains, 0)
        corrected[0, a, 1] = own[a, 0]
        setpoint[0, a] = 0.0
        for row in range(1, inbox.shape[0]):
            if heard[row - 1]:
                corrected[row, a, 0] = inbox[row, 0, a]
                corrected[row, a, 1] = inbox[row, 1, a]
                known[row, a, 0] = inbox[row, 1, a]
                known[row, a, 1] = inbox[row, 2, a]
    for q in range(others.shape[0]):
        r2 = 0.0
        for a in range(n_axes):
            d[a] = others[q, a] - corrected[0, a, 0]
            r2 += d[a] * d[a]
        push = push_factor(law.neighbour_function, r2, params)
        for a in range(n_axes):
            setpoint[0, a] += d[a] * push
    for e in range(heard.shape[0]):
        if heard[e]:
            formation_pair(k, e, known, agents, pairs, law, params, box, events, counters)
    scale = tilt_scale(setpoint, 0, n_axes, params.c_max)
    for a in range(n_axes):
        out[a] = setpoint[0, a] * scale
