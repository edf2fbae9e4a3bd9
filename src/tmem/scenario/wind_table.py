"""The ``[wind]`` table: a constant wind and Dryden turbulence on the quadrotor, and its checks.

Keys (:mod:`tmem.vehicles.wind` gives the model and its equations, ``docs/vehicles.md`` explains it):

* ``velocity`` — the constant wind (m/s, world frame), one number per axis of the run;
* ``vertical`` — its vertical part (m/s, up), 0 by default;
* ``[wind.turbulence]`` — Dryden gusts, each agent its own, with their intensities from one of

  * ``severity`` — ``"light"``, ``"moderate"`` or ``"severe"``: ``W_20`` = 15, 30, 45 knots,
  * ``w20`` — the wind speed at 20 ft, 6 m (m/s),
  * ``sigma`` — ``[sigma_u, sigma_v, sigma_w]`` (m/s) given directly;

  and ``height`` — the height above the ground (m) of MIL-F-8785C's low-altitude scales and
  intensities, from 10 to 1000 ft (3.048 to 304.8 m), 10 m by default; ``length`` —
  ``[L_u, L_v, L_w]`` (m) given directly instead; ``speed`` — the speed at which the field passes
  the vehicles (m/s), by default the constant wind's; ``seed`` — the gusts' seed.

Only the quadrotor model feels wind: it acts through the drag, and the linear model (2) has none.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Any, Literal

import numpy as np
from pydantic import Field, model_validator

from tmem.scenario.tables import FieldError, Number, NonNegative, Positive, StrictModel, per_axis

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario

#: The low-altitude model's range of heights, 10 to 1000 ft (m).
LOWEST, HIGHEST = 3.048, 304.8
#: The strongest wind a scenario may set (m/s): beyond any a multirotor flies in, and above the strongest
#: surface gust measured (113 m/s, Barrow Island, 1996).  A larger figure is a slip of units.
STRONGEST = 100.0
#: One foot and one knot in SI units (m, m/s).
FOOT = 0.3048
KNOT = 1852.0 / 3600.0
#: ``W_20``, the wind speed at 20 ft, of each severity of MIL-F-8785C's low-altitude turbulence (m/s).
SEVERITY_W20 = {"light": 15.0 * KNOT, "moderate": 30.0 * KNOT, "severe": 45.0 * KNOT}


def low_altitude_scales(height: float, w20: float) -> tuple[np.ndarray, np.ndarray]:
    """``(sigma, L)`` of ``(u, v, w)``, (D4)-(D5) of :mod:`tmem.vehicles.wind`: MIL-F-8785C's
    low-altitude intensities and scales.

    Parameters
    ----------
    height : float
        Height above the ground (m), from 10 to 1000 ft (3.048 to 304.8 m).
    w20 : float
        The wind speed at 20 ft, 6 m (m/s).
    """
    h = height / FOOT
    base = 0.177 + 0.000823 * h
    sigma_w = 0.1 * w20
    sigma_u = sigma_w / base**0.4
    length_u = h / base**1.2 * FOOT
    return np.array([sigma_u, sigma_u, sigma_w]), np.array([length_u, length_u, height])


def scales(turbulence: Any) -> tuple[np.ndarray, np.ndarray]:
    """``(sigma, L)`` of ``(u, v, w)`` for a ``[wind.turbulence]`` table: given, or (D4)-(D5).

    Parameters
    ----------
    turbulence : TurbulenceParams
        The table.
    """
    w20 = turbulence.w20 if turbulence.w20 is not None else SEVERITY_W20.get(turbulence.severity, 0.0)
    sigma, length = low_altitude_scales(turbulence.height, w20)
    if turbulence.sigma is not None:
        sigma = np.array(turbulence.sigma, dtype=float)
    if turbulence.length is not None:
        length = np.array(turbulence.length, dtype=float)
    return sigma, length


class TurbulenceParams(StrictModel):
    """Dryden gusts (module text); the intensities from exactly one of ``severity``, ``w20``, ``sigma``."""

    severity: Literal["light", "moderate", "severe"] | None = None
    w20: Positive | None = None
    sigma: Annotated[list[NonNegative], Field(min_length=3, max_length=3)] | None = None
    height: Annotated[float, Field(ge=LOWEST, le=HIGHEST)] = 10.0
    length: Annotated[list[Positive], Field(min_length=3, max_length=3)] | None = None
    speed: Positive | None = None
    seed: Annotated[int, Field(ge=0, lt=2**63)] = 0

    @model_validator(mode="after")
    def _one_intensity(self) -> "TurbulenceParams":
        given = [k for k in ("severity", "w20", "sigma") if getattr(self, k) is not None]
        if len(given) != 1:
            raise FieldError("severity", f"the gusts' intensity comes from exactly one of severity, w20 or sigma, got "
                             f"{', '.join(given) if given else 'none'}")  # fmt: skip
        return self


class WindParams(StrictModel):
    """The wind the quadrotors fly in (module text)."""

    velocity: list[Number] | None = None
    vertical: Number = 0.0
    turbulence: TurbulenceParams | None = None

    def mean(self) -> tuple[float, float, float]:
        """The constant wind ``(w_x, w_y, w_z)`` (m/s, world frame); ``w_y = 0`` in a 1-D run."""
        horizontal = [*(self.velocity or []), 0.0, 0.0]
        return horizontal[0], horizontal[1], self.vertical

    def passing_speed(self) -> float:
        """The speed ``V`` of the Dryden form (m/s): ``turbulence.speed``, else the constant wind's."""
        if self.turbulence is not None and self.turbulence.speed is not None:
            return self.turbulence.speed
        return math.hypot(*self.mean())


def check_wind(scenario: Scenario) -> None:
    """The ``[wind]`` table against the rest of the scenario; raise :class:`FieldError` naming the field.

    Parameters
    ----------
    scenario : Scenario
        The scenario, its tables valid on their own.
    """
    wind, axes = scenario.wind, scenario.space.axes
    if wind is None:
        return
    if scenario.model.kind != "quadrotor":
        raise FieldError("wind", f"only the quadrotor model feels wind, through its drag; the {scenario.model.kind} "
                         "model (2) has no drag: set [model] kind = 'quadrotor' or remove [wind]")  # fmt: skip
    if wind.velocity is not None and len(wind.velocity) != axes:
        raise FieldError("wind.velocity", per_axis(axes, len(wind.velocity)))
    speed = math.hypot(*wind.mean())
    if speed > STRONGEST:
        field = "wind.velocity" if wind.velocity is not None and math.hypot(*wind.velocity) > 0.0 else "wind.vertical"
        raise FieldError(field, f"the wind's speed is {speed:g} m/s, more than {STRONGEST:g} m/s (stronger than any "
                         "surface wind measured; check the units: m/s)")  # fmt: skip
    gusts = wind.turbulence
    if gusts is not None:
        for key in ("w20", "speed"):
            if (getattr(gusts, key) or 0.0) > STRONGEST:
                raise FieldError(f"wind.turbulence.{key}", f"{getattr(gusts, key):g} m/s is more than {STRONGEST:g} m/s "
                                 "(stronger than any surface wind measured; check the units: m/s)")  # fmt: skip
    if wind.turbulence is not None and not wind.passing_speed() > 0.0:
        raise FieldError("wind.turbulence.speed", "is required when there is no constant wind: the Dryden form needs "
                         "the speed at which the gusts' frozen field passes the vehicles (m/s)")  # fmt: skip
