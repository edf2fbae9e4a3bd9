"""Running sweeps: rows against single runs, failures, interruption and resume, a real Dask cluster."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from dask.distributed import Client, LocalCluster

import tmem
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes
from tmem.sweep import SweepInterrupted, loads_sweep, run_sweep
from tmem.sweep.report import coupling_statistics, rms_statistics
from tmem.sweep.spec import SCALAR_METRICS
from tmem.sweep.store import ResultStore
from tmem.sweep.tasks import plan_chunks, row, run_chunk

# Short, coarse runs: the paper's pair with random starts, both coupling functions.
ENCOUNTERS = """
name = "encounters"
base = "fig7"
cases = {cases}
seed = 5
batch = {batch}
[set]
"simulation.dt" = 0.001
"simulation.duration" = 40.0
[grid]
"interaction.function" = ["switching", "improved"]
[random]
"agents.0.position" = {{ uniform = [45, 70] }}
"agents.0.velocity" = {{ uniform = [-4, -1] }}
"agents.1.velocity" = {{ uniform = [1, 4] }}
"""


def encounters(cases=6, batch=3):
    return loads_sweep(ENCOUNTERS.format(cases=cases, batch=batch), source="encounters.toml")


def test_batched_rows_equal_single_runs_of_the_engine():
    sweep = encounters()
    metrics = tuple(SCALAR_METRICS)
    cases = sweep.cases()
    chunks = plan_chunks(sweep.base, cases, metrics, None)
    assert len(chunks) == 2  # one batch per function
    rows = [row for chunk in chunks for row in run_chunk(sweep.base, chunk, metrics)]
    assert [r["case"] for r in rows] == [c.index for c in cases]
    for case, row in zip(cases, rows):
        one = summarize(tmem.simulate(with_changes(sweep.base, case.changes)))
        assert row["error"] is None
        for m in ("rms_change_percent", "rms_velocity_final", "min_distance", "final_distance"):
            assert row[m] == pytest.approx(one[m], abs=1e-7), m
        assert row["coupled"] == one["coupled"]
        for m in ("couple_time", "uncouple_time"):
            assert (row[m] is None and one[m] is None) or row[m] == pytest.approx(one[m], abs=1e-9)
        assert row["uncouple_rule"] == one["uncouple_rule"]


# Encounters at an angle, under explicit cases that set different keys.
PLANE = """
name = "plane"
base = "../encounter_plane.toml"
cases = 3
seed = 2
[set]
"simulation.dt" = 0.001
"simulation.duration" = 45.0
"interaction.function" = "improved"
[random]
"agents.0.position" = { polar = [[45.0, 60.0], [-15.0, 15.0]] }
"agents.0.velocity" = { polar = [[2.0, 4.0], [160.0, 200.0]] }
"agents.1.velocity" = { polar = [[2.0, 4.0], [-20.0, 20.0]] }
[[case]]
"interaction.uncouple_when" = "energy"
[[case]]
"interaction.synchronise" = true
"""


def test_explicit_cases_with_different_keys_in_the_plane(cluster, tmp_path):
    """A key that only some explicit cases set is empty in the others' rows; each row's figures and
    uncoupling rule are those of tmem.simulate for the same case."""
    sweep = loads_sweep(PLANE, source="plane.toml", directory=Path(__file__).parent.parent / "examples" / "sweeps")
    outcome = run_sweep(sweep, tmp_path / "out", scheduler=cluster.scheduler_address)
    table = outcome.table
    assert outcome.failed == 0 and len(table) == 6
    assert table["interaction.synchronise"].isna().tolist() == [True] * 3 + [False] * 3
    for case, row in zip(sweep.cases(), table.itertuples(index=False)):
        one = summarize(tmem.simulate(with_changes(sweep.base, case.changes)))
        assert row.rms_change_percent == pytest.approx(one["rms_change_percent"], abs=1e-7)
        assert (pd.isna(row.uncouple_rule) and one["uncouple_rule"] is None) or row.uncouple_rule == one["uncouple_rule"]
    assert set(table["uncouple_rule"].dropna()) <= {"window", "energy", "fallback"}
    assert "## What released the pairs" in (tmp_path / "out" / "summary.md").read_text()


def test_a_vector_key_that_a_case_leaves_out_is_empty_in_its_row(tmp_path):
    """A constant wind set by one case and left out by the reference, both in one part: the
    reference's row has no wind (null, not the JSON text of NaN), the other its vector as JSON."""
    sweep = loads_sweep('name = "wind"\nbase = "../vehicles/fig9.toml"\nmetrics = ["rms_change_percent"]\n'
                        'case = [{}, { "wind.velocity" = [1.0] }]\n', source="wind.toml",
                        directory=Path(__file__).parent.parent / "examples" / "sweeps")  # fmt: skip
    store = ResultStore.check(tmp_path / "out", sweep)
    with store.opened():
        store.add([row(case, ("rms_change_percent",), {"rms_change_percent": 0.0}, None, 0.0) for case in sweep.cases()])
        table = store.table()
    assert table["wind.velocity"].isna().tolist() == [True, False]
    assert json.loads(table["wind.velocity"][1]) == [1.0]


