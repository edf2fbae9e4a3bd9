"""``tmem view``'s pages opened in a real browser: headless Chromium, driven by Playwright.

Each page is opened from disk, as a user would open it, with no network; the
tests fail on any console error or page error.  What the view draws is read
from the page (``window.tmemViewer``) and compared with the trajectory file as
xarray reads it; the slider, the buttons and the view are worked with the
keyboard and the mouse.  Screenshots are checked for their size, for not being
blank and for the agents' colour, not pixel by pixel; the hex and the 3-D gas
are saved as ``docs/images/viewer-hex19.png`` and ``docs/images/viewer-3d.png``
for the documentation.

Chromium is Debian's (``apt-get install chromium``, as ``.ci/run`` does),
never a browser Playwright downloads.  Without it these tests fail, saying
so; ``TMEM_SKIP_BROWSER_TESTS=1`` skips them instead.
"""

import os
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from PIL import Image

import tmem
from tmem.files.io import write_run
from tmem.scenario import load
from tmem.figures.viewer import write_view
from tmem.figures.viewer.data import read_view
from test_viewer import ROUTE

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = Path(os.environ.get("TMEM_CHROMIUM", "/usr/bin/chromium"))
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--no-first-run"]  # fmt: skip
VIEWPORT = {"width": 1400, "height": 860}
AGENT = (31, 119, 180)  # the agents' colour, #1f77b4
REMOVED = (127, 127, 127)
GOAL, ROUTE_LINE = (214, 39, 40), (44, 160, 44)  # #d62728, #2ca02c
SCENARIOS = {
    "hex19": lambda: load(ROOT / "examples" / "swarm" / "hex19.toml"),
    "gas3d": lambda: load(ROOT / "examples" / "swarm" / "gas3d.toml"),
    "ring8_loss": lambda: load(ROOT / "examples" / "swarm" / "ring8_loss.toml"),
    "fig9": lambda: tmem.preset("fig9"),
    "route3": lambda: tmem.loads(ROUTE),
}


@pytest.fixture(scope="module")
def browser():
    if os.environ.get("TMEM_SKIP_BROWSER_TESTS"):
        pytest.skip("TMEM_SKIP_BROWSER_TESTS is set")
    if not CHROMIUM.is_file():
        pytest.fail(f"Chromium is not at {CHROMIUM}: install it (apt-get install -y chromium), or set "
                    "TMEM_CHROMIUM to its path, or TMEM_SKIP_BROWSER_TESTS=1 to skip the browser tests")  # fmt: skip
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.fail("Playwright is not installed: pip install -e '.[test]'")
    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=str(CHROMIUM), args=FLAGS)
        yield chromium
        chromium.close()


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """``runs(name)``: the directory of a run of one of :data:`SCENARIOS`, simulated once."""
    made = {}

    def run(name):
        if name not in made:
            made[name] = tmp_path_factory.mktemp("runs") / name
            write_run(tmem.simulate(SCENARIOS[name]()), made[name])
        return made[name]

    return run


class Viewer:
    """A page open in the browser, with the console's errors and the page's errors kept."""

    def __init__(self, browser, html: Path):
        self.page = browser.new_page(viewport=VIEWPORT)
        self.errors = []
        self.page.on("console", lambda m: self.errors.append(f"console: {m.text}") if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(f"page error: {e}"))
        self.page.goto(html.as_uri())
        self.page.wait_for_selector("body[data-ready=true]", timeout=30_000)

    def js(self, expression):
        return self.page.evaluate(expression)

    def drawn(self):
        return self.js("tmemViewer.drawn()")

    def screen(self):
        return np.array(self.js("tmemViewer.screen()"))

    def time(self) -> float:
        return self.js("tmemViewer.player.t")

    def slide_to_end(self):
        self.page.focus("#time")
        self.page.keyboard.press("End")

    def screenshot(self, path: Path) -> np.ndarray:
        self.page.wait_for_timeout(200)
        self.page.screenshot(path=path)
        with Image.open(path) as image:
            return np.asarray(image.convert("RGB")).astype(int)

    def close(self):
        self.page.close()
        assert not self.errors, self.errors


