"""tmem.plan against brute force and closed forms: CAPT's assignment, trajectories and guarantee,
the target shapes, routes around circular obstacles and spaced random starts."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist, pdist

from tmem.plan import assignment as capt
from tmem.plan import route, shapes, starts
from tmem.world import formation

# --- assignment (CAPT) ---------------------------------------------------------------------------


def _brute_cost(starts: np.ndarray, goals: np.ndarray) -> float:
    """The least sum of squared distances over every injection of starts into goals."""
    cost = cdist(starts, goals, "sqeuclidean")
    rows = np.arange(len(starts))
    return min(cost[rows, list(p)].sum() for p in itertools.permutations(range(len(goals)), len(starts)))


@pytest.mark.parametrize("n, m, axes", [(1, 1, 2), (3, 3, 2), (5, 5, 3), (6, 7, 2), (7, 7, 2), (4, 7, 3), (7, 7, 1)])
def test_assign_matches_the_brute_force_minimum(n, m, axes):
    rng = np.random.default_rng(100 * n + m + axes)
    for _ in range(3):
        starts, goals = rng.uniform(-10, 10, (n, axes)), rng.uniform(-10, 10, (m, axes))
        chosen = capt.assign(starts, goals)
        assert chosen.shape == (n,) and len(set(chosen.tolist())) == n and chosen.min() >= 0 and chosen.max() < m
        cost = capt.assignment_cost(starts, goals, chosen)
        assert cost == pytest.approx(_brute_cost(starts, goals), rel=1e-12, abs=1e-12)
        rows, cols = linear_sum_assignment(cdist(starts, goals, "sqeuclidean"))
        assert cost == pytest.approx(cdist(starts, goals, "sqeuclidean")[rows, cols].sum(), rel=1e-12)


def test_assign_refuses_more_starts_than_goals_and_bad_shapes():
    with pytest.raises(ValueError, match="3 starts cannot go to 2 goals"):
        capt.assign(np.zeros((3, 2)), np.ones((2, 2)))
    with pytest.raises(ValueError, match="starts have 2 axes and goals 3"):
        capt.assign(np.zeros((2, 2)), np.ones((2, 3)))
    with pytest.raises(ValueError, match=r"goals must have shape \(n, axes\)"):
        capt.assign(np.zeros((2, 2)), np.ones(4))
    with pytest.raises(ValueError, match="distinct goals"):
        capt.capt_clearance(np.zeros((2, 2)), np.ones((2, 2)), np.array([1, 1]))


@pytest.mark.parametrize("profile", ["cubic", "quintic"])
def test_the_trajectories_run_from_starts_to_goals_with_zero_end_velocity(profile):
    rng = np.random.default_rng(7)
    starts, goals = rng.uniform(0, 50, (6, 2)), rng.uniform(0, 50, (8, 2))
    chosen = capt.assign(starts, goals)
    at, speed = capt.capt_trajectory(starts, goals, chosen, 4.0, np.array([-1.0, 0.0, 4.0, 5.0]), profile)
    assert at.shape == (4, 6, 2)
    np.testing.assert_allclose(at[:2], [starts, starts], atol=1e-12)
    np.testing.assert_allclose(at[2:], [goals[chosen], goals[chosen]], atol=1e-12)
    np.testing.assert_allclose(speed, 0.0, atol=1e-12)
    times = np.linspace(0.0, 4.0, 4001)
    at, speed = capt.capt_trajectory(starts, goals, chosen, 4.0, times, profile)
    np.testing.assert_allclose(np.gradient(at, times, axis=0)[1:-1], speed[1:-1], atol=1e-4)
    middle, _ = capt.capt_trajectory(starts, goals, chosen, 4.0, 2.0, profile)
    np.testing.assert_allclose(middle, 0.5 * (starts + goals[chosen]), atol=1e-12)  # both profiles: beta(1/2) = 1/2


@pytest.mark.parametrize("profile", ["cubic", "quintic"])
def test_the_duration_meets_the_limits_and_is_the_shortest(profile):
    rng = np.random.default_rng(11)
    starts, goals = rng.uniform(0, 80, (10, 3)), rng.uniform(0, 80, (10, 3))
    chosen = capt.assign(starts, goals)
    for v_max, a_max in [(2.0, 10.0), (20.0, 0.5), (5.0, 2.0)]:
        duration = capt.capt_duration(starts, goals, chosen, v_max, a_max, profile)
        times = np.linspace(0.0, duration, 20001)
        _, velocity = capt.capt_trajectory(starts, goals, chosen, duration, times, profile)
        speed = np.linalg.norm(velocity, axis=2)
        accel = np.linalg.norm(np.gradient(velocity, times, axis=0), axis=2)[1:-1]
        assert speed.max() <= v_max * (1 + 1e-9) and accel.max() <= a_max * (1 + 1e-3)
        assert speed.max() >= v_max * (1 - 1e-6) or accel.max() >= a_max * (1 - 1e-3)  # one limit is reached
    if profile == "cubic":
        longest = np.linalg.norm(goals[chosen] - starts, axis=1).max()
        assert capt.capt_duration(starts, goals, chosen, 5.0, 2.0) == pytest.approx(
            max(1.5 * longest / 5.0, math.sqrt(6 * longest / 2.0)))
    assert capt.capt_duration(starts, starts, np.arange(10), 1.0, 1.0) == 0.0


def test_the_clearance_closed_form_matches_dense_sampling():
    rng = np.random.default_rng(3)
    for n, axes in [(2, 2), (5, 2), (9, 3), (12, 2)]:
        starts, goals = rng.uniform(0, 20, (n, axes)), rng.uniform(0, 20, (n + 2, axes))
        for chosen in (capt.assign(starts, goals), rng.permutation(n + 2)[:n]):
            i, j = np.triu_indices(n, 1)
            a, c = starts[i] - starts[j], goals[chosen][i] - goals[chosen][j]
            beta = np.linspace(0.0, 1.0, 100_001)[:, None, None]
            sampled = np.linalg.norm((1 - beta) * a + beta * c, axis=2).min()
            closed = capt.capt_clearance(starts, goals, chosen)
            assert closed <= sampled + 1e-12
            assert closed == pytest.approx(sampled, abs=1e-6)
    assert capt.capt_clearance(np.zeros((1, 2)), np.ones((1, 2)), [0]) == math.inf


def test_the_clearance_is_exact_on_a_crossing():
    starts = np.array([[0.0, 0.0], [10.0, 1.0]])
    goals = np.array([[10.0, 0.0], [0.0, 1.0]])  # a head-on pass 1 m apart, the pair swapped
    assert capt.capt_clearance(starts, goals, np.array([0, 1])) == pytest.approx(1.0)


def test_capt_guarantee_holds_on_random_separated_cases():
    rng = np.random.default_rng(2024)
    radius, checked = 0.5, 0
    limit = 2 * math.sqrt(2) * radius
    while checked < 60:
        n, axes = int(rng.integers(2, 30)), int(rng.integers(2, 4))
        m = n + int(rng.integers(0, 5))
        side = limit * (n ** (1 / axes)) * 2.0
        starts, goals = rng.uniform(0, side, (n, axes)), rng.uniform(0, side, (m, axes))
        if not capt.capt_safe(starts, goals, radius):
            continue
        checked += 1
        assert capt.capt_clearance(starts, goals, capt.assign(starts, goals)) > 2 * radius


def test_capt_guarantee_is_tight():
    """Two agents swapping across a square of side ``Delta / sqrt 2`` meet ``Delta / sqrt 2`` apart at mid-flight."""
    radius = 1.0
    spacing = 2 * math.sqrt(2) * radius * (1 + 1e-6)
    starts = np.array([[0.0, 0.0], [spacing, 0.0]])
    goals = np.array([[spacing / 2, spacing / 2], [spacing / 2, -spacing / 2]])
    assert capt.capt_safe(starts, goals, radius)
    clearance = capt.capt_clearance(starts, goals, capt.assign(starts, goals))
    assert clearance > 2 * radius and clearance == pytest.approx(spacing / math.sqrt(2), rel=1e-12)


def test_capt_safe_tests_the_separation():
    starts = np.array([[0.0, 0.0], [3.0, 0.0]])
    goals = np.array([[0.0, 5.0], [2.0, 5.0], [9.0, 9.0]])
    assert capt.capt_safe(starts, goals, 0.7) is True  # 2 sqrt 2 * 0.7 = 1.98 < 2
    assert capt.capt_safe(starts, goals, 0.71) is False  # 2.008 > 2 (the goals)
    with pytest.raises(ValueError, match="2 starts cannot go to 1 goals"):
        capt.capt_safe(starts, goals[:1], 0.0)


# --- shapes -------------------------------------------------------------------------------------


def _nearest(offsets: np.ndarray) -> np.ndarray:
    """Each slot's distance to its nearest other slot."""
    distance = cdist(offsets, offsets)
    np.fill_diagonal(distance, np.inf)
    return distance.min(axis=1)