def test_a_failing_case_is_a_row_with_its_error_and_the_others_run():
    sweep = loads_sweep(
        """
base = "fig7"
cases = 8
seed = 1
[set]
"simulation.duration" = 30.0
"simulation.dt" = 0.001
[random]
"agents.0.position" = { choice = [50.0, 0.0] }
""",
        source="t.toml",
    )
    cases = sweep.cases()
    assert cases[0].changes["agents.0.position"] == 50.0  # the file's check uses the first draw
    bad = [c.index for c in cases if c.changes["agents.0.position"] == 0.0]
    assert 0 < len(bad) < len(cases)
    metrics = tuple(SCALAR_METRICS)
    rows = [row for chunk in plan_chunks(sweep.base, cases, metrics, None) for row in run_chunk(sweep.base, chunk, metrics)]
    for row in rows:
        if row["case"] in bad:
            assert "two agents at one point" in row["error"] and row["rms_change_percent"] is None
        else:
            assert row["error"] is None and row["rms_change_percent"] is not None


def test_swarm_cases_run_one_by_one_with_nested_metrics():
    sweep = loads_sweep(
        """
base = "../examples/swarm/triangle.toml"
metrics = ["rms_change_percent", "formation.distance_error.max", "pairs.0.coupled_at"]
[set]
"simulation.duration" = 5.0
[grid]
"interaction.c_max" = [0.1, 0.2]
""",
        source="t.toml",
        directory=Path(__file__).parent,
    )
    metrics = tuple(sweep.spec.metrics)
    chunks = plan_chunks(sweep.base, sweep.cases(), metrics, None)
    assert [len(c) for c in chunks] == [1, 1]
    for chunk in chunks:
        (row,) = run_chunk(sweep.base, chunk, metrics)
        one = summarize(tmem.simulate(with_changes(sweep.base, chunk[0].changes)))
        assert row["formation.distance_error.max"] == one["formation"]["distance_error"]["max"]
        assert row["pairs.0.coupled_at"] == one["pairs"][0]["coupled_at"]


@pytest.fixture(scope="module")
def cluster():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as c:
        yield c


def test_a_sweep_through_a_real_cluster_address_has_one_row_per_case(cluster, tmp_path):
    sweep = encounters(cases=10, batch=4)
    outcome = run_sweep(sweep, tmp_path / "out", scheduler=cluster.scheduler_address)
    table = pd.read_parquet(tmp_path / "out" / "results.parquet")
    assert list(table["case"]) == list(range(20))
    assert outcome.ran == 20 and outcome.failed == 0
    assert table["error"].isna().all()
    assert (tmp_path / "out" / "summary.md").exists() and (tmp_path / "out" / "rms_change_histogram.png").exists()
    assert not (tmp_path / "out" / "parts").exists()
    # run again: nothing left to run, the same table
    again = run_sweep(sweep, tmp_path / "out", scheduler=cluster.scheduler_address)
    assert again.ran == 0
    pd.testing.assert_frame_equal(again.table, table)


