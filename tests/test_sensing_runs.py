"""Sensed runs: the same bits on any number of threads and with either kind of neighbour list; the
sensed path without effects gives the exact path's bits; bad ``[sensing]`` tables are refused in one
line; the examples run.

The bit-equalities are the product's claims (docs/sensing.md): the draws are keyed by the message,
never by the order pairs are visited in; and the sensed path adds its effects and nothing else.
"""

from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np
import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app
from tmem.engine import driver, lists
from tmem.scenario import from_dict, with_changes

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "sensing"
#: Every effect at once; the range is required with lists.
EVERYTHING = {"seed": 3, "position_noise": 0.5, "velocity_noise": 0.2, "own_position_noise": 0.1,
              "own_velocity_noise": 0.05, "delay": [0.02, 0.05], "loss": 0.2, "hold": 0.1, "range": 45.0}  # fmt: skip


def swarm(method: str, sensing: dict | None, n: int = 200, steps: int = 300) -> tmem.Scenario:
    """A random 2-D swarm in a periodic box, one neighbour within reach on average, under repulsion."""
    side = float(np.sqrt(n * np.pi * 40.0**2 / 1))
    data = {"interaction": {"function": "repulsion"}, "space": {"axes": 2, "periodic": True, "box": [side, side]},
            "swarm": {"n": n, "seed": 7, "speed_rms": 3.0}, "neighbors": {"method": method, "skin": 2.0},
            "simulation": {"dt": 0.01, "duration": steps * 0.01, "record_every": 50}}  # fmt: skip
    return from_dict(data | ({"sensing": sensing} if sensing is not None else {}))


def test_lists_and_all_pairs_give_the_same_bits(monkeypatch):
    """Noise, random delays, loss and a range: the Verlet lists (over positions, rebuilt on the way)
    and every pair give the same bits (the claim, so bit for bit), with small blocks so that many
    pairs cross between them."""
    monkeypatch.setattr(lists, "BLOCK", 64)
    every = tmem.simulate(swarm("all", EVERYTHING))
    listed = tmem.simulate(swarm("verlet", EVERYTHING))
    assert listed.list_builds > 1
    assert every.final_state.tobytes() == listed.final_state.tobytes()
    assert every.min_neighbor_distance == listed.min_neighbor_distance < 40.0
    exact = tmem.simulate(swarm("verlet", None))
    assert np.abs(exact.final_state - listed.final_state).max() > 1e-3  # the effects act


def test_one_thread_two_threads_and_the_serial_loop_give_the_same_bits(monkeypatch):
    """Threads give the serial loop's bits (the product's claim), with every sensing effect on."""
    monkeypatch.setattr(lists, "BLOCK", 32)  # several blocks, summed on threads, and pairs between them
    monkeypatch.setattr(driver, "THREADED_SWARM", 100)
    scenario = swarm("verlet", EVERYTHING)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = tmem.simulate(scenario)
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = tmem.simulate(scenario)
    finally:
        numba.set_num_threads(threads)
    monkeypatch.setattr(driver, "THREADED_SWARM", 10**9)
    serial = tmem.simulate(scenario)
    assert one.final_state.tobytes() == two.final_state.tobytes() == serial.final_state.tobytes()


@pytest.mark.parametrize("case", ["fig9", "swarm"])
def test_the_sensed_path_without_effects_gives_the_exact_bits(case):
    """Each agent pushing from its own exact measurement gives the exact path's equal and opposite
    pushes to the bit: Fig. 9 (a formation pair, its events and its recorded |d|), and a swarm.  Bit
    for bit because it is the same arithmetic on the same numbers: the functions are odd to the bit
    (tests/test_interaction.py), so an agent's own push is the exact path's, and the sensed path
    claims to add its effects and nothing else."""
    scenario = (with_changes(tmem.preset("fig9"), {"simulation.dt": 0.01, "simulation.record_every": 10})
                if case == "fig9" else swarm("all", None))  # fmt: skip
    exact = tmem.simulate(scenario)
    sensed = tmem.simulate(scenario, sensing={})
    assert exact.state.tobytes() == sensed.state.tobytes()
    assert exact.final_state.tobytes() == sensed.final_state.tobytes()
    np.testing.assert_array_equal(exact.interaction_distance, sensed.interaction_distance)
    assert exact.events == sensed.events


