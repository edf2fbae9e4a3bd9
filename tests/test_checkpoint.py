"""Checkpoints: a run stopped after a checkpoint and resumed ends with the same bits as one never stopped.

The reference is always the same scenario run from start to end without checkpoints.  In-process,
a run with checkpoints is stopped (an exception from its progress callback) right after a
checkpoint, and a new run resumes from the file; every array of the two trajectories must be equal
bit for bit, the product's claim (docs/checkpoints.md).  The real command is killed with SIGKILL after it wrote a checkpoint, run again, and
its files compared with an uninterrupted run's.  A checkpoint of another scenario or another tmem
is refused in one line.
"""

import dataclasses
import inspect
import json
import math
import signal
from pathlib import Path
from typing import NamedTuple

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app
from tmem.engine import checkpoint as ckpt
from tmem.engine import records
from tmem.engine.checkpoint import CheckpointError, Checkpoints, checkpoint_path
from tmem.engine.gas_counts import COMMON
from tmem.vehicles.quadrotor import BODY_NAMES
from tmem.scenario import from_dict, with_changes

from test_interruptions import Command, partials  # starts `python -m tmem`, waits for a moment

ROOT = Path(__file__).parent.parent


class Stop(Exception):
    """Raised by a progress callback to stop a run in-process."""


def stopped_after(scenario, path: Path, every: float, stop_time: float) -> ckpt.Saved:
    """Run ``scenario`` with checkpoints every ``every`` s into ``path`` and stop it just after the
    checkpoint at ``stop_time``; return the checkpoint."""
    stop_step = scenario.simulation.step_of(stop_time)

    def progress(done, total):
        if done >= stop_step:
            raise Stop

    with pytest.raises(Stop):
        tmem.simulate(scenario, progress=progress, checkpoints=Checkpoints(path, every))
    return Checkpoints(path, every).start(scenario)


def assert_same_bits(a: tmem.Trajectory, b: tmem.Trajectory) -> None:
    """Every array and number of two trajectories equal bit for bit, the events equal."""
    for f in dataclasses.fields(tmem.Trajectory):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes(), f.name
        elif isinstance(x, (int, float, list)):
            assert x == y or (isinstance(x, float) and math.isnan(x) and math.isnan(y)), f.name


def fig9():
    """The paper's Fig. 9 to t = 35 s: coupled at 3.2 s, the command at 29 s, uncoupled at 30.8 s."""
    return with_changes(tmem.load(ROOT / "examples/fig9.toml"), {"simulation.duration": 35.0})


def neighbour_lists():
    """500 agents in a periodic square, above the all-pairs limit: Verlet lists, rebuilt along the way."""
    side = np.sqrt(500 * np.pi * 40.0**2 / 6)
    return from_dict(
        {
            "interaction": {"function": "repulsion"},
            "space": {"axes": 2, "periodic": True, "box": [side, side]},
            "swarm": {"n": 500, "seed": 7, "speed_rms": 3.0},
            "simulation": {"dt": 0.01, "duration": 3.0, "record_every": 50},
        }
    )


def with_commands(example: str, duration: float, commands: list[dict]) -> tmem.Scenario:
    data = tmem.load(ROOT / "examples" / example).model_dump(mode="json", exclude_none=True)
    data["simulation"]["duration"] = duration
    return from_dict({**data, "commands": commands})


def gas_box():
    """examples/swarm/gas_box.toml to 4 s: walls, the thermostat, the mean of pushes; a temperature
    command at 1 s changes the thermostat's set-point before the checkpoint.  The gas is counted
    every 7 steps, so that the checkpoint at step 300 falls between two counts: the weights and the
    thermostat's group pushes of the count at step 294 are held across it."""
    scenario = with_commands("swarm/gas_box.toml", 4.0, [{"time": 1.0, "action": "temperature", "value": 3.0}])
    return with_changes(scenario, {"simulation.gas_period": 0.07})


def hex19():
    """examples/swarm/hex19.toml to 8 s; agent 3 is lost at 2 s and added back at 6 s (after the checkpoint)."""
    commands = [{"time": 2.0, "action": "remove", "agent": 3}, {"time": 6.0, "action": "add", "agent": 3}]
    return with_commands("swarm/hex19.toml", 8.0, commands)


