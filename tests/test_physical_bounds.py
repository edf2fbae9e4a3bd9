"""Every physical input against the bound that makes it meaningful, each bound a figure of the model.

Two parts:

* the figures of :mod:`tmem.scenario.bounds` against references that do not use them: the tilt
  the rotors hold against the flight controller's own allocation, the inner loops' poles against
  python-control and against the compiled quadrotor flown, the airspeed against the rigid body's
  trim found from its own forces, the peak tilt against an ODE solver, the stopping speed against
  the engine's encounters;
* a battery of values beyond a bound, each refused by ``tmem run`` in one line naming the field
  (exit status 2, no traceback, nothing written), of values legal but doubtful, each warned of in
  one line, and of values just inside each bound, accepted without a word.
"""

from __future__ import annotations

import math
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app
from tmem.scenario import QuadrotorModelParams, ScenarioWarning, loads
from tmem.scenario.bounds import (
    SMALL_ANGLE_TILT, airspeed_limit, held_tilt, hover_drag, loop_poles, peak_tilt, stopping_speed,
)  # fmt: skip
from test_bad_input_battery import _assert_refused, changed, dump

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CRAZYFLIE = QuadrotorModelParams(kind="quadrotor")


def _table(path: str) -> dict:
    return tomllib.loads(tmem.scenario.load(EXAMPLES / path).to_toml())


FIG9 = tomllib.loads(tmem.preset("fig9").to_toml())
QUAD = _table("vehicles/fig9.toml")
QUAD_TILT = changed(QUAD, "model.inner_loop", "tilt")
HEX = _table("swarm/hex19.toml")
HEX_QUAD = _table("vehicles/hex19_wind.toml")
GAS = _table("swarm/gas2d.toml")
EDGES = _table("swarm/edges.toml")
SHORT = changed(changed(FIG9, "simulation.duration", 5.0), "commands", [])


# -- the figures against independent references ----------------------------------------------------


@pytest.mark.parametrize("share", [1.0, 0.9])
def test_the_held_tilt_is_where_the_allocation_clips_the_rotors(share):
    """The flight controller's allocation (tmem.vehicles.rigid_body.rotor_commands), asked for the
    altitude hold's thrust m g / cos(tilt), commands every rotor below its fastest speed just inside
    the held tilt, and clips one just beyond."""
    from tmem.vehicles.quadrotor import QuadrotorModel
    from tmem.vehicles.rigid_body import rotor_commands

    frame = QuadrotorModel(CRAZYFLIE).airframe()._replace(rotor_speed_max=share * CRAZYFLIE.rotor_speed_max)
    tilt = held_tilt(CRAZYFLIE.mass, CRAZYFLIE.g, CRAZYFLIE.k_eta, frame.rotor_speed_max)
    for factor, clipped in ((0.999, False), (1.001, True)):
        speeds = rotor_commands.py_func(CRAZYFLIE.mass * CRAZYFLIE.g / math.cos(factor * tilt), 0.0, 0.0, 0.0, frame)
        assert (max(speeds) >= frame.rotor_speed_max) is clipped
    assert tilt == pytest.approx(1.0335, abs=1e-4) if share == 1.0 else tilt == pytest.approx(0.8868, abs=1e-4)


@pytest.mark.parametrize("kp, kd, damping, h", [(6.0, 25.0, 0.349, 0.002), (13.0, 25.0, 0.0, 1e-4), (2.0, 8.0, 0.18, 0.001),
                                                (1e6, 25.0, 0.349, 0.002), (6.0, 125.0, 0.0, 0.002)])  # fmt: skip
def test_the_inner_loop_poles_are_python_controls(kp, kd, damping, h):
    """The loop x' = r, r' = a - c r, a' = (u - a) / tau, u = -kd (kp x + r), sampled by a zero-order
    hold: python-control's c2d of the plant, the state feedback closed on the sampled system."""
    control = pytest.importorskip("control")
    tau = 0.072
    plant = control.ss([[0, 1, 0], [0, -damping, 1], [0, 0, -1 / tau]], [[0], [0], [1 / tau]], np.eye(3), np.zeros((3, 1)))
    sampled = control.c2d(plant, h, method="zoh")
    closed = sampled.A - sampled.B @ np.array([[kd * kp, kd, 0.0]])
    expected = np.sort_complex(np.linalg.eigvals(closed))
    np.testing.assert_allclose(np.sort_complex(loop_poles(kp, kd, damping, tau, h)), expected, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 30.0, 1e4])
