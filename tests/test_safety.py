"""A run's safety figures in ``summary.json``: against brute force over the recorded steps, and the
closing-speed limit (M1) against the pair's own stopping distance."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import tmem
from tmem.analysis.metrics import summarize
from tmem.scenario import ScenarioError, with_changes

HEAD_ON = """
name = "head-on"
[space]
axes = 2
[interaction]
function = "repulsion"
c_max = {c_max}
[[agents]]
position = [0.0, 0.0]
velocity = [{speed}, 0.0]
[[agents]]
position = [200.0, 0.5]
velocity = [-{speed}, 0.0]
[safety]
radius = 3.0
[simulation]
dt = 0.001
duration = 30.0
record_every = 20
"""


def _closest(trajectory) -> float:
    p = trajectory.state[:, :, :, 0]
    return float(np.linalg.norm(p[:, 1] - p[:, 0], axis=-1).min())


@pytest.mark.parametrize("speed", [4.0, 9.0])
def test_a_pair_slower_than_the_limit_keeps_outside_the_radius_and_a_faster_one_does_not(speed):
    """(M1): at c_max = 0.02 rad the limit is sqrt(4 g c_max (40 - 3)) = 5.39 m/s of closing speed."""
    scenario = tmem.loads(HEAD_ON.format(c_max=0.02, speed=speed / 2))
    summary = summarize(tmem.simulate(scenario))["safety"]
    assert summary["closing_speed_limit"] == pytest.approx(math.sqrt(4 * 9.8 * 0.02 * 37.0))
    assert (summary["near_misses"] == 0) == (speed < summary["closing_speed_limit"])


def test_the_summary_counts_the_near_miss_that_brute_force_finds():
    trajectory = tmem.simulate(tmem.loads(HEAD_ON.format(c_max=0.005, speed=5.0)))
    safety = summarize(trajectory)["safety"]
    closest = _closest(trajectory)
    assert closest < 3.0  # the pass is a near miss: the test could fail
    assert safety["near_misses"] == 1
    assert safety["min_separation"] == pytest.approx(closest, rel=1e-12)
    assert safety["closest_pass"] <= closest


def test_a_run_without_the_table_has_no_safety_figures():
    scenario = with_changes(tmem.loads(HEAD_ON.format(c_max=0.1, speed=1.0)), {"safety": None})
    assert summarize(tmem.simulate(scenario))["safety"] is None


@pytest.mark.parametrize(("change", "message"), [
    ({"safety.radius": 40.0}, r"safety\.radius: 40 m is not inside the repulsion's reach R \+ R_j = 40 m"),
    ({"safety.collision_radius": 3.0}, r"collision_radius: must be below the safety radius 3 m, got 3"),
    ({"safety.range": -1.0}, r"safety\.range"),
])  # fmt: skip
def test_a_bad_safety_key_is_refused_in_one_line(change, message):
    with pytest.raises(ScenarioError, match=message):
        with_changes(tmem.loads(HEAD_ON.format(c_max=0.1, speed=1.0)), change)


def test_a_random_swarm_with_a_minimum_spacing_starts_that_far_apart_and_refuses_what_cannot_fit():
    """Against brute force over every pair of the 400 starts."""
    from scipy.spatial.distance import pdist

    from tmem.world.initial import build

    scenario = tmem.load(Path(__file__).parent.parent / "examples" / "swarm" / "gas_thermostat.toml")
    starts = build(with_changes(scenario, {"swarm.min_spacing": 5.0})).state[:, :, 0]
    assert len(starts) == 400 and pdist(starts).min() >= 5.0
    assert pdist(build(scenario).state[:, :, 0]).min() < 5.0  # without it, closer: the test could fail
    with pytest.raises(ScenarioError, match=r"^swarm\.min_spacing: 400 points cannot be 500 m apart"):
        with_changes(scenario, {"swarm.min_spacing": 500.0})
