"""What the agents push from: exact knowledge, or what each agent senses (:mod:`tmem.world.sensing`).

The knowledge binds four names of the loop (:mod:`tmem.engine.loop`):

* ``measure(k, x, knowledge)`` — the states as each agent knows its own (exact: the true states,
  no copy; sensed: each agent's measurement, the step's messages broadcast);
* ``pair_pass(k, first, stop, w, agents, neighbours, law, params, run, knowledge, gas, counting)`` —
  the neighbours' pushes (8) of a run of listed pairs (exact: each pair once, equal and opposite,
  in vectorised chunks, :func:`tmem.engine.pushes.pair_pass`; sensed: each agent from its own
  measurement, :func:`tmem.engine.sensed.pair_pass`);
* ``formation_pair(k, e, known, agents, pairs, law, params, run, events, counters, knowledge)`` —
  a formation pair's flag (9), pull (10)/(11) and synchronisation (S2) (:mod:`tmem.engine.pairs`;
  sensed: :func:`tmem.engine.sensed.formation_pair`);
* ``LISTED`` — what the neighbour lists hold: 0, ``P*`` (6), or 1, ``P`` (the sensing range is one of
  positions).
"""

from __future__ import annotations

import numba

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.engine.pairs import formation_pair as pair_law


@numba.njit(inline="always")
def _true_states(k, x, knowledge):
    """Exact knowledge: every agent knows every state; the true states, without a copy."""
    return x


@numba.njit(inline="always")
def _exact_formation_pair(k, e, known, agents, pairs, law, params, run, events, counters, knowledge):
    """Exact knowledge: the pair law of :func:`tmem.engine.pairs.formation_pair` on the true states."""
    pair_law(k, e, known, agents, pairs, law, params, run.box, events, counters)


def _exact() -> dict:
    from tmem.engine.pushes import pair_pass

    return dict(measure=_true_states, pair_pass=pair_pass, formation_pair=_exact_formation_pair, LISTED=0)


def _sensed() -> dict:
    from tmem.engine.sensed import formation_pair, pair_pass
    from tmem.world.sensing import measure

    return dict(measure=measure, pair_pass=pair_pass, formation_pair=formation_pair, LISTED=1)


#: The knowledge the agents may have, by name: a function giving the names it binds in the loop.
KNOWLEDGE = {"exact": _exact, "sensed": _sensed}