def test_an_interrupted_sweep_resumes_with_only_the_missing_cases(cluster, tmp_path):
    sweep = encounters(cases=12, batch=2)
    out = tmp_path / "out"
    seen = []

    def interrupt_after_some(done, total):
        seen.append(done)
        if done >= 6:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted) as info:
        run_sweep(sweep, out, scheduler=cluster.scheduler_address, progress=interrupt_after_some)
    saved = info.value.done
    assert 6 <= saved <= 24  # a quiet cluster may report every case in the first batch it hands back
    assert not (out / "results.parquet").exists()
    parts = pd.concat([pd.read_parquet(p) for p in (out / "parts").glob("part-*.parquet")])
    assert len(parts) == saved and parts["case"].is_unique
    resumed = run_sweep(sweep, out, scheduler=cluster.scheduler_address)
    assert resumed.ran == 24 - saved
    table = pd.read_parquet(out / "results.parquet")
    assert list(table["case"]) == list(range(24))
    # the rows saved before the interruption are those an uninterrupted sweep gives
    whole = run_sweep(sweep, tmp_path / "whole", scheduler=cluster.scheduler_address).table
    cols = ["case", *sweep.parameters, *sweep.spec.metrics]
    pd.testing.assert_frame_equal(table[cols], whole[cols])


def test_a_killed_worker_loses_no_case(tmp_path):
    sweep = encounters(cases=40, batch=2)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        client = Client(cluster)
        killed = []

        def kill_a_worker_once(done, total):
            if done > 0 and not killed:
                pid = next(iter(client.run(os.getpid).values()))
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)

        outcome = run_sweep(sweep, tmp_path / "out", scheduler=cluster.scheduler_address, progress=kill_a_worker_once)
        client.close()
    assert killed
    assert list(outcome.table["case"]) == list(range(80))
    assert outcome.table["error"].isna().all()


def test_ctrl_c_on_the_command_then_the_same_command_finishes(tmp_path):
    sweep_file = tmp_path / "encounters.toml"
    sweep_file.write_text(ENCOUNTERS.format(cases=1000, batch=8).replace("0.001", "0.0001"))  # a few seconds
    out = tmp_path / "out"
    command = [sys.executable, "-m", "tmem", "sweep", str(sweep_file), "--out", str(out), "--workers", "2"]
    # Ctrl-C in a terminal reaches the whole process group: the command and its workers.
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 120
    while not list((out / "parts").glob("part-*.parquet")) and time.monotonic() < deadline:
        time.sleep(0.2)
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert "run the same command again" in stderr and "Traceback" not in stderr
    assert not (out / "results.parquet").exists()
    finished = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert finished.returncode == 0, finished.stderr
    table = pd.read_parquet(out / "results.parquet")
    assert list(table["case"]) == list(range(2000))


def test_statistics_against_closed_forms():
    values = pd.Series(np.arange(101, dtype=float))  # 0, 1, ..., 100
    s = rms_statistics(pd.concat([values, pd.Series([np.nan])]))
    assert s["n"] == 101 and s["mean"] == 50 and s["median"] == 50
    assert (s["p5"], s["p25"], s["p75"], s["p95"]) == (5, 25, 75, 95)
    assert s["std"] == pytest.approx(np.sqrt(101 * 102 / 12))  # sample std of 0..n: sqrt(n(n+2)/12) with n = 100
    group = pd.DataFrame(
        {
            "coupled": [True, True, True, False, None],
            "couple_time": [3.0, 4.0, 5.0, np.nan, np.nan],
            "uncouple_time": [30.0, 32.0, np.nan, np.nan, np.nan],
            "error": [None, None, None, None, "boom"],
        }
    )
    c = coupling_statistics(group, command_time=29.0)
    assert c["n"] == 4 and c["coupled_percent"] == 75.0
    assert c["uncoupled_percent"] == pytest.approx(200 / 3) and c["uncouple_delay_median"] == 2.0
    assert c["couple_time_median"] == 4.0


