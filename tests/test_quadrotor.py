"""The quadrotor model (tmem.vehicles.quadrotor) against RotorPy, its linearisation against (2), and its symmetries.

RotorPy (``rotorpy.vehicles.multirotor.Multirotor``, MIT) integrates the same
Crazyflie with scipy's adaptive Runge-Kutta from its own equations; it is fed
the commands of tmem's flight controller, under either inner loop (collective
thrust and body rates, its ``cmd_ctbr`` abstraction with ``k_w = kd``), computed
from RotorPy's own state at every inner-loop period.  What is compared is the rigid body, the
rotors, their allocation and lag, and the integration.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tmem.vehicles.flight_controller import acceleration_loop, advance_reference, initial_reference, rate_loop, tilt_loop
from tmem.vehicles.quadrotor import GUSTS, QuadrotorModel, axis_view, step_quadrotor
from tmem.vehicles.rigid_body import derivative, hover_speed, loads
from tmem.vehicles.linear import state_matrices
from tmem.scenario import QuadrotorModelParams

#: The inner period of the comparison with RotorPy (s): one sub-step per step.
PERIOD = 0.01
DURATION = 10.0

#: Tilt set-points ``(U_x, U_y)`` (rad) over time (s).  RotorPy takes 3 to 8 s a manoeuvre here: the
#: two that exercise both axes and a varying command run always under the tilt loop, one under the
#: acceleration loop, the others with ``-m slow`` (docs/scripts/vehicles.py prints the errors of all five).
MANOEUVRES = {
    "hover": lambda t: (0.0, 0.0),
    "step x": lambda t: (0.1 if t >= 1.0 else 0.0, 0.0),
    "step y": lambda t: (0.0, -0.1 if t >= 1.0 else 0.0),
    "sine x": lambda t: (0.1 * math.sin(2.0 * math.pi * 0.5 * t), 0.0),
    "step both": lambda t: (0.07 if t >= 1.0 else 0.0, 0.05 if t >= 2.0 else 0.0),
}
ALWAYS = (("sine x", "tilt"), ("step both", "tilt"), ("step both", "acceleration"))
#: No wind (m/s).
CALM = (0.0, 0.0, 0.0)


def quadrotor(**changes) -> QuadrotorModel:
    """The tilt loop (Q5)-(Q8), unless ``changes`` say otherwise (tests/test_flight_controller.py: the acceleration loop)."""
    return QuadrotorModel(QuadrotorModelParams(**{"kind": "quadrotor", "inner_loop": "tilt", **changes}))


def packed(x: np.ndarray, body: np.ndarray) -> tuple:
    """The 17-number body state of agent 0 of a 2-D run."""
    b = body[0]
    return (x[0, 0, 0], x[0, 1, 0], b[0], x[0, 0, 1], x[0, 1, 1], b[1], *b[2:GUSTS])


def fly_tmem(model: QuadrotorModel, setpoint, start: np.ndarray) -> np.ndarray:
    """The body states (17) at every step of the compiled model flying ``setpoint(t)``."""
    params = model.step_params(PERIOD)
    x, body = start.copy(), model.initial_body(start)
    u = np.zeros((1, 2))
    states = [packed(x, body)]
    for k in range(round(DURATION / PERIOD)):
        u[0] = setpoint(k * PERIOD)
        step_quadrotor(x, body, u, 0, 1.0, params, 2)
        states.append(packed(x, body))
    return np.array(states)


def fly_rotorpy(model: QuadrotorModel, setpoint, first: np.ndarray, wind=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The same with RotorPy's ``Multirotor`` and its own integration, from the same state, in
    RotorPy's ``ConstantWind`` ``wind`` (m/s, world frame)."""
    multirotor = pytest.importorskip("rotorpy.vehicles.multirotor")
    from rotorpy.vehicles.crazyflie_params import quad_params
    from rotorpy.wind.default_winds import ConstantWind

    air = ConstantWind(*wind)

    p = model.params
    assert (p.mass, p.ixx, p.izz, p.k_eta, p.k_m, p.tau_m) == tuple(quad_params[k] for k in ("mass", "Ixx", "Izz", "k_eta", "k_m", "tau_m"))
    vehicle = multirotor.Multirotor(dict(quad_params, k_w=p.kd), control_abstraction="cmd_ctbr", aero=True,
                                    integrator_kwargs={"method": "RK45", "rtol": 1e-7, "atol": 1e-9})  # fmt: skip
    state = {"x": first[0:3], "v": first[3:6], "q": first[6:10], "w": first[10:13], "wind": np.zeros(3), "rotor_speeds": first[13:]}
    params = model.step_params(PERIOD)
    states = [first]
    if params.acceleration:  # the reference (Q9) starts as the model's own does (QuadrotorModel.initial_body)
        tilts = axis_view(tuple(first))
        ref = tuple(initial_reference(tuple(first), tilts[0::2], tilts[1::2], params, p.g, tuple(air.update(0.0, first[:3]))))
    for k in range(round(DURATION / PERIOD)):
        s = tuple(np.concatenate([state["x"], state["v"], state["q"], state["w"], state["rotor_speeds"]]))
        state["wind"] = air.update(k * PERIOD, state["x"])  # as RotorPy's Environment sets it
        loaded, u = loads(s, params, tuple(state["wind"])), setpoint(k * PERIOD)
        if params.acceleration:
            thrust, *rates = acceleration_loop(s, loaded, ref, *u, params)
            ref = advance_reference(ref, *u, params)
        else:
            thrust, *rates = tilt_loop(s, loaded, *u, params)
        state = vehicle.step(state, {"cmd_thrust": thrust, "cmd_w": np.array(rates)}, PERIOD)
        states.append(np.concatenate([state["x"], state["v"], state["q"], state["w"], state["rotor_speeds"]]))
    return np.array(states)


