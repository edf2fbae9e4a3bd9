"""The space the swarm flies in and the tables set in it: ``[space]``, ``[[obstacles]]``, ``[coverage]``
and ``[thermostat]``.

Each table checks its own keys; :mod:`tmem.scenario.schema` checks them against the rest of the
scenario (agents inside the walls and off the obstacles, a coverage map that fits).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from tmem.scenario.tables import LIMIT, FieldError, NonNegative, Number, Positive, StrictModel, per_axis


class SpaceParams(StrictModel):
    """The space the agents fly in: 1 to 3 axes, optionally a box from 0 to ``box`` on each axis,
    periodic or walled.  ``wall_radius``: ``R_w``, a wall or obstacle pushes an agent whose ``P*`` is
    within ``R + R_w`` of it (default ``R``)."""

    axes: Literal[1, 2, 3] = 1
    periodic: bool = False
    walls: bool = False
    wall_radius: Positive | None = None
    box: list[Positive] | None = None

    @model_validator(mode="after")
    def _box_fits(self) -> "SpaceParams":
        if self.box is not None and len(self.box) != self.axes:
            raise FieldError("box", per_axis(self.axes, len(self.box)))
        if self.periodic and self.box is None:
            raise FieldError("box", "is required when periodic = true")
        if self.walls and self.box is None:
            raise FieldError("box", "is required when walls = true")
        if self.walls and self.periodic:
            raise FieldError("walls", "a box is periodic or walled, not both")
        return self


class Obstacle(StrictModel):
    """A circle (a sphere in 3-D, an interval in 1-D) the agents keep off: a neighbour held still."""

    center: Annotated[list[Number], Field(min_length=1, max_length=3)]
    radius: Positive


class CoverageParams(StrictModel):
    """How the coverage of a walled box is measured (:mod:`tmem.analysis.coverage`): square cells of side
    ``cell`` (m; default ``R``), each visited when an agent passes within ``sensor_radius`` (m) of its
    centre (0: when it passes through the cell)."""

    cell: Positive | None = None
    sensor_radius: NonNegative = 0.0


class ThermostatParams(StrictModel):
    """The swarm's temperature as an operator's set-point: its RMS velocity ``rms_velocity`` (m/s;
    none: the thermostat waits for a ``temperature`` command), reached with time constant ``tau`` (s)
    (:mod:`tmem.engine.thermostat`)."""

    rms_velocity: Positive | None = None
    tau: Annotated[float, Field(gt=0, le=LIMIT)] = 1.0
