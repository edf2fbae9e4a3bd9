"""tmem: the thermal motion equivalent method (TMEM) for robot and UAV swarms.

The public API, in the order data flows::

    scenario = tmem.load("examples/fig9.toml")     # or tmem.preset("fig9")
    trajectory = tmem.simulate(scenario)           # engine: model, control, interaction, coupling
    summary = tmem.summarize(trajectory)           # metrics: RMS velocity, events, distances
    tmem.write_run(trajectory, "out/fig9")         # summary.json, trajectory.nc, figures
"""

from .control import interaction_point, modal_gains, printed_gains, roots
from .engine import Event, Trajectory, simulate
from .interaction import FUNCTIONS, attraction, improved_switching, repulsion, switching
from .model import state_matrices, zero_order_hold
from .scenario import Scenario, ScenarioError, load, loads, preset

__version__ = "0.1.0"

__all__ = [
    "FUNCTIONS",
    "Event",
    "Scenario",
    "ScenarioError",
    "Trajectory",
    "attraction",
    "improved_switching",
    "interaction_point",
    "load",
    "loads",
    "modal_gains",
    "preset",
    "printed_gains",
    "repulsion",
    "roots",
    "simulate",
    "state_matrices",
    "switching",
    "zero_order_hold",
]
