"""An agent's attitude from its tilts: the quaternion that exchange formats carry.

The paper's model (2) moves an agent along a horizontal axis by tilting it: ``dV/dt = g phi``.
A multirotor accelerates along +x by pitching its thrust towards +x, a rotation about its body y
axis by ``phi_x``; along +y by rolling it towards +y, a rotation about its body x axis by
``-phi_y``.  With z up and no yaw, the attitude is the rotation

    R = Rz(0) Ry(phi_x) Rx(-phi_y),

Z-Y-X Euler angles (yaw 0, pitch ``phi_x``, roll ``-phi_y``), which turns the thrust axis ``e_z``
to ``(sin phi_x cos phi_y, sin phi_y, cos phi_x cos phi_y)``.  A run's tilt on a vertical axis (its
third, in 3-D) changes the thrust, not the attitude, and does not enter it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["attitude_quaternion"]


def attitude_quaternion(phi_x: np.ndarray, phi_y: np.ndarray) -> np.ndarray:
    """The attitude ``Ry(phi_x) Rx(-phi_y)`` (yaw 0, z up) as unit quaternions ``(qw, qx, qy, qz)``, ``qw > 0``.

    Parameters
    ----------
    phi_x : ndarray
        Tilt on the x axis (rad): positive pitches the thrust towards +x.
    phi_y : ndarray, same shape
        Tilt on the y axis (rad): positive rolls the thrust towards +y.

    Returns
    -------
    ndarray, shape (..., 4)
        The product of ``(cos(phi_x/2), 0, sin(phi_x/2), 0)`` and ``(cos(phi_y/2), -sin(phi_y/2), 0, 0)``.
    """
    cb, sb = np.cos(0.5 * np.asarray(phi_x)), np.sin(0.5 * np.asarray(phi_x))
    ca, sa = np.cos(-0.5 * np.asarray(phi_y)), np.sin(-0.5 * np.asarray(phi_y))
    return np.stack([ca * cb, sa * cb, ca * sb, -sa * sb], axis=-1)
