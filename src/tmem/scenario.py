"""Scenario files: the validated schema, TOML loading and the paper's presets.

A scenario is a TOML file with the tables ``[model]`` (Table 1), ``[controller]``
(roots (5)), ``[interaction]``, ``[simulation]``, ``[[agents]]`` (Table 2) and
``[[commands]]``.  Every key is checked: unknown keys, non-finite numbers and
values out of range are refused with :class:`ScenarioError`, a one-line
message naming the field and the reason.  Defaults are documented in
``docs/parameters.md``.
"""

from __future__ import annotations

import json
import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from .formation import generate
from .interaction.registry import FUNCTION_NAMES, uses_coupling

PRESETS = ("fig5", "fig7", "fig9", "repulsion")


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message is one line naming the field."""


class StrictModel(BaseModel):
    # strict: no quiet coercion of true to 1 or "6.0" to 6.0.
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


#: Every number is bounded in magnitude, so that no product in the model overflows.
LIMIT = 1e9
Number = Annotated[float, Field(ge=-LIMIT, le=LIMIT)]
Positive = Annotated[float, Field(gt=0, le=LIMIT)]
NonNegative = Annotated[float, Field(ge=0, le=LIMIT)]
Pair = Annotated[list[int], Field(min_length=2, max_length=2)]
#: Most bytes a run may set aside for its records.
MAX_RECORD_BYTES = 8 * 2**30


class ModelParams(StrictModel):
    """Quadrocopter model (1)-(2), Table 1."""

    kind: Literal["linear"] = "linear"
    kp: Positive = 6.0
    kd: Positive = 25.0
    g: Positive = 9.8


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
    """Interaction function and its parameters, (7)-(11)."""

    function: Literal[FUNCTION_NAMES] = "improved"
    radius: Positive = 20.0
    c_max: Positive = 0.1
    d_t: Positive = 35.0
    eps: Positive = 0.2
    switch_at: Literal["window", "crossing"] = "window"

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

    @property
    def n_steps(self) -> int:
        """Steps of ``dt`` in ``duration``."""
        return self.step_of(self.duration)

    def step_of(self, time: float) -> int:
        """The step at which something due at ``time`` (s) happens: the nearest whole step."""
        return int(round(time / self.dt))

    @model_validator(mode="after")
    def _whole_steps(self) -> "SimulationParams":
        if self.dt > self.duration:
            raise FieldError("dt", f"must not exceed duration = {self.duration:g} s, got {self.dt:g}")
        steps = self.duration / self.dt
        if abs(steps - round(steps)) > 1e-6 * max(1.0, steps):
            raise FieldError("duration", f"must be a whole number of steps dt = {self.dt:g} s, got {self.duration:g}")
        return self


class SpaceParams(StrictModel):
    """The space the agents fly in: 1 to 3 axes, optionally a periodic box."""

    axes: Literal[1, 2, 3] = 1
    periodic: bool = False
    box: list[Positive] | None = None

    @model_validator(mode="after")
    def _box_fits(self) -> "SpaceParams":
        if self.box is not None and len(self.box) != self.axes:
            raise FieldError("box", f"needs {self.axes} values (one per axis), got {len(self.box)}")
        if self.periodic and self.box is None:
            raise FieldError("box", "is required when periodic = true")
        return self


class NeighborParams(StrictModel):
    """Neighbour search: every pair, or Verlet lists built from cells with a skin."""

    method: Literal["auto", "all", "verlet"] = "auto"
    skin: Positive = 4.0


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
    seed: int = 0
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
    seed: int = 0
    region: list[Positive] | None = None
    speed_rms: NonNegative = 0.0


Vector = Number | list[Number]


class Agent(StrictModel):
    """Initial state of one agent (Table 2): a number per axis, or one number on one axis."""

    position: Vector
    velocity: Vector = 0.0
    tilt: Vector = 0.0
    tilt_rate: Vector = 0.0
    active: bool = True


class Command(StrictModel):
    """An operator's command at ``time``.

    ``couple`` / ``uncouple`` act on ``pair``, on the listed ``pairs``, or on
    every formation pair when neither is given; ``remove`` / ``add`` act on
    ``agent``.
    """

    time: NonNegative
    action: Literal["couple", "uncouple", "remove", "add"]
    pair: Pair | None = None
    pairs: list[Pair] | None = None
    agent: int | None = None

    @model_validator(mode="after")
    def _targets(self) -> "Command":
        if self.action in ("couple", "uncouple"):
            if self.agent is not None:
                raise FieldError("agent", f"is for remove / add, not {self.action}; use pair or pairs")
            if self.pair is not None and self.pairs is not None:
                raise FieldError("pairs", "give pair or pairs, not both")
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


#: Beyond this many agents, a coupling function needs a [formation]: without one every pair
#: would be a formation pair, and their number grows as the square of the swarm.
MAX_AGENTS_ALL_PAIRS = 2000
#: Without a formation, swarms up to this size have every pair tracked (recorded distances,
#: per-pair figures) even when the function has no coupling flag.
TRACK_ALL_PAIRS = 32


class Scenario(StrictModel):
    """A whole scenario; see the module docstring.

    The agents come from exactly one of ``[[agents]]`` (Table 2),
    ``[formation]`` with a generated ``kind`` (chain, ring, triangle, hex) or
    ``[swarm]`` (random); ``[formation] kind = "edges"`` couples listed
    ``[[agents]]``.  Without a formation, a coupling function (10) or (11)
    treats every pair as a formation pair with the set distance
    ``interaction.d_t``: the paper's two-agent case.
    """

    name: str = ""
    model: ModelParams = ModelParams()
    controller: ControllerParams = ControllerParams()
    interaction: InteractionParams = InteractionParams()
    simulation: SimulationParams = SimulationParams()
    space: SpaceParams = SpaceParams()
    neighbors: NeighborParams = NeighborParams()
    formation: FormationParams | None = None
    swarm: SwarmParams | None = None
    agents: list[Agent] = []
    commands: list[Command] = []

    @property
    def n_agents(self) -> int:
        if self.swarm is not None:
            return self.swarm.n
        if self.formation is not None and self.formation.kind != "edges":
            return 3 if self.formation.kind == "triangle" else self.formation.n
        return len(self.agents)

    def pairs(self) -> np.ndarray:
        """The pairs handled one by one, ``(i, j)`` with ``i < j``, shape ``(m, 2)``.

        The formation's edges; without a formation, every pair when the function
        couples (the paper's case) or the swarm is small (at most
        :data:`TRACK_ALL_PAIRS` agents), else none.  These pairs carry the flag
        ``F_en`` and a distance record; all other neighbours only repel.
        """
        if self.formation is None:
            n = self.n_agents
            if not uses_coupling(self.interaction.function) and n > TRACK_ALL_PAIRS:
                return np.empty((0, 2), dtype=np.int64)
            i, j = np.triu_indices(n, k=1)
            return np.stack([i, j], axis=1).astype(np.int64)
        if self.formation.kind == "edges":
            return np.array(sorted(sorted(e[:2]) for e in self.formation.edges), dtype=np.int64).reshape(-1, 2)
        f = self.formation
        return generate(f.kind, self.n_agents, f.d_t or self.interaction.d_t, self.space.axes).edges

    @model_validator(mode="after")
    def _consistent(self) -> "Scenario":
        axes = self.space.axes
        self._check_sources()
        self._check_agents(axes)
        n = self.n_agents
        if n < 2:
            raise FieldError("agents", f"needs at least 2 agents, got {n}")
        if self.formation is not None:
            self._check_formation(axes, n)
        elif uses_coupling(self.interaction.function) and n > MAX_AGENTS_ALL_PAIRS:
            raise FieldError(
                "interaction.function",
                f"{self.interaction.function!r} without a [formation] makes all {n * (n - 1) // 2} pairs "
                f"formation pairs; give a [formation] or use 'repulsion' beyond {MAX_AGENTS_ALL_PAIRS} agents",
            )
        if self.swarm is not None:
            region = self.swarm.region or self.space.box
            if region is None:
                raise FieldError("swarm.region", "is required unless space.box is given")
            if len(region) != axes:
                raise FieldError("swarm.region", f"needs {axes} values (one per axis), got {len(region)}")
        if self.simulation.record_agents is not None:
            for k, a in enumerate(self.simulation.record_agents):
                if not 0 <= a < n:
                    raise FieldError(f"simulation.record_agents[{k}]", f"names agent {a}, outside 0..{n - 1}")
        pairs = self.pairs()  # generating a large formation is not free: once per validation
        self._check_commands(n, pairs)
        self._check_record_size(n, len(pairs))
        return self

    def _check_record_size(self, n: int, pairs: int) -> None:
        sim = self.simulation
        records = sim.n_steps // sim.record_every + 2
        agents = n if sim.record_agents is None else len(sim.record_agents)
        size = records * (agents * (5 * self.space.axes * 8 + 1) + pairs * 32)
        if size > MAX_RECORD_BYTES:
            raise FieldError(
                "simulation.record_every",
                f"the records would take {size / 2**30:.1f} GiB (at most {MAX_RECORD_BYTES / 2**30:g}); "
                "record less often or fewer agents (record_agents)",
            )

    def _check_sources(self) -> None:
        generated = self.formation is not None and self.formation.kind != "edges"
        sources = [name for name, given in (("agents", bool(self.agents)), ("formation", generated),
                                            ("swarm", self.swarm is not None)) if given]  # fmt: skip
        if len(sources) > 1:
            raise FieldError(sources[1], f"give the agents once: by {' or '.join(sources)}, not both")
        if not sources:
            raise FieldError("agents", "no agents: give [[agents]], a [formation] or a [swarm]")

    def _check_agents(self, axes: int) -> None:
        seen: dict[tuple, int] = {}
        for k, agent in enumerate(self.agents):
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
                    raise FieldError(f"agents[{k}].{name}", f"needs {axes} values (one per axis), got {len(value)}")
                if not isinstance(value, list) and axes > 1 and (name == "position" or value != 0.0):
                    raise FieldError(f"agents[{k}].{name}", f"needs a list of {axes} values for axes = {axes}")

    def _check_formation(self, axes: int, n: int) -> None:
        f = self.formation
        if not uses_coupling(self.interaction.function):
            raise FieldError("formation", "needs interaction.function 'switching' (10) or 'improved' (11)")
        if f.bearing and axes == 1:
            raise FieldError("formation.bearing", "a direction to hold needs 2 or 3 axes, got axes = 1")
        if f.kind in ("ring", "triangle", "hex") and axes == 1:
            raise FieldError("formation.kind", f"{f.kind!r} is planar and needs 2 or 3 axes, got axes = 1")
        d_t = f.d_t or self.interaction.d_t
        if d_t >= self.interaction.reach:
            raise FieldError("formation.d_t", f"must be less than R + R_j = {self.interaction.reach:g} m, got {d_t:g}")
        for name in ("center", "velocity"):
            value = getattr(f, name)
            if value is not None and len(value) != axes:
                raise FieldError(f"formation.{name}", f"needs {axes} values (one per axis), got {len(value)}")
        if f.kind == "edges":
            seen = set()
            for k, edge in enumerate(f.edges):
                i, j = edge[:2]
                if not (isinstance(i, int) and isinstance(j, int)):
                    raise FieldError(f"formation.edges[{k}]", f"needs two agent indices first, got {list(edge)}")
                if len(edge) == 3 and not 0 < edge[2]:
                    raise FieldError(f"formation.edges[{k}]", f"d_t must be > 0, got {edge[2]}")
                if not (0 <= i < n and 0 <= j < n) or i == j:
                    raise FieldError(f"formation.edges[{k}]", f"needs two different agents in 0..{n - 1}, got {list(edge)}")
                if len(edge) == 3 and edge[2] >= self.interaction.reach:
                    raise FieldError(f"formation.edges[{k}]", f"d_t must be less than R + R_j = {self.interaction.reach:g} m")
                if (min(i, j), max(i, j)) in seen:
                    raise FieldError(f"formation.edges[{k}]", f"repeats the pair {sorted((i, j))}")
                seen.add((min(i, j), max(i, j)))

    def _check_commands(self, n: int, formation_pairs: np.ndarray) -> None:
        pairs = {tuple(e) for e in formation_pairs.tolist()} if self.commands else set()
        active = [a.active for a in self.agents] if self.agents else [True] * n
        for k, command in sorted(enumerate(self.commands), key=lambda kc: kc[1].time):
            where = f"commands[{k}]"
            if command.time > self.simulation.duration:
                raise FieldError(
                    f"{where}.time", f"must not be later than duration = {self.simulation.duration:g} s, got {command.time:g}"
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

    def to_toml(self) -> str:
        """The scenario as TOML text, every default written out."""
        return _to_toml(self.model_dump(mode="json", exclude_none=True))


class FieldError(ValueError):
    """Raised by a cross-field check to name the field at fault, relative to its table."""

    def __init__(self, field: str, reason: str):
        super().__init__(reason)
        self.field = field
        self.reason = reason


def _location(loc: tuple) -> str:
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


_REWORDING = (
    ("Input should be a valid dictionary or instance of", "must be a table, a"),
    ("List should have", "must have"),
    ("Input should be", "must be"),
    (" after validation", ""),
)


def _explain(error: dict) -> str:
    where = _location(error["loc"])
    kind = error["type"]
    if kind == "extra_forbidden":
        reason = "unknown key (a typo?)"
    elif kind == "missing":
        reason = "is required"
    elif kind == "finite_number":
        reason = f"must be a finite number, got {error['input']}"
    else:
        ctx_error = error.get("ctx", {}).get("error")
        if isinstance(ctx_error, FieldError):
            where = f"{where}.{ctx_error.field}" if where and ctx_error.field else (where or ctx_error.field)
            reason = ctx_error.reason
        else:
            reason = error["msg"].removeprefix("Value error, ")
            for pydantic_words, ours in _REWORDING:
                reason = reason.replace(pydantic_words, ours)
            if "got" not in reason and "input" in error and not isinstance(error["input"], dict | list):
                reason += f", got {error['input']!r}"
    return f"{where}: {reason}" if where else reason


def describe(exc: ValidationError) -> str:
    """A validation failure as one line: each error's field and reason, in the file's words."""
    return "; ".join(_explain(e) for e in exc.errors())


def from_dict(data: dict) -> Scenario:
    """Validate a scenario given as nested dicts; raise :class:`ScenarioError`."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError(describe(exc)) from None


