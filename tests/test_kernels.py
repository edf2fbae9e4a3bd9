"""Compiled kernels of the world and the law on small inputs, against closed forms and brute force.

The nearest image and the box (:mod:`tmem.world.space`), ``P*`` (6) and the tilt limit
(:mod:`tmem.law.modal`), and the walls' and obstacles' pushes (W1)-(W2) (:mod:`tmem.world.walls`).
Each kernel is called from Python on a handful of numbers; the expectations are written out here.
The other kernels' unit tests are marked ``unit`` where they stand: the interaction functions
(``test_interaction.py``), the flag's rules (``test_coupling.py``), the neighbour lists
(``test_swarm.py``) and the sensing draws (``test_sensing.py``).
"""

from __future__ import annotations

import numpy as np
import pytest

from tmem.law.interaction.kernels import FunctionParams
from tmem.law.modal import corrected_position, gains_row, saturation, tilt_scale
from tmem.world.space import into_box, nearest_image
from tmem.world.walls import keep_off, wall_pushes, with_priority

K_P, REACH, C_MAX = 0.0296347, 40.0, 0.1
PARAMS = FunctionParams(K_P, REACH, 35.0, C_MAX)


def repulsion(r: float) -> float:
    """(8) written out: ``K_P (r - reach)`` inside the reach, 0 outside, within ``c_max``."""
    return max(-C_MAX, min(C_MAX, K_P * (r - REACH))) if r < REACH else 0.0


# --- the space ------------------------------------------------------------------------------------


def test_the_nearest_image_is_the_smallest_of_the_periodic_copies():
    rng = np.random.default_rng(1)
    side = 250.0
    deltas = np.concatenate([rng.uniform(-3 * side, 3 * side, 500), [0.0, 62.4, -62.6, 124.9, -125.1, 249.0, 251.0]])
    for delta in deltas:
        copies = delta + side * np.arange(-4, 5)
        expected = copies[np.argmin(np.abs(copies))]
        assert nearest_image(delta, side) == pytest.approx(expected, abs=1e-9 * side), delta
    assert nearest_image(700.0, 0.0) == 700.0  # an open axis: the difference as it is


def test_into_box_brings_a_position_into_the_box_by_whole_sides():
    side = 80.0
    for position in (-300.5, -80.0, -0.25, 0.0, 12.0, 79.9, 80.0, 1000.3):
        inside = into_box(position, side)
        assert 0.0 <= inside < side
        turns = (position - inside) / side
        assert turns == pytest.approx(round(turns), abs=1e-9)


# --- P* and the tilt limit ------------------------------------------------------------------------


@pytest.mark.parametrize("shared", [True, False], ids=["one row of gains", "a row per agent"])
def test_the_corrected_position_is_p_plus_the_gains_ratios_times_the_state(shared):
    """(6): ``P* = P + (K_V / K_P) V + (K_phi / K_P) phi + (K_omega / K_P) omega``."""
    x = np.array([[[12.0, 2.0, 0.05, -0.3], [-4.0, 0.5, -0.02, 0.1]], [[3.0, -1.0, 0.0, 0.0], [8.0, 0.0, 0.01, 0.2]]])
    table1 = np.array([0.029635, 0.0049388, -0.037917, -0.0066667])
    gains = table1[None, :] if shared else np.array([table1, 2.0 * table1 + [0.01, 0.0, 0.0, 0.0]])
    for i in range(2):
        row = gains_row(gains, i)
        assert row == (0 if shared else i)
        k = gains[row]
        for a in range(2):
            p, v, phi, omega = x[i, a]
            expected = p + k[1] / k[0] * v + k[2] / k[0] * phi + k[3] / k[0] * omega
            assert corrected_position(x, i, a, gains, row) == pytest.approx(expected, rel=1e-14, abs=1e-14)


