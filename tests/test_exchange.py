"""`tmem export`: the MCAP file of Foxglove messages and the Crazyswarm2-style CSV files, read back with
independent readers (the mcap reader with schemas decoded from the file, Python's csv, SciPy's rotations)
and compared with the run; the command's refusals and its atomic writes."""

import csv
import importlib
import pkgutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app
from tmem.files.exchange import export
from tmem.files.exchange.attitude import attitude_quaternion
from tmem.files.io import write_netcdf, write_run
from tmem.scenario import with_changes

EXAMPLES = Path(__file__).parent.parent / "examples"

TRIANGLE = """
name = "triangle"
[space]
axes = 2
[interaction]
function = "improved"
[formation]
kind = "triangle"
velocity = [3.0, 0.0]
jitter = 1.0
seed = 1
[simulation]
dt = 0.001
duration = 4.0
record_every = 20
[[commands]]
time = 2.0
action = "uncouple"
"""


@pytest.fixture(scope="module")
def triangle(tmp_path_factory):
    """A 2-D formation run written by ``write_run`` (as ``tmem run`` writes it), and its trajectory."""
    trajectory = tmem.simulate(tmem.loads(TRIANGLE))
    out = tmp_path_factory.mktemp("export") / "triangle"
    write_run(trajectory, out)
    return out, trajectory


@pytest.fixture(scope="module")
def gas3d(tmp_path_factory):
    """A short 3-D gas of 8 agents, only some recorded (agents 5, 0 and 3): its trajectory.nc alone."""
    changes = {"simulation.duration": 0.5, "swarm.n": 8, "simulation.record_agents": [5, 0, 3]}
    trajectory = tmem.simulate(with_changes(tmem.load(EXAMPLES / "swarm" / "gas3d.toml"), changes))
    out = tmp_path_factory.mktemp("export") / "gas3d"
    out.mkdir()
    write_netcdf(trajectory, out / "trajectory.nc")
    return out, trajectory


# ----------------------------------------------------------------------------------------------
# The attitude


def _tilts_attitude(phi_x, phi_y):
    """SciPy's rotation with yaw 0, pitch phi_x and the roll whose thrust axis has the tilt phi_y,
    ``atan2(b_3y, b_3z)``, as ``(qw, qx, qy, qz)``."""
    roll = -np.arctan(np.tan(phi_y) * np.cos(phi_x))
    euler = np.stack([np.zeros_like(phi_x), phi_x, roll], axis=-1)
    return Rotation.from_euler("ZYX", euler).as_quat()[..., [3, 0, 1, 2]]  # SciPy writes (x, y, z, w)


def test_the_attitude_has_the_tilts_the_quadrotor_reads_and_no_yaw():
    """The tilts defined as in docs/vehicles.md, atan2(b_3a, b_3z) of the thrust axis, read back from
    SciPy's rotation of e_z; yaw 0; the same quaternion as the quadrotor's own start from tilts."""
    from tmem.vehicles.quadrotor import attitude_of_tilts

    phi_x = np.array([0.0, 0.1, -0.3, 0.0, 0.7, 0.05, 0.4])
    phi_y = np.array([0.0, 0.0, 0.2, -0.4, 0.0, 0.05, -0.6])
    q = attitude_quaternion(phi_x, phi_y)
    assert np.all(q[:, 0] > 0)
    rotation = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    thrust = rotation.apply([0.0, 0.0, 1.0])
    np.testing.assert_allclose(np.arctan2(thrust[:, 0], thrust[:, 2]), phi_x, atol=1e-15)
    np.testing.assert_allclose(np.arctan2(thrust[:, 1], thrust[:, 2]), phi_y, atol=1e-15)
    np.testing.assert_allclose(rotation.as_euler("ZYX")[:, 0], 0.0, atol=1e-15)
    quadrotor = np.array([attitude_of_tilts(x, y) for x, y in zip(phi_x, phi_y)])[:, [3, 0, 1, 2]]
    np.testing.assert_allclose(q, quadrotor, atol=1e-15)


@pytest.fixture(scope="module")
def quadrotor_run(tmp_path_factory):
    """The triangle flown by quadrotors (they record their body attitude), written as ``tmem run`` does."""
    text = TRIANGLE.replace("[space]", '[model]\nkind = "quadrotor"\n[space]')
    trajectory = tmem.simulate(tmem.loads(text))
    out = tmp_path_factory.mktemp("export") / "quadrotor"
    write_run(trajectory, out)
    return out, trajectory


