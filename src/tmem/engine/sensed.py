"""The step loop's sensed path: each agent pushes from what it measures of itself and its neighbours.

With sensing effects (:mod:`tmem.world.sensing`), what agent ``i`` knows of ``j``
differs from what ``k`` knows of ``j``, so a pair's two pushes are no longer
equal and opposite: each receiver evaluates its own, from ``d = P*_other -
P*_own``, its neighbour's ``P*`` (6) as it measures it and its own as it
measures itself.  These stages take the place of
:func:`tmem.engine.pushes.neighbour_pushes` and
:func:`tmem.engine.pairs.formation_pairs` in the loop's sensed copy
(:func:`tmem.engine.loop.advance_for`); the exact path is compiled without
them, as before.

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
from tmem.law.modal import corrected_position
from tmem.law.interaction.kernels import pair_control
from tmem.world.sensing import known_axis, known_corrected, latest_message, message_of
from tmem.world.space import nearest_image
from tmem.law.synchronise import synchronising_push
from tmem.engine.pairs import check_flag, pair_push, released_if_lost, synchronise


@numba.njit(cache=True, error_model="numpy", inline="always")
def _receiver_push(k, state, corrected, receiver, sender, sensing, gains, box, function, params, w, u):
    """Add to ``u[receiver]`` the push of ``sender`` as ``receiver`` measures it; return whether it
    measured the sender within reach.  ``sensing.work[w]`` holds ``d``."""
    s = latest_message(k, receiver, sender, sensing)
    if s < 0:
        return False
    key = message_of(sensing, receiver, sender, s)
    d = sensing.work
    r2 = 0.0
    for a in range(len(box)):
        d[w, a] = nearest_image(known_corrected(state, sensing, gains, key, sender, s, a) - corrected[receiver, a, 0], box[a])
        r2 += d[w, a] * d[w, a]
    if not (r2 < params.reach * params.reach and r2 > 0.0):
        return False
    r = np.sqrt(r2)
    push = pair_control(function, r, 0, params) / r
    for a in range(len(box)):
        u[receiver, a] += push * d[w, a]
    return True


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _sensed_pushes_of(k, state, corrected, pairs, first, stop, box, function, params, gains, u, sensing, w):
    """Add to ``u`` the pushes of pairs ``first:stop`` as each agent measures them; return the smallest
    ``|P_j - P_i|^2`` of a pair one of whose agents measured the other within reach."""
    nearest2 = np.inf
    for e in range(first, stop):
        i = pairs[e, 0]
        j = pairs[e, 1]
        dist2 = 0.0
        for a in range(len(box)):
            delta = nearest_image(corrected[j, a, 1] - corrected[i, a, 1], box[a])
            dist2 += delta * delta
        if dist2 >= sensing.range2:
            continue
        i_near = _receiver_push(k, state, corrected, i, j, sensing, gains, box, function, params, w, u)
        j_near = _receiver_push(k, state, corrected, j, i, sensing, gains, box, function, params, w, u)
        if i_near or j_near:
            nearest2 = min(nearest2, dist2)
    return nearest2


@numba.njit(cache=True, error_model="numpy", inline="always")
def sensed_neighbour_pushes(k, agents, neighbours, law, params, run, sensing):
    """Every listed non-formation pair's pushes, each agent's from its own measurement (module text).

    The blocks of :func:`tmem.world.neighbors.arrange` run on threads, then the pairs between them, as in
    :func:`tmem.engine.pushes.neighbour_pushes`.

    Parameters
    ----------
    k : int
        The step.
    agents, neighbours, law, run
        The loop's records (:mod:`tmem.engine.records`); ``agents`` and ``neighbours`` change in place.
    params : FunctionParams
        The interaction functions' parameters.
    sensing : Sensing
        The measurement stage (:mod:`tmem.world.sensing`).
    """
    box = run.box
    function = law.neighbour_function
    gains = law.gains
    state = agents.state
    corrected = agents.corrected
    setpoint = agents.setpoint
    pairs = neighbours.pairs
    block_ptr = neighbours.block_ptr
    block_nearest2 = neighbours.block_nearest2
    n_blocks = block_ptr.shape[0] - 1
    for b in numba.prange(n_blocks):
        block_nearest2[b] = np.inf
        if block_ptr[b + 1] > block_ptr[b]:
            block_nearest2[b] = _sensed_pushes_of(k, state, corrected, pairs, block_ptr[b], block_ptr[b + 1], box, function,
                                                  params, gains, setpoint, sensing, b)  # fmt: skip
    nearest2 = np.inf
    if neighbours.n_pairs > neighbours.n_inside:
        nearest2 = _sensed_pushes_of(k, state, corrected, pairs, neighbours.n_inside, neighbours.n_pairs, box, function,
                                     params, gains, setpoint, sensing, n_blocks)  # fmt: skip
    for b in range(n_blocks):
        nearest2 = min(nearest2, block_nearest2[b])
    neighbours.closest[0] = min(neighbours.closest[0], nearest2)


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
    key = message_of(sensing, receiver, partner, s)
    states = sensing.pair_states
    r2 = 0.0
    for a in range(len(box)):
        p, v, phi, omega = known_axis(state, sensing, key, partner, s, a)
        states[1 - own_row, a, 0] = p
        states[1 - own_row, a, 1] = v
        states[1 - own_row, a, 2] = phi
        states[1 - own_row, a, 3] = omega
        for m in range(4):
            states[own_row, a, m] = sensing.own[receiver, a, m]
        star_i = corrected_position(states[0, a, 0], states[0, a, 1], states[0, a, 2], states[0, a, 3], law.gains, i)
        star_j = corrected_position(states[1, a, 0], states[1, a, 1], states[1, a, 2], states[1, a, 3], law.gains, j)
        d[a] = nearest_image(star_j - star_i, box[a])
        r2 += d[a] * d[a]
    return np.sqrt(r2)


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def sensed_formation_pair(k, e, agents, pairs, law, params, box, events, counters, sensing):
    """Formation pair ``e`` at step ``k``, each agent from its own measurement (module text): the first
    agent checks the flag ``F_en`` ((9), or the energy match) and pushes, then its partner pushes;
    each synchronises (S2) from its own view, the pair's ``E*`` set by the first.

    Parameters
    ----------
    k, e : int
        The step and the pair.
    agents, pairs, law, events, counters
        The loop's records (:mod:`tmem.engine.records`); all but ``law`` change in place.
    params : FunctionParams
        The interaction functions' parameters; each pair's own ``d_t`` replaces the scenario's.
    box : tuple of float
        The box sides (0: open axis).
    sensing : Sensing
        The measurement stage (:mod:`tmem.world.sensing`).
    """
    if released_if_lost(k, e, agents, pairs, events, counters):
        return
    n_axes = len(box)
    i = pairs.i[e]
    j = pairs.j[e]
    d, states, pushes, u = pairs.d, sensing.pair_states, sensing.pushes, agents.setpoint
    dist2 = 0.0
    for a in range(n_axes):
        delta = nearest_image(agents.corrected[j, a, 1] - agents.corrected[i, a, 1], box[a])
        dist2 += delta * delta
    dist = np.sqrt(dist2)
    pairs.min_distance[e] = min(pairs.min_distance[e], dist)
    in_range = dist2 < sensing.range2
    r = _pair_view(k, e, i, agents.state, pairs, law, sensing, box, d) if in_range else np.nan
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
    r = _pair_view(k, e, j, agents.state, pairs, law, sensing, box, d) if in_range else np.nan
    if not np.isnan(r):
        pair_push(e, d, r, pairs, law, params, n_axes)
        for a in range(n_axes):
            u[j, a] -= d[a]
            pushes[0, a] = pushes[1, a] = 0.0
        if law.sync_gain > 0.0 and not np.isnan(pairs.kept_speed2[e]):
            synchronising_push(states, 0, 1, law.sync_gain, pairs.flag[e] == 1, pairs.kept_speed2[e], d, params.c_max,
                               n_axes, pushes)  # fmt: skip
            for a in range(n_axes):
                u[j, a] += pushes[1, a]


@numba.njit(cache=True, error_model="numpy", inline="always")
def sensed_formation_pairs(k, agents, pairs, law, params, run, events, counters, sensing):
    """Every formation pair's step from its agents' measurements, :func:`sensed_formation_pair`, in order.

    Parameters
    ----------
    k : int
        The step.
    agents, pairs, law, run, events, counters
        The loop's records (:mod:`tmem.engine.records`); all but ``law`` and ``run`` change in place.
    params : FunctionParams
        The interaction functions' parameters.
    sensing : Sensing
        The measurement stage (:mod:`tmem.world.sensing`).
    """
    for e in range(pairs.i.shape[0]):
        sensed_formation_pair(k, e, agents, pairs, law, params, run.box, events, counters, sensing)
