"""The step loop: scenario in, recorded trajectory and events out.

State is kept as arrays shaped ``(agents, axes, 4)``; every axis uses the
paper's per-axis model (2) with the same gains.  Each step ``k`` (time
``k dt``):

1. operator commands due at step ``k`` arm or disarm formation pairs, or
   remove or add agents;
2. every agent's corrected position ``P*`` (6) is formed, and the neighbour
   lists rebuilt if some ``P*`` has moved more than half the skin;
3. every agent sums the pushes of its non-formation neighbours within
   ``R + R_j``: the repulsion (8) (or the flagless function of the scenario),
   ``f(|d|)`` along ``d / |d|`` with ``d = P*_j - P*_i``;
4. every formation pair (or, in a small swarm without a formation, every
   pair: :meth:`Scenario.pairs`) updates its flag ``F_en`` (:mod:`tmem.coupling`) and
   adds its switching function (10) or (11), equal and opposite, to its two
   agents; while coupled with a required direction ``b``, the pair's pull is
   the vector spring ``K_P (d - d_t b)`` instead;
5. each agent's summed set-point is saturated on its norm, ``|U| <= c_max``:
   a tilt limit that does not depend on how the axes are turned;
6. the step is recorded if ``k`` is a multiple of ``record_every`` (and always
   at the last step);
7. the state advances with the exact zero-order hold of (2) over ``dt``.

A removed agent stops where it is, and no longer interacts (a lost
vehicle); an added agent starts from its ``[[agents]]`` entry.  The loop is
compiled with Numba and runs in chunks, so that a caller can show progress
between them.  It keeps the agents in *slots*, numbered in a spatial order
so that neighbours are close in memory, and takes each neighbouring pair
once, in an order that does not depend on the kind of list or the number of
threads (:mod:`tmem.neighbors`).  In large swarms the per-agent steps and the
neighbour sums of separate blocks of agents run on threads.  The neighbour
sums go in chunks of pairs: gathered, pushed in vectorised arithmetic, then
added to both agents.
"""

from __future__ import annotations

import time as _time
import types
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from . import _numba_cache  # noqa: F401  (drops stale compiled caches before any load)
from . import coupling, interaction
from .control import modal_gains
from .initial import InitialArrays, build
from .model import state_matrices, zero_order_hold
from .neighbors import all_pairs, arrange, nearest_image, spatial_order, verlet_pairs
from .scenario import Scenario

#: Command kinds in the compiled loop.
UNCOUPLE, COUPLE, REMOVE, ADD = range(4)
_COMMAND_CODES = {"uncouple": UNCOUPLE, "couple": COUPLE, "remove": REMOVE, "add": ADD}
#: Swarms at least this large use Verlet lists ("auto").
LARGE_SWARM = 64
#: Swarms at least this large step on threads: below, starting the threads at every step costs more
#: than it saves (gas-N on 2 cores: 1.14e7 agent-steps/s serial against 9.5e6 threaded at 10^3, equal
#: at 10^4).
THREADED_SWARM = 10_000
#: Agents per block of the neighbour sums (:func:`tmem.neighbors.arrange`); it fixes the order of
#: each agent's sum, so results do not depend on the number of threads.
BLOCK = 4096
#: Status returned by the compiled loop when the neighbour lists must be built before step k.
_LISTS_STALE = -1


class SimulationError(ValueError):
    """A run that could not be completed; the message is one line."""


DIVERGED = "the run diverged (non-finite agent states); check the model and controller values and dt"


@dataclass(frozen=True)
class Event:
    """A coupling transition, or an operator command (``agents`` empty for several or every pair)."""

    time: float
    kind: str  # "command" | "couple" | "uncouple"
    agents: tuple[int, ...]
    action: str | None = None  # for commands: "couple" | "uncouple" | "remove" | "add"


