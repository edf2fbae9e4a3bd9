"""Run outputs: the trajectory as a NetCDF file or an xarray dataset, and run directories.

A run directory holds ``summary.json`` (:func:`tmem.analysis.metrics.summarize`),
``trajectory.nc`` (:func:`write_netcdf`, NetCDF-4) and the figures of
:mod:`tmem.figures.plot`, and the manifest ``.tmem-output.json``.  When a directory
may be replaced, and how an interrupted run leaves nothing behind, is
:mod:`tmem.files.outputs`'s.

What the file holds is described once (:func:`contents`; its layout, CF trajectories, and how
tmem reads it back: :mod:`tmem.files.trajectory_file`); :func:`to_dataset`
makes an :class:`xarray.Dataset` of it, and :func:`write_netcdf` writes it
through h5netcdf directly, as xarray would, without loading xarray, pandas
and Dask (a second and a half of a two-second command).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import NamedTuple

import numpy as np

from tmem import __version__

from tmem.analysis import metrics

from tmem.figures import plot
from tmem.engine import Trajectory
from tmem.engine.gas import COLUMNS
from tmem.files.outputs import OutputError, check_directory, replace_directory
from tmem.files.trajectory_file import (
    CONVENTIONS, FRAME, FRAME_AXES, GRID_MAPPING, GRID_MAPPING_ATTRS, OVER_AGENTS, OVER_PAIRS, POSITION_ATTRS, TIME_UNITS,
)  # fmt: skip

__all__ = ["OutputError", "agent_names", "check_output_directory", "contents", "to_dataset", "write_netcdf", "write_run", "write_run_files"]

PAPER = "E. Heiss, A. Kozyr, O. Morozov, Formations Organization in Robotic Swarm Using the Thermal Motion Equivalent Method"


class Contents(NamedTuple):
    """A trajectory file's variables: each name maps to ``(dims, values, attributes)``.

    ``coords`` holds the coordinates (time, the agents and their names, the positions ``x``,
    ``y``, ``z``, the pairs and their agents); ``data`` the variables; ``attrs`` the file's attributes.
    """

    coords: dict[str, tuple[tuple[str, ...], np.ndarray, dict]]
    data: dict[str, tuple[tuple[str, ...], np.ndarray, dict]]
    attrs: dict


def agent_names(trajectory: Trajectory) -> list[str]:
    """Each recorded agent's name: its ``name`` in the scenario, else ``agentN``, numbered from 1 as in the paper.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    listed = trajectory.scenario.agents
    return [(listed[a].name if a < len(listed) else None) or f"agent{a + 1}" for a in trajectory.agents.tolist()]


def _coordinates(trajectory: Trajectory, order: np.ndarray) -> dict:
    """Time, the agents (index, and name: the trajectories' id), the positions, the pairs (CF 9.5)."""
    n_axes = trajectory.scenario.space.axes
    positions = trajectory.model.position(trajectory.state)[:, order]
    coords = {
        "time": (("time",), trajectory.time, {
            "standard_name": "time", "long_name": "time from the start of the run", "units": TIME_UNITS,
            "calendar": "proleptic_gregorian", "units_metadata": "leap_seconds: none", "axis": "T"}),
        "agent": (("agent",), trajectory.agents[order], {"long_name": "agent's index in the scenario, from 0"}),
        "agent_name": (("agent",), np.array(agent_names(trajectory), dtype=str)[order], {
            "long_name": "agent's name (agentN: numbered from 1, as in the paper)", "cf_role": "trajectory_id"}),
    }  # fmt: skip
    for a, name in enumerate(FRAME_AXES[: max(n_axes, 2)]):  # CF wants x and y: a 1-D run has y = 0
        values = positions[..., a] if a < n_axes else np.zeros(())
        coords[name] = (OVER_AGENTS if a < n_axes else (), values.T, {**POSITION_ATTRS[name], "units": "m"})
    coords["pair"] = (("pair",), np.arange(len(trajectory.pairs), dtype=np.int64), {"long_name": "pair's index"})
    coords["pair_i"] = (("pair",), trajectory.pairs[:, 0], {"long_name": "first agent of the pair"})
    coords["pair_j"] = (("pair",), trajectory.pairs[:, 1], {"long_name": "second agent of the pair"})
    return coords


