"""The Python API checks what the command line checks, and says what it does with what it refuses.

* ``tmem.simulate(scenario, sensing={...})``: an override of a ``[sensing]`` key meets the table's
  checks, and gives the bits of the same key in the file;
* ``tmem.simulate``, ``controllers_for`` and ``fly`` take a scenario, its file's path or its
  tables, and refuse anything else in one line naming the argument;
* a controller refuses a message holding a number that is not finite (its stamp too), as not
  received, and never returns a set-point that is not finite;
* the quadrotor's start refuses a tilt past the horizontal in one line; the command line warns of a
  doubtful value in one line, and maps the coverage of any walled box.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

import tmem
from tmem.agent import AgentController, AgentMessage, Edge, controllers_for, fly
from tmem.agent.controller import MessageWarning
from tmem.cli.main import app
from tmem.scenario import ScenarioError, ScenarioWarning, with_changes

#: Fig. 9, short and coarse: 2 s at dt = 1 ms, no command, the pair within reach from the start.
SHORT = with_changes(tmem.preset("fig9"), {"simulation.dt": 1e-3, "simulation.duration": 2.0, "simulation.record_every": 10,
                                           "commands": [], "agents[0].position": 38.0})  # fmt: skip


# -- the sensing overrides -------------------------------------------------------------------------------


@pytest.mark.parametrize("overrides, line", [
    ({"loss": 2.0}, "sensing.loss: must be less than 1"),
    ({"position_noise": math.nan}, "sensing.position_noise: must be a finite number"),
    ({"position_noise": -0.1}, "sensing.position_noise: must be greater than or equal to 0"),
    ({"delay": 100.0}, "sensing.delay: 100 s is not shorter than the run"),
    ({"every": 3}, "sensing.every: is set from the [sensing] table's keys"),
    ({"colour": 1.0}, "sensing.colour: unknown key"),
])  # fmt: skip
def test_an_override_is_checked_as_the_table_is(overrides, line):
    with pytest.raises(ScenarioError) as refused:
        tmem.simulate(SHORT, sensing=overrides)
    assert str(refused.value).startswith(line) and "\n" not in str(refused.value)


def test_overrides_not_a_dict_are_refused():
    with pytest.raises(ScenarioError, match="^sensing: must be a dict"):
        tmem.simulate(SHORT, sensing=[("loss", 0.1)])


@pytest.mark.parametrize("keys", [{"position_noise": 0.3, "seed": 2}, {"loss": 0.5, "seed": 3}, {"delay": 0.05, "period": 0.01}])
def test_an_override_gives_the_bits_of_the_same_key_in_the_file(keys):
    """The measurement stage built from the table (its buffer sized for the delay and the loss),
    whether the key is given in the file or over it."""
    over = tmem.simulate(SHORT, sensing=keys)
    filed = tmem.simulate(with_changes(SHORT, {f"sensing.{k}": v for k, v in keys.items()}))
    assert over.state.tobytes() == filed.state.tobytes()
    assert not np.array_equal(over.state, tmem.simulate(SHORT).state)  # the effect acted


# -- a scenario, its file or its tables -------------------------------------------------------------------


def test_simulate_takes_a_path_or_the_tables(tmp_path):
    path = tmp_path / "short.toml"
    path.write_text(SHORT.to_toml())
    tables = json.loads(SHORT.model_dump_json(exclude_none=True))
    reference = tmem.simulate(SHORT).state.tobytes()
    assert tmem.simulate(str(path)).state.tobytes() == reference
    assert tmem.simulate(path).state.tobytes() == reference
    assert tmem.simulate(tables).state.tobytes() == reference


@pytest.mark.parametrize("call", [tmem.simulate, controllers_for, fly], ids=["simulate", "controllers_for", "fly"])
def test_anything_else_is_refused_in_one_line_naming_the_argument(call, tmp_path):
    with pytest.raises(ScenarioError, match=r"^scenario: must be a Scenario, the path of a scenario file or a dict .* got int$"):
        call(3)
    with pytest.raises(ScenarioError, match=r"nowhere.toml: no such file$"):
        call(tmp_path / "nowhere.toml")
    with pytest.raises(ScenarioError, match=r"^interaction.c_max: must be greater than 0"):
        call({"interaction": {"c_max": -1.0}, "agents": [{"position": 0.0}, {"position": 50.0}]})


def test_controllers_for_and_fly_take_a_path(tmp_path):
    path = tmp_path / "short.toml"
    path.write_text(SHORT.to_toml())
    by_path, by_scenario = controllers_for(str(path)), controllers_for(SHORT)
    assert [c.settings for c in by_path] == [c.settings for c in by_scenario]
    assert fly(path).state.tobytes() == fly(SHORT).state.tobytes()


# -- a controller's messages --------------------------------------------------------------------------------


def _pair(**settings):
    gains = tmem.modal_gains(6.0, 25.0, 9.8, 12.0, 0.1, 0.55)
    return [AgentController(a, gains, dt=1e-3, edges=[Edge(neighbour=1 - a, coupled=True)], **settings) for a in (0, 1)]


def _states():
    states = np.zeros((2, 1, 4))
    states[1, 0, 0], states[0, 0, 1] = 30.0, 1.0
    return states


@pytest.mark.parametrize("sender", [1, 7], ids=["formation neighbour", "other agent"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_message_holding_a_number_not_finite_is_refused_as_not_received(sender, bad):
    states = _states()
    message = _pair()[1].message(states[1], 0.0)._replace(sender=sender)
    vectors = message.vectors.copy()
    vectors[0, 0] = bad
    controller = _pair()[0]
    with pytest.warns(MessageWarning, match=rf"^messages: agent {sender}'s message holds .* refused, as not received$"):
        u = controller.update(states[0], [message._replace(vectors=vectors)], 0.0)
    assert np.isfinite(u).all() and controller.refused == 1
    assert np.array_equal(u, _pair()[0].update(states[0], [], 0.0))


def test_a_stamp_not_finite_is_refused_and_max_age_holds():
    """Before, t - nan > max_age was false and a message of no age was used; it is refused now."""
    states = _states()
    old = _pair()[1].message(states[1], 0.0)
    controller = _pair(max_age=0.05)[0]
    with pytest.warns(MessageWarning, match="holds the stamp nan"):
        u = controller.update(states[0], [old._replace(stamp=math.nan)], 1.0)
    assert np.array_equal(u, _pair(max_age=0.05)[0].update(states[0], [], 1.0))
    assert not np.array_equal(u, _pair()[0].update(states[0], [old], 0.0))  # a good message would have pushed


def test_a_set_point_not_finite_is_never_returned(monkeypatch):
    """Finite messages and states keep the law's sum finite (a neighbour beyond reach pushes nothing,
    however far); should the law still give a sum that is not finite (a law of its own, here one
    that gives NaN from the second update on), the controller holds its last finite set-point."""
    import tmem.agent.controller as module

    real = module.control

    def failing(k, *args):
        real(k, *args)
        if k > 0:
            args[-1][:] = math.nan

    states = _states()
    controller, neighbour = _pair()
    first = controller.update(states[0], [neighbour.message(states[1], 0.0)], 0.0)
    monkeypatch.setattr(module, "control", failing)
    with pytest.warns(MessageWarning, match=r"^update: the law gave the set-point \[nan\] at t = 0.001 s; the last finite one"):
        u = controller.update(states[0], [neighbour.message(states[1], 0.001)], 0.001)
    assert np.isfinite(u).all() and np.array_equal(u, first) and np.any(first != 0.0)


# -- the quadrotor's start, the command line's warning, the coverage of a walled box ------------------------


@pytest.mark.parametrize("tilt", [-2.0, 3.0, math.pi / 2, math.nan])
def test_the_quadrotor_start_refuses_a_tilt_past_the_horizontal_in_one_line(tilt):
    from tmem.scenario import QuadrotorModelParams
    from tmem.vehicles.quadrotor import QuadrotorModel

    state = np.zeros((2, 1, 4))
    state[1, 0, 2] = tilt
    with pytest.raises(ValueError, match=r"^state: the tilt of agent 1 on axis 0 is .* lies within \+-pi/2 = 1.571 rad$"):
        QuadrotorModel(QuadrotorModelParams(kind="quadrotor")).initial_body(state)


def test_the_command_line_warns_of_a_doubtful_value_in_one_line(tmp_path):
    """eps = 3 mm at dt = 1 ms: Fig. 9's pair closes 4.5 mm a step, more than eps (legal: the window,
    6 mm wide, still holds a step).  Run as a user runs it, Python's own warnings on."""
    path = tmp_path / "doubtful.toml"
    path.write_text(with_changes(SHORT, {"interaction.eps": 0.003}).to_toml())
    done = subprocess.run([sys.executable, "-m", "tmem", "run", str(path), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("warning: interaction.eps: 0.003 m is less than the 0.0045 m"), lines[0]


def test_a_walled_box_of_small_agents_maps_its_coverage(tmp_path):
    """R = 0.05 m in a 1 km box (the agent at 0.5 m/s, below the 0.63 m/s the tilt limit stops within
    R + R_j = 0.1 m: nothing doubtful): cells of side R would be 4e8; the map takes cells of 1 m (10^6),
    and field.png is drawn (before: an AttributeError, exit status 1)."""
    scenario = {"space": {"axes": 2, "walls": True, "box": [1000.0, 1000.0]},
                "interaction": {"function": "repulsion", "radius": 0.05, "d_t": 0.08, "eps": 0.01},
                "agents": [{"position": [100.0, 100.0], "velocity": [0.5, 0.0]}, {"position": [200.0, 100.0]}],
                "simulation": {"dt": 0.001, "duration": 1.0, "record_every": 100}}  # fmt: skip
    path = tmp_path / "small.toml"
    path.write_text(tmem.scenario.from_dict(scenario).to_toml())
    with warnings.catch_warnings():
        warnings.simplefilter("error", ScenarioWarning)  # nothing doubtful here
        result = CliRunner().invoke(app, ["run", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output[-3000:]
    assert (tmp_path / "out" / "field.png").exists()
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["coverage"]["cell"] == pytest.approx(1.0) and summary["coverage"]["cells"] == 10**6
    # each agent stays in its cell of 1 m over the second (one moves 0.5 m from its cell's edge): 2 of 10^6
    assert summary["coverage"]["share_final"] == pytest.approx(2e-6)
