"""``tmem view``'s page data and files, from small synthetic run directories (no browser).

The page's embedded run is decoded here in Python, independently of the page's
scripts, and compared with the trajectory file as xarray reads it.
``tests/test_viewer_browser.py`` opens real pages in Chromium.
"""

import base64
import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from tmem.cli.main import app
from tmem.vehicles.linear import LinearModel
from tmem.figures.viewer import default_out, write_view
from tmem.figures.drawing import STRAIN_FLOOR
from tmem.files.trajectory_file import RunReadError
from tmem.figures.viewer.data import FLYING, MAX_AGENTS, MAX_COORDINATES, MAX_FRAMES, REMOVED, WAITING, agent_status, read_view, strain_scale
from tmem.figures.viewer import data
from tmem.figures.viewer.page import VIEW_MARK, headline, quantised

VENDOR = Path(__file__).resolve().parents[1] / "src" / "tmem" / "figures" / "viewer" / "vendor"


def scenario_text(n_agents: int, n_axes: int, name: str = "synthetic") -> str:
    return f'name = {json.dumps(name)}\n[space]\naxes = {n_axes}\n[interaction]\nfunction = "repulsion"\nd_t = 35.0\n[swarm]\nn = {n_agents}\nregion = {[200.0] * n_axes}\n'


