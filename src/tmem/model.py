"""Agent dynamics along one horizontal axis, equations (1)-(2) of the paper.

The state of one agent along one axis is ``x = (P, V, phi, omega)``:
position (m), velocity (m/s), tilt from the vertical (rad) and tilt rate
(rad/s).  The input is the tilt set-point ``U = phi_d`` (rad).  The inner
attitude loop of (1), ``omega_d = kp (phi_d - phi)`` and
``omega_dot = kd (omega_d - omega)``, with ``x_ddot = g phi``, gives the
linear model (2)::

    x_dot = A x + B U
    A = [[0, 1, 0, 0], [0, 0, g, 0], [0, 0, 0, 1], [0, 0, -kp kd, -kd]]
    B = [0, 0, 0, kp kd]^T

The simulator advances this model with the exact zero-order-hold
discretisation: between two control updates the input is held constant and
the state is propagated with the matrix exponential, so the only
discretisation error is that of sampling the control.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

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

    Returns
    -------
    Ad : ndarray, shape (4, 4)
    Bd : ndarray, shape (4,)
    """
    n = a.shape[0]
    augmented = np.zeros((n + 1, n + 1))
    augmented[:n, :n] = a
    augmented[:n, n] = b
    m = expm(augmented * dt)
    return m[:n, :n].copy(), m[:n, n].copy()
