"""CAPT: the assignment of starts to goals, and the synchronised straight-line trajectories.

Concurrent assignment and planning of trajectories (CAPT; Turpin, Michael and Kumar 2014 [1]_) for
agents of equal radius ``R`` in open space:

1. **Assignment.**  Start ``i`` goes to goal ``phi(i)``, the one-to-one map that minimises the sum
   of squared distances ``sum_i |g_phi(i) - s_i|^2`` (CAPT's cost), solved as a linear assignment
   problem (:func:`scipy.optimize.linear_sum_assignment`, Crouse 2016 [2]_).  There may be more
   goals than starts (``N <= M``); the unused goals stay empty.
2. **Trajectories.**  Every agent flies the straight line to its goal on the same clock,
   ``x_i(t) = (1 - beta(t)) s_i + beta(t) g_phi(i)``, where ``beta`` rises from 0 to 1 over
   ``[0, T]`` with zero velocity at both ends (:data:`PROFILES`).
3. **Guarantee** (the paper's safety theorem for centralised CAPT).  If every two starts and every
   two goals are more than ``2 sqrt(2) R`` apart, every two agents stay more than ``2 R`` apart all the
   way.  Why, in two lines: the optimal assignment cannot be improved by swapping two goals, so
   ``a . c >= 0`` for ``a = s_i - s_j`` and ``c = g_phi(i) - g_phi(j)``; then
   ``|(1 - beta) a + beta c|^2 >= ((1 - beta)^2 + beta^2) Delta^2 >= Delta^2 / 2`` for separation
   ``Delta``, i.e. the pair is never closer than ``Delta / sqrt(2)``.

The clearance of a plan (:func:`capt_clearance`) does not depend on ``beta``'s shape: all agents
share it, so a pair's difference moves along the segment ``a + beta b``, ``beta`` in [0, 1].

References
----------
.. [1] M. Turpin, N. Michael and V. Kumar, "CAPT: Concurrent assignment and planning of
   trajectories for multiple robots", The International Journal of Robotics Research 33(1),
   98-112 (2014), doi:10.1177/0278364913515307.
.. [2] D. F. Crouse, "On implementing 2D rectangular assignment algorithms", IEEE Transactions on
   Aerospace and Electronic Systems 52(4), 1679-1696 (2016), doi:10.1109/TAES.2016.140952 (the
   algorithm of SciPy's solver).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["PROFILES", "assign", "assignment_cost", "capt_clearance", "capt_duration", "capt_safe", "capt_trajectory"]

#: The time scalings ``beta(tau)``, ``tau = t / T`` in [0, 1], with beta(0) = 0, beta(1) = 1 and
#: beta'(0) = beta'(1) = 0: each row is (coefficients of beta in powers of tau from tau^0, the
#: largest ``|d beta / d tau|``, the largest ``|d^2 beta / d tau^2|``).  ``"cubic"`` (the default):
#: 3 tau^2 - 2 tau^3, peak slope 3/2 at tau = 1/2, peak curvature 6 at both ends (the acceleration
#: jumps at start and end).
#: ``"quintic"``: 10 tau^3 - 15 tau^4 + 6 tau^5 (zero acceleration at both ends too), peak slope
#: 15/8 at tau = 1/2, peak curvature 10/sqrt(3) at tau = 1/2 -+ sqrt(3)/6.
PROFILES: dict[str, tuple[tuple[float, ...], float, float]] = {
    "cubic": ((0.0, 0.0, 3.0, -2.0), 1.5, 6.0),
    "quintic": ((0.0, 0.0, 0.0, 10.0, -15.0, 6.0), 15.0 / 8.0, 10.0 / math.sqrt(3.0)),
}


def _points(name: str, values: object) -> np.ndarray:
    """``values`` as a float array of shape (n, axes), refused with one line otherwise."""
    array = np.asarray(values, dtype=float)
    if array.ndim != 2 or array.shape[1] < 1:
        raise ValueError(f"{name} must have shape (n, axes), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} has values that are not finite")
    return array


def _plan(starts: object, goals: object, assignment: object | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The starts, and the goal of each start (shape (N, axes) both), checked."""
    starts, goals = _points("starts", starts), _points("goals", goals)
    if starts.shape[1] != goals.shape[1]:
        raise ValueError(f"starts have {starts.shape[1]} axes and goals {goals.shape[1]}")
    if len(starts) > len(goals):
        raise ValueError(f"{len(starts)} starts cannot go to {len(goals)} goals: give at least as many goals as starts")
    if assignment is None:
        return starts, goals
    index = np.asarray(assignment)
    if index.shape != (len(starts),) or not np.issubdtype(index.dtype, np.integer):
        raise ValueError(f"assignment must be {len(starts)} integer goal indices, got shape {index.shape}")
    if np.any(index < 0) or np.any(index >= len(goals)) or len(np.unique(index)) != len(index):
        raise ValueError(f"assignment must name distinct goals among 0..{len(goals) - 1}")
    return starts, goals[index]


