"""Bad input: one line naming the field and the reason, exit status 2, no traceback, no output."""

import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app

GOOD = tmem.preset("fig9").to_toml()


def edit(old: str, new: str) -> str:
    assert old in GOOD, old
    return GOOD.replace(old, new, 1)


def quadrotor(keys: str) -> str:
    """The good scenario on the quadrotor, with ``keys`` (TOML lines) in its ``[model]`` table."""
    return edit('[model]\nkind = "linear"\nkp = 6.0\nkd = 25.0\ng = 9.8', f'[model]\nkind = "quadrotor"\n{keys}')


def without_agent(text: str) -> str:
    head, _, tail = text.partition("[[agents]]")
    return head + tail.split("[[agents]]", 1)[1].join(["[[agents]]", ""]) if tail else text


CASES = {
    "d_t at reach": (edit("d_t = 35.0", "d_t = 40.0"), "interaction.d_t", "less than R + R_j"),
    "d_t beyond reach": (edit("d_t = 35.0", "d_t = 45.0"), "interaction.d_t", "less than R + R_j"),
    "radius zero": (edit("radius = 20.0", "radius = 0.0"), "interaction.radius", "must be greater than 0"),
    "radius negative": (edit("radius = 20.0", "radius = -1.0"), "interaction.radius", "must be greater than 0"),
    "dt zero": (edit("dt = 0.0001", "dt = 0.0"), "simulation.dt", "must be greater than or equal to"),
    "duration negative": (edit("duration = 60.0", "duration = -5.0"), "simulation.duration", "must be greater than 0"),
    "c_max zero": (edit("c_max = 0.1", "c_max = 0.0"), "interaction.c_max", "must be greater than 0"),
    "eps negative": (edit("eps = 0.2", "eps = -0.2"), "interaction.eps", "must be greater than 0"),
    "nan": (edit("kp = 6.0", "kp = nan"), "model.kp", "finite"),
    "inf": (edit("position = 50.0", "position = inf"), "agents[0].position", "finite"),
    "one agent": (without_agent(GOOD), "agents", "needs at least 2 agents, got 1"),
    "unknown function": (edit('function = "improved"', 'function = "magnet"'), "interaction.function", "'repulsion'"),
    "unknown action": (edit('action = "uncouple"', 'action = "explode"'), "commands[0].action", "'couple'"),
    "typo in key": (edit("c_max = 0.1", "cmax = 0.1"), "interaction.cmax", "unknown key"),
    "unknown table": (GOOD + "\n[weather]\nspeed = 3.0\n", "weather", "unknown key"),
    "command before start": (edit("time = 29.0", "time = -1.0"), "commands[0].time", "must be greater than or equal to 0"),
    "command after end": (edit("time = 29.0", "time = 61.0"), "commands[0].time", "later than duration"),
    "command names missing agent": (edit("pair = [0, 1]", "pair = [0, 2]"), "commands[0].pair", "outside 0..1"),
    "command names one agent twice": (edit("pair = [0, 1]", "pair = [1, 1]"), "commands[0].pair", "two different"),
    "unstable left roots": (edit("r_l = 12.0", "r_l = -1.0"), "controller.r_l", "stable"),
    "zero r_l": (edit("r_l = 12.0", "r_l = 0.0"), "controller.r_l", "stable"),
    "missing position": (edit("position = 0.0", "velocity_x = 1.0"), "agents[1].position", "is required"),
    "boolean for a number": (edit("kp = 6.0", "kp = true"), "model.kp", "must be a valid number"),
    "string for a number": (edit("kp = 6.0", 'kp = "6.0"'), "model.kp", "must be a valid number"),
    "boolean for an index": (edit("pair = [0, 1]", "pair = [false, true]"), "commands[0].pair", "valid integer"),
    "huge number": (edit("kp = 6.0", "kp = 1e308"), "model.kp", "less than or equal to"),
    "tiny dt": (edit("dt = 0.0001", "dt = 1e-300"), "simulation.dt", "greater than or equal to"),
    "fractional steps": (edit("dt = 0.0001", "dt = 0.7"), "simulation.duration", "whole number of steps"),
    "agents at one point": (edit("position = 0.0", "position = 50.0"), "agents[1].position", "place of agents[0]"),
    "records too big": (edit("record_every = 100", "record_every = 1").replace("duration = 60.0", "duration = 1e7"),
                        "simulation.record_every", "GiB"),
    "pair of three": (edit("pair = [0, 1]", "pair = [0, 1, 1]"), "commands[0].pair", "at most 2"),
    "bearing on one axis": (GOOD + '\n[formation]\nkind = "edges"\nedges = [[0, 1]]\nbearing = true\n',
                            "formation.bearing", "2 or 3 axes"),
    "table as a number": (GOOD.replace('[model]\nkind = "linear"\nkp = 6.0\nkd = 25.0\ng = 9.8', "model = 3"), "model", "must be a table"),
    "unknown model kind": (edit('kind = "linear"', 'kind = "nonsense"'), "model.kind", "must be one of 'linear', 'quadrotor', 'ground_robot', got 'nonsense'"),
    "model kind not a name": (edit('kind = "linear"', "kind = 2"), "model.kind", "must be one of 'linear', 'quadrotor', 'ground_robot', got 2"),
    "typo in a model key": (edit("kd = 25.0", "kdd = 25.0"), "model.kdd", "unknown key"),
    "wrong type": (edit("kd = 25.0", 'kd = "fast"'), "model.kd", "number"),
    "toml syntax": (edit("kd = 25.0", "kd = = 25.0"), "TOML syntax error", "line 6"),
    "quadrotor in 3-D": (quadrotor("").replace("axes = 1", "axes = 3").replace("position = 50.0", "position = [50.0, 0.0, 0.0]").replace("position = 0.0", "position = [0.0, 0.0, 0.0]").replace("velocity = -1.5", "velocity = [-1.5, 0.0, 0.0]").replace("velocity = 3.0", "velocity = [3.0, 0.0, 0.0]"),
                         "space.axes", "at most 2 axes"),
    "quadrotor cannot lift": (quadrotor("rotor_speed_max = 1800.0"), "model.rotor_speed_max", "hover speed"),
    "quadrotor inner loop too slow": (quadrotor("inner_period = 0.05"), "model.inner_period", "too long for the rate loop"),
    "quadrotor drag negative": (quadrotor("rotor_drag = -1.0"), "model.rotor_drag", "greater than or equal to 0"),
    "quadrotor typo": (quadrotor("mas = 0.03"), "model.mas", "unknown key"),
    "quadrotor drag left to the acceleration loop": (quadrotor("drag_feedforward = false"), "model.drag_feedforward", "tilt loop's"),
    "quadrotor unknown inner loop": (quadrotor('inner_loop = "rate"'), "model.inner_loop", "acceleration"),
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


SWARM = """
[space]
axes = 2
[interaction]
function = "improved"
[formation]
kind = "hex"
n = 7
"""

SWARM_CASES = {
    "formation with repulsion": (SWARM.replace('"improved"', '"repulsion"'), "formation", "'switching' (10) or"),
    "formation with the law off": (SWARM.replace('"improved"', '"none"'), "formation", "'switching' (10) or"),
    "formation without n": (SWARM.replace("n = 7", ""), "formation.n", "is required"),
    "ring of two": (SWARM.replace('"hex"', '"ring"').replace("n = 7", "n = 2"), "formation.n", "at least 3"),
    "planar formation on one axis": (SWARM.replace("axes = 2", "axes = 1"), "formation.kind", "2 or 3 axes"),
    "formation d_t beyond reach": (SWARM + "d_t = 41.0\n", "formation.d_t", "less than R + R_j"),
    "velocity of the wrong size": (SWARM + "velocity = [1.0, 2.0, 3.0]\n", "formation.velocity", "needs 2 values"),
    "agents and a formation": (SWARM + "[[agents]]\nposition = [0.0, 0.0]\n", "formation", "give the agents once"),
    "edge to a missing agent": (
        SWARM.replace('kind = "hex"\nn = 7', 'kind = "edges"\nedges = [[0, 5]]')
        + "[[agents]]\nposition = [0.0, 0.0]\n[[agents]]\nposition = [30.0, 0.0]\n",
        "formation.edges[0]", "two different agents in 0..1",
    ),
    "repeated edge": (
        SWARM.replace('kind = "hex"\nn = 7', 'kind = "edges"\nedges = [[0, 1], [1, 0]]')
        + "[[agents]]\nposition = [0.0, 0.0]\n[[agents]]\nposition = [30.0, 0.0]\n",
        "formation.edges[1]", "repeats the pair",
    ),
    "command on a non-pair": (SWARM + '[[commands]]\ntime = 1.0\naction = "uncouple"\npair = [1, 4]\n',
                              "commands[0].pair", "not a formation pair"),
    "remove an agent twice": (
        SWARM + '[[commands]]\ntime = 1.0\naction = "remove"\nagent = 2\n'
        '[[commands]]\ntime = 2.0\naction = "remove"\nagent = 2\n',
        "commands[1].agent", "not flying",
    ),
    "add a flying agent": (SWARM + '[[commands]]\ntime = 1.0\naction = "add"\nagent = 2\n', "commands[0].agent",
                           "already flying"),
    "remove without agent": (SWARM + '[[commands]]\ntime = 1.0\naction = "remove"\n', "commands[0].agent",
                             "is required"),
    "record an agent out of range": (SWARM + "[simulation]\nrecord_agents = [0, 9]\n",
                                     "simulation.record_agents[1]", "outside 0..6"),
    "periodic without a box": ("[space]\naxes = 2\nperiodic = true\n[swarm]\nn = 10\n", "space.box", "is required"),
    "swarm without a region": ("[space]\naxes = 2\n[swarm]\nn = 10\n", "swarm.region", "is required"),
    "2-D agent given one number": ("[space]\naxes = 2\n[[agents]]\nposition = 1.0\n[[agents]]\nposition = [5.0, 0.0]\n",
                                   "agents[0].position", "list of 2 values"),
    "no agents at all": ("[space]\naxes = 2\n", "agents", "no agents"),
    "every pair in a big swarm": ("[space]\naxes = 2\nperiodic = true\nbox = [1e4, 1e4]\n"
                                  '[interaction]\nfunction = "improved"\n[swarm]\nn = 3000\n',
                                  "interaction.function", "give a [formation]"),
}


@pytest.mark.parametrize("case", SWARM_CASES, ids=list(SWARM_CASES))
def test_bad_swarm_scenario_is_refused_with_one_line(case, tmp_path, runner):
    text, field, reason = SWARM_CASES[case]
    scenario = tmp_path / "bad.toml"
    scenario.write_text(text)
    result = runner.invoke(app, ["run", str(scenario), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and field in lines[0] and reason in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_missing_file(tmp_path, runner):
    result = runner.invoke(app, ["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "nope.toml: no such file" in result.stderr
    assert not (tmp_path / "out").exists()


def test_unreadable_file(tmp_path, runner, monkeypatch):
    scenario = tmp_path / "secret.toml"
    scenario.write_text(GOOD)

    def refuse(self, *args, **kwargs):  # root reads any file, so refuse as a file system would
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(Path, "read_text", refuse)
    result = runner.invoke(app, ["run", str(scenario), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "cannot be read" in result.stderr and "Permission denied" in result.stderr


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


@pytest.mark.parametrize("marker", [None, "summary.json", "report.md"])
def test_output_directory_with_other_files_is_not_touched(tmp_path, runner, marker):
    """Even a directory that looks like an earlier run keeps files tmem did not write."""
    scenario = tmp_path / "ok.toml"
    scenario.write_text(GOOD)
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("precious")
    if marker:
        (out / marker).write_text("{}")
    result = runner.invoke(app, ["run", str(scenario), "--out", str(out)])
    assert result.exit_code == 2
    assert "holds files that are not marked as a tmem output (chapter1.tex" in result.stderr
    assert (out / "chapter1.tex").read_text() == "precious"


def _ok_scenario(tmp_path):
    scenario = tmp_path / "ok.toml"
    scenario.write_text(GOOD)
    return scenario


def test_output_into_the_current_directory_is_refused(tmp_path, runner, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["run", str(_ok_scenario(tmp_path)), "--out", "."])
    assert result.exit_code == 2 and "current directory" in result.stderr


def test_output_below_a_file_is_refused(tmp_path, runner):
    (tmp_path / "afile").write_text("x")
    result = runner.invoke(app, ["run", str(_ok_scenario(tmp_path)), "--out", str(tmp_path / "afile" / "sub")])
    assert result.exit_code == 2 and "is a file" in result.stderr


def test_output_symlink_is_refused(tmp_path, runner):
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    result = runner.invoke(app, ["run", str(_ok_scenario(tmp_path)), "--out", str(tmp_path / "link")])
    assert result.exit_code == 2 and "symbolic link" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "ok.toml", "real"]


def test_unwritable_output_gives_one_line_and_leaves_nothing(tmp_path, runner, monkeypatch):
    def full(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("tmem.files.outputs.replace.make_partial", full)
    out = tmp_path / "new" / "deeper" / "out"
    result = runner.invoke(app, ["run", str(_ok_scenario(tmp_path)), "--out", str(out)])
    assert result.exit_code == 2 and "No space left" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.toml"]  # the parents made for it are gone


def test_agents_at_rest_run_and_report_no_rms_change(tmp_path, runner):
    scenario = tmp_path / "rest.toml"
    scenario.write_text(GOOD.replace("velocity = -1.5", "velocity = 0.0").replace("velocity = 3.0", "velocity = 0.0"))
    result = runner.invoke(app, ["run", str(scenario), "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    import json

    assert json.loads((tmp_path / "o" / "summary.json").read_text())["rms_change_percent"] is None


def test_console_script_exits_2_without_traceback(tmp_path):
    """The installed entry point, not just the Typer app."""
    scenario = tmp_path / "bad.toml"
    scenario.write_text(CASES["d_t beyond reach"][0])
    proc = subprocess.run(
        [sys.executable, "-c", "from tmem.cli.main import main; main()", "run", str(scenario), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "interaction.d_t" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not Path(tmp_path / "o").exists()


EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("sweep", sorted((EXAMPLES / "sweeps").glob("*.toml")), ids=lambda p: p.name)
def test_a_sweep_file_given_to_run_is_named_a_sweep_file(sweep, tmp_path, runner):
    """One line that says what it is and what to use, not a line per sweep key."""
    result = runner.invoke(app, ["run", str(sweep), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "is a sweep file" in lines[0] and "tmem sweep" in lines[0], lines
    assert "unknown key" not in lines[0] and not (tmp_path / "out").exists()


PER_AXIS = {
    "2-D position on one axis": (edit("position = 0.0", "position = [0.0, 1.0]"), "agents[1].position",
                                 "needs 1 value, one per axis (space.axes = 1), got 2; for a 2-D run set axes = 2 in [space]"),
    "3-D velocity on one axis": (edit("velocity = 3.0", "velocity = [3.0, 0.0, 0.0]"), "agents[1].velocity",
                                 "needs 1 value, one per axis (space.axes = 1), got 3; for a 3-D run set axes = 3 in [space]"),
    "2-D box in 3-D": (SWARM.replace("axes = 2", "axes = 3\nbox = [500.0, 500.0]"), "space.box",
                       "needs 3 values, one per axis (space.axes = 3), got 2; for a 2-D run set axes = 2 in [space]"),
    "four values": (SWARM + "velocity = [1.0, 2.0, 3.0, 4.0]\n", "formation.velocity",
                    "needs 2 values, one per axis (space.axes = 2), got 4"),
}


@pytest.mark.parametrize("case", PER_AXIS, ids=list(PER_AXIS))
def test_a_list_of_the_wrong_size_says_how_many_and_suggests_space_axes(case, tmp_path, runner):
    text, field, reason = PER_AXIS[case]
    (tmp_path / "bad.toml").write_text(text)
    result = runner.invoke(app, ["run", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].endswith(f"{field}: {reason}"), lines


@pytest.mark.parametrize("when", [0.0, 0.5])
def test_every_agent_removed_writes_null_not_infinity(when, tmp_path, runner):
    """Every agent removed (at the start, or later): summary.json stays valid JSON, with null where no agent flies."""
    import json

    short = GOOD.replace("duration = 60.0", "duration = 1.0").replace("dt = 0.0001", "dt = 0.001")
    head = short.split("[[commands]]")[0]
    removals = "".join(f'[[commands]]\ntime = {when}\naction = "remove"\nagent = {a}\n' for a in (0, 1))
    (tmp_path / "gone.toml").write_text(head + removals)
    result = runner.invoke(app, ["run", str(tmp_path / "gone.toml"), "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    text = (tmp_path / "o" / "summary.json").read_text()
    s = json.loads(text, parse_constant=lambda name: pytest.fail(f"{name} in summary.json"))
    assert s["rms_velocity_final"] is None and s["rms_change_percent"] is None and s["final_distance"] is None
    assert (s["pairs"][0]["min_distance"] is None) == (when == 0.0)  # never measured when removed at once
