"""A scenario's swarm as per-agent controllers, and a plain loop that flies them.

:func:`controllers_for` builds one :class:`~tmem.agent.controller.AgentController`
per agent of a scenario: the scenario's gains and law, each agent's formation
edges (with their set distances, directions and starting flags) and the
operator's commands that concern it, and the engine's order of summation.
:func:`fly` then runs the swarm as separate vehicles would: at each step every
agent broadcasts its message, every controller reads the others' and returns
its set-point, and each vehicle takes its step with the vehicle model's own
compiled step.  It gives the bits :func:`tmem.simulate` gives.

What the per-agent controllers do not do is refused in one line
(:class:`~tmem.agent.settings.ControllerError`): the gas's thermostat, walls,
obstacles, mean of pushes and totals, a periodic box, agents removed, added
or grounded at the start, and swarms of more than :data:`MAX_AGENTS`.
"""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tmem.engine.driver import record_steps, slot_order
from tmem.law.record import law_of
from tmem.engine.trajectory import Event
from tmem.world.initial import build
from tmem.vehicles import vehicle_model
from tmem.scenario import Scenario, as_scenario
from tmem.agent.controller import AgentController
from tmem.law.params import ControllerLaw, LawParams
from tmem.agent.settings import ControllerError, Edge, OperatorCommand

#: Most agents :func:`controllers_for` builds: every controller reads every agent's message, so a
#: step of the loop reads n^2 of them (the engine, with its neighbour lists, is for larger swarms).
MAX_AGENTS = 512


def _refuse_what_is_not_flown(scenario: Scenario) -> None:
    """Raise :class:`ControllerError` on the first thing in ``scenario`` per-agent controllers do not do."""
    refused = _refusal(scenario)
    if refused is not None:
        raise ControllerError(f"{refused[0]}: {refused[1]}")


def _refusal(scenario: Scenario) -> tuple[str, str] | None:
    """``(field, reason)`` of the first thing in ``scenario`` the per-agent controllers do not do."""
    if scenario.n_agents > MAX_AGENTS:
        generated = scenario.formation is not None and scenario.formation.kind != "edges"
        field = "swarm.n" if scenario.swarm is not None else "formation.n" if generated else "agents"
        return field, (f"{scenario.n_agents} agents; per-agent controllers are built for at most {MAX_AGENTS} "
                       "(each reads every agent's message: n^2 a step)")  # fmt: skip
    gas = "is the engine's gas stage, which a per-agent controller does not run"
    for given, field in ((scenario.space.periodic, "space.periodic"), (scenario.space.walls, "space.walls"),
                         (bool(scenario.obstacles), "obstacles"), (scenario.thermostat is not None, "thermostat"),
                         (scenario.interaction.combine == "mean", "interaction.combine"),
                         (scenario.simulation.observe_gas, "simulation.observe_gas")):  # fmt: skip
        if given:
            reason = "per-agent controllers fly in open space" if field == "space.periodic" else gas
            return field, reason
    for name in scenario.agent_terms:
        return name, "is an agent term of the engine's step loop, which a per-agent controller does not run"
    for k, agent in enumerate(scenario.agents):
        if not agent.active:
            return f"agents[{k}].active", "every agent flies from the start under per-agent controllers"
    for k, command in enumerate(scenario.commands):
        if command.action not in ("couple", "uncouple"):
            return f"commands[{k}].action", f"{command.action!r} is not a command to a controller (only couple and uncouple)"
    return None