def _recorded_attitude(trajectory, k):
    """Agent ``k``'s quaternion as the run recorded it, ``(qw, qx, qy, qz)`` with qw > 0."""
    from tmem.vehicles.quadrotor import BODY_NAMES

    q = trajectory.body[:, k][:, [BODY_NAMES.index(n) for n in ("q_w", "q_x", "q_y", "q_z")]]
    return q * np.sign(q[:, :1]) / np.linalg.norm(q, axis=1, keepdims=True)


def test_a_quadrotor_exports_the_attitude_it_recorded(quadrotor_run, tmp_path):
    """CSV and MCAP carry the recorded body quaternion, not one rebuilt from the tilts (which leaves out
    the body's yaw and any difference in how the tilts were taken)."""
    run_dir, trajectory = quadrotor_run
    out = export(run_dir, "csv", tmp_path / "csv")
    _, messages, = _read_mcap(export(run_dir, "mcap", tmp_path / "run.mcap"))[1:]
    for k in range(3):
        recorded = _recorded_attitude(trajectory, k)
        _, table = _read_csv(out / f"agent{k + 1}.csv")
        np.testing.assert_allclose(table[:, 4:], recorded, atol=1e-15)
        turns = [next(e for e in scene.entities if e.id == f"agent{k + 1}").spheres[0].pose.orientation
                 for _, scene in messages["/swarm"]]  # fmt: skip
        np.testing.assert_allclose([[o.w, o.x, o.y, o.z] for o in turns], recorded, atol=1e-15)
    # What was exported before: the tilts' attitude, off the recorded one by more than rounding.
    tilts = trajectory.state[:, 0, :, 2]
    assert np.abs(_tilts_attitude(tilts[:, 0], tilts[:, 1]) - _recorded_attitude(trajectory, 0)).max() > 1e-6


# ----------------------------------------------------------------------------------------------
# MCAP


def _foxglove_schemas() -> dict:
    """Foxglove's published message schemas, from its own package: full name -> the file defining it."""
    import foxglove_schemas_protobuf

    files = {}
    for module in pkgutil.iter_modules(foxglove_schemas_protobuf.__path__):
        if module.name.endswith("_pb2"):
            descriptor = importlib.import_module(f"foxglove_schemas_protobuf.{module.name}").DESCRIPTOR
            files.update({m.full_name: descriptor for m in descriptor.message_types_by_name.values()})
    return files


def _read_mcap(path: Path):
    """The file's header, channels (topic -> schema) and decoded messages, with classes built from the file's schemas."""
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory

    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        channels = {c.topic: summary.schemas[c.schema_id] for c in summary.channels.values()}
        messages = {}
        for _, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            messages.setdefault(channel.topic, []).append((message.log_time, decoded))
        return reader.get_header(), channels, messages


def test_every_channel_is_a_published_foxglove_schema(triangle, tmp_path):
    from google.protobuf import descriptor_pb2

    out = export(triangle[0], "mcap", tmp_path / "run.mcap")
    _, channels, _ = _read_mcap(out)
    published = _foxglove_schemas()
    assert len(published) > 30  # the package's whole set, not a list typed here
    names = {topic: schema.name for topic, schema in channels.items()}
    assert names["/swarm"] == "foxglove.SceneUpdate" and names["/metrics/rms_velocity"] == "foxglove.Vector2"
    for topic, schema in channels.items():
        assert schema.name in published and schema.encoding == "protobuf", topic
        # The schema's text is the package's own: the file that defines the message, as Foxglove ships it.
        shipped = descriptor_pb2.FileDescriptorProto()
        published[schema.name].CopyToProto(shipped)
        carried = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
        assert shipped in list(carried.file), topic


