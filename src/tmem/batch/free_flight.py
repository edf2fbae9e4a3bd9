"""Free flight in closed form: when a pair of the batch feels no push, and how far its flight may be skipped.

A pair that is uncoupled, out of reach and *level* (every component of its agents' states after the
velocity at rest: the tilt and its rate died out, for a tilting multirotor) feels no push, so its
agents fly at constant velocity and ``P* = P + (K_V / K_P) V`` (6) moves at ``V``.  Both batches
(:mod:`tmem.batch.encounters` on 1 to 3 axes, :mod:`tmem.batch.relative` on the paper's one axis)
skip such a flight up to just before ``|P*_j - P*_i|`` could come back within reach.
"""

from __future__ import annotations

import numba

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

#: Below these the inner states count as at rest: the first component after the velocity (the tilt,
#: rad), and every later one (the tilt rate, rad/s).
LEVEL_FIRST, LEVEL_REST = 1e-13, 1e-12


@numba.njit(cache=True, inline="always")
def level(x, i, a):
    """Whether row ``i``'s state on axis ``a`` is level: every component after the velocity at rest.

    Parameters
    ----------
    x : ndarray, shape (rows, axes, n_state)
        States, ``(P, V, ...)`` first.
    i, a : int
        The row and the axis.
    """
    n_state = x.shape[2]
    if n_state > 2 and abs(x[i, a, 2]) >= LEVEL_FIRST:  # apart from the loop below: no test of m in it
        return False
    for m in range(3, n_state):
        if abs(x[i, a, m]) >= LEVEL_REST:
            return False
    return True


@numba.njit(cache=True, inline="always")
def steps_before_contact(d, velocity, steps_left, gap, dt):
    """On one axis: the steps a free pair ``gap`` m beyond reach may skip: every step left if it
    separates (``d`` grows at ``velocity``), else those before it could close the gap.

    Parameters
    ----------
    d : float
        ``P*_j - P*_i`` (m).
    velocity : float
        ``V_j - V_i`` (m/s).
    steps_left : int
        Steps to the end of the run.
    gap : float
        ``|d|`` less the reach and the coupling window (m).
    dt : float
        The step (s).
    """
    closing = -velocity if d > 0 else velocity
    if closing <= 0.0:
        return steps_left
    return min(steps_left, int(gap / (closing * dt)) - 1)
