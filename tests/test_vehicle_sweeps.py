"""The sweeps of "What survives" (docs/vehicles.md): the quadrotor under sensing effects and wind, swept on Dask.

The sweep files load and build every case; the wind sweeps start from the sensing sweeps' reference
and blow the winds their files name; a sensing key sweeps a base that has no ``[sensing]`` table,
and a wind key one that has no ``[wind]`` table; a mini sweep of the hex on the quadrotor with delays, run through a Dask cluster, gives the
rows a direct :func:`tmem.simulate` of each case gives; the formation's error over the last 20 s
agrees with the settling time, a different reading of the same run.
"""

from pathlib import Path

import pytest
from dask.distributed import LocalCluster

import tmem
from tmem.analysis.metrics import LAST_WINDOW, SETTLE_BAND, summarize
from tmem.scenario import ScenarioError, load, with_changes
from tmem.sweep import SweepError, load_sweep, loads_sweep, run_sweep

ROOT = Path(__file__).parent.parent
SWEEPS = ROOT / "examples" / "sweeps"


@pytest.mark.parametrize(("name", "cases"), [("fig9_sensing", 34), ("hex19_sensing", 34), ("hex19_grid", 60),
                                             ("fig9_wind", 19), ("hex19_wind", 32)])  # fmt: skip
def test_the_sweep_files_load_on_the_quadrotor_at_100_hz(name, cases):
    sweep = load_sweep(SWEEPS / f"vehicles_{name}.toml")
    assert sweep.n_cases == cases
    assert sweep.base.model.kind == "quadrotor" and sweep.base.sensing.period == 0.01
    for case in sweep.cases():  # every case is a valid scenario; noise keeps velocity = position / 3 s
        changed = with_changes(sweep.base, case.changes).sensing
        assert changed.velocity_noise == pytest.approx(changed.position_noise / 3.0, abs=1e-4)


#: MIL-F-8785C's wind speeds at 20 ft for light, moderate and severe turbulence: 15, 30, 45 knots (m/s).
W20 = {"light": 15 * 1852 / 3600, "moderate": 30 * 1852 / 3600, "severe": 45 * 1852 / 3600}


@pytest.mark.parametrize("vehicle", ["fig9", "hex19"])
def test_the_wind_sweeps_start_from_the_sensing_sweeps_reference(vehicle):
    wind, sensing = (load_sweep(SWEEPS / f"vehicles_{vehicle}_{axis}.toml") for axis in ("wind", "sensing"))
    built = [with_changes(wind.base, case.changes) for case in wind.cases()]
    assert built[0] == with_changes(sensing.base, sensing.cases()[0].changes) and built[0].wind is None
    assert all(s.sensing == built[0].sensing for s in built)
    winds = {synchronised: [s.wind for s in built if s.interaction.synchronise == synchronised and s.wind is not None]
             for synchronised in (False, True)}  # fmt: skip
    assert winds[True] == ([] if vehicle == "fig9" else winds[False])  # the hex flies each wind both ways
    constant = [w.mean() for w in winds[False] if w.turbulence is None]
    speeds = [1.0, 2.0, 5.0, 8.0, 12.0, 16.0] + ([20.0, 30.0, 40.0] if vehicle == "fig9" else [])
    assert [x for x, _, _ in constant] == speeds and all(y == z == 0.0 for _, y, z in constant)  # along x
    gusts = [w for w in winds[False] if w.turbulence is not None]
    assert all(w.velocity is None and w.vertical == 0.0 for w in gusts)  # turbulence alone, no mean wind
    assert sorted((w.turbulence.severity, w.turbulence.seed) for w in gusts) == [(k, s) for k in sorted(W20) for s in (1, 2, 3)]
    for w in gusts:  # the field passes at the intensity's own W_20, to the table's 3 decimals
        assert w.passing_speed() == pytest.approx(W20[w.turbulence.severity], abs=5e-4)


def test_wind_keys_by_path_build_the_table_a_file_spells_out():
    calm, windy = (load(ROOT / "examples" / "vehicles" / f"{name}.toml") for name in ("hex19", "hex19_wind"))
    assert calm.wind is None
    changes = {"wind.velocity": [2.0, 0.0], "wind.vertical": 0.0, "wind.turbulence.severity": "light",
               "wind.turbulence.height": 10.0, "wind.turbulence.seed": 0, "name": windy.name}  # fmt: skip
    assert with_changes(calm, changes) == windy
    assert with_changes(calm, {"wind.turbulence.seed": 4, "wind.velocity": [1.0, 0.0], "wind.turbulence.w20": 3.0}).wind.turbulence.height == 10.0


@pytest.mark.parametrize(("changes", "message"), [
    ({"wind.turbulence.sevrity": "light"}, r"^wind\.turbulence\.sevrity: unknown key"),
    ({"wind.turbulence.severity": "fierce", "wind.turbulence.speed": 5.0}, r"^wind\.turbulence\.severity: must be 'light', 'moderate' or 'severe'"),
    ({"wind.turbulence.severity": "light"}, r"^wind\.turbulence\.speed: is required when there is no constant wind"),
    ({"wind.velocity": [1.0, 0.0]}, r"^wind\.velocity: needs 1 value, one per axis"),
    ({"wind.velocity.0": 1.0}, r"^wind\.velocity\.0: unknown parameter path"),
    ({"wind.gust": 1.0}, r"^wind\.gust: unknown key"),
])  # fmt: skip
def test_a_bad_wind_key_is_refused_naming_it(changes, message):
    with pytest.raises(ScenarioError, match=message):
        with_changes(load(ROOT / "examples" / "vehicles" / "fig9.toml"), changes)


def test_a_bad_wind_case_stops_the_sweep_before_anything_runs():
    text = 'base = "../examples/vehicles/fig9.toml"\ncase = [{}, { "wind.turbulence.severity" = "light", "wind.turbulence.seed" = 1 }]\n'
    with pytest.raises(SweepError, match=r"wind\.turbulence\.speed: is required"):
        loads_sweep(text, source="wind.toml", directory=Path(__file__).parent)


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


@pytest.mark.physics
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
