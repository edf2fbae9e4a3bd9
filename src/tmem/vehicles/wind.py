"""Wind on the quadrotor: a constant wind and Dryden turbulence, each agent with gusts of its own.

The wind acts through the drag, as in RotorPy's ``Multirotor``: the rotors' drag ``H_k`` and the
frame's drag ``D`` of :mod:`tmem.vehicles.rigid_body` act on the airspeed, the velocity over the
ground less the wind's, in the world frame::

    v_air = v - w,   w = w_0 + u_g d + v_g d_perp + w_g e_3                          (D1)

``w_0`` is the constant wind (``[wind] velocity``, ``vertical``), ``d`` the unit vector along its
horizontal part (``e_1`` when it has none), ``d_perp`` the horizontal unit vector a quarter turn
from ``d``, and ``(u_g, v_g, w_g)`` the agent's gusts: longitudinal, lateral and vertical, as
MIL-F-8785C names them.  A 1-D run flies in the x-z plane and leaves the lateral gust out.

**The Dryden form** (U.S. Military Specification MIL-F-8785C, 5 November 1980, section 3.7,
*Atmospheric disturbances*: the Dryden spectra; reproduced in MIL-HDBK-1797, 1997).  Each gust is a
stationary Gaussian process; a vehicle flying through the frozen field at the speed ``V`` sees
the one-sided power spectral densities, in temporal frequency ``omega`` (rad/s), with
``∫_0^∞ Φ d omega = sigma^2``::

    Φ_u(omega) = sigma_u^2 (2 L_u / (pi V)) / (1 + (L_u omega / V)^2)                (D2)
    Φ_v(omega) = sigma_v^2 (L_v / (pi V)) (1 + 3 (L_v omega / V)^2) / (1 + (L_v omega / V)^2)^2   (D3)

and ``Φ_w`` as ``Φ_v`` with ``sigma_w``, ``L_w``.  For a hovering multirotor the field passes at
the mean wind's speed: ``V`` is ``|w_0|`` unless ``[wind.turbulence] speed`` is given.

**The low-altitude scales and intensities** (MIL-F-8785C, section 3.7, the low-altitude model for
``h`` below 1000 ft; MIL-HDBK-1797 gives the same), with the height ``h`` and the scales in feet
and ``W_20`` the wind speed at 20 ft (6 m)::

    L_w = h,   L_u = L_v = h / (0.177 + 0.000823 h)^1.2                             (D4)
    sigma_w = 0.1 W_20,   sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4     (D5)

with ``W_20`` = 15, 30 and 45 knots for light, moderate and severe turbulence.  At
``h = 1000 ft`` they give ``L_u = L_v = L_w`` and ``sigma_u = sigma_v = sigma_w``: isotropy.

**The shaping filters.**  The autocorrelations of (D2) and (D3) are ``sigma_u^2 exp(-|tau| / T_u)``
and ``sigma_v^2 (1 - |tau| / (2 T_v)) exp(-|tau| / T_v)``, ``T = L / V``.  The first is one lag
driven by white noise; the second two equal lags in cascade, ``g_1' = (q - g_1) / T`` and
``g_2' = (g_1 - g_2) / T``, read out as ``v_g = sqrt(3) g_1 + (1 - sqrt(3)) g_2``, which is
``(1 + sqrt(3) T s) / (1 + T s)^2``, the Dryden filter.  The body state keeps each gust and, for
``v`` and ``w``, the second lag ``g_2`` (:data:`GUST_NAMES`).

**Exact discretisation.**  Over a step ``dt`` each filter's state ``z`` moves as::

    z_(k+1) = Phi z_k + C n_k,   z_0 = S n                                          (D6)

with ``Phi = exp(A dt)``, ``C C^T = ∫_0^dt exp(A s) B B^T exp(A^T s) ds`` and ``S S^T`` the
stationary covariance, ``n`` independent standard normal draws (:func:`gust_coefficients`).  The
samples ``z_k`` then have exactly the joint distribution of the continuous process at the times
``k dt``, at any ``dt``: their spectrum is (D2)-(D3) folded at the Nyquist frequency, nothing
else.  The vehicle holds each step's wind over the step (its sub-steps see the same gust).

**Reproducible draws.**  The draws of step ``k`` of agent ``i`` are those of the message
``(seed, i, WIND_STREAM, k)`` of :mod:`tmem.world.streams`: agent ``i`` is its number in the scenario,
and ``WIND_STREAM`` is no agent's, so the gusts do not depend on the slots, the threads, the
neighbour lists, the number of agents, nor on the sensing's draws.  The body state carries the
agent's number and its step (``gust_stream``, ``gust_step``), so the vehicle's step needs nothing
else, and a checkpoint keeps the gusts with the rest of the body.  An agent added back starts again
from its start, its gusts too.  An agent's generator is ``(c, seed, agent)``, as the functions that
draw gusts take it: the 30 numbers ``c`` of (D6) (:func:`gust_coefficients`), the turbulence's
``seed`` and the ``agent``'s number in the scenario.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.world.streams import message_key, normal_pair
# The intensities and scales (D4)-(D5) are the [wind] table's, read by validation without Numba.
from tmem.scenario.wind_table import FOOT, KNOT, SEVERITY_W20, low_altitude_scales, scales  # noqa: F401

#: The "sender" of the wind's draws in :func:`tmem.world.streams.message_key`: no agent's number.
WIND_STREAM = np.uint64(0xFFFFFFFFFFFFFFFF)

#: The gusts' part of the body state, after the rigid body's: (D1), (D6).
GUST_NAMES = ("gust_u", "gust_v", "gust_w", "gust_v_lag", "gust_w_lag", "gust_stream", "gust_step")
GUST_UNITS = ("m s-1", "m s-1", "m s-1", "m s-1", "m s-1", "1", "1")
GUST_LONG_NAMES = (
    "longitudinal gust (along the mean wind)", "lateral gust (across the mean wind)", "vertical gust",
    "second lag of the lateral gust's filter", "second lag of the vertical gust's filter",
    "the agent's number: its stream of gusts", "steps of gusts drawn",
)  # fmt: skip
#: Numbers per gust component in :func:`gust_coefficients`: ``Phi`` (4), ``C`` (3) and ``S`` (3).
PER_COMPONENT = 10

#: The wind's fields of the quadrotor's step record (:class:`tmem.vehicles.quadrotor.QuadrotorStep`):
#: the constant wind (m/s, world frame), the unit vector ``d`` along its horizontal part, whether
#: there are gusts, their seed and the 30 numbers of (D6) (an array: a parallel loop takes no tuple
#: in a record).
WIND_FIELDS = [("wind_x", float), ("wind_y", float), ("wind_z", float), ("along_x", float), ("along_y", float),
               ("turbulent", bool), ("seed", int), ("gust", np.ndarray)]  # fmt: skip


def dryden_psd(omega: np.ndarray, sigma: np.ndarray, length: np.ndarray, speed: float) -> np.ndarray:
    """The one-sided power spectral densities (D2)-(D3) of ``(u, v, w)`` at ``omega``: shape ``(3, len(omega))``.

    In (m/s)^2 per rad/s; ``∫_0^∞ Φ d omega = sigma^2``.

    Parameters
    ----------
    omega : ndarray
        Temporal frequencies (rad/s), >= 0.
    sigma, length : ndarray, shape (3,)
        Intensities (m/s) and scales (m) of ``(u, v, w)``.
    speed : float
        The speed ``V`` at which the frozen field passes (m/s).
    """
    omega = np.asarray(omega, dtype=float)
    x = [(length[c] * omega / speed) ** 2 for c in range(3)]
    u = sigma[0] ** 2 * 2.0 * length[0] / (math.pi * speed) / (1.0 + x[0])
    v, w = (sigma[c] ** 2 * length[c] / (math.pi * speed) * (1.0 + 3.0 * x[c]) / (1.0 + x[c]) ** 2 for c in (1, 2))
    return np.stack([u, v, w])


def _two_lags(sigma: float, steps: float) -> list[float]:
    """``Phi``, ``C``, ``S`` of (D6) for the Dryden filter (D3), over ``steps = dt / T``, in the
    coordinates ``(v_g, g_2)``.  The noise covariance ``∫_0^x e^(-2s) (1, s, s^2) ds`` is in closed
    form through the regularised incomplete gamma function, exact for small steps too."""
    from scipy.special import gammainc

    e = math.exp(-steps)
    r3 = math.sqrt(3.0)
    to_gust = np.array([[r3, 1.0 - r3], [0.0, 1.0]])  # (g_1, g_2) -> (v_g, g_2)
    from_gust = np.linalg.inv(to_gust)
    phi = to_gust @ (e * np.array([[1.0, 0.0], [steps, 1.0]])) @ from_gust
    i0, i1, i2 = (math.factorial(n) / 2.0 ** (n + 1) * gammainc(n + 1, 2.0 * steps) for n in range(3))
    noise = to_gust @ np.array([[i0, i1], [i1, i2]]) @ to_gust.T
    stationary = to_gust @ np.array([[0.5, 0.25], [0.25, 0.25]]) @ to_gust.T
    c, s = np.linalg.cholesky(noise), np.linalg.cholesky(stationary)
    return [*phi.ravel(), *(sigma * np.array([c[0, 0], c[1, 0], c[1, 1], s[0, 0], s[1, 0], s[1, 1]]))]


def gust_coefficients(sigma: np.ndarray, length: np.ndarray, speed: float, dt: float) -> np.ndarray:
    """The 30 numbers of (D6) for a step ``dt``: for ``u``, ``v``, ``w`` in turn, ``Phi`` by rows (4),
    the lower triangle of ``C`` (3) and of ``S`` (3).

    ``u``'s filter is one lag, ``Phi = exp(-dt / T_u)``, ``C = sigma_u sqrt(1 - Phi^2)``,
    ``S = sigma_u``; its second state is not used (zeros).

    Parameters
    ----------
    sigma, length : ndarray, shape (3,)
        Intensities (m/s) and scales (m) of ``(u, v, w)``.
    speed : float
        The speed ``V`` at which the frozen field passes (m/s).
    dt : float
        The step (s).
    """
    steps_u = dt * speed / length[0]
    u = [math.exp(-steps_u), 0.0, 0.0, 0.0, sigma[0] * math.sqrt(-math.expm1(-2.0 * steps_u)), 0.0, 0.0, sigma[0], 0.0, 0.0]
    v, w = (_two_lags(sigma[c], dt * speed / length[c]) for c in (1, 2))
    return np.array([*u, *v, *w], dtype=float)


def wind_fields(wind: Any, dt: float) -> tuple:
    """The values of :data:`WIND_FIELDS` for the scenario's ``[wind]`` table (``None``: no wind).

    Parameters
    ----------
    wind : WindParams or None
        The table (:class:`tmem.scenario.wind_table.WindParams`).
    dt : float
        The step (s).
    """
    if wind is None:
        return (0.0, 0.0, 0.0, 1.0, 0.0, False, 0, np.zeros(3 * PER_COMPONENT))
    mean = wind.mean()
    horizontal = math.hypot(mean[0], mean[1])
    along = (mean[0] / horizontal, mean[1] / horizontal) if horizontal > 0.0 else (1.0, 0.0)
    gusts = wind.turbulence
    if gusts is None:
        return (*mean, *along, False, 0, np.zeros(3 * PER_COMPONENT))
    sigma, length = scales(gusts)
    return (*mean, *along, True, gusts.seed, gust_coefficients(sigma, length, wind.passing_speed(), dt))


def initial_gusts(wind: Any, n_agents: int) -> np.ndarray:
    """The gusts' part of the body states at the start (:data:`GUST_NAMES`), agents in the scenario's
    order: each agent's step 0 of (D6), its number, step 0; zeros without turbulence.

    Parameters
    ----------
    wind : WindParams or None
        The ``[wind]`` table.
    n_agents : int
        How many agents.
    """
    gusts = np.zeros((n_agents, len(GUST_NAMES)))
    if wind is None or wind.turbulence is None:
        return gusts
    _, _, _, _, _, _, seed, c = wind_fields(wind, 1.0)  # S of (D6) does not depend on the step
    for i in range(n_agents):
        gusts[i, :5] = first_gusts(c, seed, i)
        gusts[i, 5] = i
    return gusts


@numba.njit(cache=True, inline="always")
def _normals(seed, agent, step):
    """The five standard normal draws of an agent's gusts at ``step``: the message ``(seed, agent, WIND_STREAM, step)``."""
    key = message_key(seed, agent, WIND_STREAM, step)
    n1, n2 = normal_pair(key, 0)
    n3, n4 = normal_pair(key, 1)
    n5, _ = normal_pair(key, 2)
    return n1, n2, n3, n4, n5


