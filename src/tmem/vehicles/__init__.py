"""Vehicle models behind one contract (:class:`tmem.vehicles.base.VehicleModel`).

:data:`VEHICLES` is the registry: each ``[model] kind``, the class that implements it and its
scenario table.  The scenario's ``[model]`` union is built from it (:mod:`tmem.scenario.tables`),
and a model's class is imported only when a run needs it, so validating a scenario loads no
compiled code.  Adding a model is one module in this package and one row here
(``docs/architecture.md``).

* :mod:`tmem.vehicles.linear` — the paper's linear quadrocopter model (1)-(2), stepped exactly;
* :mod:`tmem.vehicles.quadrotor` — a nonlinear quadrotor (the Crazyflie 2.x by default) under its
  flight controller (:mod:`tmem.vehicles.flight_controller`, :mod:`tmem.vehicles.rigid_body`), in
  wind (:mod:`tmem.vehicles.wind`); its table in :mod:`tmem.vehicles.quadrotor_table`;
* :mod:`tmem.vehicles.ground_robot` — a holonomic ground robot: a double integrator with a
  first-order drive and an acceleration limit.
"""

from __future__ import annotations

from tmem._lazy import import_named, submodules

from functools import cache
from typing import Any

#: ``kind -> ("module:Model", "module:Table")``: each vehicle model's class and its ``[model]`` table.
#: A model whose module loads no compiler keeps its table in it; the quadrotor's compiles on import.
VEHICLES: dict[str, tuple[str, str]] = {
    "linear": ("tmem.vehicles.linear:LinearModel", "tmem.vehicles.linear:LinearModelParams"),
    "quadrotor": ("tmem.vehicles.quadrotor:QuadrotorModel", "tmem.vehicles.quadrotor_table:QuadrotorModelParams"),
    "ground_robot": ("tmem.vehicles.ground_robot:GroundRobot", "tmem.vehicles.ground_robot:GroundRobotParams"),
}


@cache
def vehicle_class(kind: str):
    """The :class:`~tmem.vehicles.base.VehicleModel` subclass of the ``[model] kind`` ``kind``.

    Parameters
    ----------
    kind : str
        A key of :data:`VEHICLES`.
    """
    return import_named(VEHICLES[kind][0])


@cache
def vehicle_table(kind: str):
    """The ``[model]`` table of the kind ``kind`` (its module loads no compiler).

    Parameters
    ----------
    kind : str
        A key of :data:`VEHICLES`: the table is the second name of its row, the class the first.
    """
    return import_named(VEHICLES[kind][1])


def vehicle_model(params: Any, wind: Any = None):
    """The :class:`~tmem.vehicles.base.VehicleModel` for a scenario's ``[model]`` table (by its ``kind``).

    Parameters
    ----------
    params
        The validated ``[model]`` table, e.g. :class:`~tmem.vehicles.linear.LinearModelParams`.
    wind
        The scenario's ``[wind]`` table, for a model that feels it (the quadrotor's: the schema
        refuses it with another); default: none.
    """
    model_class = vehicle_class(params.kind)
    return model_class(params) if wind is None else model_class(params, wind)

__getattr__ = submodules(__name__)  # noqa: F811  (submodules loaded on first use)