def test_mcap_positions_times_and_plots_are_the_runs(triangle, tmp_path):
    run_dir, trajectory = triangle
    header, channels, messages = _read_mcap(export(run_dir, "mcap", tmp_path / "run.mcap"))
    assert "written by tmem export" in header.library
    stamps = [round(t * 1e9) for t in trajectory.time]
    scenes = messages["/swarm"]
    assert [stamp for stamp, _ in scenes] == stamps
    radius = trajectory.scenario.interaction.radius
    for r, (_, scene) in enumerate(scenes):
        agents = {e.id: e for e in scene.entities if e.id != "formation"}
        assert list(agents) == ["agent1", "agent2", "agent3"]
        for k, entity in enumerate(agents.values()):
            body, reach = entity.spheres
            p = body.pose.position
            assert [p.x, p.y, p.z] == [*trajectory.state[r, k, :, 0], 0.0]
            assert reach.size.x == 2 * radius and entity.frame_id == "world"
        coupled = next(e for e in scene.entities if e.id == "formation").lines
        drawn = [len(line.points) // 2 for line in coupled if line.color.a == 1.0]
        assert sum(drawn) == int(trajectory.flag[r].sum())
    rms = [point.y for _, point in messages["/metrics/rms_velocity"]]
    np.testing.assert_array_equal(rms, tmem.analysis.metrics.rms_velocity(trajectory.state[..., 1], trajectory.active))
    for p, (i, j) in enumerate(trajectory.pairs.tolist()):
        points = messages[f"/pairs/agent{i + 1}-agent{j + 1}/distance"]
        assert [stamp for stamp, _ in points] == stamps
        np.testing.assert_array_equal([point.y for _, point in points], trajectory.pair_distance[:, p])
        np.testing.assert_array_equal([point.x for _, point in points], trajectory.time)


def test_mcap_of_a_3d_run_with_some_agents_recorded(gas3d, tmp_path):
    run_dir, trajectory = gas3d
    _, channels, messages = _read_mcap(export(run_dir, "mcap", tmp_path / "gas.mcap"))
    order = np.argsort(trajectory.agents)
    for r, (_, scene) in enumerate(messages["/swarm"]):
        agents = [e for e in scene.entities if e.id != "formation"]
        assert [e.id for e in agents] == ["agent1", "agent4", "agent6"]
        got = [[e.spheres[0].pose.position.x, e.spheres[0].pose.position.y, e.spheres[0].pose.position.z] for e in agents]
        np.testing.assert_array_equal(got, trajectory.state[r][order][..., 0])
        # Of the 28 pairs tracked (a swarm this small tracks all), the lines join the recorded agents only.
        lines = next(e for e in scene.entities if e.id == "formation").lines
        assert sum(len(line.points) for line in lines) == 2 * 3
    assert len(trajectory.pairs) == 28 and len([t for t in channels if t.startswith("/pairs/")]) == 28


# ----------------------------------------------------------------------------------------------
# CSV


def _read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array(rows[1:], dtype=float)


def test_csv_files_hold_positions_and_attitudes_numbered_from_1(triangle, tmp_path):
    run_dir, trajectory = triangle
    out = export(run_dir, "csv", tmp_path / "csv")
    assert sorted(p.name for p in out.iterdir()) == [".tmem-output.json", "agent1.csv", "agent2.csv", "agent3.csv"]
    for k in range(3):
        header, table = _read_csv(out / f"agent{k + 1}.csv")
        assert header == ["timestamp", "x", "y", "z", "qw", "qx", "qy", "qz"]
        np.testing.assert_array_equal(table[:, 0], trajectory.time)
        np.testing.assert_array_equal(table[:, 1:3], trajectory.state[:, k, :, 0])  # the text reads back exactly
        assert np.all(table[:, 3] == 0.0)  # a 2-D run flies in the plane z = 0
        tilts = trajectory.state[:, k, :, 2]
        np.testing.assert_allclose(table[:, 4:], _tilts_attitude(tilts[:, 0], tilts[:, 1]), atol=1e-15)
        assert np.abs(tilts).max() > 1e-3  # the tilts are not all zero: the comparison compares something


def test_csv_of_a_3d_run_names_each_file_by_the_agents_number(gas3d, tmp_path):
    run_dir, trajectory = gas3d
    out = export(run_dir, "csv", tmp_path / "csv")
    assert sorted(p.name for p in out.glob("*.csv")) == ["agent1.csv", "agent4.csv", "agent6.csv"]
    for k, agent in enumerate(trajectory.agents.tolist()):
        _, table = _read_csv(out / f"agent{agent + 1}.csv")
        np.testing.assert_array_equal(table[:, 1:4], trajectory.state[:, k, :, 0])


# ----------------------------------------------------------------------------------------------
# The command


def _tmem(*args: str):
    """The command run in-process (its refusals need no process of their own); exit code and stderr."""
    result = CliRunner().invoke(app, list(args))
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.stderr


def test_the_command_writes_beside_the_run_by_default_and_replaces_its_own(triangle, tmp_path):
    import shutil

    run_dir = tmp_path / "run"
    shutil.copytree(triangle[0], run_dir)
    for to, name in (("mcap", "run.mcap"), ("csv", "run-crazyswarm")):
        result = CliRunner().invoke(app, ["export", str(run_dir), "--to", to])
        assert result.exit_code == 0 and f"written {tmp_path / name}" in result.output, result.output
        again = CliRunner().invoke(app, ["export", str(run_dir), "--to", to])
        assert again.exit_code == 0, again.output


@pytest.mark.parametrize("args, message", [
    (["--to", "vtk"], "error: --to: must be one of mcap, csv, got 'vtk'"),
    (["--to", "csv"], "error: export: no trajectory.nc in {dir}; give a folder written by tmem run"),
])  # fmt: skip
def test_a_folder_that_is_not_a_run_is_refused_in_one_line(tmp_path, args, message):
    (tmp_path / "notes.txt").write_text("mine")
    code, stderr = _tmem("export", str(tmp_path), *args)
    assert code == 2 and stderr.strip() == message.format(dir=tmp_path), stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


def test_a_netcdf_file_that_is_not_a_runs_trajectory_is_refused(tmp_path):
    import xarray as xr

    xr.Dataset({"a": ("t", np.arange(3.0))}).to_netcdf(tmp_path / "trajectory.nc", engine="h5netcdf")
    code, stderr = _tmem("export", str(tmp_path), "--to", "mcap")
    assert code == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert "is not the trajectory of a tmem run" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trajectory.nc"]


def test_a_file_export_did_not_write_is_kept(triangle, tmp_path):
    mine = tmp_path / "mine.mcap"
    mine.write_bytes(b"not tmem's")
    result = CliRunner().invoke(app, ["export", str(triangle[0]), "--to", "mcap", "--out", str(mine)])
    assert result.exit_code == 2 and "exists and was not written by tmem export" in result.output
    assert mine.read_bytes() == b"not tmem's"


@pytest.mark.parametrize("to, module, writer", [("mcap", "foxglove", "write_mcap"), ("csv", "crazyswarm", "write_csv_files")])
def test_an_interrupted_export_leaves_nothing(triangle, tmp_path, monkeypatch, to, module, writer):
    """Ctrl-C halfway through writing: neither the output nor a temporary file is left."""
    target = importlib.import_module(f"tmem.files.exchange.{module}")
    real = getattr(target, writer)

    def interrupted(recording, where):
        real(recording, where)  # everything written under the temporary name...
        raise KeyboardInterrupt  # ...and then Ctrl-C

    monkeypatch.setattr(target, writer, interrupted)
    with pytest.raises(KeyboardInterrupt):
        export(triangle[0], to, tmp_path / "out" / "export")
    assert not (tmp_path / "out").exists()


def test_a_swarm_without_tracked_pairs_exports_its_agents(tmp_path):
    """40 agents under repulsion track no pair: the export has no pair channel and no formation."""
    changes = {"simulation.duration": 10.0, "swarm.n": 40}  # 101 records
    trajectory = tmem.simulate(with_changes(tmem.load(EXAMPLES / "swarm" / "gas2d.toml"), changes))
    assert trajectory.pairs.shape == (0, 2) and len(trajectory.time) == 101
    write_netcdf(trajectory, tmp_path / "trajectory.nc")
    _, channels, messages = _read_mcap(export(tmp_path, "mcap"))
    assert sorted(channels) == ["/metrics/rms_velocity", "/swarm"]
    assert [len(scene.entities) for _, scene in messages["/swarm"]] == [40] * 101
    _, table = _read_csv(export(tmp_path, "csv") / "agent40.csv")
    np.testing.assert_array_equal(table[:, 1:3], trajectory.state[:, 39, :, 0])


def test_a_run_that_recorded_no_agent_is_refused(tmp_path):
    changes = {"simulation.duration": 2.0, "simulation.dt": 0.001, "commands": [], "simulation.record_agents": []}
    write_netcdf(tmem.simulate(with_changes(tmem.preset("fig9"), changes)), tmp_path / "trajectory.nc")
    with pytest.raises(ValueError, match=r"^export: .*trajectory\.nc: the run recorded no agent \(simulation\.record_agents = \[\]\); nothing to export$"):
        export(tmp_path, "csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trajectory.nc"]
