"""Walls and obstacles (W1)-(W2): neighbours held still, with the last word on the set-point.

The gas stage (:mod:`tmem.engine.gas`) calls these for each agent when the box has walls or
obstacles; ``docs/gas.md`` derives them.

* **(W1)** A wall or an obstacle is a neighbour held still: the repulsion (8) acts on the distance
  from the agent's ``P*`` (6) to its nearest point, with ``R + R_w`` for ``R + R_j``
  (:func:`wall_pushes`, :func:`wall_params`).  Held still, it is the case the modal gains were
  designed for.
* **(W2)** Within its reach, the part of the agent's other pushes that points into it is dropped
  (:func:`keep_off`), and the others get what the tilt limit leaves after the walls' pushes
  (:func:`with_priority`).

The functions take agent ``i``'s slot; ``corrected``, each agent's ``(P*, P)`` per axis
(``Agents.corrected``, shape (agents, axes, 2)); ``walls``, the walled box's sides (shape (axes,); 0:
no walls on that axis, the box spans ``[0, side]``); ``obstacles``, each obstacle's centre and radius
(m, shape (obstacles, axes + 1)); ``box``, the periodic box's sides (0: open axis); and the number
of axes ``n_axes``.  A walled axis has two walls, at 0 and at ``side``, and each function takes them
in that order, by the same arithmetic.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law.interaction.kernels import FunctionParams, repulsion
from tmem.world.space import nearest_image


@numba.njit(cache=True, inline="always")
def _obstacle_gap(i, o, corrected, obstacles, box, n_axes):
    """Distance from agent ``i``'s ``P*`` to the centre of obstacle ``o``, and to its surface (m)."""
    r2 = 0.0
    for a in range(n_axes):
        delta = nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a])
        r2 += delta * delta
    centre = np.sqrt(r2)
    return centre, centre - obstacles[o, n_axes]


@numba.njit(cache=True, inline="always")
def _wall_face(i, a, face, corrected, walls):
    """Face ``face`` of axis ``a``'s walls as agent ``i`` sees it: 0, the wall at 0; 1, the wall at
    ``walls[a]``.  Return the distance to it from the agent's ``P*`` and from its ``P`` (m), and
    ``sign(d)`` along the axis (-1.0 or 1.0), ``d`` from the agent to the wall: the push ``U`` of (8)
    on the agent is ``U sign(d)`` along ``a``."""
    if face == 0:
        return corrected[i, a, 0], corrected[i, a, 1], -1.0
    return walls[a] - corrected[i, a, 0], walls[a] - corrected[i, a, 1], 1.0


@numba.njit(cache=True, inline="always")
def _first_push(pushed, i, contacts, n_axes):
    """Clear ``pushed[i]`` before the first push of agent ``i``'s step (``contacts`` so far 0): an agent
    out of every wall's reach, most of them, writes nothing."""
    if contacts == 0:
        for a in range(n_axes):
            pushed[i, a] = 0.0


@numba.njit(cache=True, inline="always")
def wall_pushes(i, corrected, pushed, walls, obstacles, box, wall_params, n_axes):
    """The pushes (8) of the walls and obstacles within reach of agent ``i``'s ``P*`` (W1), summed into
    ``pushed[i]`` (written only when one pushes).  Return how many pushed; the sum of their squared
    sizes over ``c_max^2`` (C1); the size of the box walls' pushes (rad) and their sum weighted by the
    agent's distance ``P`` from each wall (rad m); and the obstacles' virial ``(P - c) . u`` about the
    box's centre ``c``.

    Parameters
    ----------
    i, corrected, walls, obstacles, box, n_axes
        As every function here takes them (module text).
    pushed : ndarray, shape (agents, axes)
        The walls' pushes, written for agent ``i``.
    wall_params : FunctionParams
        The repulsion's parameters with ``R + R_w`` for its reach (:func:`wall_params`).
    """
    contacts = 0
    pressing = 0.0
    on_walls = 0.0
    moment = 0.0
    obstacle_virial = 0.0
    reach = wall_params.reach
    for a in range(n_axes):
        if walls[a] > 0.0:
            for face in range(2):
                gap, from_wall, toward = _wall_face(i, a, face, corrected, walls)
                if gap < reach:
                    _first_push(pushed, i, contacts, n_axes)
                    u = repulsion(max(gap, 0.0), 0, wall_params)
                    pushed[i, a] += toward * u  # u < 0 pushes away from the wall
                    on_walls -= u
                    moment -= u * from_wall
                    contacts += 1
                    pressing += (u / wall_params.c_max) ** 2
    for o in range(obstacles.shape[0]):
        centre, gap = _obstacle_gap(i, o, corrected, obstacles, box, n_axes)
        if gap < reach and centre > 0.0:
            _first_push(pushed, i, contacts, n_axes)
            u = repulsion(max(gap, 0.0), 0, wall_params)
            for a in range(n_axes):
                along = u * nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a]) / centre
                pushed[i, a] += along
                obstacle_virial += (corrected[i, a, 1] - 0.5 * walls[a]) * along
            contacts += 1
            pressing += (u / wall_params.c_max) ** 2
    return contacts, pressing, on_walls, moment, obstacle_virial