def test_the_small_exponential_is_scipys(scale):
    from scipy.linalg import expm

    from tmem.scenario.bounds import exponential

    m = scale * np.array([[0.0, 1.0, 0.0, 0.0], [-2.0, -0.3, 1.0, 0.0], [0.0, 0.0, -1.0, 1.0], [0.0, 0.0, 0.0, 0.0]])
    np.testing.assert_allclose(exponential(m), expm(m), rtol=1e-12, atol=1e-14 * np.abs(expm(m)).max())


@pytest.mark.parametrize("kp, grows", [(11.0, False), (17.0, True)])
def test_the_stability_bound_is_the_compiled_quadrotors(kp, grows):
    """The Crazyflie's attitude loop is stable below kp = 13.89 /s at h = 2 ms (the bound's figure, on
    its pitch axis, damped by the rotors' inflow at c_r = 0.349 /s): flown from a tilt of 0.02 rad,
    the compiled Crazyflie's tilt dies out at kp = 11 and grows at kp = 17."""
    from tmem.scenario.vehicle_bounds import _largest_stable

    radius = lambda g: max(abs(loop_poles(g, 25.0, c, 0.072, 0.002)).max() for c in (0.349, 0.469))  # noqa: E731
    assert _largest_stable(radius, 1e6) == pytest.approx(13.89, abs=0.01)
    from tmem.vehicles.quadrotor import QuadrotorModel

    model = QuadrotorModel(QuadrotorModelParams(kind="quadrotor", kp=kp, inner_loop="tilt"))
    x = np.zeros((1, 1, 4))
    x[0, 0, 2] = 0.02
    body, params, u = model.initial_body(x), model.step_params(0.002), np.zeros((1, 1))
    tilts = []
    for _ in range(2500):  # 5 s
        model.kernel()(x, body, u, 0, 1.0, params, 1)
        tilts.append(x[0, 0, 2])
    last = np.abs(np.nan_to_num(np.array(tilts[-500:]), nan=np.inf)).max()
    assert (last > 0.1) if grows else (last < 0.002)


def _trim(theta: float, frame) -> tuple[float, float]:
    """``(airspeed, rotor speed)`` of the rigid body level at the lean ``theta``: its own forces
    (tmem.vehicles.rigid_body.wrench) balanced, found by root finding."""
    from scipy.optimize import brentq

    from tmem.vehicles.quadrotor import attitude_of_tilts
    from tmem.vehicles.rigid_body import rotation, wrench

    q = attitude_of_tilts(theta, 0.0)
    r = rotation(*q)

    def force(v, o):
        f = wrench.py_func((0, 0, 0, v, 0, 0, *q, 0, 0, 0, o, o, o, o), r, frame, (0.0, 0.0, 0.0))
        return r[0] * f[0] + r[1] * f[1] + r[2] * f[2], r[6] * f[0] + r[7] * f[1] + r[8] * f[2] - frame.mass * frame.g

    rotor = lambda v: brentq(lambda o: force(v, o)[1], 100.0, 1e5)  # noqa: E731
    v = brentq(lambda v: force(v, rotor(v))[0], 0.0, 1000.0)
    return v, rotor(v)


@pytest.mark.parametrize("share, tolerance", [(1.0, 0.03), (0.9, 0.10)])
def test_the_airspeed_limit_is_the_rigid_bodys_trim(share, tolerance):
    """The fastest level airspeed of the rigid body whose rotors stay at or below share x o_max: its
    own trim (lean and rotor speed found from (Q1)'s forces, the rotors' drag and inflow in) is
    66.1 m/s at o_max, where the bound's first-order figure is 67.4 m/s; 54.0 m/s at 0.9 o_max, 49.2."""
    from scipy.optimize import brentq

    from tmem.vehicles.quadrotor import QuadrotorModel

    frame = QuadrotorModel(CRAZYFLIE).airframe()
    speed = share * CRAZYFLIE.rotor_speed_max
    lean = brentq(lambda t: _trim(t, frame)[1] - speed, 0.5, 1.4)
    true = _trim(lean, frame)[0]
    m = CRAZYFLIE
    bound = airspeed_limit(m.mass, m.g, hover_drag(m.mass, m.g, m.k_eta, m.rotor_drag), 0.0, held_tilt(m.mass, m.g, m.k_eta, speed))
    assert bound == pytest.approx(true, rel=tolerance)


