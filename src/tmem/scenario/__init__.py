"""Scenarios: the validated schema, TOML loading and the paper's presets.

A scenario is a TOML file with the tables ``[model]`` (Table 1), ``[controller]``
(roots (5)), ``[interaction]``, ``[simulation]``, ``[[agents]]`` (Table 2) and
``[[commands]]``.  Every key is checked: unknown keys, non-finite numbers and
values out of range are refused with :class:`ScenarioError`, a one-line
message naming the field and the reason.  Defaults are documented in
``docs/parameters.md``.

* :mod:`~tmem.scenario.tables` — one pydantic model per table, and the number types;
* :mod:`~tmem.scenario.schema` — :class:`Scenario`, the tables checked against each other;
* :mod:`~tmem.scenario.sensing_table` — the ``[sensing]`` table and its checks against the scenario;
* :mod:`~tmem.scenario.wind_table` — the ``[wind]`` table (the quadrotor's wind) and its checks;
* :mod:`~tmem.scenario.files` — reading, writing and editing files; the presets.
"""

from .files import PRESETS, describe, from_dict, load, loads, preset, read_text, with_changes
from .schema import MAX_AGENTS_ALL_PAIRS, MAX_RECORD_BYTES, TRACK_ALL_PAIRS, Scenario
from .sensing_table import SensingParams
from .wind_table import TurbulenceParams, WindParams
from .tables import (
    LIMIT,
    MODEL_KINDS,
    Agent,
    Command,
    Obstacle,
    ControllerParams,
    CoverageParams,
    FieldError,
    FormationParams,
    InteractionParams,
    LinearModelParams,
    ModelParams,
    NeighborParams,
    NonNegative,
    Number,
    Pair,
    Positive,
    QuadrotorModelParams,
    ScenarioError,
    SimulationParams,
    SpaceParams,
    StrictModel,
    SwarmParams,
    ThermostatParams,
    Vector,
)

__all__ = [
    "LIMIT",
    "MAX_AGENTS_ALL_PAIRS",
    "MAX_RECORD_BYTES",
    "MODEL_KINDS",
    "PRESETS",
    "TRACK_ALL_PAIRS",
    "Agent",
    "Command",
    "Obstacle",
    "ControllerParams",
    "CoverageParams",
    "FieldError",
    "FormationParams",
    "InteractionParams",
    "LinearModelParams",
    "ModelParams",
    "NeighborParams",
    "NonNegative",
    "Number",
    "Pair",
    "Positive",
    "QuadrotorModelParams",
    "Scenario",
    "ScenarioError",
    "SensingParams",
    "SimulationParams",
    "SpaceParams",
    "StrictModel",
    "SwarmParams",
    "ThermostatParams",
    "TurbulenceParams",
    "Vector",
    "WindParams",
    "describe",
    "from_dict",
    "load",
    "loads",
    "preset",
    "read_text",
    "with_changes",
]
