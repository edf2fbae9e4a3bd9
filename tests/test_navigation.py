"""Group navigation (N1)-(N4): a rigid formation stays rigid, the centre moves as one agent does.

The references are independent of the term's code: the relative states of a perfect formation
(zero, for a common-mode push), the closed loop of the centre's velocity written here from the
model (2) and scipy's ``expm``, the loop's roots from ``numpy.linalg.eigvals``, and the mission's
goal.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

import tmem
from tmem.scenario import ScenarioError, with_changes
from tmem.terms.navigation import loop_gains

HEX = """
name = "hex7-mission"
[space]
axes = 2
[interaction]
function = "improved"
synchronise = true
d_t = 35.0
[formation]
kind = "hex"
n = 7
velocity = [0.0, 0.0]
jitter = 0.0
[navigation]
bandwidth = 0.5
[[navigation.legs]]
time = 0.0
action = "velocity"
velocity = [2.0, 1.0]
[[navigation.legs]]
time = 30.0
action = "route"
waypoints = [[150.0, 0.0], [150.0, 120.0]]
speed = 4.0
[simulation]
dt = 0.001
duration = 150.0
record_every = 200
"""


@pytest.fixture(scope="module")
def flown():
    scenario = tmem.loads(HEX)
    return scenario, tmem.simulate(scenario)


def test_a_perfect_formation_told_to_move_and_turn_keeps_zero_strain(flown):
    """A common-mode push leaves every relative state where it was: all agents share one velocity."""
    scenario, trajectory = flown
    v = trajectory.state[:, :, :, 1]  # (time, agent, axis)
    assert np.ptp(v, axis=1).max() < 1e-9
    assert np.abs(trajectory.pair_distance - 35.0).max() < 1e-8
    speed = np.linalg.norm(v[:, 0], axis=-1)
    assert speed.max() > 3.5  # it did fly: the test could fail


def test_the_group_arrives_at_the_end_of_its_route(flown):
    scenario, trajectory = flown
    centre = trajectory.state[-1, :, :, 0].mean(axis=0)
    assert np.linalg.norm(centre - [150.0, 120.0]) < 0.05
    assert np.abs(trajectory.state[-1, :, :, 1]).max() < 0.01


def test_the_centre_follows_the_closed_loop_of_one_agent_under_the_velocity_loop(flown):
    """During the velocity leg (no saturation after the first seconds), the centre's velocity against
    the exact zero-order hold of ``A_s - B_s K_n`` written here, started from the recorded state."""
    scenario, trajectory = flown
    m = scenario.model
    a = np.array([[0, m.g, 0], [0, 0, 1], [0, -m.kp * m.kd, -m.kd]], dtype=float)  # (V, phi, omega)
    b = np.array([0, 0, m.kp * m.kd], dtype=float)
    k = loop_gains(scenario, 0.5)
    closed = a - np.outer(b, k)
    dt = scenario.simulation.dt * scenario.simulation.record_every
    start, stop = int(10.0 / dt), int(29.0 / dt)
    centre = trajectory.state[:, :, :, 1:4].mean(axis=1)  # (time, axis, 3)
    wanted = np.array([2.0, 1.0])
    x = centre[start] - np.stack([wanted, [0, 0], [0, 0]], axis=1)
    step = expm(closed * dt)
    for n in range(start + 1, stop):
        x = x @ step.T
        np.testing.assert_allclose(centre[n, :, 0], x[:, 0] + wanted, atol=2e-4)


def test_the_velocity_loop_has_the_roots_it_is_placed_at():
    scenario = tmem.loads(HEX)
    m = scenario.model
    a = np.array([[0, m.g, 0], [0, 0, 1], [0, -m.kp * m.kd, -m.kd]], dtype=float)
    b = np.array([0, 0, m.kp * m.kd], dtype=float)
    for bandwidth in (0.1, 0.5, 2.0):
        roots = np.sort_complex(np.linalg.eigvals(a - np.outer(b, loop_gains(scenario, bandwidth))))
        np.testing.assert_allclose(roots, np.sort_complex([-12 - 0.1j, -12 + 0.1j, -bandwidth]), atol=1e-9)


def test_a_mission_damps_the_pairs_without_holding_their_energy_unless_told():
    scenario = tmem.loads(HEX)
    assert not scenario.keeps_energy
    assert with_changes(scenario, {"interaction.keep_energy": True}).keeps_energy
    assert with_changes(scenario, {"navigation": None}).keeps_energy


@pytest.mark.parametrize(("change", "message"), [
    ({"navigation.bandwidth": 3.5}, r"navigation\.bandwidth: 3\.5 /s is above a quarter of the law's slowest damped root, 12 /s"),
    ({"navigation.share": 1.0}, r"navigation\.share: must be below 1"),
    ({"navigation.legs": []}, r"navigation\.legs: is empty"),
    ({"navigation.legs": [{"time": 0.0, "action": "goto", "target": [1.0, 2.0]}]}, r"navigation\.legs\[0\]\.speed: is required for goto"),
    ({"navigation.legs": [{"time": 0.0, "action": "goto", "target": [1.0], "speed": 2.0}]}, r"navigation\.legs\[0\]\.target: needs 2 values"),
    ({"navigation.legs": [{"time": 0.0, "action": "hold", "speed": 2.0}]}, r"navigation\.legs\[0\]\.speed: is not used by hold"),
    ({"navigation.legs": [{"time": 0.0, "action": "route", "waypoints": [[1.0, 2.0]], "speed": [1.0, 2.0]}]},
     r"navigation\.legs\[0\]\.speed: gives 2 speeds for 1 waypoints"),
    ({"navigation.legs": [{"time": 0.0, "action": "goto", "target": [1.0, 2.0], "speed": 2.0, "avoid": True}]},
     r"navigation\.legs\[0\]\.avoid: has no \[\[obstacles\]\] to plan around"),
    ({"navigation.legs": [{"time": 5.0, "action": "hold"}, {"time": 5.0, "action": "hold"}]},
     r"navigation\.legs\[1\]\.time: must come after the leg before \(5 s\)"),
    ({"navigation.legs": [{"time": 500.0, "action": "hold"}]}, r"navigation\.legs\[0\]\.time: must not be later than duration = 150 s"),
])  # fmt: skip
def test_a_bad_mission_is_refused_in_one_line_naming_the_key(change, message):
    scenario = tmem.loads(HEX)
    with pytest.raises(ScenarioError, match=message):
        with_changes(scenario, change)


def test_a_mission_goes_on_from_its_checkpoint_to_the_same_bits(tmp_path):
    """Each agent's leg, waypoint and hold point are saved (the route turns after the checkpoint)."""
    from test_checkpoint import assert_same_bits, stopped_after

    from tmem.engine.checkpoint import Checkpoints

    scenario = with_changes(tmem.loads(HEX), {"simulation.duration": 70.0})
    reference = tmem.simulate(scenario)
    saved = stopped_after(scenario, tmp_path / "run.npz", 35.0, 40.0)
    assert {"terms.navigation.leg_now", "terms.navigation.point_now", "terms.navigation.leg_from"} <= set(saved.arrays)
    resumed = tmem.simulate(scenario, checkpoints=Checkpoints(tmp_path / "run.npz", 35.0))
    assert_same_bits(reference, resumed)


