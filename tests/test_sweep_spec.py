"""Sweep files: how cases are expanded, and the one-line errors for bad files."""

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tmem.cli.main import app
from tmem.sweep import SweepError, load_sweep, loads_sweep
from tmem.sweep.spec import SCALAR_METRICS

BASE = """
name = "t"
base = "fig7"
"""


def sweep(text: str):
    return loads_sweep(BASE + text, source="t.toml")


def test_cases_are_explicit_times_grid_times_draws_with_the_same_draws_everywhere():
    s = sweep(
        """
cases = 4
seed = 7
[grid]
"interaction.function" = ["switching", "improved"]
"interaction.c_max" = [0.05, 0.1, 0.2]
[random]
"agents.0.velocity" = { uniform = [-5, -1] }
[[case]]
"interaction.eps" = 0.1
[[case]]
"interaction.eps" = 0.3
"""
    )
    cases = s.cases()
    assert s.n_cases == len(cases) == 2 * 2 * 3 * 4
    assert [c.index for c in cases] == list(range(len(cases)))
    # explicit case outermost, then the grid in file order, then the draws
    assert cases[0].changes["interaction.eps"] == 0.1 and cases[24].changes["interaction.eps"] == 0.3
    assert cases[0].changes["interaction.function"] == "switching" and cases[12].changes["interaction.function"] == "improved"
    assert [cases[k].changes["interaction.c_max"] for k in (0, 4, 8)] == [0.05, 0.1, 0.2]
    draws = [c.changes["agents.0.velocity"] for c in cases]
    assert all(-5 <= v <= -1 for v in draws)
    for setting in range(12):  # every setting sees the same four starts
        assert draws[4 * setting : 4 * setting + 4] == draws[:4]
    assert len(set(draws[:4])) == 4
    assert s.settings == ["interaction.function", "interaction.c_max", "interaction.eps"]


def test_draws_depend_on_the_seed_alone_and_keep_their_bounds():
    text = """
cases = 2000
seed = {seed}
[random]
"agents.0.velocity" = {{ uniform = [-5, -1] }}
"interaction.c_max" = {{ loguniform = [0.01, 1.0] }}
"interaction.function" = {{ choice = ["switching", "improved"] }}
"agents.1.velocity" = {{ normal = [3.0, 0.5] }}
"""
    a, b, c = sweep(text.format(seed=1)), sweep(text.format(seed=1)), sweep(text.format(seed=2))
    assert [x.changes for x in a.cases()] == [x.changes for x in b.cases()]
    assert [x.changes for x in a.cases()] != [x.changes for x in c.cases()]
    c_max = np.array([x.changes["interaction.c_max"] for x in a.cases()])
    assert c_max.min() >= 0.01 and c_max.max() <= 1.0
    # log-uniform: the decades 0.01-0.1 and 0.1-1 are equally likely
    assert abs(np.mean(c_max < 0.1) - 0.5) < 0.05
    assert {x.changes["interaction.function"] for x in a.cases()} == {"switching", "improved"}
    normal = np.array([x.changes["agents.1.velocity"] for x in a.cases()])
    assert abs(normal.mean() - 3.0) < 0.05 and abs(normal.std() - 0.5) < 0.05


def test_polar_draws_are_uniform_in_length_and_direction():
    """Checked against the draw's definition: the length and the angle of each vector, recovered with
    numpy's hypot and arctan2, fill their ranges uniformly (Kolmogorov-Smirnov against scipy's uniform)."""
    from scipy.stats import kstest

    swept = loads_sweep('name = "t"\nbase = "../encounter_plane.toml"\ncases = 4000\nseed = 3\n[random]\n'
                        '"agents.0.velocity" = { polar = [[1.0, 5.0], [150.0, 210.0]] }\n',
                        directory=Path(__file__).parent.parent / "examples" / "sweeps")  # fmt: skip
    v = np.array([case.changes["agents.0.velocity"] for case in swept.cases()])
    length = np.hypot(v[:, 0], v[:, 1])
    angle = np.degrees(np.arctan2(v[:, 1], v[:, 0])) % 360.0
    assert kstest(length, "uniform", args=(1.0, 4.0)).pvalue > 0.01
    assert kstest(angle, "uniform", args=(150.0, 60.0)).pvalue > 0.01
    assert 1.0 <= length.min() and length.max() <= 5.0


def test_nested_tables_mean_the_same_paths_as_quoted_keys():
    quoted = sweep('[grid]\n"interaction.c_max" = [0.05, 0.1]\n')
    nested = sweep("[grid]\ninteraction.c_max = [0.05, 0.1]\n")
    assert [c.changes for c in quoted.cases()] == [c.changes for c in nested.cases()]
    assert quoted.fingerprint == nested.fingerprint


