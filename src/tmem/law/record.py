"""The TMEM controller of a run as the step loop's :class:`~tmem.law.record.Law` record.

The ``[interaction]`` table names the law: the interaction function (8), (10) or (11) and the
function the other neighbours push with, where the flag ``F_en`` flips and how a pair uncouples
(9) (:mod:`tmem.law.coupling`), and speed synchronisation (S1)-(S3) (:mod:`tmem.law.synchronise`).  The
engine's driver and the per-agent controllers (:mod:`tmem.agent`) build the same record here, so
both run the same law.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from tmem.law import coupling
from tmem.law.interaction.kernels import FunctionParams
from tmem.law.interaction.registry import code, uses_coupling
from tmem.law.params import LawParams
from tmem.scenario import Scenario
from tmem.law.synchronise import coupled_mode, synchronising_gain


class Law(NamedTuple):
    """The TMEM controller of every agent: (6)-(11) and the saturation.

    Attributes
    ----------
    gains : ndarray, shape (agents, 4) or (1, 4)
        Each agent's ``K = (K_P, K_V, K_phi, K_omega)``, in slot order; ``P* = x . K / K_P`` (6)
        with the agent's own gains.  One row is every agent's: a scenario gives all agents the same.
    function : int
        Registry code of the scenario's function, used by the formation pairs.
    neighbour_function : int
        Registry code of the function other neighbours use: the scenario's own
        if it has no flag, else the repulsion (8).
    couples : bool
        Whether the function switches on ``F_en``.
    at_crossing : bool
        ``interaction.switch_at == "crossing"`` (:func:`tmem.law.coupling.next_flag`).
    eps : float
        The coupling window of (9) (m).
    uncouple_rule : int
        Code of ``interaction.uncouple_when`` (:data:`tmem.law.coupling.UNCOUPLE_RULES`).
    energy_tolerance : float
        The relative tolerance of the energy-matched uncoupling.
    fallback_steps : int
        Steps after an uncouple command when the energy-matched uncoupling falls back on (9).
    sync_gain : float
        ``k_s`` of the speed synchronisation (S2) (rad per m/s); 0: none.
    keep_energy : bool
        Whether (S2) holds each pair's mean square speed (S3), or only damps its relative motion.

    The interaction functions' parameters travel beside it, as their own
    record (:class:`~tmem.law.interaction.kernels.FunctionParams`: the law's ``K_P``,
    ``R + R_j``, the scenario's ``d_t`` and ``c_max``): a parallel loop takes a
    record only as an argument of the function it runs in, not as a field.
    """

    gains: np.ndarray
    function: int
    neighbour_function: int
    couples: bool
    at_crossing: bool
    eps: float
    uncouple_rule: int
    energy_tolerance: float
    fallback_steps: int
    sync_gain: float
    keep_energy: bool


#: The fields of :class:`Law` taken as they are from :class:`~tmem.law.params.LawParams` (the others are
#: derived from it: codes for names, flags for choices).
_COPIED = tuple(name for name in Law._fields if name in LawParams.model_fields and name not in ("function", "keep_energy"))


def law_of(scenario: Scenario, linearisation: tuple[np.ndarray, np.ndarray], gains: np.ndarray) -> tuple[Law, FunctionParams]:
    """The TMEM controller of a scenario with the modal gains ``gains``, and its functions' parameters.

    Parameters
    ----------
    scenario : Scenario
        The scenario whose ``[interaction]`` table sets the law.
    linearisation : (ndarray, ndarray)
        The vehicle's ``(A, B)`` on the law's state: the coupled pair's loop (S1) sets the
        synchronising gain and the energy rule's fallback time.
    gains : ndarray, shape (n_law,)
        ``K`` placing the roots (5) (:meth:`tmem.vehicles.base.VehicleModel.gains`), every agent's: the
        law holds it as one row that all agents share.

    Returns
    -------
    Law
    FunctionParams
    """
    ia = scenario.interaction
    sync_gain = synchronising_gain(*linearisation, gains, ia.sync_damping) if ia.synchronise else 0.0
    slow = coupled_mode(*linearisation, gains, sync_gain)
    period = 2.0 * np.pi / abs(slow.imag) if slow.imag != 0.0 else 1.0 / abs(slow.real)
    return law_record(ia, gains, scenario.simulation.step_of(period), sync_gain, scenario.keeps_energy)


def law_record(params: LawParams, gains: np.ndarray, fallback_steps: int, sync_gain: float,
               keep_energy: bool = True) -> tuple[Law, FunctionParams]:  # fmt: skip
    """The :class:`Law` of agents that share the gains ``gains``, and the interaction functions'
    parameters, from the law's parameters (:class:`tmem.law.params.LawParams`: a scenario's
    ``[interaction]`` table or a controller's :class:`~tmem.law.params.ControllerLaw`), by name.

    Parameters
    ----------
    params : LawParams
        The law's parameters, with its ``reach``.
    gains : ndarray, shape (n_law,)
        ``K`` (:meth:`tmem.vehicles.base.VehicleModel.gains`).
    fallback_steps : int
        Steps after an uncouple command when the energy rule falls back on (9).
    sync_gain : float
        ``k_s`` of (S2); 0: no synchronisation.
    keep_energy : bool
        Whether (S2) holds the pairs' mean square speed (S3) (:attr:`Scenario.keeps_energy`).
    """
    couples = uses_coupling(params.function)
    law = Law(
        gains=np.asarray(gains, dtype=float)[np.newaxis, :],
        function=code(params.function),
        neighbour_function=code("repulsion") if couples else code(params.function),
        couples=couples,
        at_crossing=params.switch_at == "crossing",
        uncouple_rule=coupling.UNCOUPLE_RULES.index(params.uncouple_when),
        fallback_steps=fallback_steps,
        sync_gain=sync_gain,
        keep_energy=keep_energy,
        **{name: getattr(params, name) for name in _COPIED},  # numbers of the law, as named there
    )
    kernels = {name: getattr(params, name) for name in FunctionParams._fields if name != "k_p"}  # reach, d_t, c_max ...
    return law, FunctionParams(k_p=float(gains[0]), **kernels)