@pytest.mark.parametrize("tilt, rate, kp, kd", [(0.0, 10.0, 6.0, 25.0), (0.1, -3.0, 6.0, 25.0), (0.0, 5.0, 40.0, 10.0),
                                                (0.3, 0.0, 6.0, 25.0), (-0.2, 8.0, 100.0, 25.0)])  # fmt: skip
def test_the_peak_tilt_is_the_ode_solvers(tilt, rate, kp, kd):
    from scipy.integrate import solve_ivp

    slowest = float(np.min(-np.roots([1.0, kd, kp * kd]).real))
    solved = solve_ivp(lambda t, x: [x[1], -kp * kd * x[0] - kd * x[1]], (0.0, 10.0 / slowest), [tilt, rate],
                       rtol=1e-11, atol=1e-13, dense_output=True)  # fmt: skip
    exact = np.abs(solved.sol(np.linspace(0.0, 10.0 / slowest, 200_001))[0]).max()
    assert peak_tilt(tilt, rate, kp, kd) == pytest.approx(exact, rel=2e-4)


def test_the_small_angle_tilt_is_where_g_phi_is_ten_percent_short():
    from scipy.optimize import brentq

    assert SMALL_ANGLE_TILT == pytest.approx(brentq(lambda x: math.tan(x) / x - 1.1, 0.1, 1.5), rel=1e-12)


@pytest.mark.parametrize("share, apart", [(0.7, True), (1.05, False)])
def test_a_pair_closing_faster_than_the_stopping_speed_passes_through(share, apart):
    """Head-on under the repulsion (8) at 0.7 of sqrt(4 g tan(c_max) (R + R_j)) the pair turns round;
    at 1.05 of it the agents cross: their order is reversed at the end."""
    v = share * stopping_speed(9.8 * math.tan(0.1), 40.0)
    scenario = tmem.scenario.from_dict(changed(changed(changed(changed(FIG9, "agents.0.velocity", -v / 2), "agents.1.velocity", v / 2),
                                       "interaction.function", "repulsion"), "commands", []) | {"simulation": {"dt": 1e-3, "duration": 20.0, "record_every": 1000}})  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ScenarioWarning)
        trajectory = tmem.simulate(scenario)
    gap = trajectory.final_state[0, 0, 0] - trajectory.final_state[1, 0, 0]
    assert bool(gap > 0.0) is apart


# -- the battery: beyond a bound, refused by the command line in one line naming the field ------------

