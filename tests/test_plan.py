"""tmem.plan against brute force and closed forms: CAPT's assignment, trajectories and guarantee,
the target shapes, routes around circular obstacles and spaced random starts."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

from tmem.plan import assignment as capt
from tmem.plan import shapes
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
