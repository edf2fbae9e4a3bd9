"""The paper's case on one axis, reduced to the pair's relative state: the fast path of :mod:`tmem.batch.encounters`.

For two agents on one axis the pushes are equal and opposite, also after
saturation (the clip is odd), so the sum ``x_0 + x_1`` flies free and only
the relative state ``e = x_1 - x_0`` feels the interaction::

    e[k+1] = Ad e[k] + Bd (U_1 - U_0) = Ad e[k] - 2 Bd U_0,
    U_0 = sat(f(|d|) sign(d)),   d = K . e / K_P   (6)

One step of one case is then a handful of multiply-adds, three times fewer
than stepping both agents.  It holds while nothing but the pair's own push
acts on it: under the window rule (9) and without synchronisation, whose
common push depends on the sum.  Free flight (uncoupled, out of reach, the
tilt died out) moves ``d`` at a constant rate and is skipped in closed form:
to the end once the pair separates, to just before contact while it closes.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law import coupling
from tmem.batch.free_flight import level, steps_before_contact
from tmem.law.interaction.kernels import pair_control
from tmem.vehicles.linear import LinearModel

#: The linear model's exact step (2): the relative state steps as an agent does, with the input ``U_1 - U_0``.
_linear_step = LinearModel.kernel()
#: Cases advanced side by side in one loop.  One case's step depends on its last, so alone it waits
#: on its own arithmetic; interleaving independent cases lets the processor overlap them.
LANES = 8


@numba.njit(cache=True, inline="always")
def _lane_states(e0, first, lanes):
    """The relative states ``(P, V, phi, omega)`` of the ``lanes`` cases from ``first``, a row each of
    an array of :data:`LANES` rows, on one axis."""
    e = np.empty((LANES, 1, e0.shape[1]))
    for lane in range(lanes):
        for m in range(e0.shape[1]):
            e[lane, 0, m] = e0[first + lane, m]
    return e


@numba.njit(cache=True, inline="always")
def _skip_free_flight(e, armed, r_before, k, c, d, gap, n_steps, command_step, dt):
    """Skip case ``c``'s free flight in closed form (:func:`tmem.batch.free_flight.steps_before_contact`),
    the command disarming it if due on the way; whether there was more than one step to skip."""
    skip = steps_before_contact(d, e[c, 0, 1], n_steps - k[c], gap, dt)
    if skip <= 1:
        return False
    if k[c] < command_step <= k[c] + skip:
        armed[c] = 0
    e[c, 0, 0] += e[c, 0, 1] * (skip * dt)
    k[c] += skip
    r_before[c] = np.nan
    return True


@numba.njit(cache=True, inline="always")
def _flag_step(flag, armed, r_before, coupled_at, uncoupled_at, c, step, r, d_t, eps, at_crossing):
    """Case ``c``'s flag ``F_en`` after its measure reached ``r`` at ``step`` (condition (9),
    :func:`tmem.law.coupling.next_flag`), and the first steps it coupled and uncoupled."""
    new = coupling.next_flag(flag[c], armed[c], r_before[c], r, d_t, eps, at_crossing)
    if new != flag[c]:
        if new == 1 and coupled_at[c] < 0:
            coupled_at[c] = step
        if new == 0 and uncoupled_at[c] < 0:
            uncoupled_at[c] = step
        flag[c] = new
    r_before[c] = r


@numba.njit(cache=True, inline="always")
def _push_on_first(function, r, f_en, params, d, c_max):
    """``U_0``: the pair's push on its first agent at measure ``r = |d|`` (8), its sign ``d``'s,
    saturated to ``c_max``; 0 at ``r = 0``."""
    u0 = 0.0
    if r > 0.0:
        u0 = pair_control(function, r, f_en, params) * (1.0 if d > 0 else -1.0)
        u0 = min(max(u0, -c_max), c_max)
    return u0


# fastmath "contract" only: the multiply-adds may fuse (one rounding instead of two); NaN and
# infinity keep their meaning, which the flag logic relies on (r_before is NaN after a skip).
@numba.njit(cache=True, parallel=True, error_model="numpy", fastmath={"contract"})
def run_relative(e0, n_steps, dt, command_step, hold, law, params, e_end, min_dist, couple_step, uncouple_step):
    """Advance each case's relative state ``e0`` (cases, 4) ``n_steps`` steps of ``dt`` under ``law`` with
    the functions' parameters ``params`` and the zero-order hold ``hold`` of the linear model; write each
    case's end, smallest distance, and the steps it first coupled and uncoupled (-1: never).
    (Records are used inside the parallel loop only as arguments: see :class:`tmem.engine.records.Law`.)
    The two agents of a case are alike: ``P*`` (6) of their relative state uses the law's first row of gains.

    Parameters
    ----------
    e0 : ndarray, shape (cases, 4)
        ``x_1 - x_0`` at the start.
    n_steps, dt, command_step
        Steps, time step (s), and the step of the uncouple command (-1: none).
    hold, law, params
        The zero-order hold, the law (window rule, no synchronisation) and the functions' parameters.
    e_end, min_dist, couple_step, uncouple_step : ndarray
        Written: the end relative state, the smallest distance, the first coupling and uncoupling steps.
    """
    gains = law.gains
    reach, d_t, eps, c_max = params.reach, params.d_t, law.eps, params.c_max
    function, couples, at_crossing = law.function, law.couples, law.at_crossing
    n_cases = e0.shape[0]
    for block in numba.prange((n_cases + LANES - 1) // LANES):
        first = block * LANES
        lanes = min(LANES, n_cases - first)
        e = _lane_states(e0, first, lanes)
        u = np.zeros((LANES, 1))  # each case's U_1 - U_0 as the step takes it
        no_body = np.empty((LANES, 0))
        flag = np.zeros(LANES, dtype=np.int64)
        armed = np.ones(LANES, dtype=np.int64)
        r_before = np.full(LANES, np.nan)
        lowest = np.full(LANES, np.inf)
        coupled_at = np.full(LANES, -1)
        uncoupled_at = np.full(LANES, -1)
        k = np.zeros(LANES, dtype=np.int64)
        running = lanes
        while running > 0:
            running = 0
            for c in range(lanes):  # one step (or one skip) of every case still running
                if k[c] > n_steps:
                    continue
                running += 1
                if k[c] == command_step:
                    armed[c] = 0
                # P* (6) of the relative state, written out for the four states of (2): this loop is
                # compiled with fused multiply-adds, and the sum written out fuses as it always has
                # (tmem.law.modal.corrected_position's loop fuses otherwise: results 1e-12 apart).
                d = (e[c, 0, 0] * gains[0, 0] + e[c, 0, 1] * gains[0, 1] + e[c, 0, 2] * gains[0, 2]
                     + e[c, 0, 3] * gains[0, 3]) / gains[0, 0]  # fmt: skip
                r = abs(d)
                lowest[c] = min(lowest[c], abs(e[c, 0, 0]))
                # Free flight: uncoupled, out of reach, level (the tilt has died out).  Then
                # d = P + (K_V / K_P) V moves at the constant rate V, so the flight is skipped in
                # closed form: to the end if the pair separates, else to just before it meets.
                if flag[c] == 0 and r > reach + eps and level(e, c, 0) and k[c] < n_steps:
                    if _skip_free_flight(e, armed, r_before, k, c, d, r - reach - eps, n_steps, command_step, dt):
                        continue
                if couples:
                    _flag_step(flag, armed, r_before, coupled_at, uncoupled_at, c, k[c], r, d_t, eps, at_crossing)
                u0 = _push_on_first(function, r, flag[c], params, d, c_max)
                if k[c] < n_steps:
                    u[c, 0] = -2.0 * u0
                    _linear_step(e, no_body, u, c, 1.0, hold, 1)
                k[c] += 1
        for lane in range(lanes):
            for m in range(e0.shape[1]):
                e_end[first + lane, m] = e[lane, 0, m]
            min_dist[first + lane] = lowest[lane]
            couple_step[first + lane] = coupled_at[lane]
            uncouple_step[first + lane] = uncoupled_at[lane]
