"""The formation pairs' law: each pair's flag ``F_en`` (9), its pull or push (10)/(11), its synchronisation.

A pair couples and uncouples by :mod:`tmem.law.coupling`: at the window (9), and,
with ``interaction.uncouple_when = "energy"``, uncouples where its relative
kinetic energy and ``f1 - f2`` match their values at coupling.  While coupled
it may also synchronise its agents' speeds (:mod:`tmem.law.synchronise`, (S2)).
:func:`formation_pair` is the law of one pair under exact knowledge (the step loop's, the batch's
and the per-agent controller's); the sensed knowledge (:mod:`tmem.engine.sensed`) runs the same
rules from each agent's own view.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem.law import coupling
from tmem.law.interaction.kernels import pair_control, with_d_t
from tmem.world.space import nearest_image
from tmem.law.synchronise import KEPT_TOLERANCE, mean_square_speed, synchronising_push
from tmem.engine.stages import log_event


@numba.njit(cache=True, error_model="numpy", inline="always")
def pair_distance2(corrected, i, j, box):
    """``|P_j - P_i|^2`` of agents ``i`` and ``j`` (nearest images), from ``corrected``'s true positions.

    Parameters
    ----------
    corrected : ndarray, shape (agents, axes, 2)
        ``(P*, P)`` of each agent on each axis (:class:`tmem.engine.records.Agents`).
    i, j : int
        The agents.
    box : tuple of float
        The box sides (0: open axis).
    """
    dist2 = 0.0
    for a in range(len(box)):
        delta = nearest_image(corrected[j, a, 1] - corrected[i, a, 1], box[a])
        dist2 += delta * delta
    return dist2


@numba.njit(cache=True, error_model="numpy", inline="always")
def _pair_geometry(corrected, e, pairs, box, d):
    """``d = P*_j - P*_i`` of pair ``e`` into ``d``; return ``(|d|, |P_j - P_i|)`` (nearest images)."""
    i = pairs.i[e]
    j = pairs.j[e]
    r2 = 0.0
    for a in range(len(box)):
        d[a] = nearest_image(corrected[j, a, 0] - corrected[i, a, 0], box[a])
        r2 += d[a] * d[a]
    return np.sqrt(r2), np.sqrt(pair_distance2(corrected, i, j, box))


@numba.njit(cache=True, error_model="numpy", inline="always")
def _next_flag(k, e, r, energy, pairs, law, params):
    """Pair ``e``'s flag after step ``k``'s check, and the rule that released it (-1: none).

    Under the energy rule, at coupling the pair records ``f1 - f2`` and its relative kinetic energy
    ``energy`` (a pair that starts coupled records them at its first step); a disarmed, coupled pair lets go
    by (9), or by the energy match with its fallback on (9) (:mod:`tmem.law.coupling`).
    """
    flag = pairs.flag[e]
    p = with_d_t(params, pairs.d_t[e])
    window = coupling.next_flag(flag, pairs.armed[e], pairs.r_before[e], r, pairs.d_t[e], law.eps, law.at_crossing)
    energy_rule = law.uncouple_rule == coupling.UNCOUPLE_BY_ENERGY
    if energy_rule and (flag == 1 and np.isnan(pairs.coupled_energy[e]) or flag == 0 and window == 1):
        pairs.coupled_gap[e] = coupling.function_gap(law.function, r, p)
        pairs.coupled_energy[e] = energy
    if flag == 0 or pairs.armed[e]:
        return window, -1
    if not energy_rule:
        return window, coupling.RELEASE_WINDOW if window == 0 else -1
    gap_before = coupling.function_gap(law.function, pairs.r_before[e], p)
    gap = coupling.function_gap(law.function, r, p)
    if coupling.energy_matched(gap_before, gap, pairs.coupled_gap[e], energy, pairs.coupled_energy[e], law.energy_tolerance):
        return 0, coupling.RELEASE_ENERGY
    if window == 0 and k - pairs.disarmed_at[e] >= law.fallback_steps:
        return 0, coupling.RELEASE_FALLBACK
    return 1, -1


@numba.njit(cache=True, error_model="numpy", inline="always")
def pair_push(e, d, r, pairs, law, params, n_axes):
    """Pair ``e``'s push on its agent ``i``, in place of ``d = P*_j - P*_i`` (``|d| = r``): (10)/(11) along
    ``d / |d|``, or, while coupled with a direction to hold ``b``, the vector spring ``K_P (d - d_t b)``
    saturated on its norm.  Agent ``j``'s push is its opposite.

    Parameters
    ----------
    e : int
        The pair.
    d : ndarray, shape (axes,)
        ``P*_j - P*_i`` on entry, the push on ``i`` (rad) on return.
    r : float
        ``|d|`` (m).
    pairs, law
        The loop's records (:mod:`tmem.engine.records`).
    params : FunctionParams
        The interaction functions' parameters; the pair's own ``d_t`` replaces the scenario's.
    n_axes : int
    """
    if pairs.flag[e] == 1 and not np.isnan(pairs.direction[e, 0]):
        norm2 = 0.0
        for a in range(n_axes):
            d[a] = params.k_p * (d[a] - pairs.direction[e, a] * pairs.d_t[e])
            norm2 += d[a] * d[a]
        push = min(1.0, params.c_max / np.sqrt(norm2)) if norm2 > 0.0 else 0.0
    else:
        p = with_d_t(params, pairs.d_t[e])
        push = pair_control(law.function, r, pairs.flag[e], p) / r if r > 0.0 else 0.0
    for a in range(n_axes):
        d[a] *= push


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def synchronise(e, i, j, r, dist, entering, pushed, known, pairs, law, params, n_axes, u):
    """(S2) on pair ``e``: from its coupling, its relative motion damped and its mean square speed held
    at its value when it came within reach; after it uncouples, the speed alone, until it is out of
    reach again (:mod:`tmem.law.synchronise`).

    Called, not inlined, and only where a scenario synchronises: inlined in the step loop it made the
    first run's compilation a third longer for every scenario.

    Parameters
    ----------
    e : int
        The pair.
    i, j : int
        The rows of its two agents in ``known`` and ``u``.
    r, dist : float
        ``|d|`` and ``|P_j - P_i|`` (m).
    entering : bool
        Whether the pair came within reach at this step.
    pushed : ndarray, shape (axes,)
        The pair's push on agent ``i`` this step (rad).
    known : ndarray, shape (rows, axes, n_state)
        The states as measured.
    pairs, law
        The loop's records; ``pairs`` changes in place.
    params : FunctionParams
        The interaction functions' parameters.
    n_axes : int
    u : ndarray, shape (rows, axes)
        The set-points the pushes are added to.
    """
    if entering:
        pairs.entry_speed2[e] = mean_square_speed(known, i, j, n_axes)
    coupled = pairs.flag[e] == 1
    kept = pairs.kept_speed2[e]
    if coupled and np.isnan(kept):  # coupled now; one coupled beyond reach keeps the energy it has
        kept = pairs.entry_speed2[e] if not np.isnan(pairs.entry_speed2[e]) else mean_square_speed(known, i, j, n_axes)
    elif not coupled and min(r, dist) >= params.reach:  # gone: held until E is back at E*
        if abs(mean_square_speed(known, i, j, n_axes) - kept) <= KEPT_TOLERANCE * kept:
            kept = np.nan
    pairs.kept_speed2[e] = kept
    if not np.isnan(kept):
        synchronising_push(known, i, j, law.sync_gain, coupled, kept, law.keep_energy, pushed, params.c_max, n_axes, u)


@numba.njit(cache=True, error_model="numpy", inline="always")
def formation_pair(k, e, known, agents, pairs, law, params, box, events, counters):
    """Formation pair ``e`` at step ``k``: its flag ``F_en`` after this step's check ((9), or the energy
    match), its smallest distance, its pull or push on both agents, and the synchronisation (S2).
    A pair whose agent was removed uncouples and rests.  The step loop calls it for every pair
    (:func:`formation_pairs`), and :mod:`tmem.batch.encounters` for each encounter of a batch.

    Inlined into the loops and the batch; what only the energy rule and the synchronisation need
    (:func:`tmem.law.coupling.function_gap`, :func:`synchronise`) is called, so that their copies of the
    interaction functions are compiled once.

    Parameters
    ----------
    k, e : int
        The step and the pair.
    known : ndarray, shape (agents, axes, n_state)
        The states as measured (:func:`tmem.world.sensing.measure`): the pair's velocities.
    agents, pairs, law, events, counters
        The loop's records (:mod:`tmem.engine.records`); ``agents``, ``pairs``, ``events`` and ``counters`` change in place.
    params : FunctionParams
        The interaction functions' parameters; each pair's own ``d_t`` replaces the scenario's.
    box : tuple of float
        The box sides (0: open axis).
    """
    d = pairs.d
    n_axes = len(box)
    i = pairs.i[e]
    j = pairs.j[e]
    if released_if_lost(k, e, agents, pairs, events, counters):
        return
    r, dist = _pair_geometry(agents.corrected, e, pairs, box, d)
    if dist < pairs.min_distance[e]:
        pairs.min_distance[e] = dist
    entering = check_flag(k, e, r, d, known, i, j, pairs, law, params, n_axes, events, counters)
    pair_push(e, d, r, pairs, law, params, n_axes)
    for a in range(n_axes):
        agents.setpoint[i, a] += d[a]
        agents.setpoint[j, a] -= d[a]
    if law.sync_gain > 0.0:
        synchronise(e, i, j, r, dist, entering, d, known, pairs, law, params, n_axes, agents.setpoint)


@numba.njit(cache=True, inline="always")
def released_if_lost(k, e, agents, pairs, events, counters):
    """Whether pair ``e`` has lost an agent (removed); a coupled pair then uncouples and rests.

    Parameters
    ----------
    k, e : int
        The step and the pair.
    agents, pairs, events, counters
        The loop's records; all but ``agents`` change in place.
    """
    i = pairs.i[e]
    j = pairs.j[e]
    if agents.active[i] and agents.active[j]:
        return False
    if pairs.flag[e] == 1:  # the pair is lost with its agent
        pairs.flag[e] = 0
        pairs.kept_speed2[e] = np.nan
        log_event(events, counters, k, coupling.EVENT_UNCOUPLE, i, j, -1, coupling.RELEASE_LOST)
    pairs.r_before[e] = np.nan
    return True


@numba.njit(cache=True, error_model="numpy", inline="always")
def check_flag(k, e, r, d, known, i, j, pairs, law, params, n_axes, events, counters):
    """Pair ``e``'s flag after step ``k``'s check ((9), or the energy match), an event where it changes;
    ``r`` becomes the pair's ``|d|`` one step earlier.  Returns whether the pair came within reach.

    Parameters
    ----------
    k, e : int
        The step and the pair.
    r : float
        ``|d|`` this step (m).
    d : ndarray, shape (axes,)
        ``P*_j - P*_i``.
    known : ndarray, shape (rows, axes, n_state)
        The states as measured; ``i`` and ``j`` are the rows of the pair's agents.
    i, j : int
    pairs, law, events, counters
        The loop's records; ``pairs``, ``events`` and ``counters`` change in place.
    params : FunctionParams
        The interaction functions' parameters.
    n_axes : int
    """
    if law.couples:
        energy = 0.0  # needed by the energy rule only
        if law.uncouple_rule == coupling.UNCOUPLE_BY_ENERGY and r > 0.0:
            energy = coupling.relative_energy(known, i, j, d, r, n_axes)
        new, released_by = _next_flag(k, e, r, energy, pairs, law, params)
        if new != pairs.flag[e]:
            pairs.flag[e] = new
            log_event(events, counters, k, coupling.EVENT_COUPLE if new == 1 else coupling.EVENT_UNCOUPLE,
                      pairs.i[e], pairs.j[e], -1, released_by)  # fmt: skip
    entering = r < params.reach and not pairs.r_before[e] < params.reach  # or at the first step
    pairs.r_before[e] = r
    return entering
