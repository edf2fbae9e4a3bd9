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

from tmem._lazy import submodules

#: Each public name and the module of this package that defines it, imported on first use (PEP 562),
#: so that a module of its tables (``tmem.scenario.fields``) imports without the whole schema.
_EXPORTS = {
    "Agent": "agents_table",
    "Command": "commands_table",
    "ControllerParams": "tables",
    "CoverageParams": "space_table",
    "FieldError": "tables",
    "FormationParams": "formation_table",
    "InteractionParams": "tables",
    "LIMIT": "tables",
    "LinearModelParams": "tables",
    "MAX_AGENTS_ALL_PAIRS": "schema",
    "MAX_RECORD_BYTES": "budget",
    "MODEL_KINDS": "tables",
    "ModelParams": "tables",
    "NeighborParams": "tables",
    "NonNegative": "tables",
    "Number": "tables",
    "Obstacle": "space_table",
    "PRESETS": "files",
    "Pair": "tables",
    "Positive": "tables",
    "QuadrotorModelParams": "tables",
    "Scenario": "schema",
    "ScenarioError": "tables",
    "ScenarioWarning": "bounds",
    "SafetyParams": "safety_table",
    "SensingParams": "sensing_table",
    "SimulationParams": "tables",
    "SpaceParams": "space_table",
    "StrictModel": "tables",
    "SwarmParams": "agents_table",
    "TRACK_ALL_PAIRS": "schema",
    "ThermostatParams": "space_table",
    "TurbulenceParams": "wind_table",
    "Vector": "agents_table",
    "WindParams": "wind_table",
    "as_scenario": "files",
    "describe": "files",
    "from_dict": "files",
    "load": "files",
    "loads": "files",
    "preset": "files",
    "read_text": "files",
    "with_changes": "files",
}


def __getattr__(name: str) -> object:
    """A public name from its module, or a module of this package, imported on first use."""
    module = _EXPORTS.get(name)
    if module is None:
        return _submodule(name)
    from importlib import import_module

    return getattr(import_module(f"tmem.scenario.{module}"), name)


_submodule = submodules(__name__)

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
    "SafetyParams",
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
