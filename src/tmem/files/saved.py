"""A saved run read back: a run directory's ``trajectory.nc`` and ``summary.json`` as a Trajectory.

``tmem plot`` draws a saved run's figures from :func:`read_run` with the code that draws them at the
end of ``tmem run`` (:func:`tmem.figures.plot.write_figures`).  The file is read through
:mod:`tmem.files.trajectory_file`: whatever is wrong with a folder or a file is refused in one line naming
it and the reason (:class:`tmem.files.trajectory_file.RunReadError`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from tmem.engine.trajectory import Event, Trajectory
from tmem.files.trajectory_file import RunReadError, check_layout, components, over_time, positions, reading, run_directory, short_reason


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
    from tmem.scenario import ScenarioError, loads

    try:
        return loads(text)
    except ScenarioError as exc:
        raise RunReadError(f"{command}: {path}: the run's scenario no longer loads ({short_reason(exc)})") from None


def _events(text: str) -> list[Event]:
    return [
        Event(row["time"], row["kind"], tuple(row["agents"]), row.get("action"), row.get("rule"))
        for row in json.loads(text)
    ]  # fmt: skip


def _trajectory(path: Path, pair_rows: list, closest: float | None, command: str) -> Trajectory:
    """Read ``path`` (``trajectory.nc``) with h5netcdf; ``pair_rows`` and ``closest`` are from ``summary.json``."""
    import h5netcdf

    from tmem.engine.gas import COLUMNS
    from tmem.world.initial import build
    from tmem.vehicles import vehicle_model

    with h5netcdf.File(path, "r") as f:
        v = f.variables
        check_layout(f, path, command)
        scenario = _loaded_scenario(str(f.attrs["scenario"]), path, command)
        model = vehicle_model(scenario.model)
        initial = build(scenario)
        pairs = np.stack([v["pair_i"][...], v["pair_j"][...]], axis=1).reshape(-1, 2)
        if pairs.shape != initial.edges.shape or not np.array_equal(pairs, initial.edges) or len(pair_rows) != len(pairs):
            raise RunReadError(f"{command}: {path}: its pairs are not those of its scenario and summary.json")
        time = np.asarray(v["time"][...], dtype=float)
        gas = [np.asarray(v[f"gas_{name}"][...], dtype=float) for name in COLUMNS if f"gas_{name}" in v]
        state = np.stack([positions(f) if m == model.POSITION else components(f, name)
                          for m, name in enumerate(model.state_names)], axis=-1)  # fmt: skip
        active = over_time(f, "active").astype(bool)
        return Trajectory(
            scenario=scenario, initial=initial, model=model, gains=np.asarray(f.attrs["gains"], dtype=float),
            time=time, agents=np.asarray(v["agent"][...], dtype=np.int64), state=state,
            control=components(f, "U"), active=active, flag=over_time(f, "F_en").astype(np.int64),
            pair_distance=over_time(f, "distance").astype(float),
            interaction_distance=over_time(f, "interaction_distance").astype(float),
            min_distance=np.array([np.inf if r["min_distance"] is None else r["min_distance"] for r in pair_rows], float),
            min_neighbor_distance=np.inf if closest is None else float(closest),
            final_state=state[-1] if len(time) else np.zeros(state.shape[1:]),
            final_active=active[-1] if len(time) else np.zeros(active.shape[1], bool),
            events=_events(str(f.attrs["events"])), list_builds=0,
            gas=np.stack(gas, axis=1) if gas else np.zeros((len(time), 0)),
        )  # fmt: skip
