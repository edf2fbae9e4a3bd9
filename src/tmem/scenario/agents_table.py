"""Where the agents come from: the ``[[agents]]`` table (Table 2), listed one by one, or the
``[swarm]`` table, drawn at random; and the listed agents' checks against the rest of the scenario.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Annotated

import numpy as np
from pydantic import Field, field_validator

from tmem.scenario.tables import FieldError, NonNegative, Number, Positive, StrictModel, per_axis

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario

Vector = Number | list[Number]
#: What an agent's name may hold: a robot's name, as ROS writes them (it names the agent's trajectory).
AGENT_NAME = re.compile(r"[A-Za-z0-9_.-]{1,64}")


class Agent(StrictModel):
    """Initial state of one agent (Table 2): a number per axis, or one number on one axis; its
    ``name`` (a robot's, say) names its trajectory in the run's files."""

    name: str | None = None
    position: Vector
    velocity: Vector = 0.0
    tilt: Vector = 0.0
    tilt_rate: Vector = 0.0
    active: bool = True

    @field_validator("name")
    @classmethod
    def _a_robot_name(cls, v: str | None) -> str | None:
        if v is not None and not AGENT_NAME.fullmatch(v):
            raise ValueError(f"must be 1 to 64 letters, digits, '_', '.' or '-' (a robot's name), got {v!r}")
        return v


class SwarmParams(StrictModel):
    """A random swarm: ``n`` agents uniform in ``region``, random velocities, from ``seed``; with
    ``min_spacing`` (m), no two closer than that (Poisson-disk sampling, :mod:`tmem.plan.starts`)."""

    n: Annotated[int, Field(ge=2)]
    seed: Annotated[int, Field(ge=0)] = 0
    region: list[Positive] | None = None
    speed_rms: NonNegative = 0.0
    min_spacing: Positive | None = None


def check_agents(scenario: Scenario, axes: int) -> None:
    """The ``[[agents]]`` against each other and the axes: names apart, places apart, one value per axis;
    raise :class:`FieldError` naming the field.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid on their own.
    axes : int
        ``space.axes``.
    """
    seen: dict[tuple, int] = {}
    named: dict[str, int] = {}
    for k, agent in enumerate(scenario.agents):
        if agent.name is not None:
            if agent.name in named:
                raise FieldError(f"agents[{k}].name", f"{agent.name!r} is the name of agents[{named[agent.name]}]: "
                                 "names tell the agents' trajectories apart")  # fmt: skip
            named[agent.name] = k
            if agent.name.startswith("agent") and agent.name[5:].isdigit() and agent.name != f"agent{k + 1}":
                raise FieldError(f"agents[{k}].name", f"{agent.name!r} is the name an unnamed agent "
                                 f"{agent.name[5:]} gets (agents are numbered from 1); choose another")  # fmt: skip
        place = tuple(np.ravel(agent.position).tolist())
        if place in seen:
            raise FieldError(
                f"agents[{k}].position",
                f"is the place of agents[{seen[place]}]: two agents at one point have no direction to part in",
            )
        seen[place] = k
        for name in ("position", "velocity", "tilt", "tilt_rate"):
            value = getattr(agent, name)
            if isinstance(value, list) and len(value) != axes:
                raise FieldError(f"agents[{k}].{name}", per_axis(axes, len(value)))
            if not isinstance(value, list) and axes > 1 and (name == "position" or value != 0.0):
                raise FieldError(f"agents[{k}].{name}", f"needs a list of {axes} values for axes = {axes}")
