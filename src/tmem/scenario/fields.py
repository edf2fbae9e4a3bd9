"""What every scenario table is built from: its base class, the number types and the errors a table raises.

The tables themselves live with what they configure: the law's, the simulation's and the
neighbours' in :mod:`tmem.scenario.tables`, a vehicle's in its module of :mod:`tmem.vehicles`,
an agent term's in its module of :mod:`tmem.terms`, the others in the ``*_table`` modules of
:mod:`tmem.scenario`.  This module imports nothing of tmem's, so any of them can import it.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message is one line naming the field."""


class FieldError(ValueError):
    """Raised by a cross-field check to name the field at fault, relative to its table.

    Parameters
    ----------
    field : str
        The field at fault, relative to its table (``"d_t"``).
    reason : str
        Why, in one line.
    """

    def __init__(self, field: str, reason: str):
        super().__init__(reason)
        self.field = field
        self.reason = reason


def per_axis(axes: int, got: int) -> str:
    """Why a list of ``got`` values is refused where one value per axis is needed, and the fix.

    Parameters
    ----------
    axes : int
        ``space.axes``.
    got : int
        How many values were given.
    """
    reason = f"needs {axes} value{'s' if axes > 1 else ''}, one per axis (space.axes = {axes}), got {got}"
    if 1 <= got <= 3:
        reason += f"; for a {got}-D run set axes = {got} in [space]"
    return reason


class StrictModel(BaseModel):
    """Base of the scenario tables: unknown keys, non-finite numbers and quiet coercions refused."""

    # strict: no quiet coercion of true to 1 or "6.0" to 6.0.
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


#: Every number is bounded in magnitude, so that no product in the model overflows.
LIMIT = 1e9
Number = Annotated[float, Field(ge=-LIMIT, le=LIMIT)]
Positive = Annotated[float, Field(gt=0, le=LIMIT)]
NonNegative = Annotated[float, Field(ge=0, le=LIMIT)]
Pair = Annotated[list[int], Field(min_length=2, max_length=2)]
