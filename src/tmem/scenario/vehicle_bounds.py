"""The bounds of a quadrotor (``[model] kind = "quadrotor"``) and of its wind: the tilt its rotors
hold, the stability of its inner loops, the airspeed its tilt and drag allow, the gusts it flies
in (the figures are :mod:`tmem.scenario.bounds`'s, derived in ``docs/parameters.md`` and
``docs/vehicles.md``).

:func:`check_vehicle` raises :class:`~tmem.scenario.tables.FieldError` on a value beyond a bound
and gives back the :class:`~tmem.scenario.bounds.Doubt` of each doubtful one.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from tmem.scenario.bounds import (
    ROTOR_SHARE, Doubt, airspeed_limit, combined_tilt, held_tilt, hover_drag, loop_poles, peak_tilt, slowest_decay, substeps,
)  # fmt: skip
from tmem.scenario.motion_bounds import per_axis_values, speeds
from tmem.scenario.tables import FieldError
from tmem.scenario.wind_table import STRONGEST, scales

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario


class Limits:
    """A quadrotor's figures: the tilts its rotors hold, its drag, the airspeeds they allow.

    Parameters
    ----------
    model : QuadrotorModelParams
        The ``[model]`` table.
    axes : int
        Horizontal axes of the run (1 or 2).

    Attributes
    ----------
    held, margin : float
        The tilt (rad) at which the fastest rotors carry the weight (Q7), and at which rotors at
        :data:`~tmem.scenario.bounds.ROTOR_SHARE` of their fastest do.
    drag, inflow : float
        The rotors' drag and inflow per unit mass at hover, ``c_h`` and ``c_v`` (1/s).
    airspeed, airspeed_margin : float
        The horizontal airspeeds (m/s) whose drag the thrust balances at ``held`` and ``margin``.
    vertical : float
        The vertical airspeed (m/s) whose inflow drag the thrust's margin over the weight balances.
    """

    def __init__(self, model, axes: int):
        m = model
        self.held = held_tilt(m.mass, m.g, m.k_eta, m.rotor_speed_max)
        self.margin = held_tilt(m.mass, m.g, m.k_eta, ROTOR_SHARE * m.rotor_speed_max)
        self.drag = hover_drag(m.mass, m.g, m.k_eta, m.rotor_drag)
        self.inflow = hover_drag(m.mass, m.g, m.k_eta, m.inflow_drag)
        frame = m.c_dx if axes == 1 else min(m.c_dx, m.c_dy)
        self.airspeed = airspeed_limit(m.mass, m.g, self.drag, frame, self.held)
        self.airspeed_margin = airspeed_limit(m.mass, m.g, self.drag, frame, self.margin)
        spare = min(4.0 * m.k_eta * m.rotor_speed_max**2 - m.mass * m.g, m.mass * m.g)  # up: the thrust falls to 0
        self.vertical = spare / (m.mass * self.inflow) if self.inflow > 0.0 else math.inf
        self.weight, self.thrust = m.mass * m.g, 4.0 * m.k_eta * m.rotor_speed_max**2


def check_vehicle(scenario: Scenario) -> list[Doubt]:
    """The quadrotor's bounds (module text); raise :class:`FieldError` beyond one, give back the doubts.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid and checked against each other.
    """
    if scenario.model.kind != "quadrotor":
        return []
    limits = Limits(scenario.model, scenario.space.axes)
    doubts = _check_loops(scenario) + _check_tilts(scenario, limits)
    return doubts + _check_airspeeds(scenario, limits) + _check_gusts(scenario, limits)


def _check_loops(scenario: Scenario) -> list[Doubt]:
    """The attitude loop (Q5)-(Q6) about x, y and the yaw axis, and the altitude hold (Q7): stable,
    sampled every sub-step through the motors' lag; doubtful where their slowest mode decays
    slower than the slow roots (5) turn."""
    m, doubts = scenario.model, []
    h = scenario.simulation.dt / substeps(scenario.simulation.dt, m.inner_period)
    hover = math.sqrt(m.mass * m.g / (4.0 * m.k_eta))
    hubs = 4.0 * hover * (m.arm_length / math.sqrt(2.0)) ** 2  # 4 o_h a^2
    # The rotors damp the body rates: their inflow k_z the roll and pitch, their drag k_d the yaw (twice: both hub offsets).
    dampings = [m.inflow_drag * hubs / m.iyy, m.inflow_drag * hubs / m.ixx, 2.0 * m.rotor_drag * hubs / m.izz]
    loops = (
        ("the attitude loop (Q5)-(Q6)", "model.kp", "model.kd", m.kd, dampings,
         lambda gain: gain),
        ("the altitude hold (Q7)", "model.altitude_kp", "model.altitude_kd", m.altitude_kd,
         [hover_drag(m.mass, m.g, m.k_eta, m.inflow_drag)], lambda gain: gain / m.altitude_kd),
    )  # fmt: skip
    im_r = scenario.controller.im_r
    for name, field, rate_field, rate_gain, dampings, outer in loops:
        gain = m.kp if field == "model.kp" else m.altitude_kp

        def radius(g: float) -> float:
            return max(float(np.max(np.abs(loop_poles(outer(g), rate_gain, c, m.tau_m, h)))) for c in dampings)

        largest = radius(gain)
        if not largest < 1.0:
            stable = _largest_stable(radius, gain)
            blame, value = (field, gain) if stable > 0.0 else (rate_field, rate_gain)
            where = f"stable for {field.split('.')[1]} below {stable:.4g}" if stable > 0.0 else "unstable at any gain"
            raise FieldError(blame, f"{value:g} makes {name} unstable: linearised at hover, through the motors' lag "
                             f"tau_m = {m.tau_m:g} s and sampled every {h:g} s, its largest pole has |z| = "
                             f"{largest:.4g}, outside the unit circle (here {where})")  # fmt: skip
        decay = slowest_decay(np.array([largest]), h)
        if decay < im_r:
            doubts.append(Doubt(field, f"{gain:g}: {name}'s slowest mode decays at {decay:.3g} /s, slower than the slow "
                                f"roots (5) turn (im_r = {im_r:g} rad/s): its transients outlast the law's motion"))  # fmt: skip
    return doubts


def _largest_stable(radius, gain: float) -> float:
    """The largest gain below ``gain`` whose loop is stable (``radius`` below 1), by bisection in its
    logarithm; 0 where none from 1e-9 of it is."""
    low, high = gain * 1e-9, gain
    if not radius(low) < 1.0:
        return 0.0
    for _ in range(60):
        middle = math.sqrt(low * high)
        low, high = (middle, high) if radius(middle) < 1.0 else (low, middle)
    return low


def _check_tilts(scenario: Scenario, limits: Limits) -> list[Doubt]:
    """The start's tilts and the law's tilt limit against the tilt the rotors hold."""
    model, ia, doubts = scenario.model, scenario.interaction, []
    held = (f"the {limits.held:.4g} rad at which the rotors' most thrust 4 k_eta o_max^2 = {limits.thrust:.4g} N "
            f"carries the weight m g = {limits.weight:.4g} N")  # fmt: skip
    spare = f"the {limits.margin:.4g} rad beyond which rotors at {ROTOR_SHARE:.0%} of their fastest no longer carry the weight"
    acceleration = model.inner_loop == "acceleration"
    lean = math.atan(ia.c_max) if acceleration else ia.c_max
    said = f"{ia.c_max:g} rad leans the airframe by {lean:.4g} rad" + (" (atan(c_max): g c_max asked of (2))" if acceleration else "")
    if lean >= limits.held:
        raise FieldError("interaction.c_max", f"{said}, not less than {held}")
    if lean > limits.margin:
        doubts.append(Doubt("interaction.c_max", f"{said}, beyond {spare}"))
    axes = scenario.space.axes
    for k, agent in enumerate(scenario.agents):
        tilts, rates = (np.ravel(agent.tilt) * np.ones(axes)).tolist(), (np.ravel(agent.tilt_rate) * np.ones(axes)).tolist()
        if max(abs(t) for t in tilts) >= math.pi / 2:
            raise FieldError(f"agents[{k}].tilt", f"{per_axis_values(tilts)} rad: a tilt of the thrust axis along an axis, "
                             "atan2(b_3a, b_3z), lies within +-pi/2 = 1.571 rad")  # fmt: skip
        start = combined_tilt(tilts)
        if start >= limits.held:
            raise FieldError(f"agents[{k}].tilt", f"{per_axis_values(tilts)} rad leans the thrust axis {start:.4g} rad from the "
                             f"vertical, not less than {held}")  # fmt: skip
        peaks = [peak_tilt(t, r, model.kp, model.kd) for t, r in zip(tilts, rates)]
        if max(peaks) >= math.pi / 2:
            raise FieldError(f"agents[{k}].tilt_rate", f"{per_axis_values(rates)} rad/s carries the tilt to {max(peaks):.4g} rad under "
                             "(1), past the horizontal")  # fmt: skip
        peak = combined_tilt(peaks)
        if peak > limits.margin:
            name = "tilt" if start > limits.margin else "tilt_rate"
            sinks = " (the rotors cannot carry the weight: it sinks)" if peak >= limits.held else ""
            doubts.append(Doubt(f"agents[{k}].{name}", f"the thrust axis leans up to {peak:.4g} rad, beyond {spare}{sinks}"))
    return doubts


def _check_airspeeds(scenario: Scenario, limits: Limits) -> list[Doubt]:
    """The starts' airspeeds and the constant wind's against what the tilt and the drag allow."""
    wind, axes, doubts = scenario.wind, scenario.space.axes, []
    mean = wind.mean() if wind is not None else (0.0, 0.0, 0.0)
    still = np.array(mean[:axes])
    found = [("wind.velocity", "an agent holding its place in the wind", math.hypot(*still))] if wind is not None else []
    found += [(s.field, s.what, math.hypot(*(np.array(s.velocity) - still)) if not s.rms else math.hypot(s.rms, *still))
              for s in speeds(scenario)]  # fmt: skip
    why = (f"the airspeed whose drag (c_h = {limits.drag:.4g} /s, the rotors' at hover, and the frame's) the thrust "
           f"balances at the lean of")  # fmt: skip
    for field, what, airspeed in found:
        if airspeed > limits.airspeed:
            raise FieldError(field, f"{what} flies at {airspeed:.4g} m/s through the air, more than {limits.airspeed:.4g} m/s, "
                             f"{why} {limits.held:.4g} rad at which the fastest rotors carry the weight")  # fmt: skip
        if airspeed > limits.airspeed_margin:
            doubts.append(Doubt(field, f"{what} flies at {airspeed:.4g} m/s through the air, more than "
                                f"{limits.airspeed_margin:.4g} m/s, {why} {limits.margin:.4g} rad (rotors at {ROTOR_SHARE:.0%})"))  # fmt: skip
    if abs(mean[2]) > limits.vertical:
        raise FieldError("wind.vertical", f"{mean[2]:g} m/s: the rotors' inflow drag (c_v = {limits.inflow:.4g} /s at hover) "
                         f"of a vertical airspeed beyond {limits.vertical:.4g} m/s takes more than the thrust's margin "
                         "over the weight (or than the weight, up)")  # fmt: skip
    return doubts


def _check_gusts(scenario: Scenario, limits: Limits) -> list[Doubt]:
    """The gusts' intensities: the RMS airspeed of an agent holding its place against the airspeed
    the airframe holds; doubtful where a gust of 3 sigma goes beyond it."""
    wind = scenario.wind
    if wind is None or wind.turbulence is None:
        return []
    gusts = wind.turbulence
    field = "wind.turbulence." + next(k for k in ("sigma", "w20", "severity") if getattr(gusts, k) is not None)
    sigma, _ = scales(gusts)
    if max(sigma) > STRONGEST:
        raise FieldError(field, f"gives gusts of sigma = {max(sigma):g} m/s, more than {STRONGEST:g} m/s (stronger "
                         "than any surface wind measured; check the units: m/s)")  # fmt: skip
    axes = scenario.space.axes
    horizontal = sigma[:axes] if axes == 2 else sigma[:1]  # a 1-D run leaves the lateral gust out
    mean = wind.mean()
    still = math.hypot(*mean[:axes])
    rms = math.hypot(still, *horizontal)
    if rms > limits.airspeed:
        raise FieldError(field, f"gives sigma = {[round(s, 4) for s in sigma.tolist()]} m/s: an agent holding its place "
                         f"meets an RMS airspeed of {rms:.4g} m/s, more than the {limits.airspeed:.4g} m/s whose drag "
                         f"its thrust balances at {limits.held:.4g} rad, the lean at which the fastest rotors carry the weight")  # fmt: skip
    vertical = math.hypot(mean[2], sigma[2])
    if vertical > limits.vertical:
        raise FieldError(field, f"gives sigma_w = {sigma[2]:.4g} m/s: an RMS vertical airspeed of {vertical:.4g} m/s, "
                         f"more than the {limits.vertical:.4g} m/s whose inflow drag the thrust's margin balances")  # fmt: skip
    peak = still + 3.0 * float(max(horizontal))
    if peak > limits.airspeed:
        return [Doubt(field, f"a gust of 3 sigma takes the airspeed to {peak:.4g} m/s, more than the {limits.airspeed:.4g} m/s "
                      "the airframe holds: it is blown off its place 0.1 % of the time or more")]  # fmt: skip
    return []