def _profile(profile: str) -> tuple[tuple[float, ...], float, float]:
    if profile not in PROFILES:
        raise ValueError(f"unknown profile {profile!r}; choose from {', '.join(PROFILES)}")
    return PROFILES[profile]


def assign(starts: object, goals: object) -> np.ndarray:
    """The goal of each start that minimises the sum of squared distances (CAPT's assignment).

    Parameters
    ----------
    starts : array_like, shape (N, axes)
        Start places (m).
    goals : array_like, shape (M, axes)
        Goal places (m), ``M >= N``.

    Returns
    -------
    ndarray of int, shape (N,)
        ``assignment[i]``: the index in ``goals`` of start ``i``'s goal; distinct.

    Notes
    -----
    The cost matrix is dense, ``N x M`` float64: 800 MB for 10^4 agents.  Solved by
    :func:`scipy.optimize.linear_sum_assignment` (shortest augmenting paths, Crouse 2016).
    """
    from scipy.optimize import linear_sum_assignment
    from scipy.spatial.distance import cdist

    starts, goals = _plan(starts, goals)
    rows, cols = linear_sum_assignment(cdist(starts, goals, "sqeuclidean"))
    out = np.empty(len(starts), dtype=np.int64)
    out[rows] = cols
    return out


def assignment_cost(starts: object, goals: object, assignment: object) -> float:
    """The sum of squared distances ``sum_i |g_assignment[i] - s_i|^2`` (m^2) of an assignment.

    Parameters
    ----------
    starts : array_like, shape (N, axes)
        Start places (m).
    goals : array_like, shape (M, axes)
        Goal places (m).
    assignment : array_like of int, shape (N,)
        Each start's goal index, as :func:`assign` returns it.
    """
    starts, ends = _plan(starts, goals, assignment)
    return float(np.sum((ends - starts) ** 2))


def capt_trajectory(
    starts: object, goals: object, assignment: object, duration: float, t: object, profile: str = "cubic"
) -> tuple[np.ndarray, np.ndarray]:
    """Places and velocities on CAPT's synchronised straight lines at times ``t``.

    ``x_i(t) = (1 - beta) s_i + beta g_i`` and ``v_i(t) = (beta' / T) (g_i - s_i)``, with
    ``beta = beta(t / T)`` from :data:`PROFILES` (Turpin et al. 2014); before 0 the agents wait at
    their starts, after ``T`` at their goals.

    Parameters
    ----------
    starts : array_like, shape (N, axes)
        Start places (m).
    goals : array_like, shape (M, axes)
        Goal places (m).
    assignment : array_like of int, shape (N,)
        Each start's goal index (:func:`assign`).
    duration : float
        ``T`` (s), > 0.
    t : float or array_like, shape (K,)
        Times (s).
    profile : str
        ``"cubic"`` (default) or ``"quintic"``: the time scaling ``beta`` (:data:`PROFILES`).

    Returns
    -------
    positions, velocities : ndarray, shape (N, axes) for a scalar ``t``, else (K, N, axes)
        Places (m) and velocities (m/s).
    """
    starts, ends = _plan(starts, goals, assignment)
    coefficients, _, _ = _profile(profile)
    if not duration > 0.0:
        raise ValueError(f"duration must be > 0 s, got {duration}")
    times = np.asarray(t, dtype=float)
    tau = np.clip(times / duration, 0.0, 1.0)
    beta = np.polynomial.polynomial.polyval(tau, coefficients)
    slope = np.polynomial.polynomial.polyval(tau, np.polynomial.polynomial.polyder(coefficients)) / duration
    slope = np.where((times < 0.0) | (times > duration), 0.0, slope)
    beta, slope = beta[..., None, None], slope[..., None, None]
    return starts + beta * (ends - starts), slope * (ends - starts)