@pytest.mark.parametrize(("name", "inner_loop"), [
    (n, loop) if (n, loop) in ALWAYS else pytest.param(n, loop, marks=pytest.mark.slow)
    for n in MANOEUVRES for loop in ("tilt", "acceleration")
])  # fmt: skip
def test_the_compiled_quadrotor_flies_as_rotorpy_integrates_it(name, inner_loop):
    model = quadrotor(inner_period=PERIOD, inner_loop=inner_loop)
    start = np.zeros((1, 2, 4))
    start[0, :, 1] = (1.0, -0.5)  # under way, so that the drag and its feed-forward are at work
    ours = fly_tmem(model, MANOEUVRES[name], start)
    theirs = fly_rotorpy(model, MANOEUVRES[name], ours[0])
    position_error = np.max(np.linalg.norm(ours[:, :3] - theirs[:, :3], axis=1))
    dot = np.abs(np.sum(ours[:, 6:10] * theirs[:, 6:10], axis=1) / np.linalg.norm(theirs[:, 6:10], axis=1))
    attitude_error = np.degrees(np.max(2.0 * np.arccos(np.minimum(dot, 1.0))))
    assert position_error < 0.01 and attitude_error < 0.1, (position_error, attitude_error)
    moved = np.linalg.norm(ours[-1, :2] - ours[0, :2])
    assert moved > 1.0  # the comparison is not of two vehicles standing still


def axis_derivative(model: QuadrotorModel, axis: int, x: np.ndarray, u: float) -> np.ndarray:
    """``(P, V, phi, omega)'`` on ``axis`` of (Q1)-(Q8) with the rotors at their command (lag -> 0)."""
    state = np.zeros((1, 2, 4))
    state[0, axis] = x
    s = packed(state, model.initial_body(state))
    params = model.step_params(model.params.inner_period)
    for _ in range(20):  # the rotors at their command: a fixed point (the feed-forward reads their drag)
        command = rate_loop(s, *tilt_loop(s, loads(s, params, CALM), *((u, 0.0) if axis == 0 else (0.0, u)), params), params)
        s = s[:13] + command
    slope = np.array(derivative(s, command, params, CALM))
    eps = 1e-6

    def view(t):  # (P, V, phi, omega) on the axis
        return np.array([t[axis], t[3 + axis], *axis_view(tuple(t))[2 * axis : 2 * axis + 2]])

    return (view(np.array(s) + eps * slope) - view(np.array(s) - eps * slope)) / (2 * eps)