def read_text(path: Path, what: str, error: type[ValueError]) -> str:
    """The text of the ``what`` file at ``path``; a missing or unreadable file raises ``error`` in one line."""
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(f"{path}: no such file") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not a {what} file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{path}: cannot be read ({exc.__class__.__name__}: {exc})") from None


def load(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file; raise :class:`ScenarioError`."""
    path = Path(path)
    return loads(read_text(path, "scenario", ScenarioError), source=str(path))


def loads(text: str, source: str = "<scenario>") -> Scenario:
    """Parse and validate scenario TOML text; raise :class:`ScenarioError`."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{source}: TOML syntax error: {exc}") from None
    try:
        return from_dict(data)
    except ScenarioError as exc:
        raise ScenarioError(f"{source}: {exc}") from None


def with_changes(scenario: Scenario, changes: dict[str, Any]) -> Scenario:
    """A copy of ``scenario`` with values replaced by dotted path, validated again.

    Example: ``with_changes(s, {"interaction.function": "repulsion", "agents[1].velocity": 2.0})``.
    A whole list can be replaced too: ``{"agents": [{"position": 0.0}, {"position": 50.0}]}``.
    """
    data = scenario.model_dump()
    for path, value in changes.items():
        parts = [int(p) if p.isdigit() else p for p in path.replace("[", ".").replace("]", "").split(".")]
        node = data
        try:
            for part in parts[:-1]:
                node = node[part]
            if isinstance(node, dict) and parts[-1] not in node:
                raise KeyError(parts[-1])
            node[parts[-1]] = value
        except (KeyError, IndexError, TypeError):
            raise ScenarioError(f"{path}: unknown parameter path") from None
    return from_dict(data)


