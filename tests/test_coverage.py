"""Coverage of a bounded field (tmem.analysis.coverage), checked against closed forms and hand counts."""

import math

import numpy as np
import pytest

from tmem.analysis.coverage import MAX_CELLS, Coverage, coverage, plot_coverage


def _run(points, times=None, active=None, box=(10.0, 10.0), cell=1.0, **options) -> Coverage:
    """Coverage of agents at ``points``, shape (records, agents, axes); one record a second by default."""
    points = np.asarray(points, dtype=float)
    times = np.arange(len(points), dtype=float) if times is None else np.asarray(times, dtype=float)
    active = np.ones(points.shape[:2], dtype=bool) if active is None else np.asarray(active)
    return coverage(points, times, active, box, cell, **options)


def _visited(cov: Coverage) -> set[tuple[int, ...]]:
    return {tuple(int(i) for i in index) for index in np.argwhere(np.isfinite(cov.first_visit))}


def _dense_cells(start, end, cell=1.0, n=200_001) -> set[tuple[int, ...]]:
    """The cells under ``n`` points evenly along a segment: the expectation, computed without tmem."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    points = np.asarray(start, float) + s * (np.asarray(end, float) - np.asarray(start, float))
    return {tuple(int(i) for i in index) for index in np.unique(np.floor(points / cell).astype(int), axis=0)}


# --- segments between records -------------------------------------------------------------------


def test_one_coarse_segment_across_the_field_visits_exactly_its_row():
    cov = _run([[[0.5, 4.5]], [[9.5, 4.5]]], times=[0.0, 9.0], periodic=False)
    assert _visited(cov) == {(i, 4) for i in range(10)}
    assert cov.share.tolist() == [0.01, 0.1]
    # at 1 m/s from x = 0.5 the agent enters cell i (x = i) at t = i - 0.5
    assert cov.first_visit[:, 4] == pytest.approx([0.0] + [i - 0.5 for i in range(1, 10)])


def test_a_coarse_segment_visits_what_a_fine_trajectory_visits():
    start, end = np.array([0.2, 0.3]), np.array([7.7, 5.1])
    coarse = _run([[start], [end]], times=[0.0, 10.0], periodic=False)
    s = np.linspace(0.0, 1.0, 1001)
    fine = _run((start + s[:, None] * (end - start))[:, None, :], times=10.0 * s)
    assert _visited(coarse) == _visited(fine) == _dense_cells(start, end)
    assert len(_visited(coarse)) == 13  # 8 columns + 5 rows entered + the first cell, no corner hit
    assert coarse.first_visit == pytest.approx(fine.first_visit, abs=10.0 / 1000, nan_ok=True)
    assert coarse.share[-1] == fine.share[-1] == 0.13


def test_with_a_sensor_radius_the_record_rate_does_not_matter_either():
    start, end = np.array([2.0, 3.0]), np.array([8.0, 6.5])
    coarse = _run([[start], [end]], sensor_radius=1.5, periodic=False)
    s = np.linspace(0.0, 1.0, 501)
    fine = _run((start + s[:, None] * (end - start))[:, None, :], times=s, sensor_radius=1.5)
    assert _visited(coarse) == _visited(fine)
    assert coarse.share[-1] > 2 * _run([[start], [start]], sensor_radius=1.5).share[-1]


def test_share_never_decreases_and_stays_at_most_one():
    rng = np.random.default_rng(3)
    steps = rng.normal(0.0, 0.8, size=(60, 5, 2))
    points = np.mod(np.cumsum(steps, axis=0) + 5.0, 10.0)  # a random walk in a periodic box
    for radius in (0.0, 1.2):
        cov = _run(points, sensor_radius=radius)
        assert np.all(np.diff(cov.share) >= 0)
        assert 0 < cov.share[0] <= cov.share[-1] <= 1
        assert cov.share[-1] == np.count_nonzero(np.isfinite(cov.first_visit)) / cov.field.sum()
        # share[k] counts the cells first visited at or before record k
        counts = [np.count_nonzero(cov.first_visit <= t) for t in cov.time]
        assert cov.share.tolist() == pytest.approx(np.array(counts) / 100)


def test_an_agent_seeing_everything_covers_all_of_the_field():
    cov = _run([[[5.0, 5.0]]], sensor_radius=20.0)
    assert cov.share.tolist() == [1.0]
    assert cov.time_to(1.0) == 0.0


# --- obstacles ----------------------------------------------------------------------------------


def test_obstacle_cells_are_not_in_the_field_nor_in_the_share():
    # centres at 0.5 and 1.5 m from (5, 5) on each axis: inside r = 2 when dx^2 + dy^2 < 4,
    # i.e. (0.5, 0.5) x4, (0.5, 1.5) x4, (1.5, 0.5) x4; (1.5, 1.5) is at 2.12 m: outside.
    obstacles = [((5.0, 5.0), 2.0)]
    blocked = {(i, j) for i in (3, 4, 5, 6) for j in (4, 5)} | {(i, j) for i in (4, 5) for j in (3, 6)}
    assert len(blocked) == 12
    cov = _run([[[5.0, 5.0]]], sensor_radius=20.0, obstacles=obstacles)
    assert {(int(i), int(j)) for i, j in np.argwhere(~cov.field)} == blocked
    assert cov.field.sum() == 88
    assert cov.share.tolist() == [1.0]  # every field cell seen: the blocked ones do not count
    assert _visited(cov) == {(i, j) for i in range(10) for j in range(10)} - blocked
    # along row 5 through the obstacle: 10 cells crossed, 4 of them blocked
    row = _run([[[0.5, 5.5]], [[9.5, 5.5]]], obstacles=obstacles, periodic=False)
    assert _visited(row) == {(i, 5) for i in (0, 1, 2, 7, 8, 9)}
    assert row.share[-1] == pytest.approx(6 / 88)


def test_obstacles_on_a_line_of_cells():
    cov = _run([[[0.5]], [[9.5]]], box=(10.0,), obstacles=[((5.0,), 1.2)], periodic=False)
    assert cov.first_visit.shape == cov.field.shape == (10,)
    assert np.flatnonzero(~cov.field).tolist() == [4, 5]  # centres 4.5 and 5.5 within 1.2 m of 5
    assert cov.share[-1] == 1.0
    assert _run([[[0.5]], [[9.5]]], box=(10.0,)).share.tolist() == [0.1, 0.2]  # default: a wrap


# --- time_to ------------------------------------------------------------------------------------


def test_time_to_is_when_the_cell_reaching_the_share_is_entered():
    """Between records the agent flies 3 cells in 2 s: it enters cell k (k = 1..9) at 2 (k - 1/2) / 3 s."""
    times = [0.0, 2.0, 4.0, 6.0]  # 1 cell, then 3 more a record: 1, 4, 7, 10 cells of 100
    cov = _run([[[0.5, 0.5]], [[3.5, 0.5]], [[6.5, 0.5]], [[9.5, 0.5]]], times=times)
    assert cov.share.tolist() == [0.01, 0.04, 0.07, 0.1]
    assert cov.time_to(0.0) == 0.0
    assert cov.time_to(0.01) == 0.0
    assert cov.time_to(0.02) == pytest.approx(1.0 / 3.0)
    assert cov.time_to(0.04) == pytest.approx(5.0 / 3.0)
    assert cov.time_to(0.05) == pytest.approx(7.0 / 3.0)
    assert cov.time_to(0.1) == pytest.approx(17.0 / 3.0)
    assert cov.time_to(0.11) is None
    assert cov.time_to(1.0) is None
    with pytest.raises(ValueError, match="^share:"):
        cov.time_to(math.nan)


# --- sensor radius ------------------------------------------------------------------------------


def test_a_stationary_agent_covers_a_disc_of_the_sensor_radius():
    cov = _run(np.full((3, 1, 2), 50.0), box=(100.0, 100.0), sensor_radius=30.0)
    expected = math.pi * 30.0**2 / 100.0**2
    assert cov.share[-1] == pytest.approx(expected, rel=0.02)
    assert np.all(cov.share == cov.share[0])  # it stays: nothing new
    i, j = np.argwhere(np.isfinite(cov.first_visit)).T
    assert np.max(np.hypot(i + 0.5 - 50.0, j + 0.5 - 50.0)) <= 30.0


def test_with_no_sensor_radius_an_agent_visits_only_the_cell_it_is_in():
    cov = _run([[[3.7, 8.2]]])
    assert _visited(cov) == {(3, 8)}
    assert _run([[[3.7, 8.2]]], sensor_radius=0.3).share[-1] == 0  # no centre within 0.3 m


# --- activity, wraps, edges of the region -------------------------------------------------------


def test_inactive_agents_visit_nothing():
    points = [[[0.5, 0.5], [0.5, 9.5]], [[4.5, 0.5], [4.5, 9.5]]]
    only_first = _run(points, active=[[True, False], [True, False]])
    assert _visited(only_first) == {(i, 0) for i in range(5)}
    assert _run(points, active=np.zeros((2, 2), bool), sensor_radius=3.0).share.tolist() == [0.0, 0.0]
    # active at both ends but not in between: no segment is drawn through the gap
    gap = _run([[[0.5, 0.5]], [[2.5, 0.5]], [[4.5, 0.5]]], active=[[True], [False], [True]])
    assert _visited(gap) == {(0, 0), (4, 0)}


def test_a_periodic_wrap_is_not_a_flight_across_the_field():
    points = [[[9.5, 2.5]], [[0.5, 2.5]]]  # 9 m in one record in a 10 m box: wrapped
    assert _visited(_run(points)) == {(9, 2), (0, 2)}
    assert _visited(_run(points, sensor_radius=0.6)) == {(9, 2), (0, 2)}
    assert _visited(_run(points, periodic=False)) == {(i, 2) for i in range(10)}
    assert _visited(_run([[[9.5, 2.5]], [[5.0, 2.5]]])) == {(i, 2) for i in range(5, 10)}  # 4.5 m: flown


def test_positions_outside_the_region_visit_nothing():
    assert _run([[[-0.5, 4.5]], [[10.5, 4.5]], [[4.5, -3.0]]]).share.tolist() == [0.0, 0.0, 0.0]
    assert _run([[[10.5, 4.5]]], sensor_radius=2.0).share.tolist() == [0.0]
    assert _visited(_run([[[10.0, 10.0]]])) == {(9, 9)}  # on the far edge: the last cell
    # a segment from outside visits only its part inside
    assert _visited(_run([[[-3.0, 4.5]], [[1.5, 4.5]]])) == {(0, 4), (1, 4)}


def test_three_axes_cover_in_x_and_y():
    cov = _run([[[0.5, 0.5, 7.0]], [[3.5, 0.5, 2.0]]], box=(10.0, 10.0, 10.0))
    assert cov.first_visit.shape == (10, 10)
    assert _visited(cov) == {(i, 0) for i in range(4)}
    assert cov.box == (10.0, 10.0, 10.0)


def test_a_side_that_is_not_a_multiple_of_the_cell():
    cov = _run([[[0.1, 0.1]]], box=(0.3, 1.05), cell=0.1)
    assert cov.first_visit.shape == (3, 11)


# --- bad input ----------------------------------------------------------------------------------

_P = np.zeros((2, 1, 2))
_T = np.array([0.0, 1.0])
_A = np.ones((2, 1), bool)


@pytest.mark.parametrize(
    ("change", "argument"),
    [
        (dict(cell=0.0), "cell"),
        (dict(cell=-1.0), "cell"),
        (dict(cell=math.nan), "cell"),
        (dict(cell=math.inf), "cell"),
        (dict(cell=1e-4), "cell"),  # 1e10 cells
        (dict(box=(10.0,)), "box"),
        (dict(box=(10.0, 10.0, 10.0)), "box"),
        (dict(box=(10.0, 0.0)), "box"),
        (dict(box=(10.0, math.inf)), "box"),
        (dict(positions=np.zeros((2, 1))), "positions"),
        (dict(positions=np.zeros((2, 1, 4))), "positions"),
        (dict(positions=np.zeros((0, 1, 2)), time=np.zeros(0), active=np.ones((0, 1), bool)), "positions"),
        (dict(time=np.zeros(3)), "time"),
        (dict(time=np.array([1.0, 0.0])), "time"),
        (dict(time=np.array([0.0, math.nan])), "time"),
        (dict(active=np.ones((2, 2), bool)), "active"),
        (dict(sensor_radius=-1.0), "sensor_radius"),
        (dict(sensor_radius=math.nan), "sensor_radius"),
        (dict(obstacles=[((5.0,), 1.0)]), r"obstacles\[0\]"),
        (dict(obstacles=[((5.0, 5.0), -1.0)]), r"obstacles\[0\]"),
        (dict(obstacles=[(1.0, 2.0, 3.0)]), r"obstacles\[0\]"),
        (dict(obstacles=[((5.0, 5.0), 100.0)]), "obstacles"),  # no field left
    ],
)
def test_bad_input_names_the_argument(change, argument):
    arguments = dict(positions=_P, time=_T, active=_A, box=(10.0, 10.0), cell=1.0) | change
    with pytest.raises(ValueError, match=f"^{argument}:"):
        coverage(**arguments)


def test_the_largest_grid_is_allowed():
    assert MAX_CELLS >= 5e7
    side = math.sqrt(MAX_CELLS) * 1.01
    with pytest.raises(ValueError, match="^cell:.*cells"):
        coverage(_P, _T, _A, (side, side), 1.0)


# --- the figure ---------------------------------------------------------------------------------


@pytest.mark.interface
def test_plot_coverage_draws_one_image_with_a_colour_bar():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    obstacles = [((5.0, 5.0), 2.0)]
    cov = _run([[[0.5, 0.5]], [[4.5, 3.5]], [[9.5, 9.5]]], obstacles=obstacles)
    fig = plot_coverage(cov, obstacles=obstacles, title="$x^$ [b]")
    main = fig.axes[0]
    assert len(main.images) == 1
    image = main.images[0]
    assert image.origin == "lower"
    assert list(image.get_extent()) == [0.0, 10.0, 0.0, 10.0]
    assert np.isnan(np.ma.filled(image.get_array(), np.nan)).sum() == 100 - np.isfinite(cov.first_visit).sum()
    assert image.get_array()[0, 0] == 0.0  # drawn as (y, x): cell (0, 0) first visited at 0 s
    assert len(fig.axes) == 2 and fig.axes[1].get_ylabel() == "first visit (s)"
    assert len(main.patches) == 1
    assert main.get_title() == "$x^$ [b]"
    fig.savefig(__import__("io").BytesIO(), format="png")


@pytest.mark.interface
def test_plot_coverage_on_given_axes_and_on_a_line():
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure

    ax = Figure().subplots()
    cov = _run([[[0.5]], [[3.5]]], box=(10.0,))
    assert plot_coverage(cov, ax=ax, obstacles=[((7.0,), 1.0)]) is ax.figure
    assert len(ax.images) == 1 and "coverage" in ax.get_title()
