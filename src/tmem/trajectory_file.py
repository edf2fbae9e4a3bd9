"""The layout of ``trajectory.nc``, CF trajectories, and how tmem's tools read it back.

A run's file follows CF's discrete sampling geometry for trajectories (CF 1.11, chapter 9 and
Appendix H.4): one trajectory per recorded agent, all at the same times, in the multidimensional
array representation.  Per agent, each record is a row over ``(agent, time)``, the order CF
recommends (its section 2.4); the positions are the coordinates ``x``, ``y``, ``z`` of the run's
local Cartesian frame (:data:`FRAME`, tied to the Earth only by a placeholder grid mapping,
:data:`GRID_MAPPING`), every other per-axis quantity one variable per axis (``V_x``, ``phi_y``,
``U_z``).  ``docs/exchange.md`` says why each choice was made.

This module holds the names the writer (:func:`tmem.io.contents`) and the readers share, and the
readers' guard against files that are missing or damaged (:func:`read_run`); it loads nothing
heavier than NumPy until a file is opened.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TypeVar

import numpy as np

T = TypeVar("T")

#: The conventions the file follows (its ``Conventions`` attribute).
CONVENTIONS = "CF-1.11"
#: CF's time units need a reference date, and a run has none: the start of the run stands at this
#: placeholder date, so that the times are the seconds from the start.
TIME_UNITS = "seconds since 1970-01-01 00:00:00"
#: The local frame's axes, in the order of a run's axes: the positions are the coordinates of
#: these names, and every other per-axis quantity is one variable per axis (``V_x``, ``U_y``).
FRAME_AXES = ("x", "y", "z")
#: The frame and the clock, as the file's ``comment`` says them.
FRAME = (
    "Positions are in the run's local Cartesian frame (metres, right-handed, z up): x and y span the "
    "horizontal plane, z is the height above it; the frame is not tied to a place on the Earth, and the "
    "origin of its grid mapping is a placeholder. A 1-D run flies along x (y = 0). Times are seconds from "
    "the start of the run, which stands at the reference date of the time units."
)
#: CF asks that horizontal coordinates other than latitude and longitude be tied to the Earth by a
#: grid mapping (its section 5.6).  The frame's x-y plane is the tangent plane at its origin (x east,
#: y north): CF's orthographic projection about the origin.  A run has no place on the Earth, so the
#: origin is a placeholder, 0 N 0 E, as the time units' date is; a user who knows the site sets it.
GRID_MAPPING = "crs"
GRID_MAPPING_ATTRS = {
    "grid_mapping_name": "orthographic",
    "latitude_of_projection_origin": 0.0,
    "longitude_of_projection_origin": 0.0,
    "false_easting": 0.0,
    "false_northing": 0.0,
    "comment": "the run's frame is local: its origin here is a placeholder; set the two origin attributes "
    "to the site's to place the run on the Earth (x east, y north)",
}
#: The dimensions of what is recorded per agent and per pair: one row per agent (pair).
OVER_AGENTS = ("agent", "time")
OVER_PAIRS = ("pair", "time")
#: Each position coordinate's attributes besides its units (m).  x and y are the coordinates of a
#: plane (CF's projection coordinates, of a frame whose place on the Earth is not known), z the
#: height above it; the ``axis`` attribute marks them as CF's X, Y and Z.
POSITION_ATTRS = {
    "x": {"standard_name": "projection_x_coordinate", "long_name": "position on the x axis", "axis": "X"},
    "y": {"standard_name": "projection_y_coordinate", "long_name": "position on the y axis", "axis": "Y"},
    "z": {"standard_name": "height", "long_name": "position on the z axis, up", "axis": "Z", "positive": "up"},
}

__all__ = [
    "CONVENTIONS", "FRAME", "FRAME_AXES", "GRID_MAPPING", "GRID_MAPPING_ATTRS", "OVER_AGENTS", "OVER_PAIRS", "POSITION_ATTRS", "TIME_UNITS", "Refused",
    "components", "open_trajectory", "positions", "read_run", "run_axes", "trajectory_path",
]  # fmt: skip


class Refused(ValueError):
    """A readable trajectory that a command cannot use; its message is final (:func:`read_run`)."""


def trajectory_path(run_dir: Path, command: str) -> Path:
    """``run_dir``'s ``trajectory.nc`` (or ``run_dir`` itself, an ``.nc`` file); one that is not there is refused.

    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``, or its ``trajectory.nc``.
    command : str
        The command reading it, at the start of a message (``"animate"``).

    Raises
    ------
    ValueError
        In one line: no such file or folder, a file given for a folder, no ``trajectory.nc``.
    """
    if run_dir.suffix == ".nc":
        if not run_dir.is_file():
            raise ValueError(f"{command}: {run_dir}: {'is not a file' if run_dir.exists() else 'no such file'}")
        return run_dir
    if not run_dir.exists():
        raise ValueError(f"{command}: {run_dir}: no such folder")
    if not run_dir.is_dir():
        raise ValueError(f"{command}: {run_dir}: is a file, not a run folder; give the folder tmem run wrote")
    if not (run_dir / "trajectory.nc").is_file():
        raise ValueError(f"{command}: no trajectory.nc in {run_dir}; give a folder written by tmem run")
    return run_dir / "trajectory.nc"


@contextmanager
def _quiet_unraisable() -> Iterator[None]:
    """Silence errors raised while objects are freed (h5netcdf's half-opened file on a damaged one)."""
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None
    try:
        yield
    finally:
        gc.collect()
        sys.unraisablehook = hook


def _reason(exc: Exception) -> str:
    """An exception as a short phrase of one line: its message, or its class when it has none."""
    text = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
    text = text.strip().splitlines()[0] if text.strip() else type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."


def read_run(run_dir: Path, command: str, read: Callable[[Path], T]) -> T:
    """``read(path)`` of ``run_dir``'s ``trajectory.nc``; a missing, damaged or truncated file is refused in one line.

    A damaged file fails in h5py, h5netcdf, xarray or NumPy, each in its own way (``OSError``,
    ``KeyError``, ``RuntimeError``, ``MemoryError``...): any such failure while reading names the
    file and the reason.  A :class:`Refused` raised by ``read`` passes as it is.

    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``, or its ``trajectory.nc`` (:func:`trajectory_path`).
    command : str
        The command reading it, at the start of a message (``"animate"``).
    read : callable
        ``read(path)`` reads what the command needs from the file at ``path``.

    Raises
    ------
    ValueError
        In one line, naming the file and the reason.
    """
    path = trajectory_path(run_dir, command)
    message = None
    with _quiet_unraisable():
        try:
            return read(path)
        except Refused:
            raise
        except Exception as exc:  # noqa: BLE001 - see the docstring
            message = f"{command}: {path}: cannot be read as a run's trajectory ({_reason(exc)})"
    raise ValueError(message)  # outside the handler: the failed file is freed, quietly, before this


def open_trajectory(path: str | Path):
    """``trajectory.nc`` as an :class:`xarray.Dataset`, with the times in seconds from the start of the run.

    xarray would turn the CF times into dates from the placeholder reference date; tmem's tools
    keep them as the seconds they are (``decode_times=False``).

    Parameters
    ----------
    path : str or Path
        The file.
    """
    import xarray as xr

    return xr.open_dataset(path, engine="h5netcdf", decode_times=False)


def run_axes(dataset) -> tuple[str, ...]:
    """The axes the run flew on: those of :data:`FRAME_AXES` whose position varies over ``(agent, time)``.

    Parameters
    ----------
    dataset : xarray.Dataset
        An open ``trajectory.nc`` (:func:`open_trajectory`).
    """
    return tuple(a for a in FRAME_AXES if a in dataset.variables and dataset[a].dims == OVER_AGENTS)


def _stacked(dataset, names: list[str]) -> np.ndarray:
    """The variables ``names`` over ``(agent, time)``, stacked as one array ``(time, agent, axis)``."""
    shape = (dataset.sizes["time"], dataset.sizes["agent"], len(names))
    out = np.empty(shape)
    for a, name in enumerate(names):
        out[..., a] = dataset[name].transpose("time", "agent").values
    return out


def positions(dataset) -> np.ndarray:
    """The positions (m), shape ``(time, agent, axis)`` as the run kept them: the coordinates ``x``, ``y``, ``z``.

    Parameters
    ----------
    dataset : xarray.Dataset
        An open ``trajectory.nc`` (:func:`open_trajectory`), or a selection of it.
    """
    return _stacked(dataset, list(run_axes(dataset)))


def components(dataset, name: str) -> np.ndarray:
    """A per-axis state or the control, shape ``(time, agent, axis)``: ``name_x``, ``name_y``, ``name_z`` stacked.

    Parameters
    ----------
    dataset : xarray.Dataset
        An open ``trajectory.nc`` (:func:`open_trajectory`), or a selection of it.
    name : str
        The quantity: a vehicle model's state name (``"V"``, ``"phi"``, ``"omega"``) or ``"U"``.
    """
    return _stacked(dataset, [f"{name}_{a}" for a in run_axes(dataset)])
