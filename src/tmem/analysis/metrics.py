"""What a run measured: RMS velocity (:mod:`tmem.analysis.rms`), distances, coupling events,
formation errors.

A formation is judged per pair by
its distance error ``|P_j - P_i| - d_t`` (and, where a direction is held, the
angle to it), over the recorded samples.
"""

from __future__ import annotations

import numpy as np

from tmem.engine import Event, Trajectory
from tmem.analysis.coverage import coverage_summary
from tmem.analysis.observables import gas_summary
from tmem.analysis.safety import safety_summary
from tmem.analysis.rms import rms_summary, rms_velocity  # noqa: F401  (rms_velocity: read from here too)


def nearest_distance(positions: np.ndarray, active: np.ndarray, box: np.ndarray) -> float | None:
    """Smallest distance between two active agents (nearest image in a periodic box).

    Parameters
    ----------
    positions : ndarray, shape (agents, axes)
        Positions (m).
    active : ndarray, shape (agents,), bool
        The agents that count.
    box : ndarray, shape (axes,)
        Periodic box sides (m); 0 on an open axis.

    Returns
    -------
    float or None
        ``None`` with fewer than two active agents.
    """
    points = positions[active]
    if len(points) < 2:
        return None
    from scipy.spatial import cKDTree  # here, not at the top: loading it takes longer than a two-agent run

    periodic = bool(np.all(box > 0))
    tree = cKDTree(np.mod(points, box) if periodic else points, boxsize=box if periodic else None)
    distances, _ = tree.query(np.mod(points, box) if periodic else points, k=2)
    return float(distances[:, 1].min())


def _first(times: list[float]) -> float | None:
    return min(times) if times else None


def _finite(value: float) -> float | None:
    """``value`` as a float, or ``None`` (JSON ``null``) where it is not a finite number."""
    value = float(value)
    return value if np.isfinite(value) else None


def coupling_states(trajectory: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Whether each pair was coupled (``F_en = 1``) at the start, at any time, and at the end.

    Replayed from the starting flags (formation pairs may start coupled, with no
    ``couple`` event) and the ``couple`` / ``uncouple`` events, so exact whatever
    was recorded.  A pair that loses an agent uncouples then.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).

    Returns
    -------
    start, ever, end : ndarray, shape (pairs,), bool
    """
    start = np.asarray(trajectory.initial.flag) == 1
    ever, end = start.copy(), start.copy()
    index = {tuple(pair): p for p, pair in enumerate(trajectory.pairs.tolist())}
    for e in trajectory.events:  # in time order
        p = index.get(e.agents) if e.kind in ("couple", "uncouple") else None
        if p is not None:
            end[p] = e.kind == "couple"
            ever[p] |= end[p]
    return start, ever, end


def pair_summary(trajectory: Trajectory, p: int) -> dict:
    """Per-pair figures: coupling and uncoupling times, separation, distances, oscillation, errors.

    ``coupled_at`` is when the pair first coupled, 0 if it started coupled;
    ``coupled_at_end`` whether it was coupled at the end.  ``separated_at`` is
    the first recorded time after the pair uncoupled at which its distance
    reaches ``R + R_j`` (the spheres no longer intersect): the paper's "actual
    disconnection".  ``oscillation_amplitude`` is half the peak-to-peak
    distance over the recorded samples with ``F_en = 1``; ``distance_error``
    the mean, RMS and largest ``|distance - d_t|`` over the same samples.
    ``None`` (JSON ``null``) where a figure does not exist: never coupled,
    never measured (an agent removed before the first step).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    p : int
        Index of the pair in ``trajectory.pairs``.
    """
    agents = tuple(int(a) for a in trajectory.pairs[p])
    events = [e for e in trajectory.events if e.agents == agents]
    started = bool(trajectory.initial.flag[p] == 1)
    coupled_at = 0.0 if started else _first([e.time for e in events if e.kind == "couple"])
    changes = [e.kind for e in events if e.kind in ("couple", "uncouple")]
    uncoupled_at = _first([e.time for e in events if e.kind == "uncouple"])
    dist = trajectory.pair_distance[:, p]
    separated_at = None
    if uncoupled_at is not None:
        after = (trajectory.time >= uncoupled_at) & (dist >= trajectory.scenario.interaction.reach)
        separated_at = float(trajectory.time[np.argmax(after)]) if after.any() else None
    while_coupled = dist[trajectory.flag[:, p] == 1]
    error = np.abs(while_coupled - trajectory.d_t[p])
    return {
        "agents": list(agents),
        "d_t": float(trajectory.d_t[p]),
        "coupled_at": coupled_at,
        "coupled_at_end": changes[-1] == "couple" if changes else started,
        "uncoupled_at": uncoupled_at,
        "separated_at": separated_at,
        "min_distance": _finite(trajectory.min_distance[p]),
        "final_distance": _finite(dist[-1]) if len(dist) else None,
        "mean_distance_coupled": float(while_coupled.mean()) if while_coupled.size else None,
        "oscillation_amplitude": float(np.ptp(while_coupled) / 2) if while_coupled.size else None,
        "distance_error": _error_stats(error),
    }


def _error_stats(error: np.ndarray) -> dict | None:
    if not error.size:
        return None
    return {"mean": float(error.mean()), "rms": float(np.sqrt(np.mean(error**2))), "max": float(error.max())}


#: The last seconds of a run over which ``distance_error_last_20s`` is taken (s).
LAST_WINDOW = 20.0


def formation_summary(trajectory: Trajectory) -> dict | None:
    """Formation figures over all its pairs, or ``None`` without a formation.

    ``distance_error``: mean, RMS and largest ``|distance - d_t|`` over every
    pair and every recorded sample while coupled; ``direction_error_deg``: the
    largest angle between a pair's direction ``P_j - P_i`` and the direction it
    must hold (pairs that hold one); ``distance_error_last_20s``: the same as
    ``distance_error`` over the last :data:`LAST_WINDOW` s of the run (the whole
    run if it is shorter), what a formation holds once its start's transient
    has passed; ``formed_at``: when the last pair coupled,
    if all did (0 if they started coupled); ``coupled_at_end``: the share of
    pairs coupled at the end; ``settling_time``: the first recorded time from
    which every coupled pair stays within :data:`SETTLE_BAND` of its ``d_t`` to
    the end (``None`` if they are not within it at the end); ``residual_error``:
    the largest ``|distance - d_t|`` of a coupled pair at the end.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    scenario = trajectory.scenario
    if scenario.formation is None or not len(trajectory.pairs):
        return None
    flag = trajectory.flag == 1
    error = np.abs(trajectory.pair_distance - trajectory.d_t)
    last = (trajectory.time >= trajectory.time[-1] - LAST_WINDOW)[:, None] & flag
    couple_times = {}
    for e in trajectory.events:
        if e.kind == "couple":
            couple_times.setdefault(e.agents, e.time)
    start = scenario.formation.coupled
    formed_at = 0.0 if start else (max(couple_times.values()) if len(couple_times) == len(trajectory.pairs) else None)
    result = {
        "pairs": len(trajectory.pairs),
        "distance_error": _error_stats(error[flag]),
        "distance_error_last_20s": _error_stats(error[last]),
        "formed_at": formed_at,
        "coupled_at_end": float(coupling_states(trajectory)[2].mean()),
        "amplitude_max": None,
    }
    amplitudes = [
        np.ptp(trajectory.pair_distance[flag[:, p], p]) / 2 for p in range(len(trajectory.pairs)) if flag[:, p].any()
    ]
    result["amplitude_max"] = float(max(amplitudes)) if amplitudes else None
    result.update(settling(trajectory))
    if scenario.formation.bearing:
        result["direction_error_deg"] = direction_error_deg(trajectory)
    return result


