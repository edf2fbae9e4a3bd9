"""The TMEM controller of a run as the step loop's :class:`~tmem.engine.records.Law` record.

The ``[interaction]`` table names the law: the interaction function (8), (10) or (11) and the
function the other neighbours push with, where the flag ``F_en`` flips and how a pair uncouples
(9) (:mod:`tmem.law.coupling`), and speed synchronisation (S1)-(S3) (:mod:`tmem.law.synchronise`).  The
engine's driver and the per-agent controllers (:mod:`tmem.agent`) build the same record here, so
both run the same law.
"""

from __future__ import annotations

import numpy as np

from tmem.law import coupling
from tmem.law.interaction.kernels import FunctionParams
from tmem.law.interaction.registry import code, uses_coupling
from tmem.scenario import Scenario
from tmem.law.synchronise import coupled_mode, synchronising_gain
from tmem.engine.records import Law


def law_of(scenario: Scenario, linearisation: tuple[np.ndarray, np.ndarray], gains: np.ndarray) -> tuple[Law, FunctionParams]:
    """The TMEM controller of a scenario with the modal gains ``gains``, and its functions' parameters.

    Parameters
    ----------
    scenario : Scenario
        The scenario whose ``[interaction]`` table sets the law.
    linearisation : (ndarray, ndarray)
        The vehicle's ``(A, B)`` on ``(P, V, phi, omega)``: the coupled pair's loop (S1) sets the
        synchronising gain and the energy rule's fallback time.
    gains : ndarray, shape (4,)
        ``K`` placing the roots (5) (:func:`tmem.law.modal.gains_for`), every agent's: the law holds it
        as one row that all agents share.

    Returns
    -------
    Law
    FunctionParams
    """
    ia = scenario.interaction
    sync_gain = synchronising_gain(*linearisation, gains, ia.sync_damping) if ia.synchronise else 0.0
    slow = coupled_mode(*linearisation, gains, sync_gain)
    period = 2.0 * np.pi / abs(slow.imag) if slow.imag != 0.0 else 1.0 / abs(slow.real)
    law = law_record(gains, ia.function, ia.switch_at, ia.eps, ia.uncouple_when, ia.energy_tolerance,
                     scenario.simulation.step_of(period), sync_gain)  # fmt: skip
    return law, FunctionParams(gains[0], ia.reach, ia.d_t, ia.c_max)


def law_record(gains: np.ndarray, function: str, switch_at: str, eps: float, uncouple_when: str, energy_tolerance: float,
               fallback_steps: int, sync_gain: float) -> Law:  # fmt: skip
    """The :class:`~tmem.engine.records.Law` of agents that share the gains ``gains``, from the names
    and numbers of an ``[interaction]`` table.

    Parameters
    ----------
    gains : ndarray, shape (4,)
        ``K`` (:func:`tmem.law.modal.gains_for`).
    function : str
        The interaction function's name (:data:`tmem.law.interaction.registry.FUNCTION_NAMES`); the
        other neighbours push with it too, or with the repulsion (8) if it switches on ``F_en``.
    switch_at, uncouple_when : str
        Where the flag flips (``"window"`` or ``"crossing"``) and the uncoupling rule
        (``"window"`` or ``"energy"``), :mod:`tmem.law.coupling`.
    eps : float
        The coupling window of (9) (m).
    energy_tolerance : float
        The energy rule's relative tolerance.
    fallback_steps : int
        Steps after an uncouple command when the energy rule falls back on (9).
    sync_gain : float
        ``k_s`` of (S2) (rad per m/s); 0: no synchronisation.
    """
    couples = uses_coupling(function)
    return Law(
        gains=np.asarray(gains, dtype=float)[np.newaxis, :],
        function=code(function),
        neighbour_function=code("repulsion") if couples else code(function),
        couples=couples,
        at_crossing=switch_at == "crossing",
        eps=eps,
        uncouple_rule=coupling.UNCOUPLE_RULES.index(uncouple_when),
        energy_tolerance=energy_tolerance,
        fallback_steps=fallback_steps,
        sync_gain=sync_gain,
    )
