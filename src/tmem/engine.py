"""The step loop: scenario in, recorded trajectory and events out.

State is kept as arrays shaped ``(agents, axes, 4)`` (the paper's case is one
axis).  Each step ``k`` (time ``k dt``):

1. operator commands due at step ``k`` arm or disarm their pairs;
2. every agent's corrected position ``P*`` (6) is formed;
3. for every pair, the pair measure ``d = P*_j - P*_i`` updates the flag
   ``F_en`` (:mod:`tmem.coupling`) and gives the control contribution
   (:mod:`tmem.interaction`), applied along ``d / |d|`` to ``i`` and opposite
   to ``j``;
4. each agent's summed set-point is saturated at ``c_max`` per axis (a single
   neighbour's contribution is already within it);
5. the step is recorded if ``k`` is a multiple of ``record_every`` (and always
   at the last step);
6. the state advances with the exact zero-order hold of (2) over ``dt``.

The loop is compiled with Numba and runs in chunks so that a caller can show
progress between them.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from . import coupling, interaction
from .control import modal_gains
from .model import state_matrices, zero_order_hold
from .neighbors import all_pairs
from .scenario import Scenario


@dataclass(frozen=True)
class Event:
    """A coupling transition or an operator command."""

    time: float
    kind: str  # "command" | "couple" | "uncouple"
    agents: tuple[int, int]
    action: str | None = None  # for commands: "couple" | "uncouple"


@dataclass(frozen=True)
class Trajectory:
    """What a run produced.

    Attributes
    ----------
    scenario : Scenario
    gains : ndarray, shape (4,)
        ``K = (K_P, K_V, K_phi, K_omega)``.
    time : ndarray, shape (n_records,)
    state : ndarray, shape (n_records, agents, axes, 4)
        ``(P, V, phi, omega)`` at each recorded time.
    control : ndarray, shape (n_records, agents, axes)
        The tilt set-point ``U`` applied from that time on.
    pairs : ndarray, shape (n_pairs, 2)
    flag : ndarray, shape (n_records, n_pairs)
        ``F_en`` of each pair at each recorded time (after that step's check).
    min_distance : ndarray, shape (n_pairs,)
        Smallest distance ``|P_j - P_i|`` of each pair over every step.
    events : list of Event
    """

    scenario: Scenario
    gains: np.ndarray
    time: np.ndarray
    state: np.ndarray
    control: np.ndarray
    pairs: np.ndarray
    flag: np.ndarray
    min_distance: np.ndarray
    events: list[Event]


@numba.njit(cache=True)
def _advance(
    k_start, k_stop, n_steps, record_every,
    x, ad, bd, gains, function, k_p, reach, d_t, eps, c_max, coupled_function,
    pairs, armed, flag, min_distance,
    command_step, command_pair, command_arm, next_command,
    rec_state, rec_control, rec_flag, next_record,
    event_step, event_kind, event_pair, event_action, n_events,
):  # fmt: skip
    n_agents, n_axes, _ = x.shape
    n_pairs = pairs.shape[0]
    p_star = np.empty((n_agents, n_axes))
    u = np.empty((n_agents, n_axes))
    d = np.empty(n_axes)
    x_new = np.empty(4)
    for k in range(k_start, k_stop):
        # 1. operator commands
        while next_command < command_step.shape[0] and command_step[next_command] <= k:
            c = next_command
            for p in range(n_pairs):
                if command_pair[c] < 0 or command_pair[c] == p:
                    armed[p] = command_arm[c]
            event_step[n_events] = k
            event_kind[n_events] = coupling.EVENT_COMMAND
            event_pair[n_events] = command_pair[c]
            event_action[n_events] = command_arm[c]
            n_events += 1
            next_command += 1
        # 2. corrected positions (6)
        for i in range(n_agents):
            for a in range(n_axes):
                s = 0.0
                for m in range(4):
                    s += x[i, a, m] * gains[m]
                p_star[i, a] = s / gains[0]
                u[i, a] = 0.0
        # 3. pairs: flag and control
        for p in range(n_pairs):
            i = pairs[p, 0]
            j = pairs[p, 1]
            r2 = 0.0
            dist2 = 0.0
            for a in range(n_axes):
                d[a] = p_star[j, a] - p_star[i, a]
                r2 += d[a] * d[a]
                dist2 += (x[j, a, 0] - x[i, a, 0]) ** 2
            r = np.sqrt(r2)
            dist = np.sqrt(dist2)
            if dist < min_distance[p]:
                min_distance[p] = dist
            if coupled_function:
                new = coupling.next_flag(flag[p], armed[p], r, d_t, eps)
                if new != flag[p]:
                    flag[p] = new
                    event_step[n_events] = k
                    event_kind[n_events] = coupling.EVENT_COUPLE if new == 1 else coupling.EVENT_UNCOUPLE
                    event_pair[n_events] = p
                    event_action[n_events] = -1
                    n_events += 1
            if r > 0.0:
                push = interaction.pair_control(function, r, flag[p], k_p, reach, d_t, c_max) / r
                for a in range(n_axes):
                    u[i, a] += push * d[a]
                    u[j, a] -= push * d[a]
        # 4. saturation of the summed set-point
        for i in range(n_agents):
            for a in range(n_axes):
                u[i, a] = min(max(u[i, a], -c_max), c_max)
        # 5. recording
        if k % record_every == 0 or k == n_steps:
            rec_state[next_record] = x
            rec_control[next_record] = u
            rec_flag[next_record] = flag
            next_record += 1
        # 6. exact zero-order-hold step of (2)
        if k < n_steps:
            for i in range(n_agents):
                for a in range(n_axes):
                    for m in range(4):
                        s = bd[m] * u[i, a]
                        for q in range(4):
                            s += ad[m, q] * x[i, a, q]
                        x_new[m] = s
                    for m in range(4):
                        x[i, a, m] = x_new[m]
    return next_command, next_record, n_events


def record_steps(n_steps: int, record_every: int) -> np.ndarray:
    """The step indices that are recorded: multiples of ``record_every`` and the last step."""
    steps = np.arange(0, n_steps + 1, record_every)
    if steps[-1] != n_steps:
        steps = np.append(steps, n_steps)
    return steps


def initial_state(scenario: Scenario) -> np.ndarray:
    """Initial states shaped ``(agents, axes=1, 4)`` from the scenario's ``[[agents]]``."""
    rows = [[a.position, a.velocity, a.tilt, a.tilt_rate] for a in scenario.agents]
    return np.array(rows, dtype=float)[:, None, :]


def simulate(
    scenario: Scenario,
    progress: Callable[[int, int], None] | None = None,
    chunk_seconds: float = 0.1,
) -> Trajectory:
    """Run a scenario and return its :class:`Trajectory`.

    Parameters
    ----------
    scenario
        A validated scenario.
    progress
        Called as ``progress(steps_done, steps_total)`` between chunks of the
        compiled loop; chunks last about ``chunk_seconds``.
    """
    m, c, ia, sim = scenario.model, scenario.controller, scenario.interaction, scenario.simulation
    a, b = state_matrices(m.kp, m.kd, m.g)
    ad, bd = zero_order_hold(a, b, sim.dt)
    gains = modal_gains(m.kp, m.kd, m.g, c.r_l, c.im_l, c.im_r)

    x = initial_state(scenario)
    n_agents = x.shape[0]
    pairs = all_pairs(n_agents)
    n_pairs = len(pairs)
    pair_index = {(int(i), int(j)): p for p, (i, j) in enumerate(pairs)}

    commands = sorted(scenario.commands, key=lambda cmd: cmd.time)
    command_step = np.array([int(round(cmd.time / sim.dt)) for cmd in commands], dtype=np.int64)
    command_pair = np.array(
        [-1 if cmd.pair is None else pair_index[tuple(sorted(cmd.pair))] for cmd in commands], dtype=np.int64
    )
    command_arm = np.array([coupling.ACTIONS.index(cmd.action) for cmd in commands], dtype=np.int64)

    n_steps = sim.n_steps
    steps = record_steps(n_steps, sim.record_every)
    rec_state = np.empty((len(steps), *x.shape))
    rec_control = np.empty((len(steps), n_agents, x.shape[1]))
    rec_flag = np.empty((len(steps), n_pairs), dtype=np.int64)
    # A pair changes flag at most once before any command and twice per command.
    max_events = n_pairs * (1 + 2 * len(commands)) + len(commands)
    event_step = np.empty(max_events, dtype=np.int64)
    event_kind = np.empty(max_events, dtype=np.int64)
    event_pair = np.empty(max_events, dtype=np.int64)
    event_action = np.empty(max_events, dtype=np.int64)

    armed = np.ones(n_pairs, dtype=np.int64)
    flag = np.zeros(n_pairs, dtype=np.int64)
    min_distance = np.full(n_pairs, np.inf)
    function = interaction.FUNCTIONS.index(ia.function)
    coupled_function = interaction.uses_coupling(ia.function)

    next_command = next_record = n_events = 0
    k = 0
    chunk = 1000
    while k <= n_steps:
        stop = min(k + chunk, n_steps + 1)
        started = _time.perf_counter()
        next_command, next_record, n_events = _advance(
            k, stop, n_steps, sim.record_every,
            x, ad, bd, gains, function, gains[0], ia.reach, ia.d_t, ia.eps, ia.c_max, coupled_function,
            pairs, armed, flag, min_distance,
            command_step, command_pair, command_arm, next_command,
            rec_state, rec_control, rec_flag, next_record,
            event_step, event_kind, event_pair, event_action, n_events,
        )  # fmt: skip
        elapsed = _time.perf_counter() - started
        if progress is not None:
            progress(min(stop, n_steps), n_steps)
        # Grow chunks towards about chunk_seconds each (the first includes compilation).
        chunk = int(min(max(chunk * 4, 1000), max(1000, chunk * chunk_seconds / max(elapsed, 1e-9))))
        k = stop

    events = []
    for e in range(n_events):
        p = event_pair[e]
        agents = (-1, -1) if p < 0 else (int(pairs[p, 0]), int(pairs[p, 1]))
        kind = coupling.EVENT_KINDS[event_kind[e]]
        action = coupling.ACTIONS[event_action[e]] if kind == "command" else None
        events.append(Event(time=round(float(event_step[e] * sim.dt), 12), kind=kind, agents=agents, action=action))

    return Trajectory(
        scenario=scenario,
        gains=gains,
        time=steps * sim.dt,
        state=rec_state,
        control=rec_control,
        pairs=pairs,
        flag=rec_flag,
        min_distance=min_distance,
        events=events,
    )