def quadrotor_hex19():
    """examples/vehicles/hex19.toml to 4 s: the nonlinear quadrotors' body states (attitude, rotor
    speeds, height) are in flight at the checkpoint."""
    return with_changes(tmem.load(ROOT / "examples/vehicles/hex19.toml"), {"simulation.duration": 4.0})


def turbulent_quadrotor_hex19():
    """The quadrotor hex to 4 s in a wind with Dryden gusts: each agent's gust filters and the step of
    its stream are in its body state at the checkpoint."""
    wind = {"velocity": [2.0, 0.0], "turbulence": {"severity": "light", "seed": 1}}
    return with_changes(quadrotor_hex19(), {"wind": wind})


def sensed_fig9():
    """Fig. 9 to 12 s (no command) with noise, a random delay and lost messages: the ring of
    messages in flight and the held ones are saved, the counter-based draws go on from the step."""
    sensing = {"position_noise": 0.05, "velocity_noise": 0.02, "delay": [0.01, 0.05], "loss": 0.2, "seed": 3}
    data = tmem.load(ROOT / "examples/fig9.toml").model_dump(mode="json", exclude_none=True)
    data["simulation"]["duration"] = 12.0
    return from_dict({**data, "commands": [], "sensing": sensing})


# Each case: the scenario, the seconds between checkpoints, the checkpoint it stops after, and what
# it has in flight there that a field left out of the checkpoint would change.
CASES = {
    "fig9": (fig9, 10.0, 20.0, lambda saved, run: saved.arrays["pairs.flag"][0] == 1),  # coupled
    "neighbour lists": (neighbour_lists, 1.0, 2.0, lambda saved, run: 1 < saved.list_builds < run.list_builds),
    "gas box": (gas_box, 1.0, 3.0, lambda saved, run: saved.arrays["gas.target2"][0] == 9.0  # the command's, not 4
                and np.any(saved.arrays["gas.held"][:, COMMON:] != 0.0)),  # group pushes held
    "hex19": (hex19, 2.0, 4.0, lambda saved, run: saved.arrays["agents.active"].sum() == 18),  # agent 3 lost
    "quadrotor hex19": (quadrotor_hex19, 1.0, 2.0, lambda saved, run: np.any(saved.arrays["agents.body"] != saved.arrays["agents.body_start"])),
    "turbulent quadrotor hex19": (turbulent_quadrotor_hex19, 1.0, 2.0, lambda saved, run: np.all(saved.arrays["agents.body"][:, BODY_NAMES.index("gust_step")] > 0)),
    "sensed fig9": (sensed_fig9, 2.0, 6.0, lambda saved, run: np.any(saved.arrays["sensing.history"] != 0.0)),
}


@pytest.mark.parametrize("case", CASES)
def test_a_resumed_run_ends_with_the_same_bits(case, tmp_path):
    make, every, stop_time, in_flight = CASES[case]
    scenario = make()
    reference = tmem.simulate(scenario)
    path = tmp_path / "run.npz"
    saved = stopped_after(scenario, path, every, stop_time)
    assert saved.step == scenario.simulation.step_of(stop_time) and in_flight(saved, reference)
    resumed = tmem.simulate(scenario, checkpoints=Checkpoints(path, every))
    assert_same_bits(reference, resumed)
    assert resumed.events == reference.events


@pytest.mark.interface
def test_every_field_of_a_changing_record_is_saved_or_declared_rebuilt(tmp_path):
    """From the file itself: each field of each record a step changes is in it, or in REBUILT with a
    reason, never both; and every record of tmem.engine.records is either changing or fixed."""
    scenario = gas_box()
    path = tmp_path / "gas.npz"
    stopped_after(scenario, path, 1.0, 1.0)
    with np.load(path) as data:
        keys = set(data.files) - {"meta"}
    for name, record_type in ckpt.CHANGING.items():
        declared = ckpt.REBUILT.get(name, {})
        assert set(declared) <= set(record_type._fields), (name, set(declared) - set(record_type._fields))
        for f in record_type._fields:
            assert (f"{name}.{f}" in keys) != (f in declared), f"{name}.{f}: neither saved nor declared rebuilt, or both"
    assert keys == {f"{n}.{f}" for n in ckpt.CHANGING for f in ckpt.saved_fields(n)}
    defined = {v for v in vars(records).values() if inspect.isclass(v) and issubclass(v, tuple) and hasattr(v, "_fields")}
    defined = {v for v in defined if v.__module__ == records.__name__}
    assert defined <= set(ckpt.CHANGING.values()) | set(ckpt.FIXED_RECORDS), defined


