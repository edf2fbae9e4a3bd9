"""Run outputs: the trajectory as an xarray dataset, and run directories.

A run directory holds ``summary.json`` (:func:`tmem.metrics.summarize`),
``trajectory.nc`` (:func:`to_dataset`, NetCDF-4 via h5netcdf) and the figures
of :mod:`tmem.plot`.  Directories are written next to their destination under
a temporary name and moved into place only when complete, so an interrupted
or failed run leaves no half-written output and never touches an older one.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__, metrics, plot
from .engine import Trajectory

PAPER = "E. Heiss, A. Kozyr, O. Morozov, Formations Organization in Robotic Swarm Using the Thermal Motion Equivalent Method"

#: Everything tmem writes into an output directory; a directory holding only these may be replaced.
OUTPUT_FILES = frozenset(
    {"summary.json", "trajectory.nc", "velocity.png", "distance.png", "formation.png", "animation.gif", "report.md"}
)
OUTPUT_DIRECTORIES = frozenset({"fig5", "fig7", "fig9"})


class OutputError(ValueError):
    """An output directory that cannot be written; the message is one line."""


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


def _only_tmem_output(directory: Path) -> bool:
    for entry in directory.iterdir():
        if entry.is_symlink():
            return False
        if entry.is_dir():
            if entry.name not in OUTPUT_DIRECTORIES or not _only_tmem_output(entry):
                return False
        elif entry.name not in OUTPUT_FILES:
            return False
    return True


def check_output_directory(out: str | Path) -> Path:
    """Refuse an ``out`` that tmem may not replace; return it as a Path.

    Allowed: a path that does not exist yet (under directories or nothing), an
    empty directory, or one holding nothing but what tmem writes.  Refused: a
    file, a symbolic link, the current directory or one containing it, a
    directory holding anything else, a path below a file.

    Parameters
    ----------
    out : str or Path
        The output directory asked for.
    """
    out = Path(out)
    if out.is_symlink():
        raise OutputError(f"--out {out}: is a symbolic link; give the directory itself")
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out}: exists and is not a directory")
    resolved = out.resolve()
    if resolved == Path.cwd().resolve() or resolved in Path.cwd().resolve().parents:
        raise OutputError(f"--out {out}: is the current directory or contains it; give a new subdirectory")
    for parent in resolved.parents:
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"--out {out}: {parent} is a file, not a directory")
    if out.is_dir() and not _only_tmem_output(out):
        raise OutputError(f"--out {out}: holds files tmem did not write; choose another directory")
    return out


@contextmanager
def atomic_directory(out: str | Path) -> Iterator[Path]:
    """Yield a temporary directory that replaces ``out`` only if the block succeeds.

    Parent directories made for it are removed again if the block fails.  File
    system errors (no permission, disk full) become :class:`OutputError`.

    Parameters
    ----------
    out : str or Path
        The output directory, checked by :func:`check_output_directory`.
    """
    out = check_output_directory(out)
    missing = [p for p in reversed(out.absolute().parents) if not p.exists()]
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    except OSError as exc:
        _remove_made(missing)
        raise OutputError(f"--out {out}: cannot be written ({exc.strerror or exc})") from None
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        tmp.chmod(0o777 & ~umask)  # mkdtemp made it private
        if out.exists():
            shutil.rmtree(out)
        tmp.rename(out)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_made(missing)
        if isinstance(exc, OSError):
            raise OutputError(f"--out {out}: cannot be written ({exc.strerror or exc})") from None
        raise


def _remove_made(directories: list[Path]) -> None:
    for directory in reversed(directories):
        try:
            directory.rmdir()
        except OSError:
            return


def write_run_files(trajectory: Trajectory, directory: Path) -> dict:
    """Write ``summary.json``, ``trajectory.nc`` and the figures into ``directory``.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    directory : Path
        An existing directory.

    Returns
    -------
    dict
        The summary (:func:`tmem.metrics.summarize`).
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
        The run directory (:func:`check_output_directory` says which may be replaced).
    """
    with atomic_directory(out) as tmp:
        return write_run_files(trajectory, tmp)
