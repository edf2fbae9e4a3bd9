"""The gas's counts: what each pair within reach adds to its agents' rows at a count, and the columns of those rows.

Every ``simulation.gas_period`` (a *count*, :attr:`tmem.engine.records.Gas.every` steps apart) the
neighbours' pass (:mod:`tmem.engine.pushes`) and the formation pairs (:func:`count_pair`) count,
for each agent, its neighbours within reach, their pushes' sizes (its contacts), their velocities
and the virial (G1); the gas's stages (:mod:`tmem.engine.gas`) and the thermostat
(:mod:`tmem.engine.thermostat`) read the counts.  A row per agent, so that the counts of a pair
touch two rows; what the stages hold between counts is kept in ``Gas.held``.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.world.space import nearest_image


#: Columns of ``Gas.work``, cleared at each count: neighbours within reach, their pushes' squared
#: sizes over ``c_max^2`` (the agent's contacts), the agent's virial (rad m), its ``|V|^2``, its
#: neighbours' ``|V|^2`` and, from :data:`NEIGHBOUR_VELOCITY` on, one column per axis, their
#: velocities, each neighbour weighted by its contact (T3).
NEAR, CONTACT, VIRIAL, SPEED2, NEIGHBOUR_SPEED2, NEIGHBOUR_VELOCITY = range(6)
#: Columns of ``Gas.held``, what the thermostat holds from one count to the next (T3): how far the
#: agent is in contact (:data:`tmem.engine.thermostat.FULL_CONTACT`), and from :data:`COMMON` on, one
#: column per axis, its push on the agent's group (rad).  The thermostat reads them at every step.
TOGETHER, COMMON = range(2)


@numba.njit(cache=True, inline="always")
def clear(i, known, work, n_axes):
    """Start agent ``i``'s count: nothing counted yet, and its own ``|V|^2`` as known.

    Called in a parallel loop: it takes the record's arrays, not the record.

    Parameters
    ----------
    i, known, n_axes
        As every per-agent function of the gas takes them (:mod:`tmem.engine.gas`).
    work : ndarray
        ``Gas.work`` (:class:`tmem.engine.records.Gas`), changed in place.
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


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def count_pair(e, agents, pairs, law, params, run, gas, counting):
    """For the gas: formation pair ``e``, if within reach, with no coupling flag (the tracked pairs of a
    small swarm) is a plain neighbour, and the mean of pushes (C1) divides its push too; at a count,
    it is counted as the neighbour stage counts its pairs.  ``pairs.d`` holds its push on ``i``
    (:func:`tmem.engine.pairs.formation_pair` leaves it there).

    Parameters
    ----------
    e : int
        The pair.
    agents, pairs, law, run, gas
        The loop's records; ``agents.setpoint`` and ``gas`` change in place.
    params : FunctionParams
        The interaction functions' parameters.
    counting : bool
        Whether the step is a count.
    """
    i = pairs.i[e]
    j = pairs.j[e]
    if not (agents.active[i] and agents.active[j]) or not pairs.r_before[e] < params.reach:
        return
    box = run.box
    n_axes = len(box)
    d = pairs.d
    size2 = 0.0
    for a in range(n_axes):
        size2 += d[a] * d[a]
    pressing = size2 / (params.c_max * params.c_max)
    if gas.mean and not law.couples:
        share = pair_share(i, j, gas.weight)
        if share < 1.0:
            for a in range(n_axes):
                agents.setpoint[i, a] -= (1.0 - share) * d[a]
                agents.setpoint[j, a] += (1.0 - share) * d[a]
                d[a] *= share
    if not counting:
        return
    virial = 0.0
    for a in range(n_axes):
        virial -= nearest_image(agents.corrected[j, a, 1] - agents.corrected[i, a, 1], box[a]) * d[a]
    add_contact(i, j, 1.0, pressing, virial, virial_by_pairs(gas.walls), gas.work, agents.state)
