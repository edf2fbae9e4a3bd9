"""The acceleration inner loop (tmem.vehicles.flight_controller): its reference against the closed form of (1),
its linearisation at hover against the paper's (2), the airframe flying (2)'s trajectory, and (slow) Fig. 9 and the hex."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

import tmem
from tmem.analysis.metrics import formation_summary, summarize
from tmem.vehicles.flight_controller import acceleration_loop, advance_reference
from tmem.vehicles.linear import state_matrices
from tmem.vehicles.flight_controller import rate_loop
from tmem.vehicles.quadrotor import GUSTS, REFERENCE, QuadrotorModel, axis_view, step_quadrotor
from tmem.vehicles.rigid_body import derivative, loads
from tmem.scenario import QuadrotorModelParams, WindParams

CALM = (0.0, 0.0, 0.0)


def quadrotor(**changes) -> QuadrotorModel:
    return QuadrotorModel(QuadrotorModelParams(kind="quadrotor", inner_loop="acceleration", **changes))


def test_the_reference_is_the_step_response_of_the_papers_attitude_model_1():
    kp, kd = 6.0, 25.0
    params = quadrotor(kp=kp, kd=kd).step_params(0.001)
    # phi'' + kd phi' + kp kd phi = kp kd U: roots p, q; from rest, phi = U (1 + (q e^pt - p e^qt) / (p - q)).
    root = math.sqrt(kd * kd - 4.0 * kp * kd)
    p, q = (-kd + root) / 2.0, (-kd - root) / 2.0
    ref, ux, uy = (0.0, 0.0, 0.0, 0.0), 0.08, -0.05
    worst = 0.0
    for k in range(1, 2001):
        ref = advance_reference(ref, ux, uy, params)
        t = k * params.h
        shape = 1.0 + (q * math.exp(p * t) - p * math.exp(q * t)) / (p - q)
        rate = p * q * (math.exp(p * t) - math.exp(q * t)) / (p - q)
        worst = max(worst, *np.abs(np.array(ref) - np.array([ux * shape, ux * rate, uy * shape, uy * rate])))
    assert worst < 1e-12, worst  # round-off over 2000 holds
    assert abs(ref[0] - ux) < 1e-6  # settled after 2 s: the roots are -10 and -15 /s


def closed_loop_slope(model: QuadrotorModel, axis: int, y: np.ndarray, u: float) -> np.ndarray:
    """``(P, V, phi, omega, phi_r, omega_r)'`` on ``axis`` under (Q1)-(Q7), (Q9)-(Q11), the rotors at their command."""
    state = np.zeros((1, 2, 4))
    state[0, axis] = y[:4]
    body = model.initial_body(state)
    s = (state[0, 0, 0], state[0, 1, 0], 0.0, state[0, 0, 1], state[0, 1, 1], 0.0, *body[0, 2:GUSTS])
    ref = [0.0] * 4
    ref[2 * axis : 2 * axis + 2] = y[4:]
    setpoint = (u, 0.0) if axis == 0 else (0.0, u)
    params = model.step_params(model.params.inner_period)
    for _ in range(30):  # the rotors at their command: a fixed point (the set-points read their drag)
        command = rate_loop(s, *acceleration_loop(s, loads(s, params, CALM), tuple(ref), *setpoint, params), params)
        s = s[:13] + command
    slope = np.array(derivative(s, command, params, CALM))
    eps = 1e-6

    def view(t):  # (P, V, phi, omega) on the axis
        return np.array([t[axis], t[3 + axis], *axis_view(tuple(t))[2 * axis : 2 * axis + 2]])

    airframe = (view(np.array(s) + eps * slope) - view(np.array(s) - eps * slope)) / (2 * eps)
    kp, kd = model.params.kp, model.params.kd
    return np.array([*airframe, y[5], kp * kd * (u - y[4]) - kd * y[5]])


