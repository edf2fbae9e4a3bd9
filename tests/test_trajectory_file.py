"""Every command that reads a run refuses, in one line, a ``trajectory.nc`` of an earlier tmem.

Before CF trajectories the file held the positions ``P`` and the other states over
``(time, agent, axis)``; no reader can use it now, and each says why instead of failing on a
missing variable.
"""

import json

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from tmem.cli.main import app

SCENARIO = 'name = "old"\n[space]\naxes = 2\n[interaction]\nradius = 20.0\n'


def earlier_run(directory):
    """A run directory as an earlier tmem wrote it: ``P``, ``V`` over (time, agent, axis), no ``x``."""
    directory.mkdir()
    over = ("time", "agent", "axis")
    values = np.zeros((4, 2, 2))
    data = {"P": (over, values), "V": (over, values), "active": (("time", "agent"), np.ones((4, 2), np.int8)),
            "F_en": (("time", "pair"), np.zeros((4, 1), np.int8)), "distance": (("time", "pair"), np.ones((4, 1)))}  # fmt: skip
    coords = {"time": 0.5 * np.arange(4), "agent": [0, 1], "axis": ["x", "y"], "pair": [0],
              "pair_i": ("pair", [0]), "pair_j": ("pair", [1])}  # fmt: skip
    attrs = {"source": "tmem 0.9", "scenario": SCENARIO}
    xr.Dataset(data, coords=coords, attrs=attrs).to_netcdf(directory / "trajectory.nc", engine="h5netcdf")
    (directory / "summary.json").write_text(json.dumps({"pairs": [{"min_distance": 1.0}], "min_distance": 1.0}))
    return directory


@pytest.mark.parametrize("command", [["plot"], ["view"], ["animate"], ["export", "--to", "csv"], ["export", "--to", "mcap"]])
def test_a_file_of_an_earlier_tmem_is_refused_in_one_line_and_nothing_is_written(tmp_path, command):
    run = earlier_run(tmp_path / "run")
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    result = CliRunner().invoke(app, [command[0], str(run), *command[1:]])
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1, result.stderr
    assert f"{command[0]}: {run / 'trajectory.nc'}: written by an earlier tmem" in result.stderr
    assert "run the scenario again" in result.stderr
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == before
