"""Modal controller of the agent: roots (5) and gains (4).

The gains ``K`` are chosen so that one agent interacting with a neighbour held
still, whose input is then ``U = -K x + const`` (see :mod:`tmem.law.interaction`),
has the closed loop ``A - B K`` with the roots (5)::

    p = (-r_l - i im_l, -r_l + i im_l, -i im_r, +i im_r)

The fast, damped left pair belongs to the tilt; the undamped right pair makes
an encounter lossless, like an elastic collision: speeds are exchanged and the
RMS velocity of the swarm (its "temperature") is kept.

Formula (4) as printed in the paper does not place these roots (see
:func:`printed_gains`).  :func:`modal_gains` matches the characteristic
polynomial of ``A - B K`` with that of the roots instead; the derivation is in
``docs/equations.md``.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)


def roots(r_l: float, im_l: float, im_r: float) -> np.ndarray:
    """The desired closed-loop roots (5), ``(-r_l -+ i im_l, -+ i im_r)``.

    Parameters
    ----------
    r_l, im_l : float
        Real part and imaginary part of the damped left pair (1/s).
    im_r : float
        Imaginary part of the undamped right pair (1/s).

    Returns
    -------
    ndarray, shape (4,), complex
    """
    return np.array([-r_l - 1j * im_l, -r_l + 1j * im_l, -1j * im_r, 1j * im_r])


def modal_gains(kp: float, kd: float, g: float, r_l: float, im_l: float, im_r: float) -> np.ndarray:
    """Gains ``K = (K_P, K_V, K_phi, K_omega)`` placing the roots (5), corrected (4).

    With ``beta = 1 / (kp kd)`` and the state order ``(P, V, phi, omega)``::

        K_P     = beta (r_l^2 + im_l^2) im_r^2 / g
        K_V     = 2 beta r_l im_r^2 / g
        K_phi   = beta (r_l^2 + im_l^2 + im_r^2) - 1
        K_omega = beta (2 r_l - kd)

    These follow from equating ``det(sI - A + B K)`` with
    ``(s^2 + 2 r_l s + r_l^2 + im_l^2)(s^2 + im_r^2)``.

    Parameters
    ----------
    kp, kd, g
        The model's parameters (1)-(2), Table 1.
    r_l, im_l, im_r
        The roots (5), Table 1.

    Returns
    -------
    ndarray, shape (4,)
    """
    return _paper_gains(kp * kd, kd, g, r_l, im_l, im_r)


def _paper_gains(kp_kd: float, kd: float, g: float, r_l: float, im_l: float, im_r: float) -> np.ndarray:
    beta = 1.0 / kp_kd
    left = r_l**2 + im_l**2
    return np.array(
        [
            beta * left * im_r**2 / g,
            2.0 * beta * r_l * im_r**2 / g,
            beta * (left + im_r**2) - 1.0,
            beta * (2.0 * r_l - kd),
        ]
    )


def gains_for(a: np.ndarray, b: np.ndarray, r_l: float, im_l: float, im_r: float) -> np.ndarray:
    """Modal gains placing the roots (5) for a vehicle model's linearisation ``(A, B)``.

    Where ``(A, B)`` has the structure of the paper's model (2) (all the
    linear model's, and a quadrotor's at hover), the closed form of
    :func:`modal_gains` is used with ``g = A[1, 2]``, ``kd = -A[3, 3]`` and
    ``kp kd = B[3]``; any other linearisation is handed to
    :func:`scipy.signal.place_poles`.

    Parameters
    ----------
    a : ndarray, shape (4, 4)
    b : ndarray, shape (4,)
        The linearisation on ``(P, V, phi, omega)`` with the tilt set-point as input.
    r_l, im_l, im_r
        The roots (5).

    Returns
    -------
    ndarray, shape (4,)
    """
    g, kd, kp_kd = a[1, 2], -a[3, 3], b[3]
    paper_form = np.array([[0, 1, 0, 0], [0, 0, g, 0], [0, 0, 0, 1], [0, 0, -kp_kd, -kd]], dtype=float)
    if np.array_equal(a, paper_form) and np.array_equal(b, [0.0, 0.0, 0.0, kp_kd]):
        return _paper_gains(kp_kd, kd, g, r_l, im_l, im_r)
    from scipy.signal import place_poles

    return place_poles(a, b[:, None], roots(r_l, im_l, im_r)).gain_matrix[0]


def printed_gains(kp: float, kd: float, g: float, r_l: float, im_l: float, im_r: float) -> np.ndarray:
    """Formula (4) exactly as printed in the paper, for comparison only.

    Taken literally with Table 1, ``eig(A - B K)`` is about
    ``{-11.93 +- 12.19i, -0.074 +- 0.140i}``, not the roots (5).  Its first
    two entries are the position and velocity gains swapped (the printed first
    entry is ``K_V``, the second ``K_P``), and the third lacks the ``- 1``:
    ``K_phi`` comes out as 0.962 instead of -0.038.  Do not use these gains to
    simulate; use :func:`modal_gains`.

    Parameters
    ----------
    kp, kd, g, r_l, im_l, im_r
        As :func:`modal_gains` takes them: the model's parameters (1)-(2) and the roots (5).

    Returns
    -------
    ndarray, shape (4,)
        The printed ``K`` (its real part), its first two entries swapped as said above.
    """
    p1, p2, p3, p4 = roots(r_l, im_l, im_r)
    beta = 1.0 / (kp * kd)
    k = np.array(
        [
            -beta / g * (p1 * p2 * p3 + p1 * p2 * p4 + p1 * p3 * p4 + p2 * p3 * p4),
            beta / g * p1 * p2 * p3 * p4,
            beta * (p2 * p3 + p2 * p4 + p3 * p4 + p1 * (p2 + p3 + p4)),
            -beta * (kd + p1 + p2 + p3 + p4),
        ]
    )
    return k.real


def interaction_point(x: np.ndarray, gains: np.ndarray) -> np.ndarray:
    """The agent's position corrected by its motion state, ``P* = x . K / K_P`` (6).

    Parameters
    ----------
    x : ndarray, shape (..., n_state)
        States, the law's components first (``(P, V, phi, omega)`` for a tilting multirotor).
    gains : ndarray, shape (n_law,)
        ``K`` from :func:`modal_gains`; ``K_P = gains[0]`` is the paper's ``K1``.  The law reads the
        first ``n_law`` components of the state.
    """
    return x[..., : len(gains)] @ (gains / gains[0])


@numba.njit(cache=True, inline="always")
def gains_row(gains, agent):
    """The row of ``gains`` that holds agent ``agent``'s ``K``: its own, or the one every agent shares.

    Parameters
    ----------
    gains : ndarray, shape (agents, n_law) or (1, n_law)
        Each agent's ``K`` (:func:`modal_gains`), or one row that every agent shares (no stream of
        identical rows through the cache).
    agent : int
        The agent's row when there is a row per agent.
    """
    return agent if gains.shape[0] > 1 else 0


@numba.njit(cache=True, inline="always")
def corrected_position(x, i, a, gains, row):
    """``P* = x . K / K_P`` (6) of row ``i``'s state on axis ``a``, in compiled code.

    The same quantity as :func:`interaction_point`, for the step loop, the batch and the per-agent
    controller.  The sum runs over the components the law reads (as many as ``K`` has: a vehicle
    may keep more after them), in the order of the state, so every caller gets the same bits.

    Parameters
    ----------
    x : ndarray, shape (rows, axes, n_state)
        States, the law's components first (``(P, V, phi, omega)`` for a tilting multirotor).
    i, a : int
        The row and the axis.
    gains : ndarray, shape (agents, n_law) or (1, n_law)
        Each agent's ``K``, or one row that every agent shares.
    row : int
        The row of ``gains`` to use (:func:`gains_row`).
    """
    total = x[i, a, 0] * gains[row, 0]
    for m in range(1, gains.shape[1]):
        total += x[i, a, m] * gains[row, m]
    return total / gains[row, 0]


@numba.njit(cache=True, inline="always")
def tilt_scale(u, i, n_axes, c_max):
    """The factor that saturates agent ``i``'s summed set-point on its norm, ``|U| <= c_max``.

    Parameters
    ----------
    u : ndarray, shape (agents, axes)
        Summed set-points (rad).
    i : int
        The agent's slot.
    n_axes : int
        Number of axes.
    c_max : float
        Tilt limit (rad).
    """
    norm2 = 0.0
    for a in range(n_axes):
        norm2 += u[i, a] * u[i, a]
    return saturation(norm2, c_max)


@numba.njit(cache=True, inline="always")
def saturation(norm2, c_max):
    """The factor that brings a set-point of squared norm ``norm2`` within ``c_max``: 1 if it is.

    Parameters
    ----------
    norm2 : float
        The set-point's squared norm (rad^2).
    c_max : float
        Tilt limit (rad).
    """
    return c_max / np.sqrt(norm2) if norm2 > c_max * c_max else 1.0
