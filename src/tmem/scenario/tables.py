"""The tables of a scenario file, one validated pydantic model each, and their number types.

``[model]`` (Table 1), ``[controller]`` (roots (5)), ``[interaction]`` (7)-(11),
``[simulation]``, ``[space]``, ``[neighbors]``, ``[formation]``, ``[swarm]``,
``[thermostat]``, ``[coverage]``, ``[[obstacles]]``, ``[[agents]]`` (Table 2) and ``[[commands]]``
(``[sensing]`` has a module of its own, :mod:`tmem.scenario.sensing_table`).  Each table checks its own keys;
:mod:`tmem.scenario.schema` checks them against each other.  A check that
spans fields raises :class:`FieldError` naming the field at fault.
"""

from __future__ import annotations

import re
from typing import Annotated, ClassVar, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, field_validator, model_validator

from ..interaction.registry import FUNCTION_NAMES
from ..model import MODELS


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
    (:mod:`tmem.model.quadrotor`).  Defaults: the Crazyflie 2.x as RotorPy gives it
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
    (``"energy"``, :mod:`tmem.coupling`).  ``synchronise``: a coupled pair
    damps its relative motion (its slow mode's damping ratio
    ``sync_damping``) and puts the energy into its common motion
    (:mod:`tmem.synchronise`).  ``combine``: an agent's pushes of several
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
    """Time stepping and recording (``record_agents``: the agents recorded; all by default)."""

    dt: Annotated[float, Field(ge=1e-9, le=LIMIT)] = 1e-4
    duration: Positive = 60.0
    record_every: Annotated[int, Field(ge=1)] = 100
    record_agents: list[int] | None = None
    observe_gas: bool = False

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


class SpaceParams(StrictModel):
    """The space the agents fly in: 1 to 3 axes, optionally a box from 0 to ``box`` on each axis,
    periodic or walled.  ``wall_radius``: ``R_w``, a wall or obstacle pushes an agent whose ``P*`` is
    within ``R + R_w`` of it (default ``R``)."""

    axes: Literal[1, 2, 3] = 1
    periodic: bool = False
    walls: bool = False
    wall_radius: Positive | None = None
    box: list[Positive] | None = None

    @model_validator(mode="after")
    def _box_fits(self) -> "SpaceParams":
        if self.box is not None and len(self.box) != self.axes:
            raise FieldError("box", per_axis(self.axes, len(self.box)))
        if self.periodic and self.box is None:
            raise FieldError("box", "is required when periodic = true")
        if self.walls and self.box is None:
            raise FieldError("box", "is required when walls = true")
        if self.walls and self.periodic:
            raise FieldError("walls", "a box is periodic or walled, not both")
        return self


class Obstacle(StrictModel):
    """A circle (a sphere in 3-D, an interval in 1-D) the agents keep off: a neighbour held still."""

    center: Annotated[list[Number], Field(min_length=1, max_length=3)]
    radius: Positive


class CoverageParams(StrictModel):
    """How the coverage of a walled box is measured (:mod:`tmem.coverage`): square cells of side
    ``cell`` (m; default ``R``), each visited when an agent passes within ``sensor_radius`` (m) of its
    centre (0: when it passes through the cell)."""

    cell: Positive | None = None
    sensor_radius: NonNegative = 0.0


class ThermostatParams(StrictModel):
    """The swarm's temperature as an operator's set-point: its RMS velocity ``rms_velocity`` (m/s;
    none: the thermostat waits for a ``temperature`` command), reached with time constant ``tau`` (s)
    (:mod:`tmem.engine.gas`)."""

    rms_velocity: Positive | None = None
    tau: Annotated[float, Field(gt=0, le=LIMIT)] = 5.0


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


class FormationParams(StrictModel):
    """A formation: a generated shape, or edges among the ``[[agents]]``."""

    kind: Literal["chain", "ring", "triangle", "hex", "edges"]
    n: Annotated[int, Field(ge=2)] | None = None
    d_t: Positive | None = None
    bearing: bool = False
    edges: list[Annotated[list[int | float], Field(min_length=2, max_length=3)]] | None = None
    center: list[Number] | None = None
    velocity: list[Number] | None = None
    jitter: NonNegative = 0.0
    seed: Annotated[int, Field(ge=0)] = 0
    coupled: bool = True

    @model_validator(mode="after")
    def _kind_needs(self) -> "FormationParams":
        if self.kind == "edges":
            if not self.edges:
                raise FieldError("edges", 'is required (and not empty) for kind = "edges"')
            for name in ("n", "center", "velocity"):
                if getattr(self, name) is not None:
                    raise FieldError(name, 'is not used with kind = "edges": give the [[agents]]')
        else:
            if self.edges is not None:
                raise FieldError("edges", f'is only for kind = "edges", not {self.kind!r}')
            if self.kind == "triangle" and self.n not in (None, 3):
                raise FieldError("n", f"a triangle has 3 agents, got {self.n}")
            if self.kind in ("chain", "ring", "hex") and self.n is None:
                raise FieldError("n", f"is required for kind = {self.kind!r}")
            if self.kind == "ring" and self.n is not None and self.n < 3:
                raise FieldError("n", f"a ring needs at least 3 agents, got {self.n}")
        return self


class SwarmParams(StrictModel):
    """A random swarm: ``n`` agents uniform in ``region``, random velocities, from ``seed``."""

    n: Annotated[int, Field(ge=2)]
    seed: Annotated[int, Field(ge=0)] = 0
    region: list[Positive] | None = None
    speed_rms: NonNegative = 0.0


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
