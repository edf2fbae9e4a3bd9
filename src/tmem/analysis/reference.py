"""Continuous-time reference: the same scenario integrated without sampling the control.

The engine (:mod:`tmem.engine`) holds each agent's set-point ``U`` constant
over a step ``dt`` (exact zero-order hold of (2)), so its only error is that
of sampling the control.  This module integrates the closed loop itself,
with ``U`` a function of the state at every instant::

    x_i_dot = A x_i + B U_i(t)                                     (2)
    U_i     = clip(sum_j f(|d_ij|) sign(d_ij), -c_max, c_max)
    d_ij    = P*_j - P*_i,   P* = x . K / K_P                      (6)

with ``f`` the interaction function of :mod:`tmem.law.interaction` (repulsion (8)
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

The closed loop, with each pair's push weighted (1 inside, 0 outside,
``alpha`` while sliding), is :class:`_ClosedLoop`; :func:`integrate` runs it
segment by segment, each segment with the pairs' modes fixed.

Supported: one axis, a vehicle model whose state is the law's (the loop
integrated is that of its linearisation ``(A, B)``: the linear model (2)
itself, or the ground robot's (R1) while its drive is not saturated), functions without a coupling flag (the flag of (10)-(11)
changes at sampled instants in the engine), and at most one pair sliding at
a time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from tmem.law.modal import interaction_point
from tmem.engine import record_steps
from tmem.world.initial import build
from tmem.law.interaction import evaluate, uses_coupling
from tmem.vehicles import vehicle_model
from tmem.vehicles.base import VehicleModel
from tmem.scenario import Scenario

#: Modes of a pair: ``|d| > reach``, ``|d| < reach``, or sliding on ``|d| = reach``.
OUTSIDE, INSIDE, SLIDING = 0, 1, 2

#: An event's pair and the mode it leads to (``None``: decided at the crossing).
Owner = tuple[int, int | None]


def integrate(
    scenario: Scenario,
    t_eval: np.ndarray | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-10,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the scenario in continuous time with ``solve_ivp`` (DOP853).

    The run is a sequence of segments, each with every pair's mode fixed
    (outside, inside or sliding); a segment ends at the first terminal event
    of a mode, and the next starts there with the modes after the event.

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
        a model whose state is not ``(P, V, phi, omega)``, or times outside
        ``[0, duration]``.
    RuntimeError
        If two pairs slide on ``|d| = reach`` at once, or the integrator fails.
    """
    model = vehicle_model(scenario.model)
    _check(scenario, model)
    duration = scenario.simulation.duration
    t_eval = _times(scenario, t_eval)
    loop = _ClosedLoop(scenario, model)
    states = np.empty((t_eval.size, loop.size))
    t0, y0 = 0.0, loop.y0
    mode = loop.initial_mode(y0)
    while True:
        sol, owners = loop.segment(mode, t0, y0, duration, rtol, atol)
        t1, y1 = sol.t[-1], sol.y[:, -1]
        here = (t_eval >= t0) & (t_eval <= t1)
        if here.any():
            states[here] = sol.sol(t_eval[here]).T
        if sol.status == 0:
            break
        t0, y0, mode = t1, y1, loop.mode_after(y1, mode, owners, sol.t_events)
    return t_eval, states.reshape(t_eval.size, loop.n_agents, 1, loop.n_state)


def final_state(scenario: Scenario, rtol: float = 1e-10, atol: float = 1e-10) -> np.ndarray:
    """State at ``t = duration`` from :func:`integrate`.

    Parameters
    ----------
    scenario
        As for :func:`integrate`.
    rtol, atol
        Tolerances of the integrator (relative; absolute in SI units).

    Returns
    -------
    ndarray, shape (agents, 1, 4)
        ``(P, V, phi, omega)`` of each agent at ``t = duration``.
    """
    _, states = integrate(scenario, t_eval=np.array([scenario.simulation.duration]), rtol=rtol, atol=atol)
    return states[-1]


def _check(scenario: Scenario, model: VehicleModel) -> None:
    """Refuse, with one line naming the field, what the reference does not integrate."""
    function = scenario.interaction.function
    if uses_coupling(function):
        raise ValueError(
            f"interaction.function: the continuous reference supports only functions without "
            f"the coupling flag F_en (repulsion, attraction), got {function!r}"
        )
    n_axes = scenario.space.axes
    if n_axes != 1:
        raise ValueError(f"space.axes: the continuous reference supports one axis only, got {n_axes}")
    if model.body_names:
        raise ValueError(
            f"model.kind: the continuous reference integrates the linearisation, which is not the "
            f"whole of {model.kind!r}: its body state {tuple(model.body_names)} has no place in it"
        )
    names = tuple(model.state_names)
    if len(names) != model.law_states:
        raise ValueError(
            f"model.kind: the continuous reference needs the state of its linearisation, the law's "
            f"{model.law_states} components, got {len(names)} components {names} for {model.kind!r}"
        )