@pytest.fixture
def open_view(browser):
    opened = []

    def open_(html):
        opened.append(Viewer(browser, html))
        return opened[-1]

    yield open_
    for viewer in opened:
        viewer.close()


def open_file(run: Path) -> xr.Dataset:
    """The run's trajectory file, times in seconds (CF trajectories: a row per agent over time)."""
    return xr.open_dataset(run / "trajectory.nc", engine="h5netcdf", decode_times=False)


def file_positions(ds: xr.Dataset) -> np.ndarray:
    """The positions, (time, agent, axis): the coordinates x, y, z over (agent, time) that the run has."""
    axes = [a for a in ("x", "y", "z") if a in ds.variables and ds[a].dims == ("agent", "time")]
    return np.stack([ds[a].values.T for a in axes], axis=-1)


def positions_in_file(run: Path, t: float) -> dict[int, np.ndarray]:
    """Each agent's position at time ``t`` as the trajectory file holds it, keyed by its number from 1."""
    with open_file(run) as ds:
        k = int(np.flatnonzero(ds["time"].values == t)[0])
        return {int(a) + 1: file_positions(ds)[k, q] for q, a in enumerate(ds["agent"].values)}


def assert_drawn_as_in_file(viewer, run: Path):
    expected = positions_in_file(run, viewer.time())
    for agent in viewer.drawn():
        np.testing.assert_allclose(agent["position"], expected[agent["agent"]], atol=0.01)  # 16-bit steps of < 1 cm


def pixels_near(image: np.ndarray, colour, tolerance=10) -> int:
    return int((np.abs(image - np.array(colour)).max(axis=-1) <= tolerance).sum())


def strain_colour(strain: float, scale: float) -> np.ndarray:
    """The colour the docs give an edge of this strain: dark grey at d_t towards purple (closer) or
    orange (farther), mixed in linear light, as sRGB 0-255."""
    linear = lambda c: np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)  # noqa: E731
    srgb = lambda v: np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)  # noqa: E731
    at_set, end = np.array([0x40] * 3) / 255, np.array([0x7B, 0x32, 0x94] if strain < 0 else [0xE6, 0x61, 0x01]) / 255
    s = min(abs(strain) / scale, 1.0)
    return 255 * srgb((1 - s) * linear(at_set) + s * linear(end))