def write_run(directory: Path, n_agents=3, n_times=30, n_axes=2, pairs=((0, 1), (1, 2)), removed=True,
              names=("P", "V", "phi", "omega"), name="synthetic"):  # fmt: skip
    """A run directory: agents on straight lines, pairs coupling halfway, the last agent removed at two thirds."""
    directory.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(1)
    time = 0.5 * np.arange(n_times)
    start = rng.uniform(0, 200, (n_agents, n_axes))
    velocity = rng.normal(0, 2, (n_agents, n_axes))
    position = start + time[:, None, None] * velocity
    pairs = np.array(pairs, dtype=int).reshape(-1, 2)
    distance = np.linalg.norm(position[:, pairs[:, 1]] - position[:, pairs[:, 0]], axis=-1)
    flag = np.zeros((n_times, len(pairs)), np.int8)
    flag[n_times // 2 :] = 1
    active = np.ones((n_times, n_agents), np.int8)
    if removed:
        active[2 * n_times // 3 :, n_agents - 1] = 0
        position[2 * n_times // 3 :, n_agents - 1] = position[2 * n_times // 3 - 1, n_agents - 1]  # stopped, as the engine holds it
    # Laid out as tmem run writes it (CF trajectories): per agent over (agent, time), the positions as
    # the coordinates x, y (z), every other per-axis state one variable per axis (V_x, V_y...).
    axes = ["x", "y", "z"][:n_axes]
    over = ("agent", "time")
    rows = position.transpose(1, 0, 2)  # (agent, time, axis)
    zeros = np.zeros((n_agents, n_times))
    data = {f"{name}_{axis}": (over, zeros) for name in (*names[2:], "U") for axis in axes}
    data |= {f"{names[1]}_{axis}": (over, np.broadcast_to(velocity[:, a, None], zeros.shape)) for a, axis in enumerate(axes)}
    data |= {
        "active": (over, active.T),
        "F_en": (("pair", "time"), flag.T),
        "distance": (("pair", "time"), distance.T),
        "interaction_distance": (("pair", "time"), distance.T),
        "d_t": ("pair", np.full(len(pairs), 35.0)),
        "rms_velocity": ("time", np.sqrt((velocity**2).sum(-1).mean()) * np.ones(n_times)),
    }
    coords = {"time": time, "agent": np.arange(n_agents), "pair": np.arange(len(pairs)),
              "pair_i": ("pair", pairs[:, 0]), "pair_j": ("pair", pairs[:, 1])}  # fmt: skip
    coords |= {axis: (over, rows[..., a]) for a, axis in enumerate(axes)}
    xr.Dataset(data, coords=coords, attrs={"scenario": scenario_text(n_agents, n_axes, name)}).to_netcdf(
        directory / "trajectory.nc", engine="h5netcdf"
    )
    summary = {"scenario": "synthetic", "function": "improved", "agents": n_agents, "duration": float(time[-1]),
               "rms_change_percent": 0.5, "min_distance": 12.0, "pairs_coupled_at_end": len(pairs), "pairs": [{}] * len(pairs)}  # fmt: skip
    (directory / "summary.json").write_text(json.dumps(summary))
    return directory


def embedded(page: Path) -> dict:
    """The run embedded in a page, decoded with NumPy (independently of the page's scripts)."""
    text = re.search(r'<script type="application/json" id="tmem-run">(.*?)</script>', page.read_text(), re.S).group(1)
    run = json.loads(text)
    raw = lambda key, dtype: np.frombuffer(base64.b64decode(run[key]), dtype)  # noqa: E731
    F, A, D = run["frames"], len(run["agents"]), len(run["axes"])
    q = np.frombuffer(base64.b64decode(run["position"]["data"]), "<u2").reshape(F, A, D)
    run["position"] = np.array(run["position"]["low"]) + q * np.array(run["position"]["step"])
    run["time"] = raw("time", "<f8")
    run["status"] = raw("status", "u1").reshape(F, A)
    run["strain"] = raw("strain", "<f4").reshape(F, -1)
    return run


def test_positions_in_the_page_match_the_file_to_the_16_bit_step(tmp_path):
    run = write_run(tmp_path / "run", removed=False)
    page = write_view(run, tmp_path / "view.html")
    shown = embedded(page)
    with xr.open_dataset(run / "trajectory.nc", engine="h5netcdf") as ds:
        expected = np.stack([ds["x"].values, ds["y"].values], axis=-1).transpose(1, 0, 2)  # (time, agent, axis)
        np.testing.assert_array_equal(shown["time"], ds["time"].values)
    step = (expected.max(axis=(0, 1)) - expected.min(axis=(0, 1))) / 65535
    assert np.all(np.abs(shown["position"] - expected) <= step / 2 + 1e-9)
    assert shown["agents"] == [1, 2, 3]  # numbered from 1


def test_quantised_values_are_within_half_a_step_and_keep_their_ends():
    values = np.random.default_rng(0).uniform(-50, 900, (40, 7, 3))
    q = quantised(values)
    back = np.array(q["low"]) + np.frombuffer(base64.b64decode(q["data"]), "<u2").reshape(values.shape) * np.array(q["step"])
    assert np.all(np.abs(back - values) <= np.array(q["step"]) / 2 + 1e-9)
    np.testing.assert_allclose(back.min(axis=(0, 1)), values.min(axis=(0, 1)))
    np.testing.assert_allclose(back.max(axis=(0, 1)), values.max(axis=(0, 1)))


def test_edges_join_the_right_agents_and_their_strain_is_the_geometry(tmp_path):
    run = write_run(tmp_path / "run", n_agents=5, pairs=((3, 0), (1, 4), (2, 3)), removed=False)
    view = read_view(run)
    for k, (a, b) in enumerate(view.edges):  # columns of the agents, from the page's own positions
        length = np.linalg.norm(view.position[:, b] - view.position[:, a], axis=-1)
        np.testing.assert_allclose(view.strain[:, k], length / 35.0 - 1, rtol=1e-9)
    assert [tuple(view.agents[e]) for e in view.edges] == [(4, 1), (2, 5), (3, 4)]
    assert view.pair_labels == ["agents 4–1", "agents 2–5", "agents 3–4"]


def test_strain_scale_is_the_largest_strain_of_the_coupled_edges_between_flying_agents():
    rng = np.random.default_rng(2)
    strain = rng.uniform(-0.03, 0.03, (200, 10))
    coupled = np.ones_like(strain, bool)
    coupled[:, 5:] = False
    strain[:, 5:] = 5.0  # uncoupled edges far off d_t do not stretch the scale
    status = np.ones((200, 11), np.uint8)
    edges = np.stack([np.arange(10), np.arange(1, 11)], axis=1)
    assert strain_scale(strain, coupled, status, edges) == np.abs(strain[:, :5]).max()
    status[7, 0] = REMOVED  # edge 0 at frame 7 is not drawn: its strain does not count
    strain[7, 0] = -0.2
    assert strain_scale(strain, coupled, status, edges) == np.abs(np.delete(strain[:, :5].ravel(), 7 * 5)).max()
    assert strain_scale(strain, np.zeros_like(coupled), status, edges) == 5.0  # none coupled: every edge
    assert strain_scale(strain / 100, coupled, status, edges) == STRAIN_FLOOR  # held to millimetres


def test_agents_are_waiting_flying_or_removed(tmp_path):
    run = write_run(tmp_path / "run", n_agents=3, n_times=30)
    view = read_view(run)
    gone = 20  # 2 * 30 // 3
    assert (view.status[:gone] == FLYING).all() and (view.status[gone:, :2] == FLYING).all()
    assert (view.status[gone:, 2] == REMOVED).all()
    later = np.ones((5, 3), bool)
    later[:2, 1] = False  # added at the third frame
    later[3, 1] = False  # removed, then added back
    assert agent_status(later)[:, 1].tolist() == [WAITING, WAITING, FLYING, REMOVED, FLYING]


def test_large_swarms_are_thinned_and_the_page_says_so(tmp_path):
    run = write_run(tmp_path / "run", n_agents=2500, n_times=400, pairs=(), removed=False)
    view = read_view(run)
    assert len(view.agents) == 1000 and view.agents[0] == 1 and view.agents[-1] == 2500
    assert len(view.time) == MAX_COORDINATES // (1000 * 2) and view.time[-1] == 0.5 * 399
    assert view.note == "Shown: 1000 of 2500 agents, evenly chosen by number; 300 of 400 recorded times, evenly spaced."
    few = read_view(run, max_agents=10, max_frames=5)
    assert few.position.shape == (5, 10, 2)
    assert read_view(write_run(tmp_path / "small"), max_frames=None).note == ""


def test_reading_a_block_of_agents_at_a_time_reads_the_same(tmp_path, monkeypatch):
    run = write_run(tmp_path / "run", n_agents=7, n_times=50, pairs=((0, 1), (5, 6)))
    whole = read_view(run, max_agents=5, max_frames=20)
    monkeypatch.setattr(data, "_READ_VALUES", 9)  # an agent's record per block
    blocks = read_view(run, max_agents=5, max_frames=20)
    for name in ("time", "position", "speed", "status", "strain", "coupled", "drawn", "rms", "pair_distance"):
        np.testing.assert_array_equal(getattr(blocks, name), getattr(whole, name), err_msg=name)
    every = read_view(run, max_frames=50)  # every agent: read in slices
    monkeypatch.setattr(data, "_READ_VALUES", 10**9)
    np.testing.assert_array_equal(every.position, read_view(run, max_frames=50).position)


def test_state_names_come_from_the_vehicle_model(tmp_path, monkeypatch):
    monkeypatch.setattr(LinearModel, "state_names", ("X", "Xdot", "tilt", "tilt_rate"))
    view = read_view(write_run(tmp_path / "renamed", names=("X", "Xdot", "tilt", "tilt_rate"), removed=False))
    assert view.position.shape == (30, 3, 2)
    with pytest.raises(RunReadError, match=r"cannot be read as a run's trajectory \(.*Xdot_x"):
        read_view(write_run(tmp_path / "usual", removed=False))


@pytest.fixture
def runner():
    return CliRunner()


def refused(runner, *args) -> str:
    result = runner.invoke(app, ["view", *map(str, args)])
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("error: "), result.stderr
    return result.stderr


def test_what_is_not_a_run_is_refused_in_one_line_and_nothing_is_written(runner, tmp_path):
    run = write_run(tmp_path / "run")
    damaged = write_run(tmp_path / "damaged")
    (damaged / "trajectory.nc").write_bytes((damaged / "trajectory.nc").read_bytes()[:3000])
    no_summary = write_run(tmp_path / "no-summary")
    (no_summary / "summary.json").unlink()
    bad_summary = write_run(tmp_path / "bad-summary")
    (bad_summary / "summary.json").write_text("{")
    before = sorted(p.name for p in tmp_path.iterdir())
    assert "no such folder" in refused(runner, tmp_path / "missing")
    assert "is a file, not a run folder" in refused(runner, run / "summary.json")
    assert "no summary.json in" in refused(runner, no_summary)
    assert "cannot be read as a run's summary" in refused(runner, bad_summary)
    assert "cannot be read as a run's trajectory" in refused(runner, damaged)
    assert "--max-frames: must be at least 1, got 0" in refused(runner, run, "--max-frames", "0")
    assert "--out" in refused(runner, run, "--out", run)  # a directory
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_view_help_loads_nothing_heavy():
    probe = (
        "import sys; sys.argv = ['tmem', 'view', '--help']\nfrom tmem.cli.main import main\n"
        "try:\n    main()\nexcept SystemExit as e:\n    assert not e.code, e.code\n"
        "print('loaded:', *(m for m in ('numba', 'xarray', 'matplotlib', 'h5netcdf') if m in sys.modules))"
    )
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.rpartition("loaded:")[2].split() == []


def test_the_help_gives_the_defaults_the_viewer_uses(runner):
    text = " ".join(runner.invoke(app, ["view", "--help"], env={"COLUMNS": "200"}).output.split())
    agents, frames = (line for line in text.split("--")[1:] if line.startswith(("max-agents", "max-frames")))
    assert "[default:" in agents and f"{MAX_AGENTS} agents" in agents
    assert "[default:" in frames and f"{MAX_FRAMES} frames, fewer for large swarms" in frames


def test_an_existing_file_is_replaced_only_if_tmem_view_wrote_it(runner, tmp_path):
    run = write_run(tmp_path / "run")
    notes = tmp_path / "notes.html"
    notes.write_text("<p>mine</p>")
    assert f"exists and was not {VIEW_MARK}" in refused(runner, run, "--out", notes)
    assert notes.read_text() == "<p>mine</p>"
    result = runner.invoke(app, ["view", str(run)])
    assert result.exit_code == 0 and (tmp_path / "run.html").is_file()
    assert default_out(run) == tmp_path / "run.html"
    assert runner.invoke(app, ["view", str(run)]).exit_code == 0  # its own page: replaced


def test_an_interrupted_write_leaves_the_earlier_page_and_no_partial_file(tmp_path, monkeypatch):
    run = write_run(tmp_path / "run")
    out = write_view(run, tmp_path / "view.html")
    earlier = out.read_bytes()

    def interrupted(self, text, encoding=None):
        Path.write_bytes(self, text[: len(text) // 2].encode())
        raise KeyboardInterrupt

    monkeypatch.setattr(Path, "write_text", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_view(run, out)
    assert out.read_bytes() == earlier
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run", "view.html"]


def test_the_page_fetches_nothing(tmp_path):
    page = write_view(write_run(tmp_path / "run"), tmp_path / "view.html").read_text()
    assert not re.search(r"<script[^>]*\ssrc=|<link\b|@import|<img\b|<iframe\b", page)
    imports = json.loads(re.search(r'<script type="importmap">(.*?)</script>', page, re.S).group(1))["imports"]
    assert imports and all(url.startswith("data:text/javascript;base64,") for url in imports.values())
    assert page.count("</script>") == page.count("<script")  # nothing inlined closes a script early


def test_the_headline_shows_the_summary_and_a_dash_for_what_is_missing():
    summary = {"agents": 19, "function": "improved", "duration": 60.0, "rms_change_percent": None,
               "min_distance": 33.076, "pairs_coupled_at_end": 40, "pairs": [{}] * 42}  # fmt: skip
    assert dict(headline(summary)) == {"agents": "19", "function": "improved", "duration": "60 s", "ΔRMS": "—",
                                       "largest ΔRMS": "—", "min distance": "33.08 m", "pairs coupled at end": "40/42"}  # fmt: skip
    assert dict(headline({"agents": True})) == {"agents": "—", "function": "—", "duration": "—", "ΔRMS": "—",
                                                "largest ΔRMS": "—", "min distance": "—"}  # fmt: skip


def test_the_headline_marks_a_swinging_rms_change_and_says_why_as_the_table_does():
    """Pairs coupled and oscillating at the end: ΔRMS marked and the table's caveat shown; pairs held
    still (a settled formation): neither.  The largest change on the way is shown with its time."""
    from tmem.cli.terminal import SWINGS as TABLE_SWINGS
    from tmem.figures.viewer.page import caveat

    summary = {"rms_change_percent": 2.26, "rms_change_while_coupled": True, "rms_change_swings": True,
               "rms_change_peak_percent": -28.9, "rms_change_peak_time": 5.0}  # fmt: skip
    shown = dict(headline(summary))
    assert shown["ΔRMS"] == "+2.260 % *" and shown["largest ΔRMS"] == "-28.900 % at 5.00 s"
    assert caveat(summary) == TABLE_SWINGS
    settled = summary | {"rms_change_swings": False}
    assert dict(headline(settled))["ΔRMS"] == "+2.260 %" and caveat(settled) == ""


def test_a_name_with_markup_is_shown_as_written(tmp_path):
    name = '</script><b>x</b> & "q" <!-- 日本語'
    page = write_view(write_run(tmp_path / "run", name=name), tmp_path / "view.html")
    assert embedded(page)["name"] == name
    text = page.read_text()
    assert "<b>x</b>" not in text and "<title>&lt;/script&gt;&lt;b&gt;x&lt;/b&gt; &amp; &quot;q&quot; &lt;!-- 日本語: tmem view</title>" in text


def test_the_shipped_libraries_are_the_ones_the_docs_name():
    table = (VENDOR / "README.md").read_text()
    for name, digest in re.findall(r"^\| `([^`]+)` \|[^|]+\|[^|]+\| `([0-9a-f]{64})` \|$", table, re.M):
        assert hashlib.sha256((VENDOR / name).read_bytes()).hexdigest() == digest, name
    assert 'const t="170"' in (VENDOR / "three.module.min.js").read_text()[:400]  # three.js's REVISION
    assert "(v1.6.32)" in (VENDOR / "uPlot.iife.min.js").read_text()[:100]
    template = (VENDOR.parent / "web" / "viewer.html").read_text()
    assert "three.js r170 and uPlot 1.6.32" in template
    for script in ("uPlot.iife.min.js",):  # inlined as a classic script
        assert not re.search(r"</script|<!--", (VENDOR / script).read_text(), re.I)


ROUTE = """name = "route3"
[space]
axes = 2
[interaction]
function = "repulsion"
[[agents]]
position = [0.0, 0.0]
[[agents]]
position = [60.0, 0.0]
[[agents]]
position = [0.0, 60.0]
[[obstacles]]
center = [40.0, 80.0]
radius = 5.0
[navigation]
[[navigation.legs]]
time = 0.0
action = "route"
waypoints = [[30.0, 20.0], [30.0, 40.0]]
speed = 2.0
[simulation]
dt = 0.01
duration = 4.0
"""


@pytest.fixture(scope="module")
def mission_run(tmp_path_factory):
    """A run of :data:`ROUTE`, simulated, its files written as ``tmem run`` writes them (without figures)."""
    import tmem
    from tmem.analysis.metrics import summarize
    from tmem.files.io import write_netcdf

    directory = tmp_path_factory.mktemp("mission")
    trajectory = tmem.simulate(tmem.loads(ROUTE))
    write_netcdf(trajectory, directory / "trajectory.nc")
    (directory / "summary.json").write_text(json.dumps(summarize(trajectory)))
    return directory


def test_a_mission_s_route_goal_and_obstacles_are_in_the_page(mission_run, tmp_path):
    import tmem
    from tmem.terms.navigation_plan import planned_points

    shown = embedded(write_view(mission_run, tmp_path / "view.html"))
    waypoints = [[30.0, 20.0], [30.0, 40.0]]  # the scenario's: a route without avoid is flown as written
    assert [points.tolist() for _, _, points in planned_points(tmem.loads(ROUTE))] == [waypoints]
    [leg] = shown["route"]["legs"]
    assert (leg["time"], leg["action"], leg["points"]) == (0.0, "route", waypoints)
    np.testing.assert_allclose(leg["from"], [20.0, 20.0])  # the three agents' centre at the start
    assert shown["route"]["goal"] == [30.0, 40.0]
    assert shown["space"]["obstacles"] == [{"center": [40.0, 80.0], "radius": 5.0}]


def test_a_run_without_navigation_has_no_route(tmp_path):
    assert "route" not in embedded(write_view(write_run(tmp_path / "run"), tmp_path / "view.html"))


def test_each_leg_starts_where_the_group_was_and_legs_without_points_are_left_out():
    """A velocity leg (no point), a goto from 1.5 s (from the flying agents' centre at 1 s, the last
    frame before it) and a hold where the group is (no point): one leg, whose target is the goal."""
    import tmem
    from tmem.figures.viewer.data import mission_route

    legs = ROUTE.split("[[navigation.legs]]")[0] + "".join(
        f"[[navigation.legs]]\ntime = {t}\naction = {json.dumps(a)}\n{keys}\n"
        for t, a, keys in ((0.0, "velocity", "velocity = [1.0, 0.0]"), (1.5, "goto", "target = [50.0, 50.0]\nspeed = 2.0"),
                           (3.0, "hold", ""))  # fmt: skip
    )
    scenario = tmem.loads(legs + "[simulation]\ndt = 0.01\nduration = 4.0\n")
    time = np.array([0.0, 1.0, 2.0, 3.0])
    position = np.arange(4)[:, None, None] + np.array([[0.0, 0.0], [60.0, 0.0], [0.0, 90.0]])
    status = np.full((4, 3), FLYING, np.uint8)
    status[1, 2] = REMOVED
    route = mission_route(scenario, time, position, status)
    assert route == {"legs": [{"time": 1.5, "action": "goto", "from": [31.0, 1.0], "points": [[50.0, 50.0]]}],
                     "goal": [50.0, 50.0]}  # fmt: skip


def test_the_headline_shows_the_safety_figures_given():
    safety = {"radius": 2.0, "min_separation": 12.345, "near_misses": 3, "min_obstacle_clearance": None}
    shown = dict(headline({"safety": safety}))
    assert shown["min separation"] == "12.35 m" and shown["near misses (< 2.00 m)"] == "3"
    assert "min obstacle clearance" not in shown
    cleared = dict(headline({"safety": safety | {"radius": None, "min_obstacle_clearance": 0.5}}))
    assert cleared["min obstacle clearance"] == "0.50 m" and cleared["near misses"] == "3"
    assert "near misses" in dict(headline({"safety": {"near_misses": 0}}))
    assert len(headline({"safety": None})) == len(headline({})) == 6


def test_a_reshaping_formation_draws_only_the_pairs_of_the_shape_it_flies(tmp_path):
    """While the lines fly, no pair is drawn; after them, the drawn edges are the pairs found d_t apart."""
    import sys

    import tmem
    from tmem.analysis.metrics import summarize
    from tmem.files.io import write_netcdf

    sys.path.insert(0, str(Path(__file__).parent))
    from test_reshape import RESHAPE

    trajectory = tmem.simulate(tmem.loads(RESHAPE))
    write_netcdf(trajectory, tmp_path / "trajectory.nc")
    (tmp_path / "summary.json").write_text(json.dumps(summarize(trajectory)))
    view = read_view(tmp_path, max_frames=len(trajectory.time))
    during, after = (np.searchsorted(view.time, t) for t in (60.0, 160.0))  # lines 40-81.4 s, then the line
    assert not view.drawn[during].any() and view.drawn[0].sum() == 12
    agents = view.agents - 1
    p = view.position[after]
    apart = {tuple(sorted((int(agents[a]), int(agents[b])))) for a, b in view.edges if abs(np.linalg.norm(p[b] - p[a]) - 35.0) < 0.1}
    drawn = {tuple(sorted((int(agents[a]), int(agents[b])))) for a, b in view.edges[view.drawn[after]]}
    assert len(drawn) == 6 and drawn == apart