def _times(scenario: Scenario, t_eval: np.ndarray | None) -> np.ndarray:
    """The output times: ``t_eval``, or the engine's recorded times; all within ``[0, duration]``."""
    sim = scenario.simulation
    if t_eval is None:
        t_eval = record_steps(sim.n_steps, sim.record_every) * sim.dt
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.size and (t_eval.min() < 0.0 or t_eval.max() > sim.duration):
        raise ValueError(f"t_eval: times must lie within [0, duration = {sim.duration:g}] s")
    return t_eval


class _ClosedLoop:
    """The swarm's closed loop (2), (6) on one axis, each pair's push scaled by a weight.

    The weight of a pair is 1 inside ``reach``, 0 outside, and the equivalent
    control ``alpha`` while it slides on ``|d| = reach``; the push is evaluated
    at ``|d|`` clamped below ``reach``, so that the right-hand side stays
    continuous within a segment.  The flat vector ``y`` of the integrator is
    the state ``(agents, n_state)`` of the model, raveled.

    Parameters
    ----------
    scenario
        The scenario, checked by :func:`_check`.
    model
        Its vehicle model; the closed loop is that of its linearisation ``(A, B)``.
    """

    def __init__(self, scenario: Scenario, model: VehicleModel):
        c, ia = scenario.controller, scenario.interaction
        self.a, self.b = model.linearisation()
        self.gains = model.gains(c.r_l, c.im_l, c.im_r)
        self.n_state = len(model.state_names)
        x0 = build(scenario).state[:, 0, :]
        self.n_agents = x0.shape[0]
        self.size = self.n_agents * self.n_state
        self.y0 = x0.ravel()
        self.first, self.second = np.triu_indices(self.n_agents, k=1)
        self.function, self.d_t, self.c_max = ia.function, ia.d_t, ia.c_max
        self.reach, self.below_reach = ia.reach, np.nextafter(ia.reach, 0.0)

    def states(self, y: np.ndarray) -> np.ndarray:
        """The flat vector ``y`` as states, shape ``(agents, n_state)``."""
        return y.reshape(self.n_agents, self.n_state)

    def pair_measure(self, y: np.ndarray) -> np.ndarray:
        """``d = P*_j - P*_i`` (6) of each pair ``i < j``."""
        p_star = interaction_point(self.states(y), self.gains)
        return p_star[self.second] - p_star[self.first]

    def velocity(self, y: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """``x_dot`` (2) with each pair's push ``weight f(min(|d|, reach^-)) sign(d)``."""
        d = self.pair_measure(y)
        f_inside = evaluate(
            self.function, np.minimum(np.abs(d), self.below_reach),
            k_p=self.gains[0], reach=self.reach, d_t=self.d_t, c_max=self.c_max,
        )  # fmt: skip
        push = weight * f_inside * np.sign(d)
        u = np.zeros(self.n_agents)
        np.add.at(u, self.first, push)
        np.subtract.at(u, self.second, push)
        u = np.clip(u, -self.c_max, self.c_max)
        return (self.states(y) @ self.a.T + u[:, None] * self.b).ravel()

    def sigma_rate(self, y: np.ndarray, weight: np.ndarray, p: int, w: float) -> float:
        """``d sigma_p / dt`` with pair ``p`` given the weight ``w``, ``sigma = |d| - reach``."""
        weight = weight.copy()
        weight[p] = w
        x_dot = self.states(self.velocity(y, weight))
        d_dot = interaction_point(x_dot[self.second[p]] - x_dot[self.first[p]], self.gains)
        return float(np.sign(self.pair_measure(y)[p]) * d_dot)

    def weights(self, y: np.ndarray, mode: np.ndarray) -> np.ndarray:
        """Each pair's weight: 1 inside, 0 outside, the equivalent control while sliding.

        The equivalent control is the ``alpha`` in [0, 1] with ``d sigma / dt = 0``.
        """
        weight = (mode == INSIDE).astype(float)
        for p in np.flatnonzero(mode == SLIDING):
            out, into = self.sigma_rate(y, weight, p, 0.0), self.sigma_rate(y, weight, p, 1.0)
            # Clamped so that trial stages just past the slide's end stay continuous.
            if out >= 0.0:
                weight[p] = 0.0
            elif into <= 0.0:
                weight[p] = 1.0
            else:
                weight[p] = brentq(lambda w: self.sigma_rate(y, weight, p, w), 0.0, 1.0, xtol=1e-15)
        return weight

    def rhs(self, t: float, y: np.ndarray, mode: np.ndarray) -> np.ndarray:
        """The right-hand side of a segment with the pairs' modes ``mode``."""
        return self.velocity(y, self.weights(y, mode))

    def initial_mode(self, y: np.ndarray) -> np.ndarray:
        """Each pair's mode at the start: inside if ``|d| < reach``, else outside."""
        return np.where(np.abs(self.pair_measure(y)) < self.reach, INSIDE, OUTSIDE)

    def events(self, mode: np.ndarray) -> tuple[list[Callable], list[Owner]]:
        """Terminal events ending each pair's mode; for each, its pair and the mode it leads to.

        A crossing of ``reach`` leads to ``None``: decided by :meth:`crossing_mode`.
        Each crossing event watches only for leaving the current side (its
        ``direction``), so a segment restarted on ``reach`` does not trigger it again.
        """
        found, owners = [], []
        weight = (mode == INSIDE).astype(float)
        for p, pair_mode in enumerate(mode):
            if pair_mode == SLIDING:
                # The slide ends where the outside push stops pointing in (w = 0)
                # or the inside push stops pointing out (w = 1).
                for w, direction, leads_to in ((0.0, 1.0, OUTSIDE), (1.0, -1.0, INSIDE)):
                    found.append(_event(lambda t, y, mode, p=p, w=w: self.sigma_rate(y, weight, p, w), direction))
                    owners.append((p, leads_to))
            else:
                direction = 1.0 if pair_mode == INSIDE else -1.0
                found.append(_event(lambda t, y, mode, p=p: abs(self.pair_measure(y)[p]) - self.reach, direction))
                owners.append((p, None))
        return found, owners

    def crossing_mode(self, y: np.ndarray, mode: np.ndarray, p: int) -> int:
        """Mode of pair ``p`` on reaching ``|d| = reach`` from its side ``mode[p]``.

        It crosses, unless the push on the far side points straight back: then it slides.
        """
        weight = self.weights(y, mode)
        if mode[p] == OUTSIDE:
            new = SLIDING if self.sigma_rate(y, weight, p, 1.0) > 0.0 else INSIDE
        else:
            new = SLIDING if self.sigma_rate(y, weight, p, 0.0) < 0.0 else OUTSIDE
        if new == SLIDING and np.any(mode == SLIDING):
            raise RuntimeError("two pairs would slide on |d| = R + R_j at once; not supported")
        return new

    def mode_after(
        self, y: np.ndarray, mode: np.ndarray, owners: list[Owner], t_events: list[np.ndarray]
    ) -> np.ndarray:
        """The pairs' modes after a segment ended at ``y`` by the events that fired (``t_events``)."""
        new_mode = mode.copy()
        for (p, leads_to), times in zip(owners, t_events):
            if times.size:
                new_mode[p] = self.crossing_mode(y, mode, p) if leads_to is None else leads_to
        return new_mode

    def segment(self, mode: np.ndarray, t0: float, y0: np.ndarray, t_end: float, rtol: float, atol: float):
        """Integrate from ``(t0, y0)`` with the modes ``mode`` until ``t_end`` or a terminal event.

        Returns
        -------
        sol : OdeResult
            ``solve_ivp``'s result with dense output; ``status`` 1 if an event ended it.
        owners : list of (int, int or None)
            Each event's pair and the mode it leads to, in the order of ``sol.t_events``.
        """
        found, owners = self.events(mode)
        sol = solve_ivp(
            self.rhs, (t0, t_end), y0, method="DOP853", rtol=rtol, atol=atol,
            events=found, dense_output=True, args=(mode,),
        )  # fmt: skip
        if not sol.success:
            raise RuntimeError(f"solve_ivp failed at t = {sol.t[-1]:g} s: {sol.message}")
        return sol, owners


def _event(function: Callable, direction: float) -> Callable:
    """``function`` marked as a terminal event of ``solve_ivp`` watching for ``direction``."""
    function.terminal = True
    function.direction = direction
    return function
