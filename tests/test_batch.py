"""The batched two-agent loop against the full engine, case by case."""

import numpy as np
import pytest

import tmem
from tmem.batch import run_batch
from tmem.metrics import summarize
from tmem.scenario import with_changes

STARTS = [((50.0, 0.0), (-1.5, 3.0)), ((60.0, 0.0), (-2.0, 2.0)), ((0.0, 45.0), (4.0, -4.0)), ((100.0, 0.0), (-0.5, 1.0))]


@pytest.mark.parametrize("function", tmem.FUNCTION_NAMES)
@pytest.mark.parametrize("switch_at", ["window", "crossing"])
def test_batch_equals_the_engine(function, switch_at):
    base = with_changes(
        tmem.preset("fig9"),
        {"interaction.function": function, "interaction.switch_at": switch_at, "simulation.duration": 45.0},
    )
    positions = np.array([p for p, _ in STARTS])
    velocities = np.array([v for _, v in STARTS])
    batch = run_batch(base, positions, velocities)
    for k, (p, v) in enumerate(STARTS):
        agents = [{"position": p[0], "velocity": v[0]}, {"position": p[1], "velocity": v[1]}]
        one = summarize(tmem.simulate(with_changes(base, {"agents": agents})))
        assert batch.rms_change_percent[k] == pytest.approx(one["rms_change_percent"], abs=1e-7)
        assert batch.min_distance[k] == pytest.approx(one["min_distance"], abs=1e-7)
        assert batch.final_distance[k] == pytest.approx(one["final_distance"], abs=1e-7)
        np.testing.assert_allclose(batch.final_velocities[k], np.ravel(one["final_velocities"]), atol=1e-9)
        for ours, theirs in ((batch.couple_time[k], one["couple_time"]), (batch.uncouple_time[k], one["uncouple_time"])):
            assert (np.isnan(ours) and theirs is None) or ours == pytest.approx(theirs, abs=1e-9)


def test_batch_refuses_what_it_cannot_run():
    with pytest.raises(ValueError, match="two agents"):
        run_batch(tmem.load("examples/swarm/triangle.toml"), np.zeros((1, 2)), np.zeros((1, 2)))


BAD_STARTS = {
    "nan position": ([[np.nan, 0.0]], [[-1.5, 3.0]], "positions[0, 0]"),
    "inf velocity": ([[50.0, 0.0]], [[-1.5, np.inf]], "velocities[0, 1]"),
    "huge position": ([[50.0, 1e300]], [[-1.5, 3.0]], "positions[0, 1]"),
    "same place": ([[50.0, 0.0], [7.0, 7.0]], [[-1.5, 3.0], [1.0, -1.0]], "positions[1]"),
    "one agent": ([[50.0]], [[-1.5]], "positions: must have shape (cases, 2)"),
    "flat": ([50.0, 0.0], [-1.5, 3.0], "positions: must have shape (cases, 2)"),
    "no cases": (np.empty((0, 2)), np.empty((0, 2)), "positions: must have shape"),
    "cases differ": ([[50.0, 0.0]], [[-1.5, 3.0], [1.0, 1.0]], "velocities: has 2 cases"),
    "text": ([["a", "b"]], [[-1.5, 3.0]], "positions: must be numbers"),
}


@pytest.mark.parametrize("name", BAD_STARTS, ids=list(BAD_STARTS))
def test_bad_starts_are_refused_in_one_line(name):
    """As ``tmem run`` refuses them (regression: these ran, returning NaN or +167 %)."""
    positions, velocities, where = BAD_STARTS[name]
    with pytest.raises(ValueError) as info:
        run_batch(tmem.preset("fig9"), positions, velocities)
    message = str(info.value)
    assert "\n" not in message and message.startswith("run_batch: ") and where in message, message


def test_a_scenario_that_is_not_one_is_refused():
    with pytest.raises(ValueError, match="run_batch: scenario: must be a tmem Scenario"):
        run_batch({"name": "fig9"}, [[50.0, 0.0]], [[-1.5, 3.0]])
