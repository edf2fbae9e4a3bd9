"""The thermostat: the swarm's RMS velocity held at an operator's set-point, ``T* = rms_velocity^2``.

``docs/gas.md`` derives it; equation labels refer to it.  Each agent uses only what it knows: its
own state and the velocities of the neighbours it counts.

* **(T1) A free agent** tilts along its own velocity so that ``dV/dt = (T* / |V|^2 - 1) V / (2 tau)``:
  Berendsen's weak coupling, applied per agent, at every step.
* **(T3) An agent in contact** heats or cools only the common motion of itself and its neighbours:
  it accelerates along their common velocity ``V_c``, so that the group's mean ``|V|^2`` relaxes to
  ``T*`` at Berendsen's rate.  The two agents of a pair find the same ``V_c`` and the same push, so
  their relative motion, the encounter, is the one without a thermostat: the kinetic energy an
  encounter holds for a while is made up while it holds it, and the thermostat never drives two
  agents into each other.  Between (T1) and (T3) the push is blended by the agent's contacts (its
  pushes' squared sizes over ``c_max^2``), which rise smoothly from 0 at the edge of reach; from
  :data:`FULL_CONTACT` on it is the group's alone.
* **The pushes come first.**  The pushes summed before are saturated at ``c_max`` on their own, and
  the thermostat's push on its own, then the two are added: a pair's pushes stay equal and
  opposite whatever the thermostat does, and the tilt may reach ``2 c_max``.
* **Walls and obstacles are left their bounces.**  A wall is a neighbour held still, which shares
  no common motion with the agent: within a wall's or an obstacle's reach the thermostat does not
  push the agent at all (:func:`tmem.engine.gas.gas_agent`).

The group's push (T3) is found at each count (:func:`hold_group_push`) from the neighbours counted
then, and held until the next; the free agent's part (T1) follows its velocity at every step
(:func:`add_thermostat_push`).
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law.modal import saturation
from tmem.engine.gas_counts import COMMON, CONTACT, NEIGHBOUR_SPEED2, NEIGHBOUR_VELOCITY, SPEED2, TOGETHER

#: The common velocity's square counts as at least this share of the group's mean ``|V|^2`` (T3): a
#: pair meeting head-on has no common motion to heat, and is left as it is, not pushed hard along a
#: direction that round-off sets.
COMMON_FLOOR = 0.25
#: Contacts from which an agent's thermostat pushes its group alone (T3): a push a third of ``c_max``
#: (``sqrt(0.1)``).  Until then the agent is pushed along its own velocity too, each of a pair
#: differently; the blend is over before the encounter has slowed the pair, so that it leaves their
#: closest approach within 0.01 m of the repulsion's alone (``docs/gas.md``, section 2).
FULL_CONTACT = 0.1


@numba.njit(cache=True, error_model="numpy", inline="always")
def hold_group_push(i, known, work, held, rate, target2, inv_g, n_axes):
    """At a count, agent ``i``'s push on its group (T3), kept until the next count.

    The group is half the agent, half the mean of its neighbours weighted by their contacts: the two
    agents of a pair find the same common velocity ``V_c = (V_i + V_j) / 2`` and mean square speed
    ``T = (|V_i|^2 + |V_j|^2) / 2``, and get the same push, ``dV/dt = (T* - T) V_c / (2 tau q)`` with
    ``q = max(|V_c|^2, T / 4)`` (:data:`COMMON_FLOOR`), so that ``dT/dt = (T* - T) / tau`` while
    ``|V_c|^2 >= T / 4``.  It is weighted by how far the agent is in contact, its contacts over
    :data:`FULL_CONTACT`, up to 1.

    Parameters
    ----------
    i, known, n_axes
        As every per-agent function of the gas takes them (:mod:`tmem.engine.gas`).
    work, held : ndarray
        ``Gas.work``, with the count's sums, and ``Gas.held``, changed in place
        (:mod:`tmem.engine.gas_counts`).
    rate : float
        ``1 / (2 tau)`` (1/s).
    target2 : float
        ``T*`` (m^2/s^2).
    inv_g : float
        ``1 / g``: an acceleration as a tilt.
    """
    contact = work[i, CONTACT]
    together = min(1.0, contact / FULL_CONTACT)
    per_contact = 1.0 / contact if contact > 0.0 else 0.0
    group2 = 0.5 * (work[i, SPEED2] + work[i, NEIGHBOUR_SPEED2] * per_contact)
    common2 = 0.0
    for a in range(n_axes):  # the common velocity first, scaled to the push below
        held[i, COMMON + a] = 0.5 * (known[i, a, 1] + work[i, NEIGHBOUR_VELOCITY + a] * per_contact)
        common2 += held[i, COMMON + a] ** 2
    floor2 = max(common2, COMMON_FLOOR * group2)
    push = together * rate * (target2 - group2) * inv_g / floor2 if floor2 > 0.0 else 0.0
    held[i, TOGETHER] = together
    for a in range(n_axes):
        held[i, COMMON + a] *= push


@numba.njit(cache=True, error_model="numpy", inline="always")
def add_thermostat_push(i, known, setpoint, held, limit, rate, target2, inv_g, c_max, n_axes):
    """Add agent ``i``'s thermostat push to its set-point: its own part (T1), weighted by how far it is
    free, and its group's push held since the count (T3); the pushes summed before saturated at
    ``c_max`` first, the thermostat's push on its own.  Its tilt limit this step becomes the size of
    the sum, so that the vehicle's step does not saturate it again.  Return the factor that saturated
    the pushes.

    Parameters
    ----------
    i, known, n_axes
        As every per-agent function of the gas takes them (:mod:`tmem.engine.gas`).
    setpoint : ndarray, shape (agents, axes)
        The pushes summed, changed in place.
    held : ndarray
        ``Gas.held``: the group's push.
    limit : ndarray, shape (agents,)
        ``Gas.limit``: the agent's tilt limit this step, written.
    rate, target2, inv_g
        As :func:`hold_group_push` takes them.
    c_max : float
        The scenario's tilt limit (rad).
    """
    speed2 = 0.0
    for a in range(n_axes):
        speed2 += known[i, a, 1] * known[i, a, 1]
    own = (1.0 - held[i, TOGETHER]) * rate * (target2 / speed2 - 1.0) * inv_g if speed2 > 0.0 else 0.0
    pushes2 = 0.0
    push2 = 0.0
    for a in range(n_axes):
        pushes2 += setpoint[i, a] * setpoint[i, a]
        push2 += (own * known[i, a, 1] + held[i, COMMON + a]) ** 2
    pushes_scale = saturation(pushes2, c_max)
    push_scale = saturation(push2, c_max)
    tilt2 = 0.0
    for a in range(n_axes):
        setpoint[i, a] = pushes_scale * setpoint[i, a] + push_scale * (own * known[i, a, 1] + held[i, COMMON + a])
        tilt2 += setpoint[i, a] * setpoint[i, a]
    limit[i] = np.sqrt(tilt2) if tilt2 > c_max * c_max else c_max
    return pushes_scale