@pytest.mark.interface
def test_a_field_that_is_not_an_array_must_be_declared():
    class Widened(NamedTuple):
        state: np.ndarray
        count: int

    state = {name: None for name in ckpt.CHANGING}
    original = ckpt.CHANGING["agents"]
    ckpt.CHANGING["agents"] = Widened
    try:
        state["agents"] = Widened(np.zeros(2), 3)
        with pytest.raises(TypeError, match="agents.count is not an array"):
            ckpt._arrays(state)
    finally:
        ckpt.CHANGING["agents"] = original


# --- the command


def run_cli(*args):
    return CliRunner().invoke(app, ["run", *map(str, args)])


def nc_variables(path: Path) -> dict:
    """Every variable's values (as bytes; strings, such as the agents' names, as the bytes they hold)
    and every attribute of a trajectory.nc."""
    found = {}
    with h5py.File(path, "r") as f:
        found["attrs"] = {k: np.asarray(v).tobytes() for k, v in f.attrs.items()}
        for name, variable in f.items():
            values = variable[()]
            held = b"\0".join(values.ravel().tolist()) if values.dtype.kind == "O" else values.tobytes()
            found[name] = (variable.dtype.str, variable.shape, held)
    return found


@pytest.fixture(scope="module")
def long_run(tmp_path_factory):
    """Fig. 9 to 120 s (1.2 million steps; coupled, uncoupled, then flying apart) as a file; its
    compiled loop loaded once."""
    scenario = tmp_path_factory.mktemp("long") / "long.toml"
    text = (ROOT / "examples/fig9.toml").read_text().replace("duration = 60.0", "duration = 120.0")
    scenario.write_text(text.replace("record_every = 100 ", "record_every = 1000 "))
    tmem.simulate(tmem.load(scenario), record=False)  # warms Numba's cache
    return scenario


def test_a_killed_run_goes_on_from_its_checkpoint_to_the_same_bits(long_run, tmp_path):
    """Killed after a checkpoint, then: a run without the option starts over (the reference) and leaves
    the checkpoint alone; the same command goes on from it, ends with the same files, removes it."""
    scenario = long_run
    out = tmp_path / "out"
    saved = checkpoint_path(out)
    command = Command("run", scenario, "--out", out, "--checkpoint-every", 20, cwd=tmp_path, terminal=False)
    reached = command.wait_for(saved.exists)
    if reached:
        command.send(signal.SIGKILL)
    code, output = command.finish()
    assert reached, f"the run ended before its first checkpoint: {output}"
    assert code == -signal.SIGKILL and saved.exists()
    before = saved.read_bytes()
    reference = tmp_path / "reference"
    plain = run_cli(scenario, "--out", reference)
    assert plain.exit_code == 0 and "checkpoint" not in plain.output, plain.output
    assert saved.read_bytes() == before and not checkpoint_path(reference).exists()
    result = run_cli(scenario, "--out", out, "--checkpoint-every", 20)
    assert result.exit_code == 0, result.output
    assert "going on from the checkpoint at t = " in result.stderr
    assert not saved.exists() and partials(tmp_path, "out") == []
    assert (out / "summary.json").read_bytes() == (reference / "summary.json").read_bytes()
    assert nc_variables(out / "trajectory.nc") == nc_variables(reference / "trajectory.nc")
    events = json.loads((out / "summary.json").read_text())["events"]
    assert events and events == json.loads((reference / "summary.json").read_text())["events"]