def _per_axis(name: str, values: np.ndarray, long_name: str, units: str) -> dict:
    """``values`` (time, agent, axis) as one variable per axis over (agent, time): ``name_x``, ``name_y``, ``name_z``."""
    return {
        f"{name}_{axis}": (OVER_AGENTS, values[..., a].T, {"long_name": f"{long_name} on the {axis} axis", "units": units})
        for a, axis in enumerate(FRAME_AXES[: values.shape[-1]])
    }


def contents(trajectory: Trajectory) -> Contents:
    """What ``trajectory.nc`` holds: a CF trajectory per recorded agent (:mod:`tmem.files.trajectory_file`).

    Dimensions ``agent`` (the recorded agents, in index order), ``pair`` and
    ``time``.  Per agent, over (agent, time): the positions, as the coordinates
    ``x``, ``y``, ``z`` (as many as the run has axes; a 1-D run has ``y = 0``);
    the vehicle model's other states (``V``, ``phi``, ``omega``) and the control
    ``U``, one variable per axis (``V_x``, ``V_y``...); the model's body state,
    when it has one, a variable per component (the quadrotor's ``height``,
    ``q_w``, ``rotor_1``...); ``active``; each names
    the grid mapping ``crs`` (:data:`tmem.files.trajectory_file.GRID_MAPPING`).  The
    agents' names (``agent_name``, the trajectories' id).  Per pair, over (pair, time):
    the coupling flag ``F_en``, the distance and the interaction distance
    ``|d|`` (6); each pair's set distance ``d_t``.  Over time: the RMS velocity
    of the recorded agents, and when the gas is observed its running totals
    ``gas_*`` (:data:`tmem.engine.gas.COLUMNS`; :mod:`tmem.analysis.observables` reads
    them).  Units are in each variable's attributes; the scenario (as TOML),
    the gains and the events are in the file's attributes.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    order = np.argsort(trajectory.agents, kind="stable")
    data = _per_agent(trajectory, order)
    data["F_en"] = (OVER_PAIRS, trajectory.flag.T.astype(np.int8), {"long_name": "pair coupling flag F_en", "units": "1"})
    data["distance"] = (OVER_PAIRS, trajectory.pair_distance.T, {"long_name": "distance |P_j - P_i|", "units": "m"})
    data["interaction_distance"] = (
        OVER_PAIRS,
        trajectory.interaction_distance.T,
        {"long_name": "interaction distance |P*_j - P*_i|, (6)", "units": "m"},
    )
    data["d_t"] = (("pair",), trajectory.d_t, {"long_name": "set distance of the pair", "units": "m"})
    data["rms_velocity"] = (
        ("time",),
        metrics.rms_velocity(trajectory.model.velocity(trajectory.state), trajectory.active),
        {"long_name": "RMS velocity over the recorded agents flying", "units": "m s-1"},
    )
    if trajectory.gas.shape[1]:
        for c, (name, (long_name, units)) in enumerate(COLUMNS.items()):
            data[f"gas_{name}"] = (("time",), trajectory.gas[:, c], {"long_name": long_name, "units": units})
    return Contents(_coordinates(trajectory, order), data, _file_attributes(trajectory))


def _per_agent(trajectory: Trajectory, order: np.ndarray) -> dict:
    """The variables over (agent, time), the agents in ``order``, and the grid mapping they name."""
    model = trajectory.model
    data = {}
    for m, (name, long_name, units) in enumerate(zip(model.state_names, model.long_names, model.state_units)):
        if m != model.POSITION:
            data.update(_per_axis(name, trajectory.state[:, order][..., m], long_name, units))
    for m, (name, long_name, units) in enumerate(zip(model.body_names, model.body_long_names, model.body_units)):
        data[name] = (OVER_AGENTS, trajectory.body[:, order][..., m].T, {"long_name": long_name, "units": units})
    data.update(_per_axis("U", trajectory.control[:, order], "tilt set-point (control)", "rad"))
    data["active"] = (OVER_AGENTS, trajectory.active[:, order].T.astype(np.int8), {"long_name": "agent flying", "units": "1"})
    for _, _, attrs in data.values():  # every per-agent variable is located in the frame
        attrs["grid_mapping"] = GRID_MAPPING
    data[GRID_MAPPING] = ((), np.array(0, dtype=np.int32), dict(GRID_MAPPING_ATTRS))
    return data


def _file_attributes(trajectory: Trajectory) -> dict:
    """The file's attributes: conventions, provenance, the scenario as TOML, the gains, the events."""
    return {
        "Conventions": CONVENTIONS,
        "featureType": "trajectory",
        "title": f"tmem run {trajectory.scenario.name}".strip(),
        "source": f"tmem {__version__}",
        "history": f"written by tmem {__version__}",
        "references": PAPER,
        "comment": FRAME,
        "scenario": trajectory.scenario.to_toml(),
        "gains": trajectory.gains,
        "gains_order": "K_P K_V K_phi K_omega",
        "events": json.dumps(metrics.summarize_events(trajectory.events)),
    }