def _brute_edges(offsets: np.ndarray, spacing: float) -> set[tuple[int, int]]:
    distance = cdist(offsets, offsets)
    return {(i, j) for i, j in zip(*np.nonzero(np.isclose(distance, spacing, rtol=1e-9, atol=0))) if i < j}


@pytest.mark.parametrize("rings, count, edges", [(0, 1, 0), (1, 7, 12), (2, 19, 42), (3, 37, 90), (4, 61, 156)])
def test_full_hexagons_have_their_counts_and_edges(rings, count, edges):
    slots = shapes.hex_slots(rings=rings, spacing=2.5)
    assert shapes.hex_count(rings) == count and slots.offsets.shape == (count, 2)
    assert len(slots.edges) == edges == 3 * rings * (3 * rings + 1)
    if count > 1:
        np.testing.assert_allclose(_nearest(slots.offsets), 2.5, rtol=1e-12)
    np.testing.assert_allclose(slots.offsets.mean(axis=0), 0.0, atol=1e-12)
    assert set(map(tuple, slots.edges.tolist())) == _brute_edges(slots.offsets, 2.5)
    same = shapes.hex_slots(count, 2.5)
    np.testing.assert_array_equal(same.offsets, slots.offsets)
    np.testing.assert_array_equal(same.edges, slots.edges)


