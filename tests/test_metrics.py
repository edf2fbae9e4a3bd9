"""Metrics on hand-made trajectories whose answers are known by construction."""

import numpy as np
import pytest

import tmem
from tmem.engine import Event, Trajectory
from tmem.metrics import nearest_distance, pair_summary, rms_velocity, summarize
from tmem.initial import build


def made(distance, flag, events, velocities=None):
    """A two-agent trajectory on one axis: agent 0 at 0, agent 1 at ``distance``."""
    scenario = tmem.preset("fig9")
    n = len(distance)
    state = np.zeros((n, 2, 1, 4))
    state[:, 1, 0, 0] = distance
    if velocities is not None:
        state[:, :, 0, 1] = velocities
    return Trajectory(
        scenario=scenario,
        initial=build(scenario),
        gains=np.ones(4),
        time=np.arange(n, dtype=float),
        agents=np.array([0, 1]),
        state=state,
        control=np.zeros((n, 2, 1)),
        active=np.ones((n, 2), dtype=bool),
        flag=np.asarray(flag)[:, None],
        pair_distance=np.asarray(distance, dtype=float)[:, None],
        interaction_distance=np.asarray(distance, dtype=float)[:, None],
        min_distance=np.array([min(distance)]),
        min_neighbor_distance=np.inf,
        final_state=state[-1],
        final_active=np.ones(2, dtype=bool),
        events=events,
        list_builds=0,
    )


def test_pair_summary_of_a_known_oscillation():
    #        t = 0   1   2   3   4   5   6   7   8
    distance = [50, 36, 33, 37, 33, 36, 39, 41, 60]
    flag = [0, 1, 1, 1, 1, 0, 0, 0, 0]
    events = [Event(1.0, "couple", (0, 1)), Event(3.0, "command", (0, 1), "uncouple"), Event(5.0, "uncouple", (0, 1))]
    s = pair_summary(made(distance, flag, events), 0)
    assert s["coupled_at"] == 1.0 and s["uncoupled_at"] == 5.0
    assert s["separated_at"] == 7.0  # first time at or beyond R + R_j = 40 m after uncoupling
    assert s["oscillation_amplitude"] == pytest.approx((37 - 33) / 2)
    assert s["mean_distance_coupled"] == pytest.approx((36 + 33 + 37 + 33) / 4)
    errors = np.array([1, 2, 2, 2])  # |distance - 35| while coupled
    assert s["distance_error"]["max"] == 2 and s["distance_error"]["mean"] == pytest.approx(errors.mean())
    assert s["distance_error"]["rms"] == pytest.approx(np.sqrt(np.mean(errors**2)))
    assert s["min_distance"] == 33 and s["final_distance"] == 60


def test_never_coupled_pair_has_no_coupling_figures():
    s = pair_summary(made([60, 50, 45, 50], [0, 0, 0, 0], []), 0)
    assert s["coupled_at"] is None and s["separated_at"] is None and s["oscillation_amplitude"] is None


def test_summary_rms_change_from_known_speeds():
    tr = made([50, 50], [0, 0], [], velocities=np.array([[3.0, -1.5], [3.0, -1.5]]))
    s = summarize(tr)
    # The initial arrays hold Table 2's start, (-1.5, 3.0); the end speeds here are (3, -1.5): the same RMS.
    assert s["rms_velocity_initial"] == pytest.approx(np.sqrt((1.5**2 + 3**2) / 2))
    assert s["rms_change_percent"] == pytest.approx(0.0, abs=1e-12)


def test_rms_velocity_counts_only_active_agents():
    v = np.array([[[3.0, 4.0], [0.0, 0.0], [6.0, 8.0]]])  # speeds 5, 0, 10
    assert rms_velocity(v)[0] == pytest.approx(np.sqrt((25 + 0 + 100) / 3))
    assert rms_velocity(v, np.array([[True, False, True]]))[0] == pytest.approx(np.sqrt((25 + 100) / 2))


def test_nearest_distance_matches_brute_force_in_a_periodic_box():
    rng = np.random.default_rng(2)
    box = np.array([100.0, 80.0])
    points = rng.uniform(0, 1, (200, 2)) * box
    active = rng.uniform(size=200) > 0.2
    delta = points[active][:, None] - points[active][None, :]
    delta -= box * np.round(delta / box)
    brute = np.linalg.norm(delta, axis=2)
    np.fill_diagonal(brute, np.inf)
    assert nearest_distance(points, active, box) == pytest.approx(brute.min(), rel=1e-12)
    assert nearest_distance(points, active, np.zeros(2)) >= brute.min()
