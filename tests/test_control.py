"""Modal gains (4)-(5): placed roots checked against independent pole placement."""

import control as ct
import numpy as np
import pytest
from scipy.signal import place_poles

from tmem.law.modal import interaction_point, modal_gains, printed_gains, roots
from tmem.vehicles.linear import state_matrices

CASES = [
    dict(kp=6.0, kd=25.0, g=9.8, r_l=12.0, im_l=0.1, im_r=0.55),  # Table 1
    dict(kp=4.0, kd=30.0, g=9.81, r_l=8.0, im_l=1.5, im_r=0.3),
    dict(kp=10.0, kd=15.0, g=9.81, r_l=5.0, im_l=0.5, im_r=1.2),
    dict(kp=2.5, kd=40.0, g=3.71, r_l=20.0, im_l=3.0, im_r=0.05),  # Mars gravity
]


def _sorted(values):
    return np.array(sorted(values, key=lambda z: (round(z.real, 6), z.imag)))


@pytest.mark.parametrize("p", CASES)
def test_closed_loop_has_the_roots_of_equation_5(p):
    a, b = state_matrices(p["kp"], p["kd"], p["g"])
    k = modal_gains(**p)
    placed = _sorted(np.linalg.eigvals(a - np.outer(b, k)))
    wanted = _sorted(roots(p["r_l"], p["im_l"], p["im_r"]))
    np.testing.assert_allclose(placed, wanted, rtol=1e-9, atol=1e-9 * np.abs(wanted).max())


def test_double_left_root_by_characteristic_polynomial():
    """im_l = 0 gives a double root -r_l: eigenvalues of a defective matrix are ill-conditioned,
    so compare the characteristic polynomial instead."""
    p = dict(kp=10.0, kd=15.0, g=9.81, r_l=5.0, im_l=0.0, im_r=1.2)
    a, b = state_matrices(p["kp"], p["kd"], p["g"])
    coeffs = np.poly(a - np.outer(b, modal_gains(**p)))
    np.testing.assert_allclose(coeffs, np.poly(roots(5.0, 0.0, 1.2)).real, rtol=1e-12)


def _assert_gains_close(k, k_ref):
    np.testing.assert_allclose(k, k_ref, rtol=1e-9, atol=1e-12 * np.abs(k_ref).max())


@pytest.mark.parametrize("p", CASES)
def test_gains_equal_scipy_place_poles(p):
    a, b = state_matrices(p["kp"], p["kd"], p["g"])
    k_ref = place_poles(a, b[:, None], roots(p["r_l"], p["im_l"], p["im_r"])).gain_matrix[0]
    _assert_gains_close(modal_gains(**p), k_ref)


@pytest.mark.parametrize("p", CASES)
def test_gains_equal_python_control_acker(p):
    a, b = state_matrices(p["kp"], p["kd"], p["g"])
    k_ref = np.asarray(ct.acker(a, b[:, None], roots(p["r_l"], p["im_l"], p["im_r"]))).ravel()
    _assert_gains_close(modal_gains(**p), k_ref)


def test_table1_gains_match_design_note(table1):
    np.testing.assert_allclose(
        modal_gains(**table1), [0.029635, 0.0049388, -0.037917, -0.0066667], rtol=1e-4
    )


def test_printed_formula_4_places_other_roots(table1):
    """As printed, (4) gives eig(A - BK) = {-11.93 +- 12.19i, -0.074 +- 0.140i}, not (5)."""
    a, b = state_matrices(table1["kp"], table1["kd"], table1["g"])
    k = printed_gains(**table1)
    placed = _sorted(np.linalg.eigvals(a - np.outer(b, k)))
    np.testing.assert_allclose(
        placed, _sorted([-11.926 - 12.187j, -11.926 + 12.187j, -0.0739 - 0.1397j, -0.0739 + 0.1397j]), atol=2e-3
    )
    # The difference: position and velocity gains swapped, and K_phi lacks the "- 1".
    good = modal_gains(**table1)
    np.testing.assert_allclose(k[[1, 0]], good[:2], rtol=1e-12)
    assert k[2] - good[2] == pytest.approx(1.0)
    assert k[3] == pytest.approx(good[3])


def test_interaction_point_is_position_for_a_resting_agent(table1):
    k = modal_gains(**table1)
    x = np.array([[12.5, 0.0, 0.0, 0.0], [3.0, 2.0, 0.01, 0.0]])
    p_star = interaction_point(x, k)
    assert p_star[0] == 12.5
    assert p_star[1] == pytest.approx(3.0 + 2.0 * k[1] / k[0] + 0.01 * k[2] / k[0])


def test_neighbour_held_still_gives_closed_loop_a_minus_bk(table1):
    """Inside the linear part of (8), U_i = K_P (P*_j - P*_i - reach) = -K x_i + const."""
    k = modal_gains(**table1)
    xj = np.array([40.0, 0.0, 0.0, 0.0])
    for xi in (np.array([3.0, 1.0, 0.0, 0.0]), np.array([5.0, -0.5, 0.02, 0.3])):
        u = k[0] * (interaction_point(xj, k) - interaction_point(xi, k) - 40.0)
        assert u == pytest.approx(-k @ xi + k @ xj - k[0] * 40.0, abs=1e-15)