SCATTERED = """
name = "hex7-assembly"
[space]
axes = 2
[interaction]
function = "improved"
synchronise = true
d_t = 35.0
[formation]
kind = "hex"
n = 7
center = [10.0, -20.0]
scatter = [300.0, 300.0]
min_spacing = 30.0
seed = 1
[navigation]
[[navigation.legs]]
time = 0.0
action = "assemble"
speed = 5.0
[simulation]
dt = 0.001
duration = 150.0
record_every = 500
"""


def test_scattered_agents_start_at_the_places_capt_gives_them_the_least_squared_distance():
    """Against a brute-force search over every assignment of the 7 starts to the 7 places."""
    from itertools import permutations

    from tmem.world.formation import generate
    from tmem.world.initial import build

    scenario = tmem.loads(SCATTERED)
    starts = build(scenario).state[:, :, 0]
    places = generate("hex", 7, 35.0, 2, False).positions + [10.0, -20.0]
    cost = lambda order: float(((starts[list(order)] - places) ** 2).sum())  # noqa: E731  (agent order[k] at place k)
    best = min(cost(order) for order in permutations(range(7)))
    assert cost(range(7)) == pytest.approx(best, rel=1e-12)
    assert np.ptp(starts, axis=0).max() > 100.0  # scattered: the test could fail
    gaps = np.linalg.norm(starts[:, None] - starts[None], axis=-1)[np.triu_indices(7, 1)]
    assert gaps.min() >= 30.0