def test_the_corrected_position_reads_only_the_laws_components():
    """A vehicle may keep more states after the law's: with two gains, ``P* = P + (K_V / K_P) V``."""
    x = np.array([[[5.0, 3.0, 100.0, -100.0, 7.0]]])
    gains = np.array([[0.5, 0.25]])
    assert corrected_position(x, 0, 0, gains, 0) == pytest.approx(5.0 + 0.5 * 3.0, rel=1e-15)


def test_the_tilt_limit_scales_the_set_point_onto_c_max():
    u = np.array([[0.06, 0.08], [0.03, -0.04], [0.3, 0.4]])
    assert tilt_scale(u, 0, 2, C_MAX) == 1.0  # |U| = c_max: left alone
    assert tilt_scale(u, 1, 2, C_MAX) == 1.0
    assert tilt_scale(u, 2, 2, C_MAX) == pytest.approx(0.2, rel=1e-15)  # |U| = 0.5
    assert saturation(4.0, 1.0) == pytest.approx(0.5, rel=1e-15)


# --- walls and obstacles (W1)-(W2) ----------------------------------------------------------------


def _agent(p_star: list[float], position: list[float] | None = None) -> np.ndarray:
    """``corrected`` of one agent: ``(P*, P)`` per axis."""
    position = p_star if position is None else position
    return np.array([[[s, p] for s, p in zip(p_star, position)]])


NO_OBSTACLE = np.empty((0, 3))
WALLS = np.array([1000.0, 600.0])
OPEN = (0.0, 0.0)


@pytest.mark.parametrize("low", [1.0, 20.0, 36.5, 39.9])
def test_a_wall_pushes_as_a_neighbour_held_still_on_its_surface(low):
    """(W1): ``P*`` ``low`` m from the wall at x = 0 gets the repulsion (8) at ``|d| = low``, along +x;
    the far walls, 560 m and more away, push nothing."""
    corrected = _agent([low, 300.0])
    pushed = np.full((1, 2), np.nan)  # written only where a wall pushes
    contacts, pressing, on_walls, moment, virial = wall_pushes(0, corrected, pushed, WALLS, NO_OBSTACLE, OPEN, PARAMS, 2)
    size = -repulsion(low)
    assert size > 0.0
    assert contacts == 1 and virial == 0.0
    np.testing.assert_allclose(pushed[0], [size, 0.0], rtol=1e-14, atol=0.0)
    assert pressing == pytest.approx((size / C_MAX) ** 2, rel=1e-14)
    assert on_walls == pytest.approx(size, rel=1e-14) and moment == pytest.approx(size * low, rel=1e-14)


def test_in_a_corner_each_wall_pushes_on_its_own_axis():
    corrected = _agent([985.0, 10.0])  # 15 m from the wall at x = 1000, 10 m from the wall at y = 0
    pushed = np.zeros((1, 2))
    contacts, _, _, _, _ = wall_pushes(0, corrected, pushed, WALLS, NO_OBSTACLE, OPEN, PARAMS, 2)
    assert contacts == 2
    np.testing.assert_allclose(pushed[0], [repulsion(15.0), -repulsion(10.0)], rtol=1e-14)


def test_out_of_every_walls_reach_nothing_is_written():
    corrected = _agent([500.0, 300.0])
    pushed = np.full((1, 2), 7.0)
    assert wall_pushes(0, corrected, pushed, WALLS, NO_OBSTACLE, OPEN, PARAMS, 2)[0] == 0
    assert np.all(pushed == 7.0)


