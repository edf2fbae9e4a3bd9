"""Interaction functions (8), Fig. 3, (10), (11) against the paper's formulas written out literally."""

import numpy as np
import pytest

from tmem.law import interaction

K_P, REACH, D_T, C_MAX = 0.0296347, 40.0, 35.0, 0.1
PARAMS = dict(k_p=K_P, reach=REACH, d_t=D_T, c_max=C_MAX)
B = (D_T + REACH) / 2


def sat(u):
    return max(-C_MAX, min(C_MAX, u))


def paper(function, d, f_en):
    """A slow literal transcription of the paper, with c_j of (7) and d_j = c_j + s_d (R + R_j)."""
    s = float(np.sign(d))
    c = d - s * REACH  # (7)
    d_j = c + s * REACH
    if function == "repulsion" or (function == "switching" and f_en == 0):  # (8), f1 of (10)
        return sat(K_P * c) if abs(d_j) < REACH else 0.0
    if function == "attraction":  # Fig. 3
        return sat(K_P * (d_j - s * D_T)) if abs(d_j) < REACH else 0.0
    if f_en == 1:  # f2 of (10) and (11)
        return sat(K_P * (d_j - s * D_T))
    if abs(d_j) >= REACH:  # f1 of (11)
        return 0.0
    if B < abs(d_j):
        return sat(K_P * c)
    if D_T <= abs(d_j):
        return sat(-K_P * (d_j - s * D_T))
    return sat(K_P * (d_j - s * D_T))


BREAKPOINTS = [0.0, 1e-9, 3.0, D_T - 1e-9, D_T, D_T + 1e-9, B - 1e-9, B, B + 1e-9, REACH - 1e-9, REACH, REACH + 1e-9, 60.0]
GRID = np.concatenate([np.linspace(-70, 70, 2801), BREAKPOINTS, [-x for x in BREAKPOINTS]])
CASES = [("repulsion", 0), ("attraction", 0), ("switching", 0), ("switching", 1), ("improved", 0), ("improved", 1)]


@pytest.mark.parametrize("function,f_en", CASES)
def test_matches_literal_transcription_everywhere(function, f_en):
    ours = interaction.evaluate(function, GRID, f_en, **PARAMS)
    ref = np.array([paper(function, d, f_en) for d in GRID])
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-15)


@pytest.mark.parametrize("function,f_en", CASES)
def test_odd_in_d_and_saturated(function, f_en):
    """Odd to the bit, in any floating-point format: the kernels take ``|d|`` and the sign is set
    after, so ``-d`` gives exactly ``-U`` (two agents of a pair get exactly opposite pushes)."""
    u = interaction.evaluate(function, GRID, f_en, **PARAMS)
    u_mirror = interaction.evaluate(function, -GRID, f_en, **PARAMS)
    np.testing.assert_array_equal(u, -u_mirror)
    assert np.all(np.abs(u) <= C_MAX)


def f(function, d, f_en=0, c_max=C_MAX):
    return interaction.evaluate(function, d, f_en, k_p=K_P, reach=REACH, d_t=D_T, c_max=c_max)


def test_repulsion_pushes_apart_inside_and_is_zero_outside():
    u = f("repulsion", np.array([10.0, 39.0, 40.0, 41.0]))
    assert u[0] == -C_MAX  # saturated
    assert u[1] == pytest.approx(-K_P * 1.0)  # linear part K_P c
    assert u[2] == 0.0 and u[3] == 0.0  # |d| = R + R_j is outside


def test_attraction_pulls_beyond_d_t_and_pushes_inside():
    u = f("attraction", np.array([30.0, 35.0, 36.0, 39.0, 40.0]))
    assert u[0] < 0 and u[1] == 0.0 and u[2] > 0 and u[3] == C_MAX and u[4] == 0.0


def test_improved_f1_is_continuous_at_b_and_d_t():
    for point in (B, D_T):
        for h in (1e-6, 1e-9):
            assert abs(f("improved", point - h) - f("improved", point + h)) < 2 * K_P * h + 1e-15
    assert f("improved", B) == pytest.approx(-K_P * (REACH - B))  # the repulsive peak of the tent
    assert f("improved", D_T) == 0.0


def test_improved_f1_equals_f2_inside_d_t():
    """Equal to the bit: inside d_t both branches are the same expression K_P (r - d_t), saturated."""
    d = np.linspace(-D_T, D_T, 1001)
    np.testing.assert_array_equal(f("improved", d, 0), f("improved", d, 1))


