"""What a run measured: RMS velocity, distances, coupling events, oscillation.

The swarm's "temperature" in TMEM is its RMS velocity,
``sqrt(mean_i |v_i|^2)`` over agents; an encounter that keeps it is lossless
in the thermal-motion sense.
"""

from __future__ import annotations

import numpy as np

from .control import interaction_point
from .engine import Event, Trajectory


def rms_velocity(velocity: np.ndarray) -> np.ndarray:
    """RMS velocity over agents, ``sqrt(mean_i sum_axes v_i^2)``.

    Parameters
    ----------
    velocity : ndarray, shape (..., agents, axes)
    """
    return np.sqrt(np.mean(np.sum(velocity**2, axis=-1), axis=-1))


def pair_distances(positions: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Euclidean distances ``|P_j - P_i|`` of each pair.

    Parameters
    ----------
    positions : ndarray, shape (..., agents, axes)
    pairs : ndarray, shape (n_pairs, 2)

    Returns
    -------
    ndarray, shape (..., n_pairs)
    """
    diff = positions[..., pairs[:, 1], :] - positions[..., pairs[:, 0], :]
    return np.sqrt(np.sum(diff**2, axis=-1))


def distance(trajectory: Trajectory) -> np.ndarray:
    """Physical distance of each pair at each recorded time, shape (n_records, n_pairs)."""
    return pair_distances(trajectory.state[..., 0], trajectory.pairs)


def interaction_distance(trajectory: Trajectory) -> np.ndarray:
    """``|d| = |P*_j - P*_i|`` (6) of each pair at each recorded time, shape (n_records, n_pairs)."""
    return pair_distances(interaction_point(trajectory.state, trajectory.gains), trajectory.pairs)


def _first(times: list[float]) -> float | None:
    return min(times) if times else None


def pair_summary(trajectory: Trajectory, p: int, dist: np.ndarray) -> dict:
    """Per-pair figures: coupling and uncoupling times, separation, distances, oscillation.

    ``separated_at`` is the first recorded time after the pair uncoupled at
    which its distance reaches ``R + R_j`` (the spheres no longer intersect):
    the paper's "actual disconnection".  ``oscillation_amplitude`` is half the
    peak-to-peak distance over the recorded samples with ``F_en = 1``.
    """
    agents = tuple(int(a) for a in trajectory.pairs[p])
    events = [e for e in trajectory.events if e.agents == agents]
    coupled_at = _first([e.time for e in events if e.kind == "couple"])
    uncoupled_at = _first([e.time for e in events if e.kind == "uncouple"])
    separated_at = None
    if uncoupled_at is not None:
        reach = trajectory.scenario.interaction.reach
        after = (trajectory.time >= uncoupled_at) & (dist[:, p] >= reach)
        separated_at = float(trajectory.time[np.argmax(after)]) if after.any() else None
    while_coupled = dist[trajectory.flag[:, p] == 1, p]
    return {
        "agents": list(agents),
        "coupled_at": coupled_at,
        "uncoupled_at": uncoupled_at,
        "separated_at": separated_at,
        "min_distance": float(trajectory.min_distance[p]),
        "final_distance": float(dist[-1, p]),
        "mean_distance_coupled": float(while_coupled.mean()) if while_coupled.size else None,
        "oscillation_amplitude": float(np.ptp(while_coupled) / 2) if while_coupled.size else None,
    }


def summarize_events(events: list[Event]) -> list[dict]:
    """Events as JSON-ready dicts; ``agents`` is ``[]`` for a command to every pair."""
    rows = []
    for e in events:
        row = {"time": e.time, "kind": e.kind, "agents": [] if e.agents[0] < 0 else list(e.agents)}
        if e.action is not None:
            row["action"] = e.action
        rows.append(row)
    return rows


def summarize(trajectory: Trajectory) -> dict:
    """The run's summary, as written to ``summary.json``.

    Top-level figures aggregate over pairs: ``min_distance`` is the smallest
    distance any pair reached at any step, ``final_distance`` the smallest
    pair distance at the end, ``coupled`` whether any pair coupled,
    ``couple_time`` / ``uncouple_time`` the first such event of any pair.
    """
    velocity = trajectory.state[..., 1]
    rms = rms_velocity(velocity[[0, -1]])
    dist = distance(trajectory)
    pairs = [pair_summary(trajectory, p, dist) for p in range(len(trajectory.pairs))]
    scenario = trajectory.scenario
    return {
        "scenario": scenario.name,
        "function": scenario.interaction.function,
        "dt": scenario.simulation.dt,
        "duration": scenario.simulation.duration,
        "rms_velocity_initial": float(rms[0]),
        "rms_velocity_final": float(rms[1]),
        "rms_change_percent": float(100.0 * (rms[1] / rms[0] - 1.0)) if rms[0] > 0 else None,
        "min_distance": float(trajectory.min_distance.min()),
        "final_distance": float(dist[-1].min()),
        "coupled": any(e.kind == "couple" for e in trajectory.events),
        "couple_time": _first([e.time for e in trajectory.events if e.kind == "couple"]),
        "uncouple_time": _first([e.time for e in trajectory.events if e.kind == "uncouple"]),
        "final_velocities": velocity[-1].tolist(),
        "events": summarize_events(trajectory.events),
        "gains": trajectory.gains.tolist(),
        "pairs": pairs,
    }
