"""Vehicle models behind one contract (:class:`tmem.vehicles.base.VehicleModel`).

:data:`MODELS` is the registry: the scenario's ``[model] kind`` and the class
that implements it, imported only when a run needs it (validating a scenario
loads no compiled code).  Adding a model is one module in this package, one
row here and its parameters table in the scenario schema
(``docs/architecture.md``).
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

#: ``kind -> "module:Class"`` of each vehicle model.
MODELS: dict[str, str] = {
    "linear": "tmem.vehicles.linear:LinearModel",
    "quadrotor": "tmem.vehicles.quadrotor:QuadrotorModel",
}


def vehicle_class(kind: str):
    """The :class:`~tmem.vehicles.base.VehicleModel` subclass of the ``[model] kind`` ``kind``.

    Parameters
    ----------
    kind : str
        A key of :data:`MODELS`.
    """
    module, name = MODELS[kind].split(":")
    return getattr(import_module(module), name)


def vehicle_model(params: Any, wind: Any = None):
    """The :class:`~tmem.vehicles.base.VehicleModel` for a scenario's ``[model]`` table (by its ``kind``).

    Parameters
    ----------
    params
        The validated ``[model]`` table, e.g. :class:`~tmem.scenario.tables.LinearModelParams`.
    wind
        The scenario's ``[wind]`` table, for a model that feels it (the quadrotor's: the schema
        refuses it with another); default: none.
    """
    model_class = vehicle_class(params.kind)
    return model_class(params) if wind is None else model_class(params, wind)
