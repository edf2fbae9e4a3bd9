"""The step loop against conservation laws, symmetries and closed forms."""

import numpy as np
import pytest
from scipy.linalg import expm

import tmem
from tmem.engine import record_steps
from tmem.vehicles.linear import state_matrices
from tmem.scenario import with_changes


def short(preset="fig9", **changes):
    return with_changes(tmem.preset(preset), {"simulation.duration": 40.0, **changes})


@pytest.mark.parametrize("function", tmem.FUNCTION_NAMES)
def test_two_agents_keep_their_total_momentum(function):
    """Pair forces are equal and opposite and the model is linear, so V0 + V1 never changes."""
    tr = tmem.simulate(short(**{"interaction.function": function}))
    total = tr.state[:, :, 0, 1].sum(axis=1)
    # Round-off accumulates to ~1e-12 over 4e5 steps; one asymmetric step would show as ~1e-4.
    np.testing.assert_allclose(total, total[0], rtol=0, atol=1e-10)


@pytest.mark.parametrize("function", tmem.FUNCTION_NAMES)
def test_mirror_image_gives_mirror_trajectory(function):
    s = short(**{"interaction.function": function})
    mirrored = with_changes(s, {"agents": [{"position": -a.position, "velocity": -a.velocity} for a in s.agents]})
    a, b = tmem.simulate(s), tmem.simulate(mirrored)
    np.testing.assert_allclose(b.state, -a.state, rtol=0, atol=1e-9)
    assert [(e.time, e.kind) for e in a.events] == [(e.time, e.kind) for e in b.events]


def test_same_scenario_gives_the_same_bits():
    a, b = tmem.simulate(short()), tmem.simulate(short())
    assert a.state.tobytes() == b.state.tobytes()