@dataclass(frozen=True)
class Trajectory:
    """What a run produced.

    Attributes
    ----------
    scenario : Scenario
    initial : InitialArrays
        The initial arrays: states, flying agents, pairs with their ``d_t`` and
        directions, the periodic box.
    gains : ndarray, shape (4,)
        ``K = (K_P, K_V, K_phi, K_omega)``.
    time : ndarray, shape (n_records,)
    agents : ndarray, shape (n_recorded,)
        Indices of the recorded agents.
    state : ndarray, shape (n_records, n_recorded, axes, 4)
        ``(P, V, phi, omega)`` at each recorded time.
    control : ndarray, shape (n_records, n_recorded, axes)
        The tilt set-point ``U`` applied from that time on.
    active : ndarray, shape (n_records, n_recorded), bool
        Whether each agent was flying.
    flag : ndarray, shape (n_records, n_pairs)
        ``F_en`` of each pair at each recorded time (after that step's check).
    pair_distance : ndarray, shape (n_records, n_pairs)
        ``|P_j - P_i|`` of each pair (nearest image).
    interaction_distance : ndarray, shape (n_records, n_pairs)
        ``|d| = |P*_j - P*_i|`` (6) of each pair.
    min_distance : ndarray, shape (n_pairs,)
        Smallest distance of each formation pair over every step.
    min_neighbor_distance : float
        Smallest distance between any two agents within ``R + R_j`` of each
        other (in ``P*``) at any step; ``inf`` if no two came so close.
    final_state : ndarray, shape (agents, axes, 4)
        Every agent's state at the end.
    final_active : ndarray, shape (agents,), bool
    events : list of Event
    list_builds : int
        How often the neighbour lists were built.
    """

    scenario: Scenario
    initial: InitialArrays
    gains: np.ndarray
    time: np.ndarray
    agents: np.ndarray
    state: np.ndarray
    control: np.ndarray
    active: np.ndarray
    flag: np.ndarray
    pair_distance: np.ndarray
    interaction_distance: np.ndarray
    min_distance: np.ndarray
    min_neighbor_distance: float
    final_state: np.ndarray
    final_active: np.ndarray
    events: list[Event]
    list_builds: int

    @property
    def pairs(self) -> np.ndarray:
        """The pairs handled one by one (:meth:`Scenario.pairs`), shape (n_pairs, 2)."""
        return self.initial.edges

    @property
    def d_t(self) -> np.ndarray:
        """Set distance of each pair, shape (n_pairs,)."""
        return self.initial.d_t


#: Pairs are summed in chunks of this many: gathered, then pushed in vectorised arithmetic, then added.
CHUNK = 256


@numba.njit(cache=True, error_model="numpy", inline="always")
def _chunk_pushes(diff, m, n_axes, function, k_p, reach, c_max):
    """The pushes of ``m`` pairs, in place: ``diff[a]`` holds ``d_a = P*_j - P*_i`` on entry and the
    push on agent ``i`` along axis ``a``, ``f(|d|) d_a / |d|``, on return (0 beyond ``reach``).
    ``diff[n_axes + a]`` holds ``P_j - P_i``; ``diff[2 n_axes]`` gets ``|P_j - P_i|^2`` for the
    pairs within reach, ``inf`` for the others.  No branches: the compiler vectorises it."""
    reach2 = reach * reach
    for t in range(m):
        r2 = 0.0
        for a in range(n_axes):
            r2 += diff[a, t] * diff[a, t]
        inside = (r2 < reach2) & (r2 > 0.0)
        r = np.sqrt(r2)
        push = interaction.pair_control(function, r, 0, k_p, reach, 0.0, c_max) / r
        push = push if inside else 0.0
        dist2 = 0.0
        for a in range(n_axes):
            dist2 += diff[n_axes + a, t] * diff[n_axes + a, t]
            diff[a, t] *= push
        diff[2 * n_axes, t] = dist2 if inside else np.inf


