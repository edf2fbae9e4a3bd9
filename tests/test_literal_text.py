"""What a user typed is printed and drawn as typed: rich markup and mathtext in names and paths are text."""

import json
import warnings

import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app

#: fig9 shortened to 2 s at dt = 1 ms, the command moved to 1 s: a run of a moment.
SHORT = (
    tmem.preset("fig9").to_toml()
    .replace("duration = 60.0", "duration = 2.0").replace("dt = 0.0001", "dt = 0.001").replace("time = 29.0", "time = 1.0")
)  # fmt: skip
NAMES = ["[/bold] oops", "d[/x]", "[bold]y", "[red]x[/red]", "$x^$", "$\\frac{", "a $b$ c", "50% [link=x]y", "日本語", "🚀 swarm"]


def _scenario(tmp_path, name: str):
    assert 'name = "fig9"' in SHORT
    path = tmp_path / "s.toml"
    path.write_text(SHORT.replace('name = "fig9"', f"name = {json.dumps(name, ensure_ascii=False)}"))
    return path


@pytest.mark.parametrize("name", NAMES)
def test_a_name_is_printed_and_plotted_as_written(tmp_path, name):
    out = tmp_path / "out"
    wide = {"COLUMNS": "200"}  # so that the table does not wrap the name in its cell
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = CliRunner().invoke(app, ["run", str(_scenario(tmp_path, name)), "--out", str(out)], env=wide)
    assert result.exit_code == 0, result.output
    assert not [w for w in caught if "missing from font" in str(w.message)]  # a box per glyph, not a warning
    assert f" {name} " in result.stdout  # in the table, literally
    assert json.loads((out / "summary.json").read_text())["scenario"] == name
    assert {"velocity.png", "distance.png"} <= {p.name for p in out.iterdir()}


@pytest.mark.parametrize("folder", ["[bold]y", "d[/x]", "[/bold] oops", "$x^$"])
def test_an_output_path_is_printed_as_written(tmp_path, folder, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["run", str(_scenario(tmp_path, "plain")), "--out", folder])
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[-1] == f"written to {folder}/"
    assert (tmp_path / folder / "summary.json").is_file()


def test_a_long_output_path_is_printed_on_one_line(tmp_path):
    """Rich would wrap it at the terminal's width, and the printed path would be wrong."""
    out = tmp_path / ("deep-" * 30) / "out"
    result = CliRunner().invoke(app, ["run", str(_scenario(tmp_path, "plain")), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[-1] == f"written to {out}/"