def capt_duration(
    starts: object, goals: object, assignment: object, v_max: float, a_max: float, profile: str = "cubic"
) -> float:
    """The shortest ``T`` keeping every agent's speed within ``v_max`` and acceleration within ``a_max``.

    Agent ``i`` flies ``D_i = |g_i - s_i|`` with speed ``D_i beta'(tau) / T`` and acceleration
    ``D_i beta''(tau) / T^2``, so with ``D = max_i D_i`` and the profile's peaks ``b1 = max |beta'|``,
    ``b2 = max |beta''|`` (:data:`PROFILES`): ``T = max(b1 D / v_max, sqrt(b2 D / a_max))``.  For
    the cubic, ``T = max(1.5 D / v_max, sqrt(6 D / a_max))``.

    Parameters
    ----------
    starts : array_like, shape (N, axes)
        Start places (m).
    goals : array_like, shape (M, axes)
        Goal places (m).
    assignment : array_like of int, shape (N,)
        Each start's goal index (:func:`assign`).
    v_max : float
        Speed limit (m/s), > 0.
    a_max : float
        Acceleration limit (m/s^2), > 0.
    profile : str
        ``"cubic"`` (default) or ``"quintic"`` (:data:`PROFILES`).

    Returns
    -------
    float
        ``T`` (s); 0 when no agent moves.
    """
    starts, ends = _plan(starts, goals, assignment)
    _, peak_slope, peak_curvature = _profile(profile)
    if not (v_max > 0.0 and a_max > 0.0):
        raise ValueError(f"v_max and a_max must be > 0, got {v_max} m/s and {a_max} m/s^2")
    longest = float(np.max(np.linalg.norm(ends - starts, axis=1), initial=0.0))
    return max(peak_slope * longest / v_max, math.sqrt(peak_curvature * longest / a_max))


def capt_clearance(starts: object, goals: object, assignment: object) -> float:
    """The smallest distance between any two agents along CAPT's trajectories (m), in closed form.

    For agents ``i`` and ``j`` the difference ``x_i - x_j = a + beta b``, with ``a = s_i - s_j`` and
    ``b = (g_i - g_j) - a``, moves on a segment as ``beta`` goes from 0 to 1; its length is least
    at ``beta* = clip(-a . b / |b|^2, 0, 1)``.  Pairs are taken in blocks of rows, so memory stays
    about 32 MB whatever ``N``.

    Parameters
    ----------
    starts : array_like, shape (N, axes)
        Start places (m).
    goals : array_like, shape (M, axes)
        Goal places (m).
    assignment : array_like of int, shape (N,)
        Each start's goal index (:func:`assign`).

    Returns
    -------
    float
        The minimum over pairs and over the flight (m); ``inf`` for fewer than two agents.
    """
    starts, ends = _plan(starts, goals, assignment)
    n, axes = starts.shape
    block = max(1, 4_000_000 // max(1, n * axes))
    best = math.inf
    for lo in range(0, n - 1, block):
        hi = min(n - 1, lo + block)
        a = starts[lo:hi, None, :] - starts[None, :, :]
        b = (ends[lo:hi, None, :] - ends[None, :, :]) - a
        bb = np.einsum("ijk,ijk->ij", b, b)
        ab = np.einsum("ijk,ijk->ij", a, b)
        with np.errstate(divide="ignore", invalid="ignore"):
            beta = np.clip(np.where(bb > 0.0, -ab / bb, 0.0), 0.0, 1.0)
        gap = np.linalg.norm(a + beta[..., None] * b, axis=2)
        later = np.arange(n)[None, :] > np.arange(lo, hi)[:, None]
        best = min(best, float(np.min(gap, where=later, initial=math.inf)))
    return best


def _nearest_gap(points: np.ndarray) -> float:
    """The smallest distance between two of ``points`` (``inf`` for fewer than two)."""
    from scipy.spatial import cKDTree

    if len(points) < 2:
        return math.inf
    distances, _ = cKDTree(points).query(points, k=2)
    return float(np.min(distances[:, 1]))


def capt_safe(starts: object, goals: object, radius: float) -> bool:
    """Whether CAPT's guarantee holds: every two starts and every two goals more than ``2 sqrt(2) R`` apart.

    Under that separation (the assumption of Turpin et al. 2014's safety theorem for centralised
    CAPT) the optimal assignment's trajectories keep every two agents more than ``2 R`` apart (the
    module text gives the argument).
    All goals count, used or not.

    Parameters
    ----------
    starts : array_like, shape (N, axes)
        Start places (m).
    goals : array_like, shape (M, axes)
        Goal places (m).
    radius : float
        ``R``, each agent's radius (m), >= 0.

    Returns
    -------
    bool
        True when the separation holds.
    """
    starts, goals = _plan(starts, goals)
    if not radius >= 0.0:
        raise ValueError(f"radius must be >= 0 m, got {radius}")
    limit = 2.0 * math.sqrt(2.0) * radius
    return _nearest_gap(starts) > limit and _nearest_gap(goals) > limit