def test_set_changes_the_base_and_fingerprint_ignores_batch_only():
    s = sweep('batch = 10\n[set]\n"interaction.c_max" = 0.2\n[grid]\n"interaction.eps" = [0.1]\n')
    assert s.base.interaction.c_max == 0.2
    assert s.parameters == ["interaction.eps"]
    assert s.fingerprint == sweep('[set]\n"interaction.c_max" = 0.2\n[grid]\n"interaction.eps" = [0.1]\n').fingerprint
    assert s.fingerprint != sweep('[set]\n"interaction.c_max" = 0.3\n[grid]\n"interaction.eps" = [0.1]\n').fingerprint


@pytest.mark.parametrize(
    "text, expected",
    [
        ('[grid]\n"interaction.c_max" = []\n', "grid.interaction.c_max: is empty"),
        ('cases = 3\n[random]\n"interaction.c_max" = { uniform = [0.2, 0.1] }\n', "random.interaction.c_max.uniform: low 0.2 > high 0.1"),
        ('[grid]\n"interaction.c_mx" = [0.1]\n', "interaction.c_mx: unknown parameter path"),
        ('[grid]\n"interaction.c_max" = [0.1, -1.0]\n', "interaction.c_max: must be greater than 0"),
        ('metrics = ["rms", "coupled"]\n', "metrics: unknown metric 'rms'"),
        ('[random]\n"interaction.c_max" = { uniform = [0.1, 0.2] }\n', "cases: is required"),
        ("cases = 5\n", "cases: counts random draws"),
        ('cases = 2\n[grid]\n"interaction.eps" = [0.1]\n[random]\n"interaction.eps" = { uniform = [0.1, 0.2] }\n', "random.interaction.eps: is also given in grid"),
        ('cases = 2\n[random]\n"interaction.eps" = { uniform = [0.1, 0.2], normal = [1, 1] }\n', "give exactly one of"),
        ('cases = 2\n[random]\n"interaction.eps" = { loguniform = [0.0, 0.2] }\n', "loguniform: low must be > 0"),
        ('cases = 0\n[random]\n"interaction.eps" = { uniform = [0.1, 0.2] }\n', "cases: must be greater than or equal to 1"),
        ("sedd = 3\n", "sedd: unknown key"),
        ('cases = 2\n[random]\n"interaction.eps" = { polar = [[2, 1], [0, 90]] }\n', "polar: the lengths must have 0 <= low <= high"),
        ('cases = 2\n[random]\n"interaction.eps" = { polar = [[1, 2], [90, 0]] }\n', "polar: the directions must have from <= to"),
        ('cases = 2\n[random]\n"interaction.eps" = { polar = [[1, 2]] }\n', "random.interaction.eps.polar"),
        ('[grid]\n"coupled" = [1.0]\n', "grid.coupled: is a column of the results"),
    ],
)
def test_bad_sweeps_are_refused_with_one_line_naming_the_key(text, expected):
    with pytest.raises(SweepError) as info:
        sweep(text)
    message = str(info.value)
    assert expected in message
    assert "\n" not in message and message.startswith("t.toml: ")


def test_a_base_that_is_neither_preset_nor_file_is_refused(tmp_path):
    with pytest.raises(SweepError, match="base: 'fig77' is neither a preset"):
        loads_sweep('base = "fig77"\n', source="t.toml")
    with pytest.raises(SweepError, match="no such file"):
        loads_sweep('base = "missing.toml"\n', source="t.toml", directory=tmp_path)


def test_default_metrics_are_the_scalar_ones():
    assert sweep("").spec.metrics == list(SCALAR_METRICS)


def test_the_command_refuses_a_bad_sweep_without_traceback_or_output(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(BASE + '[grid]\n"interaction.c_max" = []\n')
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["sweep", str(bad), "--out", str(out)])  # in-process: no real process needed
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit)  # refused, not raised
    assert "Traceback" not in result.stderr
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "grid.interaction.c_max: is empty" in lines[0]
    assert not out.exists()


def test_the_command_refuses_a_directory_of_another_sweep(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "sweep.json").write_text('{"fingerprint": "0000"}')
    (out / "results.parquet").write_bytes(b"keep me")
    good = tmp_path / "good.toml"
    good.write_text(BASE + '[grid]\n"interaction.c_max" = [0.1]\n"simulation.duration" = [30.0]\n')
    result = CliRunner().invoke(app, ["sweep", str(good), "--out", str(out)])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit)
    assert "holds the results of a different sweep" in result.stderr
    assert "Traceback" not in result.stderr
    assert (out / "results.parquet").read_bytes() == b"keep me"
    assert sorted(p.name for p in out.iterdir()) == ["results.parquet", "sweep.json"]


def test_example_sweeps_are_valid():
    paths = sorted((Path(__file__).parent.parent / "examples" / "sweeps").glob("*.toml"))
    assert len(paths) >= 3
    for path in paths:
        assert load_sweep(path).n_cases >= 1
