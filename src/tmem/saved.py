"""A saved run read back: a run directory's ``trajectory.nc`` and ``summary.json`` as a Trajectory.

``tmem plot`` draws a saved run's figures from :func:`read_run` with the code that draws them at the
end of ``tmem run`` (:func:`tmem.plot.write_figures`).  ``tmem animate`` finds its file with
:func:`trajectory_file` and reads it under :func:`reading`.  Whatever is wrong with a folder or a
file is refused in one line naming it and the reason (:class:`RunReadError`).
"""

from __future__ import annotations

import gc
import json
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .engine.trajectory import Event, Trajectory

#: A run directory's files that :func:`read_run` reads.
RUN_FILES = ("trajectory.nc", "summary.json")


class RunReadError(ValueError):
    """A run directory or file that cannot be read back; the message is one line."""


def trajectory_file(run_dir: str | Path, command: str) -> Path:
    """``run_dir``'s ``trajectory.nc`` (or ``run_dir`` itself, an ``.nc`` file); refuse one that is not there.

    Parameters
    ----------
    run_dir : str or Path
        A run directory, or the path of its ``trajectory.nc``.
    command : str
        The command asking, which starts the message (``"animate"``).
    """
    run_dir = Path(run_dir)
    if run_dir.suffix == ".nc":
        if not run_dir.is_file():
            raise RunReadError(f"{command}: {run_dir}: {'is not a file' if run_dir.exists() else 'no such file'}")
        return run_dir
    return run_directory(run_dir, command, RUN_FILES[:1]) / RUN_FILES[0]


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
    missing = [name for name in files if not (run_dir / name).is_file()]
    if missing:
        inside = sorted(p for p in run_dir.iterdir() if all((p / name).is_file() for name in files))
        example = f" (such as {inside[0]})" if inside else ""
        raise RunReadError(f"{command}: no {' or '.join(missing)} in {run_dir}; give a folder written by tmem run{example}")
    return run_dir


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
            message = f"{command}: {path}: cannot be read as {what} ({_reason(exc)})"
    if message is not None:
        raise RunReadError(message)


def read_run(run_dir: str | Path, command: str = "plot") -> Trajectory:
    """The run saved in ``run_dir`` (by ``tmem run``, or one of ``tmem paper``'s), as a Trajectory.

    What the files keep is read as written: the scenario, the gains, the recorded times, agents,
    states, set-points, flags, distances, the events and the gas's totals.  The initial arrays
    are built again from the scenario (its seed makes them the same).  What the files do not
    keep comes from what they do: each pair's smallest distance and the smallest distance
    between neighbours from ``summary.json``; ``final_state`` and ``final_active`` are the last
    record, of the recorded agents only; ``list_builds`` is 0.

    Parameters
    ----------
    run_dir : str or Path
        The run directory, holding ``trajectory.nc`` and ``summary.json``.
    command : str
        The command reading it, which starts any message.

    Raises
    ------
    RunReadError
        One line: no such folder, a missing or damaged file, a scenario that no longer loads, or
        files that do not belong together.
    """
    directory = run_directory(run_dir, command)
    with reading(directory / "summary.json", command, "a run's summary"):
        summary = json.loads((directory / "summary.json").read_text(encoding="utf-8"))
        pair_rows = summary["pairs"]
        closest = summary["min_distance"]
    path = directory / "trajectory.nc"
    with reading(path, command):
        return _trajectory(path, pair_rows, closest, command)


def _loaded_scenario(text: str, path: Path, command: str):
    from .scenario import ScenarioError, loads

    try:
        return loads(text)
    except ScenarioError as exc:
        raise RunReadError(f"{command}: {path}: the run's scenario no longer loads ({_reason(exc)})") from None


def _events(text: str) -> list[Event]:
    return [
        Event(row["time"], row["kind"], tuple(row["agents"]), row.get("action"), row.get("rule"))
        for row in json.loads(text)
    ]  # fmt: skip


def _trajectory(path: Path, pair_rows: list, closest: float | None, command: str) -> Trajectory:
    """Read ``path`` (``trajectory.nc``) with h5netcdf; ``pair_rows`` and ``closest`` are from ``summary.json``."""
    import h5netcdf

    from .engine.gas import COLUMNS
    from .initial import build
    from .model import vehicle_model

    with h5netcdf.File(path, "r") as f:
        v = f.variables
        scenario = _loaded_scenario(str(f.attrs["scenario"]), path, command)
        model = vehicle_model(scenario.model)
        initial = build(scenario)
        pairs = np.stack([v["pair_i"][...], v["pair_j"][...]], axis=1).reshape(-1, 2)
        if pairs.shape != initial.edges.shape or not np.array_equal(pairs, initial.edges) or len(pair_rows) != len(pairs):
            raise RunReadError(f"{command}: {path}: its pairs are not those of its scenario and summary.json")
        time = np.asarray(v["time"][...], dtype=float)
        gas = [np.asarray(v[f"gas_{name}"][...], dtype=float) for name in COLUMNS if f"gas_{name}" in v]
        state = np.stack([np.asarray(v[name][...], dtype=float) for name in model.state_names], axis=-1)
        active = np.asarray(v["active"][...]).astype(bool)
        return Trajectory(
            scenario=scenario, initial=initial, model=model, gains=np.asarray(f.attrs["gains"], dtype=float),
            time=time, agents=np.asarray(v["agent"][...], dtype=np.int64), state=state,
            control=np.asarray(v["U"][...], dtype=float), active=active,
            flag=np.asarray(v["F_en"][...]).astype(np.int64),
            pair_distance=np.asarray(v["distance"][...], dtype=float),
            interaction_distance=np.asarray(v["interaction_distance"][...], dtype=float),
            min_distance=np.array([np.inf if r["min_distance"] is None else r["min_distance"] for r in pair_rows], float),
            min_neighbor_distance=np.inf if closest is None else float(closest),
            final_state=state[-1] if len(time) else np.zeros(state.shape[1:]),
            final_active=active[-1] if len(time) else np.zeros(active.shape[1], bool),
            events=_events(str(f.attrs["events"])), list_builds=0,
            gas=np.stack(gas, axis=1) if gas else np.zeros((len(time), 0)),
        )  # fmt: skip