@pytest.fixture
def left_checkpoint(tmp_path):
    """A scenario file (Fig. 9 to 35 s), and the checkpoint a run of it into tmp_path/out left when
    stopped at 20 s."""
    scenario = tmp_path / "pair.toml"
    scenario.write_text((ROOT / "examples/fig9.toml").read_text().replace("duration = 60.0", "duration = 35.0"))
    out = tmp_path / "out"
    stopped_after(tmem.load(scenario), checkpoint_path(out), 10.0, 20.0)
    return scenario, out, checkpoint_path(out)


def one_line_refusal(result, *words) -> str:
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr, result.stderr
    for word in words:
        assert word in result.stderr, result.stderr
    return result.stderr


@pytest.mark.interface
def test_a_checkpoint_of_another_scenario_is_refused_and_kept(left_checkpoint):
    scenario, out, saved = left_checkpoint
    before = saved.read_bytes()
    scenario.write_text(scenario.read_text().replace("c_max = 0.1 ", "c_max = 0.12 "))
    one_line_refusal(run_cli(scenario, "--out", out, "--checkpoint-every", 10), str(saved), "another scenario")
    assert saved.read_bytes() == before and not out.exists()


@pytest.mark.interface
def test_a_checkpoint_of_another_tmem_is_refused(left_checkpoint):
    scenario, out, saved = left_checkpoint
    with np.load(saved) as data:
        arrays = dict(data)
    meta = json.loads(str(arrays["meta"]))
    meta["made_by"] = "tmem 0.0.1 (Numba 0.1, NumPy 1.0)"
    arrays["meta"] = np.array(json.dumps(meta))
    with open(saved, "wb") as f:
        np.savez(f, **arrays)
    one_line_refusal(run_cli(scenario, "--out", out, "--checkpoint-every", 10), "was written by tmem 0.0.1", "this is tmem ")
    assert saved.exists() and not out.exists()


@pytest.mark.interface
def test_a_file_that_is_not_a_checkpoint_is_refused_and_kept(tmp_path):
    scenario = tmp_path / "pair.toml"
    scenario.write_text((ROOT / "examples/fig9.toml").read_text().replace("duration = 60.0", "duration = 35.0"))
    notes = checkpoint_path(tmp_path / "out")
    notes.write_text("my notes\n")
    one_line_refusal(run_cli(scenario, "--out", tmp_path / "out", "--checkpoint-every", 10), "is not a tmem checkpoint")
    assert notes.read_text() == "my notes\n"


@pytest.mark.interface
def test_ctrl_c_keeps_the_checkpoint_and_says_where_the_command_goes_on(tmp_path, monkeypatch):
    """Ctrl-C arriving right after the checkpoint at 10 s (raised from its save, in-process)."""
    scenario = tmp_path / "pair.toml"
    scenario.write_text((ROOT / "examples/fig9.toml").read_text().replace("duration = 60.0", "duration = 35.0"))
    save = Checkpoints.save

    def save_then_interrupt(self, *args):
        save(self, *args)
        raise KeyboardInterrupt

    monkeypatch.setattr(Checkpoints, "save", save_then_interrupt)
    result = run_cli(scenario, "--out", tmp_path / "out", "--checkpoint-every", 10)
    assert result.exit_code == 130, result.output
    assert result.stderr == "interrupted; no output was written; the same command goes on from t = 10 s\n"
    assert checkpoint_path(tmp_path / "out").exists() and not (tmp_path / "out").exists()


@pytest.mark.interface
@pytest.mark.parametrize("every,why", [("0", "positive"), ("-5", "positive"), ("nan", "positive"), ("1e-5", "at least the time step")])
def test_bad_checkpoint_intervals_are_refused(tmp_path, every, why):
    scenario = tmp_path / "pair.toml"
    scenario.write_text((ROOT / "examples/fig9.toml").read_text())
    one_line_refusal(run_cli(scenario, "--out", tmp_path / "out", "--checkpoint-every", every), "--checkpoint-every", why)
    assert not (tmp_path / "out").exists() and not checkpoint_path(tmp_path / "out").exists()


@pytest.mark.interface
def test_the_python_interval_is_checked_too(tmp_path):
    with pytest.raises(CheckpointError, match="positive"):
        Checkpoints(tmp_path / "c.npz", float("inf"))
