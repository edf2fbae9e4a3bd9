"""Animation of a run on one axis, in the plane and in space, from small synthetic ``trajectory.nc`` files."""

import subprocess
import sys

import matplotlib.animation
import numpy as np
import pytest
import xarray as xr
from PIL import Image, ImageChops

from tmem.figures.animate import animate
from tmem.figures.animate.frames import read_frames
from tmem.figures.animate.scene import positions, scene, update
from tmem.files.trajectory_file import FRAME_AXES, OVER_AGENTS, OVER_PAIRS, TIME_UNITS

SCENARIO = 'name = "synthetic"\n\n[interaction]\nradius = 20.0\nd_t = 35.0\n'


def _dataset(n_times=30, n_axes=2, agents=(0, 1, 2), pairs=((0, 1),), active=True, d_t=True):
    """Agents on straight lines, the pairs coupling halfway, the last agent removed at two thirds.

    Laid out as ``trajectory.nc`` is (:mod:`tmem.files.trajectory_file`): per agent over (agent, time),
    the positions as the coordinates x, y, z (a 1-D run with y = 0), a variable per axis.
    """
    n = len(agents)
    time = 0.5 * np.arange(n_times)
    start = np.array([[0.0, 0.0, 0.0], [80.0, 10.0, 0.0], [40.0, -50.0, 0.0]] * n)[:n, :n_axes]
    velocity = np.array([[2.0, 0.5, 0.0], [-2.0, 0.0, 0.0], [0.0, 1.0, 0.0]] * n)[:n, :n_axes]
    P = start[:, None, :] + time[None, :, None] * velocity[:, None, :]  # (agent, time, axis)
    pairs = np.array(pairs, dtype=int).reshape(-1, 2)
    flag = np.zeros((len(pairs), n_times), np.int8)
    flag[:, n_times // 2 :] = 1
    data = {f"{name}_{axis}": (OVER_AGENTS, np.zeros((n, n_times))) for name in ("V", "U") for axis in FRAME_AXES[:n_axes]}
    data["F_en"] = (OVER_PAIRS, flag)
    if active:
        alive = np.ones((n, n_times), np.int8)
        alive[n - 1, 2 * n_times // 3 :] = 0
        data["active"] = (OVER_AGENTS, alive)
    if d_t:
        data["d_t"] = ("pair", np.full(len(pairs), 35.0))
    coords = {
        "time": ("time", time, {"units": TIME_UNITS}),
        "agent": np.asarray(agents),
        "pair": np.arange(len(pairs)),
        "pair_i": ("pair", pairs[:, 0]),
        "pair_j": ("pair", pairs[:, 1]),
    }
    for a, axis in enumerate(FRAME_AXES[: max(n_axes, 2)]):
        coords[axis] = (OVER_AGENTS, P[..., a]) if a < n_axes else ((), 0.0)
    return xr.Dataset(data, coords=coords, attrs={"scenario": SCENARIO})


def _write(tmp_path, **kwargs):
    _dataset(**kwargs).to_netcdf(tmp_path / "trajectory.nc", engine="h5netcdf")
    return tmp_path


def _frames(path):
    with Image.open(path) as gif:
        frames = []
        for k in range(gif.n_frames):
            gif.seek(k)
            frames.append(gif.convert("RGB"))
        return frames


@pytest.mark.parametrize("max_frames, expected", [(400, 30), (7, 7)])
def test_gif_has_one_frame_per_time_up_to_max_frames(tmp_path, max_frames, expected):
    run = _write(tmp_path)
    out = animate(run, max_frames=max_frames, dpi=40)
    assert out == run.parent / f"{run.name}.gif"  # beside the run directory, never in it
    frames = _frames(out)
    assert len(frames) == expected
    assert ImageChops.difference(frames[0], frames[-1]).getbbox() is not None


def test_gas_without_pairs_active_or_d_t(tmp_path):
    run = _write(tmp_path, pairs=(), active=False, d_t=False)
    out = animate(run, out=tmp_path / "sub" / "gas.gif", max_frames=5, dpi=40)
    assert len(_frames(out)) == 5


def test_recorded_subset_maps_pairs_by_agent_index(tmp_path):
    # Agents 7, 3, 5 recorded; the pair with agent 9 (not recorded) is left out.
    run = _write(tmp_path, agents=(7, 3, 5), pairs=((3, 7), (5, 9), (7, 5)))
    drawn = read_frames(run, max_frames=10)
    assert drawn.col_i.tolist() == [1, 0] and drawn.col_j.tolist() == [0, 2]
    assert drawn.flag.shape == (10, 2)
    assert drawn.d_t.tolist() == [35.0, 35.0]
    assert not drawn.active[-1, 2] and drawn.active[0].all()
    assert len(_frames(animate(run, max_frames=10, dpi=40))) == 10


def test_a_run_on_one_axis_is_drawn_on_the_line(tmp_path):
    """The paper's runs fly on one axis: each frame puts the agents at (x, 0), x as the file holds it."""
    ds = _dataset(n_axes=1)
    run = _write(tmp_path, n_axes=1)
    frames = read_frames(run, max_frames=400)
    shown, cross = positions(frames)
    fig, moving = scene(frames, shown, dpi=40)
    assert [ax.name for ax in fig.axes].count("3d") == 0 and list(fig.axes[0].get_yticks()) == []
    for f in (0, 17, 29):
        update(moving, frames, f, shown, cross, True)
        flying = ds["active"].values[:, f] == 1
        expected = np.stack([ds["x"].values[:, f], np.zeros(3)], axis=-1)[flying]
        np.testing.assert_array_equal(moving["dots"].get_offsets()[flying], expected)
    assert len(_frames(animate(run, max_frames=10, dpi=40))) == 10


def test_the_paper_s_run_can_be_animated_from_the_command_line(tmp_path):
    """Fig. 9 (6 s of it) written as tmem run writes it, animated by the command."""
    from typer.testing import CliRunner

    import tmem
    from tmem.cli.main import app
    from tmem.files.io import write_run
    from tmem.scenario import with_changes

    scenario = with_changes(tmem.preset("fig9"), {"simulation.duration": 6.0, "simulation.dt": 0.001, "commands": []})
    write_run(tmem.simulate(scenario), tmp_path / "fig9")
    result = CliRunner().invoke(app, ["animate", str(tmp_path / "fig9"), "--max-frames", "8"])
    assert result.exit_code == 0, result.output
    assert len(_frames(tmp_path / "fig9.gif")) == 8  # beside the run, as every derived file


def test_3d_run_is_drawn_in_3d_beside_its_projection(tmp_path):
    run = _write(tmp_path, n_axes=3)
    frames = read_frames(run, max_frames=10)
    shown, cross = positions(frames)
    fig, moving = scene(frames, shown, dpi=40)
    assert [ax.name for ax in fig.axes].count("3d") == 1
    assert any(ax.get_title() == "projection on (x, y)" for ax in fig.axes)
    update(moving, frames, 9, shown, cross, True)
    flying = frames.active[9]
    np.testing.assert_allclose(moving["space dots"].get_offsets()[flying], frames.pos[9, flying, :2])
    assert len(moving["space coupled"].get_array()) == 1  # the pair, coupled from the middle on
    assert len(_frames(animate(run, max_frames=10, dpi=40))) == 10


def test_agents_are_numbered_from_one_as_in_the_paper(tmp_path):
    frames = read_frames(_write(tmp_path, agents=(7, 3, 5), pairs=((3, 7),)), max_frames=5)
    fig, _ = scene(frames, positions(frames)[0], dpi=40)
    assert sorted(t.get_text() for t in fig.axes[0].texts if t.get_text().isdigit()) == ["4", "6", "8"]


def test_strain_scale_is_fitted_to_the_coupled_pairs_drawn(tmp_path):
    ds = _dataset()
    run = _write(tmp_path)
    frames = read_frames(run, max_frames=400)
    _, moving = scene(frames, positions(frames)[0], dpi=40)
    P = np.stack([ds["x"].values, ds["y"].values], axis=-1)  # (agent, time, axis)
    coupled = ds["F_en"].values[0] == 1
    strain = np.linalg.norm(P[1, coupled] - P[0, coupled], axis=1) / 35.0 - 1
    assert moving["coupled"].norm.vmax == pytest.approx(np.abs(strain).max(), rel=1e-12)
    assert moving["coupled"].norm.vmin == -moving["coupled"].norm.vmax


def test_missing_trajectory(tmp_path):
    with pytest.raises(ValueError, match="animate: no trajectory.nc in"):
        animate(tmp_path)


def test_missing_folder_is_called_missing(tmp_path):
    """Not "no trajectory.nc in ...": the folder itself is not there."""
    with pytest.raises(ValueError) as error:
        animate(tmp_path / "nowhere")
    assert str(error.value) == f"animate: {tmp_path / 'nowhere'}: no such folder"


def _truncated(data: bytes) -> bytes:
    return data[: len(data) // 2]


def _header_flipped(data: bytes) -> bytes:
    """The version byte of the last object header (a variable's) flipped: h5py raised KeyError."""
    at = data.rindex(b"OHDR") + 4
    return data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1 :]


def _superblock_flipped(data: bytes) -> bytes:
    return bytes([data[0] ^ 0x01]) + data[1:]


@pytest.mark.parametrize("damage", [_truncated, _header_flipped, _superblock_flipped], ids=lambda f: f.__name__[1:])
def test_damaged_trajectory_is_refused_naming_the_file(tmp_path, damage):
    path = _write(tmp_path) / "trajectory.nc"
    path.write_bytes(damage(path.read_bytes()))
    with pytest.raises(ValueError) as error:
        animate(tmp_path, max_frames=3)
    message = str(error.value)
    assert message.startswith(f"animate: {path}: cannot be read as a run's trajectory (") and "\n" not in message
    assert not (tmp_path.parent / f"{tmp_path.name}.gif").exists()


def test_damaged_trajectory_gives_one_line_and_exit_2_from_the_command(tmp_path):
    """The real command: no traceback, and no "Exception ignored" from the half-opened file."""
    path = _write(tmp_path) / "trajectory.nc"
    path.write_bytes(_header_flipped(path.read_bytes()))
    proc = subprocess.run(
        [sys.executable, "-c", "from tmem.cli.main import main; main()", "animate", str(tmp_path)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "trajectory.nc: cannot be read" in lines[0], proc.stderr
    assert proc.stdout == "" and sorted(p.name for p in tmp_path.iterdir()) == ["trajectory.nc"]


@pytest.mark.parametrize("name", ["$x^$", "$\\frac{", "[/bold] oops"])
def test_a_name_is_drawn_as_written(tmp_path, name, monkeypatch):
    """Mathtext in the scenario's name is text in the title, not a formula that fails to parse."""
    import json

    monkeypatch.setattr(sys.modules[__name__], "SCENARIO", f"name = {json.dumps(name)}\n" + SCENARIO.split("\n", 1)[1])
    out = animate(_write(tmp_path), max_frames=2)
    assert out.is_file()


def test_mp4_without_ffmpeg(tmp_path, monkeypatch):
    monkeypatch.setattr(matplotlib.animation.writers, "is_available", lambda name: False)
    run = _write(tmp_path)
    with pytest.raises(ValueError) as error:
        animate(run, out=tmp_path / "run.mp4")
    assert str(error.value) == "animate: writing MP4 needs ffmpeg; write a .gif instead"


@pytest.mark.skipif(not matplotlib.animation.writers.is_available("ffmpeg"), reason="ffmpeg not installed")
def test_mp4_with_ffmpeg(tmp_path):
    out = animate(_write(tmp_path), out=tmp_path / "run.mp4", max_frames=10, dpi=40)
    assert out.stat().st_size > 0


def test_unknown_format(tmp_path):
    with pytest.raises(ValueError, match="name a .gif or .mp4 file"):
        animate(_write(tmp_path), out=tmp_path / "run.png")