def test_hex_slots_are_the_formation_patch_and_its_lattice_edges():
    for n in (5, 19, 30):
        patch, slots = formation.hex_patch(n, 3.0, 3), shapes.hex_slots(n, 3.0, axes=3)
        np.testing.assert_array_equal(slots.offsets, patch.positions)
        np.testing.assert_array_equal(slots.edges, patch.edges)
    with pytest.raises(ValueError, match="either n"):
        shapes.hex_slots(7, 1.0, rings=1)
    with pytest.raises(ValueError, match="spacing must be"):
        shapes.hex_slots(7, 0.0)


@pytest.mark.parametrize("heading", [0.0, 0.3, math.pi / 2, 2.0])
def test_line_slots_lie_along_the_heading(heading):
    slots = shapes.line_slots(6, 4.0, heading)
    assert slots.offsets.shape == (6, 2) and len(slots.edges) == 5
    np.testing.assert_array_equal(slots.edges, [[k, k + 1] for k in range(5)])
    steps = np.diff(slots.offsets, axis=0)
    np.testing.assert_allclose(steps, np.tile([4 * math.cos(heading), 4 * math.sin(heading)], (5, 1)), atol=1e-12)
    np.testing.assert_allclose(slots.offsets.mean(axis=0), 0.0, atol=1e-12)
    assert shapes.line_slots(1, 4.0).edges.shape == (0, 2)


@pytest.mark.parametrize("n", [3, 4, 5, 8, 13])
def test_ring_slots_are_a_polygon_of_side_spacing(n):
    slots = shapes.ring_slots(n, 5.0, axes=3)
    assert slots.offsets.shape == (n, 3) and len(slots.edges) == n
    np.testing.assert_allclose(_nearest(slots.offsets), 5.0, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(slots.offsets, axis=1), 5.0 / (2 * math.sin(math.pi / n)), rtol=1e-12)
    assert set(map(tuple, slots.edges.tolist())) == _brute_edges(slots.offsets, 5.0)


