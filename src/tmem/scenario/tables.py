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

from typing import Annotated, ClassVar, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, field_validator, model_validator

from tmem.law.interaction.registry import FUNCTION_NAMES
from tmem.vehicles import MODELS


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message is one line naming the field."""


class FieldError(ValueError):
    """Raised by a cross-field check to name the field at fault, relative to its table.

    Parameters
    ----------
    field : str
        The field at fault, relative to its table (``"d_t"``).
    reason : str
        Why, in one line.
    """

    def __init__(self, field: str, reason: str):
        super().__init__(reason)
        self.field = field
        self.reason = reason


def per_axis(axes: int, got: int) -> str:
    """Why a list of ``got`` values is refused where one value per axis is needed, and the fix.

    Parameters
    ----------
    axes : int
        ``space.axes``.
    got : int
        How many values were given.
    """
    reason = f"needs {axes} value{'s' if axes > 1 else ''}, one per axis (space.axes = {axes}), got {got}"
    if 1 <= got <= 3:
        reason += f"; for a {got}-D run set axes = {got} in [space]"
    return reason


class StrictModel(BaseModel):
    """Base of the scenario tables: unknown keys, non-finite numbers and quiet coercions refused."""

    # strict: no quiet coercion of true to 1 or "6.0" to 6.0.
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


#: Every number is bounded in magnitude, so that no product in the model overflows.
LIMIT = 1e9
Number = Annotated[float, Field(ge=-LIMIT, le=LIMIT)]
Positive = Annotated[float, Field(gt=0, le=LIMIT)]
NonNegative = Annotated[float, Field(ge=0, le=LIMIT)]
Pair = Annotated[list[int], Field(min_length=2, max_length=2)]


class LinearModelParams(StrictModel):
    """Quadrocopter model (1)-(2), linear per axis, Table 1: ``[model] kind = "linear"``."""

    kind: Literal["linear"] = "linear"
    kp: Positive = 6.0
    kd: Positive = 25.0
    g: Positive = 9.8

    #: The most axes a run of this model may have.
    max_axes: ClassVar[int] = 3


#: Most of ``kd x inner_period``: the rate loop (Q6) held over a sub-step stays close to the
#: continuous one (docs/vehicles.md).
MAX_RATE_LOOP_STEP = 0.25


class QuadrotorModelParams(StrictModel):
    """A nonlinear quadrotor under the paper's inner loop, ``[model] kind = "quadrotor"``
    (:mod:`tmem.vehicles.quadrotor`).  Defaults: the Crazyflie 2.x as RotorPy gives it
    (``docs/vehicles.md`` names the source of each number)."""

    kind: Literal["quadrotor"]
    kp: Positive = 6.0
    kd: Positive = 25.0
    g: Positive = 9.81
    mass: Positive = 0.03
    ixx: Positive = 1.43e-5
    iyy: Positive = 1.43e-5
    izz: Positive = 2.89e-5
    arm_length: Positive = 0.043
    k_eta: Positive = 2.3e-8
    k_m: Positive = 7.8e-10
    rotor_drag: NonNegative = 1.02506e-6
    inflow_drag: NonNegative = 7.553e-7
    c_dx: NonNegative = 0.0
    c_dy: NonNegative = 0.0
    c_dz: NonNegative = 0.0
    tau_m: Annotated[float, Field(ge=1e-6, le=LIMIT)] = 0.072
    rotor_speed_max: Positive = 2500.0
    altitude_kp: Positive = 16.0
    altitude_kd: Positive = 8.0
    inner_period: Annotated[float, Field(ge=1e-6, le=1.0)] = 0.002
    drag_feedforward: bool = True
    #: ``"acceleration"``: the airframe asked for (2)'s acceleration, (Q9)-(Q11); ``"tilt"``: the
    #: set-point ``U`` to the attitude loop, with the drag feed-forward (Q8) (docs/vehicles.md).
    inner_loop: Literal["acceleration", "tilt"] = "acceleration"

    #: The most axes a run of this model may have: the vertical one is the altitude hold's.
    max_axes: ClassVar[int] = 2

    @model_validator(mode="after")
    def _flies(self) -> "QuadrotorModelParams":
        hover = (self.mass * self.g / (4.0 * self.k_eta)) ** 0.5
        if hover >= 0.9 * self.rotor_speed_max:
            raise FieldError("rotor_speed_max", f"{self.rotor_speed_max:g} rad/s leaves no margin above the hover "
                             f"speed sqrt(m g / (4 k_eta)) = {hover:.4g} rad/s (at least 10 %)")  # fmt: skip
        if self.kd * self.inner_period > MAX_RATE_LOOP_STEP:
            raise FieldError("inner_period", f"{self.inner_period:g} s is too long for the rate loop: kd x inner_period = "
                             f"{self.kd * self.inner_period:.3g}, at most {MAX_RATE_LOOP_STEP:g}")  # fmt: skip
        if not self.drag_feedforward and self.inner_loop == "acceleration":
            raise FieldError("drag_feedforward", 'false is the tilt loop\'s (inner_loop = "tilt"): the acceleration loop '
                             "cancels the drag it feels")  # fmt: skip
        return self


def _linear_unless_named(table: object) -> object:
    """A ``[model]`` table without ``kind`` is the linear model, as before kinds were named."""
    if isinstance(table, dict) and "kind" not in table:
        return {"kind": "linear", **table}
    return table


#: The ``[model]`` table: one class per vehicle model, chosen by its ``kind`` (add a class to the
#: union for a new kind; pydantic then reports an unknown kind as ``model.kind``).
ModelParams = Annotated[
    LinearModelParams | QuadrotorModelParams,
    BeforeValidator(_linear_unless_named),
    Field(discriminator="kind"),
]
#: The model kinds a scenario may name (the vehicle-model registry; it loads no compiled code).
MODEL_KINDS: tuple[str, ...] = tuple(MODELS)


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


class InteractionParams(StrictModel):
    """Interaction function and its parameters, (7)-(11), and how coupled pairs behave.

    ``uncouple_when``: after an uncouple command, a pair lets go at the first
    moment (9) holds (``"window"``), or where its relative kinetic energy and
    ``f1 - f2`` match their values at coupling, within ``energy_tolerance``
    (``"energy"``, :mod:`tmem.law.coupling`).  ``synchronise``: a coupled pair
    damps its relative motion (its slow mode's damping ratio
    ``sync_damping``) and puts the energy into its common motion
    (:mod:`tmem.law.synchronise`).  ``combine``: an agent's pushes of several
    neighbours are summed (``"sum"``, the paper's reading) or averaged over
    the neighbours, walls and obstacles within reach (``"mean"``, which keeps
    each agent's loop ``A - B K`` in crowds: :mod:`tmem.engine.gas`).
    """

    function: Literal[FUNCTION_NAMES] = "improved"
    radius: Positive = 20.0
    c_max: Positive = 0.1
    d_t: Positive = 35.0
    eps: Positive = 0.2
    switch_at: Literal["window", "crossing"] = "window"
    uncouple_when: Literal["window", "energy"] = "window"
    energy_tolerance: Annotated[float, Field(gt=0, lt=1)] = 0.05
    synchronise: bool = False
    sync_damping: Annotated[float, Field(gt=0, lt=1)] = 0.7
    combine: Literal["sum", "mean"] = "sum"

    @property
    def reach(self) -> float:
        """``R + R_j``: the distance below which two agents interact."""
        return 2.0 * self.radius

    @model_validator(mode="after")
    def _coupling_inside_reach(self) -> "InteractionParams":
        if self.d_t >= self.reach:
            raise FieldError("d_t", f"must be less than R + R_j = {self.reach:g} m (condition (9)), got {self.d_t:g}")
        if self.eps >= self.d_t:
            raise FieldError("eps", f"must be less than d_t = {self.d_t:g} m, got {self.eps:g}")
        return self


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
