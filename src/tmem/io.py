"""Run outputs: the trajectory as an xarray dataset, and run directories.

A run directory holds ``summary.json`` (:func:`tmem.metrics.summarize`),
``trajectory.nc`` (:func:`to_dataset`, NetCDF-4 via h5netcdf) and the figures
of :mod:`tmem.plot`, and the manifest ``.tmem-output.json``.  When a
directory may be replaced, and how an interrupted run leaves nothing behind,
is :mod:`tmem.outputs`'s.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__, metrics, plot
from .engine import Trajectory
from .outputs import OutputError, check_directory, replace_directory

__all__ = ["OutputError", "check_output_directory", "to_dataset", "write_run", "write_run_files"]

PAPER = "E. Heiss, A. Kozyr, O. Morozov, Formations Organization in Robotic Swarm Using the Thermal Motion Equivalent Method"

def to_dataset(trajectory: Trajectory) -> xr.Dataset:
    """The recorded trajectory as an :class:`xarray.Dataset`.

    Dimensions ``time``, ``agent`` (the recorded agents, by index), ``axis``
    and ``pair``; variables ``P``, ``V``, ``phi``, ``omega`` and the control
    ``U`` over (time, agent, axis); ``active`` over (time, agent); the
    coupling flag ``F_en``, the distance and the interaction distance ``|d|``
    (6) over (time, pair); each pair's set distance ``d_t``; the RMS velocity
    of the recorded agents over time.  Units are in each variable's
    attributes; the scenario (as TOML), the gains and the events are in the
    dataset's attributes.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    n_axes = trajectory.scenario.space.axes
    coords = {
        "time": ("time", trajectory.time, {"units": "s"}),
        "agent": trajectory.agents,
        "axis": ["x", "y", "z"][:n_axes],
        "pair": np.arange(len(trajectory.pairs)),
        "pair_i": ("pair", trajectory.pairs[:, 0], {"long_name": "first agent of the pair"}),
        "pair_j": ("pair", trajectory.pairs[:, 1], {"long_name": "second agent of the pair"}),
    }
    over_agents = ("time", "agent", "axis")
    over_pairs = ("time", "pair")
    data = {}
    model = trajectory.model
    for m, (name, long_name, units) in enumerate(zip(model.state_names, model.long_names, model.state_units)):
        data[name] = (over_agents, trajectory.state[..., m], {"long_name": long_name, "units": units})
    data["U"] = (over_agents, trajectory.control, {"long_name": "tilt set-point (control)", "units": "rad"})
    data["active"] = (("time", "agent"), trajectory.active.astype(np.int8), {"long_name": "agent flying", "units": "1"})
    data["F_en"] = (over_pairs, trajectory.flag.astype(np.int8), {"long_name": "pair coupling flag F_en", "units": "1"})
    data["distance"] = (over_pairs, trajectory.pair_distance, {"long_name": "distance |P_j - P_i|", "units": "m"})
    data["interaction_distance"] = (
        over_pairs,
        trajectory.interaction_distance,
        {"long_name": "interaction distance |P*_j - P*_i|, (6)", "units": "m"},
    )
    data["d_t"] = ("pair", trajectory.d_t, {"long_name": "set distance of the pair", "units": "m"})
    data["rms_velocity"] = (
        ("time",),
        metrics.rms_velocity(model.velocity(trajectory.state), trajectory.active),
        {"long_name": "RMS velocity over the recorded agents flying", "units": "m s-1"},
    )
    attrs = {
        "title": f"tmem run {trajectory.scenario.name}".strip(),
        "source": f"tmem {__version__}",
        "references": PAPER,
        "scenario": trajectory.scenario.to_toml(),
        "gains": trajectory.gains,
        "gains_order": "K_P K_V K_phi K_omega",
        "events": json.dumps(metrics.summarize_events(trajectory.events)),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def check_output_directory(out: str | Path) -> Path:
    """Refuse an ``out`` that ``tmem run`` may not replace (:func:`tmem.outputs.manifest.check_directory`); return it.

    Parameters
    ----------
    out : str or Path
        The run directory (``--out``).
    """
    return check_directory(out, "run")


def write_run_files(trajectory: Trajectory, directory: Path) -> dict:
    """Write ``summary.json``, ``trajectory.nc`` and the figures into ``directory``; return the summary.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    directory : Path
        An existing directory (the temporary one of :func:`write_run`).
    """
    summary = metrics.summarize(trajectory)
    (directory / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    to_dataset(trajectory).to_netcdf(directory / "trajectory.nc", engine="h5netcdf")
    plot.write_figures(trajectory, directory)
    return summary


def write_run(trajectory: Trajectory, out: str | Path) -> dict:
    """Write a complete run directory at ``out`` (atomically) and return its summary.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    out : str or Path
        The run directory (``--out``); an existing one is replaced only as
        :mod:`tmem.outputs` allows.
    """
    with replace_directory(out, "run") as tmp:
        return write_run_files(trajectory, tmp)
