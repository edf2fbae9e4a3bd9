"""A formation that changes its shape in flight (``reshape`` legs): hex -> line -> hex.

The references are independent of the code under test: a brute-force search over every assignment
of the old shape's places to the new shape's, the pairs found d_t apart in the flown positions, the
same reshape flown at rest (a reshape carried at the group's velocity must give the same relative
motion on the linear model: a Galilean symmetry), brute force over every recorded step for the
separations, and the bits of an uninterrupted run for a resumed one.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np
import pytest

import tmem
from tmem.scenario import ScenarioError, with_changes
from tmem.world.formation import generate

D_T = 35.0
RESHAPE = f"""
name = "hex7-reshape"
[space]
axes = 2
[interaction]
function = "improved"
synchronise = true
d_t = {D_T}
[formation]
kind = "hex"
n = 7
bearing = true
[navigation]
[[navigation.legs]]
time = 0.0
action = "velocity"
velocity = [2.0, 1.0]
[[navigation.legs]]
time = 40.0
action = "reshape"
shape = "chain"
speed = 4.0
[[navigation.legs]]
time = 170.0
action = "reshape"
shape = "hex"
speed = 4.0
[simulation]
dt = 0.01
duration = 290.0
record_every = 50
"""


def _at(trajectory, time: float) -> np.ndarray:
    """The recorded positions at ``time`` (s), relative to their centre."""
    p = trajectory.state[np.searchsorted(trajectory.time, time - 1e-9), :, :, 0]
    return p - p.mean(axis=0)


def _least_cost(before: np.ndarray, places: np.ndarray) -> float:
    """The least sum of squared distances from ``before`` to ``places`` over every assignment."""
    return min(float(((places[list(order)] - before) ** 2).sum()) for order in permutations(range(len(places))))


@pytest.fixture(scope="module")
def flown():
    scenario = tmem.loads(RESHAPE)
    return scenario, tmem.simulate(scenario)


@pytest.fixture(scope="module")
def at_rest():
    scenario = with_changes(tmem.loads(RESHAPE), {"navigation.legs[0]": {"time": 0.0, "action": "hold"}})
    return tmem.simulate(scenario)


def test_each_reshape_flies_the_assignment_of_least_squared_distance(flown):
    """The flown positions after each reshape are the new shape's places, given by the assignment a
    brute-force search over all 5040 finds cheapest from where the agents were."""
    _, trajectory = flown
    hex_places, line = generate("hex", 7, D_T, 2).positions, generate("chain", 7, D_T, 2).positions
    for start, end, places in ((40.0, 169.5, line), (170.0, 290.0, hex_places)):
        before, after = _at(trajectory, start), _at(trajectory, end)
        cost = float(((after - before) ** 2).sum())
        assert cost == pytest.approx(_least_cost(before, places), rel=1e-3)
        gaps = np.linalg.norm(after[:, None] - places[None], axis=-1)  # each agent at one of the places
        assert gaps.min(axis=1).max() < 0.1


def test_the_coupled_pairs_are_the_new_shapes_neighbours(flown):
    """After each reshape the coupled pairs are exactly the pairs found d_t apart (and no other pair is)."""
    _, trajectory = flown
    for time, count in ((169.5, 6), (290.0, 12)):
        r = np.searchsorted(trajectory.time, time - 1e-9)
        p = trajectory.state[r, :, :, 0]
        near = {(i, j) for i in range(7) for j in range(i + 1, 7) if abs(np.linalg.norm(p[j] - p[i]) - D_T) < 0.1}
        coupled = {tuple(pair) for pair in trajectory.pairs[trajectory.flag[r] == 1].tolist()}
        assert len(near) == count and coupled == near


def test_a_reshape_carried_at_the_groups_velocity_moves_as_one_at_rest(flown, at_rest):
    """The same reshape, flown moving and at rest: the same positions about the centre (the pushes of
    the law and of the lines do not see a common velocity on the linear model, once the group's velocity
    has settled: a reshape that starts while the group still accelerates saturates its agents unequally)."""
    _, moving = flown
    for time in (60.0, 130.0, 210.0, 290.0):
        assert np.abs(_at(moving, time) - _at(at_rest, time)).max() < 1e-6
    assert np.linalg.norm(moving.state[-1, :, :, 0].mean(axis=0)) > 400.0  # it did fly on: the test could fail


def test_no_two_agents_come_within_the_safety_radius_while_reshaping(flown):
    """Brute force over every recorded step and pair."""
    _, trajectory = flown
    p = trajectory.state[:, :, :, 0]
    gaps = np.linalg.norm(p[:, :, None] - p[:, None], axis=-1)[:, *np.triu_indices(7, 1)]
    assert gaps.min() > 3.0


def test_the_pairs_let_go_when_a_reshape_starts_and_the_new_ones_couple_when_its_lines_end(flown):
    scenario, trajectory = flown
    a_b = 0.5 * 0.5 * 0.1 * 9.8  # half of share c_max g: what the lines may ask (N3)
    span = max(1.5 * 70.0 / 4.0, np.sqrt(6.0 * 70.0 / a_b))  # T of (N5), cubic lines: the farthest agent flies 70 m
    changes = {}
    for e in trajectory.events:
        if e.kind in ("couple", "uncouple"):
            changes.setdefault((e.time, e.kind), set()).add(e.agents)
    hex_edges = {tuple(edge) for edge in generate("hex", 7, D_T, 2).edges.tolist()}
    line = changes[(round(round((40.0 + span) / 0.01) * 0.01, 12), "couple")]
    assert changes[(40.0, "uncouple")] == hex_edges and len(line) == 6
    assert changes[(170.0, "uncouple")] == line and len(changes[(round(round((170.0 + span) / 0.01) * 0.01, 12), "couple")]) == 12
    assert len(changes) == 4  # nothing else coupled or let go
    assert {e.rule for e in trajectory.events if e.kind == "uncouple"} == {"reshape"}


def test_a_reshape_goes_on_from_its_checkpoint_to_the_same_bits(tmp_path):
    """Each agent's line start and the group's velocity at the reshape are saved (checkpoint mid-reshape)."""
    from test_checkpoint import assert_same_bits, stopped_after

    from tmem.engine.checkpoint import Checkpoints

    scenario = with_changes(tmem.loads(RESHAPE), {"simulation.duration": 180.0})
    reference = tmem.simulate(scenario)
    saved = stopped_after(scenario, tmp_path / "run.npz", 30.0, 60.0)
    assert {"terms.navigation.line_from", "terms.navigation.drift"} <= set(saved.arrays)
    resumed = tmem.simulate(scenario, checkpoints=Checkpoints(tmp_path / "run.npz", 30.0))
    assert_same_bits(reference, resumed)


@pytest.mark.parametrize(("change", "message"), [
    ({"navigation.legs[1]": {"time": 40.0, "action": "reshape", "speed": 4.0}}, r"navigation\.legs\[1\]\.shape: is required for reshape"),
    ({"navigation.legs[1].shape": "triangle"}, r"navigation\.legs\[1\]\.shape: a triangle cannot hold the formation's 7 agents"),
    ({"navigation.legs[1].shape": "star"}, r"navigation\.legs\.1\.shape|navigation\.legs\[1\]\.shape"),
    ({"navigation.legs[1].speed": [4.0, 5.0]}, r"navigation\.legs\[1\]\.speed: is one speed for reshape"),
    ({"navigation.legs[0]": {"time": 0.0, "action": "hold", "shape": "ring"}}, r"navigation\.legs\[0\]\.shape: is not used by hold"),
    ({"formation": None, "swarm": {"n": 7, "region": [300.0, 300.0], "seed": 1}}, r"navigation\.legs\[1\]\.action: 'reshape' needs a \[formation\] of a generated kind"),
    ({"navigation.legs[2].time": 60.0}, r"navigation\.legs\[2\]\.time: 60 s is before the reshape of legs\[1\] ends its lines at 81\.4 s"),
    ({"navigation.legs[2]": {"time": 170.0, "action": "assemble", "speed": 4.0}},
     r"navigation\.legs\[2\]\.action: an assemble leg comes before any reshape"),
])  # fmt: skip
def test_a_bad_reshape_is_refused_in_one_line_naming_the_key(change, message):
    with pytest.raises(ScenarioError, match=message):
        with_changes(tmem.loads(RESHAPE), change)


def test_a_reshapes_speed_is_among_the_speeds_the_vehicles_bounds_check():
    """The quadrotor's airspeed bound (B3) and (M1) read a mission's speeds: a reshape's is one of them."""
    from tmem.scenario.motion_bounds import speeds

    found = {s.field: s.velocity for s in speeds(tmem.loads(RESHAPE))}
    assert found["navigation.legs[1].speed"] == (4.0, 0.0) and found["navigation.legs[2].speed"] == (4.0, 0.0)
