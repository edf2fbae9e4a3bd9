"""Scenario files: the validated schema, TOML loading and the paper's presets.

A scenario is a TOML file with the tables ``[model]`` (Table 1), ``[controller]``
(roots (5)), ``[interaction]``, ``[simulation]``, ``[[agents]]`` (Table 2) and
``[[commands]]``.  Every key is checked: unknown keys, non-finite numbers and
values out of range are refused with :class:`ScenarioError`, a one-line
message naming the field and the reason.  Defaults are documented in
``docs/parameters.md``.
"""

from __future__ import annotations

import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

PRESETS = ("fig5", "fig7", "fig9", "repulsion")


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message is one line naming the field."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


Positive = Annotated[float, Field(gt=0)]


class ModelParams(_Strict):
    """Quadrocopter model (1)-(2), Table 1."""

    kp: Positive = 6.0
    kd: Positive = 25.0
    g: Positive = 9.8


class ControllerParams(_Strict):
    """Roots (5) of the modal controller, Table 1."""

    r_l: float = 12.0
    im_l: Annotated[float, Field(ge=0)] = 0.1
    im_r: Positive = 0.55

    @field_validator("r_l")
    @classmethod
    def _stable_left_pair(cls, v: float) -> float:
        if v <= 0:
            raise ValueError("must be > 0 so that the left pair of roots -r_l +- i im_l is stable")
        return v


class InteractionParams(_Strict):
    """Interaction function and its parameters, (7)-(11)."""

    function: Literal["repulsion", "attraction", "switching", "improved"] = "improved"
    radius: Positive = 20.0
    c_max: Positive = 0.1
    d_t: Positive = 35.0
    eps: Positive = 0.2

    @property
    def reach(self) -> float:
        """``R + R_j``: the distance below which two agents interact."""
        return 2.0 * self.radius

    @model_validator(mode="after")
    def _coupling_inside_reach(self) -> "InteractionParams":
        if self.d_t >= self.reach:
            raise _FieldError("d_t", f"must be less than R + R_j = {self.reach:g} m (condition (9)), got {self.d_t:g}")
        if self.eps >= self.d_t:
            raise _FieldError("eps", f"must be less than d_t = {self.d_t:g} m, got {self.eps:g}")
        return self


class SimulationParams(_Strict):
    """Time stepping and recording."""

    dt: Positive = 1e-4
    duration: Positive = 60.0
    record_every: Annotated[int, Field(ge=1)] = 100

    @property
    def n_steps(self) -> int:
        return int(round(self.duration / self.dt))

    @model_validator(mode="after")
    def _at_least_one_step(self) -> "SimulationParams":
        if self.dt > self.duration:
            raise _FieldError("dt", f"must not exceed duration = {self.duration:g} s, got {self.dt:g}")
        return self


class Agent(_Strict):
    """Initial state of one agent along the axis (Table 2)."""

    position: float
    velocity: float = 0.0
    tilt: float = 0.0
    tilt_rate: float = 0.0


class Command(_Strict):
    """An operator's command at ``time``: couple or uncouple a pair (or every pair)."""

    time: Annotated[float, Field(ge=0)]
    action: Literal["couple", "uncouple"]
    pair: tuple[int, int] | None = None


class Scenario(_Strict):
    """A whole scenario; see the module docstring."""

    name: str = ""
    model: ModelParams = ModelParams()
    controller: ControllerParams = ControllerParams()
    interaction: InteractionParams = InteractionParams()
    simulation: SimulationParams = SimulationParams()
    agents: list[Agent] = Field(min_length=2)
    commands: list[Command] = []

    @model_validator(mode="after")
    def _commands_fit(self) -> "Scenario":
        n = len(self.agents)
        for k, command in enumerate(self.commands):
            if command.time > self.simulation.duration:
                raise _FieldError(
                    f"commands[{k}].time",
                    f"must not be later than duration = {self.simulation.duration:g} s, got {command.time:g}",
                )
            if command.pair is not None:
                i, j = command.pair
                if not (0 <= i < n and 0 <= j < n):
                    raise _FieldError(f"commands[{k}].pair", f"names agent outside 0..{n - 1}: {list(command.pair)}")
                if i == j:
                    raise _FieldError(f"commands[{k}].pair", f"needs two different agents, got {list(command.pair)}")
        return self

    def to_toml(self) -> str:
        """The scenario as TOML text, every default written out."""
        return _to_toml(self.model_dump(mode="json"))


class _FieldError(ValueError):
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


def _explain(error: dict) -> str:
    where = _location(error["loc"])
    kind = error["type"]
    if kind == "extra_forbidden":
        reason = "unknown key (a typo?)"
    elif kind == "missing":
        reason = "is required"
    elif kind == "finite_number":
        reason = f"must be a finite number, got {error['input']}"
    elif kind == "too_short":
        reason = f"needs at least {error['ctx']['min_length']} entries, got {error['ctx']['actual_length']}"
    else:
        ctx_error = error.get("ctx", {}).get("error")
        if isinstance(ctx_error, _FieldError):
            where = f"{where}.{ctx_error.field}" if where else ctx_error.field
            reason = ctx_error.reason
        else:
            reason = error["msg"].removeprefix("Value error, ").replace("Input should be", "must be")
            if "input" in error and not isinstance(error["input"], dict | list):
                reason += f", got {error['input']!r}"
    return f"{where}: {reason}" if where else reason


def from_dict(data: dict) -> Scenario:
    """Validate a scenario given as nested dicts; raise :class:`ScenarioError`."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError("; ".join(_explain(e) for e in exc.errors())) from None


def load(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file; raise :class:`ScenarioError`."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise ScenarioError(f"{path}: is a directory, not a scenario file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path}: cannot be read ({exc.__class__.__name__}: {exc})") from None
    return loads(text, source=str(path))


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
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
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
