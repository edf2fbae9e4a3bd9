"""What a run produced: the trajectory, its events (read back from the loop's record), and a run that failed."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tmem.law import coupling
from tmem.world.initial import InitialArrays
from tmem.vehicles.base import VehicleModel
from tmem.scenario import Scenario
from tmem.engine.records import COMMANDS, Events


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
    rule: str | None = None  # for uncouple events: what released the pair (tmem.law.coupling.RELEASES)


@dataclass(frozen=True)
class Trajectory:
    """What a run produced.

    Attributes
    ----------
    scenario : Scenario
    initial : InitialArrays
        The initial arrays: states, flying agents, pairs with their ``d_t`` and
        directions, the periodic box.
    model : VehicleModel
        The vehicle model: state names, units and the indices of position,
        velocity and tilt in ``state``.
    gains : ndarray, shape (4,)
        ``K = (K_P, K_V, K_phi, K_omega)``.
    time : ndarray, shape (n_records,)
    agents : ndarray, shape (n_recorded,)
        Indices of the recorded agents.
    state : ndarray, shape (n_records, n_recorded, axes, 4)
        The state at each recorded time, named by ``model.state_names``
        (the linear model's ``(P, V, phi, omega)``).
    control : ndarray, shape (n_records, n_recorded, axes)
        The tilt set-point ``U`` applied from that time on.
    active : ndarray, shape (n_records, n_recorded), bool
        Whether each agent was flying.
    flag : ndarray, shape (n_records, n_pairs)
        ``F_en`` of each pair at each recorded time (after that step's check).
    pair_distance : ndarray, shape (n_records, n_pairs)
        ``|P_j - P_i|`` of each pair (nearest image).
    interaction_distance : ndarray, shape (n_records, n_pairs)
        ``|d| = |P*_j - P*_i|`` (6) of each pair; with sensing effects, as the pair's first agent
        measured it (NaN where it measured nothing: :mod:`tmem.engine.sensed`).
    min_distance : ndarray, shape (n_pairs,)
        Smallest distance of each formation pair over every step.
    min_neighbor_distance : float
        Smallest distance between any two agents within ``R + R_j`` of each
        other (in ``P*``; with sensing effects, as one of them measured) at any
        step; ``inf`` if no two came so close.
    final_state : ndarray, shape (agents, axes, 4)
        Every agent's state at the end.
    final_active : ndarray, shape (agents,), bool
    events : list of Event
    list_builds : int
        How often the neighbour lists were built.
    gas : ndarray, shape (n_records, 7) or (n_records, 0)
        When the gas is observed (:attr:`Scenario.gas_observed`), at each record the swarm's running
        totals :data:`tmem.engine.gas.TOTALS` and then :data:`tmem.engine.gas.SNAPSHOT`
        (:mod:`tmem.analysis.observables` reads them); no columns otherwise.
    body : ndarray, shape (n_records, n_recorded, n_body)
        The vehicle model's body state at each recorded time, named by ``model.body_names``
        (no columns for the linear model).
    final_body : ndarray, shape (agents, n_body)
        Every agent's body state at the end.
    """

    scenario: Scenario
    initial: InitialArrays
    model: VehicleModel
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
    gas: np.ndarray
    body: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 0)))
    final_body: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    @property
    def pairs(self) -> np.ndarray:
        """The pairs handled one by one (:meth:`Scenario.pairs`), shape (n_pairs, 2)."""
        return self.initial.edges

    @property
    def d_t(self) -> np.ndarray:
        """Set distance of each pair, shape (n_pairs,)."""
        return self.initial.d_t


def read_events(events: Events, n_events: int, order: np.ndarray, dt: float) -> list[Event]:
    """The first ``n_events`` events of a loop's record, with agents named by ``order[slot]``.

    Parameters
    ----------
    events : Events
        The record the loop logged them in (:func:`tmem.engine.stages.log_event`).
    n_events : int
        How many it logged.
    order : ndarray
        The agent in each slot.
    dt : float
        The time step (s): an event at step ``k`` happened at ``k dt``.
    """
    found = []
    for e in range(n_events):
        kind = coupling.EVENT_KINDS[events.kind[e]]
        agents = tuple(int(order[v]) for v in (events.i[e], events.j[e]) if v >= 0)
        action = COMMANDS[events.action[e]] if kind == "command" else None
        rule = coupling.RELEASES[events.rule[e]] if events.rule[e] >= 0 else None
        found.append(Event(time=round(float(events.step[e] * dt), 12), kind=kind, agents=agents, action=action, rule=rule))
    return found
