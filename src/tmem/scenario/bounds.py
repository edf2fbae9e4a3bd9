"""The physical bounds of a scenario's inputs, each a figure of the model, and the warning of a doubtful value.

Each function gives one figure; ``docs/parameters.md`` ("Bounds") derives each and gives its value
at the defaults:

* :func:`held_tilt` — the largest tilt of the thrust axis at which the rotors' most thrust still
  carries the weight, the height held (Q7): ``cos(phi) = m g / (4 k_eta o^2)``;
* :func:`loop_poles` — the poles of an inner loop of the flight controller, (Q5)-(Q6) or (Q7),
  linearised at hover, through the motors' lag (Q4) and sampled every sub-step;
* :func:`airspeed_limit` — the airspeed whose drag (Q1) the thrust balances at a lean;
* :func:`peak_tilt` — the largest tilt the attitude loop (1) reaches from a start;
* :data:`SMALL_ANGLE_TILT` — where (2)'s ``g phi`` is ``g tan(phi)`` less 10 %;
* :func:`stopping_speed` — the closing speed the tilt limit stops within the reach.

:mod:`tmem.scenario.vehicle_bounds` and :mod:`tmem.scenario.motion_bounds` apply them to a
scenario: a value beyond a bound raises :class:`~tmem.scenario.tables.FieldError`; a value legal
but doubtful is a :class:`Doubt`, warned of once the whole scenario is valid (:func:`warn`), as
a :class:`ScenarioWarning` on one line.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections.abc import Iterator
from contextvars import ContextVar
from typing import NamedTuple

import numpy as np

#: The share of the fastest rotor speed a rotor may need to carry the weight: the rest is the
#: attitude loop's, to make its moments (``rotor_speed_max`` must be 10 % above the hover speed).
ROTOR_SHARE = 0.9
#: The error of (2)'s small-angle ``g phi`` beside ``g tan(phi)`` (the horizontal acceleration with
#: the height held) from which a tilt is warned of.
SMALL_ANGLE_ERROR = 0.10


def _small_angle_tilt(error: float) -> float:
    """The tilt (rad) at which ``tan(phi) / phi = 1 + error``: by bisection (the ratio grows on (0, pi/2))."""
    low, high = 1e-6, math.pi / 2 - 1e-12
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if math.tan(middle) / middle < 1.0 + error else (low, middle)
    return 0.5 * (low + high)


#: The tilt (rad) beyond which (2)'s ``g phi`` is off ``g tan(phi)`` by more than
#: :data:`SMALL_ANGLE_ERROR`: 0.5218 rad (29.9 deg).
SMALL_ANGLE_TILT = _small_angle_tilt(SMALL_ANGLE_ERROR)


class ScenarioWarning(UserWarning):
    """A value a scenario may hold but that makes its results doubtful; the message is one line
    naming the field, the reason and the figure."""


class Doubt(NamedTuple):
    """A doubtful value: the field (as the scenario file names it) and why, with the figure."""

    field: str
    reason: str


#: Where the scenario being read comes from, at the start of a warning's line.
_SOURCE: ContextVar[str] = ContextVar("scenario_source", default="scenario")
#: The warnings given: Python's ``default`` action shows each line once.
_SHOWN: dict = {}


@contextlib.contextmanager
def reading(source: str) -> Iterator[None]:
    """Name ``source`` (a file) in the warnings of the scenarios validated inside the block.

    Parameters
    ----------
    source : str
        Where the scenario comes from (its file).
    """
    token = _SOURCE.set(source)
    try:
        yield
    finally:
        _SOURCE.reset(token)


def warn(doubts: list[Doubt]) -> None:
    """Warn of each doubt, as one line ``field: reason`` of a :class:`ScenarioWarning`.

    The warning names the scenario's file as its place (line 0: no line of source is shown under
    it), so that it prints on one line; each line is shown once, as Python shows warnings.

    Parameters
    ----------
    doubts : list of Doubt
        What to warn of.
    """
    for field, reason in doubts:
        warnings.warn_explicit(f"{field}: {reason}", ScenarioWarning, _SOURCE.get(), 0, module="tmem.scenario",
                               registry=_SHOWN)  # fmt: skip


def held_tilt(mass: float, g: float, k_eta: float, rotor_speed: float) -> float:
    """The largest tilt of the thrust axis (rad) at which four rotors at ``rotor_speed`` carry the weight.

    The altitude hold (Q7) asks for the thrust ``m g / cos(phi)`` at the tilt ``phi``; four rotors
    give at most ``4 k_eta o^2``, so ``cos(phi) >= m g / (4 k_eta o^2)``.  NaN where they cannot
    carry it level.

    Parameters
    ----------
    mass, g : float
        The airframe's mass (kg) and gravity (m/s^2).
    k_eta : float
        A rotor's thrust coefficient (N s^2/rad^2).
    rotor_speed : float
        The rotors' speed (rad/s).
    """
    ratio = mass * g / (4.0 * k_eta * rotor_speed**2)
    return math.acos(ratio) if ratio <= 1.0 else math.nan


def combined_tilt(tilts) -> float:
    """The tilt of the thrust axis from the vertical (rad) whose tilt along each axis is ``tilts``.

    ``phi_a = atan2(b_3a, b_3z)`` on each axis (:mod:`tmem.vehicles.quadrotor`) gives
    ``tan(theta)^2 = sum_a tan(phi_a)^2``; every ``|phi_a| < pi/2``.

    Parameters
    ----------
    tilts : sequence of float
        The tilt along each horizontal axis (rad).
    """
    return math.atan(math.sqrt(sum(math.tan(t) ** 2 for t in tilts)))


def hover_drag(mass: float, g: float, k_eta: float, rotor_drag: float) -> float:
    """``c_h = 4 k_d o_h / m``: the rotors' drag per unit mass at hover (1/s), ``o_h = sqrt(m g / (4 k_eta))``.

    Parameters
    ----------
    mass, g : float
        Mass (kg) and gravity (m/s^2).
    k_eta : float
        A rotor's thrust coefficient (N s^2/rad^2).
    rotor_drag : float
        ``k_d``, or the inflow's ``k_z`` (kg/rad).
    """
    return 4.0 * rotor_drag * math.sqrt(mass * g / (4.0 * k_eta)) / mass


def airspeed_limit(mass: float, g: float, drag: float, frame_drag: float, lean: float) -> float:
    """The airspeed (m/s) whose drag the thrust balances at the lean ``lean``, the height held.

    Level at the airspeed ``v``, the thrust's horizontal part ``m g tan(lean)`` balances the drag
    ``m c v + c_D v^2`` of the rotors (``c``: their drag per unit mass) and of the frame; ``inf``
    without drag.

    Parameters
    ----------
    mass, g : float
        Mass (kg) and gravity (m/s^2).
    drag : float
        ``c``: the rotors' drag per unit mass (1/s).
    frame_drag : float
        ``c_D``: the frame's quadratic drag (N s^2/m^2).
    lean : float
        The lean of the thrust axis (rad).
    """
    force = mass * g * math.tan(lean)
    if frame_drag > 0.0:
        linear = mass * drag
        return (math.sqrt(linear * linear + 4.0 * frame_drag * force) - linear) / (2.0 * frame_drag)
    return force / (mass * drag) if drag > 0.0 else math.inf


def substeps(dt: float, inner_period: float) -> int:
    """How many sub-steps the quadrotor takes in a step: the fewest that make each at most ``inner_period``.

    Its sub-step is ``dt / substeps(dt, inner_period)``, the longest that divides ``dt`` into whole
    steps and is at most ``inner_period``.

    Parameters
    ----------
    dt : float
        The time step (s).
    inner_period : float
        The flight controller's longest period (s).
    """
    return max(1, math.ceil(dt / inner_period - 1e-9))


def exponential(m: np.ndarray) -> np.ndarray:
    """``exp(m)`` of a small matrix: its Taylor series to degree 18 after scaling ``m`` to a norm of at
    most 1/2, then squared back (relative error below 1e-16 there).

    Small matrices only, where LAPACK's threads cost more than the sum (``scipy.linalg.expm`` takes
    25 ms a 4 x 4 on a loaded machine, this 0.2 ms).

    Parameters
    ----------
    m : ndarray, shape (n, n)
        The matrix.
    """
    norm = float(np.abs(m).sum(axis=1).max())
    squarings = max(0, math.ceil(math.log2(norm / 0.5))) if norm > 0.5 else 0
    scaled, out = m / 2.0**squarings, np.eye(len(m))
    term = out
    for k in range(1, 19):
        term = term @ scaled / k
        out = out + term
    for _ in range(squarings):
        out = out @ out
    return out


def loop_poles(gain: float, rate_gain: float, damping: float, lag: float, h: float) -> np.ndarray:
    """The poles of an inner loop of the flight controller, sampled every ``h`` (z-plane).

    The loop, per unit inertia: an angle (or height) ``x`` whose rate ``r`` is damped by ``damping``
    and driven by the motors' output ``a``, which follows the command ``c`` through their lag
    (Q4) (``T = k_eta o^2`` linearised at hover: the thrust lags the command by ``tau_m``)::

        x' = r,   r' = a - damping r,   a' = (c - a) / lag,   c = -rate_gain (gain x + r)

    with ``c`` computed at the start of each sub-step and held over it, as the flight controller
    does.  The attitude loop (Q5)-(Q6) is ``gain = kp``, ``rate_gain = kd`` and ``damping = c_r``
    (the rotors' inflow on the roll and pitch rates, ``4 k_z o_h a^2 / I``; their drag on the yaw
    rate, ``8 k_d o_h a^2 / I_zz``); the altitude hold (Q7) is
    ``gain = k_zp / k_zd``, ``rate_gain = k_zd`` and ``damping`` the inflow's ``4 k_z o_h / m``.
    The loop is stable where every pole lies inside the unit circle.

    Parameters
    ----------
    gain : float
        The outer gain (1/s).
    rate_gain : float
        The rate gain (1/s).
    damping : float
        The damping of the rate (1/s).
    lag : float
        The motors' time constant ``tau_m`` (s).
    h : float
        The sub-step (s).
    """
    a = np.array([[0.0, 1.0, 0.0], [0.0, -damping, 1.0], [0.0, 0.0, -1.0 / lag]])
    held = np.zeros((4, 4))
    held[:3, :3], held[2, 3] = a * h, h / lag
    step = exponential(held)
    feedback = np.array([rate_gain * gain, rate_gain, 0.0])
    return np.linalg.eigvals(step[:3, :3] - np.outer(step[:3, 3], feedback))


def slowest_decay(poles: np.ndarray, h: float) -> float:
    """The decay rate (1/s) of the slowest mode of a loop sampled every ``h``: ``-ln(max |z|) / h``.

    Parameters
    ----------
    poles : ndarray
        The loop's poles (z-plane), inside the unit circle.
    h : float
        The sub-step (s).
    """
    return -math.log(float(np.max(np.abs(poles)))) / h


def peak_tilt(tilt: float, rate: float, kp: float, kd: float) -> float:
    """The largest ``|phi|`` (rad) the attitude loop (1) reaches from ``(tilt, rate)``, its set-point 0.

    (1) is ``phi'' = kd (kp (0 - phi) - phi')``, stable for ``kp, kd > 0``; ``phi`` is sampled
    from its exact solution (the matrix exponential) every 1/2000 of ten time constants of its
    slowest root, and at the start.

    Parameters
    ----------
    tilt, rate : float
        The start's tilt (rad) and tilt rate (rad/s).
    kp, kd : float
        The attitude and rate gains of (1) (1/s).
    """
    if rate == 0.0:
        return abs(tilt)  # the loop has no overshoot from rest: (1)'s free response decays from it
    a = np.array([[0.0, 1.0], [-kp * kd, -kd]])
    slowest = float(np.min(-np.linalg.eigvals(a).real))
    step = exponential(a * 10.0 / slowest / 2000.0)
    x, peak = np.array([tilt, rate]), abs(tilt)
    for _ in range(2000):
        x = step @ x
        peak = max(peak, abs(float(x[0])))
    return peak


def stopping_speed(braking: float, reach: float) -> float:
    """The closing speed (m/s) two agents' limits stop within the reach: ``sqrt(4 a reach)``.

    Each agent brakes at most at ``a``, the largest acceleration the law asks of its vehicle
    (``g tan(c_max)`` for a tilting multirotor, the tilt limit held with the height held; ``c_max``
    for the ground robot), the pair at twice that, over the distance ``R + R_j`` at most.

    Parameters
    ----------
    braking : float
        ``a``, one agent's largest braking (m/s^2): the vehicle table's ``largest_acceleration(c_max)``.
    reach : float
        ``R + R_j`` (m).
    """
    return math.sqrt(4.0 * braking * reach)