#: A formation has settled when every coupled pair's distance stays within this of its ``d_t`` (m).
SETTLE_BAND = 0.1


def settling(trajectory: Trajectory, band: float = SETTLE_BAND) -> dict:
    """``settling_time`` and ``residual_error`` of a formation's coupled pairs (see :func:`formation_summary`).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    band : float
        The band around ``d_t`` (m).
    """
    coupled = trajectory.flag == 1
    error = np.where(coupled, np.abs(trajectory.pair_distance - trajectory.d_t), 0.0)
    outside = np.flatnonzero((error > band).any(axis=1))
    settled = not outside.size or outside[-1] < len(trajectory.time) - 1
    return {
        "settling_time": (float(trajectory.time[outside[-1] + 1]) if outside.size else 0.0) if settled else None,
        "residual_error": float(error[-1].max()) if coupled[-1].any() else None,
    }


def held_still(trajectory: Trajectory, band: float = SETTLE_BAND) -> bool:
    """Whether every pair coupled over the run's last :data:`LAST_WINDOW` s (the whole run if it is
    shorter) stayed within ``band`` of its ``d_t`` all that time, none coupling in it: their
    oscillation has died out, and the RMS velocity no longer swings with it.

    A pair passing through ``d_t`` in mid-swing is within the band for a moment only, and one that
    has just coupled is within it at first: neither counts as held.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`) with at least one record.
    band : float
        The band around ``d_t`` (m).
    """
    settled_at = settling(trajectory, band)["settling_time"]
    window = max(float(trajectory.time[0]), float(trajectory.time[-1]) - LAST_WINDOW)
    late_couple = any(e.kind == "couple" and e.time >= window for e in trajectory.events)
    return settled_at is not None and settled_at <= window and not late_couple


