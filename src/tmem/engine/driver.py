"""The driver of a run: the records built, the compiled loop driven in chunks, the trajectory read back.

:func:`simulate` builds the records of :mod:`tmem.engine.records` from a
scenario, lists the neighbouring pairs (:mod:`tmem.world.neighbors`), and runs the
compiled loop (:mod:`tmem.engine.loop`) in chunks that last about
``chunk_seconds``, so that a caller can show progress between them.  When the
loop reports that the lists are stale (an agent's ``P*`` moved half the skin,
or an agent was removed or added), it lists them again and goes on from the
same step.  Given :class:`~tmem.engine.checkpoint.Checkpoints`, it ends chunks
at the checkpoints' steps and saves the run there, and goes on from the last
checkpoint a run left.  At the end it translates slots back to the scenario's
agents.
"""

from __future__ import annotations

import os
import sys
import time as _time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from tmem.law.modal import interaction_point
from tmem.world.initial import InitialArrays, build
from tmem.vehicles import vehicle_model
from tmem.world.neighbors import spatial_order
from tmem.scenario import Scenario
from tmem.scenario.files import as_scenario
from tmem.scenario.sensing_table import SensingParams, with_overrides
from tmem.world.sensing import Sensing, exact, sensing_of
from tmem.engine.checkpoint import Checkpoints, Saved, restore
from tmem.engine.loop import advance_for
from tmem.engine.variants import Variant, compiles
from tmem.engine.lists import NeighbourLister
from tmem.engine.gas import SNAPSHOT, TOTALS, gas_record
from tmem.law.record import law_of
from tmem.engine.records import (
    COMMANDS, LISTS_STALE, Agents, Commands, Counters, Events, Neighbours, Pairs, Records, Run,
)  # fmt: skip
from tmem.engine.trajectory import DIVERGED, SimulationError, Trajectory, read_events
from tmem.terms import term_class

#: The line a run writes to standard error before its step loop compiles: once per kind of run (vehicle,
#: knowledge, terms, gas, threads) on a machine, then Numba's cache holds it.  The time is what two
#: shipped examples' first runs spent compiling on 2 cores (23 and 33 s, docs/speed.md).
COMPILING = "tmem: compiling the step loop for this kind of run ({name}), once on this machine: about 30 s"
#: An environment variable that, set to 1, leaves the line out (scripts that keep standard error for errors).
QUIET = "TMEM_NO_COMPILE_NOTICE"
#: Swarms at least this large step on threads: below, starting the threads at every step costs more
#: than it saves (gas-N on 2 cores: 1.14e7 agent-steps/s serial against 9.5e6 threaded at 10^3, equal
#: at 10^4).
THREADED_SWARM = 10_000


def record_steps(n_steps: int, record_every: int) -> np.ndarray:
    """The step indices that are recorded: multiples of ``record_every`` and the last step.

    Parameters
    ----------
    n_steps : int
        Steps of the run.
    record_every : int
        Record every this many steps.
    """
    steps = np.arange(0, n_steps + 1, record_every)
    if steps[-1] != n_steps:
        steps = np.append(steps, n_steps)
    return steps


def _commands(scenario: Scenario, edges: np.ndarray, slot: np.ndarray) -> Commands:
    """Commands as arrays: step, kind, and targets (pair indices, or the agent's slot) in rows; a mission's
    changes of shape among them, each with the direction its pairs hold (where the formation holds directions)."""
    axes = scenario.space.axes
    index = {(int(i), int(j)): e for e, (i, j) in enumerate(edges)}
    timed = [(cmd.time, COMMANDS.index(cmd.action), cmd.agent, cmd.targets, cmd.value, None) for cmd in scenario.commands]
    if scenario.shapes_change:  # the mission's changes of the pairs (tmem.terms.navigation_plan.shape_commands)
        from tmem.terms.navigation_plan import shape_commands

        timed += [(time, COMMANDS.index("reshape"), None, [tuple(edge) for edge in edges.tolist()], None, held)
                  for time, edges, held in shape_commands(scenario)]  # fmt: skip
    timed.sort(key=lambda command: command[0])
    step = np.array([scenario.simulation.step_of(time) for time, *_ in timed], dtype=np.int64)
    kind = np.array([code for _, code, *_ in timed], dtype=np.int64)
    targets, directions = [], []
    for _, _, agent, pairs, _, held in timed:
        if agent is not None:
            targets.append([slot[agent]])
        else:
            targets.append([index[(min(i, j), max(i, j))] for i, j in pairs or []])
        directions.append(np.full((len(targets[-1]), axes), np.nan) if held is None else held)
    ptr = np.cumsum([0] + [len(t) for t in targets]).astype(np.int64)
    flat = np.array([t for row in targets for t in row], dtype=np.int64)
    value = np.array([np.nan if value is None else value for *_, value, _ in timed], dtype=float)
    direction = np.concatenate(directions) if directions else np.empty((0, axes))
    return Commands(step, kind, ptr, flat, value, direction)


