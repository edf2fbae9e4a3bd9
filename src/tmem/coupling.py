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
"""

from __future__ import annotations

import numba

from . import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

#: Command actions, in the order of their integer codes.
ACTIONS = ("uncouple", "couple")
#: Event kinds, in the order of their integer codes.
EVENT_KINDS = ("command", "couple", "uncouple")
EVENT_COMMAND, EVENT_COUPLE, EVENT_UNCOUPLE = range(3)


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
