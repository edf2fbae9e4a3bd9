"""The ground robot (R1)-(R3): its gains against pole placement, its step against the closed form,
the law's loop on it, and Fig. 9's pair and the 19-agent hex driven by it, against closed forms
and the continuous-time reference."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import place_poles

import tmem
from tmem.analysis.reference import final_state
from tmem.scenario import ScenarioError, with_changes
from tmem.vehicles import vehicle_model
from tmem.vehicles.ground_robot import GroundRobotParams
from tmem.world.formation import generate

ROOT = Path(__file__).resolve().parents[1]
IM_R = 0.55


def robot(tau: float = 0.1, a_max: float = 2.0):
    return vehicle_model(GroundRobotParams(kind="ground_robot", tau=tau, a_max=a_max))


@pytest.mark.parametrize("tau", [0.02, 0.1, 0.5])
def test_the_gains_place_the_drives_root_and_the_undamped_pair(tau):
    model = robot(tau)
    a, b = model.linearisation()
    placed = place_poles(a, b[:, None], [-1.0 / tau, -1j * IM_R, 1j * IM_R]).gain_matrix[0]
    np.testing.assert_allclose(model.gains(12.0, 0.1, IM_R), placed, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("tau", [0.05, 0.5])
@pytest.mark.parametrize("pushers", [1, 2, 6])
def test_any_number_of_pushers_leaves_the_slow_pair_undamped(tau, pushers):
    """(R3): det(sI - A + c B K) = (s + 1/tau)(s^2 + c im_r^2)."""
    model = robot(tau)
    a, b = model.linearisation()
    roots = np.linalg.eigvals(a - pushers * np.outer(b, model.gains(12.0, 0.1, IM_R)))
    expected = [-1.0 / tau, -1j * IM_R * np.sqrt(pushers), 1j * IM_R * np.sqrt(pushers)]
    np.testing.assert_allclose(sorted(roots, key=lambda s: (s.real, s.imag)), sorted(expected, key=lambda s: (s.real, s.imag)),
                               atol=1e-9)  # fmt: skip


@pytest.mark.parametrize(("asked", "given"), [(0.7, 0.7), (5.0, 2.0)])
def test_the_step_is_the_closed_form_of_the_drive_with_its_limit(asked, given):
    """A held set-point over 200 steps of 0.01 s from (P, V, a) = (1, -2, 0.3): the drive follows
    ``sat(U)`` with its lag, ``a(t) = g + (a0 - g) e^(-t/tau)``, integrated twice in closed form."""
    tau, dt, steps = 0.1, 0.01, 200
    model = robot(tau, a_max=2.0)
    step, params = model.kernel(), model.step_params(dt)
    x = np.array([[[1.0, -2.0, 0.3]]])
    u = np.array([[asked]])
    for _ in range(steps):
        step(x, np.zeros((1, 0)), u, 0, 1.0, params, 1)
    t, p0, v0, a0, g = steps * dt, 1.0, -2.0, 0.3, given
    fade = np.exp(-t / tau)
    expected = [p0 + v0 * t + g * t**2 / 2 + (a0 - g) * tau * (t - tau * (1 - fade)), v0 + g * t + (a0 - g) * tau * (1 - fade),
                g + (a0 - g) * fade]  # fmt: skip
    np.testing.assert_allclose(x[0, 0], expected, rtol=1e-10)


def test_fig9s_pair_oscillates_at_the_closed_forms_frequency_while_coupled():
    """On the robot ``P*'' = U`` (R2): the coupled pair's ``|d|`` swings about ``d_t`` under the spring
    ``K_P (r - d_t)`` on both agents, at ``sqrt(2) im_r``, while the pushes stay below ``c_max`` (here
    the drive's whole 2 m/s^2: at the example's 0.98 the swing's ends saturate)."""
    scenario = with_changes(tmem.load(ROOT / "examples/robots/fig9.toml"), {"interaction.c_max": 2.0})
    trajectory = tmem.simulate(scenario)
    couple, uncouple = (e.time for e in trajectory.events if e.kind in ("couple", "uncouple"))
    assert couple < 5.0 and 29.0 < uncouple < 32.0  # couples, and lets go after the command at 29 s
    held = (trajectory.time > couple + 5.0) & (trajectory.time < 29.0)
    r = trajectory.interaction_distance[held, 0] - scenario.interaction.d_t
    assert 0.2 < np.abs(r).max() < scenario.interaction.c_max / scenario.position_gain  # swinging, below saturation
    crossings = trajectory.time[held][1:][np.diff(np.sign(r)) > 0]  # upward zero crossings
    period = np.mean(np.diff(crossings))
    assert period == pytest.approx(2 * np.pi / (np.sqrt(2) * IM_R), rel=2e-3)


def test_the_hex_swings_in_the_modes_of_its_graph_laplacian():
    """The 19-agent hex on the robot, coupled, each edge holding its direction: ``P*'' = -K_P L (P* - shape)``
    on each axis while no push saturates, so the deviations from the shape are the modes of the
    graph's Laplacian ``L`` at ``im_r sqrt(lambda_k)``.  Started 0.2 m off the shape at a common
    velocity, the recorded ``P* = P + tau V`` follows that closed form; momentum is kept."""
    scenario = with_changes(tmem.load(ROOT / "examples/robots/hex19.toml"),
                            {"formation.jitter": 0.2, "formation.bearing": True, "simulation.duration": 20.0})  # fmt: skip
    trajectory = tmem.simulate(scenario)
    tau, k_p = scenario.model.tau, scenario.position_gain
    star = trajectory.state[..., 0] + tau * trajectory.state[..., 1]  # (time, agent, axis)
    edges = trajectory.initial.edges
    n = star.shape[1]
    laplacian = np.zeros((n, n))
    for i, j in edges:
        laplacian[i, j] = laplacian[j, i] = -1.0
        laplacian[i, i] += 1.0
        laplacian[j, j] += 1.0
    shape = generate("hex", n, scenario.interaction.d_t, 2).positions  # where the held directions put them
    assert np.allclose(shape[edges[:, 1]] - shape[edges[:, 0]], scenario.interaction.d_t * trajectory.initial.direction)
    drift = trajectory.time[:, None, None] * np.array([3.0, 0.0])
    deviation = star - drift - shape
    deviation -= deviation[0].mean(axis=0)  # the common shift, kept
    values, vectors = np.linalg.eigh(laplacian)
    omega = IM_R * np.sqrt(np.clip(values, 0.0, None))
    modes0 = vectors.T @ (deviation[0] - deviation[0].mean(axis=0))
    expected = np.einsum("km,tk,ka->tma", vectors.T, np.cos(np.outer(trajectory.time, omega)), modes0)
    assert np.abs(deviation[0]).max() > 0.05  # there is something to follow
    np.testing.assert_allclose(deviation - deviation.mean(axis=1, keepdims=True), expected, atol=2e-3)
    velocity = trajectory.state[..., 1].mean(axis=1)
    np.testing.assert_allclose(velocity, [[3.0, 0.0]] * len(velocity), atol=1e-9)


def test_a_head_on_encounter_matches_the_continuous_reference():
    """The repulsion (8) between two robots on one axis: the engine's exchanged speeds against the
    closed loop integrated in continuous time (scipy), within the step's sampling error."""
    scenario = with_changes(tmem.preset("repulsion"), {"model": {"kind": "ground_robot"}, "interaction.c_max": 0.98,
                                                       "simulation.dt": 0.001})  # fmt: skip
    engine = tmem.simulate(scenario).final_state[:, 0, 1]
    reference = final_state(scenario)[:, 0, 1]
    np.testing.assert_allclose(engine, reference, atol=5e-3)
    assert engine[0] > 2.9 and engine[1] < -1.4  # the speeds were exchanged


def test_the_robot_refuses_a_law_that_asks_more_than_its_drive_and_a_tilt():
    base = tmem.load(ROOT / "examples/robots/fig9.toml")
    with pytest.raises(ScenarioError, match=r"interaction\.c_max: 3 m/s\^2 is more than the ground robot's drive gives"):
        with_changes(base, {"interaction.c_max": 3.0})
    with pytest.raises(ScenarioError, match=r"agents\[1\]\.tilt: the ground robot does not tilt"):
        with_changes(base, {"agents.1.tilt": 0.05})