@numba.njit(cache=True, inline="always")
def _filter(g, lag, c, o, n1, n2):
    """One step (D6) of the filter whose numbers start at ``c[o]``: ``(g, lag)`` after it."""
    return (c[o] * g + c[o + 1] * lag + c[o + 4] * n1,
            c[o + 2] * g + c[o + 3] * lag + c[o + 5] * n1 + c[o + 6] * n2)  # fmt: skip


@numba.njit(cache=True, error_model="numpy", inline="always")
def next_gusts(z, c, seed, agent, step):
    """The gusts ``(u, v, w, v_lag, w_lag)`` of step ``step`` (>= 1) from those of the step before, (D6).

    Parameters
    ----------
    z : tuple of 5 float
        The gusts of step ``step - 1``.
    c, seed, agent
        The agent's generator (module text).
    step : int
        The step drawn (its draws are the message ``(seed, agent, WIND_STREAM, step)``).
    """
    n1, n2, n3, n4, n5 = _normals(seed, agent, step)
    u, _ = _filter(z[0], 0.0, c, 0, n1, 0.0)
    v, v_lag = _filter(z[1], z[3], c, PER_COMPONENT, n2, n3)
    w, w_lag = _filter(z[2], z[4], c, 2 * PER_COMPONENT, n4, n5)
    return u, v, w, v_lag, w_lag


