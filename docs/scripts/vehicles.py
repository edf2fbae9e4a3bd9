"""The figures of docs/vehicles.md: the quadrotor against RotorPy, its linearisation, Fig. 9 and hex19 beside the linear model.

Prints Markdown tables to standard output::

    python docs/scripts/vehicles.py          # about 3 minutes on 2 cores once compiled

The comparison with RotorPy (``pip install rotorpy``) flies the manoeuvres of
``tests/test_quadrotor.py`` with that test's own code, so that the errors
printed are those the test bounds.  Every number in docs/vehicles.md is
printed here.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import test_quadrotor as manoeuvres  # noqa: E402

import tmem  # noqa: E402
from tmem.law.modal import gains_for  # noqa: E402
from tmem.analysis.metrics import formation_summary, summarize  # noqa: E402
from tmem.vehicles.quadrotor import BODY_NAMES, QuadrotorModel  # noqa: E402
from tmem.scenario import QuadrotorModelParams, from_dict, load  # noqa: E402


def against_rotorpy() -> None:
    print("| manoeuvre | inner loop | largest position error (m) | largest attitude error (deg) | distance flown (m) |")
    print("| --- | --- | --- | --- | --- |")
    for (name, setpoint), inner_loop in itertools.product(manoeuvres.MANOEUVRES.items(), ("tilt", "acceleration")):
        model = manoeuvres.quadrotor(inner_period=manoeuvres.PERIOD, inner_loop=inner_loop)
        start = np.zeros((1, 2, 4))
        start[0, :, 1] = (1.0, -0.5)
        ours = manoeuvres.fly_tmem(model, setpoint, start)
        theirs = manoeuvres.fly_rotorpy(model, setpoint, ours[0])
        position = np.max(np.linalg.norm(ours[:, :3] - theirs[:, :3], axis=1))
        dot = np.abs(np.sum(ours[:, 6:10] * theirs[:, 6:10], axis=1) / np.linalg.norm(theirs[:, 6:10], axis=1))
        attitude = np.degrees(np.max(2.0 * np.arccos(np.minimum(dot, 1.0))))
        flown = np.sum(np.linalg.norm(np.diff(ours[:, :3], axis=0), axis=1))
        print(f"| {name} | {inner_loop} | {position:.1e} | {attitude:.1e} | {flown:.1f} |")


def with_lag(model: QuadrotorModel, gains: np.ndarray, tau: float) -> np.ndarray:
    """Roots of one axis's loop ``(P, V, phi, omega, m)`` with the rate loop's moment ``m`` (over the
    inertia) reaching the body through the motors' first-order lag ``tau``."""
    a, b = model.linearisation()
    inflow = -a[3, 3] - model.params.kd  # the rotors' damping of the body rate acts on the body itself
    full = np.zeros((5, 5))
    full[:3, :4] = a[:3]
    full[3, 3], full[3, 4] = -inflow, 1.0
    commanded = a[3] - b[3] * gains
    commanded[3] += inflow
    full[4, :4], full[4, 4] = commanded / tau, -1.0 / tau
    return np.linalg.eigvals(full)


def linearisation() -> None:
    model = QuadrotorModel(QuadrotorModelParams(kind="quadrotor", inner_loop="tilt"))
    a, b = model.linearisation()
    numerical, numerical_b = manoeuvres.numerical_linearisation(model, 0)
    print(f"A at hover (Crazyflie, feed-forward on):\n{np.array2string(a, precision=4, suppress_small=True)}")
    print(f"B = {b}; largest difference from finite differences of (Q1)-(Q8): "
          f"{max(np.max(np.abs(a - numerical)), np.max(np.abs(b - numerical_b))):.1e}")  # fmt: skip
    gains = gains_for(a, b, 12.0, 0.1, 0.55)
    print(f"K = {np.array2string(gains, precision=5)}; roots of A - B K: {np.round(np.linalg.eigvals(a - np.outer(b, gains)), 4)}")
    for tau in (0.072, 0.03, 0.01):
        print(f"with the motors' lag tau_m = {tau} s: {np.round(with_lag(model, gains, tau), 3)}")
    model = QuadrotorModel(QuadrotorModelParams(kind="quadrotor", inner_loop="acceleration"))
    a, b = model.linearisation()
    gains = gains_for(a, b, 12.0, 0.1, 0.55)
    print(f"acceleration loop: A =\n{np.array2string(a, precision=4, suppress_small=True)}\nB = {b}")
    print(f"K = {np.array2string(gains, precision=5)}; roots of A - B K: {np.round(np.linalg.eigvals(a - np.outer(b, gains)), 4)}")


