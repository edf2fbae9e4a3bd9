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
