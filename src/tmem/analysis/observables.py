"""The swarm's observables as a gas: temperature, density, pressure, encounters and mean free path.

A run that observes its gas (:attr:`tmem.scenario.Scenario.gas_observed`) keeps running totals over
every agent and step (:data:`tmem.engine.gas.TOTALS`), summed at each record; this module turns
their differences between two records into the gas's observables.  Everything is per unit agent
mass: a tilt ``phi`` is an acceleration ``g phi``.

* **Temperature**: the RMS velocity ``sqrt(<|V|^2>)`` of the flying agents, and the mean kinetic
  energy per agent and axis, ``<|V|^2> / (2 D)`` (J/kg), ``D`` the number of axes.
* **Density**: flying agents per unit of the box's free volume (area in 2-D): the box less the
  obstacles in it.
* **Pressure from the virial** (G1): ``p V D = <sum_i |V_i|^2> + <sum_pairs r_ij . a_ij>`` with
  ``r_ij = P_i - P_j`` and ``a_ij`` the push of ``j`` on ``i`` as applied (after the tilt limit),
  averaged over the window.  In a periodic box ``sum_pairs`` runs over the pairs and ``V`` is the
  free volume.  In a walled box it is each agent's ``(P_i - c) . a_i`` over every push but the
  walls' (the obstacles' included), ``c`` the box's centre, ``V`` the whole box, less the boundary
  term ``[sum_i (P_i - c) . V_i] / T`` that the theorem's average over a finite window ``T`` keeps.
* **Pressure on the walls** (G2): the momentum the walls of the box receive per unit time and unit
  area (length in 2-D), from the walls' pushes as applied.  Over a bounce the tilt's integral equals
  the set-point's (the inner loop has a static gain of one), so the momentum is exact.
* **The walls' range** (G3): walls push from ``R + R_w`` away, not at contact, so the virial theorem
  reads ``p_walls V D = <sum |V|^2> + <sum_pairs r_ij . a_ij> + <sum_walls delta |a_w|>``, with
  ``delta`` an agent's distance from the wall pushing it; ``pressure_wall_range`` is the last term
  over ``V D``.  (G1) plus it equals (G2): the test of both.  ``pressure_virial_walls`` is that sum,
  the virial's pressure on the walls, and ``pressure_agreement_percent`` its difference from (G2),
  ``100 ((G1 + G3) / (G2) - 1)``: what ``docs/gas.md`` compares.  (G1) alone falls short of (G2) by
  the share of the pressure the walls' reach takes (3.6 % in ``examples/swarm/gas_box.toml``).
* **Encounter rate and mean free path**: an encounter is a neighbour coming within ``R + R_j`` (of
  ``P*``), counted from the rises of each agent's number of neighbours within reach; the rate is
  encounters per agent per second, the mean free path the path flown per encounter.
* **Breaches**: agent-steps spent beyond a wall or inside an obstacle (0 in a safe run).

``docs/gas.md`` derives (G1)-(G2) and shows the swarm's equation of state.
"""

from __future__ import annotations

import math

import numpy as np

from tmem.engine.gas import SNAPSHOT, TOTALS
from tmem.engine.trajectory import Trajectory

_COLUMN = {name: k for k, name in enumerate(TOTALS + SNAPSHOT)}


def free_volume(trajectory: Trajectory) -> float | None:
    """The box's volume (area in 2-D, length in 1-D) less its obstacles' (m^D); ``None`` in open space.

    Obstacles are taken whole: one that pokes out of the box counts in full.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    """
    space = trajectory.scenario.space
    if space.box is None or not (space.walls or space.periodic):
        return None
    axes = space.axes
    ball = math.pi ** (axes / 2) / math.gamma(axes / 2 + 1)
    return math.prod(space.box) - sum(ball * o.radius**axes for o in trajectory.scenario.obstacles)


def wall_area(trajectory: Trajectory) -> float | None:
    """The area of the box's walls (their length in 2-D; 2 in 1-D) (m^(D-1)); ``None`` without walls.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`) in a walled box, or in any other space (``None``).
    """
    space = trajectory.scenario.space
    if not space.walls:
        return None
    box = space.box
    return float(sum(2.0 * math.prod(box[:a] + box[a + 1 :]) for a in range(len(box))))


