"""A pull of every agent towards a point: the worked example of an agent term.

``[pull]`` with ``point`` (m, one value per axis) and ``gain`` (rad per m; in the vehicle's input
per metre for a vehicle that is not a tilting multirotor) adds to each agent's set-point::

    U_i += -gain (P*_i - point),   saturated on its norm at c_max                          (P1)

with ``P*`` (6) as the agent knows it.  Alone, an agent under (P1) sees the closed loop
``A - (gain / K_P) B K``: at ``gain = K_P`` it is the law's own loop, with the roots (5).  For
``gain <= K_P`` the real part of its slow pair stays within 2e-7 /s of zero (Table 1: a growth or
decay over weeks), so the agent swings about the point without growing or dying out (no damping:
a pull, not a hold).  Above ``K_P`` the slow pair grows: 1.2e-6 /s at 1.5 ``K_P``, 3.2e-4 /s at
5 ``K_P``; the table refuses ``gain > K_P``.

It is a toy, kept small to show what a term is: one table, one record, one kernel, and a row in
:data:`tmem.terms.TERMS` (``docs/architecture.md`` counts the files).
"""

from __future__ import annotations

from functools import cache
from typing import NamedTuple

import numpy as np

from tmem.scenario.tables import FieldError, Number, Positive, StrictModel, per_axis
from tmem.terms.base import AgentTerm


class PullParams(StrictModel):
    """``[pull]``: every agent pulled towards ``point`` (m) with ``gain`` (rad/m), (P1)."""

    point: list[Number]
    gain: Positive

    def check(self, scenario) -> None:
        """Check the table against the scenario: one value of ``point`` per axis, ``gain <= K_P``.

        Parameters
        ----------
        scenario : Scenario
            The whole scenario.
        """
        axes = scenario.space.axes
        if len(self.point) != axes:
            raise FieldError("pull.point", per_axis(axes, len(self.point)))
        k_p = scenario.position_gain
        if self.gain > k_p:
            raise FieldError("pull.gain", f"{self.gain:g} rad/m exceeds the law's K_P = {k_p:.4g} rad/m: beyond it the "
                             "agent's loop A - (gain / K_P) B K grows (its slow pair leaves the imaginary axis)")  # fmt: skip


class Pulled(NamedTuple):
    """The record of (P1): the point (m, one value per axis), the gain (rad/m) and the tilt limit (rad)."""

    point: np.ndarray
    gain: float
    c_max: float


def _push(i, k, known, agents, box, pull):
    """(P1) on agent ``i``: ``-gain (P* - point)``, saturated on its norm at ``c_max``, added to its set-point."""
    n_axes = len(box)
    size2 = 0.0
    for a in range(n_axes):
        size2 += (pull.gain * (agents.corrected[i, a, 0] - pull.point[a])) ** 2
    scale = min(1.0, pull.c_max / np.sqrt(size2)) if size2 > 0.0 else 1.0
    for a in range(n_axes):
        agents.setpoint[i, a] -= scale * pull.gain * (agents.corrected[i, a, 0] - pull.point[a])


class Pull(AgentTerm):
    """(P1): a pull of every agent towards a point (module text)."""

    name = "pull"
    table = PullParams
    rebuilt = {"point": "a number fixed for the run", "gain": "a number fixed for the run", "c_max": "a number fixed for the run"}

    @classmethod
    def record(cls, settings: PullParams, scenario, gains) -> Pulled:
        """The record of (P1) for a run of ``scenario``.

        Parameters
        ----------
        settings : PullParams
            The ``[pull]`` table.
        scenario : Scenario
            The whole scenario: its tilt limit.
        gains : ndarray
            ``K`` of the law (unused).
        """
        return Pulled(np.asarray(settings.point, dtype=float), float(settings.gain), float(scenario.interaction.c_max))

    @classmethod
    @cache
    def kernel(cls):
        """The compiled (P1), :func:`_push` (compiled on first use, so that validating a scenario loads no compiler)."""
        import numba

        return numba.njit(inline="always", error_model="numpy")(_push)