def _records(n_steps_recorded: int, rec_agents: np.ndarray, slots: np.ndarray, n_axes: int, n_state: int, n_edges: int,
             observe: bool, n_body: int) -> Records:
    rows = n_steps_recorded
    return Records(
        slots=slots,
        state=np.empty((rows, len(rec_agents), n_axes, n_state)),
        control=np.empty((rows, len(rec_agents), n_axes)),
        active=np.empty((rows, len(rec_agents)), dtype=np.bool_),
        flag=np.empty((rows, n_edges), dtype=np.int64),
        distance=np.empty((rows, n_edges)),
        measure=np.empty((rows, n_edges)),
        gas=np.zeros((rows, len(TOTALS) + len(SNAPSHOT) if observe else 0)),
        body=np.empty((rows, len(rec_agents), n_body)),
    )


def _events(capacity: int) -> Events:
    return Events(*(np.empty(capacity, dtype=np.int64) for _ in Events._fields))


@dataclass
class _Slots:
    """A run's records with the agents in slots: ``order[s]`` is the agent in slot ``s``, ``slot[a]``
    the slot of agent ``a``.  The loop keeps a spatial order, so that neighbours are close in memory."""

    order: np.ndarray
    slot: np.ndarray
    agents: Agents
    pairs: Pairs
    commands: Commands
    records: Records
    events: Events
    counters: Counters
    recorded: np.ndarray  # the recorded agents, by number
    steps: np.ndarray  # the recorded steps


def slot_order(scenario: Scenario, initial: InitialArrays, gains: np.ndarray) -> np.ndarray:
    """The agent in each slot of a run: a spatial order of the starting ``P*`` (6).

    Each agent adds its neighbours' pushes in this order (:func:`tmem.world.neighbors.arrange`).

    Parameters
    ----------
    scenario : Scenario
        Its reach and skin set the cells.
    initial : InitialArrays
        The starting states, flying agents and box.
    gains : ndarray, shape (4,)
        ``K`` of every agent.
    """
    cell = scenario.interaction.reach + scenario.neighbors.skin
    return spatial_order(interaction_point(initial.state, gains), initial.active, cell, initial.box)


def _in_slots(scenario: Scenario, initial: InitialArrays, gains: np.ndarray, record: bool, body: np.ndarray) -> _Slots:
    """The records of a run, its agents placed in a spatial order of their ``P*`` (6); ``body`` the
    agents' body states at the start (by agent number)."""
    sim = scenario.simulation
    n_agents, n_axes, n_state = initial.state.shape
    order = slot_order(scenario, initial, gains)
    slot = np.empty(n_agents, dtype=np.int64)
    slot[order] = np.arange(n_agents)
    x = initial.state[order]
    body = body[order]
    agents = Agents.at_start(x, initial.active[order], body)
    edges = initial.edges
    n_edges = len(edges)
    pairs = Pairs.at_start(slot[edges[:, 0]], slot[edges[:, 1]], initial.d_t, initial.direction, initial.flag.copy())
    commands = _commands(scenario, edges, slot)
    steps = record_steps(sim.n_steps, sim.record_every) if record else np.empty(0, dtype=np.int64)
    recorded = np.arange(n_agents) if sim.record_agents is None else np.array(sim.record_agents, dtype=np.int64)
    recorded = recorded if record else recorded[:0]
    records = _records(len(steps), recorded, slot[recorded], n_axes, n_state, n_edges, scenario.gas_observed, body.shape[1])
    # A pair changes flag at most once before any command and twice after each.
    events = _events(n_edges * (1 + 2 * len(commands.step)) + len(commands.step))
    return _Slots(order, slot, agents, pairs, commands, records, events, Counters.zero(), recorded, steps)


