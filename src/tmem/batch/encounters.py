"""Many two-agent encounters at once: the paper's case, and its like in 2-D and 3-D, as a batch.

Each case is two agents flying from level starts, with no other agent, in
open space; only their starts differ.  A batch runs the cases side by side,
:data:`LANES` at a time in one compiled loop, each case with the step
loop's own formation-pair stage (:func:`tmem.engine.pairs.formation_pair`:
the flag (9) or the energy rule, the pull (10)/(11), the synchronisation
(S2)) and the vehicle model's step, so that a case gives what
:func:`tmem.simulate` gives for it.

The paper's own case, one axis under the window rule (9) without
synchronisation, reduces to the pair's relative state and runs about three
times faster (:mod:`tmem.batch.relative`); every other case steps both agents.
What the batch adds is free flight in closed form.  A pair that is uncoupled,
out of reach, level (its tilts died out) and not holding a synchronised
energy feels no push, so its agents fly at constant velocity and the pair's
``P*_j - P*_i`` (``P* = P + (K_V / K_P) V`` when level) moves at their relative
velocity ``w``: the flight is skipped to the end if
``|P*_j - P*_i|`` never comes back within ``R + R_j + eps``, else to just
before it does.  The smallest distance over a skip is found in closed form.
The figures are those of :func:`tmem.analysis.metrics.summarize` for the same
scenario (tests compare the two), without recording trajectories.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law import coupling
from tmem.batch.free_flight import level
from tmem.law.modal import corrected_position, gains_row, tilt_scale
from tmem.law.record import law_of
from tmem.engine.pairs import formation_pair
from tmem.engine.records import Agents, Counters, Events, Pairs
from tmem.vehicles import vehicle_model
from tmem.vehicles.linear import LinearModel
from tmem.batch.relative import LANES, run_relative
from tmem.scenario import LIMIT, Scenario


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
    uncouple_rule: np.ndarray  # what released the pair (tmem.law.coupling.RELEASES), None if nothing did
    final_velocities: np.ndarray  # (cases, 2, axes)

    @property
    def coupled(self) -> np.ndarray:
        """Whether each case coupled, shape (cases,), bool."""
        return ~np.isnan(self.couple_time)



#: The linear model's exact step (2), which the batch takes.
_linear_step = LinearModel.kernel()


@numba.njit(cache=True, error_model="numpy", inline="always")
def _free_flight_steps(x, corrected, i, j, reach, steps_left, dt):
    """Steps the free pair ``(i, j)`` may skip: every step left if ``|P*_j - P*_i|`` does not come back
    within ``reach`` at the relative velocity ``w`` (level, ``P*`` moves at ``V``), else those before it could."""
    b = 0.0  # d . w
    w2 = 0.0
    d2 = 0.0
    for a in range(x.shape[1]):
        d = corrected[j, a, 0] - corrected[i, a, 0]
        w = x[j, a, 1] - x[i, a, 1]
        b += d * w
        w2 += w * w
        d2 += d * d
    disc = b * b - w2 * (d2 - reach * reach)
    if b >= 0.0 or disc < 0.0:  # parting, or passing wide
        return steps_left
    t = (-b - np.sqrt(disc)) / w2
    return min(steps_left, int(t / dt) - 1)


@numba.njit(cache=True, error_model="numpy", inline="always")
def _closest_in_flight(x, i, j, steps, dt):
    """The smallest ``|P_j - P_i|`` at the steps ``0 .. steps - 1`` of a free flight of the pair."""
    b = 0.0
    w2 = 0.0
    for a in range(x.shape[1]):
        b += (x[j, a, 0] - x[i, a, 0]) * (x[j, a, 1] - x[i, a, 1])
        w2 += (x[j, a, 1] - x[i, a, 1]) ** 2
    nearest = np.inf
    at = 0.0 if w2 == 0.0 else -b / (w2 * dt)  # the closest step, between two whole ones
    for m in (np.floor(at), np.floor(at) + 1.0):
        m = min(max(m, 0.0), steps - 1.0)
        dist2 = 0.0
        for a in range(x.shape[1]):
            dist2 += (x[j, a, 0] - x[i, a, 0] + (x[j, a, 1] - x[i, a, 1]) * m * dt) ** 2
        nearest = min(nearest, np.sqrt(dist2))
    return nearest


@numba.njit(cache=True, error_model="numpy", inline="always")
def _is_free(x, e, pairs, r, reach):
    """Pair ``e`` feels nothing this step: uncoupled, ``|d|`` beyond ``reach``, level, holding no energy."""
    if pairs.flag[e] != 0 or r <= reach or not np.isnan(pairs.kept_speed2[e]):
        return False
    for s in (pairs.i[e], pairs.j[e]):
        for a in range(x.shape[1]):
            if not level(x, s, a):
                return False
    return True


@numba.njit(cache=True, error_model="numpy", inline="always")
def _case_step(k, e, x, agents, pairs, law, params, box, hold, command_step, n_steps, dt, events, counters):
    """One step of case ``e`` (agents ``2e``, ``2e + 1``) from step ``k``, or one skip of its free flight;
    return the step it reaches."""
    i = pairs.i[e]
    j = pairs.j[e]
    n_axes = len(box)
    if k == command_step:
        pairs.armed[e] = 0
        pairs.disarmed_at[e] = k
    r2 = 0.0
    for s in (i, j):
        for a in range(n_axes):
            agents.corrected[s, a, 0] = corrected_position(x, s, a, law.gains, gains_row(law.gains, s - i))
            agents.corrected[s, a, 1] = x[s, a, 0]
            agents.setpoint[s, a] = 0.0
    for a in range(n_axes):
        r2 += (agents.corrected[j, a, 0] - agents.corrected[i, a, 0]) ** 2
    if k < n_steps and _is_free(x, e, pairs, np.sqrt(r2), params.reach + law.eps):
        skip = _free_flight_steps(x, agents.corrected, i, j, params.reach + law.eps, n_steps - k, dt)
        if skip > 1:
            if k < command_step <= k + skip:
                pairs.armed[e] = 0
                pairs.disarmed_at[e] = command_step
            pairs.min_distance[e] = min(pairs.min_distance[e], _closest_in_flight(x, i, j, skip, dt))
            for s in (i, j):
                for a in range(n_axes):
                    x[s, a, 0] += x[s, a, 1] * (skip * dt)
            pairs.r_before[e] = np.nan
            return k + skip
    formation_pair(k, e, x, agents, pairs, law, params, box, events, counters)
    if k < n_steps:
        for s in (i, j):
            _linear_step(x, agents.body, agents.setpoint, s, tilt_scale(agents.setpoint, s, n_axes, params.c_max), hold, n_axes)
    return k + 1


@numba.njit(cache=True, error_model="numpy", _nrt=False)
def _advance_block(k, x, agents, pairs, law, params, box, hold, command_step, n_steps, dt, events, counters):
    """Every case of a block to its end: one step (or one skip) of each in turn, so that the
    processor overlaps independent cases.  Without Numba's runtime, as the step loop
    (:mod:`tmem.engine.loop`): a reference count on every record field read made it three times slower."""
    running = len(k)
    while running > 0:
        running = 0
        for c in range(len(k)):
            if k[c] <= n_steps:
                running += 1
                k[c] = _case_step(k[c], c, x, agents, pairs, law, params, box, hold, command_step, n_steps, dt, events, counters)


@numba.njit(cache=True, error_model="numpy")
def _run_block(first, lanes, starts, n_steps, dt, command_step, hold, law, params, box, ends, min_dist, couple_step, uncouple_step, rule):
    """Cases ``first .. first + lanes - 1`` of :func:`_run_batch`, side by side, with records of their own
    as the step loop's for a swarm of ``2 lanes`` agents.  (Called from the parallel loop, not inlined
    in it: a parallel loop takes records only as arguments.)"""
    n_axes = len(box)
    x = np.zeros((2 * lanes, n_axes, 4))
    for c in range(lanes):
        x[2 * c : 2 * c + 2] = starts[first + c]
    no_body = np.zeros((2 * lanes, 0))  # the linear model has no body state
    agents = Agents(x, x, np.ones(2 * lanes, dtype=np.bool_), np.zeros((2 * lanes, n_axes, 2)), np.zeros((2 * lanes, n_axes)),
                    no_body, no_body)
    nan = np.full(lanes, np.nan)
    pairs = Pairs(np.arange(0, 2 * lanes, 2), np.arange(1, 2 * lanes, 2), np.full(lanes, params.d_t),
                  np.full((lanes, n_axes), np.nan), np.zeros(lanes, dtype=np.int64), np.ones(lanes, dtype=np.int64),
                  nan.copy(), np.full(lanes, np.inf), nan.copy(), nan.copy(), nan.copy(), nan.copy(),
                  np.zeros(lanes, dtype=np.int64), np.empty(n_axes))  # fmt: skip
    room = 4 * lanes  # a case couples once before the command and uncouples once after it
    events = Events(np.empty(room, dtype=np.int64), np.empty(room, dtype=np.int64), np.empty(room, dtype=np.int64),
                    np.empty(room, dtype=np.int64), np.empty(room, dtype=np.int64), np.empty(room, dtype=np.int64))  # fmt: skip
    counters = Counters(np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64),
                        np.zeros(1, dtype=np.int64))  # fmt: skip
    _advance_block(np.zeros(lanes, dtype=np.int64), x, agents, pairs, law, params, box, hold, command_step, n_steps, dt,
                   events, counters)  # fmt: skip
    for c in range(lanes):
        ends[first + c] = x[2 * c : 2 * c + 2]
        min_dist[first + c] = pairs.min_distance[c]
        couple_step[first + c] = -1
        uncouple_step[first + c] = -1
        rule[first + c] = -1
    for n in range(counters.n_events[0]):
        c = first + events.i[n] // 2
        if events.kind[n] == coupling.EVENT_COUPLE and couple_step[c] < 0:
            couple_step[c] = events.step[n]
        if events.kind[n] == coupling.EVENT_UNCOUPLE and uncouple_step[c] < 0:
            uncouple_step[c] = events.step[n]
            rule[c] = events.rule[n]


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _run_batch(starts, n_steps, dt, command_step, hold, law, params, box, ends, min_dist, couple_step, uncouple_step, rule):
    """Advance each case of ``starts`` (cases, 2, axes, 4) ``n_steps`` steps of ``dt`` under ``law`` with the
    functions' parameters ``params`` and the zero-order hold ``hold`` of the linear model; write each
    case's end state, smallest distance, the steps it first coupled and uncoupled (-1: never) and the
    rule that released it (-1: none).  Blocks of :data:`LANES` cases run on the threads."""
    n_cases = starts.shape[0]
    for block in numba.prange((n_cases + LANES - 1) // LANES):
        first = block * LANES
        _run_block(first, min(LANES, n_cases - first), starts, n_steps, dt, command_step, hold, law, params, box,
                   ends, min_dist, couple_step, uncouple_step, rule)  # fmt: skip


def unsupported(scenario: Scenario) -> str | None:
    """Why ``scenario``'s cases cannot run as a batch, or ``None`` if they can.

    A batch needs encounters of two agents: two agents listed, flying from
    level starts (tilts and tilt rates zero), without a formation, in open
    space on any number of axes (no walls, obstacles or gas options), with at
    most one command (an uncouple), on the linear model.  Only the agents' positions and velocities vary.

    Parameters
    ----------
    scenario : Scenario
        The base scenario of the cases.
    """
    if scenario.model.kind != "linear":
        return "needs the linear model (2), whose exact step the batch takes"
    if len(scenario.agents) != 2 or scenario.formation is not None:
        return "needs two agents listed in [[agents]], without a formation"
    if scenario.space.periodic or scenario.space.walls or scenario.obstacles:
        return "needs open space: free flight is skipped in closed form, without walls, obstacles or a box to wrap in"
    if scenario.gas_observed:
        return "the gas's options (thermostat, mean of pushes, observed totals) are the step loop's"
    if scenario.agent_terms:
        return f"the agent terms ({', '.join(f'[{name}]' for name in scenario.agent_terms)}) are the step loop's"
    if scenario.sensing is not None and not scenario.sensing.exact:
        return "the agents measure each other exactly: sensing effects ([sensing]) are the step loop's"
    if len(scenario.commands) > 1 or any(c.action != "uncouple" for c in scenario.commands):
        return "at most one command, an uncouple"
    if any(not np.all(np.equal(a.tilt, 0)) or not np.all(np.equal(a.tilt_rate, 0)) or not a.active for a in scenario.agents):
        return "the agents must start level (tilt and tilt rate zero) and flying"
    return None


def _starts(name: str, values, cases: int | None, n_axes: int) -> np.ndarray:
    """``values`` as a float array of shape (cases, 2, axes), finite and bounded as a scenario's; else ValueError."""
    shape = "(cases, 2)" if n_axes == 1 else f"(cases, 2, {n_axes})"
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"run_batch: {name}: must be numbers, shape {shape} ({exc})") from None
    if n_axes == 1 and array.ndim == 2:
        array = array[:, :, np.newaxis]
    if array.ndim != 3 or array.shape[1:] != (2, n_axes) or len(array) == 0:
        raise ValueError(f"run_batch: {name}: must have shape {shape} with at least one case, got {np.shape(values)}")
    if cases is not None and len(array) != cases:
        raise ValueError(f"run_batch: {name}: has {len(array)} cases, positions has {cases}")
    bad = ~np.isfinite(array) | (np.abs(array) > LIMIT)
    if bad.any():
        where = np.argwhere(bad)[0]
        at = ", ".join(str(w) for w in (where[:2] if n_axes == 1 else where))
        raise ValueError(f"run_batch: {name}[{at}]: must be a finite number of magnitude at most {LIMIT:g}, got {array[tuple(where)]}")
    return array


