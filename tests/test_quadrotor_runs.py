"""Runs of the quadrotor through the engine: its symmetries, its body state carried, restored, recorded and written."""

from __future__ import annotations

import numpy as np
import pytest

import tmem
from tmem.files.io import contents
from tmem.vehicles.quadrotor import ACCELERATION_BODY_NAMES, BODY_NAMES
from tmem.scenario import from_dict


def two_agents(axes: int, along: int = 0, commands: list | None = None):
    """Fig. 9's pair on the quadrotor for 10 s at dt = 1 ms, flying along axis ``along`` of ``axes``."""

    def vector(value: float):
        if axes == 1:
            return value
        v = [0.0] * axes
        v[along] = value
        return v

    return from_dict({
        "model": {"kind": "quadrotor"},
        "space": {"axes": axes},
        "simulation": {"dt": 0.001, "duration": 10.0, "record_every": 10},
        "agents": [{"position": vector(50.0), "velocity": vector(-1.5)}, {"position": vector(0.0), "velocity": vector(3.0)}],
        "commands": commands or [],
    })  # fmt: skip


@pytest.fixture(scope="module")
def runs():
    return {name: tmem.simulate(two_agents(*shape)) for name, shape in {"1-D": (1,), "x": (2, 0), "y": (2, 1)}.items()}


def test_a_1d_run_is_the_2d_run_along_x(runs):
    one, two = runs["1-D"], runs["x"]
    assert np.min(one.pair_distance) < 36.0  # the pair met
    np.testing.assert_allclose(two.state[:, :, 0, :], one.state[:, :, 0, :], rtol=0, atol=1e-9)
    assert np.all(two.state[:, :, 1, :] == 0.0)  # nothing moves across
    np.testing.assert_allclose(two.body, one.body, rtol=0, atol=1e-9)


def test_a_run_along_y_is_the_run_along_x_turned_a_quarter(runs):
    along_x, along_y = runs["x"], runs["y"]
    np.testing.assert_allclose(along_y.state[:, :, 1, :], along_x.state[:, :, 0, :], rtol=0, atol=1e-8)
    np.testing.assert_allclose(along_y.state[:, :, 0, :], 0.0, atol=1e-12)


def test_the_body_state_is_recorded_and_written(runs):
    trajectory = runs["x"]
    assert trajectory.body.shape == (len(trajectory.time), 2, len(ACCELERATION_BODY_NAMES))  # the default loop's
    np.testing.assert_array_equal(trajectory.final_body, trajectory.body[-1])
    height = trajectory.body[:, :, BODY_NAMES.index("height")]
    assert np.max(np.abs(height)) < 0.05  # the altitude hold keeps the height through the encounter
    quaternion = trajectory.body[:, :, 2:6]
    np.testing.assert_allclose(np.linalg.norm(quaternion, axis=-1), 1.0, atol=1e-12)
    written = contents(trajectory).data
    dims, values, attrs = written["height"]
    assert dims == ("agent", "time") and attrs["units"] == "m"  # a CF trajectory per agent
    np.testing.assert_array_equal(values, height.T)
    assert written["rotor_1"][2]["units"] == "rad s-1"


def test_an_agent_added_back_starts_again_with_its_body():
    """An agent added back starts from its entry's body state and state, exactly: they are copied."""
    commands = [{"time": 3.0, "action": "remove", "agent": 1}, {"time": 5.0, "action": "add", "agent": 1}]
    trajectory = tmem.simulate(two_agents(2, commands=commands))
    added = int(np.argmin(np.abs(trajectory.time - 5.0)))
    np.testing.assert_array_equal(trajectory.body[added, 1], trajectory.body[0, 1])
    np.testing.assert_array_equal(trajectory.state[added, 1], trajectory.state[0, 1])
    removed = (trajectory.time > 3.0) & (trajectory.time < 5.0)
    assert np.all(trajectory.body[removed, 1] == trajectory.body[np.flatnonzero(removed)[0], 1])  # not stepped


@pytest.mark.interface
def test_the_continuous_reference_refuses_the_quadrotor_in_one_line():
    from tmem.analysis.reference import integrate

    with pytest.raises(ValueError, match=r"^model\.kind: .*body state") as refused:
        integrate(from_dict({"model": {"kind": "quadrotor"}, "interaction": {"function": "repulsion"},
                             "agents": [{"position": 50.0}, {"position": 0.0}]}))  # fmt: skip
    assert "\n" not in str(refused.value)


@pytest.mark.slow  # the same threaded quadrotor loop as tests/test_wind.py's gusts on threads, which run by default
def test_the_quadrotor_swarm_on_threads_is_the_serial_one(monkeypatch):
    """Threads give the serial loop's bits (the product's claim), on the quadrotor in calm air.  The
    default run checks it in a turbulent wind (tests/test_wind.py), on one and on two threads."""
    from tmem.engine import driver

    gas = from_dict({
        "model": {"kind": "quadrotor"}, "interaction": {"function": "repulsion"},
        "space": {"axes": 2, "periodic": True, "box": [200.0, 200.0]},
        "swarm": {"n": 40, "seed": 3, "speed_rms": 3.0}, "neighbors": {"method": "verlet"},
        "simulation": {"dt": 0.01, "duration": 2.0, "record_every": 20},
    })  # fmt: skip
    serial = tmem.simulate(gas)
    monkeypatch.setattr(driver, "THREADED_SWARM", 0)
    threaded = tmem.simulate(gas)
    np.testing.assert_array_equal(threaded.state, serial.state)
    np.testing.assert_array_equal(threaded.body, serial.body)
    assert np.ptp(serial.body[:, :, BODY_NAMES.index("rotor_1")]) > 0.0  # the rotors worked
