"""The ``[safety]`` table: what a run's summary counts as a near miss, and the figures the field reports.

Keys (:mod:`tmem.analysis.field_metrics` computes the figures, ``docs/missions.md`` explains them):

* ``radius`` — the safety radius (m): two agents closer than it are a near miss, counted once per
  encounter (3 m by default, the collision radius of Vásárhelyi et al. 2018's simulator);
* ``collision_radius`` — closer than this is a collision (m; none by default), below ``radius``;
* ``range`` — the communication range (m) of the groups and the algebraic connectivity: by default
  the sensing range where one is set, else the interaction's ``R + R_j``.

Two agents closing at ``v_c`` come within ``r`` of each other unless the repulsion (8), which starts
at ``R + R_j`` and at most decelerates their relative motion by ``2 g c_max``, stops them first::

    v_c <= sqrt(4 g c_max (R + R_j - r))                                                  (M1)

(12 m/s with Table 1, ``c_max = 0.1`` rad and ``r = 3`` m); the summary gives this limit beside the
near misses, and :func:`check_safety` warns where a scenario's speeds exceed it.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from pydantic import model_validator

from tmem.scenario.tables import FieldError, Positive, StrictModel

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario


class SafetyParams(StrictModel):
    """``[safety]``: the safety radius, a collision radius and the communication range (module text)."""

    radius: Positive = 3.0
    collision_radius: Positive | None = None
    range: Positive | None = None

    @model_validator(mode="after")
    def _collision_inside(self) -> "SafetyParams":
        if self.collision_radius is not None and self.collision_radius >= self.radius:
            raise FieldError("collision_radius", f"must be below the safety radius {self.radius:g} m, got {self.collision_radius:g}")
        return self


def closing_speed_limit(scenario: Scenario) -> float | None:
    """(M1): the fastest two agents may close and still stop outside the safety radius (m/s); ``None``
    where the radius lies beyond the repulsion's reach, the TMEM law is off, or the model's input is not a tilt.

    Parameters
    ----------
    scenario : Scenario
        Its ``[safety]`` radius, reach, tilt limit and model.
    """
    from tmem.law.interaction.registry import pushes
    from tmem.scenario.bounds import stopping_speed

    room = scenario.interaction.reach - scenario.safety.radius
    g = getattr(scenario.model, "g", None)
    if room <= 0.0 or g is None or not pushes(scenario.interaction.function):
        return None
    return stopping_speed(g * scenario.interaction.c_max, room)


def check_safety(scenario: Scenario) -> list[tuple[str, str]]:
    """The ``[safety]`` table against the scenario: a radius inside the repulsion's reach (else nothing
    keeps agents apart at it); the doubts (``field``, ``reason``) where the mission's speed exceeds (M1).

    Parameters
    ----------
    scenario : Scenario
        A scenario with a ``[safety]`` table, its tables valid on their own.
    """
    from tmem.law.interaction.registry import pushes

    safety = scenario.safety
    if not pushes(scenario.interaction.function):  # the TMEM law off: an agent term keeps agents apart, or nothing
        return []
    if safety.radius >= scenario.interaction.reach:
        raise FieldError("safety.radius", f"{safety.radius:g} m is not inside the repulsion's reach R + R_j = "
                         f"{scenario.interaction.reach:g} m: nothing keeps agents apart at it")  # fmt: skip
    limit = closing_speed_limit(scenario)
    nav = getattr(scenario, "navigation", None)
    speeds = [s for leg in (nav.legs if nav else []) for s in leg.speeds() if math.isfinite(s)]
    if limit is not None and speeds and 2.0 * max(speeds) > limit:
        return [("safety.radius", f"two agents meeting head-on at the mission's {max(speeds):g} m/s close at "
             f"{2 * max(speeds):g} m/s, above the {limit:.3g} m/s the tilt limit stops within R + R_j - radius (M1)")]  # fmt: skip
    return []
