"""tmem.analysis.field_metrics against brute force (plain loops over pairs, dense sampling of the straight
passes) on small random cases, and against closed forms: two agents, regular polygons, paths and
complete graphs, rotated copies of a shape."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
from scipy.linalg import orthogonal_procrustes
from scipy.spatial.transform import Rotation

from tmem.analysis import field_metrics as fm


def polygon(n: int, radius: float = 1.0, phase: float = 0.3) -> np.ndarray:
    """The vertices of a regular n-gon in the plane, shape (n, 2)."""
    angle = phase + 2 * np.pi * np.arange(n) / n
    return radius * np.column_stack([np.cos(angle), np.sin(angle)])


def random_case(seed: int, records: int = 6, agents: int = 7, axes: int = 3, inactive: float = 0.2):
    """Positions on a random walk, velocities (some zero), an active mask with some agents off."""
    rng = np.random.default_rng(seed)
    positions = rng.uniform(0, 3, (1, agents, axes)) + np.cumsum(rng.normal(0, 0.6, (records, agents, axes)), axis=0)
    velocities = rng.normal(size=(records, agents, axes))
    velocities[rng.random((records, agents)) < 0.15] = 0.0
    active = rng.random((records, agents)) >= inactive
    return positions, velocities, active


# --- brute force ---------------------------------------------------------------------------------


def brute_order(v, on):
    terms = []
    for i, j in itertools.permutations(range(len(v)), 2):
        si, sj = math.hypot(*v[i]), math.hypot(*v[j])
        if on[i] and on[j] and si > 0 and sj > 0:
            terms.append(sum(a * b for a, b in zip(v[i], v[j])) / (si * sj))
    return sum(terms) / len(terms) if terms else math.nan


def brute_pairs(points, on):
    return [(i, j, math.dist(points[i], points[j])) for i, j in itertools.combinations(range(len(points)), 2) if on[i] and on[j]]


def brute_groups(points, reach):
    """Connected groups by flooding, pair by pair."""
    label = list(range(len(points)))
    changed = True
    while changed:
        changed = False
        for i, j in itertools.combinations(range(len(points)), 2):
            if math.dist(points[i], points[j]) < reach and label[i] != label[j]:
                label[i] = label[j] = min(label[i], label[j])
                changed = True
    return len(set(label))


def brute_fiedler(points, reach):
    n = len(points)
    laplacian = [[0.0] * n for _ in range(n)]
    for i, j in itertools.combinations(range(n), 2):
        if math.dist(points[i], points[j]) < reach:
            laplacian[i][j] = laplacian[j][i] = -1.0
            laplacian[i][i] += 1.0
            laplacian[j][j] += 1.0
    return sorted(np.linalg.eigvals(np.array(laplacian)).real)[1]


def brute_encounters(positions, times, radius, active, samples=4001):
    """Encounters, closest pass and first entry, from each pair's distance sampled densely along the straight passes."""
    count, closest, first = 0, math.inf, math.inf
    for i, j in itertools.combinations(range(positions.shape[1]), 2):
        inside = False
        for t in range(len(positions)):
            if not (active[t, i] and active[t, j]):
                inside = False
                continue
            if t and active[t - 1, i] and active[t - 1, j]:
                s = np.linspace(0, 1, samples)[1:]
                a = positions[t - 1, i] + s[:, None] * (positions[t, i] - positions[t - 1, i])
                b = positions[t - 1, j] + s[:, None] * (positions[t, j] - positions[t - 1, j])
                path = [(times[t - 1] + f * (times[t] - times[t - 1]), math.dist(x, y)) for f, x, y in zip(s, a, b)]
            else:
                path = [(times[t], math.dist(positions[t, i], positions[t, j]))]
            for when, d in path:
                closest = min(closest, d)
                if d < radius and not inside:
                    count, first = count + 1, min(first, when)
                inside = d < radius
    return count, closest, first


# --- order ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(4))
def test_order_is_the_mean_over_ordered_pairs(seed):
    _, velocities, active = random_case(seed, agents=8)
    expected = [brute_order(v, on) for v, on in zip(velocities, active)]
    np.testing.assert_allclose(fm.order(velocities, active), expected, rtol=1e-12, atol=1e-12)


def test_order_of_two_agents_is_the_cosine_and_of_a_regular_fan_its_least():
    theta = 0.7
    two = np.array([[[2.0, 0.0], [3 * np.cos(theta), 3 * np.sin(theta)]]])
    assert fm.order(two)[0] == pytest.approx(np.cos(theta), abs=1e-14)
    for n in (3, 5, 8):  # unit vectors summing to zero: (0 - n) / (n (n - 1))
        assert fm.order(polygon(n)[None])[0] == pytest.approx(-1 / (n - 1), abs=1e-14)