def to_dataset(trajectory: Trajectory):
    """The recorded trajectory as an :class:`xarray.Dataset` (the variables of :func:`contents`).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    import xarray as xr

    c = contents(trajectory)
    dataset = xr.Dataset(c.data, coords=c.coords, attrs=c.attrs)
    for name in c.coords:  # CF: coordinates carry no fill value
        dataset[name].encoding["_FillValue"] = None
    return dataset


def _coordinates_attribute(name: str, dims: tuple[str, ...], c: Contents) -> str | None:
    """The coordinates a data variable names, as xarray writes them: those over some of its dimensions."""
    names = [k for k, (d, _, _) in c.coords.items() if d != (k,) and set(d) <= set(dims)]
    return " ".join(names) if names and name not in c.coords else None


def write_netcdf(trajectory: Trajectory, path: Path) -> None:
    """Write :func:`contents` to ``path`` as NetCDF-4, as ``to_dataset(trajectory).to_netcdf(path)`` would.

    As xarray writes it: floating-point data variables with ``_FillValue = NaN``
    (coordinates with none, as CF asks), strings as variable-length strings, and
    each data variable naming in its ``coordinates`` attribute the coordinates
    over some of its dimensions (the positions, the agents' names, the pairs'
    agents), so that readers take those as coordinates.

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
    with h5netcdf.File(path, "w") as f:
        f.dimensions = {name: len(values) for name, (dims, values, _) in c.coords.items() if dims == (name,)}
        for name, (dims, values, attrs) in {**c.coords, **c.data}.items():
            if values.dtype.kind == "U":
                variable = f.create_variable(name, dims, dtype=h5py.string_dtype())
                variable[...] = values.astype(object)
            else:
                fill = np.nan if values.dtype.kind == "f" and name not in c.coords else None
                variable = f.create_variable(name, dims, data=values, fillvalue=fill)
            variable.attrs.update(attrs)
            coordinates = _coordinates_attribute(name, dims, c)
            if coordinates:
                variable.attrs["coordinates"] = coordinates
        f.attrs.update(c.attrs)


def check_output_directory(out: str | Path) -> Path:
    """Refuse an ``out`` that ``tmem run`` may not replace (:func:`tmem.files.outputs.manifest.check_directory`); return it.

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
        :mod:`tmem.files.outputs` allows.
    """
    with replace_directory(out, "run") as tmp:
        return write_run_files(trajectory, tmp)