REFUSED: dict[str, tuple[dict, str]] = {
    # the quadrotor: the tilt its rotors hold (1.033 rad), its inner loops, its airspeed (67.4 m/s)
    "quadrotor start tilt 1.2 rad": (changed(QUAD, "agents.0.tilt", 1.2), "agents[0].tilt"),
    "quadrotor start tilt -2 rad": (changed(QUAD, "agents.0.tilt", -2.0), "agents[0].tilt"),
    "quadrotor start tilt 3 rad": (changed(QUAD, "agents.0.tilt", 3.0), "agents[0].tilt"),
    "quadrotor start tilt pi/2": (changed(QUAD, "agents.1.tilt", math.pi / 2), "agents[1].tilt"),
    "quadrotor tilts 0.9 on both axes": ({k: v for k, v in HEX_QUAD.items() if k != "formation"} | {"agents": [
        {"position": [0.0, 0.0], "tilt": [0.9, 0.9]}, {"position": [30.0, 0.0]}]}, "agents[0].tilt"),
    "quadrotor tilt rate 100 rad/s": (changed(QUAD, "agents.0.tilt_rate", 100.0), "agents[0].tilt_rate"),
    "quadrotor slower rotors, tilt 0.7": (changed(changed(QUAD, "model.rotor_speed_max", 2000.0), "agents.0.tilt", 0.7),
                                          "agents[0].tilt"),
    "attitude kp 1e6": (changed(QUAD, "model.kp", 1e6), "model.kp"),
    "attitude kp 20": (changed(QUAD, "model.kp", 20.0), "model.kp"),
    "motors' lag 0.5 s": (changed(QUAD, "model.tau_m", 0.5), "model.kp"),
    "altitude_kp 1e9": (changed(QUAD, "model.altitude_kp", 1e9), "model.altitude_kp"),
    "altitude_kp 200": (changed(QUAD, "model.altitude_kp", 200.0), "model.altitude_kp"),
    "tilt limit 1.8 rad, acceleration loop": (changed(QUAD, "interaction.c_max", 1.8), "interaction.c_max"),
    "tilt limit 1.1 rad, tilt loop": (changed(QUAD_TILT, "interaction.c_max", 1.1), "interaction.c_max"),
    "quadrotor at 200 m/s": (changed(QUAD, "agents.0.velocity", 200.0), "agents[0].velocity"),
    "quadrotor formation at 80 m/s": (changed(HEX_QUAD, "formation.velocity", [80.0, 0.0]), "formation.velocity"),
    "wind 99 m/s": (changed(QUAD, "wind", {"velocity": [99.0]}), "wind.velocity"),
    "wind 70 m/s": (changed(HEX_QUAD, "wind.velocity", [0.0, 70.0]), "wind.velocity"),
    "downdraft 60 m/s": (changed(QUAD, "wind", {"vertical": -60.0}), "wind.vertical"),
    "gusts sigma 500 m/s": (changed(HEX_QUAD, "wind.turbulence", {"sigma": [500.0, 500.0, 500.0]}), "wind.turbulence.sigma"),
    "gusts sigma 60 m/s": (changed(HEX_QUAD, "wind.turbulence", {"sigma": [60.0, 60.0, 5.0]}), "wind.turbulence.sigma"),
    "vertical gusts sigma 55 m/s": (changed(HEX_QUAD, "wind.turbulence", {"sigma": [1.0, 1.0, 55.0]}), "wind.turbulence.sigma"),
    # the small-angle model (1)-(2): tilts within +-pi/2
    "linear start tilt 3 rad": (changed(FIG9, "agents.0.tilt", 3.0), "agents[0].tilt"),
    "linear start tilt -1.6 rad": (changed(FIG9, "agents.1.tilt", -1.6), "agents[1].tilt"),
    "linear tilt rate 100 rad/s": (changed(FIG9, "agents.0.tilt_rate", 100.0), "agents[0].tilt_rate"),
    # the coupling window against one step's closing distance (4.5 m/s x dt)
    "eps 0.001 m at dt 0.01 s": (changed(changed(FIG9, "interaction.eps", 0.001), "simulation.dt", 0.01), "interaction.eps"),
    "eps 0.02 m at dt 0.01 s": (changed(changed(FIG9, "interaction.eps", 0.02), "simulation.dt", 0.01), "interaction.eps"),
    "eps 1e-5 m at dt 1e-4 s": (changed(FIG9, "interaction.eps", 1e-5), "interaction.eps"),
    # starts against the reach per step (R + R_j) / dt
    "start at 1e9 m/s": (changed(FIG9, "agents.0.velocity", 1e9), "agents[0].velocity"),
    "start at 5e5 m/s": (changed(FIG9, "agents.1.velocity", 5e5), "agents[1].velocity"),
    "walled box, 50 m a step": (changed(changed(GAS, "space", {"axes": 2, "walls": True, "box": [600.0, 600.0]}),
                                        "swarm", {"n": 50, "seed": 1, "speed_rms": 2500.0}), "swarm.speed_rms"),
    "swarm at 1e4 m/s RMS": (changed(SHORT | {"agents": []}, "swarm", {"n": 10, "region": [500.0], "speed_rms": 1e4})
                             | {"simulation": {"dt": 0.01, "duration": 1.0}}, "swarm.speed_rms"),  # fmt: skip
    "thermostat at 1e4 m/s": (changed(GAS, "thermostat", {"rms_velocity": 1e4}), "thermostat.rms_velocity"),
    # a formation's jitter against d_t and R + R_j - d_t (5 m)
    "jitter 100 m": (changed(HEX, "formation.jitter", 100.0), "formation.jitter"),
    "jitter 2 m in the plane": (changed(HEX, "formation.jitter", 2.0), "formation.jitter"),
    "jitter 13 m, pairs uncoupled": (changed(changed(HEX, "formation.jitter", 13.0), "formation.coupled", False), "formation.jitter"),
    "edges coupled 50 m apart": (changed(changed(EDGES, "formation.coupled", True), "agents.1.position", [60.0, 0.0]),
                                 "formation.edges"),
    # the sensing against the run's duration, the set distance and the reach
    "delay 100 s in a 5 s run": (changed(SHORT, "sensing", {"delay": 100.0}), "sensing.delay"),
    "delays [6, 8] s in a 5 s run": (changed(SHORT, "sensing", {"delay": [6.0, 8.0]}), "sensing.delay"),
    "period 70 s in a 60 s run": (changed(FIG9, "sensing", {"period": 70.0}), "sensing.period"),
    "range 30 m below d_t": (changed(FIG9, "sensing", {"range": 30.0}), "sensing.range"),
    "position noise 50 m": (changed(FIG9, "sensing", {"position_noise": 50.0}), "sensing.position_noise"),
    "own position noise 45 m": (changed(FIG9, "sensing", {"own_position_noise": 45.0}), "sensing.own_position_noise"),
}