@pytest.mark.parametrize("rows, cols", [(1, 1), (1, 5), (3, 4), (6, 6)])
def test_grid_slots_count_spacing_and_edges(rows, cols):
    slots = shapes.grid_slots(rows, cols, 1.5)
    assert slots.offsets.shape == (rows * cols, 2)
    assert len(slots.edges) == 2 * rows * cols - rows - cols
    if rows * cols > 1:
        np.testing.assert_allclose(_nearest(slots.offsets), 1.5, rtol=1e-12)
    np.testing.assert_allclose(slots.offsets.mean(axis=0), 0.0, atol=1e-12)
    assert set(map(tuple, slots.edges.tolist())) == _brute_edges(slots.offsets, 1.5)
    with pytest.raises(ValueError, match="rows must be an integer >= 1"):
        shapes.grid_slots(0, cols, 1.5)


# --- routes around circular obstacles ------------------------------------------------------------


def _around_one_disc(start: np.ndarray, goal: np.ndarray, center: np.ndarray, rho: float) -> float:
    """The shortest path from ``start`` to ``goal`` around one disc whose chord blocks it: tangent, arc, tangent."""
    d1, d2 = np.linalg.norm(start - center), np.linalg.norm(goal - center)
    cosine = np.dot(start - center, goal - center) / (d1 * d2)
    arc = math.acos(np.clip(cosine, -1, 1)) - math.acos(rho / d1) - math.acos(rho / d2)
    return math.sqrt(d1**2 - rho**2) + math.sqrt(d2**2 - rho**2) + rho * arc


def _sampled_clearance(waypoints: np.ndarray, centers: np.ndarray, radii: np.ndarray, samples: int = 2001) -> float:
    """The least distance to an obstacle's edge over points sampled densely along every segment."""
    t = np.linspace(0.0, 1.0, samples)[:, None]
    points = np.concatenate([a + t * (b - a) for a, b in zip(waypoints[:-1], waypoints[1:])])
    return float((cdist(points, centers) - radii[None, :]).min())


def _corridor(seed: int, clearance: float, count: int = 10, width: float = 300.0, length: float = 1000.0):
    """``count`` obstacles of radius 20-60 m in a ``width x length`` corridor, none covering its two ends."""
    rng = np.random.default_rng(seed)
    start, goal = np.array([width / 2, 0.0]), np.array([width / 2, length])
    centers, radii = [], []
    while len(centers) < count:
        c, r = rng.uniform([0.0, 0.0], [width, length]), rng.uniform(20.0, 60.0)
        if min(np.linalg.norm(c - start), np.linalg.norm(c - goal)) > r + clearance:
            centers.append(c)
            radii.append(r)
    return start, goal, np.array(centers), np.array(radii)


