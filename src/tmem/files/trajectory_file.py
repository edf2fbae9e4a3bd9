"""The layout of ``trajectory.nc``, CF trajectories, and how tmem's tools read it back.

A run's file follows CF's discrete sampling geometry for trajectories (CF 1.11, chapter 9 and
Appendix H.4): one trajectory per recorded agent, all at the same times, in the multidimensional
array representation.  Per agent, each record is a row over ``(agent, time)``, the order CF
recommends (its section 2.4); the positions are the coordinates ``x``, ``y``, ``z`` of the run's
local Cartesian frame (:data:`FRAME`, tied to the Earth only by a placeholder grid mapping,
:data:`GRID_MAPPING`), every other per-axis quantity one variable per axis (``V_x``, ``phi_y``,
``U_z``).  ``docs/exchange.md`` says why each choice was made.

This module holds the names the writer (:func:`tmem.files.io.contents`) and the readers share, the
readers' guard against folders and files that are missing, damaged or of an earlier tmem
(:func:`run_directory`, :func:`trajectory_path`, :func:`reading`, :func:`check_layout`), and the
arrays as the tools use them, over time first (:func:`positions`, :func:`components`,
:func:`over_time`), from the file opened by xarray (:func:`open_trajectory`) or by h5netcdf (which
loads faster, for ``tmem plot`` and ``tmem view``).  It loads nothing heavier than NumPy until a file
is opened.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from tmem.files.outputs.names import OneLineError

#: A run directory's files that tmem's tools read back (``tmem animate`` and ``tmem export`` need
#: only the first).
RUN_FILES = ("trajectory.nc", "summary.json")

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
    "CONVENTIONS", "FRAME", "FRAME_AXES", "GRID_MAPPING", "GRID_MAPPING_ATTRS", "OVER_AGENTS", "OVER_PAIRS", "POSITION_ATTRS",
    "RUN_FILES", "SUMMARY_MAX", "TIME_UNITS", "RunReadError", "axis_variables", "check_layout", "components", "open_trajectory", "over_time",
    "positions", "reading", "run_axes", "run_directory", "short_reason", "trajectory_path",
]  # fmt: skip


#: The largest ``summary.json`` read (bytes): a summary lists every pair, about 200 bytes each.
SUMMARY_MAX = 256 * 2**20


class RunReadError(OneLineError):
    """A run directory or file that cannot be read back; the message is one line (control characters escaped).

    Parameters
    ----------
    message : str
        What is wrong.
    """


def run_directory(run_dir: str | Path, command: str, files: tuple[str, ...] = RUN_FILES) -> Path:
    """``run_dir``, if it is a folder holding ``files``; else a one-line :class:`RunReadError`.

    Parameters
    ----------
    run_dir : str or Path
        The folder ``tmem run`` wrote.
    command : str
        The command asking, which starts the message (``"plot"``).
    files : tuple of str
        The files it must hold.
    """
    run_dir = Path(run_dir)
    if not run_dir.exists():
        raise RunReadError(f"{command}: {run_dir}: no such folder")
    if not run_dir.is_dir():
        raise RunReadError(f"{command}: {run_dir}: is a file, not a run folder; give the folder tmem run wrote")
    for name in files:  # only regular files are read, and a summary of bounded size
        path = run_dir / name
        if path.exists() and not path.is_file():
            raise RunReadError(f"{command}: {path}: is not a regular file (a FIFO, a device or a folder)")
        if name == "summary.json" and path.is_file() and path.stat().st_size > SUMMARY_MAX:
            raise RunReadError(f"{command}: {path}: is {path.stat().st_size} bytes, more than a run's summary may be ({SUMMARY_MAX} bytes)")
    missing = [name for name in files if not (run_dir / name).is_file()]
    if missing:
        inside = sorted(p for p in run_dir.iterdir() if all((p / name).is_file() for name in files))
        example = f" (such as {inside[0]})" if inside else ""
        raise RunReadError(f"{command}: no {' or '.join(missing)} in {run_dir}; give a folder written by tmem run{example}")
    return run_dir


def trajectory_path(run_dir: str | Path, command: str) -> Path:
    """``run_dir``'s ``trajectory.nc`` (or ``run_dir`` itself, an ``.nc`` file); one that is not there is refused.

    Parameters
    ----------
    run_dir : str or Path
        A run directory written by ``tmem run``, or its ``trajectory.nc``.
    command : str
        The command reading it, at the start of a message (``"animate"``).

    Raises
    ------
    RunReadError
        In one line: no such file or folder, a file given for a folder, no ``trajectory.nc``.
    """
    run_dir = Path(run_dir)
    if run_dir.suffix == ".nc":
        if not run_dir.is_file():
            raise RunReadError(f"{command}: {run_dir}: {'is not a file' if run_dir.exists() else 'no such file'}")
        return run_dir
    return run_directory(run_dir, command, RUN_FILES[:1]) / RUN_FILES[0]


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


def short_reason(exc: Exception) -> str:
    """An exception as a short phrase of one line: its message, or its class when it has none.

    Parameters
    ----------
    exc : Exception
        What went wrong.
    """
    text = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
    text = text.strip().splitlines()[0] if text.strip() else type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."


@contextmanager
def reading(path: Path, command: str, what: str = "a run's trajectory") -> Iterator[None]:
    """Turn any failure while reading ``path`` into one line naming the file and the reason.

    A damaged file fails in h5py, h5netcdf, xarray, JSON or NumPy, each in its own way
    (``OSError``, ``KeyError``, ``RuntimeError``, ``MemoryError``...): any such failure in the
    block becomes a :class:`RunReadError`, raised once the failed file is freed, quietly.  A
    :class:`RunReadError` raised in the block passes as it is.

    Parameters
    ----------
    path : Path
        The file read in the block.
    command : str
        The command reading it, which starts the message.
    what : str
        What the file should be, for the message.
    """
    message = None
    with _quiet_unraisable():
        try:
            yield
        except RunReadError:
            raise
        except Exception as exc:  # noqa: BLE001 - see the docstring
            message = f"{command}: {path}: cannot be read as {what} ({short_reason(exc)})"
    if message is not None:
        raise RunReadError(message)


def check_layout(dataset, path: Path, command: str) -> None:
    """Refuse, in one line, a file of an earlier tmem: positions ``P`` over ``(time, agent, axis)``, not CF's ``x``.

    Parameters
    ----------
    dataset : xarray.Dataset or h5netcdf.File
        The open file.
    path : Path
        Its path, for the message.
    command : str
        The command reading it, which starts the message.
    """
    if FRAME_AXES[0] not in dataset.variables and "P" in dataset.variables:
        raise RunReadError(
            f"{command}: {path}: written by an earlier tmem (its layout is not CF trajectories); run the scenario again"
        )


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


def _dims(variable) -> tuple[str, ...]:
    """A variable's dimensions, of xarray (``dims``) or of h5netcdf (``dimensions``)."""
    return tuple(variable.dims) if hasattr(variable, "dims") else tuple(variable.dimensions)


