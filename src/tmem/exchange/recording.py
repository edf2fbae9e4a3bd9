"""A run directory read back for export: what every exchange format draws from ``trajectory.nc``."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..trajectory_file import Refused, components, open_trajectory, positions, read_run, run_axes

__all__ = ["Recording", "read_recording"]


class Recording(NamedTuple):
    """What a run recorded, as the exporters use it; every array is over time first.

    Attributes
    ----------
    time : ndarray, shape (n_times,)
        Seconds from the start of the run.
    agents : ndarray, shape (n_agents,)
        The recorded agents' indices in the scenario, from 0 (the paper numbers them from 1).
    names : list of str
        Their names (``agentN``, or the scenario's).
    positions : ndarray, shape (n_times, n_agents, 3)
        Positions (m) in the run's local frame; 0 on the axes the run does not have.
    tilts : ndarray, shape (n_times, n_agents, 2)
        Tilts ``phi_x``, ``phi_y`` (rad); 0 on the axes the run does not have.
    active : ndarray, shape (n_times, n_agents), bool
        Whether each agent was flying.
    pairs : ndarray, shape (n_pairs, 2)
        The tracked pairs' agents (indices in the scenario).
    flags : ndarray, shape (n_times, n_pairs)
        Each pair's coupling flag ``F_en``.
    distances : ndarray, shape (n_times, n_pairs)
        Each pair's distance (m).
    rms_velocity : ndarray, shape (n_times,)
        RMS velocity of the recorded agents flying (m/s).
    radius : float
        The interaction radius ``R`` (m).
    n_axes : int
        The run's axes.
    scenario : str
        The scenario that ran, as TOML.
    """

    time: np.ndarray
    agents: np.ndarray
    names: list[str]
    positions: np.ndarray
    tilts: np.ndarray
    active: np.ndarray
    pairs: np.ndarray
    flags: np.ndarray
    distances: np.ndarray
    rms_velocity: np.ndarray
    radius: float
    n_axes: int
    scenario: str

    def number(self, k: int) -> int:
        """The paper's number of the ``k``-th recorded agent: its index in the scenario plus 1.

        Parameters
        ----------
        k : int
            The agent's place among the recorded ones.
        """
        return int(self.agents[k]) + 1


def _padded(values: np.ndarray, width: int) -> np.ndarray:
    """``values`` (time, agent, axis) with zeros on the missing axes up to ``width``."""
    out = np.zeros(values.shape[:2] + (width,))
    out[..., : min(width, values.shape[-1])] = values[..., :width]
    return out


def _over_time(ds, name: str, dtype: type) -> np.ndarray:
    """A per-pair variable as ``(time, pair)``; none read when there are no pairs (reading an empty
    variable through xarray's h5netcdf backend can fail in h5py's selection)."""
    if ds.sizes["pair"] == 0:
        return np.zeros((ds.sizes["time"], 0), dtype=dtype)
    return ds[name].transpose("time", "pair").values.astype(dtype)


def _read(path: Path) -> Recording:
    with open_trajectory(path) as ds:
        if not str(ds.attrs.get("source", "")).startswith("tmem ") or "scenario" not in ds.attrs:
            raise Refused(f"export: {path}: is not the trajectory of a tmem run; give a folder written by tmem run")
        if ds.attrs.get("featureType") != "trajectory" or "agent_name" not in ds.variables:
            raise Refused(f"export: {path}: written by an earlier tmem (its layout is not CF trajectories); "
                          "run the scenario again")  # fmt: skip
        if ds.sizes["agent"] == 0:
            raise Refused(f"export: {path}: the run recorded no agent (simulation.record_agents = []); nothing to export")
        scenario = str(ds.attrs["scenario"])
        return Recording(
            time=ds["time"].values.astype(float),
            agents=ds["agent"].values.astype(np.int64),
            names=[str(name) for name in ds["agent_name"].values],
            positions=_padded(positions(ds), 3),
            tilts=_padded(components(ds, "phi"), 2),
            active=ds["active"].transpose("time", "agent").values.astype(bool),
            pairs=np.stack([ds["pair_i"].values, ds["pair_j"].values], axis=-1).astype(np.int64).reshape(-1, 2),
            flags=_over_time(ds, "F_en", np.int8),
            distances=_over_time(ds, "distance", float),
            rms_velocity=ds["rms_velocity"].values.astype(float),
            radius=float(tomllib.loads(scenario)["interaction"]["radius"]),
            n_axes=len(run_axes(ds)),
            scenario=scenario,
        )


def read_recording(run_dir: str | Path) -> Recording:
    """Read a run directory's ``trajectory.nc`` for export; refuse, in one line, what is not a tmem run.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``tmem run`` (or its ``trajectory.nc``).

    Raises
    ------
    ValueError
        In one line: no such folder, no ``trajectory.nc``, a file that cannot be read, a file of
        an earlier tmem, a run that recorded no agent.
    """
    return read_run(Path(run_dir), "export", _read)
