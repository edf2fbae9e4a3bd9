"""agents_from: a scenario's agents from a Crazyswarm2 crazyflies.yaml (its robots: NAME: {enabled, uri,
initial_position: [x, y, z], type} layout), and the one-line refusals of a file that does not fit."""

from pathlib import Path

import pytest
import yaml

import tmem
from tmem.scenario import ScenarioError

#: As Crazyswarm2 lays out crazyflie/config/crazyflies.yaml: robots by name, robot types, settings for all.
CRAZYFLIES = """\
# named list of all robots
robots:
  cf231:
    enabled: true
    uri: radio://0/80/2M/E7E7E7E7E7
    initial_position: [0.0, 0.0, 0.0]
    type: cf21  # see robot_types
  cf5:
    enabled: false
    uri: radio://0/80/2M/E7E7E7E705
    initial_position: [0.0, -0.5, 0.0]
    type: cf21
  cf6:
    enabled: true
    uri: radio://0/80/2M/E7E7E7E706
    initial_position: [30.0, 5, 0.0]
    type: cf21
  cf7:
    enabled: true
    uri: radio://0/80/2M/E7E7E7E707
    initial_position: [-12.5, 40.0, 0.0]
    type: cf21
robot_types:
  cf21:
    motion_capture:
      enabled: true
      marker: default_single_marker
      dynamics: default
    big_quad: false
    battery:
      voltage_warning: 3.8  # V
      voltage_critical: 3.7 # V
all:
  firmware_logging:
    enabled: false
  firmware_params:
    commander:
      enHighLevel: 1
  broadcasts:
    num_repeats: 15
    delay_between_repeats_ms: 1
"""

SCENARIO = """\
name = "lab"
agents_from = "{yaml}"
[space]
axes = {axes}
[interaction]
function = "repulsion"
[simulation]
dt = 0.001
duration = 1.0
"""


def _scenario(folder: Path, text: str = CRAZYFLIES, axes: int = 2, yaml_name: str = "crazyflies.yaml") -> Path:
    (folder / "config").mkdir(exist_ok=True)
    (folder / "config" / "crazyflies.yaml").write_text(text)
    path = folder / "lab.toml"
    path.write_text(SCENARIO.format(yaml=yaml_name if "/" in yaml_name else f"config/{yaml_name}", axes=axes))
    return path


def test_enabled_robots_become_named_agents_at_their_places(tmp_path):
    scenario = tmem.load(_scenario(tmp_path, axes=3))
    robots = yaml.safe_load(CRAZYFLIES)["robots"]  # the file read by an independent parser
    enabled = [name for name, robot in robots.items() if robot["enabled"]]
    assert [a.name for a in scenario.agents] == enabled == ["cf231", "cf6", "cf7"]
    assert [a.position for a in scenario.agents] == [robots[n]["initial_position"] for n in enabled]
    assert all(a.velocity == 0.0 and a.tilt == 0.0 and a.active for a in scenario.agents)


def test_a_planar_run_keeps_x_and_y_and_the_path_is_the_scenario_files(tmp_path, monkeypatch):
    path = _scenario(tmp_path, axes=2)
    monkeypatch.chdir(tmp_path / "config")  # elsewhere than the scenario: the path is still the file's
    scenario = tmem.load(path)
    assert [a.position for a in scenario.agents] == [[0.0, 0.0], [30.0, 5.0], [-12.5, 40.0]]


def test_the_stored_scenario_lists_the_agents_and_loads_without_the_yaml(tmp_path):
    path = _scenario(tmp_path, axes=2)
    scenario = tmem.load(path)
    text = scenario.to_toml()
    assert "agents_from" not in text and 'name = "cf6"' in text
    (tmp_path / "config" / "crazyflies.yaml").unlink()
    assert tmem.loads(text) == scenario


def test_the_robots_names_name_the_trajectories(tmp_path):
    from tmem.files.io import write_netcdf
    from tmem.files.trajectory_file import open_trajectory, positions

    trajectory = tmem.simulate(tmem.load(_scenario(tmp_path, axes=2)))
    write_netcdf(trajectory, tmp_path / "trajectory.nc")
    with open_trajectory(tmp_path / "trajectory.nc") as ds:
        assert ds["agent_name"].values.tolist() == ["cf231", "cf6", "cf7"]
        assert positions(ds)[0].tolist() == [[0.0, 0.0], [30.0, 5.0], [-12.5, 40.0]]


