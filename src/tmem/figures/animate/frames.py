"""What an animation draws of a run, read from its ``trajectory.nc``: the frames, agents and pairs."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tmem.figures.drawing import columns_of, evenly
from tmem.files.trajectory_file import RunReadError, check_layout, open_trajectory, over_time, positions, reading, run_axes, trajectory_path

#: Most agents drawn; larger runs are thinned evenly to this many.
MAX_AGENTS_DRAWN = 3000


@dataclass
class Frames:
    """What is drawn of a run, at the chosen frames and agents.

    Attributes
    ----------
    time : ndarray, shape (frame,)
        The frames' times (s).
    pos : ndarray, shape (frame, agent, axes)
        Positions of the drawn agents (m); 2 or 3 axes (a run on one axis with ``y = 0``).
    active : ndarray, shape (frame, agent), bool
        Whether each drawn agent flies.
    agents : ndarray, shape (agent,)
        The drawn agents' indices in the files (agent ``k + 1`` in the figure).
    agents_note : str
        Which agents are drawn when not all (``""`` when all).
    col_i, col_j : ndarray, shape (edge,)
        Columns in ``pos`` of each drawn pair's two agents.
    flag : ndarray, shape (frame, edge)
        ``F_en`` of each drawn pair.
    d_t : ndarray, shape (edge,)
        Set distances (m); NaN when not known.
    radius : float
        The interaction radius ``R`` (m).
    name : str
        The scenario's name.
    box : list or None
        The walled box's sides (m); None without walls.
    obstacles : list
        ``(center, radius)`` of each obstacle (m).
    line : bool
        Whether the run flew on one axis (drawn on the line ``y = 0``).
    """

    time: np.ndarray
    pos: np.ndarray
    active: np.ndarray
    agents: np.ndarray
    agents_note: str
    col_i: np.ndarray
    col_j: np.ndarray
    flag: np.ndarray
    d_t: np.ndarray
    radius: float
    name: str
    box: list | None
    obstacles: list
    line: bool = False

    @property
    def n_axes(self) -> int:
        """2 or 3."""
        return self.pos.shape[2]


def read_frames(run_dir: str | Path, max_frames: int) -> Frames:
    """Read the frames (at most ``max_frames``, evenly spread) and agents to draw.

    Parameters
    ----------
    run_dir : str or Path
        A run directory, or its ``trajectory.nc``.
    max_frames : int
        Most frames.

    Raises
    ------
    tmem.files.trajectory_file.RunReadError
        In one line: no such folder or file, a damaged or truncated file, one with nothing
        recorded, a scenario without ``interaction.radius``.
    """
    path = trajectory_path(run_dir, "animate")
    with reading(path, "animate"):
        return _read(path, max_frames)


def _scenario(ds, path: Path) -> tuple[dict, float]:
    try:
        scenario = tomllib.loads(ds.attrs["scenario"])
        return scenario, float(scenario["interaction"]["radius"])
    except (KeyError, TypeError, ValueError) as error:
        raise RunReadError(f"animate: {path}: the run's scenario attribute gives no interaction.radius") from error


def _read(path: Path, max_frames: int) -> Frames:
    """Read the frames and agents to draw from ``path``; a run on one axis on the line ``y = 0``."""
    with open_trajectory(path) as ds:
        check_layout(ds, path, "animate")
        if ds.sizes["time"] == 0 or ds.sizes["agent"] == 0:
            raise RunReadError("animate: the run has no recorded times or agents")
        scenario, radius = _scenario(ds, path)
        drawn = evenly(ds.sizes["agent"], MAX_AGENTS_DRAWN, "agents")
        sub = ds.isel(time=evenly(ds.sizes["time"], max_frames, "frames").index, agent=drawn.index)
        pos = positions(sub)
        line = pos.shape[2] == 1
        if line:
            pos = np.concatenate([pos, np.zeros_like(pos)], axis=-1)
        active = over_time(sub, "active").astype(bool) if "active" in sub else np.ones(pos.shape[:2], bool)
        # Pairs whose two agents are both drawn (``pair_i``/``pair_j`` hold agent indices).
        col_i, ok_i = columns_of(sub["agent"].values, ds["pair_i"].values)
        col_j, ok_j = columns_of(sub["agent"].values, ds["pair_j"].values)
        kept = np.flatnonzero(ok_i & ok_j)
        if "d_t" in ds:
            d_t = ds["d_t"].values[kept].astype(float)
        else:
            d_t = np.full(kept.size, float(scenario["interaction"].get("d_t", np.nan)))
        return Frames(
            time=sub["time"].values.astype(float), pos=pos, active=active,
            agents=sub["agent"].values.astype(np.int64), agents_note=drawn.note,
            col_i=col_i[kept], col_j=col_j[kept],
            flag=over_time(sub.isel(pair=kept), "F_en"),
            d_t=d_t, radius=radius, name=str(scenario.get("name", "")),
            box=scenario["space"]["box"] if scenario.get("space", {}).get("walls") else None,
            obstacles=[(o["center"], o["radius"]) for o in scenario.get("obstacles", [])], line=line,
        )  # fmt: skip
