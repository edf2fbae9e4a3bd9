"""The neighbours' pushes under exact knowledge: every listed non-formation pair, summed in chunks.

Step 4 of the loop (:mod:`tmem.engine.loop`), the exact knowledge's ``pair_pass``
(:mod:`tmem.engine.knowledge`).  Each pair ``(i, j)`` of the
neighbour lists (:mod:`tmem.world.neighbors`) is pushed once, equal and opposite, with the interaction
function of :attr:`tmem.law.record.Law.neighbour_function` along ``d / |d|``, ``d = P*_j - P*_i``
(6).  Pairs are gathered into chunks, pushed in vectorised arithmetic (:func:`_chunk_pushes`), then
added to the set-points, weighted under the mean of pushes (C1).  At a count of the gas, the adding
also counts each pair for the gas (:func:`_add_counted`; :mod:`tmem.engine.gas`).
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law.interaction.kernels import push_factor
from tmem.world.space import nearest_image
from tmem.engine.gas_counts import add_contact, pair_share, virial_by_pairs

#: Pairs are summed in chunks of this many: gathered, then pushed in vectorised arithmetic, then added.
CHUNK = 256


@numba.njit(cache=True, error_model="numpy", inline="always")
def _chunk_pushes(chunks, w, m, n_axes, function, params):
    """The pushes of ``m`` pairs, in place in the work space ``chunks[w]``: row ``a`` holds
    ``d_a = P*_j - P*_i`` on entry and the push on agent ``i`` along axis ``a``, ``f(|d|) d_a / |d|``,
    on return (0 beyond reach).  Row ``n_axes + a`` holds ``P_j - P_i``; row ``2 n_axes`` gets
    ``|P_j - P_i|^2`` for the pairs within reach, ``inf`` for the others.  No branches: the compiler
    vectorises it."""
    reach2 = params.reach * params.reach
    for t in range(m):
        r2 = 0.0
        for a in range(n_axes):
            r2 += chunks[w, a, t] * chunks[w, a, t]
        inside = (r2 < reach2) & (r2 > 0.0)
        push = push_factor(function, r2, params)
        dist2 = 0.0
        for a in range(n_axes):
            dist2 += chunks[w, n_axes + a, t] * chunks[w, n_axes + a, t]
            chunks[w, a, t] *= push
        chunks[w, 2 * n_axes, t] = dist2 if inside else np.inf


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def pair_pass(k, first, stop, w, agents, neighbours, law, params, box, knowledge, gas, counting):
    """Add the pushes of the listed pairs ``first:stop`` to the set-points, each ``(i, j)`` once,
    equal and opposite, in the order listed; return the smallest ``|P_j - P_i|^2`` of a pair within
    reach.  The exact knowledge's ``pair_pass`` (:mod:`tmem.engine.knowledge`).

    Under the mean of pushes (C1) each push is weighted; at a count of the gas, each pair is counted
    for both its agents too (:func:`_add_counted`).  Called, not inlined: the loop calls it from two
    places, and each inlined copy of it (with the interaction functions inside) cost two seconds of
    the first run's compilation.  The call costs nanoseconds against the chunks of pairs it sums.

    Parameters
    ----------
    k : int
        The step (unused: exact knowledge does not age).
    first, stop : int
        The listed pairs ``neighbours.pairs[first:stop]``.
    w : int
        The row of ``neighbours.chunks`` this call works in (its block's).
    agents, neighbours, law, gas
        The loop's records (:mod:`tmem.engine.records`); ``agents.setpoint`` and the gas's counts
        change in place.
    params : FunctionParams
        The interaction functions' parameters.
    box : tuple of float
        The periodic box's sides (0: open axis).
    knowledge : Sensing
        Unused: every agent knows every state.
    counting : bool
        Whether the step is a count of the gas.
    """
    corrected, known, u = agents.corrected, agents.state, agents.setpoint  # the gas's stages need exact knowledge
    pairs, chunks, function = neighbours.pairs, neighbours.chunks, law.neighbour_function
    n_axes = len(box)
    nearest2 = np.inf
    for begin in range(first, stop, CHUNK):
        m = min(CHUNK, stop - begin)
        for t in range(m):
            i = pairs[begin + t, 0]
            j = pairs[begin + t, 1]
            for a in range(n_axes):
                chunks[w, a, t] = nearest_image(corrected[j, a, 0] - corrected[i, a, 0], box[a])
                chunks[w, n_axes + a, t] = nearest_image(corrected[j, a, 1] - corrected[i, a, 1], box[a])
        _chunk_pushes(chunks, w, m, n_axes, function, params)
        for t in range(m):
            nearest2 = min(nearest2, chunks[w, 2 * n_axes, t])
        if counting:
            _add_counted(chunks, w, m, pairs, begin, n_axes, u, gas, known)
        else:
            _add_pushes(chunks, w, m, pairs, begin, n_axes, u, gas.weight, gas.mean)
    return nearest2


@numba.njit(cache=True, error_model="numpy", inline="always")
def _add_pushes(chunks, w, m, pairs, begin, n_axes, u, weight, mean):
    """Add a chunk's pushes to ``u``, equal and opposite; under the mean of pushes (``mean``, C1) each
    divided by :func:`tmem.engine.gas.pair_share`, the weight its agents broadcast at the last count."""
    for t in range(m):
        i = pairs[begin + t, 0]
        j = pairs[begin + t, 1]
        share = pair_share(i, j, weight) if mean else 1.0
        for a in range(n_axes):
            u[i, a] += chunks[w, a, t] * share
            u[j, a] -= chunks[w, a, t] * share


@numba.njit(cache=True, error_model="numpy", inline="always")
def _add_counted(chunks, w, m, pairs, begin, n_axes, u, gas, known):
    """Add a chunk's pushes to ``u`` as :func:`_pushes_of` does, for the gas (:mod:`tmem.engine.gas`):
    under the mean of pushes (C1) each push divided by :func:`tmem.engine.gas.pair_share`, and each
    pair within reach counted for both its agents (:func:`tmem.engine.gas.add_contact`), in one
    pass; in a periodic box, each pair's virial too (G1).  A pair beyond reach adds zeros rather
    than being skipped: whether a listed pair is within reach is a coin toss the processor cannot
    predict, and the branch cost more than the adds."""
    work = gas.work
    weight = gas.weight
    mean = gas.mean
    pair_virial = virial_by_pairs(gas.walls)
    inv_c_max2 = 1.0 / (gas.c_max * gas.c_max)
    for t in range(m):
        i = pairs[begin + t, 0]
        j = pairs[begin + t, 1]
        size2 = 0.0
        for a in range(n_axes):
            size2 += chunks[w, a, t] * chunks[w, a, t]
        share = pair_share(i, j, weight) if mean else 1.0
        virial = 0.0
        for a in range(n_axes):
            push = chunks[w, a, t] * share
            u[i, a] += push
            u[j, a] -= push
            if pair_virial:
                virial -= chunks[w, n_axes + a, t] * push
        add_contact(i, j, 1.0 if chunks[w, 2 * n_axes, t] < np.inf else 0.0, size2 * inv_c_max2, virial, pair_virial,
                    work, known)  # fmt: skip
