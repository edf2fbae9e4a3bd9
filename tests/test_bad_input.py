"""Bad input: one line naming the field and the reason, exit status 2, no traceback, no output."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli import app

GOOD = tmem.preset("fig9").to_toml()


def edit(old: str, new: str) -> str:
    assert old in GOOD, old
    return GOOD.replace(old, new, 1)


def without_agent(text: str) -> str:
    head, _, tail = text.partition("[[agents]]")
    return head + tail.split("[[agents]]", 1)[1].join(["[[agents]]", ""]) if tail else text


CASES = {
    "d_t at reach": (edit("d_t = 35.0", "d_t = 40.0"), "interaction.d_t", "less than R + R_j"),
    "d_t beyond reach": (edit("d_t = 35.0", "d_t = 45.0"), "interaction.d_t", "less than R + R_j"),
    "radius zero": (edit("radius = 20.0", "radius = 0.0"), "interaction.radius", "must be greater than 0"),
    "radius negative": (edit("radius = 20.0", "radius = -1.0"), "interaction.radius", "must be greater than 0"),
    "dt zero": (edit("dt = 0.0001", "dt = 0.0"), "simulation.dt", "must be greater than 0"),
    "duration negative": (edit("duration = 60.0", "duration = -5.0"), "simulation.duration", "must be greater than 0"),
    "c_max zero": (edit("c_max = 0.1", "c_max = 0.0"), "interaction.c_max", "must be greater than 0"),
    "eps negative": (edit("eps = 0.2", "eps = -0.2"), "interaction.eps", "must be greater than 0"),
    "nan": (edit("kp = 6.0", "kp = nan"), "model.kp", "finite"),
    "inf": (edit("position = 50.0", "position = inf"), "agents[0].position", "finite"),
    "one agent": (without_agent(GOOD), "agents", "needs at least 2 agents, got 1"),
    "unknown function": (edit('function = "improved"', 'function = "magnet"'), "interaction.function", "'repulsion'"),
    "unknown action": (edit('action = "uncouple"', 'action = "explode"'), "commands[0].action", "'couple'"),
    "typo in key": (edit("c_max = 0.1", "cmax = 0.1"), "interaction.cmax", "unknown key"),
    "unknown table": (GOOD + "\n[wind]\nspeed = 3.0\n", "wind", "unknown key"),
    "command before start": (edit("time = 29.0", "time = -1.0"), "commands[0].time", "must be greater than or equal to 0"),
    "command after end": (edit("time = 29.0", "time = 61.0"), "commands[0].time", "later than duration"),
    "command names missing agent": (edit("pair = [0, 1]", "pair = [0, 2]"), "commands[0].pair", "outside 0..1"),
    "command names one agent twice": (edit("pair = [0, 1]", "pair = [1, 1]"), "commands[0].pair", "two different"),
    "unstable left roots": (edit("r_l = 12.0", "r_l = -1.0"), "controller.r_l", "stable"),
    "zero r_l": (edit("r_l = 12.0", "r_l = 0.0"), "controller.r_l", "stable"),
    "missing position": (edit("position = 0.0", "velocity_x = 1.0"), "agents[1]", ""),
    "wrong type": (edit("kd = 25.0", 'kd = "fast"'), "model.kd", "number"),
    "toml syntax": (edit("kd = 25.0", "kd = = 25.0"), "TOML syntax error", "line 5"),
}


@pytest.fixture
def runner():
    return CliRunner()


@pytest.mark.parametrize("case", CASES, ids=list(CASES))
def test_bad_scenario_is_refused_with_one_line(case, tmp_path, runner):
    text, field, reason = CASES[case]
    scenario = tmp_path / "bad.toml"
    scenario.write_text(text)
    out = tmp_path / "out"
    result = runner.invoke(app, ["run", str(scenario), "--out", str(out)])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert field in lines[0] and reason in lines[0], lines[0]
    assert "Traceback" not in result.output
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]  # nothing half-written beside it


def test_missing_file(tmp_path, runner):
    result = runner.invoke(app, ["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "nope.toml: no such file" in result.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.skipif(os.geteuid() == 0, reason="root can read any file")
def test_unreadable_file(tmp_path, runner):
    scenario = tmp_path / "secret.toml"
    scenario.write_text(GOOD)
    scenario.chmod(0)
    result = runner.invoke(app, ["run", str(scenario), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "cannot be read" in result.stderr


def test_directory_instead_of_file(tmp_path, runner):
    result = runner.invoke(app, ["run", str(tmp_path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "is a directory" in result.stderr


def test_not_utf8(tmp_path, runner):
    scenario = tmp_path / "latin1.toml"
    scenario.write_bytes(b'name = "caf\xe9"\n')
    result = runner.invoke(app, ["run", str(scenario), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "cannot be read" in result.stderr


def test_output_directory_with_other_files_is_not_touched(tmp_path, runner):
    scenario = tmp_path / "ok.toml"
    scenario.write_text(GOOD)
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("precious")
    result = runner.invoke(app, ["run", str(scenario), "--out", str(out)])
    assert result.exit_code == 2
    assert "not empty" in result.stderr
    assert [p.name for p in out.iterdir()] == ["chapter1.tex"]


def test_console_script_exits_2_without_traceback(tmp_path):
    """The installed entry point, not just the Typer app."""
    scenario = tmp_path / "bad.toml"
    scenario.write_text(CASES["d_t beyond reach"][0])
    proc = subprocess.run(
        [sys.executable, "-c", "from tmem.cli import main; main()", "run", str(scenario), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "interaction.d_t" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not Path(tmp_path / "o").exists()