def preset(name: str) -> Scenario:
    """One of the shipped scenarios: the paper's ``fig5``, ``fig7``, ``fig9`` or ``repulsion``."""
    if name not in PRESETS:
        raise ScenarioError(f"preset: unknown name {name!r}; choose from {', '.join(PRESETS)}")
    text = resources.files("tmem").joinpath("presets", f"{name}.toml").read_text(encoding="utf-8")
    return loads(text, source=f"preset {name}")


def _to_toml(data: dict) -> str:
    lines: list[str] = []
    scalars = {k: v for k, v in data.items() if not isinstance(v, dict | list)}
    lines += [f"{k} = {_toml_value(v)}" for k, v in scalars.items()]
    for key, value in data.items():
        if isinstance(value, dict):
            lines += ["", f"[{key}]"] + [f"{k} = {_toml_value(v)}" for k, v in value.items()]
        elif isinstance(value, list):
            for item in value:
                lines += ["", f"[[{key}]]"]
                lines += [f"{k} = {_toml_value(v)}" for k, v in item.items() if v is not None]
    return "\n".join(lines).lstrip() + "\n"


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        # A JSON string is a TOML basic string, given raw non-ASCII text and an escaped DEL.
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007F")
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return str(v)


__all__ = [
    "PRESETS",
    "Agent",
    "Command",
    "ControllerParams",
    "InteractionParams",
    "ModelParams",
    "Scenario",
    "ScenarioError",
    "SimulationParams",
    "load",
    "loads",
    "preset",
    "with_changes",
]
