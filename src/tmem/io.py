"""Run outputs: the trajectory as a NetCDF file or an xarray dataset, and run directories.

A run directory holds ``summary.json`` (:func:`tmem.metrics.summarize`),
``trajectory.nc`` (:func:`write_netcdf`, NetCDF-4) and the figures of
:mod:`tmem.plot`, and the manifest ``.tmem-output.json``.  When a directory
may be replaced, and how an interrupted run leaves nothing behind, is
:mod:`tmem.outputs`'s.

What the file holds is described once (:func:`contents`); :func:`to_dataset`
makes an :class:`xarray.Dataset` of it, and :func:`write_netcdf` writes it
through h5netcdf directly, as xarray would, without loading xarray, pandas
and Dask (a second and a half of a two-second command).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import NamedTuple

import numpy as np

from . import __version__, metrics, plot
from .engine import Trajectory
from .engine.gas import COLUMNS
from .outputs import OutputError, check_directory, replace_directory

__all__ = ["OutputError", "check_output_directory", "contents", "to_dataset", "write_netcdf", "write_run", "write_run_files"]

PAPER = "E. Heiss, A. Kozyr, O. Morozov, Formations Organization in Robotic Swarm Using the Thermal Motion Equivalent Method"


class Contents(NamedTuple):
    """A trajectory file's variables: each name maps to ``(dims, values, attributes)``.

    ``coords`` holds the dimension coordinates and ``pair_i``, ``pair_j``; ``data`` the variables;
    ``attrs`` the file's attributes.
    """

    coords: dict[str, tuple[tuple[str, ...], np.ndarray, dict]]
    data: dict[str, tuple[tuple[str, ...], np.ndarray, dict]]
    attrs: dict


def contents(trajectory: Trajectory) -> Contents:
    """What ``trajectory.nc`` holds.

    Dimensions ``time``, ``agent`` (the recorded agents, by index), ``axis``
    and ``pair``; variables ``P``, ``V``, ``phi``, ``omega`` (the vehicle
    model's state names) and the control ``U`` over (time, agent, axis); the
    model's body state, when it has one, over (time, agent), a variable per
    component (the quadrotor's ``height``, ``q_w``, ``rotor_1``, ...);
    ``active`` over (time, agent); the coupling flag ``F_en``, the distance and
    the interaction distance ``|d|`` (6) over (time, pair); each pair's set
    distance ``d_t``; the RMS velocity of the recorded agents over time; when
    the gas is observed, its running totals ``gas_*`` over time
    (:data:`tmem.engine.gas.COLUMNS`; :mod:`tmem.observables` reads them).  Units
    are in each variable's attributes; the scenario (as TOML), the gains and the
    events are in the file's attributes.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    n_axes = trajectory.scenario.space.axes
    coords = {
        "time": (("time",), trajectory.time, {"units": "s"}),
        "agent": (("agent",), trajectory.agents, {}),
        "axis": (("axis",), np.array(["x", "y", "z"][:n_axes]), {}),
        "pair": (("pair",), np.arange(len(trajectory.pairs), dtype=np.int64), {}),
        "pair_i": (("pair",), trajectory.pairs[:, 0], {"long_name": "first agent of the pair"}),
        "pair_j": (("pair",), trajectory.pairs[:, 1], {"long_name": "second agent of the pair"}),
    }
    over_agents = ("time", "agent", "axis")
    over_pairs = ("time", "pair")
    data = {}
    model = trajectory.model
    for m, (name, long_name, units) in enumerate(zip(model.state_names, model.long_names, model.state_units)):
        data[name] = (over_agents, trajectory.state[..., m], {"long_name": long_name, "units": units})
    if trajectory.body.shape[-1]:
        for m, (name, long_name, units) in enumerate(zip(model.body_names, model.body_long_names, model.body_units)):
            data[name] = (("time", "agent"), trajectory.body[..., m], {"long_name": long_name, "units": units})
    data["U"] = (over_agents, trajectory.control, {"long_name": "tilt set-point (control)", "units": "rad"})
    data["active"] = (("time", "agent"), trajectory.active.astype(np.int8), {"long_name": "agent flying", "units": "1"})
    data["F_en"] = (over_pairs, trajectory.flag.astype(np.int8), {"long_name": "pair coupling flag F_en", "units": "1"})
    data["distance"] = (over_pairs, trajectory.pair_distance, {"long_name": "distance |P_j - P_i|", "units": "m"})
    data["interaction_distance"] = (
        over_pairs,
        trajectory.interaction_distance,
        {"long_name": "interaction distance |P*_j - P*_i|, (6)", "units": "m"},
    )
    data["d_t"] = (("pair",), trajectory.d_t, {"long_name": "set distance of the pair", "units": "m"})
    data["rms_velocity"] = (
        ("time",),
        metrics.rms_velocity(model.velocity(trajectory.state), trajectory.active),
        {"long_name": "RMS velocity over the recorded agents flying", "units": "m s-1"},
    )
    if trajectory.gas.shape[1]:
        for c, (name, (long_name, units)) in enumerate(COLUMNS.items()):
            data[f"gas_{name}"] = (("time",), trajectory.gas[:, c], {"long_name": long_name, "units": units})
    attrs = {
        "title": f"tmem run {trajectory.scenario.name}".strip(),
        "source": f"tmem {__version__}",
        "references": PAPER,
        "scenario": trajectory.scenario.to_toml(),
        "gains": trajectory.gains,
        "gains_order": "K_P K_V K_phi K_omega",
        "events": json.dumps(metrics.summarize_events(trajectory.events)),
    }
    return Contents(coords, data, attrs)


def to_dataset(trajectory: Trajectory):
    """The recorded trajectory as an :class:`xarray.Dataset` (the variables of :func:`contents`).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    import xarray as xr

    c = contents(trajectory)
    return xr.Dataset(c.data, coords=c.coords, attrs=c.attrs)


def write_netcdf(trajectory: Trajectory, path: Path) -> None:
    """Write :func:`contents` to ``path`` as NetCDF-4, as ``to_dataset(trajectory).to_netcdf(path)`` would.

    As xarray writes it: floating-point variables with ``_FillValue = NaN``,
    strings as variable-length strings, and each variable over ``pair`` naming
    ``pair_i pair_j`` in its ``coordinates`` attribute, so that readers take
    those two as coordinates.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    path : Path
        The file to write.
    """
    import h5netcdf
    import h5py

    c = contents(trajectory)
    pair_coords = [name for name, (dims, _, _) in c.coords.items() if dims == ("pair",) and name != "pair"]
    with h5netcdf.File(path, "w") as f:
        f.dimensions = {name: len(values) for name, (dims, values, _) in c.coords.items() if dims == (name,)}
        for name, (dims, values, attrs) in {**c.coords, **c.data}.items():
            if values.dtype.kind == "U":
                variable = f.create_variable(name, dims, dtype=h5py.string_dtype())
                variable[...] = values.astype(object)
            else:
                fill = np.nan if values.dtype.kind == "f" else None
                variable = f.create_variable(name, dims, data=values, fillvalue=fill)
            variable.attrs.update(attrs)
            if "pair" in dims and name not in c.coords:
                variable.attrs["coordinates"] = " ".join(pair_coords)
        f.attrs.update(c.attrs)


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
    write_netcdf(trajectory, directory / "trajectory.nc")
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