def test_improved_f1_and_f2_differ_between_d_t_and_reach():
    d = np.linspace(D_T + 0.1, REACH - 0.1, 50)
    assert np.all(f("improved", d, 0) < 0) and np.all(f("improved", d, 1) > 0)


def test_switching_steps_at_the_coupling_point():
    """(10): at |d| = d_t, f1 is the repulsion, f2 is zero: a jump of min(K_P (reach - d_t), c_max)."""
    f1, f2 = f("switching", D_T, 0), f("switching", D_T, 1)
    assert f2 == 0.0
    assert f1 - f2 == pytest.approx(-min(K_P * (REACH - D_T), C_MAX))
    # Unsaturated, the step is the full K_P (reach - d_t).
    assert f("switching", D_T, 0, c_max=1.0) == pytest.approx(-K_P * (REACH - D_T))


def test_coupled_attraction_has_no_range_limit():
    assert f("switching", 100.0, 1) == C_MAX
    assert f("improved", -100.0, 1) == -C_MAX


def test_uses_coupling():
    assert [interaction.uses_coupling(name) for name in interaction.FUNCTION_NAMES] == [False, False, True, True, False]


# Every registered function, checked for what the method needs of any interaction function and for
# what its registry row claims.
ROWS = [pytest.param(row, id=row.name) for row in interaction.FUNCTIONS]
FINE = np.linspace(-2 * REACH, 2 * REACH, 160_001)


@pytest.mark.parametrize("row", ROWS)
def test_every_function_is_saturated_odd_and_repels_when_close_unless_it_pushes_nothing(row):
    for f_en in (0, 1) if row.couples else (0,):
        u = f(row.name, FINE, f_en)
        assert np.all(np.abs(u) <= C_MAX)
        np.testing.assert_array_equal(u, -f(row.name, -FINE, f_en))  # odd to the bit: see test_odd_in_d_and_saturated
    close = np.linspace(0.01, 5.0, 50)
    if row.pushes:
        assert np.all(f(row.name, close, 0) < 0)  # pushes apart (U < 0 for d > 0) when nearly touching
    else:  # "none", the law off: nothing anywhere, coupled or not
        assert not np.any(f(row.name, FINE, 0)) and not np.any(f(row.name, FINE, 1))


@pytest.mark.parametrize("row", ROWS)
def test_every_function_leaves_uncoupled_agents_beyond_reach_alone(row):
    assert np.all(f(row.name, np.linspace(REACH, 10 * REACH, 100), 0) == 0.0)


@pytest.mark.parametrize("row", ROWS)
def test_continuity_is_as_the_registry_claims(row):
    """Continuous rows move by no more than the slope K_P allows between neighbouring points of a fine
    grid of ``|d|``; the others jump somewhere by more than that."""
    r = np.linspace(1e-3, 2 * REACH, 80_001)
    largest_step = np.abs(np.diff(f(row.name, r, 0))).max()
    slope_bound = K_P * (r[1] - r[0]) * (1 + 1e-9)
    assert (largest_step <= slope_bound) == row.continuous, largest_step


@pytest.mark.parametrize("row", ROWS)
def test_each_row_names_a_kernel_and_its_code_dispatches_to_it(row):
    from tmem.law.interaction import kernels

    code = interaction.code(row.name)
    params = kernels.FunctionParams(K_P, REACH, D_T, C_MAX)
    for r in BREAKPOINTS[1:]:  # d > 0: evaluate takes the signed measure
        for f_en in (0, 1):
            expected = getattr(kernels, row.kernel).py_func(r, f_en, params)
            assert kernels.pair_control.py_func(code, r, f_en, params) == expected
            assert f(row.name, r, f_en) == expected


@pytest.mark.interface
def test_the_documented_table_of_functions_is_the_registry():
    """docs/equations.md lists one row per registered function, in registry order, with its equation,
    and a coupled column exactly for the functions that switch on F_en."""
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "equations.md").read_text()
    rows = [line for line in page.splitlines() if line.startswith("| `")]
    assert len(rows) == len(interaction.FUNCTIONS)
    for line, row in zip(rows, interaction.FUNCTIONS):
        name_cell, _, coupled_cell = [cell.strip() for cell in line.strip("|").split(" | ")][:3]
        assert name_cell == f"`{row.name}`, {row.equation}"
        assert (coupled_cell != "—") == row.couples
