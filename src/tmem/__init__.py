"""tmem: the thermal motion equivalent method (TMEM) for robot and UAV swarms.

The public API, in the order data flows::

    import tmem
    from tmem.metrics import summarize
    from tmem.io import write_run

    scenario = tmem.load("examples/fig9.toml")   # or tmem.preset("fig9")
    trajectory = tmem.simulate(scenario)         # engine: model, control, interaction, coupling
    summary = summarize(trajectory)              # RMS velocity, events, distances, formation
    write_run(trajectory, "out/fig9")            # summary.json, trajectory.nc, figures
"""

__version__ = "0.1.0"

from .control import interaction_point, modal_gains, printed_gains, roots  # noqa: E402
from .engine import Event, Trajectory, simulate  # noqa: E402
from .interaction import FUNCTION_NAMES  # noqa: E402
from .model.linear import state_matrices, zero_order_hold  # noqa: E402
from .scenario import Scenario, ScenarioError, load, loads, preset  # noqa: E402

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