def test_order_is_nan_with_fewer_than_two_moving():
    v = np.array([[[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]]])
    assert np.isnan(fm.order(v, np.array([[True, True, False]])))[0]
    assert fm.order(v)[0] == pytest.approx(0.0, abs=1e-15)  # the one at rest is left out


# --- separation ----------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(3))
def test_separations_are_the_least_pair_distance(seed):
    positions, _, active = random_case(seed)
    expected = [min((d for *_, d in brute_pairs(x, on)), default=math.nan) for x, on in zip(positions, active)]
    np.testing.assert_allclose(fm.separations(positions, active), expected, rtol=1e-12)
    assert fm.min_separation(positions, active) == pytest.approx(np.nanmin(expected), rel=1e-12)


def test_separation_of_a_regular_polygon_is_its_side():
    for n in (3, 6, 11):
        assert fm.separations(polygon(n, 2.5)[None])[0] == pytest.approx(2 * 2.5 * np.sin(np.pi / n), rel=1e-12)
    assert fm.min_separation(polygon(4)[None], np.array([[True, False, False, False]])) is None


# --- near misses and collisions ------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
def test_near_misses_count_each_encounter_once_along_the_passes(seed):
    positions, _, active = random_case(seed, records=7, agents=6, inactive=0.1)
    times = np.cumsum(np.random.default_rng(seed).uniform(0.1, 1.0, 7))
    for radius in (0.8, 1.6):
        found = fm.near_misses(positions, times, radius, active)
        count, closest, first = brute_encounters(positions, times, radius, active)
        assert found["count"] == count
        assert found["closest_pass"] == pytest.approx(closest, abs=1e-3)
        assert found["closest_pass"] <= closest + 1e-12
        assert found["first_time"] == (None if count == 0 else pytest.approx(first, abs=1e-3 * times[-1]))
        assert fm.collisions(positions, times, radius, active) == count


@pytest.mark.parametrize("seed", range(3))
def test_the_share_within_the_radius_is_counted_pair_by_pair(seed):
    positions, _, active = random_case(seed)
    found = fm.near_misses(positions, np.arange(len(positions)), 1.2, active)
    for t, (x, on) in enumerate(zip(positions, active)):
        pairs = brute_pairs(x, on)
        expected = sum(d < 1.2 for *_, d in pairs) / len(pairs) if pairs else math.nan
        np.testing.assert_allclose(found["pairs_within_share"][t], expected, rtol=1e-12)


def test_a_head_on_pass_between_two_records_is_caught_in_closed_form():
    # x from -1 to +1 and back across 0.1 m apart in y, over 2 s: |r|^2 = (2 - 4 s)^2 + 0.01.
    positions = np.array([[[-1.0, 0.0], [1.0, 0.1]], [[1.0, 0.0], [-1.0, 0.1]]])
    found = fm.near_misses(positions, np.array([0.0, 2.0]), 0.5)
    assert found["count"] == 1
    assert np.all(found["pairs_within_share"] == 0.0)  # neither record sees it
    assert found["closest_pass"] == pytest.approx(0.1, abs=1e-12)
    assert found["first_time"] == pytest.approx(2 * (2 - np.sqrt(0.24)) / 4, abs=1e-12)


def test_a_pair_inside_from_the_start_counts_once_and_again_when_it_comes_back():
    gaps = np.array([0.1, 0.2, 0.1, 2.0, 0.3, 0.3])
    positions = np.zeros((len(gaps), 2, 2))
    positions[:, 1, 1] = gaps  # along y, no pass between records comes closer than they do
    assert fm.near_misses(positions, np.arange(6.0), 0.5)["count"] == 2
    assert fm.near_misses(positions[:3], np.arange(3.0), 0.5) == {
        "count": 1, "pairs_within_share": pytest.approx([1.0, 1.0, 1.0]), "closest_pass": pytest.approx(0.1), "first_time": 0.0,
    }  # fmt: skip


# --- groups and connectivity ---------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(3))
def test_union_counts_the_groups_by_flooding(seed):
    positions, _, active = random_case(seed, agents=9)
    for reach in (1.0, 2.5):
        expected = [brute_groups(x[on], reach) for x, on in zip(positions, active)]
        np.testing.assert_array_equal(fm.union(positions, reach, active), expected)


