"""Per-agent controllers (tmem.agent): the engine's bits from a plain loop, messages only, bad input refused.

The loop over controllers (:func:`tmem.agent.fly`) is checked against :func:`tmem.simulate`, an
independent implementation of the same law (one compiled loop over the whole swarm, in its own
numbering of the agents): states, set-points, flags and events must be equal to the bit, the
product's claim (docs/agent_controller.md, "Same bits as the engine").  The
runs are short (the loop is Python); fig9's is the one that couples, gets its command and
uncouples, with the command moved from 29 s to 5 s.
"""

import re
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest

import tmem
from tmem.agent import AgentController, AgentMessage, ControllerError, Edge, OperatorCommand, controllers_for, fly
from tmem.scenario import with_changes

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _short(scenario, duration, dt=1e-3, commands=(), **changes):
    return with_changes(scenario, {"simulation.dt": dt, "simulation.duration": duration, "simulation.record_every": 10,
                                   "commands": list(commands), **changes})  # fmt: skip


UNCOUPLE_01 = {"time": 5.0, "action": "uncouple", "pair": [0, 1]}
#: Name -> (scenario, the event kinds it must show: a case that shows nothing proves little).
CASES = {
    "fig5": (_short(tmem.preset("fig5"), 4.0, commands=[{"time": 1.0, "action": "uncouple", "pair": [0, 1]}]), {"command"}),
    "fig7": (_short(tmem.preset("fig7"), 9.0, commands=[UNCOUPLE_01]), {"couple", "command", "uncouple"}),
    "fig9": (_short(tmem.preset("fig9"), 8.5, commands=[UNCOUPLE_01]), {"couple", "command", "uncouple"}),
    "fig9-dt": (_short(tmem.preset("fig9"), 0.5, dt=1e-4), set()),  # the shipped dt
    "hex19": (_short(tmem.load(EXAMPLES / "swarm/hex19.toml"), 0.6, commands=[{"time": 0.2, "action": "uncouple"}]),
              {"command", "uncouple"}),
    "triangle": (_short(tmem.load(EXAMPLES / "swarm/triangle.toml"), 2.0), set()),
    # a bearing held, the energy rule, synchronisation, the flag flipped at the crossing
    "chain-options": (_short(tmem.load(EXAMPLES / "swarm/chain5.toml"), 2.0, commands=[{"time": 0.3, "action": "uncouple"}],
                             **{"interaction.uncouple_when": "energy", "interaction.synchronise": True,
                                "interaction.switch_at": "crossing", "formation.n": 3}),
                      {"command"}),  # fmt: skip
    # the nonlinear quadrotor: each vehicle's body state (attitude, rotors, height) stepped by the model
    "quadrotor-hex19": (_short(tmem.load(EXAMPLES / "vehicles/hex19.toml"), 0.3, dt=5e-4), set()),
    # 40 agents without pairs: every push is a neighbour's, summed in the engine's own order
    "swarm40": (tmem.loads('[space]\naxes = 2\n[interaction]\nfunction = "repulsion"\n'
                           '[swarm]\nn = 40\nseed = 3\nregion = [150.0, 150.0]\nspeed_rms = 4.0\n'
                           "[simulation]\ndt = 0.001\nduration = 0.5\nrecord_every = 10\n"), set()),
}  # fmt: skip


@pytest.mark.parametrize("name", CASES)
def test_the_per_agent_loop_flies_the_engines_bits(name):
    scenario, kinds = CASES[name]
    engine, flight = tmem.simulate(scenario), fly(scenario)
    for field in ("time", "state", "control", "flag", "final_state"):
        assert np.array_equal(getattr(flight, field), getattr(engine, field)), field
    assert flight.events == engine.events
    assert kinds <= {e.kind for e in engine.events}
    for i, j in scenario.pairs().tolist():  # both agents of a pair hold the same flag
        assert flight.controllers[i].flag(j) == flight.controllers[j].flag(i)