def closed_loop_matrices(model: QuadrotorModel, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of the six states by central differences of :func:`closed_loop_slope` about hover."""
    delta = 1e-5
    columns = [(closed_loop_slope(model, axis, delta * e, 0.0) - closed_loop_slope(model, axis, -delta * e, 0.0)) / (2 * delta)
               for e in np.eye(6)]  # fmt: skip
    b = (closed_loop_slope(model, axis, np.zeros(6), delta) - closed_loop_slope(model, axis, np.zeros(6), -delta)) / (2 * delta)
    return np.column_stack(columns), b


@pytest.mark.parametrize("axis", [0, 1])
def test_without_drag_the_airframe_under_the_acceleration_loop_is_the_papers_model_2(axis):
    model = quadrotor(rotor_drag=0.0, inflow_drag=0.0)
    a, b = closed_loop_matrices(model, axis)
    a2, b2 = state_matrices(6.0, 25.0, 9.81)
    np.testing.assert_allclose(a[:4, :4], a2, atol=1e-4)  # (P, V, phi, omega) move as (2) ...
    np.testing.assert_allclose(a[:4, 4:], 0.0, atol=1e-4)  # ... whatever the reference does
    np.testing.assert_allclose(b[:4], b2, atol=1e-4)
    np.testing.assert_array_equal(model.linearisation()[0], a2)  # (2) exactly without drag, as its docstring says


@pytest.mark.parametrize("axis", [0, 1])
def test_with_the_crazyflies_drag_the_law_reads_model_2_through_the_drags_tilt(axis):
    model = quadrotor()
    frame = model.airframe()
    c_h = 4.0 * frame.k_d * math.sqrt(frame.mass * frame.g / (4.0 * frame.k_eta)) / frame.mass
    a2, b2 = state_matrices(6.0, 25.0, 9.81)
    # The airframe's tilt is (2)'s plus the tilt that balances the drag, c_h V / g; its rate follows.
    t = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, c_h / 9.81, 1, 0], [0, 0, c_h, 1]])
    a, b = closed_loop_matrices(model, axis)
    for s in (0.55j, 1.0 + 2.0j, 5.0j, 3.0):
        seen = np.linalg.solve(s * np.eye(6) - a, b)[:4]  # U to what the law reads
        np.testing.assert_allclose(seen, t @ np.linalg.solve(s * np.eye(4) - a2, b2), rtol=1e-4, atol=1e-7)
        position = 9.81 * 150.0 / (s * s * (s * s + 25.0 * s + 150.0))  # (2)'s g kp kd / (s^2 (s^2 + kd s + kp kd))
        assert abs(seen[0] - position) < 1e-4 * abs(position)
    linear_a, linear_b = model.linearisation()
    np.testing.assert_allclose(linear_a, t @ a2 @ np.linalg.inv(t), atol=1e-12)
    np.testing.assert_allclose(linear_b, b2, atol=1e-12)
    assert c_h > 0.2  # the drag is there to be cancelled


@pytest.mark.parametrize("wind", [None, [2.0, -1.0]], ids=["calm", "in a constant wind"])
def test_the_crazyflie_flies_the_trajectory_of_model_2(wind):
    params = QuadrotorModelParams(kind="quadrotor", inner_loop="acceleration")
    model = QuadrotorModel(params) if wind is None else QuadrotorModel(params, WindParams(velocity=wind))
    a2, b2 = state_matrices(6.0, 25.0, 9.81)
    x = np.zeros((1, 2, 4))
    x[0, :, 1] = (3.0, -1.5)
    x[0, :, 2] = np.arctan(0.2444 * x[0, :, 1] / 9.81)  # about the tilt that balances the drag
    body, params, u = model.initial_body(x), model.step_params(0.002), np.array([[0.04, 0.02]])
    start = body[0, REFERENCE:].copy()
    for _ in range(2500):
        step_quadrotor(x, body, u, 0, 1.0, params, 2)
    for axis in (0, 1):  # (2) from the same start, 5 s of U held: its exact solution
        y0 = np.array([0.0, 3.0 if axis == 0 else -1.5, *start[2 * axis : 2 * axis + 2], u[0, axis]])
        exact = expm(np.block([[a2, b2[:, None]], [np.zeros((1, 5))]]) * 5.0) @ y0
        assert abs(x[0, axis, 0] - exact[0]) < 0.02, (x[0, axis, 0], exact[0])  # of some 20 m flown
        assert abs(x[0, axis, 1] - exact[1]) < 0.003, (x[0, axis, 1], exact[1])
        np.testing.assert_allclose(body[0, REFERENCE + 2 * axis : REFERENCE + 2 * axis + 2], exact[2:4], atol=1e-9)
    assert abs(body[0, 0]) < 0.01  # the height held


EXAMPLES = Path(__file__).parent.parent / "examples"


@pytest.mark.slow
def test_fig9_on_the_crazyflie_gains_what_it_gains_on_model_2():
    linear = summarize(tmem.simulate(tmem.load(EXAMPLES / "fig9.toml")))
    flown = summarize(tmem.simulate(tmem.load(EXAMPLES / "vehicles" / "fig9.toml")))
    pair, reference = flown["pairs"][0], linear["pairs"][0]
    assert abs(pair["coupled_at"] - reference["coupled_at"]) < 0.1
    assert 29.0 < pair["uncoupled_at"] < 31.0 and pair["separated_at"] is not None
    assert abs(flown["rms_change_percent"] - linear["rms_change_percent"]) < 0.5


@pytest.mark.slow
def test_the_hex_on_the_crazyflie_keeps_every_edge_within_2_m():
    error = formation_summary(tmem.simulate(tmem.load(EXAMPLES / "vehicles" / "hex19.toml")))["distance_error"]
    assert error["max"] < 2.0
