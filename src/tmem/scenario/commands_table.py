"""The ``[[commands]]`` table: an operator's commands in time, and their checks against the scenario
(agents and pairs that exist, a coupling function for ``couple``, agents removed only while flying).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import model_validator

from tmem.law.interaction.registry import uses_coupling
from tmem.scenario.tables import FieldError, NonNegative, Pair, Positive, StrictModel

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario


class Command(StrictModel):
    """An operator's command at ``time``.

    ``couple`` / ``uncouple`` act on ``pair``, on the listed ``pairs``, or on
    every formation pair when neither is given; ``remove`` / ``add`` act on
    ``agent``; ``temperature`` sets the thermostat's RMS velocity to ``value`` (m/s).
    """

    time: NonNegative
    action: Literal["couple", "uncouple", "remove", "add", "temperature"]
    pair: Pair | None = None
    pairs: list[Pair] | None = None
    agent: int | None = None
    value: Positive | None = None

    @model_validator(mode="after")
    def _targets(self) -> "Command":
        if (self.value is None) == (self.action == "temperature"):
            raise FieldError("value", "is required for temperature" if self.value is None else f"is for temperature, not {self.action}")
        if self.action == "temperature":
            if self.agent is not None or self.pair is not None or self.pairs is not None:
                raise FieldError("agent" if self.agent is not None else "pair", "a temperature command acts on the whole swarm")
        elif self.action in ("couple", "uncouple"):
            if self.agent is not None:
                raise FieldError("agent", f"is for remove / add, not {self.action}; use pair or pairs")
            if self.pair is not None and self.pairs is not None:
                raise FieldError("pairs", "give pair or pairs, not both")
            if self.pairs is not None and not self.pairs:
                raise FieldError("pairs", "is empty: leave it out to act on every formation pair, or list at least one")
            seen: set[tuple[int, int]] = set()
            for k, (i, j) in enumerate(self.pairs or []):
                if (min(i, j), max(i, j)) in seen:
                    raise FieldError(f"pairs[{k}]", f"names the pair {sorted((i, j))} a second time")
                seen.add((min(i, j), max(i, j)))
        else:
            if self.agent is None:
                raise FieldError("agent", f"is required for {self.action}")
            if self.pair is not None or self.pairs is not None:
                raise FieldError("pair", f"is for couple / uncouple, not {self.action}")
        return self

    @property
    def targets(self) -> list[list[int]] | None:
        """The pairs a couple / uncouple command names; ``None`` for every pair."""
        if self.pair is not None:
            return [self.pair]
        return self.pairs


def check_commands(scenario: Scenario, n: int, formation_pairs: np.ndarray) -> None:
    """The ``[[commands]]`` against the rest of the scenario, in the order of their times; raise
    :class:`FieldError` naming the field.

    Parameters
    ----------
    scenario, n
        The scenario, its tables valid on their own, and its number of agents.
    formation_pairs : ndarray, shape (m, 2)
        The pairs a couple / uncouple command may name (:meth:`Scenario.pairs`).
    """
    pairs = {tuple(e) for e in formation_pairs.tolist()} if scenario.commands else set()
    active = [a.active for a in scenario.agents] if scenario.agents else [True] * n
    for k, command in sorted(enumerate(scenario.commands), key=lambda kc: kc[1].time):
        where = f"commands[{k}]"
        if command.action == "couple" and not uses_coupling(scenario.interaction.function):
            raise FieldError(
                f"{where}.action",
                f"'couple' does nothing: interaction.function {scenario.interaction.function!r} has no coupling flag "
                "(use 'switching' (10) or 'improved' (11))",
            )
        if command.time > scenario.simulation.duration:
            raise FieldError(
                f"{where}.time", f"must not be later than duration = {scenario.simulation.duration:g} s, got {command.time:g}"
            )
        if command.agent is not None:
            if not 0 <= command.agent < n:
                raise FieldError(f"{where}.agent", f"names agent {command.agent}, outside 0..{n - 1}")
            wanted = command.action == "remove"
            if active[command.agent] != wanted:
                state = "not flying" if wanted else "already flying"
                raise FieldError(f"{where}.agent", f"cannot {command.action} agent {command.agent}: it is {state} then")
            active[command.agent] = not wanted
        field = f"{where}.pair" if command.pair is not None else f"{where}.pairs"
        for i, j in command.targets or []:
            if not (0 <= i < n and 0 <= j < n):
                raise FieldError(field, f"names agent outside 0..{n - 1}: {[i, j]}")
            if i == j:
                raise FieldError(field, f"needs two different agents, got {[i, j]}")
            if (min(i, j), max(i, j)) not in pairs:
                raise FieldError(field, f"{[i, j]} is not a formation pair")
