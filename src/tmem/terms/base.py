"""The contract of an agent term: its scenario table, its record, its compiled kernel.

An agent term adds a push to each agent's set-point after the TMEM law's pair terms (the
neighbours' pushes (8) and the formation pairs (9)-(11)) and before the gas's walls, which keep
the last word (W2).  It is a *gather*: agent ``i``'s push is computed from what ``i`` knows and
written to ``i``'s row only, ``u[i] += term(i, ...)``, so that agents can be pushed in any order,
on any number of threads (or a GPU's), with the same bits.

A term provides, as class attributes and methods (:mod:`tmem.terms.pull` is a worked example):

* :attr:`AgentTerm.name` and :attr:`AgentTerm.table` — its scenario table ``[name]``, a
  :class:`tmem.scenario.tables.StrictModel` whose ``check(scenario)`` (optional) checks it against
  the rest of the scenario, raising :class:`tmem.scenario.FieldError`;
* :meth:`AgentTerm.record` — the ``NamedTuple`` of arrays and numbers its kernel reads (and may
  change in place, e.g. an estimate it carries from step to step);
* :meth:`AgentTerm.kernel` — its compiled push ``push(i, k, known, agents, box, record)`` (``box``: the
  periodic box's sides, 0 on an open axis): agent
  ``i`` at step ``k``, its state as it knows it ``known[i]`` and ``P*`` (6) in
  ``agents.corrected[i, :, 0]``; it adds to ``agents.setpoint[i]``;
* :attr:`AgentTerm.rebuilt` — the fields of its record a checkpoint does not hold (numbers fixed for
  the run, work space), each with the reason it is made again exactly; every other field is saved;
* :attr:`AgentTerm.local` — whether it reads the agent's own state only, so that a per-agent
  controller (:mod:`tmem.agent`) could run it;
* :attr:`AgentTerm.steers_group` — whether it sets the group's mean motion (a mission): the speed
  synchronisation (S2) then damps the pairs' relative motion without holding their mean square
  speed (S3), which would fight every change of speed the term asks for (``interaction.keep_energy``).

A term that gathers over every agent (``local = False``) reads ``known[j]``, each agent's state as
it measures its own, not the messages between agents: the flocking laws refuse the sensing effects
between agents that would not reach them (:func:`check_gathered_knowledge`); the navigation takes
``known`` as what the group broadcasts (:mod:`tmem.terms.navigation`).  :func:`surroundings` and :func:`acceleration_per_input` give a record the
walls, the obstacles and the vehicle's set-point per unit of acceleration.
"""

from __future__ import annotations

from typing import Any, ClassVar, NamedTuple

import numpy as np

from tmem.scenario.fields import FieldError, per_axis

#: The ``[sensing]`` keys of what agents measure of each other (messages), which a gathering term does not read.
BETWEEN_AGENTS = ("position_noise", "velocity_noise", "delay", "period", "loss", "range")


def check_gathered_knowledge(scenario: Any, name: str) -> None:
    """Refuse, for the term ``[name]`` that gathers over every agent, a ``[sensing]`` effect between agents.

    The term reads every agent's state as that agent measures its own (``known``; own noise
    included); a neighbour's noise, delay, period, loss and range act on the messages the TMEM
    law's pairs read, and would not reach it.

    Parameters
    ----------
    scenario : Scenario
        The whole scenario.
    name : str
        The term's table.
    """
    sensing = scenario.sensing
    if sensing is None:
        return
    for key in BETWEEN_AGENTS:
        value = getattr(sensing, key)
        if (max(sensing.delays) if key == "delay" else value) not in (None, 0.0):
            raise FieldError(f"sensing.{key}", f"{value} acts on what agents measure of each other, which [{name}] "
                             "does not read: it gathers every agent's own measured state (own_position_noise, "
                             "own_velocity_noise)")  # fmt: skip


def surroundings(scenario: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(walls, obstacles)``: the walled box's sides (shape (axes,), 0 where an axis has no walls) and
    each ``[[obstacles]]`` circle's centre and radius (m, shape (obstacles, axes + 1)), as the gas holds them.

    Parameters
    ----------
    scenario : Scenario
        The whole scenario.
    """
    space = scenario.space
    walls = np.asarray(space.box, dtype=float) if space.walls else np.zeros(space.axes)
    obstacles = np.array([o.center + [o.radius] for o in scenario.obstacles], dtype=float).reshape(-1, space.axes + 1)
    return walls, obstacles


def acceleration_per_input(scenario: Any) -> float:
    """The horizontal acceleration (m/s^2) one unit of the scenario's vehicle's set-point gives
    (:meth:`tmem.vehicles.base.VehicleModel.acceleration_per_input`: ``g`` for a tilting multirotor).

    Parameters
    ----------
    scenario : Scenario
        The whole scenario: its ``[model]`` (and ``[wind]``).
    """
    from tmem.vehicles import vehicle_model

    return vehicle_model(scenario.model, scenario.wind).acceleration_per_input()


class AgentTerm:
    """An agent term (see the module text).  Subclasses set the class attributes and define the methods."""

    #: The scenario table's name, ``[name]``, and the key of :data:`tmem.terms.TERMS`.
    name: ClassVar[str]
    #: The scenario table.
    table: ClassVar[type]
    #: Fields of the record a checkpoint does not hold, with the reason each is made again exactly.
    rebuilt: ClassVar[dict[str, str]] = {}
    #: Whether the term reads the agent's own state only.
    local: ClassVar[bool] = True
    #: Whether the term sets the group's mean motion (module text).
    steers_group: ClassVar[bool] = False

    @classmethod
    def record(cls, settings: Any, scenario: Any, gains: Any) -> NamedTuple:
        """The record the kernel reads, for a run of ``scenario``.

        Parameters
        ----------
        settings
            The scenario's ``[name]`` table (an instance of :attr:`table`).
        scenario : Scenario
            The whole scenario.
        gains : ndarray, shape (n_law,)
            ``K`` of the law (:func:`tmem.law.modal.gains_for`).
        """
        raise NotImplementedError

    @classmethod
    def kernel(cls) -> Any:
        """The compiled push ``push(i, k, known, agents, box, record)`` (module text)."""
        raise NotImplementedError


def check_route(name: str, route, speed, axes: int) -> None:
    """A flocking term's moving reference: points of ``axes`` values, and a speed where it has more than one.

    Parameters
    ----------
    name : str
        The term's table, e.g. ``"olfati_saber"``.
    route : list of list of float or None
        ``route``: the reference's points (m).
    speed : float or None
        ``route_speed`` (m/s).
    axes : int
        The space's axes.
    """
    if route is None:
        if speed is not None:
            raise FieldError(f"{name}.route_speed", "is not used without a route")
        return
    if not route:
        raise FieldError(f"{name}.route", "is empty: give at least one point")
    for k, point in enumerate(route):
        if len(point) != axes:
            raise FieldError(f"{name}.route[{k}]", per_axis(axes, len(point)))
    if len(route) > 1 and speed is None:
        raise FieldError(f"{name}.route_speed", f"is required with a route of {len(route)} points: how fast the reference flies it")