def controllers_for(scenario: Scenario | str | os.PathLike | dict) -> list[AgentController]:
    """One controller per agent of ``scenario``, in the order of its agents.

    Each has the scenario's gains (:meth:`tmem.vehicles.base.VehicleModel.gains`) and law
    (:func:`tmem.law.record.law_of`), its agent's formation edges, the scenario's couple and
    uncouple commands that name one of them (or every pair), and the engine's order of the
    neighbours' pushes (:func:`tmem.engine.driver.slot_order`).

    Parameters
    ----------
    scenario : Scenario, str, os.PathLike or dict
        A validated scenario, the path of a scenario file or a dict of its tables
        (:func:`tmem.scenario.as_scenario`).

    Raises
    ------
    ControllerError
        What the scenario asks that per-agent controllers do not do, in one line naming the field.
    ScenarioError
        A file or tables refused, or a ``scenario`` of another type, in one line.
    """
    scenario = as_scenario(scenario)
    _refuse_what_is_not_flown(scenario)
    c, ia, sim = scenario.controller, scenario.interaction, scenario.simulation
    model = vehicle_model(scenario.model)
    linearisation, gains = model.linearisation(), model.gains(c.r_l, c.im_l, c.im_r)
    law, _ = law_of(scenario, linearisation, gains)
    initial = build(scenario)
    n = scenario.n_agents
    edges: list[list[Edge]] = [[] for _ in range(n)]
    for e, (i, j) in enumerate(initial.edges.tolist()):
        b = None if np.isnan(initial.direction[e, 0]) else initial.direction[e]
        d_t, coupled = float(initial.d_t[e]), bool(initial.flag[e])
        edges[i].append(Edge(neighbour=j, d_t=d_t, direction=None if b is None else b.tolist(), coupled=coupled))
        edges[j].append(Edge(neighbour=i, d_t=d_t, direction=None if b is None else (-b).tolist(), coupled=coupled))
    commands: list[list[OperatorCommand]] = [[] for _ in range(n)]
    for command in scenario.commands:
        named = command.targets
        concerned = range(n) if named is None else sorted({a for pair in named for a in pair})
        for a in concerned:
            commands[a].append(OperatorCommand(time=command.time, action=command.action, pairs=named))
    order = slot_order(scenario, initial, gains).tolist()
    fallback = law.fallback_steps * sim.dt if ia.uncouple_when == "energy" else None
    shared = {name: getattr(ia, name) for name in LawParams.model_fields}  # the law's parameters, declared once
    agent_law = ControllerLaw(**shared, reach=ia.reach, fallback_time=fallback, sync_gain=law.sync_gain)
    return [
        AgentController(a, gains, dt=sim.dt, axes=scenario.space.axes, law=agent_law, edges=edges[a], commands=commands[a],
                        order=order)  # fmt: skip
        for a in range(n)
    ]


@dataclass(frozen=True)
class Flight:
    """What :func:`fly` recorded, shaped as :class:`tmem.Trajectory`'s arrays of the same name.

    Attributes
    ----------
    time : ndarray, shape (n_records,)
    agents : ndarray, shape (n_recorded,)
        The recorded agents.
    state : ndarray, shape (n_records, n_recorded, axes, 4)
        The states at each recorded step, before the vehicles move.
    control : ndarray, shape (n_records, n_recorded, axes)
        The set-points the controllers returned at that step.
    flag : ndarray, shape (n_records, n_pairs)
        ``F_en`` of each formation pair (:meth:`Scenario.pairs`) after that step's update, as its
        first agent holds it.
    events : list of Event
        The swarm's events: each pair's from its first agent, each command once.
    final_state : ndarray, shape (agents, axes, 4)
    controllers : list of AgentController
        The controllers, as they ended.
    """

    time: np.ndarray
    agents: np.ndarray
    state: np.ndarray
    control: np.ndarray
    flag: np.ndarray
    events: list[Event]
    final_state: np.ndarray
    controllers: list[AgentController]


def _step_events(controllers: Sequence[AgentController], seen: Sequence[int]) -> list[Event]:
    """The events of one step: each command once (as often as one controller logged it), then each
    pair's events as its first agent logged them, in the order of the pairs."""
    commands: dict[Event, int] = {}
    pairs = []
    for controller, first in zip(controllers, seen):
        logged = Counter()
        for event in controller.events[first:]:
            if event.kind == "command":
                logged[event] += 1
            elif event.agents[0] == controller.agent:
                pairs.append(event)
        for event, times in logged.items():
            commands[event] = max(commands.get(event, 0), times)
    return [event for event, times in commands.items() for _ in range(times)] + pairs


