"""Agent terms: the pull towards a point (P1), the worked example of a term, against an independent recursion.

The reference steps the linear model (2) by its exact zero-order hold, written here from scipy
(``expm`` for the hold, ``place_poles`` for the gains), with the pull (P1) as the only push: the
agents start far beyond each other's reach and stay there.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm
from scipy.signal import place_poles

import tmem
from tmem.scenario import ScenarioError, loads, with_changes

SCENARIO = """
name = "pulled"
[space]
axes = 2
[interaction]
function = "repulsion"
[simulation]
dt = 0.001
duration = 20.0
record_every = 100
[[agents]]
position = [300.0, 0.0]
velocity = [0.0, 2.0]
[[agents]]
position = [0.0, 100000.0]
[pull]
point = [10.0, -5.0]
gain = {gain}
"""


def reference(scenario) -> np.ndarray:
    """Every agent's states at every step under (P1) alone: ``x <- Ad x + Bd U`` with
    ``U = -gain (P* - point)`` saturated on its norm at ``c_max``; shape (steps + 1, agents, axes, 4)."""
    m, c, sim = scenario.model, scenario.controller, scenario.simulation
    a = np.array([[0, 1, 0, 0], [0, 0, m.g, 0], [0, 0, 0, 1], [0, 0, -m.kp * m.kd, -m.kd]], dtype=float)
    b = np.array([0, 0, 0, m.kp * m.kd], dtype=float)
    poles = [-c.r_l - 1j * c.im_l, -c.r_l + 1j * c.im_l, -1j * c.im_r, 1j * c.im_r]
    k = place_poles(a, b[:, None], poles).gain_matrix[0]
    augmented = np.zeros((5, 5))
    augmented[:4, :4], augmented[:4, 4] = a, b
    hold = expm(augmented * sim.dt)
    ad, bd = hold[:4, :4], hold[:4, 4]
    point, gain, c_max = np.array(scenario.pull.point), scenario.pull.gain, scenario.interaction.c_max
    x = np.zeros((len(scenario.agents), 2, 4))
    for i, agent in enumerate(scenario.agents):
        x[i, :, 0], x[i, :, 1] = agent.position, agent.velocity
    out = [x.copy()]
    for _ in range(sim.n_steps):
        u = -gain * (x @ (k / k[0]) - point)
        u *= np.minimum(1.0, c_max / np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-300))
        x = x @ ad.T + u[..., None] * bd
        out.append(x.copy())
    return np.array(out)


@pytest.fixture(scope="module")
def k_p() -> float:
    return tmem.loads(SCENARIO.format(gain=1e-6)).position_gain


def test_the_pull_moves_the_agents_as_the_zero_order_hold_of_the_model_does(k_p):
    scenario = tmem.loads(SCENARIO.format(gain=k_p / 90))  # the far agent saturated, the near one not
    trajectory = tmem.simulate(scenario)
    expected = reference(scenario)[:: scenario.simulation.record_every]
    np.testing.assert_allclose(trajectory.state, expected, rtol=1e-9, atol=1e-9)
    assert np.ptp(trajectory.state[:, 0, 0, 0]) > 10.0  # it did move: the test could fail


def test_a_gain_above_k_p_is_refused_in_one_line(k_p):
    with pytest.raises(ScenarioError, match=r"pull\.gain: .* exceeds the law's K_P = 0\.02963 rad/m"):
        tmem.loads(SCENARIO.format(gain=1.01 * k_p))


def test_a_point_with_the_wrong_number_of_values_is_refused():
    scenario = tmem.loads(SCENARIO.format(gain=1e-4))
    with pytest.raises(ScenarioError, match=r"pull\.point: needs 2 values"):
        with_changes(scenario, {"pull.point": [1.0, 2.0, 3.0]})


@pytest.mark.parametrize(("share", "low", "high"), [(0.05, 0.0, 2e-7), (0.5, 0.0, 2e-7), (0.9, 0.0, 2e-7),
                                                     (1.0, 0.0, 2e-7), (1.5, 1e-6, 2e-6), (5.0, 3e-4, 4e-4)])
def test_the_slow_pair_of_a_pulled_agent_stays_on_the_axis_up_to_k_p_and_grows_above(share, low, high):
    """(P1) alone: the loop A - (gain / K_P) B K, its slow pair's real part as the module text states it."""
    a = np.array([[0, 1, 0, 0], [0, 0, 9.8, 0], [0, 0, 0, 1], [0, 0, -150.0, -25.0]])
    b = np.array([0, 0, 0, 150.0])
    k = place_poles(a, b[:, None], [-12 - 0.1j, -12 + 0.1j, -0.55j, 0.55j]).gain_matrix[0]
    slow = sorted(np.roots(np.poly(a - share * np.outer(b, k))), key=abs)[:2]
    growth = max(root.real for root in slow)
    assert low <= abs(growth) < high if share <= 1.0 else low <= growth < high


def test_a_pulled_run_goes_on_from_its_checkpoint_to_the_same_bits(tmp_path):
    from test_checkpoint import assert_same_bits, stopped_after

    from tmem.engine.checkpoint import Checkpoints

    scenario = with_changes(tmem.loads(SCENARIO.format(gain=1e-4)), {"simulation.duration": 6.0})
    reference = tmem.simulate(scenario)
    saved = stopped_after(scenario, tmp_path / "run.npz", 2.0, 4.0)
    assert not [key for key in saved.arrays if key.startswith("terms.")]  # (P1)'s record is fixed for the run
    resumed = tmem.simulate(scenario, checkpoints=Checkpoints(tmp_path / "run.npz", 2.0))
    assert_same_bits(reference, resumed)


def test_the_batch_and_the_per_agent_controllers_refuse_an_agent_term_in_one_line():
    from tmem.agent import ControllerError, controllers_for
    from tmem.batch import unsupported

    scenario = tmem.loads(SCENARIO.format(gain=1e-4))
    assert unsupported(scenario) == "the agent terms ([pull]) are the step loop's"
    assert unsupported(with_changes(scenario, {"pull": None})) is None
    with pytest.raises(ControllerError, match=r"^pull: is an agent term of the engine's step loop"):
        controllers_for(scenario)