@numba.njit(cache=True, error_model="numpy", inline="always")
def _neighbour_pushes(pos, pairs, first, stop, box, function, k_p, reach, c_max, u):
    """Add to ``u`` the pushes of pairs ``first:stop`` of ``pairs``, each ``(i, j)`` once, equal and
    opposite, in the order listed; return the smallest ``|P_j - P_i|^2`` of a pair within reach.

    ``pos[i, a]`` holds ``(P*, P)`` of agent ``i`` on axis ``a``.  Step 3 of the loop: the
    non-formation neighbours' pushes, ``f(|d|)`` along ``d / |d|``, with ``f`` the repulsion (8) or
    the scenario's flagless function."""
    n_axes = len(box)  # a tuple: compiled for each number of axes
    diff = np.empty((2 * n_axes + 1, CHUNK))
    nearest2 = np.inf
    for begin in range(first, stop, CHUNK):
        m = min(CHUNK, stop - begin)
        for t in range(m):
            i = pairs[begin + t, 0]
            j = pairs[begin + t, 1]
            for a in range(n_axes):
                diff[a, t] = nearest_image(pos[j, a, 0] - pos[i, a, 0], box[a])
                diff[n_axes + a, t] = nearest_image(pos[j, a, 1] - pos[i, a, 1], box[a])
        _chunk_pushes(diff, m, n_axes, function, k_p, reach, c_max)
        for t in range(m):
            nearest2 = min(nearest2, diff[2 * n_axes, t])
        for t in range(m):
            i = pairs[begin + t, 0]
            j = pairs[begin + t, 1]
            for a in range(n_axes):
                u[i, a] += diff[a, t]
                u[j, a] -= diff[a, t]
    return nearest2


@numba.njit(cache=True, inline="always")
def _tilt_scale(u, i, n_axes, c_max):
    """Step 5: the factor that saturates agent ``i``'s summed set-point on its norm, ``|U| <= c_max``."""
    norm2 = 0.0
    for a in range(n_axes):
        norm2 += u[i, a] * u[i, a]
    return c_max / np.sqrt(norm2) if norm2 > c_max * c_max else 1.0