def changed(scenario, **tables):
    data = scenario.model_dump(mode="json", exclude_none=True)
    for table, values in tables.items():
        data[table] = {**data[table], **values}
    return from_dict(data)


def trimmed(scenario, trim: bool = True):
    """``scenario`` with each agent starting at the tilt that balances its drag at its speed (Q8),
    or level (``trim`` false)."""
    a, _ = QuadrotorModel(scenario.model).linearisation()
    data = scenario.model_dump(mode="json", exclude_none=True)
    for agent in data["agents"]:
        agent["tilt"] = float(np.arctan(-a[1, 1] * agent["velocity"] / scenario.model.g)) if trim else 0.0
    return from_dict(data)


def fig9() -> None:
    linear = load(ROOT / "examples" / "fig9.toml")
    quad = load(ROOT / "examples" / "vehicles" / "fig9.toml")  # the acceleration loop, started trimmed
    level = trimmed(quad, trim=False)
    tilt = changed(level, model={"inner_loop": "tilt"})
    no_drag = {"rotor_drag": 0.0, "inflow_drag": 0.0}
    runs = {
        "linear (2)": linear,
        "tilt loop": tilt,
        "tilt loop, no drag feed-forward": changed(tilt, model={"drag_feedforward": False}),
        "tilt loop, no rotor drag": changed(tilt, model=no_drag),
        "tilt loop, motors' lag 10 ms": changed(tilt, model={"tau_m": 0.01}),
        "tilt loop, started trimmed": trimmed(tilt),
        "acceleration loop, started trimmed (examples/vehicles/fig9.toml)": quad,
        "acceleration loop, started level": level,
        "acceleration loop, no rotor drag": changed(level, model=no_drag),
        "acceleration loop, motors' lag 10 ms": changed(quad, model={"tau_m": 0.01}),
    }
    print("| vehicle | couples at (s) | uncouples at (s) | apart at (s) | RMS change (%) | largest height error (m) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, scenario in runs.items():
        trajectory = tmem.simulate(scenario)
        s = summarize(trajectory)
        pair = s["pairs"][0]
        height = np.max(np.abs(trajectory.body[..., BODY_NAMES.index("height")])) if trajectory.body.shape[-1] else 0.0
        print(f"| {name} | {pair['coupled_at']} | {pair['uncoupled_at']} | {pair['separated_at']} | "
              f"{s['rms_change_percent']:+.3f} | {height:.4f} |")  # fmt: skip


def hex19() -> None:
    quad = load(ROOT / "examples" / "vehicles" / "hex19.toml")
    linear = load(ROOT / "examples" / "swarm" / "hex19.toml")
    linear_1ms = quad.model_dump(mode="json", exclude_none=True) | {"model": {"kind": "linear"}}
    runs = {"linear (2), dt = 0.1 ms": linear, "linear (2), dt = 1 ms": from_dict(linear_1ms),
            "quadrotor, tilt loop, dt = 1 ms": changed(quad, model={"inner_loop": "tilt"}),
            "quadrotor, acceleration loop, dt = 1 ms": quad}  # fmt: skip
    print("| vehicle | largest edge error (m) | RMS edge error (m) | RMS change (%) | largest height error (m) |")
    print("| --- | --- | --- | --- | --- |")
    for name, scenario in runs.items():
        trajectory = tmem.simulate(scenario)
        error = formation_summary(trajectory)["distance_error"]
        height = np.max(np.abs(trajectory.body[..., BODY_NAMES.index("height")])) if trajectory.body.shape[-1] else 0.0
        print(f"| {name} | {error['max']:.3f} | {error['rms']:.3f} | {summarize(trajectory)['rms_change_percent']:+.3f} | {height:.4f} |")


if __name__ == "__main__":
    for part in (linearisation, against_rotorpy, fig9, hex19):
        print(f"\n## {part.__name__}\n")
        part()
