"""Counter-based random streams: every draw a hash of who, when and what, in compiled code.

A draw is a function of ``(seed, receiver, sender, step, draw)`` alone, with
no generator state carried from one draw to the next.  What agent ``i``
measures of agent ``j`` at a step therefore does not depend on the order in
which the loop visits pairs, on the number of threads, or on which pairs a
neighbour list happens to hold: the same scenario gives the same bits every
way it is run (:mod:`tmem.sensing` draws its noise, delays and losses here).

The hash chains SplitMix64's finaliser (Steele, Lea and Flood, "Fast
splittable pseudorandom number generators", OOPSLA 2014; the reference
``splitmix64.c`` of Vigna) over the five numbers: each is added to the hash so
far with the golden-ratio increment, and the sum is mixed.  Agents are named
by their number in the scenario, not by their slot in the loop.

:func:`uniform` and :func:`normal` are called, not inlined: the sensed loop
draws in a dozen places, and each inlined copy of the hash and of Box-Muller
lengthened its first compilation.
"""

from __future__ import annotations

import numba
import numpy as np

from . import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

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
def bits(seed, receiver, sender, step, draw):
    """64 random bits of one draw: the hash of its five numbers.

    Parameters
    ----------
    seed : int
        The scenario's seed (``sensing.seed``), >= 0.
    receiver, sender : int
        The agents' numbers in the scenario (the same for an agent's measure of itself).
    step : int
        The step the draw belongs to (for a message, the step it was sent), >= 0.
    draw : int
        Which draw of that message, >= 0 (:data:`tmem.sensing.LOSS`, ...).
    """
    h = mix(np.uint64(seed))
    h = mix(h + np.uint64(receiver))
    h = mix(h + np.uint64(sender))
    h = mix(h + np.uint64(step))
    return mix(h + np.uint64(draw))


@numba.njit(cache=True)
def uniform(seed, receiver, sender, step, draw):
    """A draw uniform on (0, 1), never 0 nor 1: the top 53 bits, centred in their interval.

    Parameters
    ----------
    seed, receiver, sender, step, draw : int
        As :func:`bits` takes them.
    """
    return (np.float64(bits(seed, receiver, sender, step, draw) >> _S11) + 0.5) * _UNIT


@numba.njit(cache=True, error_model="numpy")
def normal(seed, receiver, sender, step, draw):
    """A standard normal draw (Box-Muller on the uniform draws ``2 draw`` and ``2 draw + 1``).

    Parameters
    ----------
    seed, receiver, sender, step : int
        As :func:`bits` takes them.
    draw : int
        Which normal draw of that message, >= 0.
    """
    u1 = uniform(seed, receiver, sender, step, 2 * draw)
    u2 = uniform(seed, receiver, sender, step, 2 * draw + 1)
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2)
