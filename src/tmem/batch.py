"""Many two-agent, one-axis encounters at once: the paper's case as a vectorised batch.

For two agents on one axis the pushes are equal and opposite, also after
saturation (the clip is odd), so the sum ``x_0 + x_1`` flies free and only
the relative state ``e = x_1 - x_0`` feels the interaction::

    e[k+1] = Ad e[k] + Bd (U_1 - U_0) = Ad e[k] - 2 Bd U_0,
    U_0 = sat(f(|d|) sign(d)),   d = K . e / K_P   (6)

One step of one case is then a handful of multiply-adds, and cases are
independent, so a batch runs them side by side in one compiled loop.  Free
flight (uncoupled, out of reach, the tilt died out) moves ``d`` at a constant
rate and is skipped in closed form: to the end once the pair separates, to
just before contact while it closes.  The
figures are those of :func:`tmem.metrics.summarize` for the same scenario
(tests compare the two), without recording trajectories.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from . import _numba_cache, coupling  # noqa: F401  (_numba_cache: drops stale compiled code first)
from .control import corrected_position, gains_for
from .engine.driver import law_of
from .interaction.kernels import pair_control
from .model import vehicle_model
from .model.linear import hold_step
from .scenario import LIMIT, Scenario


@dataclass(frozen=True)
class BatchResult:
    """Per-case figures, each an array over cases (NaN where an event did not happen)."""

    rms_velocity_initial: np.ndarray
    rms_velocity_final: np.ndarray
    rms_change_percent: np.ndarray
    min_distance: np.ndarray
    final_distance: np.ndarray
    couple_time: np.ndarray
    uncouple_time: np.ndarray
    final_velocities: np.ndarray  # (cases, 2)

    @property
    def coupled(self) -> np.ndarray:
        """Whether each case coupled, shape (cases,), bool."""
        return ~np.isnan(self.couple_time)


#: Cases advanced side by side in one loop.  One case's step depends on its last, so alone it waits
#: on its own arithmetic; interleaving independent cases lets the processor overlap them.
LANES = 8


@numba.njit(cache=True, inline="always")
def _free_flight_steps(d, velocity, steps_left, gap, dt):
    """Steps a free pair (uncoupled, level, ``gap`` m beyond reach and window) may skip: every step
    left if it separates (``d`` grows), else those before it could close the gap at ``velocity``."""
    closing = -velocity if d > 0 else velocity
    if closing <= 0.0:
        return steps_left
    return min(steps_left, int(gap / (closing * dt)) - 1)


# fastmath "contract" only: the multiply-adds may fuse (one rounding instead of two); NaN and
# infinity keep their meaning, which the flag logic relies on (r_before is NaN after a skip).
@numba.njit(cache=True, parallel=True, error_model="numpy", fastmath={"contract"})
def _run_batch(e0, n_steps, dt, command_step, hold, law, params, e_end, min_dist, couple_step, uncouple_step):
    """Advance each case of ``e0`` (cases, 4) ``n_steps`` steps of ``dt`` under ``law`` with the
    functions' parameters ``params`` and the zero-order hold ``hold`` of the linear model; write each
    case's end, smallest distance, and the steps it first coupled and uncoupled (-1: never).
    (Records are used inside the parallel loop only as arguments: see :class:`tmem.engine.records.Law`.)
    The two agents of a case are alike: ``P*`` (6) of their relative state uses the law's first row of gains."""
    gains = law.gains
    reach, d_t, eps, c_max = params.reach, params.d_t, law.eps, params.c_max
    function, couples, at_crossing = law.function, law.couples, law.at_crossing
    ad, bd = hold.ad, hold.bd
    n_cases = e0.shape[0]
    for block in numba.prange((n_cases + LANES - 1) // LANES):
        first = block * LANES
        lanes = min(LANES, n_cases - first)
        e_p = np.empty(LANES)
        e_v = np.empty(LANES)
        e_phi = np.empty(LANES)
        e_om = np.empty(LANES)
        flag = np.zeros(LANES, dtype=np.int64)
        armed = np.ones(LANES, dtype=np.int64)
        r_before = np.full(LANES, np.nan)
        lowest = np.full(LANES, np.inf)
        coupled_at = np.full(LANES, -1)
        uncoupled_at = np.full(LANES, -1)
        k = np.zeros(LANES, dtype=np.int64)
        for lane in range(lanes):
            e_p[lane], e_v[lane], e_phi[lane], e_om[lane] = e0[first + lane]
        running = lanes
        while running > 0:
            running = 0
            for c in range(lanes):  # one step (or one skip) of every case still running
                if k[c] > n_steps:
                    continue
                running += 1
                if k[c] == command_step:
                    armed[c] = 0
                d = corrected_position(e_p[c], e_v[c], e_phi[c], e_om[c], gains, 0)
                r = abs(d)
                lowest[c] = min(lowest[c], abs(e_p[c]))
                # Free flight: uncoupled, out of reach, level (the tilt has died out).  Then
                # d = P + (K_V / K_P) V moves at the constant rate V, so the flight is skipped in
                # closed form: to the end if the pair separates, else to just before it meets.
                if flag[c] == 0 and r > reach + eps and abs(e_phi[c]) < 1e-13 and abs(e_om[c]) < 1e-12 and k[c] < n_steps:
                    skip = _free_flight_steps(d, e_v[c], n_steps - k[c], r - reach - eps, dt)
                    if skip > 1:
                        if k[c] < command_step <= k[c] + skip:
                            armed[c] = 0
                        e_p[c] += e_v[c] * (skip * dt)
                        k[c] += skip
                        r_before[c] = np.nan
                        continue
                if couples:
                    new = coupling.next_flag(flag[c], armed[c], r_before[c], r, d_t, eps, at_crossing)
                    if new != flag[c]:
                        if new == 1 and coupled_at[c] < 0:
                            coupled_at[c] = k[c]
                        if new == 0 and uncoupled_at[c] < 0:
                            uncoupled_at[c] = k[c]
                        flag[c] = new
                    r_before[c] = r
                u0 = 0.0
                if r > 0.0:
                    u0 = pair_control(function, r, flag[c], params) * (1.0 if d > 0 else -1.0)
                    u0 = min(max(u0, -c_max), c_max)
                if k[c] < n_steps:
                    e_p[c], e_v[c], e_phi[c], e_om[c] = hold_step(ad, bd, e_p[c], e_v[c], e_phi[c], e_om[c], -2.0 * u0)
                k[c] += 1
        for lane in range(lanes):
            e_end[first + lane] = (e_p[lane], e_v[lane], e_phi[lane], e_om[lane])
            min_dist[first + lane] = lowest[lane]
            couple_step[first + lane] = coupled_at[lane]
            uncouple_step[first + lane] = uncoupled_at[lane]


def unsupported(scenario: Scenario) -> str | None:
    """Why ``scenario``'s cases cannot run as a batch, or ``None`` if they can.

    A batch needs the paper's case: one axis, two agents flying from the
    start without a formation, at most one command (an uncouple).  Only the
    agents' positions and velocities vary; their tilts and tilt rates start at
    zero.

    Parameters
    ----------
    scenario : Scenario
        The base scenario of the cases.
    """
    if scenario.model.kind != "linear":
        return "needs the linear model (2): a batch steps the pair's relative state"
    if scenario.space.axes != 1 or len(scenario.agents) != 2 or scenario.formation is not None:
        return "needs a one-axis scenario with two agents listed in [[agents]], without a formation"
    if len(scenario.commands) > 1 or any(c.action != "uncouple" for c in scenario.commands):
        return "at most one command, an uncouple"
    if any(a.tilt != 0 or a.tilt_rate != 0 or not a.active for a in scenario.agents):
        return "the agents must start level (tilt and tilt rate zero) and flying"
    if scenario.interaction.uncouple_when != "window" or scenario.interaction.synchronise:
        return "the batch uncouples by the window (9) and does not synchronise"
    return None


def _starts(name: str, values, cases: int | None) -> np.ndarray:
    """``values`` as a float array of shape (cases, 2), finite and bounded as a scenario's; else ValueError."""
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"run_batch: {name}: must be numbers, shape (cases, 2) ({exc})") from None
    if array.ndim != 2 or array.shape[1] != 2 or len(array) == 0:
        raise ValueError(f"run_batch: {name}: must have shape (cases, 2) with at least one case, got {array.shape}")
    if cases is not None and len(array) != cases:
        raise ValueError(f"run_batch: {name}: has {len(array)} cases, positions has {cases}")
    bad = ~np.isfinite(array) | (np.abs(array) > LIMIT)
    if bad.any():
        case, agent = np.argwhere(bad)[0]
        raise ValueError(
            f"run_batch: {name}[{case}, {agent}]: must be a finite number of magnitude at most {LIMIT:g}, got {array[case, agent]}"
        )
    return array