def direction_error_deg(trajectory: Trajectory) -> float | None:
    """Largest angle (degrees) between a recorded pair's direction and the one it must hold.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    n_records = len(trajectory.time)
    direction = np.broadcast_to(trajectory.initial.direction, (n_records, *trajectory.initial.direction.shape))
    if trajectory.scenario.shapes_change:  # each shape's own, from when it is taken
        from tmem.terms.navigation_plan import held_pairs

        direction = held_pairs(trajectory.scenario, trajectory.pairs, trajectory.time)[1]
    position = {int(a): q for q, a in enumerate(trajectory.agents)}
    worst = None
    for p, (i, j) in enumerate(trajectory.pairs.tolist()):
        if np.isnan(direction[:, p, 0]).all() or i not in position or j not in position:
            continue
        where = trajectory.model.position(trajectory.state)
        delta = where[:, position[j]] - where[:, position[i]]
        box = trajectory.initial.box
        delta = np.where(box > 0, delta - box * np.round(delta / np.where(box > 0, box, 1.0)), delta)
        cosine = np.sum(delta * direction[:, p], axis=1) / np.linalg.norm(delta, axis=1)
        angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))[(trajectory.flag[:, p] == 1) & np.isfinite(cosine)]
        if angle.size:
            worst = max(worst or 0.0, float(angle.max()))
    return worst


def summarize_events(events: list[Event]) -> list[dict]:
    """Events as JSON-ready dicts; ``agents`` is ``[]`` for a command to several or every pair.

    Parameters
    ----------
    events : list of Event
        A run's events (:attr:`tmem.engine.trajectory.Trajectory.events`).
    """
    rows = []
    for e in events:
        row = {"time": e.time, "kind": e.kind, "agents": list(e.agents)}
        if e.action is not None:
            row["action"] = e.action
        if e.rule is not None:
            row["rule"] = e.rule
        rows.append(row)
    return rows


def coupling_summary(trajectory: Trajectory) -> dict:
    """Whether and when pairs were coupled, as written to ``summary.json``.

    ``coupled``: some pair was coupled at some time, from the start (a
    formation's pairs start coupled, with no ``couple`` event) or after
    coupling; ``pairs_coupled_at_start`` / ``_ever`` / ``_at_end``: how many
    pairs were so; ``couple_time``: when a pair was first coupled (0 if one
    started coupled); ``uncouple_time``: the first ``uncouple`` event (after an
    operator's command, or a pair losing an agent), and ``uncouple_rule`` what
    released it (:data:`tmem.law.coupling.RELEASES`).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    start, ever, end = coupling_states(trajectory)
    events = trajectory.events
    return {
        "coupled": bool(ever.any()),
        "pairs_coupled_at_start": int(start.sum()),
        "pairs_coupled_ever": int(ever.sum()),
        "pairs_coupled_at_end": int(end.sum()),
        "couple_time": 0.0 if start.any() else _first([e.time for e in events if e.kind == "couple"]),
        "uncouple_time": _first([e.time for e in events if e.kind == "uncouple"]),
        "uncouple_rule": next((e.rule for e in events if e.kind == "uncouple"), None),  # events are in time order
    }


def summarize(trajectory: Trajectory) -> dict:
    """The run's summary, as written to ``summary.json``.

    The RMS velocity, its change and its largest change on the way:
    :func:`tmem.analysis.rms.rms_summary`; coupling:
    :func:`coupling_summary`; the gas's observables (when observed):
    :func:`tmem.analysis.observables.gas_summary`; the coverage of a walled box:
    :func:`~tmem.analysis.coverage.runs.coverage_summary`; safety and the field's figures (with a
    ``[safety]`` table): :func:`tmem.analysis.safety.safety_summary`.  ``min_distance`` is the smallest distance two
    agents reached at any step (formation pairs always; other pairs once within
    ``R + R_j``); ``final_distance`` the smallest distance between two flying
    agents at the end.  Every number is finite: ``None`` (JSON ``null``) stands
    for a value that does not exist (no agent flying, no two agents close).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    scenario = trajectory.scenario
    model = trajectory.model
    coupling = coupling_summary(trajectory)
    settled = len(trajectory.time) > 0 and held_still(trajectory)
    min_pairs = float(trajectory.min_distance.min()) if len(trajectory.min_distance) else np.inf
    final_position = model.position(trajectory.final_state)
    return {
        "scenario": scenario.name,
        "function": scenario.interaction.function,
        "agents": int(trajectory.final_state.shape[0]),
        "axes": scenario.space.axes,
        "dt": scenario.simulation.dt,
        "duration": scenario.simulation.duration,
        **rms_summary(trajectory, coupling["pairs_coupled_at_end"], settled),
        "min_distance": _finite(min(min_pairs, trajectory.min_neighbor_distance)),
        "final_distance": nearest_distance(final_position, trajectory.final_active, trajectory.initial.box),
        **coupling,
        "final_velocities": model.velocity(trajectory.final_state).tolist() if trajectory.final_state.shape[0] <= 100 else None,
        "events": summarize_events(trajectory.events),
        "gains": trajectory.gains.tolist(),
        "formation": formation_summary(trajectory),
        "gas": gas_summary(trajectory),
        "coverage": coverage_summary(trajectory),
        "safety": safety_summary(trajectory),
        "pairs": [pair_summary(trajectory, p) for p in range(len(trajectory.pairs))],
    }
