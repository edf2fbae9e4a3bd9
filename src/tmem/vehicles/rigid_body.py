"""A quadrotor as a rigid body with four rotors: the equations of RotorPy's ``Multirotor``, compiled.

The body's state, one flat tuple of 17 numbers in RotorPy's order (its wind
kept apart, a tuple ``(w_x, w_y, w_z)`` handed to each function)::

    (x, y, z, v_x, v_y, v_z, q_x, q_y, q_z, q_w, w_x, w_y, w_z, o_1, o_2, o_3, o_4)

position and velocity in the world frame (m, m/s; ``z`` up), the attitude as a
quaternion, scalar last, rotating body to world, the body rates (rad/s) and the
rotor speeds (rad/s).  With ``R`` the attitude's rotation, ``v_b = R^T (v - w)`` the
airspeed in the body frame (``w`` the wind, :mod:`tmem.vehicles.wind`) and ``r_k`` the hub of rotor ``k`` (Folk et al.,
RotorPy, ``rotorpy/vehicles/multirotor.py``)::

    x'   = v
    v'   = (R F_b) / m - g e_3                                   (Q1)
    q'   = 1/2 G(q)^T w                                          (Q2)
    w'   = J^-1 (M_b - w x J w)                                  (Q3)
    o_k' = (c_k - o_k) / tau_m                                   (Q4)

    F_b = sum_k (T_k + H_k) + D,   M_b = sum_k r_k x (T_k + H_k) + e_3 sum_k s_k k_m o_k^2
    T_k = k_eta o_k^2 e_3          thrust of rotor k
    H_k = -o_k diag(k_d, k_d, k_z) (v_b + w x r_k)   rotor drag and induced inflow at its hub
    D   = -|v_b| diag(c_Dx, c_Dy, c_Dz) v_b         parasitic drag of the frame

``c_k`` is rotor ``k``'s commanded speed, ``s_k`` its sense of turning.  The
rotors sit at ``(+a, +a)``, ``(+a, -a)``, ``(-a, -a)``, ``(-a, +a)`` (``a`` is the
arm length over sqrt 2: RotorPy's Crazyflie in its X configuration) and turn
``+1, -1, +1, -1``.  RotorPy's translational lift ``k_h`` and flapping moment
``k_flap`` are zero for the Crazyflie and left out; so are its ground and its
motor noise.  Like RotorPy, ``R`` is the rotation of the normalised
quaternion, and (Q2) does not renormalise: a step does, after it.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

#: Each rotor's hub in units of the arm's offset ``a`` along body x and y, and its sense of turning.
ROTOR_X = (1.0, 1.0, -1.0, -1.0)
ROTOR_Y = (1.0, -1.0, -1.0, 1.0)
ROTOR_SENSE = (1.0, -1.0, 1.0, -1.0)


class Airframe(NamedTuple):
    """The numbers of the rigid body and its rotors (SI units; :mod:`tmem.vehicles.quadrotor` fills them).

    The compiled functions read these fields by name from whatever record they are given: the
    quadrotor's step record has them all, and serves as the airframe.

    Attributes
    ----------
    mass, g : float
        Mass (kg) and gravity (m/s^2).
    ixx, iyy, izz : float
        Principal moments of inertia (kg m^2).
    offset : float
        ``a``: each hub's distance from the centre along body x and along body y (m), the arm
        length over sqrt 2.
    k_eta, k_m : float
        Thrust (N s^2/rad^2) and yaw-moment (N m s^2/rad^2) coefficients of a rotor.
    k_d, k_z : float
        Rotor drag in the rotor's plane and induced inflow along its axis (kg/rad).
    c_dx, c_dy, c_dz : float
        Parasitic drag of the frame along each body axis (N s^2/m^2).
    tau_m : float
        The motors' time constant (s).
    rotor_speed_max : float
        Fastest rotor speed (rad/s); commands are clipped to ``[0, rotor_speed_max]``.
    """

    mass: float
    g: float
    ixx: float
    iyy: float
    izz: float
    offset: float
    k_eta: float
    k_m: float
    k_d: float
    k_z: float
    c_dx: float
    c_dy: float
    c_dz: float
    tau_m: float
    rotor_speed_max: float


def hover_speed(frame: Airframe) -> float:
    """The rotor speed at which four rotors carry the weight (rad/s), ``sqrt(m g / (4 k_eta))``.

    Parameters
    ----------
    frame : Airframe
    """
    return math.sqrt(frame.mass * frame.g / (4.0 * frame.k_eta))


@numba.njit(cache=True, inline="always")
def rotation(qx, qy, qz, qw):
    """The rotation matrix of the quaternion ``(qx, qy, qz, qw)`` normalised, as nine numbers by rows.

    Parameters
    ----------
    qx, qy, qz, qw : float
        The quaternion, scalar last (any non-zero length).
    """
    s = 2.0 / (qx * qx + qy * qy + qz * qz + qw * qw)
    return (
        1.0 - s * (qy * qy + qz * qz), s * (qx * qy - qz * qw), s * (qx * qz + qy * qw),
        s * (qx * qy + qz * qw), 1.0 - s * (qx * qx + qz * qz), s * (qy * qz - qx * qw),
        s * (qx * qz - qy * qw), s * (qy * qz + qx * qw), 1.0 - s * (qx * qx + qy * qy),
    )  # fmt: skip


@numba.njit(cache=True, inline="always")
def wrench(s, r, frame, wind):
    """Force and moment on the body, in the body frame, and the aerodynamic part of the force.

    Returns ``(f_x, f_y, f_z, m_x, m_y, m_z, a_x, a_y, a_z)``: ``F_b``, ``M_b`` and ``sum_k H_k + D``
    of the module text (N, N m, N).

    Parameters
    ----------
    s : tuple of 17 float
        The body's state (module text).
    r : tuple of 9 float
        Its attitude's :func:`rotation`.
    frame : Airframe
    wind : tuple of 3 float
        The wind ``w`` (m/s, world frame).
    """
    air_x, air_y, air_z = s[3] - wind[0], s[4] - wind[1], s[5] - wind[2]  # the airspeed, world frame
    ub = r[0] * air_x + r[3] * air_y + r[6] * air_z  # v_b = R^T (v - w)
    vb = r[1] * air_x + r[4] * air_y + r[7] * air_z
    wb = r[2] * air_x + r[5] * air_y + r[8] * air_z
    wx, wy, wz = s[10], s[11], s[12]
    norm = math.sqrt(ub * ub + vb * vb + wb * wb)
    ax, ay, az = -norm * frame.c_dx * ub, -norm * frame.c_dy * vb, -norm * frame.c_dz * wb
    fz = az
    mx = my = mz = 0.0
    for k in range(4):
        o = s[13 + k]
        rx, ry = ROTOR_X[k] * frame.offset, ROTOR_Y[k] * frame.offset
        hx = -o * frame.k_d * (ub - wz * ry)  # airspeed at the hub: v_b + w x r_k
        hy = -o * frame.k_d * (vb + wz * rx)
        hz = -o * frame.k_z * (wb + wx * ry - wy * rx)
        lift = frame.k_eta * o * o + hz
        ax += hx
        ay += hy
        az += hz
        fz += lift
        mx += ry * lift  # r_k x (H_k + T_k), r_k in the rotors' plane
        my -= rx * lift
        mz += rx * hy - ry * hx + ROTOR_SENSE[k] * frame.k_m * o * o
    return ax, ay, fz, mx, my, mz, ax, ay, az


@numba.njit(cache=True, inline="always")
def loads(s, frame, wind):
    """``(R, wrench)``: the attitude's :func:`rotation` and the :func:`wrench` on the body in state ``s``.

    What (Q1)-(Q3) read, and what a flight controller measures (its attitude, and the
    aerodynamic force from its accelerometer): computed once per state and handed to both.

    Parameters
    ----------
    s : tuple of 17 float
        The body's state (module text).
    frame : Airframe
    wind : tuple of 3 float
        The wind (m/s, world frame).
    """
    r = rotation(s[6], s[7], s[8], s[9])
    return r, wrench(s, r, frame, wind)


@numba.njit(cache=True, inline="always")
def derivative(s, command, frame, wind):
    """``s'`` of (Q1)-(Q4): the body's state changing under the rotor speeds ``command``.

    Parameters
    ----------
    s, frame, wind
        As :func:`loads` takes them.
    command : tuple of 4 float
        The rotors' commanded speeds ``c_k`` (rad/s).
    """
    return derivative_under(s, loads(s, frame, wind), command, frame)


@numba.njit(cache=True, inline="always")
def derivative_under(s, loaded, command, frame):
    """``s'`` of (Q1)-(Q4) with the state's :func:`loads` already computed.

    Parameters
    ----------
    loaded : tuple
        ``loads(s, frame, wind)``: the state's attitude and wrench.
    s, command, frame
        As :func:`derivative` takes them.
    """
    r, (fx, fy, fz, mx, my, mz, _, _, _) = loaded
    qx, qy, qz, qw = s[6], s[7], s[8], s[9]
    wx, wy, wz = s[10], s[11], s[12]
    inverse_tau, inverse_mass = 1.0 / frame.tau_m, 1.0 / frame.mass
    return (
        s[3], s[4], s[5],
        (r[0] * fx + r[1] * fy + r[2] * fz) * inverse_mass,
        (r[3] * fx + r[4] * fy + r[5] * fz) * inverse_mass,
        (r[6] * fx + r[7] * fy + r[8] * fz) * inverse_mass - frame.g,
        0.5 * (qw * wx - qz * wy + qy * wz),
        0.5 * (qz * wx + qw * wy - qx * wz),
        0.5 * (-qy * wx + qx * wy + qw * wz),
        0.5 * (-qx * wx - qy * wy - qz * wz),
        (mx - (frame.izz - frame.iyy) * wy * wz) / frame.ixx,
        (my - (frame.ixx - frame.izz) * wz * wx) / frame.iyy,
        (mz - (frame.iyy - frame.ixx) * wx * wy) / frame.izz,
        (command[0] - s[13]) * inverse_tau,
        (command[1] - s[14]) * inverse_tau,
        (command[2] - s[15]) * inverse_tau,
        (command[3] - s[16]) * inverse_tau,
    )  # fmt: skip


@numba.njit(cache=True, inline="always")
def rotor_commands(thrust, mx, my, mz, frame):
    """The rotor speeds that give the collective thrust and the body moments asked for (RotorPy's allocation).

    The four rotor forces solve ``[T, M_x, M_y, M_z] = F f`` with the rows of ``F`` ``(1, 1, 1, 1)``,
    ``a (+1, -1, -1, +1)``, ``-a (+1, +1, -1, -1)`` and ``k_m / k_eta (+1, -1, +1, -1)``; the rows
    are orthogonal, so ``F^-1`` is ``F^T`` scaled row by row.  A speed is ``sign(f) sqrt(|f| / k_eta)``,
    clipped to ``[0, rotor_speed_max]``.

    Parameters
    ----------
    thrust : float
        Collective thrust ``T`` (N).
    mx, my, mz : float
        Body moments (N m).
    frame : Airframe
    """
    roll, pitch = mx / (4.0 * frame.offset), -my / (4.0 * frame.offset)
    yaw = mz * frame.k_eta / (4.0 * frame.k_m)
    c0 = _rotor_speed(0.25 * thrust + roll + pitch + yaw, frame)
    c1 = _rotor_speed(0.25 * thrust - roll + pitch - yaw, frame)
    c2 = _rotor_speed(0.25 * thrust - roll - pitch + yaw, frame)
    c3 = _rotor_speed(0.25 * thrust + roll - pitch - yaw, frame)
    return c0, c1, c2, c3


@numba.njit(cache=True, inline="always")
def _rotor_speed(force, frame):
    speed = math.copysign(math.sqrt(abs(force) / frame.k_eta), force)
    return min(max(speed, 0.0), frame.rotor_speed_max)