@numba.njit(cache=True, error_model="numpy")
def first_gusts(c, seed, agent):
    """The gusts of step 0, drawn from the stationary distribution: ``z_0 = S n`` of (D6).

    Parameters
    ----------
    c, seed, agent
        The agent's generator (module text).
    """
    n1, n2, n3, n4, n5 = _normals(seed, agent, 0)
    v, w = PER_COMPONENT + 7, 2 * PER_COMPONENT + 7
    return c[7] * n1, c[v] * n2, c[w] * n4, c[v + 1] * n2 + c[v + 2] * n3, c[w + 1] * n4 + c[w + 2] * n5


@numba.njit(cache=True)
def gust_series(c, seed, agent, n_steps):
    """The gusts of steps ``0 .. n_steps - 1`` of one agent, shape ``(n_steps, 5)``: the generator
    the vehicle's step runs, alone (for studies and tests of its statistics).

    Parameters
    ----------
    c, seed, agent
        The agent's generator (module text).
    n_steps : int
        How many steps.
    """
    out = np.empty((n_steps, 5))
    z = first_gusts(c, seed, agent)
    for k in range(n_steps):
        if k > 0:
            z = next_gusts(z, c, seed, agent, k)
        for m in range(5):
            out[k, m] = z[m]
    return out


@numba.njit(cache=True, inline="always")
def wind_now(body, i, first, params, two):
    """The wind agent ``i`` flies in over this step, (D1): ``(w_x, w_y, w_z)`` in the world frame.

    Parameters
    ----------
    body : ndarray, shape (agents, columns)
        Body states; the gusts (:data:`GUST_NAMES`) from column ``first``.
    i : int
        The agent's slot.
    first : int
        The column of ``gust_u``.
    params : QuadrotorStep
        Its :data:`WIND_FIELDS`.
    two : bool
        Whether the run has two axes (else the lateral gust and the y wind are left out).
    """
    u, v, w = body[i, first], body[i, first + 1], body[i, first + 2]
    wx = params.wind_x + u * params.along_x - v * params.along_y
    wy = params.wind_y + u * params.along_y + v * params.along_x if two else 0.0
    return wx, wy, params.wind_z + w


@numba.njit(cache=True, inline="always")
def advance_gusts(body, i, first, params):
    """Draw agent ``i``'s gusts of its next step into its body state, (D6).

    Parameters
    ----------
    body, i, first, params
        As :func:`wind_now` takes them; ``body`` is changed in place.
    """
    b = body
    step = b[i, first + 6] + 1.0
    z = (b[i, first], b[i, first + 1], b[i, first + 2], b[i, first + 3], b[i, first + 4])
    z = next_gusts(z, params.gust, params.seed, np.int64(b[i, first + 5]), np.int64(step))
    for m in range(5):
        b[i, first + m] = z[m]
    b[i, first + 6] = step