def test_the_swarm_case_has_agents_with_several_pushes_at_once():
    """Else the order of summation would go untested."""
    scenario, _ = CASES["swarm40"]
    trajectory = tmem.simulate(scenario)
    corrected = tmem.interaction_point(trajectory.state, trajectory.gains)  # (records, agents, axes)
    gaps = np.linalg.norm(corrected[:, :, None] - corrected[:, None], axis=-1)
    within = (gaps < scenario.interaction.reach).sum(axis=-1) - 1
    assert within.max() >= 3
    order = controllers_for(scenario)[0].settings.order  # the engine's numbering, not the agents'
    assert order != sorted(order)


def _messages(controllers, states, t=0.0, skip=()):
    return [c.message(x, t) for c, x in zip(controllers, states) if c.agent not in skip]


def _setpoints(scenario, change=None):
    """Every agent's set-point at the start, each controller given the messages ``change`` leaves it."""
    controllers = controllers_for(scenario)
    states = tmem.world.initial.build(scenario).state
    messages = _messages(controllers, states)
    return np.array([c.update(x, change(c.agent, messages) if change else messages, 0.0) for c, x in zip(controllers, states)])


def test_dropping_a_formation_neighbours_message_changes_that_agent_and_nobody_else():
    scenario = tmem.load(EXAMPLES / "swarm/triangle.toml")
    full = _setpoints(scenario)
    dropped = _setpoints(scenario, lambda agent, ms: [m for m in ms if not (agent == 0 and m.sender == 1)])
    assert not np.array_equal(dropped[0], full[0])
    assert np.array_equal(dropped[1:], full[1:])


def _far_and_near(agent, messages, distance):
    """The messages and one from an agent that is no formation neighbour, ``distance`` m ahead of agent 0 in P*."""
    ahead = messages[0].vectors.copy()
    ahead[:2, 0] += distance
    return messages + [AgentMessage(99, 0.0, True, ahead)]


def test_a_message_from_a_non_neighbour_beyond_reach_changes_nothing_and_within_reach_it_pushes():
    scenario = tmem.load(EXAMPLES / "swarm/triangle.toml")
    full = _setpoints(scenario)
    reach = scenario.interaction.reach
    assert np.array_equal(_setpoints(scenario, lambda a, ms: _far_and_near(a, ms, 1.5 * reach)), full)
    assert not np.array_equal(_setpoints(scenario, lambda a, ms: _far_and_near(a, ms, 0.5 * reach))[0], full[0])


def _pair(**changes):
    """Two agents 35 m apart by hand, coupled, agent 1 at rest and agent 0 closing at 1 m/s."""
    gains = tmem.modal_gains(6.0, 25.0, 9.8, 12.0, 0.1, 0.55)
    settings = {"dt": 1e-3, "law": {"function": "improved"}, **changes}
    controllers = [AgentController(0, gains, edges=[Edge(neighbour=1, coupled=True)], **settings),
                   AgentController(1, gains, edges=[Edge(neighbour=0, coupled=True)], **settings)]  # fmt: skip
    states = np.zeros((2, 1, 4))
    states[1, 0, 0], states[0, 0, 1] = 35.0, 1.0
    return controllers, states


def test_a_neighbour_that_no_longer_flies_releases_the_pair():
    controllers, states = _pair()
    grounded = controllers[1].message(states[1], 0.0)._replace(flying=False)
    u = controllers[0].update(states[0], [grounded], 0.0)
    assert controllers[0].flag(1) == 0
    assert [(e.kind, e.rule) for e in controllers[0].events] == [("uncouple", "lost")]
    assert np.array_equal(u, [0.0])  # no push from a grounded agent


