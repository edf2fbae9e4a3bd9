"""trajectory.nc follows CF's trajectories: the IOOS compliance checker finds no error in a 1-D, a 2-D
and a 3-D run, CF's time decodes as the seconds from the start, and the file holds the run's numbers
exactly, laid out per agent over (agent, time)."""

import json
from pathlib import Path

import h5netcdf
import numpy as np
import pytest

import tmem
from tmem.files.io import write_netcdf
from tmem.scenario import with_changes
from tmem.files.trajectory_file import components, open_trajectory, positions, run_axes

#: Loading the checker's plugins warns of one (not used here) that is to go.
pytestmark = pytest.mark.filterwarnings("ignore:The ioos_sos checker is deprecated:DeprecationWarning")

EXAMPLES = Path(__file__).parent.parent / "examples"
#: The CF version the file claims and the checker checks against.
CF = "cf:1.11"

PLANE = """
name = "plane"
[space]
axes = 2
[interaction]
function = "improved"
[formation]
kind = "triangle"
velocity = [3.0, 0.0]
jitter = 1.0
seed = 1
[simulation]
dt = 0.001
duration = 5.0
record_every = 10
record_agents = [2, 0, 1]
"""


def _scenarios() -> dict:
    """A 1-D (the paper's Fig. 9), a 2-D (a triangle, its agents recorded out of order) and a 3-D run (a
    gas); and the hex on the quadrotor, whose body state adds a variable per component."""
    gas = with_changes(tmem.load(EXAMPLES / "swarm" / "gas3d.toml"), {"simulation.duration": 1.0, "swarm.n": 12})
    quadrotor = with_changes(tmem.load(EXAMPLES / "vehicles" / "hex19.toml"), {"simulation.duration": 1.0})
    return {1: tmem.load(EXAMPLES / "fig9.toml"), 2: tmem.loads(PLANE), 3: gas, "quadrotor": quadrotor}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Each run's trajectory and its file."""
    folder = tmp_path_factory.mktemp("cf")
    out = {}
    for axes, scenario in _scenarios().items():
        trajectory = tmem.simulate(scenario)
        write_netcdf(trajectory, folder / f"run{axes}d.nc")
        out[axes] = (trajectory, folder / f"run{axes}d.nc")
    return out


def _checked(path: Path, tmp_path: Path) -> dict:
    """The IOOS compliance checker's JSON report of ``path`` against CF 1.11 (it reads the file with netCDF4)."""
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    report = tmp_path / "report.json"
    _, crashed = ComplianceChecker.run_checker(str(path), [CF], 0, "normal", output_filename=str(report), output_format="json")
    assert not crashed, crashed  # a check that raised checked nothing
    return json.loads(report.read_text())[CF]


@pytest.mark.parametrize("axes", [1, 2, 3, "quadrotor"])
def test_the_cf_checker_finds_no_error(runs, axes, tmp_path):
    report = _checked(runs[axes][1], tmp_path)
    errors = [f"{r['name']}: {m}" for r in report["high_priorities"] for m in r["msgs"]]
    assert report["high_count"] == 0 and not errors, errors
    assert report["scored_points"] > 0.9 * report["possible_points"]  # it did check


def test_the_file_declares_cf_trajectories(runs):
    with open_trajectory(runs[2][1]) as ds:
        assert ds.attrs["Conventions"] == "CF-1.11" and ds.attrs["featureType"] == "trajectory"
        assert [n for n in ds.variables if ds[n].attrs.get("cf_role") == "trajectory_id"] == ["agent_name"]
        assert ds["agent_name"].values.tolist() == ["agent1", "agent2", "agent3"]
        assert {ds[a].attrs["axis"] for a in ("x", "y")} == {"X", "Y"} and ds["time"].attrs["axis"] == "T"
    with h5netcdf.File(runs[2][1], "r") as f:  # the attributes as any CF reader sees them
        for name in ("V_x", "phi_y", "U_x", "active"):
            assert set(f.variables[name].attrs["coordinates"].split()) >= {"x", "y", "agent_name"}
            assert f.variables[name].attrs["grid_mapping"] == "crs"
        assert "_FillValue" not in f.variables["time"].attrs  # CF: coordinate variables have none
        assert f.variables["crs"].attrs["grid_mapping_name"] == "orthographic"
    with open_trajectory(runs[3][1]) as ds:
        assert ds["z"].attrs["positive"] == "up" and ds["z"].attrs["axis"] == "Z"


def test_cf_time_decodes_to_seconds_from_the_start(runs):
    """xarray's CF decoding (an independent reading of the units) puts record k at 1970-01-01 + t_k."""
    import xarray as xr

    trajectory, path = runs[2]
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        seconds = (ds["time"].values - np.datetime64("1970-01-01T00:00:00")) / np.timedelta64(1, "s")
    np.testing.assert_allclose(seconds, trajectory.time, rtol=0, atol=2e-9)  # xarray keeps whole nanoseconds


@pytest.mark.parametrize("axes", [1, 2, 3])
def test_the_file_holds_the_runs_numbers(runs, axes):
    """Every per-agent and per-pair record reads back bit for bit, the agents in index order."""
    trajectory, path = runs[axes]
    order = np.argsort(trajectory.agents)
    state = trajectory.state[:, order]
    with open_trajectory(path) as ds:
        assert run_axes(ds) == ("x", "y", "z")[:axes]
        assert ds["agent"].values.tolist() == sorted(trajectory.agents.tolist())
        np.testing.assert_array_equal(ds["time"].values, trajectory.time)
        np.testing.assert_array_equal(positions(ds), state[..., 0])
        for m, name in enumerate(("V", "phi", "omega"), start=1):
            np.testing.assert_array_equal(components(ds, name), state[..., m])
        np.testing.assert_array_equal(components(ds, "U"), trajectory.control[:, order])
        np.testing.assert_array_equal(ds["active"].values.T, trajectory.active[:, order])
        np.testing.assert_array_equal(ds["F_en"].values.T, trajectory.flag)
        np.testing.assert_array_equal(ds["distance"].values.T, trajectory.pair_distance)
        if axes == 1:
            assert float(ds["y"]) == 0.0 and ds["y"].dims == ()


def test_the_grid_mapping_puts_x_east_and_y_north_in_metres(runs):
    """pyproj reads the CF grid mapping independently: 1 km along x is 1 km east of the placeholder origin."""
    from pyproj import CRS, Geod, Transformer

    with h5netcdf.File(runs[2][1], "r") as f:
        crs = CRS.from_cf(dict(f.variables["crs"].attrs))
    to_degrees = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
    (lon_x, lon_y), (lat_x, lat_y) = to_degrees.transform([1000.0, 0.0], [0.0, 1000.0])
    assert lon_x > 0.0 and lat_x == pytest.approx(0.0, abs=1e-9)  # x: east
    assert lat_y > 0.0 and lon_y == pytest.approx(0.0, abs=1e-9)  # y: north
    geod = Geod(ellps="WGS84")
    assert geod.inv(0.0, 0.0, lon_x, lat_x)[2] == pytest.approx(1000.0, rel=1e-6)
    assert geod.inv(0.0, 0.0, lon_y, lat_y)[2] == pytest.approx(1000.0, rel=1e-6)
