"""The quadrotor's flight controller: its attitude, rate and altitude loops, and the two inner loops that feed them.

The TMEM law gives each horizontal axis ``a`` its tilt set-point ``U_a``.  The
tilt on axis ``a`` is the angle of the thrust axis ``b_3 = R e_3`` from the
vertical, seen along the other horizontal axis, ``phi_a = atan2(b_3a, b_3z)``.
The flight controller runs every sub-step ``h`` (zero-order hold, as
a digital one does) and turns the set-points into what the vehicle takes:

* attitude loop, the paper's (1)::

      omega_d = kp (phi_d - phi)                                   (Q5)

  on each axis, as body rates: ``w_y,d = kp (phi_d,x - phi_x)``,
  ``w_x,d = -kp (phi_d,y - phi_y)`` (a tilt along +x is a rotation about +y,
  along +y about -x), and the yaw held at 0 with ``w_z,d = -kp psi``;
* rate loop, the paper's ``omega' = kd (omega_d - omega)`` on the body rates,
  realised as moments through the rotors and their lag (RotorPy's ``cmd_ctbr``
  with ``k_w = kd``)::

      M = J kd (w_d - w)                                           (Q6)

* altitude hold: a collective thrust whose vertical part carries the weight
  and a PD correction of the height ``z`` (0 at the start)::

      T = m (g - k_zp z - k_zd z') / b_3z                           (Q7)

  so that, height held, the horizontal acceleration on each axis is
  ``g tan(phi_a)``: with this tilt and ``T b_3z = m g`` it is exactly
  ``(T / m) b_3a = g b_3a / b_3z``, on each axis apart, and to first order it
  is (2)'s ``g phi``.  (Holding the thrust at ``m g`` instead would give
  ``g sin``, and the vehicle would sink as it tilts.)
* drag feed-forward (``drag_feedforward``): the frame's and rotors' drag
  slows a quadrotor in free flight (the Crazyflie's rotor drag alone, by
  ``c_h = 4 k_d o_h / m = 0.24 /s``), where (2)'s agent keeps its speed.  The
  controller adds the tilt that balances the drag it would feel now,
  ``phi_ff,a = atan(-D_a / (m g))`` with ``D_a`` the aerodynamic force on axis
  ``a`` (world frame), to the set-point::

      phi_d = U + phi_ff                                           (Q8)

That is the *tilt loop* (``[model] inner_loop = "tilt"``).  The default, the
*acceleration loop*, feeds (Q5)-(Q7) the tilt set-points (Q9)-(Q11) instead:
those that give the airframe the horizontal acceleration of the paper's linear
agent (2), its drag cancelled; (Q8) is not used.

The acceleration loop
---------------------
``[model] inner_loop = "acceleration"`` (:mod:`tmem.vehicles.quadrotor`).  The flight controller
runs, per axis, the paper's attitude model (1) as a reference, the tilt the linear agent would have::

    phi_r' = omega_r,   omega_r' = kp kd (U - phi_r) - kd omega_r              (Q9)

stepped exactly (zero-order hold over the sub-step ``h``, as the linear model is over ``dt``).
It asks the airframe for the linear agent's horizontal acceleration ``g phi_r`` (2) and cancels
the aerodynamic force ``D`` it feels (world frame; the drag of the airspeed, which an
accelerometer measures as the specific force less the rotors' thrust), so that the drag no
longer acts on the horizontal motion the law sees.  The thrust, per unit mass, is to be::

    f_a = g phi_r,a - D_a / m,   f_z = g - k_zp z - k_zd z'                      (Q10)

(``f_z`` is the altitude hold (Q7)'s), so the thrust axis is to lean by
``theta_a = atan2(f_a, f_z)`` on each axis.  The attitude and rate loops (Q5)-(Q6) are those of
the tilt loop; they take the set-point that makes their closed loop, the paper's (1) with the
rotors' inflow damping ``c_r`` on the body rate, follow ``theta`` without lag (its inverse,
``phi_d = theta + (theta'' + (kd + c_r) theta') / (kp kd)``)::

    phi_d,a = theta_a + U_a - phi_r,a + ((c + c_r,a) omega_r,a + (kd + c_r,a) c phi_r,a) / (kp kd)   (Q11)

``theta = phi_r + delta``: the reference's own part of the inverse is ``U - phi_r`` by (Q9); the
drag's tilt ``delta = -D_a / (m g)`` changes as the velocity does, ``delta' = c V' / g = c phi_r``
and ``delta'' = c omega_r``, with ``c = k_d sum_k o_k / m`` the rotors' drag per unit mass (the
hover's ``c_h`` at hover) and ``c_r,a = k_z a^2 sum_k o_k / I`` (``I_yy`` on x, ``I_xx`` on y).
The frame's quadratic drag is cancelled in (Q10) but not anticipated in (Q11).

Linearised at hover with the motors' lag taken to 0, the airframe's tilt then stays at
``phi_r + c_h V / g`` and its rate at ``omega_r + c_h phi_r``, and ``V' = g phi_r``: the
airframe moves as (2).  What the law reads, the airframe's own tilt and rate, is (2)'s state
in the coordinates ``T`` of :func:`reported_coordinates`.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.vehicles.linear import state_matrices, zero_order_hold
from tmem.vehicles.rigid_body import loads, rotor_commands

#: The reference (Q9) in the body state, after the gusts: each axis's tilt and its rate.
REFERENCE_NAMES = ("phi_r_x", "omega_r_x", "phi_r_y", "omega_r_y")
REFERENCE_UNITS = ("rad", "rad s-1", "rad", "rad s-1")
REFERENCE_LONG_NAMES = (
    "reference tilt along x (the linear agent's)", "reference tilt rate along x",
    "reference tilt along y (the linear agent's)", "reference tilt rate along y",
)  # fmt: skip
#: The fields of the step record that hold (Q9)'s zero-order hold over a sub-step.
REFERENCE_FIELDS = [("hold_pp", float), ("hold_pw", float), ("hold_wp", float), ("hold_ww", float),
                    ("hold_pu", float), ("hold_wu", float)]  # fmt: skip


def reference_hold(kp: float, kd: float, h: float) -> tuple[float, ...]:
    """(Q9)'s exact zero-order hold over ``h``: ``(Ad_pp, Ad_pw, Ad_wp, Ad_ww, Bd_p, Bd_w)``.

    Parameters
    ----------
    kp, kd : float
        The attitude and rate gains of (1) (1/s).
    h : float
        The sub-step (s).
    """
    a, b = state_matrices(kp, kd, 0.0)
    ad, bd = zero_order_hold(a[2:, 2:], b[2:], h)
    return float(ad[0, 0]), float(ad[0, 1]), float(ad[1, 0]), float(ad[1, 1]), float(bd[0]), float(bd[1])


@numba.njit(cache=True, inline="always")
def advance_reference(ref, ux, uy, params):
    """The reference (Q9) ``(phi_r,x, omega_r,x, phi_r,y, omega_r,y)`` one sub-step on, ``U`` held.

    Parameters
    ----------
    ref : tuple of 4 float
        The reference now (rad, rad/s).
    ux, uy : float
        Tilt set-points ``U`` on x and y (rad).
    params : QuadrotorStep
        Its ``hold_*`` fields (:func:`reference_hold`).
    """
    p = params
    return (
        p.hold_pp * ref[0] + p.hold_pw * ref[1] + p.hold_pu * ux,
        p.hold_wp * ref[0] + p.hold_ww * ref[1] + p.hold_wu * ux,
        p.hold_pp * ref[2] + p.hold_pw * ref[3] + p.hold_pu * uy,
        p.hold_wp * ref[2] + p.hold_ww * ref[3] + p.hold_wu * uy,
    )


@numba.njit(cache=True, inline="always")
def acceleration_loop(s, loaded, ref, ux, uy, params):
    """Collective thrust and body-rate set-points ``(T, w_x,d, w_y,d, w_z,d)`` of the acceleration loop:
    (Q10)-(Q11), then (Q5) and (Q7) (:func:`attitude_commands`).

    The attitude loop (Q5) needs each axis's error ``phi_d,a - phi_a``, with ``phi_d,a`` (Q11)
    ``theta_a`` plus the reference's terms.  ``theta_a - phi_a``, the angle from the thrust axis
    to the thrust asked for (Q10), seen along the other axis, is computed as one angle,
    ``atan2(f_a b_3z - f_z b_3a, f_z b_3z + f_a b_3a)``: the difference of the two ``atan2``
    while both lie within (-pi/2, pi/2) (``f_z`` and ``b_3z`` positive, a vehicle upright and
    holding its height), and the shorter way round otherwise.

    Parameters
    ----------
    s : tuple of 17 float
        The body's state (:mod:`tmem.vehicles.rigid_body`).
    loaded : tuple
        Its attitude and the wrench on it, :func:`~tmem.vehicles.rigid_body.loads` (in the wind).
    ref : tuple of 4 float
        The reference (Q9) now.
    ux, uy : float
        Tilt set-points ``U`` on x and y (rad).
    params : QuadrotorStep
    """
    frame = params
    r, (_, _, _, _, _, _, ax, ay, az) = loaded
    force_z = frame.g - params.altitude_kp * s[2] - params.altitude_kd * s[5]
    force_x = frame.g * ref[0] - (r[0] * ax + r[1] * ay + r[2] * az) / frame.mass
    force_y = frame.g * ref[2] - (r[3] * ax + r[4] * ay + r[5] * az) / frame.mass
    b3x, b3y, b3z = r[2], r[5], r[8]
    lean_x = math.atan2(force_x * b3z - force_z * b3x, force_z * b3z + force_x * b3x)  # theta_x - phi_x
    lean_y = math.atan2(force_y * b3z - force_z * b3y, force_z * b3z + force_y * b3y)
    rotors = s[13] + s[14] + s[15] + s[16]
    c = frame.k_d * rotors / frame.mass
    inflow = frame.k_z * frame.offset * frame.offset * rotors
    c_rx, c_ry = inflow / frame.iyy, inflow / frame.ixx
    kpkd, kd = params.kp * params.kd, params.kd
    error_x = lean_x + ux - ref[0] + ((c + c_rx) * ref[1] + (kd + c_rx) * c * ref[0]) / kpkd
    error_y = lean_y + uy - ref[2] + ((c + c_ry) * ref[3] + (kd + c_ry) * c * ref[2]) / kpkd
    return attitude_commands(s, r, error_x, error_y, params)


def initial_reference(s: tuple, tilts: tuple[float, float], rates: tuple[float, float], frame, g: float, wind: tuple) -> np.ndarray:
    """The reference (Q9) of an airframe starting in ``s``: the tilt whose (Q10) is the airframe's.

    ``tan(phi_a) = (g phi_r,a - D_a / m) / g`` gives ``phi_r,a = tan(phi_a) + D_a / (m g)``, and
    ``omega_r,a = omega_a - c phi_r,a`` (the module text): an airframe started at the tilt that
    balances its drag has a level reference.

    Parameters
    ----------
    s : tuple of 17 float
        The body's state at the start.
    tilts, rates : tuple of 2 float
        Its tilt and tilt rate on x and y (rad, rad/s).
    frame : Airframe
    g : float
        Gravity (m/s^2).
    wind : tuple of 3 float
        The wind of the first step (m/s, world frame).
    """
    r, (_, _, _, _, _, _, ax, ay, az) = loads(s, frame, wind)
    c = frame.k_d * sum(s[13:17]) / frame.mass
    drag = ((r[0] * ax + r[1] * ay + r[2] * az) / frame.mass, (r[3] * ax + r[4] * ay + r[5] * az) / frame.mass)
    phi = [math.tan(t) + d / g for t, d in zip(tilts, drag)]
    return np.array([phi[0], rates[0] - c * phi[0], phi[1], rates[1] - c * phi[1]])


def reported_coordinates(c_h: float, g: float) -> np.ndarray:
    """``T``: the airframe's ``(P, V, phi, omega)`` from (2)'s under the acceleration loop, at hover.

    ``phi = phi_r + (c_h / g) V`` and ``omega = omega_r + c_h phi_r`` (the module text)::

        T = [[1, 0, 0, 0], [0, 1, 0, 0], [0, c_h / g, 1, 0], [0, 0, c_h, 1]]

    Parameters
    ----------
    c_h : float
        The rotors' drag per unit mass at hover (1/s).
    g : float
        Gravity (m/s^2).
    """
    t = np.eye(4)
    t[2, 1], t[3, 2] = c_h / g, c_h
    return t


@numba.njit(cache=True, inline="always")
def tilt_loop(s, loaded, ux, uy, params):
    """Collective thrust and body-rate set-points ``(T, w_x,d, w_y,d, w_z,d)`` of the tilt loop:
    (Q8), then (Q5) and (Q7) (:func:`attitude_commands`).

    The feed-forward (Q8) balances the aerodynamic force the vehicle feels, the drag of its
    airspeed: an accelerometer measures it (the specific force less the rotors' thrust), with no
    knowledge of the wind.

    Parameters
    ----------
    s : tuple of 17 float
        The body's state.
    loaded : tuple
        Its attitude and the wrench on it, :func:`~tmem.vehicles.rigid_body.loads` (in the wind,
        (D1) of :mod:`tmem.vehicles.wind`).
    ux, uy : float
        Tilt set-points ``U`` on x and y (rad).
    params : QuadrotorStep
    """
    frame = params
    r, (_, _, _, _, _, _, ax, ay, az) = loaded
    if params.feedforward:
        weight = frame.mass * frame.g
        ux += math.atan(-(r[0] * ax + r[1] * ay + r[2] * az) / weight)
        uy += math.atan(-(r[3] * ax + r[4] * ay + r[5] * az) / weight)
    b3z = r[8]
    return attitude_commands(s, r, ux - math.atan2(r[2], b3z), uy - math.atan2(r[5], b3z), params)


@numba.njit(cache=True, inline="always")
def attitude_commands(s, r, error_x, error_y, params):
    """Collective thrust (Q7) and body-rate set-points (Q5) ``(T, w_x,d, w_y,d, w_z,d)`` for the tilt errors.

    Parameters
    ----------
    s : tuple of 17 float
        The body's state.
    r : tuple of 9 float
        Its attitude's rotation (:func:`~tmem.vehicles.rigid_body.rotation`).
    error_x, error_y : float
        Each axis's ``phi_d,a - phi_a`` (rad).
    params : QuadrotorStep
    """
    frame = params
    thrust = frame.mass * (frame.g - params.altitude_kp * s[2] - params.altitude_kd * s[5]) / r[8]
    rate_x = -params.kp * error_y
    rate_y = params.kp * error_x
    rate_z = -params.kp * math.atan2(r[3], r[0])
    return thrust, rate_x, rate_y, rate_z


@numba.njit(cache=True, inline="always")
def rate_loop(s, thrust, rate_x, rate_y, rate_z, params):
    """The rotor speeds commanded for the thrust and the body rates asked for: (Q6), then the allocation.

    Parameters
    ----------
    s : tuple of 17 float
        The body's state.
    thrust : float
        Collective thrust (N).
    rate_x, rate_y, rate_z : float
        Body-rate set-points (rad/s).
    params : QuadrotorStep
    """
    frame, kd = params, params.kd
    mx = frame.ixx * kd * (rate_x - s[10])
    my = frame.iyy * kd * (rate_y - s[11])
    mz = frame.izz * kd * (rate_z - s[12])
    return rotor_commands(thrust, mx, my, mz, frame)
