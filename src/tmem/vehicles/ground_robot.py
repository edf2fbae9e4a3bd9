"""A holonomic ground robot flown by the TMEM law: a double integrator with a first-order drive.

The first vehicle that does not fly by tilting.  On each horizontal axis the robot's state is
``x = (P, V, a)``: position (m), velocity (m/s) and the acceleration its drive gives (m/s^2).
The law's set-point ``U`` is the acceleration asked of the drive (m/s^2); the drive follows it
with the lag ``tau`` and gives at most ``a_max`` (on the norm over the axes)::

    P' = V,   V' = a,   a' = (sat(U) - a) / tau,   |sat(U)| <= a_max                        (R1)

so that, linear while ``|U| <= a_max``, ``A = [[0, 1, 0], [0, 0, 1], [0, 0, -1/tau]]`` and
``B = [0, 0, 1/tau]^T``.

The law's gains place the drive's own root ``-1/tau`` and the undamped pair ``+- i im_r`` of (5)::

    K = im_r^2 (1, tau, 0),   P* = P + tau V   (6)                                          (R2)

so that ``P*' = V + tau a`` and ``P*'' = a + tau a' = U``: the law sees a double integrator, and
an agent pushed by ``c`` neighbours with the law's spring, ``U = -c K x + const``, has the loop
``(s + 1/tau)(s^2 + c im_r^2)`` — its slow pair undamped for any ``c``::

    det(sI - A + c B K) = (s + 1/tau)(s^2 + c im_r^2)                                       (R3)

A pair's encounter (``c = 2`` in its relative state, (S1)) is then lossless while the pushes stay
below ``c_max``, and a crowd does not heat (the tilting multirotor needs the mean of pushes (C1)
for that).  Another fast root than the drive's would feed the acceleration back, ``K_a != 0``, and
move the pair's slow roots off the axis: with ``r_l = 12 /s`` placed instead, a head-on encounter
of ``docs/reproduction.md``'s repulsion changes the RMS velocity by -0.66 % at ``tau = 0.1 s`` and
+51 % at ``tau = 0.02 s`` (+0.04 % with (R2) at any ``tau``).  So ``r_l`` and ``im_l`` of the
``[controller]`` table are not used for the robot.  The law's tilt limit ``c_max`` is, for the
robot, the largest acceleration the law asks for (m/s^2); it may not exceed ``a_max``.  The robot
is stepped exactly: the zero-order hold of (R1) over ``dt`` (Van Loan's method, as the linear
multirotor is), with ``U`` saturated at ``a_max`` before the step.
"""

from __future__ import annotations

from functools import cache
from typing import ClassVar, Literal, NamedTuple

import numpy as np

from tmem.scenario.fields import FieldError, Positive, StrictModel
from tmem.vehicles.base import VehicleModel
from tmem.vehicles.linear import zero_order_hold


class GroundRobotParams(StrictModel):
    """A holonomic ground robot, ``[model] kind = "ground_robot"`` (:mod:`tmem.vehicles.ground_robot`):
    the drive's lag ``tau`` (s) and its largest acceleration ``a_max`` (m/s^2)."""

    kind: Literal["ground_robot"]
    tau: Positive = 0.1
    a_max: Positive = 2.0

    #: The most axes a run of this model may have.
    max_axes: ClassVar[int] = 3

    def position_gain(self, r_l: float, im_l: float, im_r: float) -> float:
        """``K_P`` of (R2): ``im_r^2`` (the drive's root takes the place of ``r_l`` and ``im_l``).

        Parameters
        ----------
        r_l, im_l, im_r : float
            The roots (5) (1/s); only ``im_r`` is used.
        """
        return im_r**2

    def largest_acceleration(self, c_max: float) -> float:
        """The largest acceleration (m/s^2) the law asks for: ``c_max``, within what the drive gives.

        Parameters
        ----------
        c_max : float
            The law's limit (m/s^2).
        """
        return min(c_max, self.a_max)

    def check(self, scenario) -> None:
        """The law asks at most what the drive gives (``interaction.c_max <= a_max``), and the agents
        start with their drive at rest (no tilt: the robot has none).

        Parameters
        ----------
        scenario : Scenario
            The whole scenario.
        """
        c_max = scenario.interaction.c_max
        if c_max > self.a_max:
            raise FieldError("interaction.c_max", f"{c_max:g} m/s^2 is more than the ground robot's drive gives, "
                             f"model.a_max = {self.a_max:g} m/s^2")  # fmt: skip
        for k, agent in enumerate(scenario.agents):
            if np.any(np.asarray(agent.tilt) != 0.0) or np.any(np.asarray(agent.tilt_rate) != 0.0):
                field = "tilt" if np.any(np.asarray(agent.tilt) != 0.0) else "tilt_rate"
                raise FieldError(f"agents[{k}].{field}", "the ground robot does not tilt: its drive starts at rest")