def _advance_source(
    k_start, k_stop, n_steps, record_every,
    x, active, x_start, ad, bd, gains, function, couples, at_crossing, pair_function, k_p, reach, eps, c_max, box,
    use_lists, skin, pairs, n_inside, n_pairs, block_ptr, p_ref,
    edge_i, edge_j, edge_dt, edge_dir, flag, armed, r_before, edge_min, closest,
    cmd_step, cmd_kind, cmd_ptr, cmd_target, next_command,
    rec_slots, rec_state, rec_control, rec_active, rec_flag, rec_dist, rec_dstar, next_record,
    event_step, event_kind, event_i, event_j, event_action, n_events,
):  # fmt: skip
    n_agents = x.shape[0]
    n_axes = len(box)  # a tuple: the loop is compiled for each number of axes
    n_edges = edge_i.shape[0]
    n_blocks = block_ptr.shape[0] - 1
    pos = np.empty((n_agents, n_axes, 2))  # (P*, P) of each agent on each axis
    u = np.zeros((n_agents, n_axes))
    block_nearest2 = np.empty(n_blocks)
    d = np.empty(n_axes)
    v = np.empty(n_axes)
    for k in range(k_start, k_stop):
        # 1. operator commands
        rebuild = False
        while next_command < cmd_step.shape[0] and cmd_step[next_command] <= k:
            c = next_command
            kind = cmd_kind[c]
            if kind == REMOVE or kind == ADD:
                i = cmd_target[cmd_ptr[c]]
                active[i] = kind == ADD
                rebuild = True  # the pairs listed are those of flying agents
                if kind == ADD:
                    x[i] = x_start[i]
                else:
                    for a in range(n_axes):
                        x[i, a, 1:] = 0.0  # a lost vehicle: it stops where it is
                event_i[n_events] = i
                event_j[n_events] = -1
            else:
                if cmd_ptr[c] == cmd_ptr[c + 1]:
                    armed[:] = 1 if kind == COUPLE else 0
                for t in range(cmd_ptr[c], cmd_ptr[c + 1]):
                    armed[cmd_target[t]] = 1 if kind == COUPLE else 0
                single = cmd_ptr[c + 1] - cmd_ptr[c] == 1
                event_i[n_events] = edge_i[cmd_target[cmd_ptr[c]]] if single else -1
                event_j[n_events] = edge_j[cmd_target[cmd_ptr[c]]] if single else -1
            event_step[n_events] = k
            event_kind[n_events] = coupling.EVENT_COMMAND
            event_action[n_events] = kind
            n_events += 1
            next_command += 1
        # 2. corrected positions (6); the largest shift of an active agent's P* since the lists were built
        moved = 0.0
        for i in numba.prange(n_agents):
            shift2 = 0.0
            for a in range(n_axes):
                s = 0.0
                for m in range(4):
                    s += x[i, a, m] * gains[m]
                pos[i, a, 0] = s / gains[0]
                pos[i, a, 1] = x[i, a, 0]
                u[i, a] = 0.0  # the sum of step 3 starts here
                if use_lists:
                    delta = nearest_image(pos[i, a, 0] - p_ref[i, a], box[a])
                    shift2 += delta * delta
            moved = max(moved, shift2 if active[i] else 0.0)
        if rebuild or (use_lists and np.sqrt(moved) > 0.5 * skin):
            # The caller lists the pairs again, from p_ref = P* now, and resumes at step k.
            p_ref[:] = pos[:, :, 0]
            return k, next_command, next_record, n_events, _LISTS_STALE
        # 3. non-formation neighbours: each block's own pairs on its thread, then the crossing pairs
        for b in numba.prange(n_blocks):
            block_nearest2[b] = _neighbour_pushes(
                pos, pairs, block_ptr[b], block_ptr[b + 1], box, pair_function, k_p, reach, c_max, u
            )  # fmt: skip
        nearest2 = _neighbour_pushes(pos, pairs, n_inside, n_pairs, box, pair_function, k_p, reach, c_max, u)
        closest[0] = min(closest[0], nearest2, block_nearest2.min())
        # 4. formation pairs
        for e in range(n_edges):
            i = edge_i[e]
            j = edge_j[e]
            if not (active[i] and active[j]):
                if flag[e] == 1:  # the pair is lost with its agent
                    flag[e] = 0
                    event_step[n_events] = k
                    event_kind[n_events] = coupling.EVENT_UNCOUPLE
                    event_i[n_events] = i
                    event_j[n_events] = j
                    event_action[n_events] = -1
                    n_events += 1
                r_before[e] = np.nan
                continue
            r2 = 0.0
            dist2 = 0.0
            for a in range(n_axes):
                d[a] = nearest_image(pos[j, a, 0] - pos[i, a, 0], box[a])
                r2 += d[a] * d[a]
                delta = nearest_image(pos[j, a, 1] - pos[i, a, 1], box[a])
                dist2 += delta * delta
            r = np.sqrt(r2)
            dist = np.sqrt(dist2)
            if dist < edge_min[e]:
                edge_min[e] = dist
            new = coupling.next_flag(flag[e], armed[e], r_before[e], r, edge_dt[e], eps, at_crossing) if couples else flag[e]
            r_before[e] = r
            if new != flag[e]:
                flag[e] = new
                event_step[n_events] = k
                event_kind[n_events] = coupling.EVENT_COUPLE if new == 1 else coupling.EVENT_UNCOUPLE
                event_i[n_events] = i
                event_j[n_events] = j
                event_action[n_events] = -1
                n_events += 1
            if flag[e] == 1 and not np.isnan(edge_dir[e, 0]):
                norm2 = 0.0
                for a in range(n_axes):
                    v[a] = k_p * (d[a] - edge_dir[e, a] * edge_dt[e])
                    norm2 += v[a] * v[a]
                scale = min(1.0, c_max / np.sqrt(norm2)) if norm2 > 0.0 else 0.0
                for a in range(n_axes):
                    u[i, a] += scale * v[a]
                    u[j, a] -= scale * v[a]
            elif r > 0.0:
                push = interaction.pair_control(function, r, flag[e], k_p, reach, edge_dt[e], c_max) / r
                for a in range(n_axes):
                    u[i, a] += push * d[a]
                    u[j, a] -= push * d[a]
        # 6. recording (before the step, with the control applied over it)
        if record_every > 0 and (k % record_every == 0 or k == n_steps):
            for q in range(rec_slots.shape[0]):
                i = rec_slots[q]
                rec_state[next_record, q] = x[i]
                rec_active[next_record, q] = active[i]
                scale = _tilt_scale(u, i, n_axes, c_max) if active[i] else 0.0
                for a in range(n_axes):
                    rec_control[next_record, q, a] = u[i, a] * scale
            for e in range(n_edges):
                rec_flag[next_record, e] = flag[e]
                dist2 = 0.0
                r2 = 0.0
                for a in range(n_axes):
                    delta = nearest_image(x[edge_j[e], a, 0] - x[edge_i[e], a, 0], box[a])
                    dist2 += delta * delta
                    delta = nearest_image(pos[edge_j[e], a, 0] - pos[edge_i[e], a, 0], box[a])
                    r2 += delta * delta
                rec_dist[next_record, e] = np.sqrt(dist2)
                rec_dstar[next_record, e] = np.sqrt(r2)
            next_record += 1
        # 5. saturation of the set-point's norm, and 7. the exact zero-order-hold step of (2)
        if k < n_steps:
            for i in numba.prange(n_agents):
                if not active[i]:
                    continue
                scale = _tilt_scale(u, i, n_axes, c_max)
                for a in range(n_axes):
                    x0 = x[i, a, 0]
                    x1 = x[i, a, 1]
                    x2 = x[i, a, 2]
                    x3 = x[i, a, 3]
                    ui = u[i, a] * scale
                    for m in range(4):
                        x[i, a, m] = ad[m, 0] * x0 + ad[m, 1] * x1 + ad[m, 2] * x2 + ad[m, 3] * x3 + bd[m] * ui
                    if box[a] > 0.0 and not 0.0 <= x[i, a, 0] < box[a]:  # inside, the floor below is 0
                        x[i, a, 0] -= box[a] * np.floor(x[i, a, 0] / box[a])
    return k_stop, next_command, next_record, n_events, 0


