"""The ``[formation]`` table: a generated shape (chain, ring, triangle, hex) or edges among the
``[[agents]]``, and its checks against the rest of the scenario (the coupling function (10) or (11),
the axes, the set distances inside reach (9)).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from tmem.law.interaction.registry import uses_coupling
from tmem.scenario.tables import FieldError, NonNegative, Number, Positive, StrictModel, per_axis

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario


class FormationParams(StrictModel):
    """A formation: a generated shape, or edges among the ``[[agents]]``."""

    kind: Literal["chain", "ring", "triangle", "hex", "edges"]
    n: Annotated[int, Field(ge=2)] | None = None
    d_t: Positive | None = None
    bearing: bool = False
    edges: list[Annotated[list[int | float], Field(min_length=2, max_length=3)]] | None = None
    center: list[Number] | None = None
    velocity: list[Number] | None = None
    jitter: NonNegative = 0.0
    seed: Annotated[int, Field(ge=0)] = 0
    coupled: bool = True
    scatter: list[Positive] | None = None
    min_spacing: Positive | None = None

    @model_validator(mode="after")
    def _kind_needs(self) -> "FormationParams":
        if self.kind == "edges":
            if not self.edges:
                raise FieldError("edges", 'is required (and not empty) for kind = "edges"')
            for name in ("n", "center", "velocity"):
                if getattr(self, name) is not None:
                    raise FieldError(name, 'is not used with kind = "edges": give the [[agents]]')
        else:
            if self.edges is not None:
                raise FieldError("edges", f'is only for kind = "edges", not {self.kind!r}')
            if self.kind == "triangle" and self.n not in (None, 3):
                raise FieldError("n", f"a triangle has 3 agents, got {self.n}")
            if self.kind in ("chain", "ring", "hex") and self.n is None:
                raise FieldError("n", f"is required for kind = {self.kind!r}")
            if self.kind == "ring" and self.n is not None and self.n < 3:
                raise FieldError("n", f"a ring needs at least 3 agents, got {self.n}")
        if self.scatter is not None:
            if self.kind == "edges":
                raise FieldError("scatter", 'is for a generated shape, not kind = "edges"')
            if self.jitter > 0.0:
                raise FieldError("scatter", "scattered agents start uncoupled and unjittered: set coupled = false, jitter = 0")
            if self.min_spacing is None:
                raise FieldError("min_spacing", "is required with scatter: the least distance between two starts (m)")
        elif self.min_spacing is not None:
            raise FieldError("min_spacing", "is for scattered starts: give scatter too")
        return self


def check_formation(scenario: Scenario, axes: int, n: int) -> None:
    """The ``[formation]`` table against the rest of the scenario; raise :class:`FieldError` naming the field.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid on their own, with a formation.
    axes : int
        ``space.axes``.
    n : int
        Its number of agents.
    """
    f = scenario.formation
    if not uses_coupling(scenario.interaction.function):
        raise FieldError("formation", "needs interaction.function 'switching' (10) or 'improved' (11)")
    if f.bearing and axes == 1:
        raise FieldError("formation.bearing", "a direction to hold needs 2 or 3 axes, got axes = 1")
    if f.kind in ("ring", "triangle", "hex") and axes == 1:
        raise FieldError("formation.kind", f"{f.kind!r} is planar and needs 2 or 3 axes, got axes = 1")
    d_t = f.d_t or scenario.interaction.d_t
    if d_t >= scenario.interaction.reach:
        raise FieldError("formation.d_t", f"must be less than R + R_j = {scenario.interaction.reach:g} m, got {d_t:g}")
    for name in ("center", "velocity", "scatter"):
        value = getattr(f, name)
        if value is not None and len(value) != axes:
            raise FieldError(f"formation.{name}", per_axis(axes, len(value)))
    if f.scatter is not None:
        from tmem.plan.starts import spaced_points

        try:  # the draw itself: the starts a run takes, or the one line that says why they cannot be drawn
            spaced_points(n, np.zeros(axes), np.asarray(f.scatter, dtype=float), f.min_spacing, f.seed)
        except ValueError as error:
            raise FieldError("formation.min_spacing", str(error)) from None
    if f.kind == "edges":
        seen = set()
        for k, edge in enumerate(f.edges):
            i, j = edge[:2]
            if not (isinstance(i, int) and isinstance(j, int)):
                raise FieldError(f"formation.edges[{k}]", f"needs two agent indices first, got {list(edge)}")
            if len(edge) == 3 and not 0 < edge[2]:
                raise FieldError(f"formation.edges[{k}]", f"d_t must be > 0, got {edge[2]}")
            if not (0 <= i < n and 0 <= j < n) or i == j:
                raise FieldError(f"formation.edges[{k}]", f"needs two different agents in 0..{n - 1}, got {list(edge)}")
            if len(edge) == 3 and edge[2] >= scenario.interaction.reach:
                raise FieldError(f"formation.edges[{k}]", f"d_t must be less than R + R_j = {scenario.interaction.reach:g} m")
            if (min(i, j), max(i, j)) in seen:
                raise FieldError(f"formation.edges[{k}]", f"repeats the pair {sorted((i, j))}")
            seen.add((min(i, j), max(i, j)))