def test_a_regular_polygon_is_one_group_above_its_side_and_apart_below_it():
    side = 2 * np.sin(np.pi / 7)
    assert fm.union(polygon(7)[None], side * 1.001)[0] == 1
    assert fm.union(polygon(7)[None], side * 0.999)[0] == 7
    line = np.array([[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]])  # exactly the range apart: not closer, so not joined
    assert fm.union(line, 1.0)[0] == 3
    assert fm.algebraic_connectivity(line, 1.0)[0] == 0.0


@pytest.mark.parametrize("seed", range(3))
def test_algebraic_connectivity_is_the_laplacians_second_eigenvalue(seed):
    positions, _, active = random_case(seed, agents=9, records=5)
    for reach in (2.0, 4.0):
        expected = [brute_fiedler(x[on], reach) if on.sum() >= 2 else math.nan for x, on in zip(positions, active)]
        np.testing.assert_allclose(fm.algebraic_connectivity(positions, reach, active), expected, atol=1e-10)


def test_algebraic_connectivity_of_a_path_a_cycle_a_complete_and_a_split_graph():
    for n in (2, 5, 12):
        path = np.column_stack([np.arange(n), np.zeros(n)])[None]
        assert fm.algebraic_connectivity(path, 1.5)[0] == pytest.approx(2 * (1 - np.cos(np.pi / n)), abs=1e-12)
        assert fm.algebraic_connectivity(path, n + 1.0)[0] == pytest.approx(n, abs=1e-12)
        assert fm.algebraic_connectivity(path, 0.5)[0] == 0.0
    cycle, reach = polygon(9)[None], 2 * np.sin(np.pi / 9) * 1.2  # the sides within range, the next neighbours not
    assert fm.algebraic_connectivity(cycle, reach)[0] == pytest.approx(2 * (1 - np.cos(2 * np.pi / 9)), abs=1e-12)


def test_algebraic_connectivity_evaluates_every_nth_record_only():
    path = np.tile(np.column_stack([np.arange(4.0), np.zeros(4)]), (5, 1, 1))
    got = fm.algebraic_connectivity(path, 1.5, every=2)
    assert np.isnan(got[[1, 3]]).all()
    np.testing.assert_allclose(got[[0, 2, 4]], 2 * (1 - np.cos(np.pi / 4)), atol=1e-12)


# --- clearance, formation, shape, goal -----------------------------------------------------------


@pytest.mark.parametrize("seed", range(3))
def test_obstacle_and_wall_clearance_against_loops(seed):
    positions, _, active = random_case(seed)
    centers, radii = np.array([[1.0, 2.0, 0.5], [3.0, 0.0, 1.0]]), np.array([0.5, 1.2])
    box = np.array([4.0, 0.0, 3.0])
    for t, (x, on) in enumerate(zip(positions, active)):
        spheres = [math.dist(p, c) - r for p, o in zip(x, on) if o for c, r in zip(centers, radii)]
        cylinders = [math.dist(p[:2], c[:2]) - r for p, o in zip(x, on) if o for c, r in zip(centers, radii)]
        walls = [min(p[a], box[a] - p[a]) for p, o in zip(x, on) if o for a in (0, 2)]
        least = [pytest.approx(min(gaps, default=np.nan), nan_ok=True) for gaps in (spheres, cylinders, walls)]
        assert fm.obstacle_clearance(positions, centers, radii, active)[t] == least[0]
        assert fm.obstacle_clearance(positions, centers[:, :2], radii, active)[t] == least[1]  # vertical cylinders
        assert fm.wall_clearance(positions, box, active)[t] == least[2]


def test_clearance_in_closed_form():
    agent = np.zeros((1, 1, 2))
    assert fm.obstacle_clearance(agent, [[3.0, 4.0]], 1.0)[0] == pytest.approx(4.0)
    assert fm.obstacle_clearance(agent, [[0.0, 0.5]], 1.0)[0] == pytest.approx(-0.5)  # inside: a breach
    assert fm.wall_clearance(np.array([[[1.0, 7.0]]]), [10.0, 8.0])[0] == pytest.approx(1.0)
    assert fm.wall_clearance(np.array([[[11.0, 4.0]]]), [10.0, 8.0])[0] == pytest.approx(-1.0)


def test_edge_errors_against_loops():
    positions, _, _ = random_case(0)
    edges, d_t = np.array([[0, 1], [2, 5], [6, 3]]), np.array([1.0, 0.5, 2.0])
    expected = [[math.dist(x[i], x[j]) - d for (i, j), d in zip(edges, d_t)] for x in positions]
    np.testing.assert_allclose(fm.edge_errors(positions, edges, d_t), expected, rtol=1e-12)


