"""`tmem run` and `tmem paper` outputs: summary.json, trajectory.nc, figures, report.md."""

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app
from tmem.analysis.metrics import rms_velocity
from tmem.files.trajectory_file import components, open_trajectory, positions

EXAMPLES = Path(__file__).parent.parent / "examples"
REQUIRED = {
    "rms_velocity_initial", "rms_velocity_final", "rms_change_percent", "min_distance",
    "final_distance", "coupled", "events", "gains",
}  # fmt: skip


@pytest.fixture(scope="module")
def fig9_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "fig9"
    result = CliRunner().invoke(app, ["run", str(EXAMPLES / "fig9.toml"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out


def test_run_writes_the_promised_files(fig9_run):
    assert sorted(p.name for p in fig9_run.iterdir()) == [
        ".tmem-output.json", "distance.png", "paths.png", "summary.json", "trajectory.nc", "velocity.png",
    ]  # fmt: skip
    manifest = json.loads((fig9_run / ".tmem-output.json").read_text())
    assert manifest["command"] == "run"
    assert manifest["files"] == ["distance.png", "paths.png", "summary.json", "trajectory.nc", "velocity.png"]
    for png in ("distance.png", "paths.png", "velocity.png"):
        assert (fig9_run / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_summary_has_the_promised_keys_and_values(fig9_run):
    s = json.loads((fig9_run / "summary.json").read_text())
    assert REQUIRED <= s.keys()
    assert s["coupled"] is True
    np.testing.assert_allclose(s["gains"], tmem.modal_gains(6.0, 25.0, 9.8, 12.0, 0.1, 0.55), rtol=1e-15)
    assert [e["kind"] for e in s["events"]] == ["couple", "command", "uncouple"]
    for e in s["events"]:
        assert set(e) >= {"time", "kind", "agents"} and e["agents"] == [0, 1]
    assert s["rms_change_percent"] == pytest.approx(100 * (s["rms_velocity_final"] / s["rms_velocity_initial"] - 1))


def test_dataset_matches_summary_and_carries_units_and_scenario(fig9_run):
    s = json.loads((fig9_run / "summary.json").read_text())
    with open_trajectory(fig9_run / "trajectory.nc") as ds:
        assert dict(ds.sizes) == {"time": 6001, "agent": 2, "pair": 1}
        for name in ("x", "V_x", "phi_x", "omega_x", "U_x", "active"):
            assert ds[name].dims == ("agent", "time")
        assert ds["F_en"].dims == ("pair", "time")
        assert ds["y"].dims == () and float(ds["y"]) == 0.0  # a 1-D run flies along x
        units = {name: ds[name].attrs["units"] for name in ("x", "V_x", "phi_x", "omega_x", "U_x", "distance")}
        assert units == {"x": "m", "V_x": "m s-1", "phi_x": "rad", "omega_x": "rad s-1", "U_x": "rad", "distance": "m"}
        assert ds["time"].attrs["units"] == "seconds since 1970-01-01 00:00:00"
        assert ds["time"].values[-1] == pytest.approx(60.0)
        assert ds["agent_name"].values.tolist() == ["agent1", "agent2"]
        rms = rms_velocity(components(ds, "V"))
        assert rms[0] == pytest.approx(s["rms_velocity_initial"], rel=1e-15)
        assert rms[-1] == pytest.approx(s["rms_velocity_final"], rel=1e-15)
        final = positions(ds)[-1, :, 0]
        np.testing.assert_allclose(abs(final[1] - final[0]), s["final_distance"], rtol=1e-12)
        np.testing.assert_allclose(ds["distance"].values[0, -1], s["final_distance"], rtol=1e-15)
        np.testing.assert_allclose(ds.attrs["gains"], s["gains"], rtol=1e-15)
        # The stored scenario is the one that ran.
        assert tmem.loads(ds.attrs["scenario"]) == tmem.load(EXAMPLES / "fig9.toml")
        # The flag is 1 exactly between the couple and uncouple events.
        coupled = ds["time"].values[ds["F_en"].values[0, :] == 1]
        assert coupled.min() == pytest.approx(s["couple_time"], abs=0.01)
        assert coupled.max() == pytest.approx(s["uncouple_time"], abs=0.01)


@pytest.mark.parametrize("scenario", ["fig9.toml", "swarm/ring8_loss.toml"])
def test_trajectory_file_reads_back_as_xarray_writes_it(scenario, tmp_path):
    """tmem writes trajectory.nc through h5netcdf directly; read back, it is what xarray's own writer gives."""
    from tmem.files.io import to_dataset, write_netcdf

    trajectory = tmem.simulate(tmem.load(EXAMPLES / scenario))
    to_dataset(trajectory).to_netcdf(tmp_path / "by_xarray.nc", engine="h5netcdf")
    write_netcdf(trajectory, tmp_path / "by_tmem.nc")
    with xr.open_dataset(tmp_path / "by_xarray.nc", engine="h5netcdf") as expected, \
            xr.open_dataset(tmp_path / "by_tmem.nc", engine="h5netcdf") as got:  # fmt: skip
        xr.testing.assert_identical(got, expected)
        # Both runs have x and y: the ring flies in 2-D, and a 1-D run along x (y = 0).
        assert set(got.coords) == {"time", "agent", "agent_name", "x", "y", "pair", "pair_i", "pair_j"}
        for name in list(expected.variables):
            assert got[name].dtype == expected[name].dtype, name
            assert got[name].encoding.get("dtype") == expected[name].encoding.get("dtype"), name
            assert np.isnan(got[name].encoding["_FillValue"]) if "_FillValue" in expected[name].encoding \
                else "_FillValue" not in got[name].encoding, name  # fmt: skip


def test_rerun_replaces_an_earlier_run(tmp_path):
    out = tmp_path / "o"
    runner = CliRunner()
    assert runner.invoke(app, ["run", str(EXAMPLES / "repulsion.toml"), "--out", str(out)]).exit_code == 0
    (out / "summary.json").write_text("{}")  # a file the earlier run wrote, changed: the user's now
    refused = runner.invoke(app, ["run", str(EXAMPLES / "repulsion.toml"), "--out", str(out)])
    assert refused.exit_code == 2 and "were changed since it wrote them (summary.json)" in refused.stderr
    assert (out / "summary.json").read_text() == "{}"
    (out / "summary.json").unlink()  # removed, as is another: nothing of the user's is left to lose
    (out / "velocity.png").unlink()
    assert runner.invoke(app, ["run", str(EXAMPLES / "repulsion.toml"), "--out", str(out)]).exit_code == 0
    assert json.loads((out / "summary.json").read_text())["function"] == "repulsion"
    assert (out / "velocity.png").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["o"]  # no temporary directory left behind


def test_paper_command_writes_the_runs_and_the_report(tmp_path):
    out = tmp_path / "paper"
    result = CliRunner().invoke(app, ["paper", "--out", str(out)])
    assert result.exit_code == 0, result.output
    further = ["fig7-energy", "fig7-sync", "fig9-energy", "fig9-sync"]
    assert sorted(p.name for p in out.iterdir()) == sorted([".tmem-output.json", "fig5", "fig7", "fig9", *further, "report.md"])
    report = (out / "report.md").read_text()
    for name in ("fig5", "fig7", "fig9"):
        s = json.loads((out / name / "summary.json").read_text())
        assert (out / name / "trajectory.nc").exists()
        if s["function"] != "attraction":
            # The report quotes our measured numbers, not numbers of its own.
            assert f"{s['rms_change_percent']:+.2f} %" in report
            assert f"F_en drops at {s['uncouple_time']:.2f} s" in report
    assert "≈ 5.6 %" in report and "≈ 0.2 %" in report
    for name in further:  # the further work's reruns, each quoted in its own row
        s = json.loads((out / name / "summary.json").read_text())
        (row,) = [line for line in report.splitlines() if line.startswith(f"| {name} |")]
        assert f"{s['rms_change_percent']:+.3f} %" in row
        released = [e for e in s["events"] if e["kind"] == "uncouple"][0]
        assert f"{released['time']:.2f} s, {released['rule']}" in row

