"""The run's figures, read through their matplotlib artists and checked against ``trajectory.nc`` read
independently with xarray: every agent and pair drawn (or a note saying which), agents numbered from
1, the paths and the shape, the strain colour scale fitted to the run, 3-D runs, and the figures of
a run read back from its files equal to those drawn at its end."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.collections import LineCollection, PathCollection

import tmem
from tmem.figures import drawing
from tmem.files.io import write_run
from tmem.figures.plot import figures_of
from tmem.files.saved import read_run
from tmem.scenario import load, with_changes
from tmem.figures.shape_plot import moments

EXAMPLES = Path(__file__).parent.parent / "examples"
SHORT = {"simulation.duration": 3.0, "simulation.record_every": 1000}  # 31 records


@pytest.fixture(scope="module")
def hex19(tmp_path_factory):
    """examples/swarm/hex19.toml, 3 s of it: its trajectory, its run directory and its file opened with xarray
    (every variable with time first; the file keeps one row per agent or pair, CF trajectories)."""
    trajectory = tmem.simulate(with_changes(load(EXAMPLES / "swarm" / "hex19.toml"), SHORT))
    out = tmp_path_factory.mktemp("hex19") / "run"
    write_run(trajectory, out)
    with xr.open_dataset(out / "trajectory.nc", engine="h5netcdf", decode_times=False) as ds:
        yield trajectory, out, ds.load().transpose("time", ...)


@pytest.fixture(scope="module")
def triangle_3d(tmp_path_factory):
    """The triangle in space, climbing, one pair uncoupled by command at 1 s."""
    changes = {**SHORT, "space.axes": 3, "formation.velocity": [3.0, 0.0, 0.5],
               "commands": [{"time": 1.0, "action": "uncouple", "pair": [0, 1]}]}  # fmt: skip
    trajectory = tmem.simulate(with_changes(load(EXAMPLES / "swarm" / "triangle.toml"), changes))
    out = tmp_path_factory.mktemp("triangle3d") / "run"
    write_run(trajectory, out)
    return trajectory, out


def labelled(ax, prefix: str) -> dict[str, object]:
    """The lines of ``ax`` whose label starts with ``prefix``, by label."""
    return {line.get_label(): line for line in ax.get_lines() if line.get_label().startswith(prefix)}


def per_axis(ds, *names: str) -> np.ndarray:
    """The variables ``names`` (one per axis: ``x``, ``y``; ``V_x``, ``V_y``), stacked as (time, agent, axis)."""
    return np.stack([ds[name].transpose("time", ...).values for name in names], axis=-1)


def agent_names(ds) -> set[str]:
    return {f"agent {a + 1}" for a in ds["agent"].values}


def test_hex19_has_the_figures_of_a_formation(hex19):
    trajectory, out, _ = hex19
    assert list(figures_of(trajectory)) == ["velocity.png", "distance.png", "formation.png", "paths.png", "shape.png"]
    assert {p.name for p in out.glob("*.png")} == set(figures_of(trajectory))


def test_velocity_draws_every_agent_numbered_from_one(hex19):
    trajectory, _, ds = hex19
    ax = figures_of(trajectory)["velocity.png"](trajectory).axes[0]
    lines = labelled(ax, "agent ")
    assert set(lines) == agent_names(ds) and len(lines) == 19
    speed = np.linalg.norm(per_axis(ds.sel(agent=6), "V_x", "V_y"), axis=-1)  # index 6 in the file is agent 7
    np.testing.assert_allclose(lines["agent 7"].get_ydata(), speed, rtol=1e-12)
    assert "\n" not in ax.get_title()  # every agent drawn: no note


def test_distance_draws_every_pair(hex19):
    trajectory, _, ds = hex19
    fig = figures_of(trajectory)["distance.png"](trajectory)
    lines = labelled(fig.axes[0], "agents ")
    pairs = list(zip(ds["pair_i"].values + 1, ds["pair_j"].values + 1))
    assert set(lines) == {f"agents {i}-{j}" for i, j in pairs} and len(lines) == 42
    for p in (0, 41):
        i, j = pairs[p]
        np.testing.assert_allclose(lines[f"agents {i}-{j}"].get_ydata(), ds["distance"].values[:, p], rtol=1e-12)
    assert fig.axes[0].get_title().endswith("all 42 pairs")
    coupled = fig.axes[1].get_lines()[0].get_ydata()  # 42 flags: their count, not 42 steps
    np.testing.assert_array_equal(coupled, (ds["F_en"].values == 1).sum(axis=1))


def test_formation_error_is_over_every_pair(hex19):
    trajectory, _, ds = hex19
    ax = figures_of(trajectory)["formation.png"](trajectory).axes[0]
    on = ds["F_en"].values == 1
    error = np.abs(ds["distance"].values - ds["d_t"].values)
    rms = np.sqrt((np.where(on, error, 0) ** 2).sum(axis=1) / on.sum(axis=1))
    np.testing.assert_allclose(labelled(ax, "RMS")["RMS"].get_ydata(), rms, rtol=1e-12)
    assert "all 42 pairs" in ax.get_title()


def test_paths_draw_every_agent_and_number_them(hex19):
    trajectory, _, ds = hex19
    ax = figures_of(trajectory)["paths.png"](trajectory).axes[0]
    lines = labelled(ax, "agent ")
    assert set(lines) == agent_names(ds)
    np.testing.assert_allclose(lines["agent 19"].get_xydata(), per_axis(ds.sel(agent=18), "x", "y"), rtol=1e-12)
    numbers = sorted(int(t.get_text()) for t in ax.texts)
    assert numbers == list(range(1, 20))


def test_shape_shows_every_agent_and_pair_with_the_strain_scale_of_the_run(hex19):
    trajectory, _, ds = hex19
    fig = figures_of(trajectory)["shape.png"](trajectory)
    panels = [ax for ax in fig.axes if ax.get_label() in ("start", "middle", "end")]
    assert [ax.get_label() for ax in panels] == ["start", "middle", "end"]  # hex19 starts coupled, no events
    strain = (ds["distance"] / ds["d_t"] - 1).where(ds["F_en"] == 1)
    largest = float(abs(strain).max())
    assert 0.01 < largest < 0.1
    for ax, (_, record) in zip(panels, moments(trajectory)):
        dots = next(c for c in ax.collections if isinstance(c, PathCollection))
        np.testing.assert_allclose(dots.get_offsets(), per_axis(ds, "x", "y")[record], rtol=1e-12)
        solid = next(c for c in ax.collections if isinstance(c, LineCollection) and c.get_array() is not None)
        assert len(solid.get_segments()) == int((ds["F_en"].values[record] == 1).sum()) == 42
        np.testing.assert_allclose(solid.get_array(), strain.values[record], rtol=1e-9)
        assert solid.norm.vmin == pytest.approx(-largest, rel=1e-12) and solid.norm.vmax == pytest.approx(largest, rel=1e-12)
        assert sorted(int(t.get_text()) for t in ax.texts) == list(range(1, 20))
    assert "19 agents and 42 pairs" in fig.texts[0].get_text()


def test_a_swarm_too_large_to_draw_whole_says_which_it_draws(hex19, monkeypatch):
    trajectory, _, _ = hex19
    monkeypatch.setattr(drawing, "MAX_LINES", 7)
    ax = figures_of(trajectory)["velocity.png"](trajectory).axes[0]
    assert set(labelled(ax, "agent ")) == {f"agent {k}" for k in range(1, 8)}
    assert ax.get_title().endswith("\n7 of 19 agents: the first 7 recorded")
    ax = figures_of(trajectory)["distance.png"](trajectory).axes[0]
    closest = np.sort(np.argsort(trajectory.min_distance, kind="stable")[:7])
    assert set(labelled(ax, "agents ")) == {drawing.pair_label(*trajectory.pairs[p]) for p in closest}
    assert ax.get_title().endswith("\n7 of 42 pairs: the 7 that came closest")


def test_strain_scale_has_a_floor():
    assert drawing.strain_limit(np.array([0.001, -0.002, np.nan])) == drawing.STRAIN_FLOOR
    assert drawing.strain_limit(np.array([0.03, -0.05])) == 0.05
    assert drawing.strain_limit(np.array([])) == drawing.STRAIN_FLOOR


def test_moments_are_start_coupling_uncoupling_end(triangle_3d):
    trajectory, _ = triangle_3d
    found = moments(trajectory)
    assert [name for name, _ in found] == ["start", "middle", "first uncoupling", "end"]
    uncouple = next(e.time for e in trajectory.events if e.kind == "uncouple")
    index = dict(found)["first uncoupling"]
    assert trajectory.time[index] >= uncouple > trajectory.time[index - 1]


def test_a_3d_run_is_drawn_in_3d_beside_its_projection(triangle_3d):
    trajectory, out = triangle_3d
    with xr.open_dataset(out / "trajectory.nc", engine="h5netcdf", decode_times=False) as ds:
        position = per_axis(ds, "x", "y", "z")
    paths = figures_of(trajectory)["paths.png"](trajectory)
    space = next(ax for ax in paths.axes if ax.name == "3d")
    plane = next(ax for ax in paths.axes if ax.name == "rectilinear" and ax.get_title() == "projection on (x, y)")
    for k in range(3):
        x, y, z = labelled(space, f"agent {k + 1}")[f"agent {k + 1}"].get_data_3d()
        np.testing.assert_allclose(np.stack([x, y, z], axis=1), position[:, k], rtol=1e-12)
        np.testing.assert_allclose(labelled(plane, f"agent {k + 1}")[f"agent {k + 1}"].get_xydata(), position[:, k, :2])
    shape = figures_of(trajectory)["shape.png"](trajectory)
    panels = [ax for ax in shape.axes if ax.name == "3d"]
    assert len(panels) == 4
    end = panels[-1]
    solid = next(c for c in end.collections if isinstance(c, LineCollection) and c.get_array() is not None)
    assert len(solid.get_array()) == int(trajectory.flag[-1].sum()) == 2  # the pair uncoupled by command is dashed


def test_figures_of_a_run_read_back_are_those_drawn_at_its_end(hex19, triangle_3d):
    """``tmem plot`` and ``tmem run`` draw through the same function: the drawn data must agree exactly."""
    for trajectory, out in (hex19[:2], triangle_3d):
        again = read_run(out)
        assert list(figures_of(again)) == list(figures_of(trajectory))
        for name, draw in figures_of(trajectory).items():
            first, second = draw(trajectory), figures_of(again)[name](again)
            for a, b in zip(first.axes, second.axes, strict=True):
                assert a.get_title() == b.get_title()
                assert [line.get_label() for line in a.get_lines()] == [line.get_label() for line in b.get_lines()]
                for la, lb in zip(a.get_lines(), b.get_lines()):
                    np.testing.assert_array_equal(la.get_xydata(), lb.get_xydata())


def test_animation_numbers_every_agent_and_fits_its_strain_scale_to_the_run(hex19):
    from tmem.figures.animate.frames import read_frames
    from tmem.figures.animate.scene import positions, scene

    _, out, ds = hex19
    frames = read_frames(out, max_frames=400)  # every record
    fig, moving = scene(frames, positions(frames)[0], dpi=40)
    largest = float(abs((ds["distance"] / ds["d_t"] - 1).where(ds["F_en"] == 1)).max())
    assert moving["coupled"].norm.vmax == pytest.approx(largest, rel=1e-9)
    assert sorted(int(t.get_text()) for t in fig.axes[0].texts if t.get_text().isdigit()) == list(range(1, 20))


def test_paths_in_a_periodic_box_break_where_they_wrap_and_cover_the_box():
    """400 agents in a periodic box, 100 drawn: no line crosses the box (a step longer than half a side
    on the recorded positions is a wrap, broken there, one break per wrap), and the agents drawn
    start all over the box, not in the strip the first 100 numbered start in."""
    scenario = with_changes(load(EXAMPLES / "swarm" / "gas_thermostat.toml"), {"simulation.duration": 20.0, "commands": []})
    trajectory = tmem.simulate(scenario)
    box = np.array(scenario.space.box)
    ax = figures_of(trajectory)["paths.png"](trajectory).axes[0]
    lines = labelled(ax, "agent ")
    assert len(lines) == 100 and ax.figure.texts[0].get_text().endswith("100 of 400 agents: spread over where they started")
    position = trajectory.model.position(trajectory.state)
    starts = []
    for label, line in lines.items():
        xy, k = line.get_xydata(), int(label.split()[1]) - 1
        wraps = int((np.abs(np.diff(position[:, k], axis=0)) > box / 2).any(axis=1).sum())
        gaps = np.isnan(xy).any(axis=1)
        assert gaps.sum() == wraps
        steps = np.abs(np.diff(xy, axis=0))[~(gaps[1:] | gaps[:-1])]
        assert (steps <= box / 2).all(), label  # no line across the box
        np.testing.assert_array_equal(np.unique(xy[~gaps], axis=0), np.unique(position[:, k], axis=0))  # every record drawn
        starts.append(position[0, k])
    cells = np.floor(np.array(starts) / (box / 4)).astype(int)
    assert len({tuple(c) for c in cells}) == 16  # every quarter of every side
    assert position[0, :100, 1].max() < box[1] / 2  # the first 100 numbered would not have been


def test_every_label_of_a_3d_view_lies_inside_its_own_panel(triangle_3d):
    """shape.png's four 3-D views side by side, paths.png's beside its projection and the animation's:
    each view's x, y and z labels are drawn inside its panel, where the next panel cannot cover them."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from tmem.figures.animate.frames import read_frames
    from tmem.figures.animate.scene import positions, scene

    trajectory, out = triangle_3d
    frames = read_frames(out, max_frames=10)
    figures = [figures_of(trajectory)[name](trajectory) for name in ("shape.png", "paths.png")]
    figures.append(scene(frames, positions(frames)[0], dpi=100)[0])
    for fig in figures:
        FigureCanvasAgg(fig)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        views = [ax for ax in fig.axes if ax.name == "3d"]
        assert views
        for ax in views:
            panel = ax.get_window_extent(renderer)
            for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
                label = axis.label.get_window_extent(renderer)
                assert axis.label.get_text().endswith(", m")
                assert panel.x0 <= label.x0 and label.x1 <= panel.x1 and panel.y0 <= label.y0 and label.y1 <= panel.y1, axis.label.get_text()