@pytest.mark.parametrize("name", REFUSED, ids=list(REFUSED))
def test_beyond_a_bound_is_refused_in_one_line(name, tmp_path, monkeypatch):
    import tmem.engine

    monkeypatch.setattr(tmem.engine, "simulate", _not_run)  # a case let through fails here, not after a run
    data, field = REFUSED[name]
    (tmp_path / "bad.toml").write_text(dump(data))
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["run", str(tmp_path / "bad.toml"), "--out", str(out)])
    _assert_refused(result, field, out, {"bad.toml"}, tmp_path)
    assert result.output.startswith("error: ")


def _not_run(*args, **kwargs):
    raise AssertionError("validation let the case through to the simulation")


# -- legal but doubtful: a warning of one line naming the field; just inside: not a word ---------------

DOUBTFUL: dict[str, tuple[dict, str]] = {
    "quadrotor start tilt 0.95 rad": (changed(QUAD, "agents.0.tilt", 0.95), "agents[0].tilt"),
    "quadrotor tilt rate 33 rad/s": (changed(QUAD, "agents.0.tilt_rate", 33.0), "agents[0].tilt_rate"),
    "attitude kp 13": (changed(QUAD, "model.kp", 13.0), "model.kp"),
    "altitude_kp 100": (changed(QUAD, "model.altitude_kp", 100.0), "model.altitude_kp"),
    "tilt limit 1.3 rad, acceleration loop": (changed(QUAD, "interaction.c_max", 1.3), "interaction.c_max"),
    "quadrotor at 55 m/s": (changed(changed(QUAD, "agents.0.velocity", 55.0), "agents.1.velocity", 55.0), "agents[0].velocity"),
    "wind 55 m/s": (changed(QUAD, "wind", {"velocity": [55.0]}), "wind.velocity"),
    "gusts of 3 sigma beyond the airspeed": (changed(HEX_QUAD, "wind.turbulence", {"sigma": [25.0, 25.0, 2.0]}),
                                             "wind.turbulence.sigma"),
    "linear start tilt 0.6 rad": (changed(FIG9, "agents.0.tilt", 0.6), "agents[0].tilt"),
    "linear tilt rate 20 rad/s": (changed(FIG9, "agents.0.tilt_rate", 20.0), "agents[0].tilt_rate"),
    "tilt limit 0.6 rad": (changed(FIG9, "interaction.c_max", 0.6), "interaction.c_max"),
    "tilt limit 2 rad, a limit past the horizontal": (changed(FIG9, "interaction.c_max", 2.0), "interaction.c_max"),
    "tilt limit 10 rad, never saturating": (changed(GAS, "interaction.c_max", 10.0), "interaction.c_max"),
    "small agents passing through each other between steps": (
        changed(changed(changed(GAS, "interaction", {"function": "repulsion", "radius": 0.05, "d_t": 0.05, "eps": 0.01}),
                        "space", {"axes": 2, "walls": True, "box": [300.0, 300.0], "wall_radius": 39.95}),
                "swarm", {"n": 50, "seed": 1, "speed_rms": 8.4}), "swarm.speed_rms"),
    "eps 0.03 m at dt 0.01 s": (changed(changed(FIG9, "interaction.eps", 0.03), "simulation.dt", 0.01), "interaction.eps"),
    "closing at 20 m/s": (changed(FIG9, "agents.1.velocity", 18.5), "agents[1].velocity"),
    "delay 5 s": (changed(FIG9, "sensing", {"delay": 5.0}), "sensing.delay"),
    "range 38 m": (changed(FIG9, "sensing", {"range": 38.0}), "sensing.range"),
    "position noise 6 m": (changed(FIG9, "sensing", {"position_noise": 6.0}), "sensing.position_noise"),
}
ACCEPTED: dict[str, dict] = {
    "quadrotor start tilt 0.85 rad": changed(QUAD, "agents.0.tilt", 0.85),
    "attitude kp 10": changed(QUAD, "model.kp", 10.0),
    "quadrotor at 45 m/s": changed(changed(QUAD, "agents.0.velocity", 45.0), "agents.1.velocity", 45.0),
    "wind 45 m/s": changed(QUAD, "wind", {"velocity": [45.0]}),
    "severe gusts": changed(HEX_QUAD, "wind.turbulence", {"severity": "severe", "speed": 23.15}),
    "linear start tilt 0.5 rad": changed(FIG9, "agents.0.tilt", 0.5),
    "tilt limit 0.5 rad": changed(FIG9, "interaction.c_max", 0.5),
    "eps 0.05 m at dt 0.01 s": changed(changed(FIG9, "interaction.eps", 0.05), "simulation.dt", 0.01),
    "closing at 12 m/s": changed(FIG9, "agents.1.velocity", 10.5),
    "jitter 1.7 m in the plane": changed(HEX, "formation.jitter", 1.7),
    "delay 2.5 s": changed(FIG9, "sensing", {"delay": 2.5}),
    "range 40 m": changed(FIG9, "sensing", {"range": 40.0}),
    "position noise 4.9 m": changed(FIG9, "sensing", {"position_noise": 4.9}),
}


