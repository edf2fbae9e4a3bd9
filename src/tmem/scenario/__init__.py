"""Scenarios: the validated schema, TOML loading and the paper's presets.

A scenario is a TOML file with the tables ``[model]`` (Table 1), ``[controller]``
(roots (5)), ``[interaction]``, ``[simulation]``, ``[[agents]]`` (Table 2) and
``[[commands]]``.  Every key is checked: unknown keys, non-finite numbers and
values out of range are refused with :class:`ScenarioError`, a one-line
message naming the field and the reason; physical values beyond what the model makes meaningful
are refused the same way, and values legal but doubtful warned of (:class:`ScenarioWarning`).  Defaults are documented in
``docs/parameters.md``.

* :mod:`~tmem.scenario.tables` — the tables' base class and number types; the model, controller,
  interaction, simulation and neighbour tables;
* :mod:`~tmem.scenario.agents_table` — the ``[[agents]]`` and ``[swarm]`` tables;
* :mod:`~tmem.scenario.space_table` — the ``[space]``, ``[[obstacles]]``, ``[coverage]`` and ``[thermostat]`` tables;
* :mod:`~tmem.scenario.formation_table` — the ``[formation]`` table and its checks against the scenario;
* :mod:`~tmem.scenario.commands_table` — the ``[[commands]]`` table and its checks against the scenario;
* :mod:`~tmem.scenario.schema` — :class:`Scenario`, the tables checked against each other;
* :mod:`~tmem.scenario.budget` — the memory a run needs and the size of its records;
* :mod:`~tmem.scenario.sensing_table` — the ``[sensing]`` table and its checks against the scenario;
* :mod:`~tmem.scenario.wind_table` — the ``[wind]`` table (the quadrotor's wind) and its checks;
* :mod:`~tmem.scenario.bounds` — the physical bounds' figures, each from the model, and
  :class:`ScenarioWarning`, the warning of a doubtful value;
* :mod:`~tmem.scenario.vehicle_bounds` — the quadrotor's and its wind's bounds;
* :mod:`~tmem.scenario.motion_bounds` — the bounds of the starts, the formation and the sensing;
* :mod:`~tmem.scenario.files` — reading, writing and editing files; the presets.
"""

from tmem.scenario.agents_table import Agent, SwarmParams, Vector
from tmem.scenario.budget import MAX_RECORD_BYTES
from tmem.scenario.commands_table import Command
from tmem.scenario.bounds import ScenarioWarning
from tmem.scenario.files import PRESETS, as_scenario, describe, from_dict, load, loads, preset, read_text, with_changes
from tmem.scenario.formation_table import FormationParams
from tmem.scenario.schema import MAX_AGENTS_ALL_PAIRS, TRACK_ALL_PAIRS, Scenario
from tmem.scenario.sensing_table import SensingParams
from tmem.scenario.space_table import CoverageParams, Obstacle, SpaceParams, ThermostatParams
from tmem.scenario.tables import (
    LIMIT,
    MODEL_KINDS,
    ControllerParams,
    FieldError,
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
    StrictModel,
)
from tmem.scenario.wind_table import TurbulenceParams, WindParams

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
    "ScenarioWarning",
    "SensingParams",
    "SimulationParams",
    "SpaceParams",
    "StrictModel",
    "SwarmParams",
    "ThermostatParams",
    "TurbulenceParams",
    "Vector",
    "WindParams",
    "as_scenario",
    "describe",
    "from_dict",
    "load",
    "loads",
    "preset",
    "read_text",
    "with_changes",
]
