"""Speed synchronisation of coupled pairs: their oscillation damped, their kinetic energy kept.

A coupled pair holds ``|d| = d_t`` with the spring ``f2 = K_P (|d| - d_t)``
of (10)/(11).  Its relative state ``e = x_j - x_i`` then follows::

    de/dt = (A - 2 B K) e + const                                   (S1)

whose slow pair of roots is undamped (``+- 0.795i`` with Table 1): without
more, a coupled pair oscillates for ever with the amplitude it coupled with.
The paper's further work asks to synchronise the coupled agents' speeds while
the RMS velocity is kept.  Each agent of a coupled pair adds, to its set-point::

    U_i += k_s (V_j - V_i) + u_c c,      U_j += -k_s (V_j - V_i) + u_c c,
    c = V_c / |V_c|,  V_c = (V_i + V_j) / 2,
    u_c = (k_s (E* - E) + (k_s |V_j - V_i|^2 + (V_j - V_i) . p) / 2) / |V_c|   (S2)

The first term damps the relative motion: with it the relative loop is
``A - 2 B (K + k_s e_V)``, and ``k_s`` (:func:`synchronising_gain`) gives its
slow pair the damping ratio ``sync_damping``.  The second term pushes both
agents along their common velocity so that the pair keeps the kinetic energy
it came with.  Per unit mass and halved, the pair's kinetic energy
is its mean square speed ``E = (|V_i|^2 + |V_j|^2) / 2 = |V_c|^2 + |V_j - V_i|^2 / 4``,
and ``E*`` is the value it keeps (below).  With ``dV/dt = g U`` the damping term
takes ``g k_s |V_j - V_i|^2`` from ``E``, the pair's own push ``p`` on agent ``i``
(``-p`` on ``j``) takes ``g (V_j - V_i) . p``, and the common push gives
``2 g u_c |V_c|``, so that with (S2)::

    dE/dt = 2 g k_s (E* - E)                                                (S3)

The energy the oscillation loses goes into the common motion, and whatever
the loop does not capture (the tilt's lag, saturation) is corrected with the
time constant ``1 / (2 g k_s)``, 1.1 s with Table 1.  The pair ends at its
common velocity with ``|V_c|^2 = E*``, and it speeds up (or slows down)
along its own direction of motion.

``E*`` is the pair's mean square speed when it came within reach (or at the
start, for a pair that starts within reach), not at coupling: on its way in
from ``R + R_j`` to ``d_t`` the pair's own push f1 took energy from it, and
after it uncouples f1 gives energy back on its way out.  So the pair holds
``E*`` from its coupling until, released, it is out of reach again and
``|E - E*| <= KEPT_TOLERANCE E*``; after the release only the common push
acts, and it also balances the pair's push f1 (``pushed`` of
:func:`synchronising_push`).  A pair that stops oscillating and flies on thus
leaves the encounter with the RMS velocity it entered with, as the paper's
further work asks.  A formation is a sum of pairs, each holding its own
``E*``; where the pairs' values differ, an agent in several pairs settles
between them.

Where the common push would exceed ``c_max / 2``, both terms are scaled down
together (the damping is slower, and (S3) corrects what the scaling leaves); a pair with no
common motion (``|V_c| = 0``) has no direction to put the energy in and is
damped without it.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

#: Velocity's index in the state ``(P, V, phi, omega)`` the TMEM law reads.
_V = 1

#: A released pair stops holding ``E*`` once out of reach with ``|E - E*| <= KEPT_TOLERANCE E*``:
#: its RMS velocity then within 0.05 % of the one it came with.
KEPT_TOLERANCE = 1e-3


def coupled_mode(a: np.ndarray, b: np.ndarray, gains: np.ndarray, k_s: float = 0.0) -> complex:
    """The least damped root of a coupled pair's relative loop ``A - 2 B (K + k_s e_V)`` (S1).

    Parameters
    ----------
    a : ndarray, shape (4, 4)
    b : ndarray, shape (4,)
        The vehicle's linearisation on ``(P, V, phi, omega)``.
    gains : ndarray, shape (4,)
        ``K`` of both agents.
    k_s : float
        The synchronising gain (rad per m/s); 0 without synchronisation.
    """
    gain = np.array(gains, dtype=float)
    gain[_V] += k_s
    roots = np.linalg.eigvals(a - 2.0 * np.outer(b, gain))
    return complex(roots[np.argmax(roots.real + 1e-12 * roots.imag)])


def damping_ratio(root: complex) -> float:
    """``-Re(s) / |s|`` of a root ``s``: 0 undamped, 1 critically damped or slower.

    Parameters
    ----------
    root : complex
    """
    return -root.real / abs(root) if root != 0 else 1.0


def synchronising_gain(a: np.ndarray, b: np.ndarray, gains: np.ndarray, zeta: float) -> float:
    """``k_s`` of (S2) giving the coupled pair's slow roots the damping ratio ``zeta``.

    The damping ratio of the slow pair grows with ``k_s`` until the pair
    becomes real (critical damping); the smallest ``k_s`` reaching ``zeta`` is
    found by bisection.

    Parameters
    ----------
    a, b, gains
        The linearisation and the gains, as :func:`coupled_mode` takes them.
    zeta : float
        The damping ratio wanted, ``0 < zeta < 1``.

    Raises
    ------
    ValueError
        Where no gain gives that damping before the slow roots turn real.
    """
    ratio = lambda k: damping_ratio(coupled_mode(a, b, gains, k))  # noqa: E731
    low, high = 0.0, 1e-3
    while ratio(high) < zeta:
        low, high = high, 2.0 * high
        if high > 1e3:
            raise ValueError(f"no synchronising gain gives the coupled pair a damping ratio of {zeta:g}")
    for _ in range(60):  # the bracket shrinks by 2^60: far below the damping ratio's 1e-12
        mid = 0.5 * (low + high)
        low, high = (mid, high) if ratio(mid) < zeta else (low, mid)
    return high


@numba.njit(cache=True, error_model="numpy", inline="always")
def mean_square_speed(known, i, j, n_axes):
    """``E = (|V_i|^2 + |V_j|^2) / 2`` of the pair ``(i, j)`` (m^2/s^2), from the measured states.

    Parameters
    ----------
    known : ndarray, shape (agents, axes, n_state)
        The measured states.
    i, j : int
        The pair's agents.
    n_axes : int
    """
    total = 0.0
    for a in range(n_axes):
        total += known[i, a, _V] * known[i, a, _V] + known[j, a, _V] * known[j, a, _V]
    return 0.5 * total


@numba.njit(cache=True, error_model="numpy", inline="always")
def synchronising_push(known, i, j, k_s, damped, kept, keeps, pushed, c_max, n_axes, u):
    """Add (S2) of the pair ``(i, j)`` to the set-points ``u`` of both agents.

    Parameters
    ----------
    known, i, j, n_axes
        The measured states and the pair's agents, as :func:`mean_square_speed` takes them.
    k_s : float
        The synchronising gain (rad per m/s).
    damped : bool
        Whether the relative motion is damped (the pair is coupled); without, only the common push
        holds ``E`` at ``E*`` (S3).
    kept : float
        ``E*``, the mean square speed the pair holds (m^2/s^2).
    keeps : bool
        Whether the common push holds ``E`` at ``E*`` (S3); without, the relative motion is only damped
        (where an agent term steers the group's mean motion, :data:`tmem.terms.base.AgentTerm.steers_group`).
    pushed : ndarray, shape (axes,)
        The pair's own push on agent ``i`` this step (``-pushed`` on ``j``; rad).
    c_max : float
        Tilt limit (rad): the common push is kept within ``c_max / 2``.
    u : ndarray, shape (agents, axes)
        The summed set-points, changed in place.
    """
    relative2 = 0.0
    common2 = 0.0
    work = 0.0  # (V_j - V_i) . pushed: minus the rate, over g, at which the pair's push changes E
    for a in range(n_axes):
        relative = known[j, a, _V] - known[i, a, _V]
        common = 0.5 * (known[i, a, _V] + known[j, a, _V])
        relative2 += relative * relative
        common2 += common * common
        work += relative * pushed[a]
    damping = k_s if damped else 0.0
    speed = np.sqrt(common2)
    energy = common2 + 0.25 * relative2
    push = (k_s * (kept - energy) + 0.5 * (work + damping * relative2)) / speed if speed > 0.0 and keeps else 0.0  # u_c
    scale = min(1.0, 0.5 * c_max / abs(push)) if push != 0.0 else 1.0
    along = scale * push / speed if speed > 0.0 else 0.0  # u_c / |V_c|: times V_c gives u_c c
    for a in range(n_axes):
        damp = scale * damping * (known[j, a, _V] - known[i, a, _V])
        common = along * 0.5 * (known[i, a, _V] + known[j, a, _V])
        u[i, a] += damp + common
        u[j, a] += common - damp
