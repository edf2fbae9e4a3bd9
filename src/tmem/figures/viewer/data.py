"""What the viewer shows of a run, read from the run directory and thinned to fit one page.

:func:`read_view` reads ``trajectory.nc`` and ``summary.json`` (as
:func:`tmem.files.io.write_run_files` writes them) into a :class:`View`: the agents
and recorded times kept, the positions and speeds at those times, each agent's
state (not yet flying, flying, removed), the formation edges between kept
agents with their strain ``(|d| - d_t) / d_t`` and flag ``F_en``, and the
series of the linked panels (RMS velocity, pair distances).

The file is read through :mod:`tmem.files.trajectory_file`: the positions are its
coordinates ``x``, ``y``, ``z``, the velocity one variable per axis named by the
run's vehicle model (:attr:`tmem.vehicles.base.VehicleModel.state_names`, at its
``VELOCITY`` index; ``V_x``, ``V_y``), built from the scenario the file carries.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tmem.figures.drawing import columns_of, evenly, strain_limit
from tmem.files.trajectory_file import RunReadError, axis_variables, check_layout, reading, run_axes, run_directory

#: Most agents shown; larger runs are thinned evenly to this many.
MAX_AGENTS = 1000
#: Most recorded times shown (frames), when no ``max_frames`` is given.
MAX_FRAMES = 1000
#: Most coordinates (frames x agents x axes) stored when no ``max_frames`` is given: the
#: frames of large swarms are thinned further, so that the page stays a few megabytes.
MAX_COORDINATES = 600_000
#: Most formation edges drawn (between agents shown); more are thinned evenly.
MAX_EDGES = 3000
#: Most pairs drawn one line each in the distance panel; more are drawn as their
#: smallest, median and largest distance.
MAX_PAIR_LINES = 60
#: Most values read from the file at once (a block of agents' records of a large swarm).
_READ_VALUES = 20_000_000
#: Codes of an agent's state in :attr:`View.status`.
WAITING, FLYING, REMOVED = 0, 1, 2


@dataclass
class View:
    """What the page shows: a run's kept agents at its kept times.

    Attributes
    ----------
    name : str
        The scenario's name.
    axis_names : list of str
        ``x``, ``y``, ``z``: one per axis of the run (1 to 3).
    radius : float
        ``R`` (m), the radius of each agent's interaction sphere.
    reach : float
        ``R + R_j`` (m): agents interact closer than this.
    space : dict
        ``box`` (sides, m, or None), ``periodic``, ``walls`` and ``obstacles``
        (``center``, ``radius``) of the scenario's space.
    agents : ndarray of int, shape (A,)
        The kept agents, numbered from 1 as in the paper (the scenario's index + 1).
    time : ndarray, shape (F,)
        The kept recorded times (s).
    position : ndarray, shape (F, A, axes)
        Positions (m); a removed agent stays where it stopped (the engine holds it there).
    speed : ndarray, shape (F, A)
        Speeds ``|V|`` (m/s).
    status : ndarray of uint8, shape (F, A)
        :data:`WAITING` (not yet added), :data:`FLYING` or :data:`REMOVED`.
    edges : ndarray of int, shape (E, 2)
        Formation edges between kept agents, as columns of ``position``.
    strain : ndarray, shape (F, E)
        ``(|P_j - P_i| - d_t) / d_t`` of each edge.
    coupled : ndarray of bool, shape (F, E)
        ``F_en = 1``.
    drawn : ndarray of bool, shape (F, E)
        Whether the edge is drawn: always, but where a mission changes the formation's shape, only the
        pairs of the shape flown then (:func:`tmem.terms.navigation_plan.held_pairs`).
    strain_scale : float
        The end of the symmetric colour scale of strain, fitted to the run (:func:`strain_scale`).
    rms : ndarray, shape (F,)
        The RMS velocity of the recorded agents flying (m/s).
    pair_labels : list of str
        The name of each series of ``pair_distance``.
    pair_distance : ndarray, shape (F, S)
        Each pair's distance ``|P_j - P_i|`` (m), or the smallest, median and largest over the pairs.
    d_t : list of float
        The pairs' set distances (m), at most three of them, as reference lines.
    summary : dict
        ``summary.json`` as read (:func:`tmem.analysis.metrics.summarize`).
    note : str
        What is shown of the run, when it was thinned; empty when everything is.
    route : dict or None
        The mission's legs and goal (:func:`mission_route`); None without ``[navigation]``.
    """

    name: str
    axis_names: list[str]
    radius: float
    reach: float
    space: dict
    agents: np.ndarray
    time: np.ndarray
    position: np.ndarray
    speed: np.ndarray
    status: np.ndarray
    edges: np.ndarray
    strain: np.ndarray
    coupled: np.ndarray
    drawn: np.ndarray
    strain_scale: float
    rms: np.ndarray
    pair_labels: list[str]
    pair_distance: np.ndarray
    d_t: list[float]
    summary: dict = field(default_factory=dict)
    note: str = ""
    route: dict | None = None


def read_view(run_dir: str | Path, max_agents: int = MAX_AGENTS, max_frames: int | None = None) -> View:
    """Read what the page shows of the run in ``run_dir``.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``tmem run``.
    max_agents : int
        Most agents shown; more are thinned evenly by number (the first and the last kept).
    max_frames : int, optional
        Most recorded times shown.  Default: :data:`MAX_FRAMES`, fewer if the
        frames would hold more than :data:`MAX_COORDINATES` coordinates.

    Raises
    ------
    RunReadError
        One line: no such folder, no ``trajectory.nc`` or ``summary.json``
        in it, or a file that cannot be read as a run's (damaged, truncated,
        without its scenario).
    """
    run_dir = run_directory(run_dir, "view")
    trajectory, summary = run_dir / "trajectory.nc", run_dir / "summary.json"
    with reading(summary, "view", "a run's summary"):
        figures = json.loads(summary.read_text(encoding="utf-8"))
        if not isinstance(figures, dict):
            raise ValueError("not a JSON object")
    with reading(trajectory, "view"):
        view = _read(trajectory, max_agents, max_frames)
    view.summary = figures
    return view


def _scenario_and_model(text, path: Path):
    """The run's scenario (from the file's ``scenario`` attribute) and its vehicle model."""
    from tmem.vehicles import vehicle_model
    from tmem.scenario import ScenarioError, loads

    if not isinstance(text, str):
        raise RunReadError(f"view: {path}: carries no scenario; give a run written by tmem run")
    try:
        scenario = loads(text, source="its scenario")
    except ScenarioError as exc:
        raise RunReadError(f"view: {path}: {exc}") from None
    return scenario, vehicle_model(scenario.model)


def _at_frames(values, frames: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
    """A variable over ``(time,)`` or ``(row, time)`` at ``frames``, as ``(frame,)`` or ``(frame, row)``
    (``rows``: the agents kept; None for every row).  Each row is a record over time in the file, so
    a block of rows is read at a time, and a large swarm's file is never in memory whole."""
    if values.ndim == 1:
        return np.asarray(values[...])[frames]
    rows = np.arange(values.shape[0]) if rows is None else rows
    if 0 in values.shape or len(rows) == 0:  # no pairs: HDF5 selects nothing from an empty dataset
        return np.zeros((len(frames), len(rows)), values.dtype)
    every = len(rows) == values.shape[0]
    step = max(1, _READ_VALUES // values.shape[1])
    blocks = []
    for start in range(0, len(rows), step):
        block = np.asarray(values[start : start + step] if every else values[rows[start : start + step]])
        blocks.append(block[:, frames])
    return np.concatenate(blocks).T


def _read(path: Path, max_agents: int, max_frames: int | None) -> View:
    """The :class:`View` of ``path``, a ``trajectory.nc`` (without its summary)."""
    import h5netcdf

    with h5netcdf.File(path, "r") as f:
        check_layout(f, path, "view")
        scenario, model = _scenario_and_model(f.attrs.get("scenario"), path)
        variables = f.variables
        n_axes, (n_agents, n_times) = len(run_axes(f)), variables["active"].shape
        if n_times == 0 or n_agents == 0:
            raise RunReadError(f"view: {path}: the run recorded no times or no agents")
        agents = evenly(n_agents, max_agents, "agents").index
        if max_frames is None:
            max_frames = min(MAX_FRAMES, max(2, MAX_COORDINATES // (len(agents) * n_axes)))
        frames = evenly(n_times, max_frames, "frames").index

        def at_frames(name: str, rows: np.ndarray | None = None) -> np.ndarray:
            return _at_frames(variables[name], frames, rows)

        def per_axis(name: str | None) -> np.ndarray:
            return np.stack([at_frames(v, agents) for v in axis_variables(f, name)], axis=-1).astype(float)

        position = per_axis(None)
        speed = np.linalg.norm(per_axis(model.state_names[model.VELOCITY]), axis=-1)
        status = agent_status(at_frames("active", agents).astype(bool))
        ids = np.asarray(variables["agent"][...])
        pairs = np.stack([variables["pair_i"][...], variables["pair_j"][...]], axis=1).astype(int).reshape(-1, 2)
        distance = at_frames("distance").astype(float)
        d_t = np.asarray(variables["d_t"][...], dtype=float)
        edges, edge_pairs = _edges(ids[agents], pairs)
        strain = distance[:, edge_pairs] / d_t[edge_pairs] - 1.0
        coupled = at_frames("F_en")[:, edge_pairs] == 1
        time = at_frames("time").astype(float)
        drawn = np.ones_like(coupled)
        if scenario.formation is not None and scenario.shapes_change:
            from tmem.terms.navigation_plan import held_pairs

            drawn = held_pairs(scenario, pairs, time)[0][:, edge_pairs]
        pair_labels, pair_distance = _pair_series(distance, pairs)
        view = View(
            name=scenario.name,
            axis_names=list(run_axes(f)),
            radius=scenario.interaction.radius,
            reach=scenario.interaction.reach,
            space=_space(scenario),
            agents=ids[agents] + 1,
            time=time,
            position=position,
            speed=speed,
            status=status,
            edges=edges,
            strain=strain,
            coupled=coupled,
            drawn=drawn,
            strain_scale=strain_scale(strain, coupled, status, edges),
            rms=at_frames("rms_velocity").astype(float),
            pair_labels=pair_labels,
            pair_distance=pair_distance,
            d_t=[float(v) for v in np.unique(d_t)[:3]],
        )
        if scenario.navigation is not None:
            view.route = mission_route(scenario, view.time, position, status)
    view.note = thinning_note(len(agents), n_agents, len(frames), n_times, len(edges), len(_edges_between(ids[agents], pairs)))
    return view


def agent_status(active: np.ndarray) -> np.ndarray:
    """Each agent's state code at each frame: :data:`FLYING`, :data:`REMOVED` (not flying after it
    flew) or :data:`WAITING` (not yet added).

    Parameters
    ----------
    active : ndarray of bool, shape (F, A)
        Whether each agent flies at each frame (the file's ``active``).
    """
    flown = np.maximum.accumulate(active, axis=0)
    return np.where(active, FLYING, np.where(flown, REMOVED, WAITING)).astype(np.uint8)


def _edges_between(kept: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """The pairs (indices into ``pairs``) whose two agents are both kept."""
    _, found_i = columns_of(kept, pairs[:, 0])
    _, found_j = columns_of(kept, pairs[:, 1])
    return np.flatnonzero(found_i & found_j)


def _edges(kept: np.ndarray, pairs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Formation edges between kept agents (as their columns), at most :data:`MAX_EDGES`, and their pairs."""
    between = _edges_between(kept, pairs)
    drawn = between[evenly(len(between), MAX_EDGES, "edges").index]
    col_i, _ = columns_of(kept, pairs[drawn, 0])
    col_j, _ = columns_of(kept, pairs[drawn, 1])
    return np.stack([col_i, col_j], axis=1).reshape(-1, 2), drawn


def strain_scale(strain: np.ndarray, coupled: np.ndarray, status: np.ndarray, edges: np.ndarray) -> float:
    """The end of the symmetric colour scale of edge strain, fitted to the run.

    The largest ``|strain|`` of the coupled edges between flying agents at the
    frames shown (of every edge between flying agents if none is coupled), at
    least :data:`tmem.figures.drawing.STRAIN_FLOOR`: the rule of the run's figures, so that a
    formation holding ``d_t`` within 4 % uses the whole scale, and one held
    to millimetres is drawn in the colour of ``d_t``.

    Parameters
    ----------
    strain : ndarray, shape (F, E)
        ``(|d| - d_t) / d_t`` of each edge at each frame.
    coupled : ndarray of bool, shape (F, E)
        ``F_en = 1``.
    status : ndarray of uint8, shape (F, A)
        Each agent's state code.
    edges : ndarray of int, shape (E, 2)
        Each edge's agents, as columns of ``status``.
    """
    flying = (status[:, edges[:, 0]] == FLYING) & (status[:, edges[:, 1]] == FLYING)
    chosen = flying & coupled if (flying & coupled).any() else flying
    return strain_limit(strain[chosen])


def _pair_series(distance: np.ndarray, pairs: np.ndarray) -> tuple[list[str], np.ndarray]:
    """The distance panel's series: each pair (agents numbered from 1), or the smallest, median and largest."""
    if len(pairs) <= MAX_PAIR_LINES:
        return [f"agents {i + 1}–{j + 1}" for i, j in pairs], distance
    envelope = np.stack([distance.min(axis=1), np.median(distance, axis=1), distance.max(axis=1)], axis=1)
    return [f"smallest of {len(pairs)} pairs", "median", "largest"], envelope


def mission_route(scenario, time: np.ndarray, position: np.ndarray, status: np.ndarray) -> dict:
    """The mission as flown (:func:`tmem.terms.navigation_plan.planned_points`), as the page draws it.

    Each leg with points (``velocity`` legs and a ``hold`` where the group is have none) starts where
    the group was when it began: the centre of the agents flying at the last frame shown at or before
    its start (the first frame for a leg that starts before it), None when none flies then.  The goal
    is the last point of the last leg with points.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario, with a ``[navigation]`` table.
    time : ndarray, shape (F,)
        The frames' times (s).
    position : ndarray, shape (F, A, axes)
        The agents' positions at those frames (m).
    status : ndarray of uint8, shape (F, A)
        Each agent's state code at those frames.

    Returns
    -------
    dict
        ``legs``: each leg's ``time`` (s), ``action``, ``from`` (the group's centre, m, or None) and
        ``points`` (m); ``goal``: a point (m), or None when no leg has one.
    """
    from tmem.terms.navigation_plan import planned_points

    legs = []
    for start, action, points in planned_points(scenario):
        if len(points) == 0:
            continue
        f = max(int(np.searchsorted(time, start, side="right")) - 1, 0)
        flying = status[f] == FLYING
        centre = position[f, flying].mean(axis=0).tolist() if flying.any() else None
        legs.append({"time": float(start), "action": action, "from": centre, "points": points.tolist()})
    return {"legs": legs, "goal": legs[-1]["points"][-1] if legs else None}


def _space(scenario) -> dict:
    space = scenario.space
    obstacles = [{"center": list(o.center), "radius": o.radius} for o in scenario.obstacles]
    return {"box": space.box, "periodic": space.periodic, "walls": space.walls, "obstacles": obstacles}


def thinning_note(agents: int, agents_recorded: int, frames: int, times_recorded: int, edges: int, edges_between: int) -> str:
    """The page's note on what is shown of a thinned run; empty when everything is.

    Parameters
    ----------
    agents, agents_recorded : int
        Agents shown, of those the run recorded.
    frames, times_recorded : int
        Recorded times shown, of those the run recorded.
    edges, edges_between : int
        Formation edges drawn, of those between the agents shown.
    """
    parts = []
    if agents < agents_recorded:
        parts.append(f"{agents} of {agents_recorded} agents, evenly chosen by number")
    if frames < times_recorded:
        parts.append(f"{frames} of {times_recorded} recorded times, evenly spaced")
    if edges < edges_between:
        parts.append(f"{edges} of the {edges_between} formation edges between them")
    return "Shown: " + "; ".join(parts) + "." if parts else ""