def test_an_obstacle_pushes_away_from_its_centre_by_the_gap_to_its_surface():
    """(W1) for an obstacle: the repulsion at the gap from ``P*`` to the surface, along the line from
    the centre to ``P*``; in a periodic box the centre is its nearest image."""
    obstacle = np.array([[30.0, 40.0, 25.0]])  # centre (30, 40), radius 25
    corrected = _agent([30.0 + 0.6 * 50.0, 40.0 + 0.8 * 50.0])  # 50 m from the centre: a gap of 25 m
    pushed = np.zeros((1, 2))
    contacts, pressing, on_walls, _, _ = wall_pushes(0, corrected, pushed, np.zeros(2), obstacle, OPEN, PARAMS, 2)
    size = -repulsion(25.0)
    assert contacts == 1 and on_walls == 0.0 and pressing == pytest.approx((size / C_MAX) ** 2, rel=1e-14)
    np.testing.assert_allclose(pushed[0], [0.6 * size, 0.8 * size], rtol=1e-13)
    # The same geometry mirrored across the edge x = 0 of a box periodic along x: P* at x = 1000 m
    # (the edge) sees the centre's image at x = 1030 m, 30 m ahead of it.
    across = _agent([1000.0, 40.0 + 0.8 * 50.0])
    mirrored = np.zeros((1, 2))
    wall_pushes(0, across, mirrored, np.zeros(2), obstacle, (1000.0, 0.0), PARAMS, 2)
    np.testing.assert_allclose(mirrored[0], [-0.6 * size, 0.8 * size], rtol=1e-13)


def test_keep_off_drops_what_points_into_a_wall_and_keeps_the_rest():
    """(W2): within the wall's reach a set-point into it is dropped (and held by the wall); along it,
    or away from it, it is kept."""
    corrected = _agent([10.0, 300.0])
    setpoint = np.array([[-0.05, 0.07]])
    held, moment, virial = keep_off(0, corrected, setpoint, WALLS, NO_OBSTACLE, OPEN, REACH, 2)
    np.testing.assert_array_equal(setpoint[0], [0.0, 0.07])  # a component set to 0, the other untouched
    assert held == 0.05 and moment == pytest.approx(0.05 * 10.0, rel=1e-15) and virial == 0.0
    away = np.array([[0.05, -0.02]])
    assert keep_off(0, corrected, away, WALLS, NO_OBSTACLE, OPEN, REACH, 2)[0] == 0.0
    np.testing.assert_array_equal(away[0], [0.05, -0.02])


def test_keep_off_drops_the_part_towards_an_obstacles_centre():
    obstacle = np.array([[0.0, 0.0, 10.0]])
    corrected = _agent([30.0, 0.0])  # 20 m from the surface: within reach
    setpoint = np.array([[-0.06, 0.03]])  # towards the centre along -x, and across
    keep_off(0, corrected, setpoint, np.zeros(2), obstacle, OPEN, REACH, 2)
    np.testing.assert_allclose(setpoint[0], [0.0, 0.03], atol=1e-17)


def _largest_alpha(w: np.ndarray, r: np.ndarray, limit: float) -> float:
    """The largest ``alpha`` in [0, 1] with ``|w + alpha r| <= limit``, by bisection."""
    if np.linalg.norm(w + r) <= limit:
        return 1.0
    low, high = 0.0, 1.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if np.linalg.norm(w + middle * r) <= limit else (low, middle)
    return low


@pytest.mark.parametrize("w, r", [
    ([0.05, 0.0], [0.02, 0.01]),  # within the limit: all of it
    ([0.08, 0.0], [0.0, 0.09]),  # the others shortened to fit
    ([0.1, 0.0], [-0.03, 0.05]),
    ([0.09, 0.09], [0.05, -0.02]),  # a corner: the walls alone exceed c_max, and keep their size
])  # fmt: skip
def test_the_walls_pushes_come_first_and_the_others_get_what_the_limit_leaves(w, r):
    w, r = np.array([w]), np.array([r])
    limit = max(C_MAX, float(np.linalg.norm(w)))
    expected = _largest_alpha(w[0], r[0], limit)
    setpoint = r.copy()
    alpha, got_limit = with_priority(0, setpoint, w, C_MAX, 2)
    assert got_limit == pytest.approx(limit, rel=1e-15)
    assert alpha == pytest.approx(expected, abs=1e-12)
    np.testing.assert_allclose(setpoint[0], w[0] + expected * r[0], atol=1e-12)
    assert np.linalg.norm(setpoint[0]) <= limit * (1 + 1e-12)