def _named(function, name):
    """The same code under another name.  Numba keys its on-disk cache by the function's name, not by
    ``parallel``: compiled from one function, the serial and threaded loops would share a cache, and
    whichever was compiled first would stand in for both."""
    twin = types.FunctionType(function.__code__, function.__globals__, name)
    twin.__qualname__ = name
    return twin


_advance_serial = numba.njit(cache=True, error_model="numpy")(_named(_advance_source, "_advance_serial"))
_advance_threaded = numba.njit(cache=True, parallel=True, error_model="numpy")(
    _named(_advance_source, "_advance_threaded")
)


def record_steps(n_steps: int, record_every: int) -> np.ndarray:
    """The step indices that are recorded: multiples of ``record_every`` and the last step."""
    steps = np.arange(0, n_steps + 1, record_every)
    if steps[-1] != n_steps:
        steps = np.append(steps, n_steps)
    return steps


def _commands(scenario: Scenario, edges: np.ndarray, dt: float, slot: np.ndarray):
    """Commands as arrays: step, kind, and targets (pair indices, or the agent's slot) in rows."""
    index = {(int(i), int(j)): e for e, (i, j) in enumerate(edges)}
    commands = sorted(scenario.commands, key=lambda cmd: cmd.time)
    step = np.array([int(round(cmd.time / dt)) for cmd in commands], dtype=np.int64)
    kind = np.array([_COMMAND_CODES[cmd.action] for cmd in commands], dtype=np.int64)
    targets = []
    for cmd in commands:
        if cmd.agent is not None:
            targets.append([slot[cmd.agent]])
        else:
            targets.append([index[(min(i, j), max(i, j))] for i, j in cmd.targets or []])
    ptr = np.cumsum([0] + [len(t) for t in targets]).astype(np.int64)
    flat = np.array([t for row in targets for t in row], dtype=np.int64)
    return step, kind, ptr, flat