def run_batch(scenario: Scenario, positions: np.ndarray, velocities: np.ndarray) -> BatchResult:
    """Run ``scenario`` once per case, with the two agents' starts taken from the arrays.

    Parameters
    ----------
    scenario
        A one-axis, two-agent scenario; everything but the agents' start is
        shared by all cases.  At most one command, an uncouple of the pair.
    positions, velocities : ndarray, shape (cases, 2)
        Each case's start (tilts and tilt rates zero).

    Raises
    ------
    ValueError
        One line naming the argument, as ``tmem run`` refuses a scenario: a
        scenario a batch cannot run, starts of the wrong shape, not finite,
        or two agents at one place.
    """
    if not isinstance(scenario, Scenario):
        raise ValueError(f"run_batch: scenario: must be a tmem Scenario, got {type(scenario).__name__}")
    reason = unsupported(scenario)
    if reason:
        raise ValueError(f"run_batch: {reason}")
    positions = _starts("positions", positions, None)
    velocities = _starts("velocities", velocities, len(positions))
    same = np.flatnonzero(positions[:, 0] == positions[:, 1])
    if len(same):
        raise ValueError(
            f"run_batch: positions[{same[0]}]: both agents at {positions[same[0], 0]}: "
            "two agents at one point have no direction to part in"
        )
    c, sim = scenario.controller, scenario.simulation
    model = vehicle_model(scenario.model)
    hold = model.step_params(sim.dt)
    linearisation = model.linearisation()
    law, params = law_of(scenario, linearisation, gains_for(*linearisation, c.r_l, c.im_l, c.im_r))
    cases = len(positions)
    start = np.zeros((cases, 2, 4))
    start[:, :, 0] = positions
    start[:, :, 1] = velocities
    relative = start[:, 1] - start[:, 0]
    total = start[:, 1] + start[:, 0]
    n_steps = sim.n_steps
    command_step = sim.step_of(scenario.commands[0].time) if scenario.commands else -1
    e_end = np.empty((cases, 4))
    min_dist = np.empty(cases)
    couple_step = np.empty(cases, dtype=np.int64)
    uncouple_step = np.empty(cases, dtype=np.int64)
    _run_batch(relative, n_steps, sim.dt, command_step, hold, law, params, e_end, min_dist, couple_step, uncouple_step)
    total_end = total @ np.linalg.matrix_power(hold.ad, n_steps).T  # the sum flies free
    v0 = (total_end[:, 1] - e_end[:, 1]) / 2
    v1 = (total_end[:, 1] + e_end[:, 1]) / 2
    rms0 = np.sqrt((velocities**2).mean(axis=1))
    rms1 = np.sqrt((v0**2 + v1**2) / 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        change = np.where(rms0 > 0, 100.0 * (rms1 / rms0 - 1.0), np.nan)
    return BatchResult(
        rms_velocity_initial=rms0,
        rms_velocity_final=rms1,
        rms_change_percent=change,
        min_distance=min_dist,
        final_distance=np.abs(e_end[:, 0]),
        couple_time=np.where(couple_step >= 0, couple_step * sim.dt, np.nan),
        uncouple_time=np.where(uncouple_step >= 0, uncouple_step * sim.dt, np.nan),
        final_velocities=np.stack([v0, v1], axis=1),
    )
