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
disarmed it does not couple again at once.  (9)'s second line, ``d_t < R +
R_j``, is a property of the scenario and is checked when it is validated.
"""

from __future__ import annotations

import numba

#: Command actions, in the order of their integer codes.
ACTIONS = ("uncouple", "couple")
#: Event kinds, in the order of their integer codes.
EVENT_KINDS = ("command", "couple", "uncouple")
EVENT_COMMAND, EVENT_COUPLE, EVENT_UNCOUPLE = range(3)


@numba.njit(cache=True)
def next_flag(f_en, armed, r, d_t, eps):
    """The pair flag after one check at pair measure ``r = |d|`` (see module text)."""
    if abs(r - d_t) < eps:
        if f_en == 0 and armed:
            return 1
        if f_en == 1 and not armed:
            return 0
    return f_en
