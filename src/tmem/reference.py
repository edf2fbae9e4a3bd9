"""Continuous-time reference: the same scenario integrated without sampling the control.

The engine (:mod:`tmem.engine`) holds each agent's set-point ``U`` constant
over a step ``dt`` (exact zero-order hold of (2)), so its only error is that
of sampling the control.  This module integrates the closed loop itself,
with ``U`` a function of the state at every instant::

    x_i_dot = A x_i + B U_i(t)                                     (2)
    U_i     = clip(sum_j f(|d_ij|) sign(d_ij), -c_max, c_max)
    d_ij    = P*_j - P*_i,   P* = x . K / K_P                      (6)

with ``f`` the interaction function of :mod:`tmem.interaction` (repulsion (8)
or attraction, Fig. 3), applied to each pair as the engine applies it.

Both functions vanish for ``|d| >= reach = R + R_j``.  Repulsion is
continuous there; attraction jumps from about ``c_max`` to 0, and an adaptive
integrator stepping across a jump loses its accuracy.  So each pair is held
on one side of ``reach`` for a segment, ``f`` evaluated at ``|d|`` clamped to
that side, which keeps the right-hand side continuous within the segment.  A
terminal event on ``sigma = |d| - reach`` ends the segment at the crossing and
integration restarts from there.  Each event watches only for the crossing
that leaves the current side (its ``direction``), so the restart point, on
``reach`` to rounding, does not trigger it again.

At the crossing the new side may push the pair straight back: ``P*`` holds
the tilt rate, which the set-point drives directly, so the jump of attraction
reverses ``d sigma / dt``.  The engine then chatters across ``reach`` from
one step to the next (a discrete sliding mode, about 0.025 s on entering and
on leaving the spheres in the ``fig5`` preset).  Its limit as ``dt -> 0`` is
Filippov's sliding motion, integrated here: while sliding, the pair's push is
``alpha f(reach^-) sign(d)`` with ``alpha`` in [0, 1] chosen so that
``d sigma / dt = 0`` (the equivalent control); the slide ends, by an event,
when ``alpha`` reaches 0 (the pair leaves the spheres) or 1 (it enters).

Supported: one axis, functions without a coupling flag (the flag of (10)-(11)
changes at sampled instants in the engine), and at most one pair sliding at
a time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from . import interaction
from .control import interaction_point, modal_gains
from .engine import record_steps
from .initial import build
from .model import state_matrices
from .scenario import Scenario

#: Modes of a pair: ``|d| > reach``, ``|d| < reach``, or sliding on ``|d| = reach``.
OUTSIDE, INSIDE, SLIDING = 0, 1, 2


def _check(scenario: Scenario) -> None:
    function = scenario.interaction.function
    if interaction.uses_coupling(function):
        raise ValueError(
            f"interaction.function: the continuous reference supports only functions without "
            f"the coupling flag F_en (repulsion, attraction), got {function!r}"
        )
    n_axes = scenario.space.axes
    if n_axes != 1:
        raise ValueError(f"agents: the continuous reference supports one axis only, got {n_axes}")


def integrate(
    scenario: Scenario,
    t_eval: np.ndarray | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-10,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the scenario in continuous time with ``solve_ivp`` (DOP853).

    Parameters
    ----------
    scenario
        A scenario with one axis and the function ``"repulsion"`` (8) or
        ``"attraction"`` (Fig. 3).  Its ``dt`` is used only for the default
        ``t_eval``; operator commands change nothing without a coupling flag
        and are ignored.
    t_eval
        Times (s) at which to return the state, within ``[0, duration]``.
        Default: the engine's recorded times, so that the result lines up
        with ``Trajectory.time``.
    rtol, atol
        Tolerances of the integrator (relative; absolute in SI units).

    Returns
    -------
    t : ndarray, shape (n_times,)
    states : ndarray, shape (n_times, agents, 1, 4)
        ``(P, V, phi, omega)`` of each agent at each time, as ``Trajectory.state``.

    Raises
    ------
    ValueError
        For a function with the coupling flag (10)-(11), more than one axis,
        or times outside ``[0, duration]``.
    RuntimeError
        If two pairs slide on ``|d| = reach`` at once, or the integrator fails.
    """
    _check(scenario)
    m, c, ia, sim = scenario.model, scenario.controller, scenario.interaction, scenario.simulation
    a, b = state_matrices(m.kp, m.kd, m.g)
    gains = modal_gains(m.kp, m.kd, m.g, c.r_l, c.im_l, c.im_r)
    x0 = build(scenario).state[:, 0, :]
    n_agents = x0.shape[0]
    first, second = np.triu_indices(n_agents, k=1)
    reach, below_reach = ia.reach, np.nextafter(ia.reach, 0.0)

    def pair_measure(y: np.ndarray) -> np.ndarray:
        p_star = interaction_point(y.reshape(n_agents, 4), gains)
        return p_star[second] - p_star[first]

    def velocity(y: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """``x_dot`` with each pair's push ``weight f(min(|d|, reach^-)) sign(d)``."""
        d = pair_measure(y)
        f_inside = interaction.evaluate(
            ia.function, np.minimum(np.abs(d), below_reach), k_p=gains[0], reach=reach, d_t=ia.d_t, c_max=ia.c_max
        )
        push = weight * f_inside * np.sign(d)
        u = np.zeros(n_agents)
        np.add.at(u, first, push)
        np.subtract.at(u, second, push)
        u = np.clip(u, -ia.c_max, ia.c_max)
        return (y.reshape(n_agents, 4) @ a.T + u[:, None] * b).ravel()

    def sigma_rate(y: np.ndarray, weight: np.ndarray, p: int, w: float) -> float:
        """``d sigma_p / dt`` with pair ``p`` given the weight ``w``."""
        weight = weight.copy()
        weight[p] = w
        x_dot = velocity(y, weight).reshape(n_agents, 4)
        d_dot = interaction_point(x_dot[second[p]] - x_dot[first[p]], gains)
        return float(np.sign(pair_measure(y)[p]) * d_dot)

    def weights(y: np.ndarray, mode: np.ndarray) -> np.ndarray:
        """Each pair's weight: 1 inside, 0 outside, the equivalent control while sliding."""
        weight = (mode == INSIDE).astype(float)
        for p in np.flatnonzero(mode == SLIDING):
            out, into = sigma_rate(y, weight, p, 0.0), sigma_rate(y, weight, p, 1.0)
            # Clamped so that trial stages just past the slide's end stay continuous.
            if out >= 0.0:
                weight[p] = 0.0
            elif into <= 0.0:
                weight[p] = 1.0
            else:
                weight[p] = brentq(lambda w: sigma_rate(y, weight, p, w), 0.0, 1.0, xtol=1e-15)
        return weight

    def rhs(t: float, y: np.ndarray, mode: np.ndarray) -> np.ndarray:
        return velocity(y, weights(y, mode))

    def events(mode: np.ndarray) -> tuple[list[Callable], list[tuple[int, int | None]]]:
        """Terminal events ending each pair's mode; for each, its pair and the mode it leads to.

        A crossing of ``reach`` leads to ``None``: decided by :func:`crossing_mode`.
        """
        found, owners = [], []
        weight = (mode == INSIDE).astype(float)
        for p, pair_mode in enumerate(mode):
            if pair_mode == SLIDING:
                # The slide ends where the outside push stops pointing in (w = 0)
                # or the inside push stops pointing out (w = 1).
                for w, direction, leads_to in ((0.0, 1.0, OUTSIDE), (1.0, -1.0, INSIDE)):
                    found.append(_event(lambda t, y, mode, p=p, w=w: sigma_rate(y, weight, p, w), direction))
                    owners.append((p, leads_to))
            else:
                direction = 1.0 if pair_mode == INSIDE else -1.0
                found.append(_event(lambda t, y, mode, p=p: abs(pair_measure(y)[p]) - reach, direction))
                owners.append((p, None))
        return found, owners

    def crossing_mode(y: np.ndarray, mode: np.ndarray, p: int) -> int:
        """Mode of pair ``p`` on reaching ``|d| = reach`` from its side ``mode[p]``.

        It crosses, unless the push on the far side points straight back: then it slides.
        """
        weight = weights(y, mode)
        if mode[p] == OUTSIDE:
            new = SLIDING if sigma_rate(y, weight, p, 1.0) > 0.0 else INSIDE
        else:
            new = SLIDING if sigma_rate(y, weight, p, 0.0) < 0.0 else OUTSIDE
        if new == SLIDING and np.any(mode == SLIDING):
            raise RuntimeError("two pairs would slide on |d| = R + R_j at once; not supported")
        return new

    duration = sim.duration
    if t_eval is None:
        t_eval = record_steps(sim.n_steps, sim.record_every) * sim.dt
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.size and (t_eval.min() < 0.0 or t_eval.max() > duration):
        raise ValueError(f"t_eval: times must lie within [0, duration = {duration:g}] s")

    states = np.empty((t_eval.size, n_agents * 4))
    t0, y0 = 0.0, x0.ravel()
    mode = np.where(np.abs(pair_measure(y0)) < reach, INSIDE, OUTSIDE)
    while True:
        found, owners = events(mode)
        sol = solve_ivp(
            rhs, (t0, duration), y0, method="DOP853", rtol=rtol, atol=atol,
            events=found, dense_output=True, args=(mode,),
        )  # fmt: skip
        if not sol.success:
            raise RuntimeError(f"solve_ivp failed at t = {sol.t[-1]:g} s: {sol.message}")
        t1, y1 = sol.t[-1], sol.y[:, -1]
        here = (t_eval >= t0) & (t_eval <= t1)
        if here.any():
            states[here] = sol.sol(t_eval[here]).T
        if sol.status == 0:
            break
        new_mode = mode.copy()
        for (p, leads_to), times in zip(owners, sol.t_events):
            if times.size:
                new_mode[p] = crossing_mode(y1, mode, p) if leads_to is None else leads_to
        t0, y0, mode = t1, y1, new_mode
    return t_eval, states.reshape(t_eval.size, n_agents, 1, 4)


def _event(function: Callable, direction: float) -> Callable:
    function.terminal = True
    function.direction = direction
    return function


def final_state(scenario: Scenario, rtol: float = 1e-10, atol: float = 1e-10) -> np.ndarray:
    """State at ``t = duration`` from :func:`integrate`, shape ``(agents, 1, 4)``."""
    _, states = integrate(scenario, t_eval=np.array([scenario.simulation.duration]), rtol=rtol, atol=atol)
    return states[-1]
