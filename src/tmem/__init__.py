"""tmem: the thermal motion equivalent method (TMEM) for robot and UAV swarms.

The public API, in the order data flows::

    import tmem

    scenario = tmem.load("examples/fig9.toml")   # or tmem.preset("fig9")
    trajectory = tmem.simulate(scenario)         # engine: vehicle, law, world
    summary = tmem.summarize(trajectory)         # RMS velocity, events, distances, formation
    tmem.write_run(trajectory, "out/fig9")       # summary.json, trajectory.nc, figures

The package, by role (``docs/architecture.md``): :mod:`tmem.scenario` (the schema and its
files), :mod:`tmem.law` (the TMEM law), :mod:`tmem.vehicles`, :mod:`tmem.world` (space,
neighbours, walls, sensing), :mod:`tmem.engine` (the step loop), :mod:`tmem.batch` (encounter
studies), :mod:`tmem.analysis`, :mod:`tmem.files`, :mod:`tmem.figures`, :mod:`tmem.paper`,
:mod:`tmem.sweep`, :mod:`tmem.agent` (one controller per agent) and :mod:`tmem.cli`.

The names below are loaded on first use (PEP 562), so that ``import
tmem.scenario`` or ``tmem --help`` does not load Numba, xarray or matplotlib.
Each compiled module refreshes Numba's cache itself (:mod:`tmem._numba_cache`).
Modules that lived at the top of the package before it was grouped by role
(``tmem.metrics``, ``tmem.io``, ``tmem.model`` ...) still import, with a
:class:`DeprecationWarning` naming their new place (:data:`MOVED`).
"""

import importlib.util as _util
import sys as _sys
import typing as _typing
import warnings as _warnings
from importlib import import_module as _import_module
from importlib.util import find_spec as _find_spec

__version__ = "0.1.0"

#: Each public name and the submodule that defines it.
_EXPORTS = {
    "FUNCTION_NAMES": "law.interaction",
    "interaction_point": "law.modal",
    "modal_gains": "law.modal",
    "printed_gains": "law.modal",
    "roots": "law.modal",
    "Event": "engine",
    "Trajectory": "engine",
    "simulate": "engine",
    "state_matrices": "vehicles.linear",
    "zero_order_hold": "vehicles.linear",
    "Scenario": "scenario",
    "ScenarioError": "scenario",
    "load": "scenario",
    "loads": "scenario",
    "preset": "scenario",
    "summarize": "analysis.metrics",
    "write_run": "files.io",
    "open_trajectory": "files.trajectory_file",
    "run_batch": "batch.encounters",
    "AgentController": "agent",
    "controllers_for": "agent",
}

__all__ = sorted(_EXPORTS)

#: Where each module that sat at the top of the package lives now (old name -> new name).
MOVED = {
    "control": "law.modal", "interaction": "law.interaction", "coupling": "law.coupling",
    "synchronise": "law.synchronise", "model": "vehicles", "space": "world.space",
    "neighbors": "world.neighbors", "sensing": "world.sensing", "streams": "world.streams",
    "formation": "world.formation", "initial": "world.initial", "relative_batch": "batch.relative",
    "metrics": "analysis.metrics", "observables": "analysis.observables", "reference": "analysis.reference",
    "coverage": "analysis.coverage", "io": "files.io", "trajectory_file": "files.trajectory_file",
    "saved": "files.saved", "outputs": "files.outputs", "exchange": "files.exchange", "plot": "figures.plot",
    "drawing": "figures.drawing", "shape_plot": "figures.shape_plot", "animate": "figures.animate",
    "viewer": "figures.viewer", "further": "paper.further", "terminal": "cli.terminal",
}  # fmt: skip

if _typing.TYPE_CHECKING:  # what static tools see; at run time __getattr__ loads these
    from tmem.agent import AgentController, controllers_for
    from tmem.analysis.metrics import summarize
    from tmem.batch.encounters import run_batch
    from tmem.engine import Event, Trajectory, simulate
    from tmem.files.io import write_run
    from tmem.files.trajectory_file import open_trajectory
    from tmem.law.interaction import FUNCTION_NAMES
    from tmem.law.modal import interaction_point, modal_gains, printed_gains, roots
    from tmem.scenario import Scenario, ScenarioError, load, loads, preset
    from tmem.vehicles.linear import state_matrices, zero_order_hold


class _MovedModules:
    """Imports ``tmem.<old>`` (and below it) as a stand-in for the module :data:`MOVED` names, with a
    warning: the stand-in reads every name from the module where it lives now."""

    def find_spec(self, fullname, path=None, target=None):
        """A spec for a name below a moved module; ``None`` for any other."""
        head = fullname.partition(".")[2].partition(".")[0]
        if not fullname.startswith(__name__ + ".") or head not in MOVED:
            return None
        return _util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        """The default module (a finder and loader by :mod:`importlib`'s protocol; not its ABCs, whose
        import costs a tenth of a second at every start)."""
        return None

    def exec_module(self, module):
        """Make ``module`` read its names from the module's new place."""
        head, _, rest = module.__name__.partition(".")[2].partition(".")
        new = ".".join(filter(None, (__name__, MOVED[head], rest)))
        _warnings.warn(f"{module.__name__} is now {new}", DeprecationWarning, stacklevel=2)
        target = _import_module(new)
        module.__getattr__ = lambda name: getattr(target, name)
        module.__doc__ = target.__doc__


_sys.meta_path.insert(0, _MovedModules())  # before the path finder, which would load a second copy


def __getattr__(name: str) -> object:
    """A public name from its submodule, or a submodule (``tmem.engine``), imported on first use."""
    module = _EXPORTS.get(name)
    if module is not None:
        value = getattr(_import_module(f".{module}", __name__), name)
    elif not name.startswith("_") and name not in MOVED and _find_spec(f"{__name__}.{name}") is not None:
        value = _import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    loaded = {name for name in globals() if not name.startswith("_") or name.startswith("__")}
    return sorted(loaded | set(__all__))
