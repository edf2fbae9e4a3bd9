"""What each agent knows of itself and its neighbours: the measurement stage.

The controller of an agent reads only what the measurement stage gives it:
the states of itself and of its neighbours as it knows them.  Today every
agent knows every state exactly (:data:`IDENTITY`), and the stage hands the
true states on without copying them.  An effect (noise, delay, loss, a
limited range) is one code in :data:`EFFECTS` and one branch of
:func:`measure` that writes what is known into the record's buffer
(``docs/architecture.md`` walks through one).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from . import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)

#: Sensing effects, in the order of their integer codes.
EFFECTS = ("identity",)
IDENTITY = 0


class Sensing(NamedTuple):
    """The measurement stage's settings and work space.

    Attributes
    ----------
    effect : int
        Code of the effect in :data:`EFFECTS`.
    known : ndarray, shape (agents, axes, n_state)
        Where an effect writes the states as known (unused by :data:`IDENTITY`).
    """

    effect: int
    known: np.ndarray


def exact(state: np.ndarray) -> Sensing:
    """Every agent knows every state exactly: no work space is needed.

    Parameters
    ----------
    state : ndarray, shape (agents, axes, n_state)
        The states of the run (only their shape is used).
    """
    return Sensing(IDENTITY, np.empty((0,) + state.shape[1:]))


@numba.njit(cache=True, inline="always")
def measure(state, sensing):
    """The states as the agents know them, shape of ``state``: ``state`` itself for :data:`IDENTITY`.

    Parameters
    ----------
    state : ndarray, shape (agents, axes, n_state)
        The true states.
    sensing : Sensing
        The effect and its work space.
    """
    return state