def run_axes(dataset) -> tuple[str, ...]:
    """The axes the run flew on: those of :data:`FRAME_AXES` whose position varies over ``(agent, time)``.

    Parameters
    ----------
    dataset : xarray.Dataset or h5netcdf.File
        An open ``trajectory.nc`` (:func:`open_trajectory`).
    """
    return tuple(a for a in FRAME_AXES if a in dataset.variables and _dims(dataset.variables[a]) == OVER_AGENTS)


def axis_variables(dataset, name: str | None = None) -> list[str]:
    """The variables of a per-axis quantity, one per axis of the run: the positions ``x``, ``y``, ``z``
    (``name`` None), else ``name_x``, ``name_y``, ``name_z``.

    Parameters
    ----------
    dataset : xarray.Dataset or h5netcdf.File
        An open ``trajectory.nc``.
    name : str, optional
        The quantity: a vehicle model's state name other than the position (``"V"``, ``"phi"``)
        or ``"U"``; None for the positions.
    """
    return [a if name is None else f"{name}_{a}" for a in run_axes(dataset)]


def over_time(dataset, name: str) -> np.ndarray:
    """The variable ``name`` with time first: ``(time,)``, ``(time, agent)`` or ``(time, pair)``.

    The file keeps each agent's (pair's) record as a row over time; the tools index by time first.
    A variable with no values is not read (through xarray, h5py fails to select from an empty one).

    Parameters
    ----------
    dataset : xarray.Dataset or h5netcdf.File
        An open ``trajectory.nc``, or (xarray) a selection of it.
    name : str
        The variable.
    """
    variable = dataset.variables[name]
    dims = _dims(variable)
    if 0 in variable.shape:
        values = np.zeros(variable.shape, dtype=variable.dtype)
    else:
        values = np.asarray(variable.values if hasattr(variable, "dims") else variable[...])
    # In time-first memory order, as the run kept it: NumPy's sums then add in the same order, so that
    # what is computed from a file read back (a figure's line) is what was computed from the run.
    return np.ascontiguousarray(np.moveaxis(values, dims.index("time"), 0)) if "time" in dims else values


def _stacked(dataset, names: list[str]) -> np.ndarray:
    """The variables ``names`` over ``(agent, time)``, stacked as one array ``(time, agent, axis)``."""
    return np.stack([over_time(dataset, name) for name in names], axis=-1).astype(float, copy=False)


def positions(dataset) -> np.ndarray:
    """The positions (m), shape ``(time, agent, axis)`` as the run kept them: the coordinates ``x``, ``y``, ``z``.

    Parameters
    ----------
    dataset : xarray.Dataset or h5netcdf.File
        An open ``trajectory.nc`` (:func:`open_trajectory`), or (xarray) a selection of it.
    """
    return _stacked(dataset, axis_variables(dataset))


def components(dataset, name: str) -> np.ndarray:
    """A per-axis state or the control, shape ``(time, agent, axis)``: ``name_x``, ``name_y``, ``name_z`` stacked.

    Parameters
    ----------
    dataset : xarray.Dataset or h5netcdf.File
        An open ``trajectory.nc`` (:func:`open_trajectory`), or (xarray) a selection of it.
    name : str
        The quantity: a vehicle model's state name (``"V"``, ``"phi"``, ``"omega"``) or ``"U"``.
    """
    return _stacked(dataset, axis_variables(dataset, name))
