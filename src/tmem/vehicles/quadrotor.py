"""A nonlinear quadrotor flown by the TMEM law: the rigid body of :mod:`tmem.vehicles.rigid_body` and its inner loop.

The TMEM law gives each horizontal axis ``a`` its tilt set-point ``U_a``.  The
tilt on axis ``a`` is the angle of the thrust axis ``b_3 = R e_3`` from the
vertical, seen along the other horizontal axis, ``phi_a = atan2(b_3a, b_3z)``.
The vehicle's flight controller (:mod:`tmem.vehicles.flight_controller`) runs every sub-step ``h``
(zero-order hold, as a digital one does) and turns the set-points into rotor speeds: the
attitude, rate and altitude loops (Q5)-(Q7), fed by the *acceleration loop* (Q9)-(Q11) (the
default) or the *tilt loop* with its drag feed-forward (Q8) (``[model] inner_loop = "tilt"``).

The sub-step ``h`` is the longest that divides ``dt`` into whole steps and is
at most ``inner_period``; Ralston's third-order Runge-Kutta method (Ralston, Math. Comp. 16,
431, 1962: the third-order method of least error bound) integrates (Q1)-(Q4) over each
sub-step, and the quaternion is normalised after it, as RotorPy does after each of its steps.
Three evaluations of (Q1)-(Q4) where RK4 takes four: with sub-steps of 10 ms, against RotorPy's
adaptive RK45, positions agree within 5e-7 m and attitudes within 2e-4 deg over 10 s
manoeuvres (RK4: 2e-8 m, 5e-6 deg; ``tests/test_quadrotor.py``, tolerance 1 cm and 0.1 deg),
the error shrinking as the cube of the sub-step; and a sub-step costs 13 % less (docs/vehicles.md, "Speed").

State layout.  The engine keeps each axis's ``(P, V, phi, omega)`` (the TMEM
law reads them) in ``state[i, a, :]`` and the rest of the body in the
per-agent body state ``body[i, :]`` (:data:`BODY_NAMES`).  ``P`` and ``V`` are
the body's own horizontal position and velocity; ``phi`` and ``omega`` are
written from its attitude and body rates after each step: the airframe's own tilt and its
rate, under either loop (the acceleration loop's reference (Q9), the linear agent's tilt, is
kept in the body state).  A 1-D run flies in
the vertical x-z plane: the lateral position and velocity are zero by
symmetry, and not kept.  A 3-D run is refused: the vertical axis is the
altitude hold's.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.scenario.bounds import substeps as count_substeps
from tmem.vehicles.base import VehicleModel
from tmem.vehicles.quadrotor_table import QuadrotorModelParams
from tmem.vehicles.flight_controller import (REFERENCE_FIELDS, REFERENCE_LONG_NAMES, REFERENCE_NAMES, REFERENCE_UNITS, acceleration_loop,
                                advance_reference, initial_reference, rate_loop, reference_hold, tilt_loop,
                                reported_coordinates)
from tmem.vehicles.linear import STATE_NAMES, state_matrices
from tmem.vehicles.rigid_body import Airframe, derivative, derivative_under, hover_speed, loads, rotation
from tmem.vehicles.wind import GUST_LONG_NAMES, GUST_NAMES, GUST_UNITS, WIND_FIELDS, advance_gusts, initial_gusts, wind_fields, wind_now

#: The per-agent body state, after the per-axis ``(P, V, phi, omega)``: the rigid body's, then the
#: gusts of :mod:`tmem.vehicles.wind` from column :data:`GUSTS` (zeros without turbulence), then, with
#: the acceleration loop only, its reference (Q9) from column :data:`REFERENCE`
#: (:data:`ACCELERATION_BODY_NAMES`).
RIGID_BODY_NAMES = ("height", "v_z", "q_x", "q_y", "q_z", "q_w", "w_x", "w_y", "w_z", "rotor_1", "rotor_2", "rotor_3", "rotor_4")
GUSTS = len(RIGID_BODY_NAMES)
BODY_NAMES = RIGID_BODY_NAMES + GUST_NAMES
BODY_UNITS = ("m", "m s-1", "1", "1", "1", "1", "rad s-1", "rad s-1", "rad s-1", "rad s-1", "rad s-1", "rad s-1", "rad s-1",
              *GUST_UNITS)  # fmt: skip
BODY_LONG_NAMES = (
    "height above the start", "vertical velocity",
    "attitude quaternion x", "attitude quaternion y", "attitude quaternion z", "attitude quaternion w",
    "body rate about x", "body rate about y", "body rate about z",
    "speed of rotor 1", "speed of rotor 2", "speed of rotor 3", "speed of rotor 4", *GUST_LONG_NAMES,
)  # fmt: skip
#: The first column of the acceleration loop's reference (Q9), after the gusts.
REFERENCE = len(BODY_NAMES)
ACCELERATION_BODY_NAMES = BODY_NAMES + REFERENCE_NAMES


#: What one step of ``dt`` needs: the airframe's numbers (:class:`~tmem.vehicles.rigid_body.Airframe`'s
#: fields, so that the record serves as the airframe), then the inner loop's gains ``kp``, ``kd``
#: (Q5)-(Q6) (1/s) and ``altitude_kp``, ``altitude_kd`` (Q7) (1/s^2, 1/s), whether the drag
#: feed-forward (Q8) is on, the number of sub-steps in ``dt`` and the sub-step ``h`` (s), whether
#: the acceleration loop (Q9)-(Q11) of :mod:`tmem.vehicles.flight_controller` flies (else the tilt
#: loop), its reference's hold over ``h`` (:data:`~tmem.vehicles.flight_controller.REFERENCE_FIELDS`)
#: and the wind (:data:`tmem.vehicles.wind.WIND_FIELDS`).  One flat record: a parallel loop takes no
#: record nested in another.
QuadrotorStep = NamedTuple(
    "QuadrotorStep",
    [*Airframe.__annotations__.items(), ("kp", float), ("kd", float), ("altitude_kp", float), ("altitude_kd", float),
     ("feedforward", bool), ("substeps", int), ("h", float), ("acceleration", bool), *REFERENCE_FIELDS, *WIND_FIELDS],
)  # fmt: skip


@numba.njit(cache=True, inline="always")
def axis_view(s):
    """``(phi_x, omega_x, phi_y, omega_y)``: each axis's tilt and its rate of change, from the body's state.

    ``phi_a = atan2(b_3a, b_3z)`` and ``omega_a = (b_3z b_3a' - b_3a b_3z') / (b_3a^2 + b_3z^2)``,
    with ``b_3' = w_y b_1 - w_x b_2`` (the columns of ``R``).

    Parameters
    ----------
    s : tuple of 17 float
        The body's state (:mod:`tmem.vehicles.rigid_body`).
    """
    r = rotation(s[6], s[7], s[8], s[9])
    wx, wy = s[10], s[11]
    b3x, b3y, b3z = r[2], r[5], r[8]
    dx, dy, dz = wy * r[0] - wx * r[1], wy * r[3] - wx * r[4], wy * r[6] - wx * r[7]
    return (
        math.atan2(b3x, b3z), (b3z * dx - b3x * dz) / (b3x * b3x + b3z * b3z),
        math.atan2(b3y, b3z), (b3z * dy - b3y * dz) / (b3y * b3y + b3z * b3z),
    )  # fmt: skip


@numba.njit(cache=True, inline="always")
def _plus(s, k, c):
    """``s + c k`` for two body states."""
    return (
        s[0] + c * k[0], s[1] + c * k[1], s[2] + c * k[2], s[3] + c * k[3], s[4] + c * k[4], s[5] + c * k[5],
        s[6] + c * k[6], s[7] + c * k[7], s[8] + c * k[8], s[9] + c * k[9], s[10] + c * k[10],
        s[11] + c * k[11], s[12] + c * k[12], s[13] + c * k[13], s[14] + c * k[14], s[15] + c * k[15],
        s[16] + c * k[16],
    )  # fmt: skip


@numba.njit(cache=True, error_model="numpy")
def substep(s, ref, ux, uy, params, wind):
    """One sub-step ``h``: the flight controller's commands, held, and one step of Ralston's
    third-order method over (Q1)-(Q4) (the module text)::

        k1 = f(s),  k2 = f(s + h k1 / 2),  k3 = f(s + 3 h k2 / 4),  s+ = s + h (2 k1 + 3 k2 + 4 k3) / 9

    Returns the body's state after it, its quaternion normalised.  The state's attitude and the
    wrench on it (:func:`~tmem.vehicles.rigid_body.loads`) serve the flight controller and the
    first slope alike.  It is called, not inlined: the step loop compiles in the same time as the
    linear model's, and a call per sub-step costs little beside its three evaluations of (Q1)-(Q4).

    Parameters
    ----------
    s : tuple of 17 float
        The body's state.
    ref : tuple of 4 float
        The acceleration loop's reference (Q9) now (unread by the tilt loop).
    ux, uy : float
        Tilt set-points ``U`` on x and y (rad).
    params : QuadrotorStep
    wind : tuple of 3 float
        The wind, held over the sub-step (m/s, world frame).
    """
    frame, h = params, params.h
    loaded = loads(s, frame, wind)
    if params.acceleration:
        thrust, rate_x, rate_y, rate_z = acceleration_loop(s, loaded, ref, ux, uy, params)
    else:
        thrust, rate_x, rate_y, rate_z = tilt_loop(s, loaded, ux, uy, params)
    command = rate_loop(s, thrust, rate_x, rate_y, rate_z, params)
    k1 = derivative_under(s, loaded, command, frame)
    k2 = derivative(_plus(s, k1, 0.5 * h), command, frame, wind)
    k3 = derivative(_plus(s, k2, 0.75 * h), command, frame, wind)
    s = _plus(_plus(_plus(s, k1, h * 2.0 / 9.0), k2, h / 3.0), k3, h * 4.0 / 9.0)
    n = 1.0 / math.sqrt(s[6] * s[6] + s[7] * s[7] + s[8] * s[8] + s[9] * s[9])
    return (s[0], s[1], s[2], s[3], s[4], s[5], s[6] * n, s[7] * n, s[8] * n, s[9] * n,
            s[10], s[11], s[12], s[13], s[14], s[15], s[16])  # fmt: skip


@numba.njit(cache=True, error_model="numpy", inline="always")
def step_quadrotor(x, body, u, i, scale, params, n_axes):
    """Advance agent ``i`` over one step with the tilt set-points ``U = u[i] * scale`` and the wind held,
    then draw its gusts of the next step (:mod:`tmem.vehicles.wind`).

    With the acceleration loop, each sub-step's tilt set-points are (Q10)-(Q11)'s from the
    reference (Q9), which advances after it.

    Parameters
    ----------
    x : ndarray, shape (agents, axes, 4)
        Per-axis states ``(P, V, phi, omega)``, changed in place.
    body : ndarray, shape (agents, 20) or (agents, 24)
        Body states (:data:`BODY_NAMES`, or :data:`ACCELERATION_BODY_NAMES`), changed in place.
    u : ndarray, shape (agents, axes)
        Summed tilt set-points (rad).
    i : int
        The agent.
    scale : float
        Saturation factor of ``u[i]`` (:func:`tmem.law.modal.tilt_scale`).
    params : QuadrotorStep
    n_axes : int
        Number of axes, 1 or 2.
    """
    two = n_axes > 1
    ux = u[i, 0] * scale
    uy = u[i, 1] * scale if two else 0.0
    b = body
    s = (x[i, 0, 0], x[i, 1, 0] if two else 0.0, b[i, 0], x[i, 0, 1], x[i, 1, 1] if two else 0.0, b[i, 1],
         b[i, 2], b[i, 3], b[i, 4], b[i, 5], b[i, 6], b[i, 7], b[i, 8], b[i, 9], b[i, 10], b[i, 11], b[i, 12])  # fmt: skip
    wind = wind_now(b, i, GUSTS, params, two)
    acceleration = params.acceleration
    ref = (b[i, REFERENCE], b[i, REFERENCE + 1], b[i, REFERENCE + 2], b[i, REFERENCE + 3]) if acceleration else (0.0,) * 4
    for _ in range(params.substeps):
        s = substep(s, ref, ux, uy, params, wind)
        if acceleration:
            ref = advance_reference(ref, ux, uy, params)
    if acceleration:
        for m in range(4):
            b[i, REFERENCE + m] = ref[m]
    x[i, 0, 0], x[i, 0, 1] = s[0], s[3]
    tilt_x, rate_x, tilt_y, rate_y = axis_view(s)
    x[i, 0, 2], x[i, 0, 3] = tilt_x, rate_x
    if two:
        x[i, 1, 0], x[i, 1, 1], x[i, 1, 2], x[i, 1, 3] = s[1], s[4], tilt_y, rate_y
    b[i, 0], b[i, 1] = s[2], s[5]
    for m in range(11):
        b[i, 2 + m] = s[6 + m]
    if params.turbulent:
        advance_gusts(b, i, GUSTS, params)


def attitude_of_tilts(tilt_x: float, tilt_y: float) -> tuple[float, float, float, float]:
    """The quaternion ``(q_x, q_y, q_z, q_w)`` with these tilts and no yaw.

    It is ``R = R_y(theta) R_x(rho)`` (yaw, pitch, roll = 0, ``theta``, ``rho``): ``theta = phi_x``
    and ``tan(rho) = -tan(phi_y) cos(theta)`` give ``atan2(b_3x, b_3z) = phi_x`` and
    ``atan2(b_3y, b_3z) = phi_y``.

    Parameters
    ----------
    tilt_x, tilt_y : float
        The tilts ``phi_x``, ``phi_y`` (rad), each within (-pi/2, pi/2).
    """
    theta = tilt_x
    rho = -math.atan(math.tan(tilt_y) * math.cos(theta))
    cr, sr, ct, st = math.cos(rho / 2), math.sin(rho / 2), math.cos(theta / 2), math.sin(theta / 2)
    return sr * ct, cr * st, -sr * st, cr * ct


class QuadrotorModel(VehicleModel):
    """A nonlinear quadrotor (the Crazyflie 2.x by default) under its inner loop: the acceleration
    loop (Q9)-(Q11) with (Q5)-(Q7) (:mod:`tmem.vehicles.flight_controller`), or the tilt loop (Q5)-(Q8).

    Parameters
    ----------
    params
        The scenario's ``[model]`` table, :class:`~tmem.vehicles.quadrotor_table.QuadrotorModelParams`.
    wind
        The scenario's ``[wind]`` table, :class:`~tmem.scenario.wind_table.WindParams` (default: none).
    """

    kind = "quadrotor"
    state_names = STATE_NAMES
    state_units = ("m", "m s-1", "rad", "rad s-1")
    long_names = ("position", "velocity", "tilt of the thrust axis from the vertical along the axis", "tilt rate")
    body_names = BODY_NAMES
    body_units = BODY_UNITS
    body_long_names = BODY_LONG_NAMES
    table = QuadrotorModelParams

    @classmethod
    def kernel(cls):
        """The compiled step :func:`step_quadrotor`."""
        return step_quadrotor

    def __init__(self, params: Any, wind: Any = None):
        super().__init__(params)
        self.wind = wind
        if params.inner_loop == "acceleration":
            self.body_names = ACCELERATION_BODY_NAMES
            self.body_units = BODY_UNITS + REFERENCE_UNITS
            self.body_long_names = BODY_LONG_NAMES + REFERENCE_LONG_NAMES

    def airframe(self) -> Airframe:
        """The rigid body's numbers, from the ``[model]`` table."""
        p = self.params
        return Airframe(p.mass, p.g, p.ixx, p.iyy, p.izz, p.arm_length / math.sqrt(2.0), p.k_eta, p.k_m,
                        p.rotor_drag, p.inflow_drag, p.c_dx, p.c_dy, p.c_dz, p.tau_m, p.rotor_speed_max)  # fmt: skip

    def linearisation(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` on the x axis at hover, with the inner loop closed and the motors' lag taken to 0.

        The gains are designed on the vehicle as the TMEM law flies it, so that its roots are
        (5) on the vehicle itself.  At hover, rotor drag slows the velocity by
        ``c_h = 4 k_d o_h / m`` and the rotors' inflow damps the body rate by
        ``c_r = 4 k_z o_h a^2 / I_yy`` (``o_h``: hover rotor speed; ``a``: the hubs' offset); the
        frame's drag is quadratic and adds nothing; the drag feed-forward (Q8) adds
        ``c_h V / g`` to the set-point::

            A = [[0, 1, 0, 0], [0, -c_h, g, 0], [0, 0, 0, 1], [0, f kp kd c_h / g, -kp kd, -kd - c_r]]
            B = [0, 0, 0, kp kd]^T                (f = 1 with the feed-forward, else 0)

        Without drag it is (2) exactly.  The y axis has ``I_xx`` for ``I_yy``: the same for a
        symmetric frame (the Crazyflie's).  ``tests/test_quadrotor.py`` checks it against finite
        differences of (Q1)-(Q8).

        That is the tilt loop's.  The acceleration loop (Q9)-(Q11) makes the airframe move as
        (2), and the law reads (2)'s state in the airframe's coordinates
        (:func:`~tmem.vehicles.flight_controller.reported_coordinates`): ``(T A_2 T^-1, T B_2)``
        with ``(A_2, B_2)`` of (2), and ``T B_2 = B_2``::

            A = [[0, 1, 0, 0], [0, -c_h, g, 0], [0, 0, 0, 1], [0, k c_h / g, -k, -kd + c_h]]
            B = [0, 0, 0, kp kd]^T                (k = kp kd - kd c_h + c_h^2)

        ``tests/test_flight_controller.py`` checks it against finite differences of
        (Q1)-(Q7), (Q9)-(Q11).
        """
        p, frame = self.params, self.airframe()
        hover = hover_speed(frame)
        c_h = 4.0 * p.rotor_drag * hover / p.mass
        if p.inner_loop == "acceleration":
            t = reported_coordinates(c_h, p.g)
            a2, b2 = state_matrices(p.kp, p.kd, p.g)
            return t @ a2 @ np.linalg.inv(t), t @ b2
        c_r = 4.0 * p.inflow_drag * hover * frame.offset**2 / p.iyy
        feedforward = p.kp * p.kd * c_h / p.g if p.drag_feedforward else 0.0
        a = np.array(
            [
                [0.0, 1.0, 0.0, 0.0],
                [0.0, -c_h, p.g, 0.0],
                [0.0, 0.0, 0.0, 1.0],
                [0.0, feedforward, -p.kp * p.kd, -p.kd - c_r],
            ]
        )
        return a, np.array([0.0, 0.0, 0.0, p.kp * p.kd])

    def step_params(self, dt: float) -> QuadrotorStep:
        """The airframe, the gains and the sub-steps of ``dt``: as many as keep each at most ``inner_period``.

        Parameters
        ----------
        dt : float
            The time step (s).
        """
        p = self.params
        substeps = count_substeps(dt, p.inner_period)
        acceleration = p.inner_loop == "acceleration"
        return QuadrotorStep(*self.airframe(), p.kp, p.kd, p.altitude_kp, p.altitude_kd, p.drag_feedforward and not acceleration,
                             substeps, dt / substeps, acceleration, *reference_hold(p.kp, p.kd, dt / substeps),
                             *wind_fields(self.wind, dt))  # fmt: skip

    def initial_body(self, state: np.ndarray) -> np.ndarray:
        """Body states for per-axis states: at height 0, not climbing, yaw 0, rotors carrying the weight.

        The attitude has each axis's tilt (:func:`attitude_of_tilts`), the body rates give each
        axis's tilt rate (:func:`axis_view` inverted) with no yaw rate; the gusts are each agent's
        first (:func:`tmem.vehicles.wind.initial_gusts`: ``state`` in the scenario's order of agents);
        the acceleration loop's reference is the one whose thrust's tilt is the airframe's, in the
        wind of its first step (:func:`~tmem.vehicles.flight_controller.initial_reference`).

        Parameters
        ----------
        state : ndarray, shape (agents, axes, 4)

        Raises
        ------
        ValueError
            Where a tilt is not within +-pi/2 (a tilt of the thrust axis along an axis,
            ``atan2(b_3a, b_3z)``, lies there), in one line naming the agent and the axis.
        """
        tilts = np.asarray(state)[:, :, 2]
        outside = ~(np.abs(tilts) < 0.5 * math.pi)  # NaN too
        if outside.any():
            i, a = (int(k) for k in np.argwhere(outside)[0])
            raise ValueError(f"state: the tilt of agent {i} on axis {a} is {tilts[i, a]!r} rad; a tilt of the thrust "
                             "axis along an axis, atan2(b_3a, b_3z), lies within +-pi/2 = 1.571 rad")  # fmt: skip
        frame = self.airframe()
        body = np.zeros((state.shape[0], len(self.body_names)))
        for i, agent in enumerate(state):
            tilt_y, rate_y = (agent[1, 2], agent[1, 3]) if len(agent) > 1 else (0.0, 0.0)
            q = attitude_of_tilts(agent[0, 2], tilt_y)
            rest = (0.0,) * 6 + q
            # The tilt rates are linear in (w_x, w_y): solve for the body rates that give them.
            by_x, by_y = (np.array(axis_view(rest + (w_x, w_y, 0.0, 0.0, 0.0, 0.0, 0.0))[1::2]) for w_x, w_y in ((1.0, 0.0), (0.0, 1.0)))
            w = np.linalg.solve(np.column_stack([by_x, by_y]), [agent[0, 3], rate_y])
            b3z = rotation(*q)[8]
            body[i, 2:6] = q
            body[i, 6:8] = w
            body[i, 9:GUSTS] = math.sqrt(frame.mass * frame.g / (4.0 * frame.k_eta * b3z))
        body[:, GUSTS:REFERENCE] = initial_gusts(self.wind, len(state))
        if self.params.inner_loop == "acceleration":
            params = self.step_params(self.params.inner_period)
            for i, agent in enumerate(state):
                two = len(agent) > 1
                s = (agent[0, 0], 0.0, 0.0, agent[0, 1], agent[1, 1] if two else 0.0, 0.0, *body[i, 2:GUSTS])
                tilts, rates = (agent[:, 2], agent[:, 3]) if two else ((agent[0, 2], 0.0), (agent[0, 3], 0.0))
                wind = wind_now(body, i, GUSTS, params, two)
                body[i, REFERENCE:] = initial_reference(s, tuple(tilts), tuple(rates), frame, frame.g, wind)
        return body