def test_free_flight_matches_the_matrix_exponential():
    """Agents too far apart to interact follow x(t) = exp(A t) x0 exactly."""
    s = with_changes(
        tmem.preset("repulsion"),
        {
            "simulation.duration": 5.0,
            "agents": [
                {"position": 0.0, "velocity": 1.0, "tilt": 0.05, "tilt_rate": -0.2},
                {"position": 500.0, "velocity": -0.5},
            ],
        },
    )
    tr = tmem.simulate(s)
    a, _ = state_matrices(6.0, 25.0, 9.8)
    x0 = np.array([0.0, 1.0, 0.05, -0.2])
    expected = np.array([expm(a * t) @ x0 for t in tr.time])
    np.testing.assert_allclose(tr.state[:, 0, 0, :], expected, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(tr.state[:, 1, 0, 0], 500.0 - 0.5 * tr.time, rtol=1e-11)
    assert np.all(tr.control == 0.0)


def test_control_is_saturated_at_c_max():
    tr = tmem.simulate(short(**{"interaction.c_max": 0.05}))
    assert np.abs(tr.control).max() == pytest.approx(0.05)


def test_recorded_times_and_final_step():
    assert list(record_steps(10, 3)) == [0, 3, 6, 9, 10]
    assert list(record_steps(9, 3)) == [0, 3, 6, 9]
    tr = tmem.simulate(short(**{"simulation.record_every": 333}))
    assert tr.time[0] == 0.0 and tr.time[-1] == pytest.approx(40.0)
    np.testing.assert_allclose(np.diff(tr.time[:-1]), 333 * 1e-4)


def test_events_record_couple_command_uncouple_in_order():
    tr = tmem.simulate(short())
    kinds = [e.kind for e in tr.events]
    assert kinds == ["couple", "command", "uncouple"]
    command = tr.events[1]
    assert command.time == pytest.approx(29.0) and command.action == "uncouple" and command.agents == (0, 1)
    # The flag record agrees with the events.
    for e in (tr.events[0], tr.events[2]):
        k = np.searchsorted(tr.time, e.time)
        assert tr.flag[k - 1, 0] == (0 if e.kind == "couple" else 1)
        assert tr.flag[min(k + 1, len(tr.time) - 1), 0] == (1 if e.kind == "couple" else 0)


def test_without_a_command_the_pair_stays_coupled():
    tr = tmem.simulate(short(commands=[]))
    assert [e.kind for e in tr.events] == ["couple"]
    assert tr.flag[-1, 0] == 1


def test_couple_command_rearms_a_released_pair():
    """Uncouple at 10 s, couple again at 15 s: the pair couples again at its next coupling point."""
    commands = [{"time": 10.0, "action": "uncouple"}, {"time": 15.0, "action": "couple", "pair": [1, 0]}]
    s = short(commands=commands)
    s = with_changes(s, {"agents": [{"position": 50.0, "velocity": -2.5}, {"position": 0.0, "velocity": 2.5}]})
    tr = tmem.simulate(s)
    kinds = [e.kind for e in tr.events]
    assert kinds[:4] == ["couple", "command", "uncouple", "command"]
    assert tr.events[1].agents == ()  # a command to every pair
    # Re-armed at 15 s while still in the spheres, the pair couples again when it next reaches d_t.
    assert kinds[4] == "couple" and 15.0 < tr.events[4].time < 25.0
    assert tr.flag[-1, 0] == 1


def test_three_agents_on_a_line_interact_pairwise():
    s = with_changes(
        tmem.preset("repulsion"),
        {
            "simulation.duration": 30.0,
            "agents": [
                {"position": 0.0, "velocity": 2.0},
                {"position": 45.0, "velocity": 0.0},
                {"position": 90.0, "velocity": -2.0},
            ],
        },
    )
    tr = tmem.simulate(s)
    assert len(tr.pairs) == 3
    # The middle agent is pushed from both sides symmetrically and stays put.
    np.testing.assert_allclose(tr.state[:, 1, 0, 0], 45.0, atol=1e-9)
    # The outer agents bounce back with their speeds.
    np.testing.assert_allclose(tr.state[-1, [0, 2], 0, 1], [-2.0, 2.0], atol=0.02)


def test_each_agent_corrected_position_uses_its_own_gains():
    """The P* stage (6) with a different row of gains per agent matches x . K_i / K_P,i row by row."""
    from tmem.law.modal import interaction_point
    from tmem.engine.records import Agents, Neighbours, Run
    from tmem.law.record import Law
    from tmem.engine.gas import gas_record
    from tmem.engine.stages import corrected_positions

    rng = np.random.default_rng(3)
    n, axes = 5, 2
    state = rng.normal(size=(n, axes, 4))
    gains = rng.uniform(0.5, 2.0, size=(n, 4))
    agents = Agents(state, state.copy(), np.ones(n, dtype=np.bool_), np.empty((n, axes, 2)), np.ones((n, axes)), np.zeros((n, 0)), np.zeros((n, 0)))
    law = Law(gains, 0, 0, False, False, 0.2, 0, 0.05, 0, 0.0, True)
    run = Run(10, 1, (0.0,) * axes, False, 1.0)
    neighbours = Neighbours(np.empty((0, 2), dtype=np.uint32), 0, 0, np.zeros(2, dtype=np.int64), np.zeros((n, axes)),
                            np.empty(1), np.empty(2), np.full(1, np.inf), np.empty((2, 2 * axes + 1, 8)))  # fmt: skip
    corrected_positions(state, agents, law, run, neighbours, gas_record(tmem.preset("fig9"), 9.8, n), 0, False)  # lists of P*
    expected = np.stack([interaction_point(state[i], gains[i]) for i in range(n)])
    np.testing.assert_allclose(agents.corrected[:, :, 0], expected, rtol=1e-13)
    np.testing.assert_array_equal(agents.corrected[:, :, 1], state[:, :, 0])
    assert not agents.setpoint.any()  # the sum of pushes starts from zero