class DriveStep(NamedTuple):
    """What one step needs: the zero-order hold of (R1), ``x <- Ad x + Bd U``, and the drive's limit."""

    ad: np.ndarray
    bd: np.ndarray
    a_max: float


def _step(x, body, u, i, scale, params, n_axes):
    """Advance robot ``i`` over one step: ``U = u[i] * scale`` saturated on its norm at ``a_max``, held (R1)."""
    norm2 = 0.0
    for a in range(n_axes):
        norm2 += (u[i, a] * scale) ** 2
    limit = min(1.0, params.a_max / np.sqrt(norm2)) if norm2 > 0.0 else 1.0
    ad, bd = params.ad, params.bd
    for a in range(n_axes):
        p, v, acc, w = x[i, a, 0], x[i, a, 1], x[i, a, 2], u[i, a] * scale * limit
        x[i, a, 0] = ad[0, 0] * p + ad[0, 1] * v + ad[0, 2] * acc + bd[0] * w
        x[i, a, 1] = ad[1, 0] * p + ad[1, 1] * v + ad[1, 2] * acc + bd[1] * w
        x[i, a, 2] = ad[2, 0] * p + ad[2, 1] * v + ad[2, 2] * acc + bd[2] * w


class GroundRobot(VehicleModel):
    """A holonomic ground robot (module text): ``[model] kind = "ground_robot"``."""

    kind = "ground_robot"
    table = GroundRobotParams
    state_names = ("P", "V", "a")
    state_units = ("m", "m s-1", "m s-2")
    long_names = ("position", "velocity", "acceleration of the drive")
    law_states = 3
    input_name = "acceleration asked of the drive"
    input_units = "m s-2"

    @classmethod
    @cache
    def kernel(cls):
        """The compiled step :func:`_step`, the exact zero-order hold of (R1) (compiled on first use)."""
        import numba

        return numba.njit(inline="always", error_model="numpy")(_step)

    def linearisation(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` of (R1) on ``(P, V, a)``, the asked acceleration as input."""
        tau = self.params.tau
        a = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0 / tau]])
        return a, np.array([0.0, 0.0, 1.0 / tau])

    def gains(self, r_l: float, im_l: float, im_r: float) -> np.ndarray:
        """``K = im_r^2 (1, tau, 0)`` placing the drive's root ``-1/tau`` and ``-+ i im_r`` (R2); ``r_l``
        and ``im_l`` are not used (module text).

        Parameters
        ----------
        r_l, im_l, im_r : float
            The roots (5) (1/s).
        """
        return self.params.position_gain(r_l, im_l, im_r) * np.array([1.0, self.params.tau, 0.0])

    @classmethod
    def initial_state(cls, state: np.ndarray) -> np.ndarray:
        """``(P, V, a)`` from the scenario's starts: the drive at rest (the table refuses a tilt).

        Parameters
        ----------
        state : ndarray, shape (agents, axes, 4)
        """
        robot = np.zeros(state.shape[:2] + (3,))
        robot[..., :2] = state[..., :2]
        return robot

    def step_params(self, dt: float) -> DriveStep:
        """The zero-order hold of (R1) over ``dt`` and the drive's limit.

        Parameters
        ----------
        dt : float
            The time step (s).
        """
        return DriveStep(*zero_order_hold(*self.linearisation(), dt), float(self.params.a_max))
