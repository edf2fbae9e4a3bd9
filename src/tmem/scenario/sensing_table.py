"""The ``[sensing]`` table: what the agents measure of each other, and its checks against the scenario.

Each key turns one effect on (:mod:`tmem.world.sensing` models them, ``docs/sensing.md`` explains
them); every default turns it off, so a table of defaults measures exactly:

* ``position_noise``, ``velocity_noise`` — the standard deviation of the Gaussian noise on a
  neighbour's position (m) and velocity (m/s) as an agent measures them, on each axis;
* ``own_position_noise``, ``own_velocity_noise`` — the same on the agent's own state;
* ``delay`` — the age of a neighbour's data when it is used (s): one number, or ``[min, max]``
  for a delay drawn for each message uniformly between them;
* ``period`` — the time (s) between two messages of an agent (default: one every step), and
  between two measurements of its own state;
* ``loss`` — the probability that a message from one agent to another is lost;
* ``hold`` — how long (s) past its largest delay a receiver keeps using the last message it got;
* ``range`` — the sensing range (m): an agent farther away is not measured at all;
* ``seed`` — the seed of the random streams (:mod:`tmem.world.streams`).

The noise keys say what they blur (position, velocity) and whose state (a neighbour's, or with
``own_``, the agent's own), in the order an engineer reads a sensor's data sheet.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated

from pydantic import BeforeValidator, Field

from tmem.scenario.tables import LIMIT, FieldError, NonNegative, Positive, StrictModel

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario

#: Bytes of one agent's state on one axis, in a message kept for delay or loss: (P, V, phi, omega).
MESSAGE_BYTES_PER_AXIS = 32
#: A delay within this many steps of a whole number of steps is that number (rounding of tau / dt).
LAG_TOLERANCE = 1e-9


def _delay(value: object) -> object:
    """``delay``: a number of seconds, or ``[min, max]``; checked here so that the line says which."""
    numbers = value if isinstance(value, list) else [value]
    if isinstance(value, list) and len(value) != 2:
        raise ValueError(f"must be one delay (s) or a list [min, max], got a list of {len(value)}")
    for v in numbers:
        if isinstance(v, bool) or not isinstance(v, int | float) or not (0.0 <= v <= LIMIT):
            raise ValueError(f"must be delays in s, each a number from 0 to {LIMIT:g}, got {value!r}")
    if isinstance(value, list) and value[0] > value[1]:
        raise ValueError(f"[min, max] must have min <= max, got {value}")
    return [float(v) for v in value] if isinstance(value, list) else float(value)


Delay = Annotated[float | list[float], BeforeValidator(_delay)]


def lag(delay: float, dt: float) -> int:
    """The steps from a message's sending to the first step at which it is ``delay`` old.

    A message sent at step ``s`` may be used from step ``s + lag``: the latest broadcast at or before
    ``t - delay``.  A delay within :data:`LAG_TOLERANCE` steps of a whole number is that number, so
    that ``0.3 / 0.1`` is 3 steps, not 4.

    Parameters
    ----------
    delay : float
        The delay (s).
    dt : float
        The step (s).
    """
    return max(0, math.ceil(delay / dt - LAG_TOLERANCE))


class SensingParams(StrictModel):
    """What each agent measures of itself and of its neighbours (module text; ``docs/sensing.md``)."""

    seed: Annotated[int, Field(ge=0, lt=2**63)] = 0
    position_noise: NonNegative = 0.0
    velocity_noise: NonNegative = 0.0
    own_position_noise: NonNegative = 0.0
    own_velocity_noise: NonNegative = 0.0
    delay: Delay = 0.0
    period: Positive | None = None
    loss: Annotated[float, Field(ge=0, lt=1)] = 0.0
    hold: Positive = 1.0
    range: Positive | None = None

    @property
    def delays(self) -> tuple[float, float]:
        """``(min, max)`` of the delay (s): equal for a fixed delay."""
        return tuple(self.delay) if isinstance(self.delay, list) else (self.delay, self.delay)

    @property
    def exact(self) -> bool:
        """Whether every effect is off: the agents then know every state exactly."""
        noise = (self.position_noise, self.velocity_noise, self.own_position_noise, self.own_velocity_noise)
        unlimited = self.range is None and self.period is None
        return not any(noise) and self.delays == (0.0, 0.0) and self.loss == 0.0 and unlimited

    def every(self, dt: float) -> int:
        """Steps between two messages of an agent (``period / dt``; 1 without a period).

        Parameters
        ----------
        dt : float
            The step (s).
        """
        return 1 if self.period is None else max(1, round(self.period / dt))

    def depth(self, dt: float) -> int:
        """How many past broadcasts a run keeps: enough for the largest delay and a period, and the
        hold with loss.

        0 when no message is delayed, held or lost: agents then read the states of the step.

        Parameters
        ----------
        dt : float
            The step (s).
        """
        oldest = lag(self.delays[1], dt) + self.every(dt) - 1 + (lag(self.hold, dt) if self.loss > 0.0 else 0)
        return oldest + 1 if oldest > 0 or self.loss > 0.0 else 0


def check_sensing(scenario: Scenario, n_agents: int, uses_lists: bool, limit: int) -> None:
    """The ``[sensing]`` table against the rest of the scenario; raise :class:`FieldError` naming the field.

    Parameters
    ----------
    scenario, n_agents
        The scenario, its tables valid on their own, and its number of agents.
    uses_lists : bool
        Whether the run finds neighbours with lists (:meth:`NeighborParams.uses_lists`).
    limit : int
        Most bytes a run may need (:func:`tmem.scenario.budget.memory_limit`).
    """
    sensing = scenario.sensing
    if sensing is None or sensing.exact:
        return
    if scenario.gas_observed:
        raise FieldError("sensing", "the gas's stages (thermostat, walls, obstacles, combine = 'mean', observe_gas) "
                         "read exact states: a run with sensing effects cannot observe its gas")  # fmt: skip
    if uses_lists and sensing.range is None:
        raise FieldError("sensing.range", "is required when neighbours are found with lists (neighbors.method = "
                         "'verlet', or 'auto' from 64 agents): the lists hold the agents within range")  # fmt: skip
    dt = scenario.simulation.dt
    if sensing.period is not None and abs(sensing.period / dt - sensing.every(dt)) > 1e-6 * sensing.every(dt):
        raise FieldError("sensing.period", f"must be a whole number of steps dt = {dt:g} s, got {sensing.period:g}")
    kept = sensing.depth(dt) * n_agents * scenario.space.axes * MESSAGE_BYTES_PER_AXIS
    if kept > limit:
        field = "sensing.hold" if sensing.loss > 0.0 and lag(sensing.hold, dt) > lag(sensing.delays[1], dt) else "sensing.delay"
        raise FieldError(field, f"keeps {sensing.depth(dt)} steps of past messages of {n_agents} agents, about "
                         f"{kept / 2**30:.3g} GiB (at most {limit / 2**30:.3g} GiB); shorten it or take a larger dt")  # fmt: skip


#: The measurement stage's fields (:class:`tmem.world.sensing.Sensing`) that the ``[sensing]`` table
#: and the run set: an override names the table's key instead.
DERIVED_FIELDS = ("agent", "every", "lag_min", "lag_max", "delay_min", "delay_max", "dt", "range2", "history", "own",
                  "pair_states", "pushes", "work")  # fmt: skip


def with_overrides(scenario: Scenario, overrides: dict | None, fields: tuple[str, ...]) -> tuple[Scenario, dict | None]:
    """The scenario with the overrides of its ``[sensing]`` table's keys set, validated as the table
    is, and the other overrides, checked: ``(scenario, rest)``.

    ``tmem.simulate(scenario, sensing={...})`` takes, over the table, the table's keys and the
    fields of the measurement stage that no key sets (an added effect's); a key of the table goes
    into the scenario, whose every check it then meets (``{"loss": 2.0}`` is refused as
    ``loss = 2.0`` in the file is).  ``rest`` is ``None`` where ``overrides`` is.

    Parameters
    ----------
    scenario : Scenario
        The scenario, validated.
    overrides : dict or None
        The overrides, by name.
    fields : tuple of str
        The measurement stage's fields (``Sensing._fields``).

    Raises
    ------
    ScenarioError
        One line naming the override at fault (``sensing.loss: must be less than 1, got 2.0``).
    """
    from tmem.scenario.files import with_changes  # the files module imports the schema, which imports this one
    from tmem.scenario.tables import ScenarioError

    if overrides is None:
        return scenario, None
    if not isinstance(overrides, dict):
        raise ScenarioError(f"sensing: must be a dict of the [sensing] table's keys, got {type(overrides).__name__}")
    keys = {k: v for k, v in overrides.items() if k in SensingParams.model_fields}
    rest = {k: v for k, v in overrides.items() if k not in keys}
    for key, value in rest.items():
        if key in DERIVED_FIELDS:
            raise ScenarioError(f"sensing.{key}: is set from the [sensing] table's keys and the run; give those "
                                f"({', '.join(SensingParams.model_fields)})")  # fmt: skip
        if key not in fields:
            raise ScenarioError(f"sensing.{key}: unknown key (a typo?); the [sensing] table's keys are "
                                f"{', '.join(SensingParams.model_fields)}")  # fmt: skip
        if isinstance(value, int | float) and not isinstance(value, bool) and not math.isfinite(value):
            raise ScenarioError(f"sensing.{key}: must be a finite number, got {value!r}")
    if keys:
        scenario = with_changes(scenario, {f"sensing.{k}": v for k, v in keys.items()})
    return scenario, rest
