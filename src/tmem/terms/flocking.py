"""The flocking laws' compiled functions: their scalar functions, the geometry they share, and their push.

Loaded when a run binds a flocking term (:mod:`tmem.terms.olfati_saber`, :mod:`tmem.terms.vasarhelyi`);
the terms' modules import no compiler.  "OS" numbers the equations of R. Olfati-Saber, "Flocking
for multi-agent dynamic systems: algorithms and theory", IEEE TAC 51(3):401-420, 2006; "VV" the
Methods of G. Vásárhelyi et al., "Optimized flocking of autonomous drones in confined
environments", Science Robotics 3(20):eaat3536, 2018 (``docs/flocking_laws.md`` gives both laws).

* Olfati-Saber: the σ-norm (OS 8), the bump ρ_h (OS 10), σ1 and the action function φ (OS 15),
  φ_α (OS 15-16), φ_β (OS, Section VII);
* Vásárhelyi: the braking curve D (VV);
* shared: a neighbour's separation to its nearest periodic image, the push of a wanted
  acceleration on the vehicle's set-point (F1) (:func:`add_push`), and a mission's reference moving
  along a route (:func:`leader`).

:func:`compile_push` compiles a term's push template (a plain function of its module that calls
these by name) with these names bound, as the step loop binds its stages
(:func:`tmem.engine.variants.bound`).
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.world.space import nearest_image

#: How every function here is compiled: inlined where it is called, as the step loop's stages are.
JIT = {"cache": True, "inline": "always", "error_model": "numpy"}


@numba.njit(**JIT)
def sigma_norm(r, eps):
    """The σ-norm (OS 8) of a vector of Euclidean norm ``r``: ``(sqrt(1 + eps r^2) - 1) / eps``.

    Written ``r^2 / (1 + sqrt(1 + eps r^2))``, the same number without the cancellation at small
    ``eps r^2``.

    Parameters
    ----------
    r : float
        ``|z| >= 0`` (m).
    eps : float
        ``ε > 0`` of the σ-norm.
    """
    return r * r / (1.0 + np.sqrt(1.0 + eps * r * r))


@numba.njit(**JIT)
def bump(z, h):
    """The bump function ρ_h (OS 10): 1 on ``[0, h)``, ``(1 + cos(π (z - h) / (1 - h))) / 2`` on
    ``[h, 1]``, 0 otherwise.

    Parameters
    ----------
    z : float
        The argument.
    h : float
        Where the bump starts to fall, ``0 < h < 1``.
    """
    if 0.0 <= z < h:
        return 1.0
    if h <= z <= 1.0:
        return 0.5 * (1.0 + np.cos(np.pi * (z - h) / (1.0 - h)))
    return 0.0


@numba.njit(**JIT)
def sigma1(z):
    """``σ1(z) = z / sqrt(1 + z^2)`` (OS 15), a sigmoid from -1 to 1.

    Parameters
    ----------
    z : float
        The argument.
    """
    return z / np.sqrt(1.0 + z * z)


@numba.njit(**JIT)
def action(z, a, b):
    """The action function φ (OS 15): ``((a + b) σ1(z + c) + (a - b)) / 2``, ``c = |a - b| / sqrt(4 a b)``,
    so that ``φ(0) = 0``; it rises from ``-b`` (repulsion) to ``a`` (attraction).

    Parameters
    ----------
    z : float
        The argument (σ-norm units).
    a, b : float
        ``0 < a <= b`` (m/s^2).
    """
    c = abs(a - b) / np.sqrt(4.0 * a * b)
    return 0.5 * ((a + b) * sigma1(z + c) + (a - b))


@numba.njit(**JIT)
def phi_alpha(z, r_alpha, d_alpha, h, a, b):
    """The α-agents' action φ_α (OS 15-16): ``ρ_h(z / r_α) φ(z - d_α)``, 0 from ``z = r_α`` on.

    Parameters
    ----------
    z : float
        ``|q_j - q_i|_σ``.
    r_alpha, d_alpha : float
        ``r_α = |r|_σ`` and ``d_α = |d|_σ``.
    h : float
        The bump's ``h`` (0.2 in OS, Section VIII).
    a, b : float
        Of :func:`action`.
    """
    return bump(z / r_alpha, h) * action(z - d_alpha, a, b)


@numba.njit(**JIT)
def phi_beta(z, d_beta, h):
    """The β-agents' repulsion φ_β (OS, Section VII): ``ρ_h(z / d_β) (σ1(z - d_β) - 1)``, negative below
    ``d_β`` and 0 from it on.

    Parameters
    ----------
    z : float
        ``|q̂_ik - q_i|_σ``.
    d_beta : float
        ``d_β = |d'|_σ``.
    h : float
        The bump's ``h`` (0.9 in OS, Section VIII).
    """
    return bump(z / d_beta, h) * (sigma1(z - d_beta) - 1.0)


@numba.njit(**JIT)
def braking(r, a, p):
    """The braking curve D(r, a, p) (VV): 0 for ``r <= 0``; ``r p`` while ``r p < a / p``; else
    ``sqrt(2 a r - a^2 / p^2)``: the largest speed from which a vehicle stops within ``r``, braking
    at ``a`` and with gain ``p`` near the stopping point.

    Parameters
    ----------
    r : float
        The distance left to the stopping point (m).
    a : float
        The braking acceleration (m/s^2), ``> 0``.
    p : float
        The linear part's gain (1/s), ``> 0``.
    """
    if r <= 0.0:
        return 0.0
    if r * p < a / p:
        return r * p
    return np.sqrt(2.0 * a * r - a * a / (p * p))


@numba.njit(**JIT)
def separation(known, i, j, a, box):
    """``q_j - q_i`` along axis ``a`` (m), to the nearest periodic image (0 on an open axis of ``box``).

    Parameters
    ----------
    known : ndarray, shape (agents, axes, n_state)
        The states as the agents know them; position first.
    i, j, a : int
        The agent, its neighbour, the axis.
    box : tuple of float
        The periodic box's sides (0: open axis).
    """
    return nearest_image(known[j, a, 0] - known[i, a, 0], box[a])


@numba.njit(**JIT)
def cap(vector, i, n_axes, limit):
    """Scale ``vector[i, 0, :]`` in place so that its norm is at most ``limit``.

    Parameters
    ----------
    vector : ndarray, shape (agents, rows, axes)
        A term's work space; row 0 of agent ``i`` is capped.
    i, n_axes : int
        The agent and the number of axes.
    limit : float
        The largest norm.
    """
    size2 = 0.0
    for a in range(n_axes):
        size2 += vector[i, 0, a] * vector[i, 0, a]
    if size2 > limit * limit:
        scale = limit / np.sqrt(size2)
        for a in range(n_axes):
            vector[i, 0, a] *= scale


@numba.njit(**JIT)
def add_push(setpoint, wanted, i, n_axes, per_input, c_max):
    """Add the set-point that asks for the acceleration ``wanted[i, 0, :]`` (m/s^2), saturated on its norm
    at ``c_max``: ``U = a / (acceleration per input)``, for the tilting multirotor ``U = a / g`` rad (F1).

    Parameters
    ----------
    setpoint : ndarray, shape (agents, axes)
        ``Agents.setpoint``, changed in place.
    wanted : ndarray, shape (agents, rows, axes)
        The term's work space, the acceleration in row 0 (changed: it becomes the set-point added).
    i, n_axes : int
        The agent and the number of axes.
    per_input : float
        The vehicle's input per m/s^2 (:meth:`tmem.vehicles.base.VehicleModel.acceleration_per_input`'s inverse).
    c_max : float
        The vehicle's bound on ``|U|`` (``interaction.c_max``).
    """
    for a in range(n_axes):
        wanted[i, 0, a] *= per_input
    cap(wanted, i, n_axes, c_max)
    for a in range(n_axes):
        setpoint[i, a] += wanted[i, 0, a]


@numba.njit(**JIT)
def leader(t, route, lengths, speed, a):
    """A mission's moving reference on axis ``a`` at time ``t`` (s): ``(position, velocity)`` of a point that
    flies the polyline ``route`` from its first point at ``speed`` and holds its last (the γ-agent of
    OS Algorithm 2 as a virtual leader; the goal SwarmLab's Vásárhelyi law steers to, moving).

    Parameters
    ----------
    t : float
        Time since the start (s).
    route : ndarray, shape (points, axes)
        The polyline (m).
    lengths : ndarray, shape (points,)
        Its length from the first point to each (m), ``lengths[0] = 0``.
    speed : float
        The reference's speed (m/s).
    a : int
        The axis.
    """
    flown = speed * t
    last = lengths.shape[0] - 1
    if flown >= lengths[last]:
        return route[last, a], 0.0
    m = 0
    while lengths[m + 1] <= flown:
        m += 1
    tangent = (route[m + 1, a] - route[m, a]) / (lengths[m + 1] - lengths[m])
    return route[m, a] + (flown - lengths[m]) * tangent, speed * tangent


def route_record(route, axes: int) -> tuple[np.ndarray, np.ndarray]:
    """A reference's polyline as :func:`leader` reads it: the points (m, shape (points, axes)) and the length
    flown to each (m).

    Parameters
    ----------
    route : list of list of float
        The points, the first where the reference starts.
    axes : int
        The space's axes.
    """
    points = np.asarray(route, dtype=float).reshape(-1, axes)
    return points, np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


#: The names a term's push template calls, each bound to its compiled function here.
NAMES = ("sigma_norm", "bump", "sigma1", "action", "phi_alpha", "phi_beta", "braking", "separation", "nearest_image",
         "cap", "add_push", "leader")  # fmt: skip


def compile_push(push, *helpers):
    """A term's push template compiled with :data:`NAMES` and its ``helpers`` bound to the names it calls.

    The helpers are compiled in the order given, each with :data:`NAMES` and the helpers before it
    bound; the push last, with all of them.

    Parameters
    ----------
    push : function
        The plain push ``push(i, k, known, agents, box, record)`` of a term's module.
    *helpers : function
        Plain functions of the same module that the push (or a later helper) calls by name.
    """
    from tmem.engine.variants import bound

    options = {"inline": "always", "error_model": "numpy"}
    names = {name: globals()[name] for name in NAMES}
    for f in (*helpers, push):
        names[f.__name__] = bound(f, f"{f.__module__}.{f.__name__}".replace(".", "_"), options, **names)
    return names[push.__name__]