def test_a_scattered_hex_assembles_at_its_centre_each_agent_at_its_place_without_a_near_miss():
    from tmem.world.formation import generate

    scenario = tmem.loads(SCATTERED)
    trajectory = tmem.simulate(scenario)
    assert np.abs(trajectory.pair_distance[-1] - 35.0).max() < 0.1
    assert np.linalg.norm(trajectory.state[-1, :, :, 0].mean(axis=0) - [10.0, -20.0]) < 0.1
    places = generate("hex", 7, 35.0, 2, False).positions + [10.0, -20.0]  # agent k starts where CAPT sends it to place k
    gaps = np.linalg.norm(trajectory.state[-1, :, None, :, 0] - places[None], axis=-1)
    assert np.array_equal(gaps.argmin(axis=1), np.arange(7))  # each at its own place (the shape may turn a little:
    assert gaps.min(axis=1).max() < 2.0  # its pairs hold distances only, and a hex turned about its centre holds them all)
    positions = trajectory.state[:, :, :, 0]  # brute force over every recorded step and pair
    gaps = np.linalg.norm(positions[:, :, None] - positions[:, None], axis=-1)[:, *np.triu_indices(7, 1)]
    assert gaps.min() > 3.0


AROUND = """
name = "hex7-around"
[space]
axes = 2
[interaction]
function = "improved"
synchronise = true
d_t = 35.0
[formation]
kind = "hex"
n = 7
velocity = [0.0, 0.0]
[navigation]
[[navigation.legs]]
time = 0.0
action = "goto"
target = [600.0, 0.0]
speed = 5.0
avoid = true
[[obstacles]]
center = [300.0, 10.0]
radius = 50.0
[safety]
radius = 3.0
[simulation]
dt = 0.001
duration = 200.0
record_every = 500
"""


def test_a_group_sent_round_an_obstacle_keeps_every_agent_out_of_its_reach():
    """(N4): the obstacle on the straight line never pushes; brute force over the recorded positions."""
    from tmem.terms.navigation_plan import planned_points

    scenario = tmem.loads(AROUND)
    route = planned_points(scenario)[0][2]
    assert len(route) > 1  # it turned: the straight line would cross the obstacle
    trajectory = tmem.simulate(scenario)
    gaps = np.linalg.norm(trajectory.state[:, :, :, 0] - [300.0, 10.0], axis=-1) - 50.0
    assert gaps.min() >= scenario.wall_reach
    assert np.abs(trajectory.pair_distance - 35.0).max() < 1e-8
    assert np.linalg.norm(trajectory.state[-1, :, :, 0].mean(axis=0) - [600.0, 0.0]) < 0.5


def test_a_goal_inside_an_obstacles_clearance_is_refused_in_one_line():
    with pytest.raises(ScenarioError, match=r"navigation\.legs\[0\]\.avoid: .*goal.* \(clearance 77\.8\d* m, \(N4\)\)"):
        with_changes(tmem.loads(AROUND), {"navigation.legs": [
            {"time": 0.0, "action": "goto", "target": [300.0, 80.0], "speed": 5.0, "avoid": True}]})


def test_a_mission_faster_than_the_quadrotor_can_fly_is_refused_in_one_line():
    """The airspeed whose drag the thrust balances at the largest lean (B3): 67.36 m/s for the Crazyflie."""
    from pathlib import Path

    scenario = tmem.load(Path(__file__).parent.parent / "examples" / "missions" / "hex19_route_quadrotor.toml")
    with pytest.raises(ScenarioError, match=r"^navigation\.legs\[0\]\.speed: .* flies at 80 m/s through the air, more than 67\.36 m/s"):
        with_changes(scenario, {"navigation.legs.0.speed": 80.0})
    with_changes(scenario, {"navigation.legs.0.speed": 20.0})  # below it: accepted