def test_the_summary_takes_only_the_edges_held_at_each_record():
    """A formation that changes its shape: the edges it does not hold at a record are left out of the errors."""
    positions, velocities, _ = random_case(0)
    times = np.arange(len(positions), dtype=float)
    edges, d_t = np.array([[0, 1], [2, 5], [6, 3]]), np.array([1.0, 0.5, 2.0])
    members = np.random.default_rng(1).random((len(times), len(edges))) < 0.5
    members[-1] = [False, True, False]
    held = [abs(math.dist(x[i], x[j]) - d) for x, row in zip(positions, members) for (i, j), d, m in zip(edges, d_t, row) if m]
    figures = fm.field_summary(positions, velocities, times, edges=edges, d_t=d_t, members=members)
    assert figures["edge_error_max"] == pytest.approx(max(held), rel=1e-12)
    assert figures["edge_error_rms"] == pytest.approx(math.sqrt(sum(e * e for e in held) / len(held)), rel=1e-12)
    assert figures["edge_error_max_final"] == pytest.approx(abs(math.dist(positions[-1][2], positions[-1][5]) - 0.5), rel=1e-12)
    everything = fm.field_summary(positions, velocities, times, edges=edges, d_t=d_t)
    assert everything["edge_error_max"] > figures["edge_error_max"]  # the mask left something out: the test could fail


def rotation_2d(angle: float) -> np.ndarray:
    return np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])


@pytest.mark.parametrize("axes", [2, 3])
def test_a_rotated_and_moved_copy_of_the_shape_is_at_distance_zero(axes):
    rng = np.random.default_rng(axes)
    target = rng.normal(size=(8, axes)) * 5
    if axes == 2:
        turns = [rotation_2d(a) for a in rng.uniform(0, 2 * np.pi, 4)]
    else:
        turns = Rotation.random(4, random_state=1).as_matrix()
    copies = np.array([target @ r.T + rng.normal(size=axes) * 100 for r in turns])
    np.testing.assert_allclose(fm.shape_distance(copies, target), 0.0, atol=1e-9)


def test_shape_distance_in_2d_against_the_closed_form_angle():
    rng = np.random.default_rng(5)
    target, positions = rng.normal(size=(6, 2)), rng.normal(size=(4, 6, 2))
    y = target - target.mean(axis=0)
    for x, got in zip(positions, fm.shape_distance(positions, target)):
        x = x - x.mean(axis=0)  # the best angle: atan2(sum x cross y, sum x . y)
        angle = math.atan2(sum(a[0] * b[1] - a[1] * b[0] for a, b in zip(x, y)), sum(a @ b for a, b in zip(x, y)))
        assert got == pytest.approx(np.sqrt(np.mean(np.sum((x @ rotation_2d(angle).T - y) ** 2, axis=1))), rel=1e-10)


def test_shape_distance_in_3d_against_scipys_rotation_and_not_a_reflection():
    rng = np.random.default_rng(6)
    target, positions = rng.normal(size=(7, 3)), rng.normal(size=(5, 7, 3))
    y = target - target.mean(axis=0)
    for x, got in zip(positions, fm.shape_distance(positions, target)):
        x = x - x.mean(axis=0)
        _, rssd = Rotation.align_vectors(y, x)
        assert got == pytest.approx(rssd / np.sqrt(len(x)), rel=1e-9)
    mirror = target * np.array([1.0, 1.0, -1.0])  # a reflection fits it exactly; no rotation does
    reflected, _ = orthogonal_procrustes(mirror - mirror.mean(axis=0), y)
    assert np.linalg.det(reflected) < 0
    assert fm.shape_distance(mirror[None], target)[0] > 0.1


def test_time_to_goal_against_a_loop():
    rng = np.random.default_rng(7)
    positions, times, goal = rng.normal(0, 1, (40, 3, 2)), np.linspace(0, 3.9, 40), np.zeros(2)
    positions[25:] *= 0.05  # settles near the goal after record 25
    positions[31, :, 0] += 9.0  # and leaves it once
    active = rng.random((40, 3)) > 0.1
    active[:, 0] = True
    near = [np.linalg.norm(x[on].mean(axis=0) - goal) <= 0.3 for x, on in zip(positions, active)]
    last_away = max(t for t, ok in enumerate(near) if not ok)
    assert last_away >= 31 and near[-1]
    assert fm.time_to_goal(positions, times, goal, 0.3, active) == pytest.approx(times[last_away + 1])
    assert fm.time_to_goal(positions[:32], times[:32], goal, 0.3, active[:32]) is None
    assert fm.time_to_goal(positions[26:31], times[26:31], goal, 0.3) == pytest.approx(times[26])