def simulate(
    scenario: Scenario | str | os.PathLike | dict,
    progress: Callable[[int, int], None] | None = None,
    chunk_seconds: float = 0.1,
    record: bool = True,
    sensing: dict | None = None,
    checkpoints: Checkpoints | None = None,
) -> Trajectory:
    """Run a scenario and return its :class:`~tmem.engine.trajectory.Trajectory`.

    Parameters
    ----------
    scenario
        A validated scenario, the path of a scenario file (:func:`tmem.scenario.load`) or a dict of
        its tables (:func:`tmem.scenario.from_dict`).
    progress
        Called as ``progress(steps_done, steps_total)`` between chunks of the
        compiled loop; chunks last about ``chunk_seconds``.
    chunk_seconds
        The wall time a chunk aims at (s).
    record
        ``False`` records nothing but the end state (for benchmarks).
    sensing
        Keys of the ``[sensing]`` table, set in the scenario over its own and checked as the table
        is, and fields of the measurement stage's record (:class:`tmem.world.sensing.Sensing`) that
        no key sets, for effects the table does not name (finite numbers); given, even empty, the
        run takes the sensed path.  By default the table decides: without effects, every agent
        knows every state exactly.
    checkpoints
        Save the run's state at these checkpoints (:mod:`tmem.engine.checkpoint`), and go on from
        the one a killed run of the same scenario left; default: none.

    Returns
    -------
    Trajectory

    Raises
    ------
    ScenarioError
        If the scenario, its file or an override of the sensing is refused (one line naming it).
    SimulationError
        If the run diverged.
    CheckpointError
        If the checkpoint file is not one this run made.
    """
    scenario = as_scenario(scenario)
    scenario, sensing = with_overrides(scenario, sensing, Sensing._fields)
    resume = checkpoints.start(scenario, record, sensing) if checkpoints is not None else None
    sim, c = scenario.simulation, scenario.controller
    model = vehicle_model(scenario.model, scenario.wind)
    gains = model.gains(c.r_l, c.im_l, c.im_r)
    initial = build(scenario)
    run = _run_of(scenario, initial, record)
    law, params = law_of(scenario, model.linearisation(), gains)
    swarm = _in_slots(scenario, initial, gains, record, model.initial_body(initial.state))
    x = swarm.agents.state
    lister, measured, sensed = _lists_and_measurement(scenario, run, swarm, gains, sensing)
    terms = {name: term_class(name).record(getattr(scenario, name), scenario, gains) for name in scenario.agent_terms}
    stages = Stages(law=law, params=params, vehicle=model.step_params(sim.dt), knowledge=measured,
                    gas=gas_record(scenario, model.acceleration_per_input(), x.shape[0]), terms=terms)
    variant = Variant(vehicle=scenario.model.kind, knowledge="sensed" if sensed else "exact", terms=tuple(terms),
                      gas=stages.gas.observe, threaded=x.shape[0] >= THREADED_SWARM)  # fmt: skip
    _drive(advance_for(variant), run, stages, swarm, lister, progress, chunk_seconds, checkpoints, resume)
    if not np.all(np.isfinite(x[swarm.agents.active])):
        raise SimulationError(DIVERGED)
    return _read_back(scenario, initial, model, gains, swarm, lister)


def _read_back(scenario: Scenario, initial: InitialArrays, model, gains: np.ndarray, swarm: _Slots,
               lister: NeighbourLister) -> Trajectory:  # fmt: skip
    """The trajectory of a finished run, its agents translated from slots back to their numbers."""
    sim = scenario.simulation
    x = swarm.agents.state
    return Trajectory(
        scenario=scenario,
        initial=initial,
        model=model,
        gains=gains,
        time=swarm.steps * sim.dt,
        agents=swarm.recorded,
        state=swarm.records.state,
        control=swarm.records.control,
        active=swarm.records.active,
        flag=swarm.records.flag,
        pair_distance=swarm.records.distance,
        interaction_distance=swarm.records.measure,
        min_distance=swarm.pairs.min_distance,
        min_neighbor_distance=float(np.sqrt(lister.closest[0])),
        final_state=x[swarm.slot],
        final_active=swarm.agents.active[swarm.slot],
        events=read_events(swarm.events, int(swarm.counters.n_events[0]), swarm.order, sim.dt),
        list_builds=lister.builds,
        gas=swarm.records.gas,
        body=swarm.records.body,
        final_body=swarm.agents.body[swarm.slot],
    )


def _lists_and_measurement(scenario: Scenario, run: Run, swarm: _Slots, gains: np.ndarray, overrides: dict | None):
    """The neighbour lister and the measurement stage (:class:`tmem.world.sensing.Sensing`), and whether the
    run takes the sensed path.  The exact path lists ``P*`` (6) within ``R + R_j`` and the skin; the
    sensed path the positions within the sensing range and the skin."""
    x = swarm.agents.state
    settings = scenario.sensing or SensingParams()
    sensed = _sensed(scenario, settings, run, overrides)
    edges = np.stack([swarm.pairs.i, swarm.pairs.j], axis=1)
    reach = settings.range if sensed and run.use_lists else scenario.interaction.reach
    lister = NeighbourLister(scenario, x.shape[0], x.shape[1], edges, run.use_lists, reach)
    lister.p_ref[:] = x[..., 0] if sensed else interaction_point(x, gains)  # what the lists hold, at the start
    if not sensed:
        return lister, exact(x), False
    blocks = len(lister.block_ptr) - 1
    return lister, sensing_of(settings, swarm.order, x.shape, scenario.simulation.dt, blocks)._replace(**(overrides or {})), True


