"""The tables of a scenario file: their base class, number types and errors, and the tables of the
vehicle and its law, one validated pydantic model each.

``[model]`` (Table 1), ``[controller]`` (roots (5)), ``[interaction]`` (7)-(11),
``[simulation]`` and ``[neighbors]`` are here.  The others have modules of their own:
:mod:`tmem.scenario.agents_table` (``[[agents]]``, Table 2, and ``[swarm]``),
:mod:`tmem.scenario.space_table` (``[space]``, ``[[obstacles]]``, ``[coverage]``,
``[thermostat]``), :mod:`tmem.scenario.formation_table`, :mod:`tmem.scenario.commands_table`,
:mod:`tmem.scenario.sensing_table` and :mod:`tmem.scenario.wind_table`; every table is importable
from :mod:`tmem.scenario`.  Each table checks its own keys; :mod:`tmem.scenario.schema` checks them
against each other.  A check that spans fields raises :class:`FieldError` naming the field
at fault.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import BeforeValidator, Field, field_validator, model_validator

from tmem.law.params import LawParams
from tmem.scenario.fields import (  # noqa: F401  (the tables' types, importable from here too)
    LIMIT, FieldError, NonNegative, Number, Pair, Positive, ScenarioError, StrictModel, per_axis,
)
from tmem.vehicles import VEHICLES, vehicle_table


def _linear_unless_named(table: object) -> object:
    """A ``[model]`` table without ``kind`` is the linear model, as before kinds were named."""
    if isinstance(table, dict) and "kind" not in table:
        return {"kind": "linear", **table}
    return table


#: The model kinds a scenario may name (the vehicle registry, :data:`tmem.vehicles.VEHICLES`).
MODEL_KINDS: tuple[str, ...] = tuple(VEHICLES)
#: The ``[model]`` table: each vehicle's own (:meth:`tmem.vehicles.vehicle_table`), chosen by its ``kind``
#: (pydantic reports an unknown kind as ``model.kind``).
ModelParams = Annotated[
    Union[tuple(vehicle_table(kind) for kind in MODEL_KINDS)],  # noqa: UP007  (a union built from the registry)
    BeforeValidator(_linear_unless_named),
    Field(discriminator="kind"),
]
#: The linear model's table, the default ``[model]``.
LinearModelParams = vehicle_table("linear")
#: The quadrotor's table.
QuadrotorModelParams = vehicle_table("quadrotor")


class ControllerParams(StrictModel):
    """Roots (5) of the modal controller, Table 1."""

    r_l: Number = 12.0
    im_l: NonNegative = 0.1
    im_r: Positive = 0.55

    @field_validator("r_l")
    @classmethod
    def _stable_left_pair(cls, v: float) -> float:
        if v <= 0:
            raise ValueError("must be > 0 so that the left pair of roots -r_l +- i im_l is stable")
        return v


class InteractionParams(LawParams):
    """Interaction function and its parameters, (7)-(11), and how coupled pairs behave: the law's
    parameters (:class:`tmem.law.params.LawParams`, with their checks) and what a scenario adds.

    ``radius``: ``R = R_j``, so that the reach is ``R + R_j = 2 R``.  ``synchronise``: a coupled
    pair damps its relative motion (its slow mode's damping ratio ``sync_damping``) and puts the
    energy into its common motion (:mod:`tmem.law.synchronise`).  ``combine``: an agent's pushes of
    several neighbours are summed (``"sum"``, the paper's reading) or averaged over the neighbours,
    walls and obstacles within reach (``"mean"``, which keeps each agent's loop ``A - B K`` in
    crowds: :mod:`tmem.engine.gas`).  ``keep_energy``: whether the synchronisation holds each pair's
    mean square speed (S3); by default it does, except where an agent term steers the group's mean
    motion (a ``[navigation]`` mission), whose changes of speed (S3) would undo.
    """

    radius: Positive = 20.0
    synchronise: bool = False
    keep_energy: bool | None = None
    sync_damping: Annotated[float, Field(gt=0, lt=1)] = 0.7
    combine: Literal["sum", "mean"] = "sum"

    @property
    def reach(self) -> float:
        """``R + R_j``: the distance below which two agents interact."""
        return 2.0 * self.radius


class SimulationParams(StrictModel):
    """Time stepping and recording (``record_agents``: the agents recorded; all by default).

    ``gas_period`` (s): how often the gas's counts are taken (:mod:`tmem.engine.gas`), rounded to
    whole steps, at least one.  At most 1 s: what the counts set, the weights of the mean of pushes
    and the thermostat's group pushes, is held that long."""

    dt: Annotated[float, Field(ge=1e-9, le=LIMIT)] = 1e-4
    duration: Positive = 60.0
    record_every: Annotated[int, Field(ge=1)] = 100
    record_agents: list[int] | None = None
    observe_gas: bool = False
    gas_period: Annotated[float, Field(gt=0, le=1.0)] = 0.1

    @property
    def n_steps(self) -> int:
        """Steps of ``dt`` in ``duration``."""
        return self.step_of(self.duration)

    def step_of(self, time: float) -> int:
        """The step at which something due at ``time`` (s) happens: the nearest whole step.

        Parameters
        ----------
        time : float
            Time from the start of the run (s).
        """
        return int(round(time / self.dt))

    @model_validator(mode="after")
    def _whole_steps(self) -> "SimulationParams":
        if self.dt > self.duration:
            raise FieldError("dt", f"must not exceed duration = {self.duration:g} s, got {self.dt:g}")
        steps = self.duration / self.dt
        if abs(steps - round(steps)) > 1e-6 * max(1.0, steps):
            raise FieldError("duration", f"must be a whole number of steps dt = {self.dt:g} s, got {self.duration:g}")
        first: dict[int, int] = {}
        for k, agent in enumerate(self.record_agents or []):
            if agent in first:
                raise FieldError(f"record_agents[{k}]", f"lists agent {agent} again (first at [{first[agent]}])")
            first[agent] = k
        if self.record_every > max(self.n_steps, 1):
            raise FieldError(
                "record_every", f"must not exceed the run's {self.n_steps} steps (duration / dt), got {self.record_every}"
            )
        return self


#: Swarms at least this large find their neighbours with Verlet lists under ``method = "auto"``.
LARGE_SWARM = 64


class NeighborParams(StrictModel):
    """Neighbour search: every pair, or Verlet lists built from cells with a skin."""

    method: Literal["auto", "all", "verlet"] = "auto"
    skin: Positive = 4.0

    def uses_lists(self, n_agents: int) -> bool:
        """Whether a swarm of ``n_agents`` finds its neighbours with lists (else it takes every pair).

        Parameters
        ----------
        n_agents : int
            The number of agents.
        """
        return self.method == "verlet" or (self.method == "auto" and n_agents >= LARGE_SWARM)
