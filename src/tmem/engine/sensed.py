"""The pair terms under sensed knowledge: each agent pushes from what it measures of itself and its neighbours.

With sensing effects (:mod:`tmem.world.sensing`), what agent ``i`` knows of ``j``
differs from what ``k`` knows of ``j``, so a pair's two pushes are no longer
equal and opposite: each receiver evaluates its own, from ``d = P*_other -
P*_own``, its neighbour's ``P*`` (6) as it measures it and its own as it
measures itself.  These are the sensed knowledge's ``pair_pass`` and
``formation_pair`` (:mod:`tmem.engine.knowledge`); the pair law itself, the
flag, the pull and the synchronisation, is the exact knowledge's
(:mod:`tmem.engine.pairs`).

* **Neighbours** (8): a pair within the sensing range (true distance of the
  positions ``P``) gives each of its agents the push of the function at the
  ``|d|`` that agent measures, if it holds a message of the other
  (:func:`tmem.world.sensing.latest_message`).  Pairs are visited in the loop's
  order and each agent adds its pushes in that order, so threads and the kind
  of list do not change the bits.
* **Formation pairs** (9)-(11): the flag ``F_en`` is the pair's; its first
  agent (the lower-numbered) checks it from its own measurement, and its
  partner acts on it at once.  Each agent pushes, and synchronises (S2), from
  its own measurement.  A pair's recorded ``|d|`` is its first agent's.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.engine.pairs import check_flag, pair_distance2, pair_push, released_if_lost, synchronise
from tmem.law.interaction.kernels import pair_control
from tmem.law.modal import corrected_position, gains_row
from tmem.law.synchronise import synchronising_push
from tmem.world.sensing import known_state, latest_message, message_of
from tmem.world.space import nearest_image


@numba.njit(cache=True, error_model="numpy", inline="always")
def _receiver_push(k, state, corrected, receiver, sender, sensing, gains, box, function, params, w, u):
    """Add to ``u[receiver]`` the push of ``sender`` as ``receiver`` measures it; return whether it
    measured the sender within reach.  ``sensing.seen[w]`` holds the sender's state, ``sensing.work[w]`` ``d``."""
    s = latest_message(k, receiver, sender, sensing)
    if s < 0:
        return False
    known_state(state, sensing, message_of(sensing, receiver, sender, s), sender, s, sensing.seen, w)
    d = sensing.work
    row = gains_row(gains, sender)
    r2 = 0.0
    for a in range(len(box)):
        d[w, a] = nearest_image(corrected_position(sensing.seen, w, a, gains, row) - corrected[receiver, a, 0], box[a])
        r2 += d[w, a] * d[w, a]
    if not (r2 < params.reach * params.reach and r2 > 0.0):
        return False
    r = np.sqrt(r2)
    push = pair_control(function, r, 0, params) / r
    for a in range(len(box)):
        u[receiver, a] += push * d[w, a]
    return True


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def pair_pass(k, first, stop, w, agents, neighbours, law, params, box, knowledge, gas, counting):
    """Add the pushes of the listed pairs ``first:stop``, each agent's from its own measurement (module
    text); return the smallest ``|P_j - P_i|^2`` of a pair one of whose agents measured the other
    within reach.  The sensed knowledge's ``pair_pass`` (:mod:`tmem.engine.knowledge`).

    Parameters
    ----------
    k : int
        The step.
    first, stop : int
        The listed pairs ``neighbours.pairs[first:stop]``.
    w : int
        The row of the work space this call works in (its block's).
    agents, neighbours, law
        The loop's records (:mod:`tmem.engine.records`); ``agents.setpoint`` changes in place.
    params : FunctionParams
        The interaction functions' parameters.
    box : tuple of float
        The periodic box's sides (0: open axis).
    knowledge : Sensing
        The measurement stage (:mod:`tmem.world.sensing`).
    gas, counting
        Unused: the gas is observed only under exact knowledge.
    """
    state, corrected, u = agents.state, agents.corrected, agents.setpoint
    pairs, function, gains = neighbours.pairs, law.neighbour_function, law.gains
    nearest2 = np.inf
    for e in range(first, stop):
        i = pairs[e, 0]
        j = pairs[e, 1]
        dist2 = 0.0
        for a in range(len(box)):
            delta = nearest_image(corrected[j, a, 1] - corrected[i, a, 1], box[a])
            dist2 += delta * delta
        if dist2 >= knowledge.range2:
            continue
        i_near = _receiver_push(k, state, corrected, i, j, knowledge, gains, box, function, params, w, u)
        j_near = _receiver_push(k, state, corrected, j, i, knowledge, gains, box, function, params, w, u)
        if i_near or j_near:
            nearest2 = min(nearest2, dist2)
    return nearest2


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _pair_view(k, e, receiver, state, pairs, law, sensing, box, d):
    """Pair ``e`` as ``receiver`` (one of its agents) knows it: its two states in ``sensing.pair_states``
    (row 0 agent ``i``, row 1 agent ``j``) and ``d = P*_j - P*_i``; returns ``|d|``, NaN when the
    receiver holds no message of its partner."""
    i = pairs.i[e]
    j = pairs.j[e]
    partner = j if receiver == i else i
    own_row = 0 if receiver == i else 1
    s = latest_message(k, receiver, partner, sensing)
    if s < 0:
        return np.nan
    states = sensing.pair_states
    known_state(state, sensing, message_of(sensing, receiver, partner, s), partner, s, states, 1 - own_row)
    r2 = 0.0
    for a in range(len(box)):
        for m in range(states.shape[2]):
            states[own_row, a, m] = sensing.own[receiver, a, m]
        star_i = corrected_position(states, 0, a, law.gains, gains_row(law.gains, i))
        star_j = corrected_position(states, 1, a, law.gains, gains_row(law.gains, j))
        d[a] = nearest_image(star_j - star_i, box[a])
        r2 += d[a] * d[a]
    return np.sqrt(r2)


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def formation_pair(k, e, known, agents, pairs, law, params, run, events, counters, knowledge):
    """Formation pair ``e`` at step ``k``, each agent from its own measurement (module text): the first
    agent checks the flag ``F_en`` ((9), or the energy match) and pushes, then its partner pushes;
    each synchronises (S2) from its own view, the pair's ``E*`` set by the first.  The sensed
    knowledge's ``formation_pair`` (:mod:`tmem.engine.knowledge`).

    Parameters
    ----------
    k, e : int
        The step and the pair.
    known : ndarray
        Unused: each agent's view is read from its messages.
    agents, pairs, law, run, events, counters
        The loop's records (:mod:`tmem.engine.records`); all but ``law`` and ``run`` change in place.
    params : FunctionParams
        The interaction functions' parameters; each pair's own ``d_t`` replaces the scenario's.
    knowledge : Sensing
        The measurement stage (:mod:`tmem.world.sensing`).
    """
    if released_if_lost(k, e, agents, pairs, events, counters):
        return
    box = run.box
    n_axes = len(box)
    i = pairs.i[e]
    j = pairs.j[e]
    d, states, pushes, u = pairs.d, knowledge.pair_states, knowledge.pushes, agents.setpoint
    dist2 = pair_distance2(agents.corrected, i, j, box)
    dist = np.sqrt(dist2)
    pairs.min_distance[e] = min(pairs.min_distance[e], dist)
    in_range = dist2 < knowledge.range2
    r = _pair_view(k, e, i, agents.state, pairs, law, knowledge, box, d) if in_range else np.nan
    if np.isnan(r):
        pairs.r_before[e] = np.nan  # no check, the flag held: the first agent does not measure its partner
    else:
        entering = check_flag(k, e, r, d, states, 0, 1, pairs, law, params, n_axes, events, counters)
        pair_push(e, d, r, pairs, law, params, n_axes)
        for a in range(n_axes):
            u[i, a] += d[a]
            pushes[0, a] = pushes[1, a] = 0.0
        if law.sync_gain > 0.0:
            synchronise(e, 0, 1, r, dist, entering, d, states, pairs, law, params, n_axes, pushes)
            for a in range(n_axes):
                u[i, a] += pushes[0, a]
    r = _pair_view(k, e, j, agents.state, pairs, law, knowledge, box, d) if in_range else np.nan
    if not np.isnan(r):
        pair_push(e, d, r, pairs, law, params, n_axes)
        for a in range(n_axes):
            u[j, a] -= d[a]
            pushes[0, a] = pushes[1, a] = 0.0
        if law.sync_gain > 0.0 and not np.isnan(pairs.kept_speed2[e]):
            synchronising_push(states, 0, 1, law.sync_gain, pairs.flag[e] == 1, pairs.kept_speed2[e], law.keep_energy, d, params.c_max,
                               n_axes, pushes)  # fmt: skip
            for a in range(n_axes):
                u[j, a] += pushes[1, a]
