"""The step loop: the stages of one step in order, each stage that varies called by a name the variant binds.

:func:`advance_for` gives the compiled loop of a :class:`~tmem.engine.variants.Variant`.  The
loop's source, :func:`_advance_source`, is written once; it calls the stages that vary by these
names, which the variant binds (:func:`tmem.engine.variants.bound`):

* ``measure``, ``pair_pass``, ``formation_pair`` and ``LISTED`` — the agents' knowledge, exact or
  sensed (:data:`tmem.engine.knowledge.KNOWLEDGE`);
* ``agent_terms`` — the agent terms' pass, their pushes gathered agent by agent, the gas's walls and
  thermostat last (:func:`tmem.engine.terms.agent_stage`);
* ``counts_due``, ``count_pair``, ``tilt_limit``, ``after_step`` — the gas's
  observers, or nothing (:data:`tmem.engine.gas.OBSERVERS`);
* ``vehicle_step`` — the vehicle model's compiled step.

Every copy is compiled without Numba's runtime (``_nrt=False``), so without reference counts.
Every record a stage receives, and every field read from it, would otherwise cost an atomic
reference-count change per array, each step: 20 to 60 of them, which made a two-agent step take
more than twice as long as its arithmetic.  It is safe because the caller keeps every array
alive and nothing in a step allocates; a stage that allocated would not compile.  For the same
reason no parallel loop reduces into a variable (Numba allocates for that): blocks write their
partial results into work space.  Inside a parallel loop, a record holding a tuple (``Run``, with
its box) cannot be passed on, and a stage that writes into a record's arrays is called, not
inlined: inlined, its writes were lost on threads (``tests/test_gas.py`` compares the threaded loop's
totals with the serial one's).
"""

from __future__ import annotations

from functools import cache

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.engine.records import DONE, LISTS_STALE
from tmem.engine.stages import apply_commands, commands_due, corrected_positions, is_recorded, record
from tmem.engine.variants import Variant, bound
from tmem.law.modal import tilt_scale
from tmem.world.space import into_box


def _advance_source(k_stop, run, law, params, vehicle, knowledge, agents, pairs, neighbours, commands, records, events,
                    counters, gas, terms):  # fmt: skip
    """Advance from step ``counters.step`` to ``k_stop``; return ``DONE``, or ``LISTS_STALE`` when the
    neighbour lists must be built before the step ``counters.step`` (the caller builds them from
    ``neighbours.p_ref`` and calls again).

    Each step: commands -> measurement -> P* (6) -> neighbour pushes (8) -> formation pairs (9)-(11)
    -> agent terms (the gas's walls and thermostat last) -> record -> saturate the set-point and step
    the vehicles (held over ``dt``).  When the gas is observed, its counts are taken at the steps
    ``counts_due`` names."""
    box = run.box
    n_axes = len(box)
    c_max = params.c_max
    x, u, body, active = agents.state, agents.setpoint, agents.body, agents.active
    block_ptr, block_nearest2 = neighbours.block_ptr, neighbours.block_nearest2  # the blocks of neighbour pairs
    n_blocks = block_ptr.shape[0] - 1
    for k in range(counters.step[0], k_stop):
        counters.step[0] = k
        counting = counts_due(k, gas)  # noqa: F821  (bound)
        rebuild = commands_due(k, commands, counters) and apply_commands(k, commands, agents, pairs, events, counters, gas)
        known = measure(k, x, knowledge)  # noqa: F821  (bound)
        moved2 = corrected_positions(known, agents, law, run, neighbours, gas, LISTED, counting)  # noqa: F821
        if rebuild or (run.use_lists and np.sqrt(moved2) > 0.5 * run.skin):
            for i in range(x.shape[0]):
                for a in range(n_axes):
                    neighbours.p_ref[i, a] = agents.corrected[i, a, LISTED]  # noqa: F821  (bound)
            return LISTS_STALE
        # The neighbours' pushes: each block's own pairs on a thread, then the pairs between blocks,
        # so that every agent adds its pushes in one order whatever the number of threads.  (A
        # parallel loop takes records of arrays and numbers, not a record holding a tuple: the box
        # goes on its own.)
        for b in numba.prange(n_blocks):
            block_nearest2[b] = np.inf
            if block_ptr[b + 1] > block_ptr[b]:
                block_nearest2[b] = pair_pass(k, block_ptr[b], block_ptr[b + 1], b, agents, neighbours, law, params,  # noqa: F821
                                              box, knowledge, gas, counting)  # fmt: skip
        nearest2 = np.inf
        if neighbours.n_pairs > neighbours.n_inside:
            nearest2 = pair_pass(k, neighbours.n_inside, neighbours.n_pairs, n_blocks, agents, neighbours, law, params,  # noqa: F821
                                 box, knowledge, gas, counting)  # fmt: skip
        for b in range(n_blocks):
            nearest2 = min(nearest2, block_nearest2[b])
        neighbours.closest[0] = min(neighbours.closest[0], nearest2)
        for e in range(pairs.i.shape[0]):
            formation_pair(k, e, known, agents, pairs, law, params, run, events, counters, knowledge)  # noqa: F821
            count_pair(e, agents, pairs, law, params, run, gas, counting)  # noqa: F821  (bound)
        agent_terms(k, known, agents, params, box, terms, gas, neighbours.block_shift2.shape[0], counting)  # noqa: F821
        if is_recorded(k, run):
            record(agents, pairs, records, c_max, run, counters, gas, LISTED == 1)  # noqa: F821  (bound)
        if k < run.n_steps:
            sampled = min(gas.every, run.n_steps - k) if counting else 0  # the steps this count stands for
            for i in numba.prange(x.shape[0]):
                if active[i]:
                    scale = tilt_scale(u, i, n_axes, tilt_limit(i, gas, c_max))  # noqa: F821  (bound)
                    vehicle_step(x, body, u, i, scale, vehicle, n_axes)  # noqa: F821  (bound)
                    for a in range(n_axes):
                        if box[a] > 0.0 and not 0.0 <= x[i, a, 0] < box[a]:  # inside, the floor is 0
                            x[i, a, 0] = into_box(x[i, a, 0], box[a])
                    after_step(x, i, scale, gas, box, n_axes, sampled)  # noqa: F821  (bound)
    counters.step[0] = k_stop
    return DONE


@cache
def advance_for(variant: Variant):
    """The compiled loop of a variant of the step (:class:`~tmem.engine.variants.Variant`).

    Parameters
    ----------
    variant : Variant
        The vehicle, the knowledge, the agent terms, the gas and the threads: their kernels are
        bound to the names the loop calls, in a copy named :meth:`Variant.name` ``("advance")``.
    """
    from tmem.engine.gas import OBSERVERS
    from tmem.engine.knowledge import KNOWLEDGE
    from tmem.engine.terms import agent_stage
    from tmem.vehicles import vehicle_class

    names = dict(KNOWLEDGE[variant.knowledge](), **OBSERVERS[variant.gas](), vehicle_step=vehicle_class(variant.vehicle).kernel(),
                 agent_terms=agent_stage(variant))  # fmt: skip
    return bound(_advance_source, variant.name("advance"),
                 {"cache": True, "parallel": variant.threaded, "error_model": "numpy", "_nrt": False}, **names)  # fmt: skip
