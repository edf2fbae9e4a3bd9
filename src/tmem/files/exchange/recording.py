"""A run directory read back for export: what every exchange format draws from ``trajectory.nc``."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import NamedTuple

import numpy as np

from tmem.files.exchange.attitude import attitude_quaternion, body_attitude
from tmem.files.trajectory_file import (
    RunReadError, check_layout, components, open_trajectory, over_time, positions, reading, run_axes, trajectory_path,
)  # fmt: skip

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
    attitude : ndarray, shape (n_times, n_agents, 4)
        The attitude ``(qw, qx, qy, qz)``: the body attitude the run recorded, where it has one (a
        quadrotor's), else the one the tilts define (:mod:`tmem.files.exchange.attitude`).
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
    attitude: np.ndarray
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


#: A recorded body attitude's variables (:data:`tmem.vehicles.quadrotor.BODY_NAMES`).
QUATERNION = ("q_x", "q_y", "q_z", "q_w")


def _attitude(ds, tilts: np.ndarray) -> np.ndarray:
    """The recorded body attitude where the run has one, else the tilts' (time, agent, 4)."""
    if all(name in ds.variables for name in QUATERNION):
        return body_attitude(*(over_time(ds, name) for name in QUATERNION))
    return attitude_quaternion(tilts[..., 0], tilts[..., 1])


def _read(path: Path) -> Recording:
    with open_trajectory(path) as ds:
        if not str(ds.attrs.get("source", "")).startswith("tmem ") or "scenario" not in ds.attrs:
            raise RunReadError(f"export: {path}: is not the trajectory of a tmem run; give a folder written by tmem run")
        check_layout(ds, path, "export")
        if ds.sizes["agent"] == 0:
            raise RunReadError(f"export: {path}: the run recorded no agent (simulation.record_agents = []); nothing to export")
        scenario = str(ds.attrs["scenario"])
        tilts = _padded(components(ds, "phi"), 2)
        return Recording(
            time=ds["time"].values.astype(float),
            agents=ds["agent"].values.astype(np.int64),
            names=[str(name) for name in ds["agent_name"].values],
            positions=_padded(positions(ds), 3),
            tilts=tilts,
            attitude=_attitude(ds, tilts),
            active=over_time(ds, "active").astype(bool),
            pairs=np.stack([ds["pair_i"].values, ds["pair_j"].values], axis=-1).astype(np.int64).reshape(-1, 2),
            flags=over_time(ds, "F_en").astype(np.int8),
            distances=over_time(ds, "distance").astype(float),
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
    path = trajectory_path(run_dir, "export")
    with reading(path, "export"):
        return _read(path)
