"""Agent model (1)-(2) and its exact zero-order-hold discretisation."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.signal import cont2discrete

from tmem.vehicles.linear import state_matrices, zero_order_hold


def test_matrices_are_those_of_equation_2():
    a, b = state_matrices(6.0, 25.0, 9.8)
    # (1): omega_dot = kd (kp (phi_d - phi) - omega), x_ddot = g phi
    x = np.array([1.0, 2.0, 0.3, -0.4])
    u = 0.05
    xdot = a @ x + b * u
    assert xdot[0] == x[1]
    assert xdot[1] == pytest.approx(9.8 * x[2])
    assert xdot[2] == x[3]
    assert xdot[3] == pytest.approx(25.0 * (6.0 * (u - x[2]) - x[3]))


@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2, 0.1])
def test_zero_order_hold_matches_scipy_cont2discrete(dt):
    a, b = state_matrices(6.0, 25.0, 9.8)
    ad, bd = zero_order_hold(a, b, dt)
    ad_ref, bd_ref, *_ = cont2discrete((a, b[:, None], np.eye(4), np.zeros((4, 1))), dt, method="zoh")
    np.testing.assert_allclose(ad, ad_ref, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(bd, bd_ref[:, 0], rtol=1e-12, atol=1e-14)


def test_zero_order_hold_is_exact_for_a_held_input():
    """One ZOH step equals the continuous solution with the input held, to integrator tolerance."""
    a, b = state_matrices(6.0, 25.0, 9.8)
    dt, u = 0.37, 0.08
    x0 = np.array([5.0, -1.0, 0.02, 0.1])
    ad, bd = zero_order_hold(a, b, dt)
    sol = solve_ivp(lambda t, x: a @ x + b * u, (0, dt), x0, rtol=1e-12, atol=1e-12, method="DOP853")
    np.testing.assert_allclose(ad @ x0 + bd * u, sol.y[:, -1], rtol=1e-9, atol=1e-11)