def fly(scenario: Scenario | str | os.PathLike | dict, controllers: Sequence[AgentController] | None = None) -> Flight:
    """Fly ``scenario`` with one controller per agent (:func:`controllers_for`), in a plain loop.

    At each step ``k`` (time ``k dt``) every agent makes its message, every controller reads all
    messages and returns its set-point, and every vehicle steps over ``dt`` with the vehicle
    model's compiled step, its set-point held.  Recorded as :func:`tmem.simulate` records; the
    arrays equal the trajectory's to the bit.

    Parameters
    ----------
    scenario : Scenario, str, os.PathLike or dict
        A validated scenario that per-agent controllers can fly, its file or its tables
        (:func:`tmem.scenario.as_scenario`).
    controllers : sequence of AgentController or None
        One per agent, in the order of the agents (they are reset first); ``None``:
        :func:`controllers_for` the scenario.

    Raises
    ------
    ControllerError
        As :func:`controllers_for`, where ``controllers`` do not fit the scenario, or where the
        scenario has sensing effects (the per-agent loop passes every message exactly).
    ScenarioError
        A file or tables refused, or a ``scenario`` of another type, in one line.
    """
    scenario = as_scenario(scenario)
    controllers = _controllers_to_fly(scenario, controllers)
    sim = scenario.simulation
    model = vehicle_model(scenario.model, scenario.wind)
    vehicle_step, hold = model.kernel(), model.step_params(sim.dt)
    x = build(scenario).state.copy()
    body = model.initial_body(x)
    n, n_axes = x.shape[:2]
    u = np.zeros((n, n_axes))
    steps = record_steps(sim.n_steps, sim.record_every)
    recorded = np.arange(n) if sim.record_agents is None else np.array(sim.record_agents, dtype=np.int64)
    pairs = scenario.pairs()
    state = np.empty((len(steps), len(recorded), n_axes, x.shape[2]))
    control = np.empty((len(steps), len(recorded), n_axes))
    flag = np.empty((len(steps), len(pairs)), dtype=np.int64)
    events: list[Event] = []
    q = 0
    for k in range(sim.n_steps + 1):
        t = k * sim.dt
        messages = [controller.message(x[i], t) for i, controller in enumerate(controllers)]
        seen = [len(controller.events) for controller in controllers]
        for i, controller in enumerate(controllers):
            u[i] = controller.update(x[i], messages, t)
        if any(len(controller.events) > first for controller, first in zip(controllers, seen)):
            events += _step_events(controllers, seen)
        if q < len(steps) and steps[q] == k:
            state[q], control[q] = x[recorded], u[recorded]
            flag[q] = [controllers[i].flag(j) for i, j in pairs.tolist()]
            q += 1
        if k < sim.n_steps:
            for i in range(n):
                vehicle_step(x, body, u, i, 1.0, hold, n_axes)
    return Flight(steps * sim.dt, recorded, state, control, flag, events, x, controllers)


def _controllers_to_fly(scenario: Scenario, controllers: Sequence[AgentController] | None) -> list[AgentController]:
    """The controllers :func:`fly` flies ``scenario`` with, reset; refused as :func:`fly` says."""
    _refuse_what_is_not_flown(scenario)
    if scenario.sensing is not None and not scenario.sensing.exact:
        raise ControllerError("sensing: fly() hands every controller every message exactly; noise, delay and loss "
                              "are tmem.simulate's measurement stage, or the bridge's own")  # fmt: skip
    if controllers is None:
        return controllers_for(scenario)
    controllers = list(controllers)
    fits = [c.agent for c in controllers] == list(range(scenario.n_agents))
    if not fits or any(c.settings.axes != scenario.space.axes for c in controllers):
        raise ControllerError(f"controllers: needs one per agent, agents 0..{scenario.n_agents - 1} in order, "
                              f"on {scenario.space.axes} axes")  # fmt: skip
    for controller in controllers:
        controller.reset()
    return controllers
