"""Wind on the quadrotor (tmem.vehicles.wind): each part against an independent reference.

* the constant wind: the compiled vehicle against RotorPy's own integration in its ``ConstantWind``,
  and a closed form: without the drag feed-forward an agent alone (``U = 0``: the TMEM law pushes
  only from neighbours) has the drag of its airspeed as its only horizontal force, so its velocity
  relaxes to the wind's, ``v(t) = w + (v_0 - w) exp(-c_h t)``, exactly while it stays level;
* the Dryden gusts: their variance and spectrum (scipy's Welch estimate) against the closed forms
  (D2)-(D3), folded at the Nyquist frequency as sampling folds them, at a fine and a coarse step;
  MIL-F-8785C's isotropy at 1000 ft; agents' gusts independent; the same bits on any number of
  threads and in a swarm of another size;
* bad ``[wind]`` tables refused in one line.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal, stats
from typer.testing import CliRunner

import tmem
from test_bad_input import GOOD, quadrotor as on_the_quadrotor
from test_quadrotor import MANOEUVRES, PERIOD, fly_rotorpy, fly_tmem
from tmem.cli.main import app
from tmem.vehicles.quadrotor import BODY_NAMES, GUSTS, REFERENCE, QuadrotorModel, step_quadrotor
from tmem.vehicles.wind import (
    FOOT,
    SEVERITY_W20,
    dryden_psd,
    gust_coefficients,
    gust_series,
    low_altitude_scales,
)
from tmem.scenario import QuadrotorModelParams, WindParams, from_dict, loads

#: Bounds of the statistical checks: about 5 standard deviations of each estimate.
Z = 5.0


def in_wind(wind: dict, **changes) -> QuadrotorModel:
    return QuadrotorModel(QuadrotorModelParams(kind="quadrotor", inner_loop="tilt", **changes), WindParams(**wind))


# --- the constant wind -------------------------------------------------------------------------


def test_in_a_constant_wind_the_compiled_quadrotor_flies_as_rotorpy_integrates_it():
    wind = (2.0, -1.5, 0.3)
    model = in_wind({"velocity": list(wind[:2]), "vertical": wind[2]}, inner_period=PERIOD)
    start = np.zeros((1, 2, 4))
    start[0, :, 1] = (1.0, -0.5)
    ours = fly_tmem(model, MANOEUVRES["step both"], start)
    theirs = fly_rotorpy(model, MANOEUVRES["step both"], ours[0], wind)
    position_error = np.max(np.linalg.norm(ours[:, :3] - theirs[:, :3], axis=1))
    dot = np.abs(np.sum(ours[:, 6:10] * theirs[:, 6:10], axis=1) / np.linalg.norm(theirs[:, 6:10], axis=1))
    attitude_error = np.degrees(np.max(2.0 * np.arccos(np.minimum(dot, 1.0))))
    assert position_error < 0.01 and attitude_error < 0.1, (position_error, attitude_error)
    calm = fly_tmem(QuadrotorModel(model.params), MANOEUVRES["step both"], start)
    assert np.linalg.norm(ours[-1, :2] - calm[-1, :2]) > 0.5  # the wind moved it (the feed-forward balances most of its drag)


def test_without_the_feedforward_an_agent_alone_relaxes_to_the_wind_velocity():
    wind = np.array([2.0, -1.0])
    model = in_wind({"velocity": list(wind)}, drag_feedforward=False)
    frame, dt = model.airframe(), 0.01
    c_h = 4.0 * frame.k_d * math.sqrt(frame.mass * frame.g / (4.0 * frame.k_eta)) / frame.mass
    x = np.zeros((1, 2, 4))
    x[0, :, 1] = (0.5, 0.5)
    body, params, u = model.initial_body(x), model.step_params(dt), np.zeros((1, 2))
    v0, error = x[0, :, 1].copy(), 0.0
    for k in range(1, 4001):
        step_quadrotor(x, body, u, 0, 1.0, params, 2)
        expected = wind + (v0 - wind) * math.exp(-c_h * k * dt)
        error = max(error, np.max(np.abs(x[0, :, 1] - expected)))
    assert error < 1e-9, error
    np.testing.assert_allclose(x[0, :, 1], wind, atol=2e-4)  # 40 s, ten time constants: drifting with the wind
    np.testing.assert_allclose(x[0, :, 2], 0.0, atol=1e-12)  # level: the law asks no tilt, no drag turns it
    assert abs(body[0, 0]) < 1e-9  # at its height


# --- the Dryden gusts --------------------------------------------------------------------------

LIGHT = low_altitude_scales(10.0, SEVERITY_W20["light"])
SPEED = 20.0


def folded_psd(f: np.ndarray, dt: float, terms: int = 500) -> np.ndarray:
    """(D2)-(D3) as sampling every ``dt`` folds them: ``sum_n 2 pi Φ(2 pi |f + n / dt|)``, per Hz."""
    total = np.zeros((3, len(f)))
    for n in range(-terms, terms + 1):
        total += 2.0 * np.pi * dryden_psd(2.0 * np.pi * np.abs(f + n / dt), *LIGHT, SPEED)
    return total


@pytest.mark.parametrize("dt, n_steps", [(0.05, 2**21), (0.5, 2**18)])
def test_the_gusts_have_the_dryden_variance_and_spectrum_at_any_step(dt, n_steps):
    sigma, length = LIGHT
    z = gust_series(gust_coefficients(sigma, length, SPEED, dt), 7, 3, n_steps)[:, :3]
    duration = n_steps * dt
    # Var of a sample variance: (2 sigma^4 / T) ∫ rho^2 over all lags; ∫ rho^2 = T_c for u, 5 T_c / 4 for v, w.
    memory = length / SPEED * np.array([1.0, 1.25, 1.25])
    bound = Z * np.sqrt(2.0 * memory / duration)
    np.testing.assert_array_less(np.abs(z.var(axis=0) / sigma**2 - 1.0), bound)
    per_segment = 2**13
    f, estimate = signal.welch(z.T, fs=1.0 / dt, window="hann", nperseg=per_segment, detrend=False)
    f, estimate = f[1:-1], estimate[:, 1:-1]
    ratio = estimate / folded_psd(f, dt)
    segments, band = 2 * n_steps // per_segment - 1, 64
    # Hann, half overlap: each bin's relative variance 1.056 / segments; adjacent bins correlate by 0.25.
    spread = math.sqrt(1.056 * 1.5 / (segments * band))
    bands = ratio[:, : ratio.shape[1] // band * band].reshape(3, -1, band).mean(axis=2)
    assert np.max(np.abs(bands - 1.0)) < Z * spread, (np.max(np.abs(bands - 1.0)), Z * spread)
    plain = 2.0 * np.pi * dryden_psd(2.0 * np.pi * f, *LIGHT, SPEED)
    assert np.max(np.abs(estimate / plain - 1.0)[:, -band:].mean(axis=1)) > 10 * Z * spread  # folding matters here


def test_the_low_altitude_forms_are_isotropic_at_1000_ft_and_scale_with_w20():
    sigma, length = low_altitude_scales(1000.0 * FOOT, 10.0)
    np.testing.assert_allclose(length, 1000.0 * FOOT, rtol=1e-12)
    np.testing.assert_allclose(sigma, 1.0, rtol=1e-12)
    sigma, length = low_altitude_scales(10.0, SEVERITY_W20["light"])
    assert sigma[2] == pytest.approx(0.1 * 15.0 * 0.514444, rel=1e-5)  # 15 knots
    assert length[2] == 10.0 and length[0] == length[1] > length[2]
    assert SEVERITY_W20["severe"] == pytest.approx(3.0 * SEVERITY_W20["light"])


def test_the_agents_gusts_are_independent_of_each_other_and_across_components():
    sigma, length = LIGHT
    coefficients = gust_coefficients(sigma, length, SPEED, 0.05)
    n_steps = 2**20
    first, second = (gust_series(coefficients, 7, agent, n_steps) for agent in (0, 1))
    other_seed = gust_series(coefficients, 8, 0, n_steps)
    # The sample correlation of two independent processes has variance ∫ rho_a rho_b / T.
    bound = Z * math.sqrt(1.25 * length[0] / SPEED / (n_steps * 0.05))
    for a, b in ((first[:, 0], second[:, 0]), (first[:, 2], second[:, 2]), (first[:, 0], first[:, 2]),
                 (first[:, 1], first[:, 2]), (first[:, 0], other_seed[:, 0])):  # fmt: skip
        assert abs(stats.pearsonr(a, b)[0]) < bound


def turbulent_gas(n: int) -> tmem.Scenario:
    return from_dict({
        "model": {"kind": "quadrotor"}, "interaction": {"function": "repulsion"},
        "space": {"axes": 2, "periodic": True, "box": [200.0, 200.0]},
        "swarm": {"n": n, "seed": 3, "speed_rms": 3.0}, "neighbors": {"method": "verlet"},
        "simulation": {"dt": 0.01, "duration": 1.0, "record_every": 10},
        "wind": {"velocity": [3.0, 1.0], "turbulence": {"severity": "moderate", "seed": 5}},
    })  # fmt: skip


def test_the_gusts_are_the_same_bits_on_threads_and_in_a_swarm_of_another_size(monkeypatch):
    """The product's claim (docs/vehicles.md), bit for bit: each agent's gusts are drawn from its own
    stream by the step, so the threaded loop on one and on two threads gives the serial loop's
    states and body states, and a swarm of 20 agents the first 20 agents' gusts."""
    import numba

    from tmem.engine import driver

    serial = tmem.simulate(turbulent_gas(40))
    monkeypatch.setattr(driver, "THREADED_SWARM", 0)
    threads = numba.get_num_threads()
    try:
        runs = []
        for count in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(count)
            runs.append(tmem.simulate(turbulent_gas(40)))
    finally:
        numba.set_num_threads(threads)
    for run in runs:
        np.testing.assert_array_equal(run.state, serial.state)
        np.testing.assert_array_equal(run.body, serial.body)
    smaller = tmem.simulate(turbulent_gas(20))
    np.testing.assert_array_equal(smaller.body[:, :, GUSTS:REFERENCE], serial.body[:, :20, GUSTS:REFERENCE])
    assert not np.array_equal(smaller.state, serial.state[:, :20])  # other swarms, the same gusts
    gusts = serial.body[:, :, GUSTS : GUSTS + 3]
    assert np.all(np.ptp(gusts, axis=0) > 0.0) and np.unique(gusts[-1, :, 0]).size == 40
    assert BODY_NAMES[GUSTS:] == ("gust_u", "gust_v", "gust_w", "gust_v_lag", "gust_w_lag", "gust_stream", "gust_step")
    assert np.all(serial.final_body[:, REFERENCE - 1] == 100)  # each agent drew the gusts of its 100 steps