def test_tasks_the_cluster_loses_leave_their_cases_to_run_again(tmp_path, monkeypatch):
    sweep = encounters(cases=6, batch=3)
    real = run_chunk

    def flaky(base, cases, metrics):  # the first chunk's connection drops
        if cases[0].index == 0:
            raise ConnectionResetError("connection to the worker closed")
        return real(base, cases, metrics)

    monkeypatch.setattr("tmem.sweep.runner.run_chunk", flaky)
    with LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as threads:
        with pytest.raises(SweepInterrupted, match="tasks lost, ConnectionResetError"):
            run_sweep(sweep, tmp_path / "out", scheduler=threads.scheduler_address)
        parts = pd.concat([pd.read_parquet(p) for p in (tmp_path / "out" / "parts").glob("part-*.parquet")])
        assert sorted(parts["case"]) == list(range(3, 12)) and parts["error"].isna().all()
        monkeypatch.setattr("tmem.sweep.runner.run_chunk", real)
        resumed = run_sweep(sweep, tmp_path / "out", scheduler=threads.scheduler_address)
    assert resumed.ran == 3 and list(resumed.table["case"]) == list(range(12))


def test_a_local_cluster_that_does_not_close_in_time_leaves_no_worker(monkeypatch):
    import multiprocessing

    from dask.distributed import LocalCluster as Local

    from tmem.sweep.cluster import dask_client

    def times_out(self, *args, **kwargs):  # as a worker that does not answer the shutdown in time
        raise TimeoutError

    before = set(multiprocessing.active_children())
    with dask_client(None, 1) as client:
        assert client.submit(sum, [1, 2]).result() == 3
        assert set(multiprocessing.active_children()) - before  # the worker's process
        monkeypatch.setattr(Local, "close", times_out)
    deadline = time.monotonic() + 10  # the nanny's own watcher may reap the killed worker a moment later
    while set(multiprocessing.active_children()) - before and time.monotonic() < deadline:
        time.sleep(0.1)
    assert set(multiprocessing.active_children()) <= before


@pytest.mark.parametrize("count", [3, 12, 25])
def test_the_scatter_plot_tells_every_setting_apart_and_hides_no_point(count):
    """Twelve or twenty-five settings: no two share a colour and marker; the legend lies beside the axes."""
    from matplotlib.colors import to_rgba

    from tmem.sweep.report import scatter_figure

    rng = np.random.default_rng(1)
    groups = [(f"interaction.c_max = {0.01 * (k + 1):.2f}",
               pd.DataFrame({"x": rng.uniform(0, 1, 50), "rms_change_percent": rng.normal(k, 1, 50), "error": None}))
              for k in range(count)]  # fmt: skip
    fig = scatter_figure(groups, "x")
    ax = fig.axes[0]
    styles = set()
    for collection in ax.collections:
        colour = tuple(np.round(to_rgba(collection.get_facecolor()[0], 1.0), 6))
        marker = collection.get_paths()[0].vertices.round(6).tobytes()
        styles.add((colour, marker))
    assert len(styles) == count
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend, axes = ax.get_legend().get_window_extent(renderer), ax.get_window_extent(renderer)
    assert legend.x0 >= axes.x1  # beside the plot, over none of its points
    assert fig.bbox.x0 <= legend.x0 and legend.x1 <= fig.bbox.x1 + 1