def temperature(trajectory: Trajectory) -> np.ndarray:
    """The RMS velocity of every flying agent at each record (m/s), from the run's totals.

    Unlike :func:`tmem.analysis.metrics.rms_velocity` on the recorded states, it covers every agent even when
    only some are recorded.

    Parameters
    ----------
    trajectory : Trajectory
        A run that observed its gas.
    """
    gas = _observed(trajectory)
    flying = gas[:, _COLUMN["flying"]]
    return np.sqrt(np.divide(gas[:, _COLUMN["speed2_sum"]], flying, out=np.full(len(flying), np.nan), where=flying > 0))


def _observed(trajectory: Trajectory) -> np.ndarray:
    if trajectory.gas.shape[1] == 0:
        raise ValueError("trajectory: the run did not observe its gas (set simulation.observe_gas = true)")
    return trajectory.gas


def gas_summary(trajectory: Trajectory, since: float | None = None) -> dict | None:
    """The gas's observables averaged from ``since`` to the end, as written to ``summary.json``.

    ``None`` when the run did not observe its gas or recorded nothing.  Pressures and densities are
    ``None`` in open space; the wall pressure, the walls' range, their sum with the virial
    (``pressure_virial_walls``, (G1) + (G3)) and its agreement with the wall pressure
    (``pressure_agreement_percent``, ``100 ((G1 + G3) / (G2) - 1)``) are ``None`` without walls.

    Parameters
    ----------
    trajectory : Trajectory
        A run (:func:`tmem.simulate`).
    since : float, optional
        Start of the window (s); default: half the duration, after the start's transient.
    """
    if trajectory.gas.shape[1] == 0 or len(trajectory.time) < 2:
        return None
    gas, time = trajectory.gas, trajectory.time
    start = int(np.searchsorted(time, trajectory.scenario.simulation.duration / 2 if since is None else since))
    start = min(start, len(time) - 2)
    span = time[-1] - time[start]
    delta = gas[-1] - gas[start]
    axes = trajectory.scenario.space.axes
    speed2 = float(np.mean(gas[start:, _COLUMN["speed2_sum"]]))  # sum over agents of |V|^2, averaged
    flying = float(np.mean(gas[start:, _COLUMN["flying"]]))
    volume, area = free_volume(trajectory), wall_area(trajectory)
    encounters = delta[_COLUMN["encounters"]]
    boundary = delta[_COLUMN["moment"]] / span
    # A walled box's virial holds the obstacles' pushes, so it acts on the whole box (G1).
    container = math.prod(trajectory.scenario.space.box) if area else volume
    virial = (speed2 + delta[_COLUMN["virial"]] / span - boundary) / (axes * container) if volume else None
    walls = delta[_COLUMN["wall_momentum"]] / (span * area) if area else None
    wall_range = delta[_COLUMN["wall_virial"]] / (span * axes * container) if area else None
    virial_walls = virial + wall_range if area and virial is not None else None
    return {
        "window": [float(time[start]), float(time[-1])],
        "rms_velocity": math.sqrt(speed2 / flying) if flying > 0 else None,
        "kinetic_energy_per_axis": speed2 / (2.0 * axes * flying) if flying > 0 else None,
        "density": flying / volume if volume else None,
        "pressure_virial": virial,
        "pressure_walls": walls,
        "pressure_wall_range": wall_range,
        "pressure_virial_walls": virial_walls,
        "pressure_agreement_percent": 100.0 * (virial_walls / walls - 1.0) if virial_walls is not None and walls else None,
        "pressure_ideal": speed2 / (axes * volume) if volume else None,
        "encounter_rate": encounters / (span * flying) if flying > 0 else None,
        "mean_free_path": delta[_COLUMN["path"]] / encounters if encounters > 0 else None,
        "breaches": int(gas[-1, _COLUMN["breaches"]]),
    }