# --- bad tables ----------------------------------------------------------------------------------

QUADROTOR = on_the_quadrotor("")
WIND_CASES = {
    "wind on the linear model": (GOOD + "\n[wind]\nvelocity = [1.0]\n", "wind", "only the quadrotor model feels wind"),
    "velocity per axis": (QUADROTOR + "\n[wind]\nvelocity = [1.0, 2.0]\n", "wind.velocity", "needs 1 value"),
    "typo": (QUADROTOR + "\n[wind]\nspeed = 1.0\n", "wind.speed", "unknown key"),
    "no intensity": (QUADROTOR + "\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nheight = 5.0\n",
                     "wind.turbulence.severity", "exactly one of severity, w20 or sigma, got none"),
    "two intensities": (QUADROTOR + '\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nseverity = "light"\nw20 = 3.0\n',
                        "wind.turbulence.severity", "got severity, w20"),
    "unknown severity": (QUADROTOR + '\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nseverity = "gale"\n',
                         "wind.turbulence.severity", "'light'"),
    "too low": (QUADROTOR + '\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nseverity = "light"\nheight = 1.0\n',
                "wind.turbulence.height", "greater than or equal to 3.048"),
    "sigma of two": (QUADROTOR + "\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nsigma = [1.0, 1.0]\n",
                     "wind.turbulence.sigma", "at least 3"),
    "negative sigma": (QUADROTOR + "\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nsigma = [1.0, -1.0, 1.0]\n",
                       "wind.turbulence.sigma[1]", "greater than or equal to 0"),
    "no speed": (QUADROTOR + '\n[wind]\n[wind.turbulence]\nseverity = "light"\n', "wind.turbulence.speed",
                 "is required when there is no constant wind"),
    "a wind in km/h": (QUADROTOR + "\n[wind]\nvelocity = [1e6]\n", "wind.velocity", "1e+06 m/s, more than 100 m/s"),
    "an updraught in km/h": (QUADROTOR + "\n[wind]\nvertical = 150.0\n", "wind.vertical", "150 m/s, more than 100"),
    "gusts in km/h": (QUADROTOR + "\n[wind]\nvelocity = [1.0]\n[wind.turbulence]\nw20 = 120.0\n",
                      "wind.turbulence.w20", "120 m/s is more than 100 m/s"),
}


@pytest.mark.interface
@pytest.mark.parametrize("case", WIND_CASES)
def test_a_bad_wind_table_is_refused_in_one_line(case, tmp_path):
    text, field, reason = WIND_CASES[case]
    scenario = tmp_path / "bad.toml"
    scenario.write_text(text)
    result = CliRunner().invoke(app, ["run", str(scenario), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and f": {field}: " in lines[0] and reason in lines[0], lines
    assert "Traceback" not in result.output and not (tmp_path / "out").exists()


@pytest.mark.interface
def test_a_good_wind_table_is_read_back_from_its_toml():
    text = QUADROTOR + '\n[wind]\nvelocity = [1.0]\nvertical = -0.5\n[wind.turbulence]\nseverity = "light"\nseed = 4\n'
    scenario = loads(text)
    assert loads(scenario.to_toml()) == scenario
    assert scenario.wind.mean() == (1.0, 0.0, -0.5) and scenario.wind.passing_speed() == pytest.approx(math.hypot(1.0, 0.5))