@numba.njit(cache=True, inline="always")
def keep_off(i, corrected, setpoint, walls, obstacles, box, reach, n_axes):
    """Drop from agent ``i``'s other pushes the part that points into a wall or an obstacle within
    reach of its ``P*`` (W2): neighbours, formation pulls and the thermostat never push it through.
    The wall or obstacle takes what is dropped: return its size on the box's walls (rad), its sum
    weighted by the agent's distance ``P`` from each wall (rad m), as :func:`wall_pushes` does, and
    the virial ``(P - c) . u`` of what the obstacles took.

    Parameters
    ----------
    i, corrected, walls, obstacles, box, n_axes
        As every function here takes them (module text).
    setpoint : ndarray, shape (agents, axes)
        The summed set-points, changed in place for agent ``i``.
    reach : float
        ``R + R_w`` (m).
    """
    held = 0.0
    moment = 0.0
    obstacle_virial = 0.0
    for a in range(n_axes):
        if walls[a] > 0.0:
            for face in range(2):
                gap, from_wall, toward = _wall_face(i, a, face, corrected, walls)
                into = toward * setpoint[i, a]  # the part of the pushes towards the wall
                if gap < reach and into > 0.0:
                    held += into
                    moment += into * from_wall
                    setpoint[i, a] = 0.0
    for o in range(obstacles.shape[0]):
        centre, gap = _obstacle_gap(i, o, corrected, obstacles, box, n_axes)
        if gap < reach and centre > 0.0:
            inward = 0.0  # the component along the unit vector from P* to the obstacle's centre
            for a in range(n_axes):
                inward += setpoint[i, a] * nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a]) / centre
            if inward > 0.0:
                for a in range(n_axes):
                    dropped = inward * nearest_image(obstacles[o, a] - corrected[i, a, 0], box[a]) / centre
                    setpoint[i, a] -= dropped
                    obstacle_virial -= (corrected[i, a, 1] - 0.5 * walls[a]) * dropped
    return held, moment, obstacle_virial


@numba.njit(cache=True, error_model="numpy", inline="always")
def with_priority(i, setpoint, pushed, c_max, n_axes):
    """Agent ``i``'s set-point as the walls' pushes plus ``alpha`` times the others, ``alpha`` the
    largest in ``[0, 1]`` that keeps it within the tilt limit (W2).  Each wall's push is saturated
    on its own, and walls do not share the limit: in a corner the tilt may reach the larger of
    ``c_max`` and the walls' pushes together (at most ``sqrt(axes) c_max`` in a box's corner), so
    that each wall stops the agent as it would alone.  Return ``alpha`` and the limit.

    Parameters
    ----------
    i : int
        The agent's slot.
    setpoint : ndarray, shape (agents, axes)
        The other pushes summed, replaced for agent ``i`` by the combined set-point.
    pushed : ndarray, shape (agents, axes)
        The walls' pushes (:func:`wall_pushes`).
    c_max : float
        Tilt limit (rad).
    n_axes : int
        Number of axes.
    """
    ww = 0.0
    wr = 0.0
    rr = 0.0
    for a in range(n_axes):
        ww += pushed[i, a] * pushed[i, a]
        wr += pushed[i, a] * setpoint[i, a]
        rr += setpoint[i, a] * setpoint[i, a]
    limit2 = max(c_max * c_max, ww)
    alpha = 1.0
    if ww + 2.0 * wr + rr > limit2:  # |w + alpha r| = limit at the root in [0, 1]
        alpha = (-wr + np.sqrt(max(wr * wr - rr * (ww - limit2), 0.0))) / rr
    for a in range(n_axes):
        setpoint[i, a] = pushed[i, a] + alpha * setpoint[i, a]
    return alpha, np.sqrt(limit2)



def wall_params(params: FunctionParams, wall_reach: float) -> FunctionParams:
    """The repulsion's parameters for walls and obstacles: the law's, with ``R + R_w`` for the reach.

    Parameters
    ----------
    params : FunctionParams
        The interaction functions' parameters.
    wall_reach : float
        ``R + R_w`` (m).
    """
    return params._replace(reach=float(wall_reach))