def test_a_seed_chooses_the_draws():
    """The same seed gives the same bits (a run is reproducible: the claim of tmem.world.streams);
    another seed, another run."""
    fig9 = with_changes(tmem.preset("fig9"), {"simulation.dt": 0.01, "simulation.duration": 5.0, "commands": []})
    run = lambda seed: tmem.simulate(with_changes(fig9, {"sensing": {"seed": seed, "position_noise": 0.3}}))  # noqa: E731
    assert run(1).final_state.tobytes() == run(1).final_state.tobytes()
    assert run(1).final_state.tobytes() != run(2).final_state.tobytes()


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return f'"{value}"' if isinstance(value, str) else repr(value)


FIG9 = tmem.preset("fig9").to_toml()
SWARM_100 = '[space]\naxes = 2\nbox = [800.0, 800.0]\n[interaction]\nfunction = "repulsion"\n[swarm]\nn = 100\n'
BAD = {
    "loss 1": (FIG9, {"loss": 1.0}, "sensing.loss"),
    "loss negative": (FIG9, {"loss": -0.1}, "sensing.loss"),
    "delay negative": (FIG9, {"delay": -1.0}, "sensing.delay"),
    "delay nan": (FIG9, {"delay": math.nan}, "sensing.delay"),
    "delay max below min": (FIG9, {"delay": [0.2, 0.1]}, "sensing.delay"),
    "delay list of one": (FIG9, {"delay": [0.1]}, "sensing.delay"),
    "delay text": (FIG9, {"delay": "0.1"}, "sensing.delay"),
    "delay true": (FIG9, {"delay": True}, "sensing.delay"),
    "noise negative": (FIG9, {"position_noise": -1.0}, "sensing.position_noise"),
    "noise inf": (FIG9, {"own_velocity_noise": math.inf}, "sensing.own_velocity_noise"),
    "range zero": (FIG9, {"range": 0.0}, "sensing.range"),
    "hold zero": (FIG9, {"hold": 0.0}, "sensing.hold"),
    "period not whole steps": (FIG9, {"period": 0.00015}, "sensing.period"),
    "seed negative": (FIG9, {"seed": -1}, "sensing.seed"),
    "unknown key": (FIG9, {"colour": 1.0}, "sensing.colour"),
    "delay too long for memory": (FIG9, {"delay": 1e6}, "sensing.delay"),
    "hold too long for memory": (FIG9, {"loss": 0.5, "hold": 1e6}, "sensing.hold"),
    "lists without a range": (SWARM_100, {"position_noise": 0.1}, "sensing.range"),
    "with a thermostat": (FIG9 + "[thermostat]\nrms_velocity = 2.0\n", {"loss": 0.1}, "sensing"),
}


@pytest.mark.interface
@pytest.mark.parametrize("name", BAD, ids=list(BAD))
def test_a_bad_sensing_table_is_refused_in_one_line(name, tmp_path):
    base, table, field = BAD[name]
    text = base + "[sensing]\n" + "".join(f"{key} = {_toml(value)}\n" for key, value in table.items())
    (tmp_path / "bad.toml").write_text(text)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["run", str(tmp_path / "bad.toml"), "--out", str(out)])
    assert result.exit_code == 2, result.output[-2000:]
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and f": {field}: " in lines[0], result.output[-2000:]
    assert "Traceback" not in result.output and not out.exists()


@pytest.mark.interface
def test_the_sensing_table_is_not_a_table():
    with pytest.raises(tmem.ScenarioError, match="sensing: must be a table"):
        tmem.loads("sensing = 3\n" + FIG9)  # a key before the first table is the scenario's


@pytest.mark.interface
def test_what_the_sensed_path_cannot_do_is_refused_in_one_line():
    """Through the Python API too: the gas's stages, and lists without a range; and the batch."""
    gas = with_changes(swarm("all", None), {"simulation.observe_gas": True})
    with pytest.raises(ValueError, match="^sensing: the gas's stages read exact states"):
        tmem.simulate(gas, sensing={})
    with pytest.raises(ValueError, match="^sensing.range: is required"):
        tmem.simulate(swarm("verlet", None), sensing={})
    from tmem.batch.encounters import run_batch

    noisy = with_changes(tmem.preset("fig7"), {"sensing": {"position_noise": 0.1}})
    with pytest.raises(ValueError, match="^run_batch: the agents measure each other exactly"):
        run_batch(noisy, np.zeros((1, 2)), np.zeros((1, 2)))


@pytest.mark.interface
@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_sensing_examples_run(path):
    scenario = tmem.load(path)
    assert scenario.sensing is not None and not scenario.sensing.exact
    short = with_changes(scenario, {"simulation.duration": 5.0, "commands": []})
    tr = tmem.simulate(short)
    assert np.all(np.isfinite(tr.final_state))