def _sensed(scenario: Scenario, settings: SensingParams, run: Run, overrides: dict | None) -> bool:
    """Whether the run takes the sensed path (:mod:`tmem.engine.sensed`); what that path cannot do is
    refused in one line (the schema refuses it in a scenario; this, given ``overrides``)."""
    sensed = overrides is not None or not settings.exact
    if sensed and run.use_lists and settings.range is None:
        raise ValueError("sensing.range: is required when neighbours are found with lists: the lists hold the agents within range")
    if sensed and scenario.gas_observed:
        raise ValueError("sensing: the gas's stages read exact states: a run with sensing effects cannot observe its gas")
    return sensed


def _run_of(scenario: Scenario, initial: InitialArrays, record: bool) -> Run:
    """What stays fixed over the run: steps, recording, the box, the kind of neighbour list."""
    sim = scenario.simulation
    n_agents = initial.state.shape[0]
    use_lists = scenario.neighbors.uses_lists(n_agents)
    box = tuple(initial.box.tolist())
    return Run(sim.n_steps, sim.record_every if record else 0, box, use_lists, scenario.neighbors.skin)


class Stages(NamedTuple):
    """The records of the law and of the stages that a run binds, by name.

    Attributes
    ----------
    law : Law
        The TMEM law (:mod:`tmem.law.record`).
    params : FunctionParams
        The interaction functions' parameters.
    vehicle : NamedTuple
        The vehicle model's numbers for a step (:meth:`tmem.vehicles.base.VehicleModel.step_params`).
    knowledge : Sensing
        The measurement stage (:mod:`tmem.world.sensing`; unused under exact knowledge).
    gas : Gas
        The gas (:mod:`tmem.engine.gas`; its arrays empty when it is not observed).
    terms : dict of str to NamedTuple
        Each agent term's record, by its table's name, in the order they push (:mod:`tmem.terms`).
    """

    law: Any
    params: Any
    vehicle: Any
    knowledge: Any
    gas: Any
    terms: dict


def _changing(swarm: _Slots, neighbours: Neighbours, stages: Stages) -> dict:
    """The records a step changes, by the names of :data:`tmem.engine.checkpoint.CHANGING`."""
    return dict(agents=swarm.agents, pairs=swarm.pairs, neighbours=neighbours, records=swarm.records, events=swarm.events,
                counters=swarm.counters, gas=stages.gas, sensing=stages.knowledge, terms=stages.terms)  # fmt: skip


def _drive(advance, run: Run, stages: Stages, swarm: _Slots, lister: NeighbourLister, progress, chunk_seconds: float,
           checkpoints: Checkpoints | None, resume: Saved | None) -> None:  # fmt: skip
    """Run the compiled loop ``advance`` over every step, in chunks of about ``chunk_seconds``,
    listing the neighbours again whenever the loop asks.  With ``checkpoints``, chunks end at the
    checkpoints' steps, where the run is saved; with ``resume``, the run goes on from it, its
    neighbours listed again from ``P*`` at their last build."""
    terms = tuple(stages.terms.values())
    neighbours = lister.list(swarm.agents.active, run.box)
    if resume is not None:
        restore(resume, _changing(swarm, neighbours, stages))
        neighbours = lister.list(swarm.agents.active, run.box)
        lister.builds = resume.list_builds
    counters = swarm.counters
    chunk = 1000
    first = True
    while counters.step[0] <= run.n_steps:
        started = _time.perf_counter()
        at = checkpoints.due(counters.step[0]) if checkpoints is not None else run.n_steps + 1
        stop = min(counters.step[0] + chunk, run.n_steps + 1, at)
        args = (stop, run, stages.law, stages.params, stages.vehicle, stages.knowledge, swarm.agents, swarm.pairs,
                neighbours, swarm.commands, swarm.records, swarm.events, counters, stages.gas, terms)  # fmt: skip
        if first and os.environ.get(QUIET) != "1" and compiles(advance, args):  # only the first call compiles
            print(COMPILING.format(name=advance.__name__), file=sys.stderr, flush=True)
        first = False
        status = advance(*args)
        if status == LISTS_STALE:
            neighbours = lister.list(swarm.agents.active, run.box)  # and go on from the same step
            continue
        elapsed = _time.perf_counter() - started
        if counters.step[0] == at <= run.n_steps:
            checkpoints.save(at, _changing(swarm, neighbours, stages), lister.builds)
        if progress is not None:
            progress(min(int(counters.step[0]), run.n_steps), run.n_steps)
        # Grow chunks towards about chunk_seconds each (the first includes compilation).
        chunk = int(min(max(chunk * 4, 1000), max(1000, chunk * chunk_seconds / max(elapsed, 1e-9))))
