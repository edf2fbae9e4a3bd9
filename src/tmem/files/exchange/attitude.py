"""An agent's attitude as the exchange formats carry it: a unit quaternion ``(qw, qx, qy, qz)``.

A run that records a body attitude (a quadrotor's quaternion, ``q_x`` ... ``q_w`` in
``trajectory.nc``) exports that attitude as it was recorded (:func:`body_attitude`).  A run of the
paper's model (2) has only its tilts, and exports the attitude they define (:func:`attitude_quaternion`).

The tilt on a horizontal axis ``a`` is defined, as for the quadrotor (``docs/vehicles.md``), from the
thrust axis ``b_3`` (the body's z axis in the world): ``phi_a = atan2(b_3a, b_3z)``.  Model (2)
accelerates along ``a`` as ``g phi_a``: a tilt towards +x pitches the thrust towards +x, one towards
+y rolls it towards +y.  With z up and no yaw, the attitude with the tilts ``phi_x``, ``phi_y`` is

    R = Rz(0) Ry(theta) Rx(rho),   theta = phi_x,   tan(rho) = -tan(phi_y) cos(phi_x),

Z-Y-X Euler angles (yaw 0, pitch ``theta``, roll ``rho``), which turns ``e_z`` to a thrust axis along
``(tan phi_x, tan phi_y, 1)``.  A run's tilt on a vertical axis (its third, in 3-D) changes the
thrust, not the attitude, and does not enter it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["attitude_quaternion", "body_attitude"]


def attitude_quaternion(phi_x: np.ndarray, phi_y: np.ndarray) -> np.ndarray:
    """The attitude with the tilts ``phi_x``, ``phi_y`` and no yaw, ``Ry(theta) Rx(rho)``, as unit
    quaternions ``(qw, qx, qy, qz)``, ``qw > 0``.

    Parameters
    ----------
    phi_x : ndarray
        Tilt on the x axis, ``atan2(b_3x, b_3z)`` (rad), within (-pi/2, pi/2): positive pitches the
        thrust towards +x.
    phi_y : ndarray, same shape
        Tilt on the y axis, ``atan2(b_3y, b_3z)`` (rad), within (-pi/2, pi/2): positive rolls the
        thrust towards +y.

    Returns
    -------
    ndarray, shape (..., 4)
        The product of ``(cos(theta/2), 0, sin(theta/2), 0)`` and ``(cos(rho/2), sin(rho/2), 0, 0)``,
        ``theta = phi_x`` and ``rho = -atan(tan(phi_y) cos(phi_x))``.
    """
    theta = np.asarray(phi_x, dtype=float)
    rho = -np.arctan(np.tan(np.asarray(phi_y, dtype=float)) * np.cos(theta))
    cb, sb = np.cos(0.5 * theta), np.sin(0.5 * theta)
    ca, sa = np.cos(0.5 * rho), np.sin(0.5 * rho)
    return np.stack([ca * cb, sa * cb, ca * sb, -sa * sb], axis=-1)


def body_attitude(q_x: np.ndarray, q_y: np.ndarray, q_z: np.ndarray, q_w: np.ndarray) -> np.ndarray:
    """A recorded body attitude (scalar last, body to world) as unit quaternions ``(qw, qx, qy, qz)``,
    ``qw >= 0`` (``q`` and ``-q`` are one attitude).

    Parameters
    ----------
    q_x, q_y, q_z, q_w : ndarray, one shape
        The recorded quaternion's parts (``trajectory.nc``'s ``q_x`` ... ``q_w``).

    Returns
    -------
    ndarray, shape (..., 4)
    """
    q = np.stack([q_w, q_x, q_y, q_z], axis=-1).astype(float)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)