def test_a_stale_message_counts_as_not_received():
    controllers, states = _pair(max_age=0.05)
    old = controllers[1].message(states[1], 0.0)
    stale = controllers[0].update(states[0], [old], 0.1)
    controllers, _ = _pair(max_age=0.05)
    assert np.array_equal(stale, controllers[0].update(states[0], [], 0.1))
    assert not np.array_equal(stale, controllers[0].update(states[0], [old._replace(stamp=0.1)], 0.1))


def test_controllers_built_by_hand_fly_as_those_of_the_scenario():
    """fig9 by hand: the gains of (4) with Table 1, one edge each, the operator's command."""
    scenario = CASES["fig9"][0]
    gains = tmem.modal_gains(6.0, 25.0, 9.8, 12.0, 0.1, 0.55)
    command = [OperatorCommand(time=5.0, action="uncouple", pairs=[[0, 1]])]
    by_hand = [AgentController(a, gains, dt=1e-3, edges=[Edge(neighbour=1 - a)], commands=command) for a in (0, 1)]
    ours, theirs = fly(scenario, by_hand), fly(scenario)
    assert np.array_equal(ours.state, theirs.state) and ours.events == theirs.events


@pytest.mark.interface
def test_the_message_goes_over_the_wire_and_back():
    controllers, states = _pair()
    message = controllers[0].message(states[0], 1.5)
    floats = message.to_floats()
    assert floats.shape == (6,)
    back = AgentMessage.from_floats(floats)
    assert (back.sender, back.stamp, back.flying) == (0, 1.5, True)
    assert np.array_equal(back.vectors, message.vectors)


@pytest.mark.interface
@pytest.mark.parametrize(
    "values, field",
    [([0.0, 1.0, 1.0, 2.0, 3.0], "3 axes numbers"), ([0.5, 0.0, 1.0, 1.0, 2.0, 3.0], "sender"),
     ([0.0, 0.0, 1.0, np.nan, 2.0, 3.0], "finite")],
)  # fmt: skip
def test_a_malformed_message_is_refused_in_one_line(values, field):
    with pytest.raises(ControllerError, match=field) as caught:
        AgentMessage.from_floats(values)
    assert "\n" not in str(caught.value)


GAINS = list(tmem.modal_gains(6.0, 25.0, 9.8, 12.0, 0.1, 0.55))
BAD = [
    ({"gains": GAINS[:3]}, "gains"),
    ({"gains": [-1.0] + GAINS[1:]}, "gains[0]"),
    ({"gains": GAINS[:3] + [float("nan")]}, "gains[3]"),
    ({"dt": 0.0}, "dt"),
    ({"law": {"function": "spring"}}, "law.function"),
    ({"law": {"d_t": 45.0}}, "law.d_t"),
    ({"law": {"eps": 40.0, "d_t": 35.0}}, "law.eps"),
    ({"edges": [Edge(neighbour=0)]}, "edges[0].neighbour"),
    ({"edges": [Edge(neighbour=1), Edge(neighbour=1)]}, "edges[1].neighbour"),
    ({"edges": [{"neighbour": 1, "d_t": -3.0}]}, "edges[0].d_t"),
    ({"edges": [Edge(neighbour=1, direction=[1.0, 0.0])]}, "edges[0].direction"),
    ({"axes": 2, "edges": [Edge(neighbour=1, direction=[1.0, 1.0])]}, "edges[0].direction"),
    ({"commands": [OperatorCommand(time=1.0, action="uncouple", pairs=[[2, 3]])]}, "commands[0].pairs"),
    ({"law": {"uncouple_when": "energy"}}, "law.fallback_time"),
    ({"order": [1, 2, 1]}, "order"),
    ({"max_age": -1.0}, "max_age"),
    ({"law": {"switch_at": "middle"}}, "law.switch_at"),
]


@pytest.mark.interface
@pytest.mark.parametrize("changes, field", BAD, ids=[field for _, field in BAD])
def test_bad_construction_input_is_refused_in_one_line_naming_the_field(changes, field):
    settings = {"gains": GAINS, "dt": 1e-3, **changes}
    with pytest.raises(ControllerError) as caught:
        AgentController(0, **settings)
    message = str(caught.value)
    assert "\n" not in message and f"{field}" in message, message


