"""Variants of the step: which compiled kernel stands for each stage that varies, bound when the loop is compiled.

A step is composed from kernels of a few kinds: the *knowledge* the agents push from (exact, or
sensed: :mod:`tmem.engine.knowledge`), the *pair terms* of the TMEM law (the neighbours' pushes
(8) and the formation pairs (9)-(11), evaluated as the knowledge says), the *agent terms*
(gathers ``u[i] += term(i, ...)``, :mod:`tmem.engine.terms`; the gas's walls and thermostat are the
last of them, :mod:`tmem.engine.gas`), the gas's observers (its counts, tally and totals, or
nothing) and the *vehicle*'s step (:mod:`tmem.vehicles`).  A :class:`Variant` names one choice of
each.  The loop's source (:mod:`tmem.engine.loop`) calls every stage that varies by a fixed name;
:func:`bound` makes a compiled copy of a Python function with those names bound to the variant's
kernels, as jax-md composes ``simulate.nve`` from an energy function and HOOMD-blue an integrator
from its forces, but at compile time.

Why names bound at compile time, and not functions passed as arguments: Numba's on-disk cache keys
compiled code by the function's name and its arguments' types, and a compiled function passed as
an argument misses the cache (every process, every Dask worker, would compile again).  A copy
bound by name is one cache entry of its own, under a name that says what is bound
(:meth:`Variant.name`, e.g. ``advance__linear__exact__gas__threaded``: the name a traceback shows),
and the kernels bound into it are inlined, so a variant costs nothing at run time that it does not
use.  Options inside a kernel that cost one predictable branch (a pair's flag, synchronisation on
or off, the mean of pushes) stay numbers in the records: a copy per option would multiply the
first run's compilation.
"""

from __future__ import annotations

import types
from dataclasses import dataclass
from typing import Any

import numba

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)


@dataclass(frozen=True)
class Variant:
    """One variant of the step.

    Attributes
    ----------
    vehicle : str
        The vehicle model's kind (:data:`tmem.vehicles.VEHICLES`).
    knowledge : str
        ``"exact"`` or ``"sensed"`` (:data:`tmem.engine.knowledge.KNOWLEDGE`).
    terms : tuple of str
        The agent terms, by their scenario tables' names, in the order they push
        (:data:`tmem.engine.terms.TERMS`).
    gas : bool
        Whether the gas is observed (:mod:`tmem.engine.gas`): its counts, walls, thermostat and totals.
    threaded : bool
        The per-agent stages and the blocks of neighbour sums on threads (large swarms).
    """

    vehicle: str
    knowledge: str
    terms: tuple[str, ...]
    gas: bool
    threaded: bool

    def name(self, stage: str) -> str:
        """The compiled copy of ``stage`` for this variant: ``stage__vehicle__knowledge[__terms][__gas]__threads``.

        Parameters
        ----------
        stage : {"advance", "agent_block", "agent_stage"}
            The template's name.
        """
        parts = (stage, self.vehicle, self.knowledge, *self.terms, *(("gas",) if self.gas else ()),
                 "threaded" if self.threaded else "serial")  # fmt: skip
        return "__".join(parts)


def bound(template, name: str, options: dict[str, Any], **names) -> Any:
    """A compiled copy of the Python function ``template`` under ``name``, with ``names`` bound in its globals.

    Parameters
    ----------
    template : function
        A plain Python function whose body calls the stages it leaves open by name.
    name : str
        The copy's name: Numba's cache keys its compiled code by it (and the arguments' types).
    options : dict
        Options of :func:`numba.njit` (``cache``, ``parallel``, ``inline`` ...).
    **names
        The kernels (or constants) bound to the names the template calls.
    """
    namespace = dict(template.__globals__, **names)
    copy = types.FunctionType(template.__code__, namespace, name, template.__defaults__)
    copy.__qualname__ = name
    copy.__doc__ = template.__doc__
    return numba.njit(**options)(copy)


@numba.njit(inline="always")
def _nothing(i, k, known, agents, box, terms):
    """No agent term: adds nothing."""


def _first_then_rest(i, k, known, agents, box, terms):
    """The agent term at ``INDEX`` of ``terms``, then those after it (bound by :func:`chain`)."""
    first(i, k, known, agents, box, terms[INDEX])  # noqa: F821  (bound)
    rest(i, k, known, agents, box, terms)  # noqa: F821  (bound)


def chain(kernels: tuple, start: int = 0):
    """One inlined kernel that adds every agent term's push in turn: ``kernels[m]`` with ``terms[m]``.

    Each kernel has the agent terms' signature ``push(i, k, known, agents, box, record)``
    (:mod:`tmem.engine.terms`); the chain takes the tuple of their records.

    Parameters
    ----------
    kernels : tuple of compiled functions
        The terms' kernels, in the order they push.
    start : int
        The first kernel of the chain (its place in ``terms``).
    """
    if start == len(kernels):
        return _nothing
    return bound(_first_then_rest, f"term_{start}_of_{len(kernels)}", {"inline": "always"}, first=kernels[start],
                 rest=chain(kernels, start + 1), INDEX=start)  # fmt: skip


def compiles(dispatcher, args: tuple) -> bool:
    """Whether calling the compiled copy ``dispatcher`` with ``args`` compiles it: not compiled in this process,
    and not in Numba's on-disk cache for these arguments' types (the cache's own index, whose entries go
    stale with the source).  ``False`` where that cannot be told (the cache's index is not Numba's public
    API): a notice is then left out rather than given falsely.

    Parameters
    ----------
    dispatcher : numba Dispatcher
        A copy made by :func:`bound` with ``cache=True``.
    args : tuple
        The arguments it is about to be called with.
    """
    if dispatcher.overloads:
        return False
    try:
        signature = tuple(dispatcher.typeof_pyval(a) for a in args)
        cache = dispatcher._cache
        return cache._index_key(signature, dispatcher.targetctx.codegen()) not in cache._cache_file._load_index()
    except Exception:  # another Numba's cache layout
        return False
