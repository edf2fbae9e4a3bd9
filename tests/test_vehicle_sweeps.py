"""The sweeps of "What survives" (docs/vehicles.md): the quadrotor under sensing effects, swept on Dask.

The sweep files load and build every case; a sensing key sweeps a base that has no ``[sensing]``
table; a mini sweep of the hex on the quadrotor with delays, run through a Dask cluster, gives the
rows a direct :func:`tmem.simulate` of each case gives; the formation's error over the last 20 s
agrees with the settling time, a different reading of the same run.
"""

from pathlib import Path

import pytest
from dask.distributed import LocalCluster

import tmem
from tmem.metrics import LAST_WINDOW, SETTLE_BAND, summarize
from tmem.scenario import ScenarioError, load, with_changes
from tmem.sweep import load_sweep, loads_sweep, run_sweep

ROOT = Path(__file__).parent.parent
SWEEPS = ROOT / "examples" / "sweeps"


@pytest.mark.parametrize(("name", "cases"), [("fig9_sensing", 34), ("hex19_sensing", 34), ("hex19_grid", 60)])
def test_the_sweep_files_load_on_the_quadrotor_at_100_hz(name, cases):
    sweep = load_sweep(SWEEPS / f"vehicles_{name}.toml")
    assert sweep.n_cases == cases
    assert sweep.base.model.kind == "quadrotor" and sweep.base.sensing.period == 0.01
    for case in sweep.cases():  # every case is a valid scenario; noise keeps velocity = position / 3 s
        changed = with_changes(sweep.base, case.changes).sensing
        assert changed.velocity_noise == pytest.approx(changed.position_noise / 3.0, abs=1e-4)


def test_a_sensing_key_adds_the_table_to_a_base_without_one():
    base = load(ROOT / "examples" / "vehicles" / "fig9.toml")
    assert base.sensing is None
    sensed = with_changes(base, {"sensing.delay": 0.05, "sensing.period": 0.01})
    assert (sensed.sensing.delay, sensed.sensing.period, sensed.sensing.loss) == (0.05, 0.01, 0.0)
    with pytest.raises(ScenarioError, match=r"^sensing\.dealy: unknown key"):
        with_changes(base, {"sensing.dealy": 0.05})
    with pytest.raises(ScenarioError, match=r"^sensing\.delay: must be delays"):
        with_changes(base, {"sensing.delay": -1.0})
    with pytest.raises(ScenarioError, match=r"^sensing\.delay\.x: unknown parameter path"):
        with_changes(base, {"sensing.delay.x": 1.0})


MINI = """
base = "../examples/vehicles/hex19.toml"
metrics = ["rms_change_percent", "min_distance", "formation.distance_error.max", "formation.distance_error_last_20s.rms"]
[set]
"simulation.duration" = 1.0
"sensing.period" = 0.01
[grid]
"sensing.delay" = [0.05, 0.1]
"""


@pytest.mark.slow  # a Dask worker and the sensed quadrotor loop: over a minute when compiled cold
def test_a_mini_sweep_of_the_hex_on_the_quadrotor_through_dask_equals_direct_runs(tmp_path):
    sweep = loads_sweep(MINI, source="mini.toml", directory=Path(__file__).parent)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        outcome = run_sweep(sweep, tmp_path / "out", scheduler=cluster.scheduler_address)
    assert outcome.failed == 0 and len(outcome.table) == 2
    rows = outcome.table.to_dict("records")
    for case, row in zip(sweep.cases(), rows):
        one = summarize(tmem.simulate(with_changes(sweep.base, case.changes)))
        assert row["sensing.delay"] == case.changes["sensing.delay"]
        assert row["rms_change_percent"] == one["rms_change_percent"]
        assert row["min_distance"] == one["min_distance"]
        assert row["formation.distance_error.max"] == one["formation"]["distance_error"]["max"]
        assert row["formation.distance_error_last_20s.rms"] == one["formation"]["distance_error_last_20s"]["rms"]
    assert rows[0]["rms_change_percent"] != rows[1]["rms_change_percent"]  # the delay reached the runs


def test_the_error_over_the_last_20_s_agrees_with_the_settling_time():
    """The settled hex stays within SETTLE_BAND of d_t from its settling time on, so over the last
    20 s, once settled before them, its largest error is within the band; over a run no longer than
    the window it is the whole run's."""
    settled = with_changes(load(ROOT / "examples" / "swarm" / "hex19_settled.toml"), {"simulation.dt": 1e-3})
    formation = summarize(tmem.simulate(settled))["formation"]
    assert formation["settling_time"] < settled.simulation.duration - LAST_WINDOW
    assert formation["distance_error_last_20s"]["max"] <= SETTLE_BAND < formation["distance_error"]["max"]
    short = summarize(tmem.simulate(with_changes(settled, {"simulation.duration": LAST_WINDOW})))["formation"]
    assert short["distance_error_last_20s"] == short["distance_error"]
