"""The paper's linear quadrocopter model (1)-(2), stepped by its exact zero-order hold.

The state of one agent along one axis is ``x = (P, V, phi, omega)``:
position (m), velocity (m/s), tilt from the vertical (rad) and tilt rate
(rad/s).  The input is the tilt set-point ``U = phi_d`` (rad).  The inner
attitude loop of (1), ``omega_d = kp (phi_d - phi)`` and
``omega_dot = kd (omega_d - omega)``, with ``x_ddot = g phi``, gives the
linear model (2)::

    x_dot = A x + B U
    A = [[0, 1, 0, 0], [0, 0, g, 0], [0, 0, 0, 1], [0, 0, -kp kd, -kd]]
    B = [0, 0, 0, kp kd]^T

The model is advanced with the exact zero-order-hold discretisation: between
two control updates the input is held constant and the state is propagated
with the matrix exponential, so the only discretisation error is that of
sampling the control.
"""

from __future__ import annotations

import math

from functools import cache
from typing import ClassVar, Literal, NamedTuple

import numpy as np
from scipy.linalg import expm

from tmem.scenario.fields import Positive, StrictModel
from tmem.vehicles.base import VehicleModel

#: Names of the four state components, in the order the arrays use.
STATE_NAMES = ("P", "V", "phi", "omega")


def state_matrices(kp: float, kd: float, g: float) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(A, B)`` of the linear model (2).

    Parameters
    ----------
    kp, kd
        Gains of the inner attitude loop in (1) (1/s).
    g
        Gravitational acceleration (m/s^2).

    Returns
    -------
    A : ndarray, shape (4, 4)
    B : ndarray, shape (4,)
    """
    a = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, g, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, 0.0, -kp * kd, -kd],
        ]
    )
    b = np.array([0.0, 0.0, 0.0, kp * kd])
    return a, b


def zero_order_hold(a: np.ndarray, b: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation of ``x_dot = A x + B U``.

    ``x[k+1] = Ad x[k] + Bd U[k]`` with ``Ad = exp(A dt)`` and
    ``Bd = integral_0^dt exp(A s) ds B``, both read off the exponential of the
    augmented matrix ``[[A, B], [0, 0]] dt`` (Van Loan's method).

    Parameters
    ----------
    a : ndarray, shape (n, n)
    b : ndarray, shape (n,)
    dt
        The time step (s).

    Returns
    -------
    Ad : ndarray, shape (n, n)
    Bd : ndarray, shape (n,)
    """
    n = a.shape[0]
    augmented = np.zeros((n + 1, n + 1))
    augmented[:n, :n] = a
    augmented[:n, n] = b
    m = expm(augmented * dt)
    return m[:n, :n].copy(), m[:n, n].copy()


class HoldStep(NamedTuple):
    """What one zero-order-hold step needs: ``x <- Ad x + Bd U``."""

    ad: np.ndarray
    bd: np.ndarray


def _step(x, body, u, i, scale, params, n_axes):
    """Advance agent ``i`` of ``x`` (agents, axes, 4) over one step with ``U = u[i] * scale`` held (2):
    ``x <- Ad x + Bd U`` on each axis (``params`` a :class:`HoldStep`; ``body`` has no columns).

    Compiled by :meth:`LinearModel.kernel`.
    """
    ad, bd = params.ad, params.bd
    for a in range(n_axes):
        x0, x1, x2, x3, v = x[i, a, 0], x[i, a, 1], x[i, a, 2], x[i, a, 3], u[i, a] * scale
        # All four computed before any is stored: a store into x could otherwise alias ad and bd for
        # the compiler, which then reads their coefficients again after each one.
        y0 = ad[0, 0] * x0 + ad[0, 1] * x1 + ad[0, 2] * x2 + ad[0, 3] * x3 + bd[0] * v
        y1 = ad[1, 0] * x0 + ad[1, 1] * x1 + ad[1, 2] * x2 + ad[1, 3] * x3 + bd[1] * v
        y2 = ad[2, 0] * x0 + ad[2, 1] * x1 + ad[2, 2] * x2 + ad[2, 3] * x3 + bd[2] * v
        y3 = ad[3, 0] * x0 + ad[3, 1] * x1 + ad[3, 2] * x2 + ad[3, 3] * x3 + bd[3] * v
        x[i, a, 0], x[i, a, 1], x[i, a, 2], x[i, a, 3] = y0, y1, y2, y3


class TiltingGain:
    """What the tables of tilting multirotors share (their ``kp``, ``kd`` and ``g``): the law's gain
    on position that they give."""

    def position_gain(self, r_l: float, im_l: float, im_r: float) -> float:
        """``K_P`` of (4) on the model (2) with this table's numbers: ``(r_l^2 + im_l^2) im_r^2 / (g kp kd)``.

        Parameters
        ----------
        r_l, im_l, im_r : float
            The roots (5) (1/s).
        """
        return (r_l**2 + im_l**2) * im_r**2 / (self.g * self.kp * self.kd)

    def largest_acceleration(self, c_max: float) -> float:
        """The largest horizontal acceleration (m/s^2) the law asks for: ``g tan(c_max)``, the tilt limit
        held with the height held (the first order of (2)'s ``g c_max``).

        Parameters
        ----------
        c_max : float
            The tilt limit (rad).
        """
        return self.g * math.tan(min(c_max, math.pi / 2 - 1e-9))


class LinearModelParams(TiltingGain, StrictModel):
    """Quadrocopter model (1)-(2), linear per axis, Table 1: ``[model] kind = "linear"``."""

    kind: Literal["linear"] = "linear"
    kp: Positive = 6.0
    kd: Positive = 25.0
    g: Positive = 9.8

    #: The most axes a run of this model may have.
    max_axes: ClassVar[int] = 3


class LinearModel(VehicleModel):
    """The linear model (2) of each horizontal axis, with the parameters ``kp``, ``kd``, ``g`` of Table 1."""

    kind = "linear"
    table = LinearModelParams
    state_names = STATE_NAMES
    state_units = ("m", "m s-1", "rad", "rad s-1")
    long_names = ("position", "velocity", "tilt from the vertical", "tilt rate")

    @classmethod
    @cache
    def kernel(cls):
        """The compiled step :func:`_step`, the exact zero-order hold of (2) (compiled on first use)."""
        import numba

        return numba.njit(inline="always", error_model="numpy")(_step)

    def linearisation(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` of (2): the model is its own linearisation."""
        p = self.params
        return state_matrices(p.kp, p.kd, p.g)

    def step_params(self, dt: float) -> HoldStep:
        """``(Ad, Bd)`` of the exact zero-order hold over ``dt``.

        Parameters
        ----------
        dt : float
            The time step (s).
        """
        return HoldStep(*zero_order_hold(*self.linearisation(), dt))
