"""The agent terms' stage: after the pair terms, each agent adds its terms' pushes, then the gas's walls and thermostat.

For each flying agent ``i``, in the order of :data:`tmem.terms.TERMS`, every agent term the
scenario gives adds its push to ``u[i]`` (:mod:`tmem.terms.base`); then, where the gas is observed,
:func:`tmem.engine.gas.gas_agent` adds the walls' and obstacles' pushes (W1) and the thermostat's
(T1), (T3), and has the last word (W2).  Agents are taken in blocks, the blocks on threads: each
agent writes its own row only, so the bits do not depend on the threads.

The stage is composed for each variant (:func:`agent_stage`): the terms' kernels chained in one
inlined function (:func:`tmem.engine.variants.chain`), bound with the gas's part into a copy of
:func:`_agent_block_source` compiled once per variant and called once per block.  Inlined into
the parallel loop, the gas's code gave the threaded loop other totals than the serial one (Numba's
diagnostics show constant assignments of that code moved out of the loop); a call per agent cost
more than the agent's work; a call per block costs nothing.  A variant without terms or gas binds
:func:`_no_agent_terms`, and its loop has no such pass at all.
"""

from __future__ import annotations

import numba

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.engine.gas import OBSERVERS, gas_agent
from tmem.engine.variants import Variant, bound, chain


@numba.njit(inline="always")
def _no_agent_terms(k, known, agents, params, box, terms, gas, n_blocks, counting):
    """A variant without agent terms or gas: nothing."""


@numba.njit(inline="always")
def _no_gas(i, known, agents, params, gas, box, counting, first):
    """A variant whose gas is not observed: no walls, obstacles or thermostat."""


def _agent_block_source(begin, end, k, known, agents, params, box, terms, gas, counting, first):
    """Agents ``begin:end``, one after the other: each flying agent's terms, then its gas."""
    for i in range(begin, end):
        if agents.active[i]:
            term_pushes(i, k, known, agents, box, terms)  # noqa: F821  (bound)
            gas_part(i, known, agents, params, gas, box, counting, first)  # noqa: F821  (bound)


def _agent_stage_source(k, known, agents, params, box, terms, gas, n_blocks, counting):
    """Every flying agent's terms and gas, by blocks of agents on threads (module text)."""
    first = first_count(gas, counting)  # noqa: F821  (bound)
    n_agents = known.shape[0]
    per_block = (n_agents + n_blocks - 1) // n_blocks
    for b in numba.prange(n_blocks):
        agent_block(b * per_block, min(n_agents, (b + 1) * per_block), k, known, agents, params, box, terms, gas,  # noqa: F821
                    counting, first)  # fmt: skip


def agent_stage(variant: Variant):
    """The compiled agent terms' stage of ``variant``: what the loop calls ``agent_terms``.

    Parameters
    ----------
    variant : Variant
        Its agent terms and whether its gas is observed.
    """
    from tmem.terms import term_class

    if not variant.terms and not variant.gas:
        return _no_agent_terms
    kernels = tuple(term_class(name).kernel() for name in variant.terms)
    block = bound(_agent_block_source, variant.name("agent_block"), {"cache": True, "error_model": "numpy", "_nrt": False},
                  term_pushes=chain(kernels), gas_part=gas_agent if variant.gas else _no_gas)  # fmt: skip
    return bound(_agent_stage_source, variant.name("agent_stage"), {"inline": "always"}, agent_block=block,
                 first_count=OBSERVERS[variant.gas]()["first_count"])  # fmt: skip