@pytest.mark.interface
def test_bad_tables_and_update_input_are_refused_in_one_line():
    with pytest.raises(ControllerError, match=r"^Edge: d_t: must be greater than 0"):
        Edge(neighbour=1, d_t=-3.0)
    with pytest.raises(ControllerError, match=r"^OperatorCommand: action"):
        OperatorCommand(time=1.0, action="remove")
    controllers, states = _pair()
    for call, field in [(lambda: controllers[0].update(np.zeros((2, 4)), [], 0.0), "own_state"),
                        (lambda: controllers[0].update(np.full((1, 4), np.inf), [], 0.0), "own_state"),
                        (lambda: controllers[0].update(states[0], [], -1.0), "t: "),
                        (lambda: controllers[0].update(states[0], [AgentMessage(1, 0.0, True, np.zeros((3, 2)))], 0.0),
                         "messages"),
                        (lambda: controllers[0].flag(5), "neighbour")]:  # fmt: skip
        with pytest.raises(ControllerError, match=field):
            call()


GAS_BOX = tmem.load(EXAMPLES / "swarm/gas_box.toml")
REFUSED = [
    (tmem.load(EXAMPLES / "swarm/gas2d.toml"), "space.periodic"),
    (with_changes(GAS_BOX, {"swarm.n": 50}), "space.walls"),
    (with_changes(GAS_BOX, {"swarm.n": 50, "space.walls": False}), "thermostat"),
    (with_changes(tmem.load(EXAMPLES / "swarm/triangle.toml"), {"interaction.combine": "mean"}), "interaction.combine"),
    (GAS_BOX, "swarm.n"),
    (tmem.load(EXAMPLES / "swarm/ring8_loss.toml"), "commands[0].action"),
    (with_changes(tmem.preset("fig9"), {"agents": [{"position": 50.0}, {"position": 0.0, "active": False}]}),
     "agents[1].active"),
]


@pytest.mark.interface
@pytest.mark.parametrize("scenario, field", REFUSED, ids=[field for _, field in REFUSED])
def test_what_per_agent_controllers_do_not_do_is_refused_in_one_line(scenario, field):
    for attempt in (lambda: controllers_for(scenario), lambda: fly(scenario)):
        with pytest.raises(ControllerError, match=rf"^{re.escape(field)}: ") as caught:
            attempt()
        assert "\n" not in str(caught.value)


@pytest.mark.interface
def test_a_scenario_with_sensing_effects_is_not_flown():
    """fly() passes every message exactly: a [sensing] table with effects would not be honoured."""
    noisy = with_changes(tmem.preset("fig9"), {"sensing": {"position_noise": 0.1}})
    with pytest.raises(ControllerError, match=r"^sensing: ") as caught:
        fly(noisy)
    assert "\n" not in str(caught.value)


def test_reset_starts_the_controller_again():
    controllers, states = _pair()
    first = [controllers[0].update(states[0], _messages(controllers, states, t), t) for t in (0.0, 0.001)]
    controllers[0].reset()
    again = [controllers[0].update(states[0], _messages(controllers, states, t), t) for t in (0.0, 0.001)]
    assert np.array_equal(first, again)


@pytest.mark.interface
def test_the_example_flies_the_engines_bits(monkeypatch, capsys):
    """examples/vehicles/per_agent_loop.py, run as a script in this process (it needs no process of its own)."""
    monkeypatch.setattr(sys, "argv", ["per_agent_loop.py", "--duration", "0.3"])
    runpy.run_path(str(EXAMPLES / "vehicles/per_agent_loop.py"), run_name="__main__")
    assert "the same bits as tmem.simulate: yes" in capsys.readouterr().out
