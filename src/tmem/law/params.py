"""The TMEM law's parameters, declared once: what every agent's controller holds, with their checks.

:class:`LawParams` is the one declaration of the law's parameters (7)-(11) and of its coupling
rules.  The scenario's ``[interaction]`` table extends it (:class:`tmem.scenario.tables.InteractionParams`:
the agents' radius ``R``, synchronisation, how pushes combine), a per-agent controller holds it as
:class:`ControllerLaw` (the reach ``R + R_j`` and the numbers a scenario would derive from its
vehicle), and the step loop's record of the law is built from either by keyword
(:func:`tmem.law.record.law_record`).  A key added here reaches the scenario, the engine, the batch
and the per-agent controllers; its kernel reads it from :class:`tmem.law.record.Law` or
:class:`tmem.law.interaction.kernels.FunctionParams`.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from tmem.law.interaction.registry import FUNCTION_NAMES
from tmem.scenario.fields import FieldError, NonNegative, Positive, StrictModel


class LawParams(StrictModel):
    """The law's parameters, shared by the scenario and the per-agent controllers.

    Attributes
    ----------
    function : str
        The interaction function of the formation pairs (:data:`tmem.law.interaction.registry.FUNCTION_NAMES`);
        the other neighbours push with it, or with the repulsion (8) if it switches on ``F_en``.
    c_max : float
        The limit of the law's set-point, ``|U| <= c_max`` (rad for a tilting multirotor, the
        vehicle's input units otherwise).
    d_t : float
        The set distance of the pairs (m), below the reach (condition (9)).
    eps : float
        The coupling window of (9) (m), below ``d_t``.
    switch_at : str
        Where the flag ``F_en`` flips: ``"window"`` (the first step within ``eps``) or ``"crossing"``
        (:mod:`tmem.law.coupling`).
    uncouple_when : str
        After an uncouple command: ``"window"`` (9), or ``"energy"``, where the pair's relative kinetic
        energy and ``f1 - f2`` match their values at coupling (:mod:`tmem.law.coupling`).
    energy_tolerance : float
        The energy rule's relative tolerance.
    """

    function: Literal[FUNCTION_NAMES] = "improved"
    c_max: Positive = 0.1
    d_t: Positive = 35.0
    eps: Positive = 0.2
    switch_at: Literal["window", "crossing"] = "window"
    uncouple_when: Literal["window", "energy"] = "window"
    energy_tolerance: Annotated[float, Field(gt=0, lt=1)] = 0.05

    # Each table that holds the law gives ``reach``, R + R_j (m): the scenario's from its radius R,
    # a controller's as a number.

    @model_validator(mode="after")
    def _coupling_inside_reach(self) -> "LawParams":
        if self.d_t >= self.reach:
            raise FieldError("d_t", f"must be less than R + R_j = {self.reach:g} m (condition (9)), got {self.d_t:g}")
        if self.eps >= self.d_t:
            raise FieldError("eps", f"must be less than d_t = {self.d_t:g} m, got {self.eps:g}")
        return self


class ControllerLaw(LawParams):
    """The law as one agent's controller holds it (:class:`tmem.agent.AgentController`): the shared
    parameters, the reach, and what a scenario derives from its vehicle.

    Attributes
    ----------
    reach : float
        ``R + R_j`` (m): agents closer than that in ``P*`` (6) interact.
    fallback_time : float or None
        With ``uncouple_when = "energy"``, how long after an uncouple command (9) takes over (s):
        one period of the coupled pair's slow mode (:func:`tmem.law.record.law_of`).
    sync_gain : float
        ``k_s`` of the speed synchronisation (S2) (per m/s, in the set-point's units;
        :func:`tmem.law.synchronise.synchronising_gain`); 0: none.
    """

    reach: Positive = 40.0
    fallback_time: Positive | None = None
    sync_gain: NonNegative = 0.0

    @model_validator(mode="after")
    def _fallback_for_the_energy_rule(self) -> "ControllerLaw":
        if self.uncouple_when == "energy" and self.fallback_time is None:
            raise FieldError("fallback_time", "is required with uncouple_when = 'energy' "
                             "(one period of the coupled pair's slow mode)")  # fmt: skip
        return self
