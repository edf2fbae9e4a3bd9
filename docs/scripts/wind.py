"""The figures of docs/vehicles.md's section on wind: RotorPy in a constant wind, Fig. 9 and hex19 in wind.

Prints Markdown tables to standard output::

    python docs/scripts/wind.py          # about 10 minutes on 2 cores once compiled

The comparison with RotorPy flies the manoeuvres of ``tests/test_quadrotor.py`` in RotorPy's
``ConstantWind`` with that test's own code.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import test_quadrotor as manoeuvres  # noqa: E402

import tmem  # noqa: E402
from tmem.analysis.metrics import formation_summary, summarize  # noqa: E402
from tmem.vehicles.quadrotor import BODY_NAMES, QuadrotorModel, step_quadrotor  # noqa: E402
from tmem.vehicles.wind import SEVERITY_W20  # noqa: E402
from tmem.scenario import QuadrotorModelParams, WindParams, from_dict, load  # noqa: E402

#: The constant wind of the comparison with RotorPy (m/s, world frame).
WIND = (2.0, -1.5, 0.3)
#: Light turbulence with no mean wind: the field passes at W_20, the wind speed it comes with.
LIGHT = {"severity": "light", "speed": round(SEVERITY_W20["light"], 3)}


def against_rotorpy() -> None:
    print(f"In the constant wind {WIND} m/s:\n")
    print("| manoeuvre | largest position error (m) | largest attitude error (deg) | distance flown (m) |")
    print("| --- | --- | --- | --- |")
    for name, setpoint in manoeuvres.MANOEUVRES.items():
        params = QuadrotorModelParams(kind="quadrotor", inner_period=manoeuvres.PERIOD)
        model = QuadrotorModel(params, WindParams(velocity=list(WIND[:2]), vertical=WIND[2]))
        start = np.zeros((1, 2, 4))
        start[0, :, 1] = (1.0, -0.5)
        ours = manoeuvres.fly_tmem(model, setpoint, start)
        theirs = manoeuvres.fly_rotorpy(model, setpoint, ours[0], WIND)
        position = np.max(np.linalg.norm(ours[:, :3] - theirs[:, :3], axis=1))
        dot = np.abs(np.sum(ours[:, 6:10] * theirs[:, 6:10], axis=1) / np.linalg.norm(theirs[:, 6:10], axis=1))
        attitude = np.degrees(np.max(2.0 * np.arccos(np.minimum(dot, 1.0))))
        flown = np.sum(np.linalg.norm(np.diff(ours[:, :3], axis=0), axis=1))
        print(f"| {name} | {position:.1e} | {attitude:.1e} | {flown:.1f} |")


def hover() -> None:
    """One Crazyflie alone (``U = 0``) starting at rest and level in a constant wind along x, 60 s."""
    print("| wind (m/s) | speed at 1 s (m/s) | at 60 s (m/s) | drift from 10 to 60 s (m/s²) | tilt (deg) |")
    print("| --- | --- | --- | --- | --- |")
    for w in (1.0, 3.0, 5.0, 12.0, 16.0):
        model = QuadrotorModel(QuadrotorModelParams(kind="quadrotor"), WindParams(velocity=[w, 0.0]))
        x = np.zeros((1, 2, 4))
        body, params, u = model.initial_body(x), model.step_params(0.01), np.zeros((1, 2))
        speeds = []
        for _ in range(6000):
            step_quadrotor(x, body, u, 0, 1.0, params, 2)
            speeds.append(x[0, 0, 1])
        drift = (speeds[-1] - speeds[999]) / 50.0
        print(f"| {w:g} | {speeds[99]:.3f} | {speeds[-1]:.3f} | {drift:.1e} | {np.degrees(x[0, 0, 2]):.2f} |")


def with_wind(scenario, wind: dict | None):
    data = scenario.model_dump(mode="json", exclude_none=True)
    data.pop("wind", None)
    return from_dict(data if wind is None else {**data, "wind": wind})


def on_two_axes(scenario):
    """Fig. 9 (one axis) flown along x in a 2-D run, so that a wind can blow across it (along y)."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    data["space"] = {**data["space"], "axes": 2}
    for agent in data["agents"]:
        agent["position"], agent["velocity"] = [agent["position"], 0.0], [agent["velocity"], 0.0]
        if "tilt" in agent:  # examples/vehicles/fig9.toml starts its agents trimmed
            agent["tilt"] = [agent["tilt"], 0.0]
    return from_dict(data)


def height(trajectory) -> float:
    return float(np.max(np.abs(trajectory.body[..., BODY_NAMES.index("height")])))


def fig9() -> None:
    quad = load(ROOT / "examples" / "vehicles" / "fig9.toml")
    across = on_two_axes(quad)
    runs = {"no wind": quad}
    runs |= {f"{w:g} m/s along x": with_wind(quad, {"velocity": [w]}) for w in (1.0, 3.0, 5.0)}
    runs |= {"no wind, 2-D": across}
    runs |= {f"{w:g} m/s across (y), 2-D": with_wind(across, {"velocity": [0.0, w]}) for w in (1.0, 3.0, 5.0)}
    runs |= {f"light turbulence, seed {seed}": with_wind(quad, {"turbulence": {**LIGHT, "seed": seed}}) for seed in (0, 1, 2)}
    runs |= {"3 m/s along x and light turbulence": with_wind(quad, {"velocity": [3.0], "turbulence": {"severity": "light"}})}
    print("| wind | couples at (s) | uncouples at (s) | apart at (s) | RMS change (%) | largest height error (m) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, scenario in runs.items():
        trajectory = tmem.simulate(scenario)
        s = summarize(trajectory)
        pair = s["pairs"][0]
        print(f"| {name} | {pair['coupled_at']} | {pair['uncoupled_at']} | {pair['separated_at'] and round(pair['separated_at'], 2)} | "
              f"{s['rms_change_percent']:+.3f} | {height(trajectory):.4f} |")  # fmt: skip


def hex19() -> None:
    quad = load(ROOT / "examples" / "vehicles" / "hex19.toml")
    runs = {f"{w:g} m/s along x": with_wind(quad, {"velocity": [w, 0.0]} if w else None) for w in (0.0, 2.0, 5.0)}
    runs |= {"light turbulence": with_wind(quad, {"turbulence": LIGHT})}
    runs |= {"2 m/s along x and light turbulence": with_wind(quad, {"velocity": [2.0, 0.0], "turbulence": {"severity": "light"}})}
    print("| wind | largest edge error (m) | RMS edge error (m) | RMS change (%) | largest height error (m) |")
    print("| --- | --- | --- | --- | --- |")
    for name, scenario in runs.items():
        trajectory = tmem.simulate(scenario)
        error = formation_summary(trajectory)["distance_error"]
        print(f"| {name} | {error['max']:.3f} | {error['rms']:.3f} | {summarize(trajectory)['rms_change_percent']:+.3f} | "
              f"{height(trajectory):.4f} |")  # fmt: skip


if __name__ == "__main__":
    for part in sys.argv[1:] and [globals()[p] for p in sys.argv[1:]] or (against_rotorpy, hover, fig9, hex19):
        print(f"\n## {part.__name__}\n", flush=True)
        part()