def _grid_length(start, goal, centers, inflated, lower, upper, cell: float) -> float:
    """The shortest path on a grid of ``cell`` (16 neighbours: steps (1, 0), (1, 1), (2, 1) and their turns),
    every step tested against the inflated discs: an upper bound on the true shortest path."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    shape = np.round((np.asarray(upper) - lower) / cell).astype(int) + 1
    ix, iy = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
    points = np.stack([ix.ravel(), iy.ravel()], axis=1) * cell + lower
    steps = [(1, 0), (0, 1), (1, 1), (1, -1), (2, 1), (1, 2), (2, -1), (1, -2)]
    rows, cols, weights = [], [], []
    for dx, dy in steps:
        ok = (ix + dx < shape[0]) & (iy + dy >= 0) & (iy + dy < shape[1])
        a = np.ravel_multi_index((ix[ok], iy[ok]), shape)
        b = np.ravel_multi_index((ix[ok] + dx, iy[ok] + dy), shape)
        p, q = points[a], points[b]
        t = np.clip(np.einsum("skd,sd->sk", centers[None] - p[:, None], q - p) / np.sum((q - p) ** 2, axis=1)[:, None], 0, 1)
        gap = np.linalg.norm(p[:, None] + t[..., None] * (q - p)[:, None] - centers[None], axis=2)
        free = np.all(gap >= inflated[None], axis=1)
        rows.append(a[free]), cols.append(b[free]), weights.append(np.full(free.sum(), cell * math.hypot(dx, dy)))
    graph = coo_matrix((np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(points.shape[0],) * 2)
    index = [int(np.ravel_multi_index(tuple(np.round((p - lower) / cell).astype(int)), shape)) for p in (start, goal)]
    return float(dijkstra(graph.tocsr(), directed=False, indices=index[0])[index[1]])


def test_route_without_obstacles_is_the_straight_segment():
    waypoints = route.plan_route([0.0, 0.0], [30.0, 40.0], np.zeros((0, 2)), np.zeros(0), 5.0)
    np.testing.assert_array_equal(waypoints, [[0.0, 0.0], [30.0, 40.0]])
    assert route.route_length(waypoints) == 50.0
    off_the_line = route.plan_route([0.0, 0.0], [100.0, 0.0], [[50.0, 30.0]], [10.0], 5.0)
    assert len(off_the_line) == 2


@pytest.mark.parametrize("sides", [8, 16, 64])
@pytest.mark.parametrize("offset", [0.0, 7.0, -12.0])
def test_one_obstacle_on_the_line_costs_between_the_tangent_arc_path_and_its_polygon_bound(sides, offset):
    start, goal, center = np.array([0.0, 0.0]), np.array([200.0, 0.0]), np.array([90.0, offset])
    radius, clearance = 30.0, 10.0
    waypoints = route.plan_route(start, goal, center[None], [radius], clearance, sides=sides)
    np.testing.assert_array_equal(waypoints[[0, -1]], [start, goal])
    shortest = _around_one_disc(start, goal, center, radius + clearance)
    length = route.route_length(waypoints)
    assert shortest * (1 - 1e-12) <= length <= shortest / math.cos(math.pi / sides)
    assert route.route_clearance(waypoints, center[None], np.array([radius])) >= clearance * (1 - 1e-9)


@pytest.mark.parametrize("seed", range(8))
def test_corridor_routes_keep_the_clearance_by_dense_sampling(seed):
    clearance = 8.0
    start, goal, centers, radii = _corridor(seed, clearance)
    waypoints = route.plan_route(start, goal, centers, radii, clearance)
    np.testing.assert_array_equal(waypoints[[0, -1]], [start, goal])
    assert _sampled_clearance(waypoints, centers, radii) >= clearance - 1e-6
    assert route.route_clearance(waypoints, centers, radii) >= clearance - 1e-6
    assert route.route_length(waypoints) >= np.linalg.norm(goal - start)


@pytest.mark.parametrize("seed", range(3))
def test_corridor_routes_are_no_longer_than_a_fine_grid_path(seed):
    clearance, cell = 8.0, 5.0
    start, goal, centers, radii = _corridor(seed, clearance)
    ours = route.route_length(route.plan_route(start, goal, centers, radii, clearance))
    grid = _grid_length(start, goal, centers, radii + clearance, [-150.0, -100.0], [450.0, 1100.0], cell)
    assert ours <= grid * 1.01 + cell
    assert grid <= ours * 1.05 + 2 * cell  # and the grid is a fair judge: close behind, not far off


@pytest.mark.parametrize("seed", [100, 101, 103, 104, 105, 108])  # fields where the straight line is blocked
def test_small_fields_against_a_one_metre_grid(seed):
    clearance, cell = 2.0, 1.0
    start, goal, centers, radii = _corridor(seed, clearance, count=5, width=60.0, length=200.0)
    radii = radii / 4  # 5-15 m
    waypoints = route.plan_route(start, goal, centers, radii, clearance, sides=16)
    assert len(waypoints) > 2
    ours = route.route_length(waypoints)
    grid = _grid_length(start, goal, centers, radii + clearance, [-30.0, -20.0], [90.0, 220.0], cell)
    assert ours <= grid * 1.01 + cell


def test_route_refuses_a_start_or_goal_inside_an_obstacle_and_a_closed_way():
    with pytest.raises(ValueError, match=r"^start \(0, 0\) is 5 m from obstacle 0's centre, within its radius \+ clearance"):
        route.plan_route([0.0, 0.0], [100.0, 0.0], [[5.0, 0.0]], [3.0], 4.0)
    with pytest.raises(ValueError, match=r"^goal \(100, 0\) .* = 10 \+ 1 = 11 m$"):
        route.plan_route([0.0, 0.0], [100.0, 0.0], [[50.0, 50.0], [95.0, 0.0]], [1.0, 10.0], 1.0)
    angle = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    ring = 100.0 * np.stack([np.cos(angle), np.sin(angle)], axis=1)  # a closed fence of discs about the start
    with pytest.raises(ValueError, match="no route from start to goal keeps 2 m from the obstacles"):
        route.plan_route([0.0, 0.0], [300.0, 0.0], ring, np.full(24, 20.0), 2.0)


# --- spaced random starts -----------------------------------------------------------------------


@pytest.mark.parametrize("bounded", [True, False])
@pytest.mark.parametrize(
    "lower, upper, spacing",
    [([0.0, 0.0], [300.0, 1000.0], 30.0), ([-5.0, 10.0, 0.0], [45.0, 40.0, 20.0], 6.0), ([2.0], [80.0], 3.0)],
)
def test_the_poisson_fill_keeps_the_spacing_in_metres_on_either_path(lower, upper, spacing, bounded):
    """Both ways of sampling (the box itself, SciPy >= 1.15; the unit cube scaled) keep the spacing and the box."""
    points = starts._fill(np.array(lower), np.array(upper), spacing, np.random.default_rng(5), bounded)
    assert pdist(points).min() >= spacing
    assert np.all(points >= lower) and np.all(points <= upper)
    reach = 2 * spacing  # spread over the whole box: no side left empty
    assert np.all(points.min(axis=0) <= np.add(lower, reach)) and np.all(points.max(axis=0) >= np.subtract(upper, reach))


def test_spaced_points_are_spaced_inside_and_reproducible(monkeypatch):
    lower, upper = [0.0, 0.0], [300.0, 1000.0]
    points = starts.spaced_points(150, lower, upper, 25.0, seed=9)
    assert points.shape == (150, 2)
    assert pdist(points).min() >= 25.0
    assert np.all(points >= lower) and np.all(points <= upper)
    np.testing.assert_array_equal(points, starts.spaced_points(150, lower, upper, 25.0, seed=9))
    assert not np.array_equal(points, starts.spaced_points(150, lower, upper, 25.0, seed=10))
    monkeypatch.setattr(starts, "_bounded", lambda: False)  # the path of SciPy < 1.15
    older = starts.spaced_points(150, lower, upper, 25.0, seed=9)
    assert pdist(older).min() >= 25.0 and np.all(older >= lower) and np.all(older <= upper)
    assert starts.spaced_points(0, lower, upper, 25.0).shape == (0, 2)


def test_the_packing_bound_is_oler_and_admits_the_tight_packings():
    assert starts.packing_bound([0, 0], [1, 1], 1.0) == 4  # the square's corners
    assert starts.packing_bound([0, 0], [2, 2], 1.0) == 9  # a 3 x 3 grid
    assert starts.packing_bound([0], [10], 2.5) == 5
    assert starts.packing_bound([0, 0, 0], [1, 1, 1], 1.0) == 11  # sqrt 2 * 8 = 11.3 (8 corners fit)
    hexagon = shapes.hex_slots(rings=4, spacing=10.0).offsets  # 61 points 10 m apart
    assert starts.packing_bound(hexagon.min(axis=0), hexagon.max(axis=0), 10.0) >= 61
    area = 300.0 * 1000.0
    assert starts.packing_bound([0, 0], [300, 1000], 20.0) == math.floor(area / (math.sqrt(3) / 2 * 400) + 1300 / 20 + 1)


def test_spaced_points_refuse_what_cannot_fit():
    most = starts.packing_bound([0, 0], [100, 100], 10.0)
    assert most == math.floor(2 / math.sqrt(3) * 100 + 20 + 1)  # 136
    refusal = rf"^{most + 1} points cannot be 10 m apart in \[0, 100\] x \[0, 100\] m: at most {most} fit \(Oler bound\)$"
    with pytest.raises(ValueError, match=refusal):
        starts.spaced_points(most + 1, [0, 0], [100, 100], 10.0, seed=1)
    with pytest.raises(ValueError, match=r"^Poisson-disk sampling placed only \d+ points 10 m apart .* fewer than n = 130"):
        starts.spaced_points(130, [0, 0], [100, 100], 10.0, seed=1)  # under the bound, past a random sample
    with pytest.raises(ValueError, match="min_spacing must be"):
        starts.spaced_points(3, [0, 0], [100, 100], -1.0)
    with pytest.raises(ValueError, match="upper > lower"):
        starts.spaced_points(3, [0, 0], [100, 0], 1.0)