def _partners(n_agents: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each agent's formation partners, in rows ``(ptr, idx)``."""
    both = np.concatenate([edges, edges[:, ::-1]]) if len(edges) else np.empty((0, 2), dtype=np.int64)
    order = np.lexsort((both[:, 1], both[:, 0]))
    both = both[order]
    ptr = np.searchsorted(both[:, 0], np.arange(n_agents + 1)).astype(np.int64)
    return ptr, both[:, 1].astype(np.int64).copy()


def simulate(
    scenario: Scenario,
    progress: Callable[[int, int], None] | None = None,
    chunk_seconds: float = 0.1,
    record: bool = True,
) -> Trajectory:
    """Run a scenario and return its :class:`Trajectory`.

    Parameters
    ----------
    scenario
        A validated scenario.
    progress
        Called as ``progress(steps_done, steps_total)`` between chunks of the
        compiled loop; chunks last about ``chunk_seconds``.
    record
        ``False`` records nothing but the end state (for benchmarks).
    """
    m, c, ia, sim = scenario.model, scenario.controller, scenario.interaction, scenario.simulation
    a, b = state_matrices(m.kp, m.kd, m.g)
    ad, bd = zero_order_hold(a, b, sim.dt)
    gains = modal_gains(m.kp, m.kd, m.g, c.r_l, c.im_l, c.im_r)
    setup: InitialArrays = build(scenario)

    n_agents, n_axes, _ = setup.state.shape
    # The loop keeps agent order[s] in slot s: a spatial order, with neighbours close in memory.
    order = spatial_order(setup.state @ (gains / gains[0]), setup.active, ia.reach + scenario.neighbors.skin, setup.box)
    slot = np.empty(n_agents, dtype=np.int64)
    slot[order] = np.arange(n_agents)
    x = setup.state[order]
    x_start = x.copy()
    active = setup.active[order]
    edges = setup.edges
    n_edges = len(edges)
    edge_i = slot[edges[:, 0]]
    edge_j = slot[edges[:, 1]]
    adj_ptr, adj_idx = _partners(n_agents, np.stack([edge_i, edge_j], axis=1))
    flag = setup.flag.copy()
    armed = np.ones(n_edges, dtype=np.int64)
    r_before = np.full(n_edges, np.nan)  # |d| of each pair one step earlier; none before the first step

    method = scenario.neighbors.method
    use_lists = method == "verlet" or (method == "auto" and n_agents >= LARGE_SWARM)
    box = tuple(setup.box.tolist())
    if use_lists:  # pairs are unsigned, as all_pairs gives them: no negative-index check in the loop
        pairs = np.empty((8 * n_agents, 2), dtype=np.uint32)
        found = np.empty((2, len(pairs) + 64), dtype=np.int32)
    block_ptr = np.empty(n_agents // BLOCK + 2, dtype=np.int64)
    advance = _advance_threaded if n_agents >= THREADED_SWARM else _advance_serial

    cmd_step, cmd_kind, cmd_ptr, cmd_target = _commands(scenario, edges, sim.dt, slot)
    n_steps = sim.n_steps
    steps = record_steps(n_steps, sim.record_every) if record else np.empty(0, dtype=np.int64)
    rec_agents = np.arange(n_agents) if sim.record_agents is None else np.array(sim.record_agents, dtype=np.int64)
    if not record:
        rec_agents = rec_agents[:0]
    rec_slots = slot[rec_agents]
    rec_state = np.empty((len(steps), len(rec_agents), n_axes, 4))
    rec_control = np.empty((len(steps), len(rec_agents), n_axes))
    rec_active = np.empty((len(steps), len(rec_agents)), dtype=np.bool_)
    rec_flag = np.empty((len(steps), n_edges), dtype=np.int64)
    rec_dist = np.empty((len(steps), n_edges))
    rec_dstar = np.empty((len(steps), n_edges))
    # A pair changes flag at most once before any command and twice after each.
    max_events = n_edges * (1 + 2 * len(cmd_step)) + len(cmd_step)
    event_step = np.empty(max_events, dtype=np.int64)
    event_kind = np.empty(max_events, dtype=np.int64)
    event_i = np.empty(max_events, dtype=np.int64)
    event_j = np.empty(max_events, dtype=np.int64)
    event_action = np.empty(max_events, dtype=np.int64)
    edge_min = np.full(n_edges, np.inf)
    closest = np.full(1, np.inf)  # the smallest squared distance between neighbours so far
    p_ref = np.zeros((n_agents, n_axes))
    builds = 0

    def list_pairs() -> tuple[int, int]:
        """List the pairs of flying agents (within reach and skin of each other in ``p_ref``, with
        Verlet lists), each once, in the loop's order; grow the arrays if needed.  Returns
        ``(n_inside, n_pairs)`` of :func:`arrange`."""
        nonlocal builds, pairs, found
        if use_lists:
            cutoff = ia.reach + scenario.neighbors.skin
            parts = numba.get_num_threads()
            listed, room = verlet_pairs(p_ref, active, cutoff, box, pairs, found, parts)
            if listed > len(pairs) or room > found.shape[1]:
                pairs = np.empty((int(1.5 * max(listed, len(pairs))) + 16, 2), dtype=np.uint32)
                found = np.empty((2, int(1.5 * max(room, found.shape[1])) + 16), dtype=np.int32)
                verlet_pairs(p_ref, active, cutoff, box, pairs, found, parts)
            builds += 1
        else:
            pairs = all_pairs(active)
            listed = len(pairs)
        return arrange(pairs, listed, adj_ptr, adj_idx, BLOCK, block_ptr)

    p_ref[:] = x @ (gains / gains[0])  # P* (6) at the start
    n_inside, n_pairs = list_pairs()

    next_command = next_record = n_events = 0
    k = 0
    chunk = 1000
    while k <= n_steps:
        stop = min(k + chunk, n_steps + 1)
        started = _time.perf_counter()
        k, next_command, next_record, n_events, status = advance(
            k, stop, n_steps, sim.record_every if record else 0,
            x, active, x_start, ad, bd, gains,
            interaction.FUNCTIONS.index(ia.function), interaction.uses_coupling(ia.function), ia.switch_at == "crossing",
            interaction.REPULSION if interaction.uses_coupling(ia.function) else interaction.FUNCTIONS.index(ia.function),
            gains[0], ia.reach, ia.eps, ia.c_max, box,
            use_lists, scenario.neighbors.skin, pairs, n_inside, n_pairs, block_ptr, p_ref,
            edge_i, edge_j, setup.d_t, setup.direction, flag, armed, r_before, edge_min, closest,
            cmd_step, cmd_kind, cmd_ptr, cmd_target, next_command,
            rec_slots, rec_state, rec_control, rec_active, rec_flag, rec_dist, rec_dstar, next_record,
            event_step, event_kind, event_i, event_j, event_action, n_events,
        )  # fmt: skip
        if status == _LISTS_STALE:  # list the pairs again and go on from the same step
            n_inside, n_pairs = list_pairs()
            continue
        elapsed = _time.perf_counter() - started
        if progress is not None:
            progress(min(k, n_steps), n_steps)
        # Grow chunks towards about chunk_seconds each (the first includes compilation).
        chunk = int(min(max(chunk * 4, 1000), max(1000, chunk * chunk_seconds / max(elapsed, 1e-9))))

    if not np.all(np.isfinite(x[active])):
        raise SimulationError(DIVERGED)
    events = []
    for e in range(n_events):
        kind = coupling.EVENT_KINDS[event_kind[e]]
        agents = tuple(int(order[v]) for v in (event_i[e], event_j[e]) if v >= 0)
        action = next(name for name, code in _COMMAND_CODES.items() if code == event_action[e]) if kind == "command" else None
        events.append(Event(time=round(float(event_step[e] * sim.dt), 12), kind=kind, agents=agents, action=action))

    min_neighbor = float(np.sqrt(closest[0]))
    return Trajectory(
        scenario=scenario,
        initial=setup,
        gains=gains,
        time=steps * sim.dt,
        agents=rec_agents,
        state=rec_state,
        control=rec_control,
        active=rec_active,
        flag=rec_flag,
        pair_distance=rec_dist,
        interaction_distance=rec_dstar,
        min_distance=edge_min,
        min_neighbor_distance=min_neighbor,
        final_state=x[slot],
        final_active=active[slot],
        events=events,
        list_builds=builds,
    )