BAD = [
    ("robots:\n  cf1: {enabled: true, initial_position: [0, 0, 0]\n", 2,
     "agents_from: {yaml}: YAML syntax error (line 3, column 1)"),
    ("robot:\n  cf1: {enabled: true}\n", 2, "agents_from: {yaml}: has no robots table"),
    ("robots: [cf1, cf2]\n", 2, "agents_from: {yaml}: has no robots table"),
    ("robots:\n  cf1: {enabled: yes please, initial_position: [0, 0, 0]}\n", 2,
     "agents_from: {yaml}: robots.cf1.enabled: must be true or false, got 'yes please'"),
    ("robots:\n  cf1: {enabled: true, initial_position: [0, 0]}\n", 3,
     "agents_from: {yaml}: robots.cf1.initial_position: must be 3 finite numbers [x, y, z] (m), got [0, 0]"),
    ("robots:\n  cf1: {enabled: true, initial_position: [0, .nan, 0]}\n", 3,
     "agents_from: {yaml}: robots.cf1.initial_position: must be 3 finite numbers"),
    ("robots:\n  cf1: {enabled: true, initial_position: [0, 0, 0]}\n  cf2: {enabled: true, initial_position: [30, 0, 0.5]}\n",
     2, "agents_from: {yaml}: robots.cf2.initial_position: z = 0.5 differs from robots.cf1's 0, but the run has "
        "space.axes = 2 (it keeps x and y)"),
    ("robots:\n  cf1: {enabled: true, initial_position: [0, 0, 1]}\n  cf2: {enabled: true, initial_position: [30, 2, 1]}\n",
     1, "agents_from: {yaml}: robots.cf2.initial_position: y = 2 differs from robots.cf1's 0, but the run has "
        "space.axes = 1 (it keeps x)"),
    ("robots:\n  cf1: {enabled: false, initial_position: [0, 0, 0]}\n", 2, "agents_from: {yaml}: no robot is enabled"),
    ("robots:\n  cf 1: {enabled: true, initial_position: [0, 0, 0]}\n", 2,
     "agents_from: {yaml}: robots.cf 1: a robot's name must be 1 to 64 letters"),
    ("robots:\n  cf1: {enabled: true, initial_position: [0, 0, 0]}\n", 2, "agents: needs at least 2 agents, got 1"),
]


@pytest.mark.parametrize("text, axes, message", BAD, ids=range(len(BAD)))
def test_a_file_that_does_not_fit_is_refused_in_one_line(tmp_path, text, axes, message):
    path = _scenario(tmp_path, text, axes=axes)
    with pytest.raises(ScenarioError) as error:
        tmem.load(path)
    expected = f"{path}: " + message.format(yaml=tmp_path / "config" / "crazyflies.yaml")
    assert str(error.value).startswith(expected) and "\n" not in str(error.value), str(error.value)


def test_a_missing_file_and_agents_given_twice_are_refused(tmp_path):
    path = _scenario(tmp_path, yaml_name="config/absent.yaml")
    with pytest.raises(ScenarioError, match=r"agents_from: .*absent\.yaml: no such file$"):
        tmem.load(path)
    twice = tmp_path / "twice.toml"
    twice.write_text('agents_from = "config/crazyflies.yaml"\n[[agents]]\nposition = 1.0\n')
    with pytest.raises(ScenarioError, match="agents_from: give the agents once: by agents_from or agents, not both"):
        tmem.load(twice)


def test_agent_names_are_unique_and_not_another_agents_number():
    base = tmem.preset("fig9")
    with pytest.raises(ScenarioError, match=r"agents\[1\]\.name: 'a' is the name of agents\[0\]"):
        tmem.scenario.with_changes(base, {"agents[0].name": "a", "agents[1].name": "a"})
    with pytest.raises(ScenarioError, match=r"agents\[0\]\.name: 'agent2' is the name an unnamed agent 2 gets"):
        tmem.scenario.with_changes(base, {"agents[0].name": "agent2"})
    assert tmem.scenario.with_changes(base, {"agents[1].name": "agent2"}).agents[1].name == "agent2"


def test_the_command_refuses_a_missing_yaml_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from tmem.cli.main import app

    path = _scenario(tmp_path, yaml_name="config/absent.yaml")
    result = CliRunner().invoke(app, ["run", str(path), "--out", str(tmp_path / "out")])  # in-process: no real process needed
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert len(lines) == 1 and "agents_from:" in lines[0] and "no such file" in lines[0], result.stderr
    assert not (tmp_path / "out").exists()
