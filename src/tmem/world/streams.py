"""Counter-based random streams: every draw a hash of who, when and what, in compiled code.

A draw is a function of ``(seed, receiver, sender, step, draw)`` alone, with
no generator state carried from one draw to the next: the first four, a
*message*, are hashed once (:func:`message_key`), and each draw of the message
is one more mix of that key with its number.  What agent ``i``
measures of agent ``j`` at a step therefore does not depend on the order in
which the loop visits pairs, on the number of threads, or on which pairs a
neighbour list happens to hold: the same scenario gives the same bits every
way it is run (:mod:`tmem.world.sensing` draws its noise, delays and losses here).

The hash chains SplitMix64's finaliser (Steele, Lea and Flood, "Fast
splittable pseudorandom number generators", OOPSLA 2014; the reference
``splitmix64.c`` of Vigna) over the five numbers: each is added to the hash so
far, and the sum is mixed with the golden-ratio increment.  Agents are named
by their number in the scenario, not by their slot in the loop.

:func:`uniform` and :func:`normal_pair` are called, not inlined: the sensed
loop draws in a dozen places, and each inlined copy of the hash and of
Box-Muller lengthened its first compilation.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

#: SplitMix64's increment, the odd integer nearest 2^64 / golden ratio.
GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
#: 2^-53: a 53-bit integer times this is a double in [0, 1).
_UNIT = 1.0 / 9007199254740992.0


@numba.njit(cache=True, inline="always")
def mix(z):
    """SplitMix64's finaliser of ``z + GOLDEN``: one output of the generator whose state was ``z``.

    Parameters
    ----------
    z : uint64
        The state (wraps modulo 2^64).
    """
    z = z + GOLDEN
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@numba.njit(cache=True, inline="always")
def message_key(seed, receiver, sender, step):
    """The hash of a message's four numbers, from which each of its draws is one more mix.

    Parameters
    ----------
    seed : int
        The scenario's seed (``sensing.seed``), >= 0.
    receiver, sender : int
        The agents' numbers in the scenario (the same for an agent's measure of itself).
    step : int
        The step the message belongs to (the step it was sent), >= 0.
    """
    h = mix(np.uint64(seed))
    h = mix(h + np.uint64(receiver))
    h = mix(h + np.uint64(sender))
    return mix(h + np.uint64(step))


@numba.njit(cache=True)
def uniform(key, draw):
    """Draw ``draw`` of the message ``key``, uniform on (0, 1), never 0 nor 1: the top 53 bits of
    ``mix(key + draw)``, centred in their interval.

    Parameters
    ----------
    key : uint64
        :func:`message_key`.
    draw : int
        Which draw of that message, >= 0 (:data:`tmem.world.sensing.LOSS`, ...).
    """
    return (np.float64(mix(np.uint64(key) + np.uint64(draw)) >> _S11) + 0.5) * _UNIT


@numba.njit(cache=True, error_model="numpy")
def normal_pair(key, draw):
    """Two independent standard normal draws of the message ``key``: Box-Muller on its uniform draws
    ``2 draw`` and ``2 draw + 1``.

    Parameters
    ----------
    key : uint64
        :func:`message_key`.
    draw : int
        Which pair of normal draws of that message, >= 0.
    """
    radius = np.sqrt(-2.0 * np.log(uniform(key, 2 * draw)))
    angle = 2.0 * np.pi * uniform(key, 2 * draw + 1)
    return radius * np.cos(angle), radius * np.sin(angle)
