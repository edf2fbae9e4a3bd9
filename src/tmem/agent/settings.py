"""What an agent's controller is built from, checked: its gains, its law's parameters, its edges, its commands.

:class:`ControllerSettings` holds everything :class:`tmem.agent.controller.AgentController`
takes, validated as the scenario's tables are (:mod:`tmem.scenario.tables`: no unknown
keys, no non-finite numbers, no quiet coercion).  Whatever is wrong is refused with a
:class:`ControllerError` whose message is one line naming the field and the reason,
``edges[1].d_t: must be less than reach = 40 m, got 45``.  The defaults of the law's
parameters are the scenario's (``docs/parameters.md``).
"""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

from pydantic import Field, ValidationError, model_validator

from tmem.law.params import ControllerLaw
from tmem.scenario.files import describe
from tmem.scenario.fields import FieldError, NonNegative, Number, Pair, Positive, StrictModel

#: How far from 1 the length of an edge's direction may be (the engine's come from a division).
UNIT_TOLERANCE = 1e-9


class ControllerError(ValueError):
    """A controller that cannot be built or run as asked; the message is one line naming the field."""


class _BadField(ControllerError, FieldError):
    """A bad field of a table: on its own, one line naming the table and the field; inside another
    table, the field as the outer table's (``edges[0].d_t``), as :func:`tmem.scenario.describe` puts it."""

    def __init__(self, title: str, text: str):
        field, reason = text.split(": ", 1) if ": " in text else ("", text)
        FieldError.__init__(self, field, reason)
        self.args = (f"{title}: {text}",)


class _Checked(StrictModel):
    """A table that reports a bad field in one line (:class:`ControllerError`), after its own name."""

    _title: ClassVar[str] = ""

    def __init__(self, **data):
        try:
            super().__init__(**data)
        except ValidationError as exc:
            raise _BadField(self._title or type(self).__name__, describe(exc)) from None


class Edge(_Checked):
    """One formation edge of an agent: the neighbour it pairs with, under (9)-(11).

    Attributes
    ----------
    neighbour : int
        The neighbour's id.
    d_t : float or None
        The pair's set distance (m); ``None``: the controller's ``d_t``.
    direction : list of float or None
        A unit vector, one entry per axis: the direction from this agent to the neighbour that
        the pair holds while coupled (a formation's bearing, the spring ``K_P (d - d_t b)``);
        ``None``: the pair holds its distance only.
    coupled : bool
        ``F_en`` at the start.
    """

    neighbour: Annotated[int, Field(ge=0)]
    d_t: Positive | None = None
    direction: Annotated[list[Number], Field(min_length=1, max_length=3)] | None = None
    coupled: bool = False


class OperatorCommand(_Checked):
    """An operator's command to the agent's formation pairs, due at ``time``.

    Attributes
    ----------
    time : float
        When it is due (s), on the controller's clock: it acts at the first update at or after
        the tick nearest to it.
    action : str
        ``"uncouple"`` (the pair lets go at the first moment (9) holds, or by the energy rule) or
        ``"couple"`` (the pair may couple again).
    pairs : list of [int, int] or None
        The pairs it names, as ``[i, j]`` agent ids; those that are edges of this agent are
        acted on.  ``None``: every edge of the agent (a command to every pair of the swarm).
    """

    time: NonNegative
    action: Literal["couple", "uncouple"]
    pairs: list[Pair] | None = None


class ControllerSettings(_Checked):
    """Everything an :class:`~tmem.agent.controller.AgentController` is built from (see its parameters).

    Attributes
    ----------
    agent : int
        This agent's id.
    gains : list of float
        ``K = (K_P, K_V, K_phi, K_omega)`` (4).
    dt : float
        The update period (s).
    axes : int
        Horizontal axes, 1 to 3.
    law : ControllerLaw
        The law's parameters (:class:`tmem.law.params.ControllerLaw`), checked as a scenario's are.
    edges : list of Edge
    commands : list of OperatorCommand
    order : list of int or None
        The ids in the order the agent adds its neighbours' pushes.
    max_age : float or None
        Messages older than this (s) are not used.
    """

    _title: ClassVar[str] = "AgentController"

    agent: Annotated[int, Field(ge=0)]
    gains: Annotated[list[Number], Field(min_length=4, max_length=4)]
    dt: Annotated[float, Field(ge=1e-9, le=1e9)]
    axes: Literal[1, 2, 3] = 1
    law: ControllerLaw = ControllerLaw()
    edges: list[Edge] = []
    commands: list[OperatorCommand] = []
    order: list[Annotated[int, Field(ge=0)]] | None = None
    max_age: Positive | None = None

    @model_validator(mode="after")
    def _consistent(self) -> "ControllerSettings":
        if not self.gains[0] > 0.0:
            raise FieldError("gains[0]", f"K_P must be > 0 (P* (6) is divided by it), got {self.gains[0]:g}")
        self._check_edges()
        self._check_commands()
        if self.order is not None and len(set(self.order)) != len(self.order):
            raise FieldError("order", "names an agent twice")
        return self

    def _check_edges(self) -> None:
        seen: set[int] = set()
        for k, edge in enumerate(self.edges):
            if edge.neighbour == self.agent:
                raise FieldError(f"edges[{k}].neighbour", f"is this agent ({self.agent}): an agent is no neighbour of itself")
            if edge.neighbour in seen:
                raise FieldError(f"edges[{k}].neighbour", f"repeats the edge to agent {edge.neighbour}")
            seen.add(edge.neighbour)
            if edge.d_t is not None and edge.d_t >= self.law.reach:
                raise FieldError(f"edges[{k}].d_t", f"must be less than reach = {self.law.reach:g} m, got {edge.d_t:g}")
            if edge.direction is not None:
                where, length = f"edges[{k}].direction", math.hypot(*edge.direction)
                if len(edge.direction) != self.axes:
                    raise FieldError(where, f"needs {self.axes} values, one per axis, got {len(edge.direction)}")
                if abs(length - 1.0) > UNIT_TOLERANCE:
                    raise FieldError(where, f"must be a unit vector, got length {length:g}")

    def _check_commands(self) -> None:
        for k, command in enumerate(self.commands):
            if command.pairs is not None and not any(self.partner_in(pair) is not None for pair in command.pairs):
                raise FieldError(f"commands[{k}].pairs", f"names no edge of agent {self.agent}: {command.pairs}")

    def partner_in(self, pair: list[int]) -> int | None:
        """The neighbour a pair ``[i, j]`` names with this agent, if it is an edge of this agent; else ``None``.

        Parameters
        ----------
        pair : list of int
            Two agent ids.
        """
        i, j = pair
        other = j if i == self.agent else i if j == self.agent else None
        return other if other != self.agent and other in {edge.neighbour for edge in self.edges} else None