def _warnings_of(data: dict) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        loads(dump(data), source="case.toml")
    return [str(w.message) for w in caught if issubclass(w.category, ScenarioWarning)]


@pytest.mark.parametrize("name", DOUBTFUL, ids=list(DOUBTFUL))
def test_a_doubtful_value_is_warned_of_in_one_line(name):
    data, field = DOUBTFUL[name]
    said = _warnings_of(data)
    assert any(line.startswith(f"{field}: ") for line in said), said
    assert all("\n" not in line and any(c.isdigit() for c in line) for line in said), said


@pytest.mark.parametrize("name", ACCEPTED, ids=list(ACCEPTED))
def test_just_inside_a_bound_is_accepted_without_a_word(name):
    assert _warnings_of(ACCEPTED[name]) == []


def test_the_battery_has_forty_new_cases_and_more():
    assert len(REFUSED) + len(DOUBTFUL) + len(ACCEPTED) >= 40


def test_the_command_warns_of_a_doubtful_value_in_one_line(tmp_path):
    """``tmem run`` prints a doubt as one ``warning:`` line on standard error, as it prints an error."""
    import subprocess
    import sys

    scenario = tmp_path / "w.toml"
    scenario.write_text('[interaction]\nc_max = 0.6\n[simulation]\nduration = 1.0\n[[agents]]\nposition = 50.0\n'
                        '[[agents]]\nposition = 0.0\n')  # fmt: skip
    done = subprocess.run([sys.executable, "-m", "tmem", "run", str(scenario), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr
    warned = [line for line in done.stderr.splitlines() if line.strip()]
    assert warned == [warned[0]] and warned[0].startswith("warning: interaction.c_max: 0.6 rad lets the law command tilts")