def light_blue(image: np.ndarray) -> int:
    """Pixels of an interaction sphere's translucent fill over white."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(((b - r > 12) & (r > 200)).sum())


def test_the_hex_plays_and_shows_what_the_file_holds(open_view, runs, tmp_path):
    run = runs("hex19")
    viewer = open_view(write_view(run, tmp_path / "hex19.html"))
    assert viewer.js("tmemViewer.webgl")
    assert viewer.page.inner_text("#title") == "hex19: 2-D run"
    assert [d.text_content() for d in viewer.page.query_selector_all(".agent-label")] == [str(k) for k in range(1, 20)]
    start = {a["agent"]: np.array(a["position"]) for a in viewer.drawn()}
    assert sorted(start) == list(range(1, 20))
    assert_drawn_as_in_file(viewer, run)
    cursors = viewer.js("tmemViewer.cursors()")

    viewer.slide_to_end()
    assert viewer.time() == pytest.approx(60.0)
    assert viewer.page.inner_text("#clock") == "t = 60.00 s"
    assert_drawn_as_in_file(viewer, run)
    travelled = [np.linalg.norm(a["position"] - start[a["agent"]]) for a in viewer.drawn()]
    assert min(travelled) > 150  # 3 m/s for 60 s, give or take the formation's swing
    assert all(after > before + 200 for before, after in zip(cursors, viewer.js("tmemViewer.cursors()")))


def test_the_hex_screenshot_shows_agents_edges_by_strain_and_spheres_on_demand(open_view, runs, tmp_path):
    run = runs("hex19")
    viewer = open_view(write_view(run, tmp_path / "hex19.html"))
    viewer.page.focus("#time")
    for _ in range(3):
        viewer.page.keyboard.press("PageUp")  # a few steps into the run
    plain = viewer.screenshot(tmp_path / "plain.png")
    assert not viewer.js("tmemViewer.spheresShown()")
    view, f = read_view(run), viewer.js("tmemViewer.player.frame")
    screen, box = viewer.screen(), viewer.page.locator("#view canvas").bounding_box()
    for e in (np.argmax(view.strain[f]), np.argmin(view.strain[f]), np.argmin(np.abs(view.strain[f]))):
        x, y = screen[view.edges[e]].mean(axis=0) + [box["x"], box["y"]]  # the edge's midpoint in the page
        near = plain[int(y) - 1 : int(y) + 2, int(x) - 1 : int(x) + 2].reshape(-1, 3)
        drawn = near[np.argmin(near.sum(axis=1))]  # the pixel least blended with the white behind it
        assert np.abs(drawn - strain_colour(view.strain[f, e], view.strain_scale)).max() < 30, (e, drawn)
    viewer.page.click("#show-spheres")
    assert viewer.js("tmemViewer.spheresShown()")
    docs = ROOT / "docs" / "images" / "viewer-hex19.png"
    docs.parent.mkdir(exist_ok=True)
    image = viewer.screenshot(docs)
    assert image.shape == (VIEWPORT["height"], VIEWPORT["width"], 3)
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 200  # not blank
    assert pixels_near(image, AGENT) > 19 * 30  # nineteen dots of 11 px
    assert light_blue(image) > light_blue(plain) + 19 * 500  # nineteen circles of R = 20 m, drawn only now


def test_pointer_names_the_agent_and_a_panel_click_shows_that_time(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("hex19"), tmp_path / "hex19.html"))
    box = viewer.page.locator("#view canvas").bounding_box()
    x, y = viewer.screen()[0]
    viewer.page.mouse.move(box["x"] + x, box["y"] + y)
    assert viewer.page.inner_text("#tooltip").startswith("agent 1 · x ")
    over = viewer.page.locator("#chart-rms .u-over").bounding_box()
    viewer.page.mouse.click(over["x"] + over["width"] / 2, over["y"] + over["height"] / 2)  # the time axis spans 0-60 s
    assert viewer.time() == pytest.approx(30.0, abs=0.5)
    spread = viewer.screen().std(axis=0).sum()
    viewer.page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    viewer.page.mouse.wheel(0, -600)  # zoom in
    viewer.page.wait_for_timeout(200)
    assert viewer.screen().std(axis=0).sum() > 1.2 * spread


def test_play_pause_and_speed(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("hex19"), tmp_path / "hex19.html"))
    viewer.page.select_option("#speed", "10")
    assert viewer.js("tmemViewer.player.speed") == 10
    viewer.page.click("#play")
    viewer.page.wait_for_timeout(800)
    viewer.page.click("#play")
    assert not viewer.js("tmemViewer.player.playing")
    assert 2.0 < viewer.time() < 60.0  # 10 s of the run per second, for about a second
    assert viewer.page.input_value("#time") == str(viewer.js("tmemViewer.player.frame"))


def test_the_3d_gas_rotates_and_zooms(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("gas3d"), tmp_path / "gas3d.html"))
    assert viewer.page.inner_text("#chart-pairs").startswith("No formation pairs")
    world, screen = viewer.drawn(), viewer.screen()
    box = viewer.page.locator("#view canvas").bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    viewer.page.mouse.move(cx, cy)
    viewer.page.mouse.down()
    viewer.page.mouse.move(cx + 200, cy + 60, steps=10)
    viewer.page.mouse.up()
    rotated = viewer.screen()
    assert np.linalg.norm(rotated - screen, axis=1).mean() > 20
    assert viewer.drawn() == world  # the view turned, not the agents
    viewer.page.mouse.wheel(0, -600)
    viewer.page.wait_for_timeout(200)
    assert viewer.screen().std(axis=0).sum() > 1.2 * rotated.std(axis=0).sum()
    viewer.page.mouse.wheel(0, 600)
    viewer.page.click("#show-spheres")
    viewer.slide_to_end()
    assert_drawn_as_in_file(viewer, runs("gas3d"))
    image = viewer.screenshot(ROOT / "docs" / "images" / "viewer-3d.png")
    assert image.shape == (VIEWPORT["height"], VIEWPORT["width"], 3)
    assert pixels_near(image, AGENT, tolerance=20) > 300 * 4


def test_a_removed_agent_is_shown_removed_where_it_stopped(open_view, runs, tmp_path):
    run = runs("ring8_loss")
    viewer = open_view(write_view(run, tmp_path / "ring.html"))
    assert all(a["flying"] for a in viewer.drawn())
    viewer.slide_to_end()
    removed = [a for a in viewer.drawn() if not a["flying"]]
    assert [a["agent"] for a in removed] == [4]  # the scenario's agent 3, numbered from 1
    assert_drawn_as_in_file(viewer, run)
    with open_file(run) as ds:
        stopped = int(np.flatnonzero(ds["active"].values[3] == 0)[0])
        np.testing.assert_allclose(removed[0]["position"], file_positions(ds)[stopped, 3], atol=0.01)  # where it stopped
    image = viewer.screenshot(tmp_path / "ring.png")
    assert pixels_near(image, REMOVED, tolerance=12) > 20


def test_a_1d_run_shows_its_two_agents_on_the_line(open_view, runs, tmp_path):
    run = runs("fig9")
    viewer = open_view(write_view(run, tmp_path / "fig9.html"))
    assert [len(a["position"]) for a in viewer.drawn()] == [1, 1]
    viewer.page.focus("#time")
    viewer.page.keyboard.press("PageUp")
    assert_drawn_as_in_file(viewer, run)
    assert viewer.js("tmemViewer.cursors()")[1] is not None  # the pair's distance panel
    assert pixels_near(viewer.screenshot(tmp_path / "fig9.png"), AGENT) > 2 * 30


def test_a_thinned_page_says_what_it_shows(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("gas3d"), tmp_path / "thin.html", max_agents=50, max_frames=40))
    assert viewer.page.is_visible("#note")
    assert viewer.page.inner_text("#note") == (
        "Shown: 50 of 300 agents, evenly chosen by number; 40 of 601 recorded times, evenly spaced."
    )
    assert len(viewer.drawn()) == 50


def tick_scale(axes: list[dict], axis: str) -> tuple[float, float]:
    """Pixels per metre and the pixel of 0 on ``axis``, fitted to the values the page writes along it."""
    ticks = [(t["value"], t["x"] if axis == "x" else t["y"]) for t in axes if t["axis"] == axis and t["value"] is not None]
    assert len(ticks) >= 3, (axis, ticks)
    values, pixels = np.array(ticks).T
    slope, offset = np.polyfit(values, pixels, 1)
    assert np.abs(slope * values + offset - pixels).max() < 0.01  # evenly spaced, one scale
    return slope, offset


def assert_ticks_read_the_agents(viewer, axes_shown: str):
    """Each agent's place on the screen, read off the axes' values, is its position in the file."""
    axes = viewer.js("tmemViewer.axes()")
    names = {t["text"] for t in axes if t["value"] is None}
    assert names == {f"{a}, m" for a in axes_shown}
    for k, axis in enumerate(axes_shown):
        slope, offset = tick_scale(axes, axis)
        world = np.array([a["position"][k] for a in viewer.drawn()])
        np.testing.assert_allclose(slope * world + offset, viewer.screen()[:, k], atol=1.0)  # within a pixel
        assert (slope > 0) == (axis == "x")  # y grows up the screen


def test_the_plane_view_has_its_axes_values_and_names_and_they_follow_a_zoom(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("hex19"), tmp_path / "hex19.html"))
    assert_ticks_read_the_agents(viewer, "xy")
    step = np.diff(sorted(t["value"] for t in viewer.js("tmemViewer.axes()") if t["axis"] == "x" and t["value"] is not None))
    box = viewer.page.locator("#view canvas").bounding_box()
    viewer.page.mouse.move(box["x"] + box["width"] / 3, box["y"] + box["height"] / 2)
    for _ in range(6):  # zoom in, about 4 times
        viewer.page.mouse.wheel(0, -600)
        viewer.page.wait_for_timeout(100)
    assert_ticks_read_the_agents(viewer, "xy")
    zoomed = np.diff(sorted(t["value"] for t in viewer.js("tmemViewer.axes()") if t["axis"] == "x" and t["value"] is not None))
    assert zoomed[0] < step[0]  # finer values once zoomed in
    # The hex is left oscillating: its ΔRMS is marked, and the page says why, as the printed table does.
    assert viewer.page.is_visible("#caveat") and "swings with their oscillation" in viewer.page.inner_text("#caveat")


def test_the_line_view_has_its_x_values(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("fig9"), tmp_path / "fig9.html"))
    assert_ticks_read_the_agents(viewer, "x")
    assert not viewer.page.is_visible("#caveat")  # the pair uncoupled before the end


def test_the_3d_view_names_each_axis_with_its_range(open_view, runs, tmp_path):
    run = runs("gas3d")
    viewer = open_view(write_view(run, tmp_path / "gas3d.html"))
    texts = {t["axis"]: t["text"] for t in viewer.js("tmemViewer.axes()")}
    scenario = load(ROOT / "examples" / "swarm" / "gas3d.toml")
    radius, box = scenario.interaction.radius, scenario.space.box
    with open_file(run) as ds:
        positions = file_positions(ds)
    for k, axis in enumerate("xyz"):
        low = min(positions[..., k].min(), 0.0) - radius  # the page's frame: every position and the box, R beyond
        high = max(positions[..., k].max(), box[k]) + radius
        assert texts[axis] == f"{axis}, m: {low:.0f} to {high:.0f}"


def test_a_mission_shows_its_route_goal_and_obstacle(open_view, runs, tmp_path):
    viewer = open_view(write_view(runs("route3"), tmp_path / "route3.html"))
    for entry in ("#legend-obstacle", "#legend-route", "#legend-goal"):
        assert viewer.page.is_visible(entry), entry
    image = viewer.screenshot(tmp_path / "route3.png")
    box = viewer.page.locator("#view canvas").bounding_box()

    def around(point, half):
        x, y = np.array(viewer.js(f"tmemViewer.project({point})")) + [box["x"], box["y"]]
        return image[int(y) - half : int(y) + half + 1, int(x) - half : int(x) + half + 1]

    assert pixels_near(around([30.0, 40.0], 12), GOAL, tolerance=30) > 40  # the goal's ring
    assert pixels_near(around([30.0, 25.0], 3), ROUTE_LINE, tolerance=20) > 5  # on the way between the waypoints
    obstacle = around([40.0, 80.0], 2).reshape(-1, 3)  # the obstacle's middle: light grey
    assert (np.ptp(obstacle, axis=1) < 8).all() and (obstacle < 240).all() and (obstacle > 180).all()
    plain = open_view(write_view(runs("hex19"), tmp_path / "hex19.html"))
    assert plain.js("tmemViewer.run.route === undefined") and not plain.page.is_visible("#legend-route")
