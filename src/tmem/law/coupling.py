"""Pair coupling state ``F_en`` and operator commands, Section III.C and (9).

Every pair carries two bits:

* ``armed`` — the operator's intent: the pair may be coupled.  All pairs start
  armed, as in the paper, where a pair couples when it first meets.  The
  operator's ``uncouple`` command disarms a pair, ``couple`` arms it again.
* ``f_en`` — the paper's flag: which branch of (10)/(11) the pair uses.

Transitions, checked once per step with ``r = |d|`` the pair measure::

    f_en 0 -> 1  when armed and  | r - d_t | < eps      (coupling point)
    f_en 1 -> 0  when disarmed and | r - d_t | < eps    (condition (9))

So a pair couples where it reaches the set distance, holds it, and after an
uncouple command lets go at the first moment (9) holds; since the pair is then
disarmed it does not couple again at once.

Where the flag flips is a reading of the paper (``interaction.switch_at``):

* ``"window"`` (default) — at the first step inside the window, the
  literal (9).  A pair arriving from outside switches near
  ``|d| = d_t + eps``, where (11)'s f1 and f2 differ by ``2 K_P eps``: a
  small step in control (0.012 rad with the defaults).
* ``"crossing"`` — at the step where ``|d|`` crosses ``d_t`` (still within
  eps), the point where (11)'s f1 and f2 agree: no step in control.

(9)'s second line, ``d_t < R + R_j``, is a property of the scenario and is
checked when it is validated.

**Energy-matched uncoupling** (``interaction.uncouple_when = "energy"``), the
paper's own rule (Section III.C, after (9)): "uncoupling must occur at the
moment when the kinetic energy of the agent and the difference between the
values of functions f1(c_j) and f2(c_j) will be equal to those that were at
the moment of coupling".  Read here as:

* the kinetic energy is that of the pair's relative motion along ``d``,
  ``E = ((V_j - V_i) . d / |d|)^2 / 4`` per unit mass of one agent (the
  reduced mass is half an agent's).  The pushes act along ``d``, equal and
  opposite: the pair's common motion and its motion across ``d`` pass through
  the encounter unchanged, so only ``E`` is exchanged with the functions;
* at coupling the pair records ``E_c`` and ``Delta_c = f1(|d|) - f2(|d|)``;
* after the uncouple command it lets go at the first step over which
  ``f1 - f2`` passes ``Delta_c`` (steps are discrete: a value is passed, not
  hit; where ``f1 - f2`` is flat, as (10)'s between its saturations, every
  step matches) with ``|E - E_c| <= energy_tolerance E_c``;
* if that has not happened one period of the coupled pair's slow mode after
  the command (:func:`tmem.law.synchronise.coupled_mode`: in that time the pair's
  oscillation passes every point of its orbit), the window rule (9) applies
  from then on, and the event names the fallback.

Events name the rule that released each pair (:data:`RELEASES`).
"""

from __future__ import annotations

import numba

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law.interaction.kernels import pair_control

#: Command actions, in the order of their integer codes.
ACTIONS = ("uncouple", "couple")
#: Event kinds, in the order of their integer codes.
EVENT_KINDS = ("command", "couple", "uncouple")
EVENT_COMMAND, EVENT_COUPLE, EVENT_UNCOUPLE = range(3)
#: ``interaction.uncouple_when``, in the order of their integer codes.
UNCOUPLE_RULES = ("window", "energy")
UNCOUPLE_BY_WINDOW, UNCOUPLE_BY_ENERGY = range(2)
#: What released a pair (an ``uncouple`` event's rule), in the order of their integer codes: (9),
#: the energy match, (9) after the energy match was not found in time, the loss of an agent, a mission's
#: change of shape (:mod:`tmem.terms.navigation`).
RELEASES = ("window", "energy", "fallback", "lost", "reshape")
RELEASE_WINDOW, RELEASE_ENERGY, RELEASE_FALLBACK, RELEASE_LOST, RELEASE_RESHAPE = range(5)


@numba.njit(cache=True)
def next_flag(f_en, armed, r_before, r, d_t, eps, at_crossing):
    """The pair flag after a step that took the pair measure from ``r_before`` to ``r`` (see module text).

    Parameters
    ----------
    f_en : int
        The pair flag ``F_en`` before the step (0 or 1).
    armed : bool
        The operator's intent: the pair may be coupled.
    r_before, r : float
        The pair measure ``|d|`` before and after the step (m).
    d_t, eps : float
        Set distance of the pair and the coupling window (9) (m).
    at_crossing : bool
        Switch only where ``r`` crosses ``d_t`` (``interaction.switch_at = "crossing"``).

    Returns
    -------
    int
        ``F_en`` after the step.
    """
    reached = abs(r - d_t) < eps
    if at_crossing:
        reached = reached and (r_before - d_t) * (r - d_t) <= 0.0
    if reached:
        if f_en == 0 and armed:
            return 1
        if f_en == 1 and not armed:
            return 0
    return f_en


@numba.njit(cache=True, _nrt=False)
def function_gap(function, r, p):
    """``f1(|d|) - f2(|d|)``: the function with ``F_en = 0`` less the one with ``F_en = 1``.

    Called, not inlined: the energy rule evaluates it three times a step, each a copy of every
    interaction function, and inlined they made the step loop's first compilation take twice as
    long (21 s against 11 s for the serial loop).  Only the energy rule calls it.

    Parameters
    ----------
    function : int
        Registry code of the function ((10) or (11)).
    r : float
        ``|d|`` (m).
    p : FunctionParams
        The functions' parameters, with the pair's ``d_t``.
    """
    return pair_control(function, r, 0, p) - pair_control(function, r, 1, p)


@numba.njit(cache=True, error_model="numpy", inline="always")
def relative_energy(known, i, j, d, r, n_axes):
    """``E = ((V_j - V_i) . d / |d|)^2 / 4``: the kinetic energy of the pair's motion along ``d``,
    per unit mass of one agent.

    Parameters
    ----------
    known : ndarray, shape (agents, axes, n_state)
        The states as measured; the velocity is component 1.
    i, j : int
        The pair's agents.
    d : ndarray, shape (axes,)
        ``P*_j - P*_i``.
    r : float
        ``|d|`` (m), > 0.
    n_axes : int
    """
    along = 0.0
    for a in range(n_axes):
        along += (known[j, a, 1] - known[i, a, 1]) * d[a]
    along /= r
    return 0.25 * along * along


@numba.njit(cache=True, inline="always")
def energy_matched(gap_before, gap, gap_c, energy, energy_c, tolerance):
    """Whether a step matched the values at coupling (see the module text).

    Parameters
    ----------
    gap_before, gap : float
        ``f1 - f2`` before and after the step (NaN before the first step: no match).
    gap_c : float
        ``f1 - f2`` at coupling.
    energy, energy_c : float
        The relative kinetic energy now and at coupling (:func:`relative_energy`).
    tolerance : float
        The relative tolerance on the energy.
    """
    passed = (gap_before - gap_c) * (gap - gap_c) <= 0.0
    return passed and abs(energy - energy_c) <= tolerance * energy_c
