"""tmem: the thermal motion equivalent method (TMEM) for robot and UAV swarms.

The public API, in the order data flows::

    import tmem
    from tmem.metrics import summarize
    from tmem.io import write_run

    scenario = tmem.load("examples/fig9.toml")   # or tmem.preset("fig9")
    trajectory = tmem.simulate(scenario)         # engine: model, control, interaction, coupling
    summary = summarize(trajectory)              # RMS velocity, events, distances, formation
    write_run(trajectory, "out/fig9")            # summary.json, trajectory.nc, figures

The names below are loaded on first use (PEP 562), so that ``import
tmem.scenario`` or ``tmem --help`` does not load Numba, xarray or matplotlib.
Each compiled module refreshes Numba's cache itself (:mod:`tmem._numba_cache`).
"""

import typing as _typing
from importlib import import_module as _import_module
from importlib.util import find_spec as _find_spec

__version__ = "0.1.0"

#: Each public name and the submodule that defines it.
_EXPORTS = {
    "FUNCTION_NAMES": "interaction",
    "interaction_point": "control",
    "modal_gains": "control",
    "printed_gains": "control",
    "roots": "control",
    "Event": "engine",
    "Trajectory": "engine",
    "simulate": "engine",
    "state_matrices": "model.linear",
    "zero_order_hold": "model.linear",
    "Scenario": "scenario",
    "ScenarioError": "scenario",
    "load": "scenario",
    "loads": "scenario",
    "preset": "scenario",
}

__all__ = [
    "FUNCTION_NAMES",
    "Event",
    "Scenario",
    "ScenarioError",
    "Trajectory",
    "interaction_point",
    "load",
    "loads",
    "modal_gains",
    "preset",
    "printed_gains",
    "roots",
    "simulate",
    "state_matrices",
    "zero_order_hold",
]

if _typing.TYPE_CHECKING:  # what static tools see; at run time __getattr__ loads these
    from .control import interaction_point, modal_gains, printed_gains, roots
    from .engine import Event, Trajectory, simulate
    from .interaction import FUNCTION_NAMES
    from .model.linear import state_matrices, zero_order_hold
    from .scenario import Scenario, ScenarioError, load, loads, preset


def __getattr__(name: str) -> object:
    """A public name from its submodule, or a submodule (``tmem.engine``), imported on first use."""
    module = _EXPORTS.get(name)
    if module is not None:
        value = getattr(_import_module(f".{module}", __name__), name)
    elif not name.startswith("_") and _find_spec(f"{__name__}.{name}") is not None:
        value = _import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    loaded = {name for name in globals() if not name.startswith("_") or name.startswith("__")}
    return sorted(loaded | set(__all__))