def run_batch(scenario: Scenario, positions: np.ndarray, velocities: np.ndarray) -> BatchResult:
    """Run ``scenario`` once per case, with the two agents' starts taken from the arrays.

    Parameters
    ----------
    scenario
        A scenario of two agents (:func:`unsupported` says what it must be); everything but the
        agents' start is shared by all cases.
    positions, velocities : ndarray, shape (cases, 2, axes), or (cases, 2) on one axis
        Each case's start (tilts and tilt rates zero).

    Raises
    ------
    ValueError
        One line naming the argument, as ``tmem run`` refuses a scenario: a
        scenario a batch cannot run, starts of the wrong shape, not finite,
        or two agents at one place.
    """
    positions, velocities = _checked_starts(scenario, positions, velocities)
    c, sim = scenario.controller, scenario.simulation
    model = vehicle_model(scenario.model)
    linearisation = model.linearisation()
    law, params = law_of(scenario, linearisation, model.gains(c.r_l, c.im_l, c.im_r))
    command_step = sim.step_of(scenario.commands[0].time) if scenario.commands else -1
    hold = model.step_params(sim.dt)
    cases = len(positions)
    starts = np.zeros((cases, 2, scenario.space.axes, 4))
    starts[..., 0] = positions
    starts[..., 1] = velocities
    min_dist = np.empty(cases)
    couple_step = np.empty(cases, dtype=np.int64)
    uncouple_step = np.empty(cases, dtype=np.int64)
    written = (min_dist, couple_step, uncouple_step)
    steps = (sim.n_steps, sim.dt, command_step, hold, law, params)
    if scenario.space.axes == 1 and law.uncouple_rule == coupling.UNCOUPLE_BY_WINDOW and law.sync_gain == 0.0:
        final_velocities, final_distance, rule = _fly_relative(starts, steps, written)
    else:
        final_velocities, final_distance, rule = _fly_pairs(starts, steps, written)
    rms0 = np.sqrt((velocities**2).sum(axis=2).mean(axis=1))
    rms1 = np.sqrt((final_velocities**2).sum(axis=2).mean(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        change = np.where(rms0 > 0, 100.0 * (rms1 / rms0 - 1.0), np.nan)
    return BatchResult(
        rms_velocity_initial=rms0,
        rms_velocity_final=rms1,
        rms_change_percent=change,
        min_distance=min_dist,
        final_distance=final_distance,
        couple_time=np.where(couple_step >= 0, couple_step * sim.dt, np.nan),
        uncouple_time=np.where(uncouple_step >= 0, uncouple_step * sim.dt, np.nan),
        uncouple_rule=np.array([coupling.RELEASES[r] if r >= 0 else None for r in rule], dtype=object),
        final_velocities=final_velocities,
    )


def _checked_starts(scenario: Scenario, positions, velocities) -> tuple[np.ndarray, np.ndarray]:
    """The starts as arrays of shape (cases, 2, axes), the scenario and the starts checked as
    :func:`run_batch` says."""
    if not isinstance(scenario, Scenario):
        raise ValueError(f"run_batch: scenario: must be a tmem Scenario, got {type(scenario).__name__}")
    reason = unsupported(scenario)
    if reason:
        raise ValueError(f"run_batch: {reason}")
    n_axes = scenario.space.axes
    positions = _starts("positions", positions, None, n_axes)
    velocities = _starts("velocities", velocities, len(positions), n_axes)
    same = np.flatnonzero(np.all(positions[:, 0] == positions[:, 1], axis=1))
    if len(same):
        raise ValueError(
            f"run_batch: positions[{same[0]}]: both agents at {positions[same[0], 0].tolist() if n_axes > 1 else positions[same[0], 0, 0]}: "
            "two agents at one point have no direction to part in"
        )
    return positions, velocities


def _fly_relative(starts: np.ndarray, steps: tuple, written: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The paper's case on one axis, on the pair's relative state (:mod:`tmem.batch.relative`); the sum
    of the states flies free.  ``steps``: ``(n_steps, dt, command_step, hold, law, params)``;
    ``written``: ``(min_dist, couple_step, uncouple_step)``, filled.  Returns the final velocities,
    the final distances and each case's release rule."""
    n_steps, dt, command_step, hold, law, params = steps
    min_dist, couple_step, uncouple_step = written
    relative = starts[:, 1, 0] - starts[:, 0, 0]
    e_end = np.empty((len(starts), 4))
    run_relative(relative, n_steps, dt, command_step, hold, law, params, e_end, min_dist, couple_step, uncouple_step)
    total_end = (starts[:, 1, 0] + starts[:, 0, 0]) @ np.linalg.matrix_power(hold.ad, n_steps).T  # the sum flies free
    final_velocities = np.stack([(total_end[:, 1] - e_end[:, 1]) / 2, (total_end[:, 1] + e_end[:, 1]) / 2], axis=1)[:, :, None]
    final_distance = np.abs(e_end[:, 0])
    rule = np.where(uncouple_step >= 0, coupling.RELEASES.index("window"), -1)
    return final_velocities, final_distance, rule


def _fly_pairs(starts: np.ndarray, steps: tuple, written: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Both agents of every case stepped (:func:`_run_batch`); arguments and results as :func:`_fly_relative`'s."""
    n_steps, dt, command_step, hold, law, params = steps
    min_dist, couple_step, uncouple_step = written
    ends = np.empty_like(starts)
    rule = np.empty(len(starts), dtype=np.int64)
    _run_batch(starts, n_steps, dt, command_step, hold, law, params, (0.0,) * starts.shape[2],
               ends, min_dist, couple_step, uncouple_step, rule)  # fmt: skip
    final_velocities = ends[..., 1]
    final_distance = np.linalg.norm(ends[:, 1, :, 0] - ends[:, 0, :, 0], axis=1)
    return final_velocities, final_distance, rule
