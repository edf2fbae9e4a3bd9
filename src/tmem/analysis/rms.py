"""The swarm's temperature over a run: its RMS velocity at the start and the end, and the largest
change on the way.

The swarm's "temperature" in TMEM is its RMS velocity, ``sqrt(mean_i |v_i|^2)`` over the agents
flying; an encounter that keeps it is lossless in the thermal-motion sense.  The change from the
start to the end (``rms_change_percent``) is what the paper's Figs. 7 and 9 measure, but it says
nothing of the way between: a swarm started out of equilibrium may gain a third of its speed in
its first seconds and give it back, and end within a percent of its start.  The largest change
over the recorded times (``rms_change_peak_percent``, at ``rms_change_peak_time``) shows that
transient.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from tmem.engine import Trajectory

__all__ = ["rms_velocity", "rms_over_time", "rms_peak", "rms_summary"]



def rms_velocity(velocity: np.ndarray, active: np.ndarray | None = None) -> np.ndarray:
    """RMS velocity over agents, ``sqrt(mean_i sum_axes v_i^2)``, counting only ``active`` agents.

    Parameters
    ----------
    velocity : ndarray, shape (..., agents, axes)
    active : ndarray, shape (..., agents), bool, optional
    """
    speed2 = np.sum(velocity**2, axis=-1)
    if active is None:
        return np.sqrt(np.mean(speed2, axis=-1))
    count = np.sum(active, axis=-1)
    return np.sqrt(np.sum(np.where(active, speed2, 0.0), axis=-1) / np.maximum(count, 1))


def rms_over_time(trajectory: Trajectory) -> np.ndarray:
    """The RMS velocity of the agents flying at each recorded time (m/s); NaN where none flies.

    Over every agent when the run observed its gas (its running totals cover every agent,
    :func:`tmem.analysis.observables.temperature`), else over the recorded agents (every agent
    unless ``simulation.record_agents`` names some).

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    if trajectory.gas.shape[1]:
        from tmem.analysis.observables import temperature

        return temperature(trajectory)
    rms = rms_velocity(trajectory.model.velocity(trajectory.state), trajectory.active)
    return np.where(np.any(trajectory.active, axis=-1), rms, np.nan)


def rms_peak(time: np.ndarray, rms: np.ndarray) -> tuple[float | None, float | None]:
    """The largest change of ``rms`` from its first value, in %, signed, and when it came.

    Parameters
    ----------
    time : ndarray, shape (records,)
        The recorded times (s).
    rms : ndarray, shape (records,)
        The RMS velocity at each (m/s); NaN where none flies.

    Returns
    -------
    peak, at : float or None
        ``100 (rms(t) / rms(t_0) - 1)`` at the record where its magnitude is largest (the first
        such), and that record's time; ``None`` where the first value is not a positive number or
        no later value is finite.
    """
    if not len(rms) or not (np.isfinite(rms[0]) and rms[0] > 0):
        return None, None
    change = 100.0 * (rms / rms[0] - 1.0)
    size = np.where(np.isfinite(change), np.abs(change), -1.0)
    k = int(np.argmax(size))
    return float(change[k]), float(time[k])


def _flying_rms(velocity: np.ndarray, active: np.ndarray) -> float | None:
    """RMS velocity of the flying agents, ``None`` when none flies (an RMS over no agent is undefined)."""
    return float(rms_velocity(velocity, active)) if np.any(active) else None


def rms_summary(trajectory: Trajectory, pairs_coupled_at_end: int, settled: bool = False) -> dict:
    """The RMS velocity at the start and the end, its change in %, whether that change swings, and its
    largest change on the way.

    ``rms_change_percent`` is ``100 (rms_final / rms_initial - 1)``, each an instantaneous value
    over the agents flying then (the measure of the paper's Figs. 7 and 9).  While pairs are still
    coupled at the end, their undamped oscillation trades speed for tilt and back, so this value
    swings with the phase at which the run stops: ``rms_change_while_coupled`` is then true, and
    ``rms_change_swings`` too unless those pairs are held still (every coupled pair within
    :data:`tmem.analysis.metrics.SETTLE_BAND` of its ``d_t`` over the run's last 20 s,
    :func:`tmem.analysis.metrics.held_still`: their oscillation has died out).  ``rms_change_peak_percent`` is the change from the start with the
    largest magnitude over the recorded times (:func:`rms_over_time`, :func:`rms_peak`), signed,
    and ``rms_change_peak_time`` when it came: the start-up transient that the change from start
    to end does not show.  ``None`` (JSON ``null``) where a value is undefined: no agent flying at
    that time, or an initial RMS of 0.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    pairs_coupled_at_end : int
        How many pairs are coupled at the end (:func:`tmem.analysis.metrics.coupling_states`).
    settled : bool
        Whether the pairs coupled at the end are held still (:func:`tmem.analysis.metrics.held_still`).
    """
    model = trajectory.model
    initial = _flying_rms(model.velocity(trajectory.initial.state), trajectory.initial.active)
    final = _flying_rms(model.velocity(trajectory.final_state), trajectory.final_active)
    defined = initial is not None and final is not None and initial > 0
    peak, at = rms_peak(trajectory.time, rms_over_time(trajectory)) if len(trajectory.time) else (None, None)
    return {
        "rms_velocity_initial": initial,
        "rms_velocity_final": final,
        "rms_change_percent": 100.0 * (final / initial - 1.0) if defined else None,
        "rms_change_while_coupled": pairs_coupled_at_end > 0,
        "rms_change_swings": pairs_coupled_at_end > 0 and not settled,
        "rms_change_peak_percent": peak,
        "rms_change_peak_time": at,
    }