def numerical_linearisation(model: QuadrotorModel, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` by central differences of :func:`axis_derivative` about hover."""
    delta = 1e-5
    columns = [(axis_derivative(model, axis, delta * e, 0.0) - axis_derivative(model, axis, -delta * e, 0.0)) / (2 * delta)
               for e in np.eye(4)]  # fmt: skip
    b = (axis_derivative(model, axis, np.zeros(4), delta) - axis_derivative(model, axis, np.zeros(4), -delta)) / (2 * delta)
    return np.column_stack(columns), b


@pytest.mark.parametrize("axis", [0, 1])
def test_without_drag_the_quadrotor_at_hover_is_the_papers_model_2(axis):
    model = quadrotor(rotor_drag=0.0, inflow_drag=0.0, tau_m=1e-6)
    a, b = numerical_linearisation(model, axis)
    a2, b2 = state_matrices(6.0, 25.0, 9.81)
    np.testing.assert_allclose(a, a2, atol=1e-4)
    np.testing.assert_allclose(b, b2, atol=1e-4)
    np.testing.assert_array_equal(model.linearisation()[0], a2)  # "Without drag it is (2) exactly" (its docstring)


@pytest.mark.parametrize("feedforward", [True, False])
def test_the_linearisation_the_gains_are_designed_on_is_the_vehicles_at_hover(feedforward):
    model = quadrotor(drag_feedforward=feedforward, kp=4.0, kd=30.0)
    a, b = numerical_linearisation(model, 0)
    expected_a, expected_b = model.linearisation()
    np.testing.assert_allclose(a, expected_a, atol=1e-4)
    np.testing.assert_allclose(b, expected_b, atol=1e-4)
    assert a[1, 1] < -0.1  # the Crazyflie's rotor drag is in it
    np.testing.assert_allclose(numerical_linearisation(model, 1)[0], a, atol=1e-4)  # a symmetric frame


def test_at_hover_the_rotors_turn_at_the_speed_that_carries_the_weight_and_nothing_moves():
    model = quadrotor()
    start = np.zeros((1, 2, 4))
    body = model.initial_body(start)
    np.testing.assert_allclose(body[0, 9:GUSTS], math.sqrt(0.03 * 9.81 / (4 * 2.3e-8)))
    assert hover_speed(model.airframe()) == pytest.approx(1788.53, abs=0.05)  # RotorPy's hover speed, rounded
    x, params = start.copy(), model.step_params(0.01)
    for _ in range(100):
        step_quadrotor(x, body, np.zeros((1, 2)), 0, 1.0, params, 2)
    assert np.max(np.abs(x)) < 1e-12 and np.max(np.abs(body[0, :2])) < 1e-12


def test_the_initial_attitude_has_each_axis_tilt_and_rate():
    from scipy.spatial.transform import Rotation

    model = quadrotor()
    state = np.zeros((1, 2, 4))
    state[0, :, 2], state[0, :, 3] = (0.3, -0.2), (0.5, 0.7)
    body = model.initial_body(state)
    b3 = Rotation.from_quat(body[0, 2:6]).apply([0.0, 0.0, 1.0])
    np.testing.assert_allclose(np.arctan2(b3[:2], b3[2]), [0.3, -0.2], atol=1e-12)
    np.testing.assert_allclose(Rotation.from_quat(body[0, 2:6]).as_euler("ZYX")[0], 0.0, atol=1e-12)  # no yaw
    view = axis_view(packed(state, body))
    np.testing.assert_allclose(view[1::2], [0.5, 0.7], atol=1e-12)
