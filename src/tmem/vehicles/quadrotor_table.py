"""The quadrotor's ``[model]`` table, in a module of its own: the quadrotor's modules compile its
step when they are imported (:mod:`tmem.vehicles.quadrotor`), and validating a scenario loads no
compiler.
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import Field, model_validator

from tmem.scenario.fields import LIMIT, FieldError, NonNegative, Positive, StrictModel
from tmem.vehicles.linear import TiltingGain

#: Most of ``kd x inner_period``: the rate loop (Q6) held over a sub-step stays close to the
#: continuous one (docs/vehicles.md).
MAX_RATE_LOOP_STEP = 0.25


class QuadrotorModelParams(TiltingGain, StrictModel):
    """A nonlinear quadrotor under the paper's inner loop, ``[model] kind = "quadrotor"``
    (:mod:`tmem.vehicles.quadrotor`).  Defaults: the Crazyflie 2.x as RotorPy gives it
    (``docs/vehicles.md`` names the source of each number)."""

    kind: Literal["quadrotor"]
    kp: Positive = 6.0
    kd: Positive = 25.0
    g: Positive = 9.81
    mass: Positive = 0.03
    ixx: Positive = 1.43e-5
    iyy: Positive = 1.43e-5
    izz: Positive = 2.89e-5
    arm_length: Positive = 0.043
    k_eta: Positive = 2.3e-8
    k_m: Positive = 7.8e-10
    rotor_drag: NonNegative = 1.02506e-6
    inflow_drag: NonNegative = 7.553e-7
    c_dx: NonNegative = 0.0
    c_dy: NonNegative = 0.0
    c_dz: NonNegative = 0.0
    tau_m: Annotated[float, Field(ge=1e-6, le=LIMIT)] = 0.072
    rotor_speed_max: Positive = 2500.0
    altitude_kp: Positive = 16.0
    altitude_kd: Positive = 8.0
    inner_period: Annotated[float, Field(ge=1e-6, le=1.0)] = 0.002
    drag_feedforward: bool = True
    #: ``"acceleration"``: the airframe asked for (2)'s acceleration, (Q9)-(Q11); ``"tilt"``: the
    #: set-point ``U`` to the attitude loop, with the drag feed-forward (Q8) (docs/vehicles.md).
    inner_loop: Literal["acceleration", "tilt"] = "acceleration"

    #: The most axes a run of this model may have: the vertical one is the altitude hold's.
    max_axes: ClassVar[int] = 2

    @model_validator(mode="after")
    def _flies(self) -> "QuadrotorModelParams":
        hover = (self.mass * self.g / (4.0 * self.k_eta)) ** 0.5
        if hover >= 0.9 * self.rotor_speed_max:
            raise FieldError("rotor_speed_max", f"{self.rotor_speed_max:g} rad/s leaves no margin above the hover "
                             f"speed sqrt(m g / (4 k_eta)) = {hover:.4g} rad/s (at least 10 %)")  # fmt: skip
        if self.kd * self.inner_period > MAX_RATE_LOOP_STEP:
            raise FieldError("inner_period", f"{self.inner_period:g} s is too long for the rate loop: kd x inner_period = "
                             f"{self.kd * self.inner_period:.3g}, at most {MAX_RATE_LOOP_STEP:g}")  # fmt: skip
        if not self.drag_feedforward and self.inner_loop == "acceleration":
            raise FieldError("drag_feedforward", 'false is the tilt loop\'s (inner_loop = "tilt"): the acceleration loop '
                             "cancels the drag it feels")  # fmt: skip
        return self