# --- the summary ---------------------------------------------------------------------------------


#: Every key of the summary.
KEYS = {
    "order_mean", "order_min", "min_separation", "near_misses", "safety_share_max", "safety_share_mean", "closest_pass",
    "collisions", "union_max", "algebraic_connectivity_min", "min_obstacle_clearance", "min_wall_clearance", "edge_error_max",
    "edge_error_rms", "edge_error_max_final", "edge_error_rms_final", "shape_distance_final", "time_to_goal",
}  # fmt: skip


def test_every_key_of_the_summary_is_documented_in_the_module():
    assert all(f"``{key}``" in fm.__doc__ for key in KEYS)


def test_the_summary_of_a_triangle_flying_to_a_goal_in_closed_form():
    side, speed = 2.0, 0.5  # flies along x to (4, 0), there at t = 8 s and stays: within 0.52 m from t = 6.96 s
    triangle = polygon(3, side / np.sqrt(3))
    top = triangle[np.argmax(triangle[:, 1])]
    times = np.linspace(0, 10, 101)
    positions = triangle[None] + speed * np.minimum(times, 8.0)[:, None, None] * np.array([1.0, 0.0])
    velocities = np.where((times < 8.0)[:, None, None], np.broadcast_to([speed, 0.0], positions.shape), 0.0)
    velocities[times < 5.0] = polygon(3)  # a regular fan for the first half: order -1/2, then 1 (none once at rest)
    summary = fm.field_summary(
        positions, velocities, times, edges=[[0, 1], [1, 2]], d_t=1.5, target=triangle @ rotation_2d(1.0).T + 4,
        obstacles=([[top[0], 10.0]], [2.0]), box=[20.0, 0.0], safety_radius=2.5, collision_radius=1.0,
        communication_range=2.5, goal=[4.0, 0.0], goal_tolerance=0.52,
    )  # fmt: skip
    assert json.loads(json.dumps(summary, allow_nan=False)) == summary
    expected = {
        "order_mean": 1.0, "order_min": -0.5, "min_separation": side, "near_misses": 3, "safety_share_max": 1.0,
        "safety_share_mean": 1.0, "closest_pass": side, "collisions": 0, "union_max": 1, "algebraic_connectivity_min": 3.0,
        "edge_error_max": 0.5, "edge_error_rms": 0.5, "edge_error_max_final": 0.5, "edge_error_rms_final": 0.5,
        "shape_distance_final": 0.0, "time_to_goal": 7.0, "min_wall_clearance": triangle[:, 0].min(),
        "min_obstacle_clearance": 10.0 - top[1] - 2.0,
    }  # fmt: skip
    assert set(summary) == KEYS
    assert summary == pytest.approx(expected, abs=1e-9)


def test_the_summary_over_the_run_and_at_its_end_of_two_agents_apart_1_2_and_1_5_m():
    positions = np.zeros((3, 2, 2))
    positions[:, 1, 0] = [1.0, 2.0, 1.5]  # edge errors against d_t 1 and 1.5: (0, -0.5), (1, 0.5), (0.5, 0)
    summary = fm.field_summary(
        positions, np.ones_like(positions), np.arange(3.0), edges=[[0, 1], [1, 0]], d_t=[1.0, 1.5], safety_radius=1.6,
    )  # fmt: skip
    expected = {
        "edge_error_max": 1.0, "edge_error_rms": np.sqrt(1.75 / 6),
        "edge_error_max_final": 0.5, "edge_error_rms_final": np.sqrt(0.125),
        "near_misses": 2, "safety_share_max": 1.0, "safety_share_mean": 2 / 3, "closest_pass": 1.0, "min_separation": 1.0,
    }  # fmt: skip
    assert {key: summary[key] for key in expected} == pytest.approx(expected, rel=1e-12)


def test_the_summary_leaves_out_what_was_not_given():
    positions, velocities, _ = random_case(1)
    summary = fm.field_summary(positions, velocities, np.arange(len(positions)))
    assert set(summary) == KEYS
    assert {key for key, value in summary.items() if value is not None} == {"order_mean", "order_min", "min_separation"}
    with pytest.raises(ValueError, match="goal_tolerance"):
        fm.field_summary(positions, velocities, np.arange(len(positions)), goal=[0.0, 0.0, 0.0])
