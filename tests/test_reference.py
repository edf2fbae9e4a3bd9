"""The engine against the continuous-time reference (:mod:`tmem.analysis.reference`).

The engine's only error is sampling the control (zero-order hold of (2)), so
it must approach the continuous solution as ``dt`` shrinks, at first order.
"""

from __future__ import annotations

import numpy as np
import pytest

import tmem
from tmem.analysis.reference import final_state, integrate
from tmem.scenario import Scenario, from_dict, with_changes

DTS = (1e-2, 1e-3, 1e-4, 1e-5)


def three_agents() -> Scenario:
    """Repulsion (8), three agents at 0, 45, 100 m moving at 3, 0, -2 m/s: two encounters."""
    agents = [
        {"position": 0.0, "velocity": 3.0},
        {"position": 45.0, "velocity": 0.0},
        {"position": 100.0, "velocity": -2.0},
    ]
    return with_changes(tmem.preset("repulsion"), {"agents": agents})


SCENARIOS = {
    "repulsion": lambda: tmem.preset("repulsion"),
    "fig5": lambda: tmem.preset("fig5"),
    "three_agents": three_agents,
}


@pytest.fixture(scope="module", params=list(SCENARIOS))
def study(request) -> dict:
    """The scenario, its reference final velocities, and the engine's at each dt in :data:`DTS`."""
    scenario = SCENARIOS[request.param]()
    engine = {dt: tmem.simulate(with_changes(scenario, {"simulation.dt": dt})).state[-1, :, 0, 1] for dt in DTS}
    return {"scenario": scenario, "reference": final_state(scenario)[:, 0, 1], "engine": engine}


def error(study: dict, dt: float) -> float:
    return float(np.max(np.abs(study["engine"][dt] - study["reference"])))


def test_final_velocities_agree_at_default_dt(study):
    assert error(study, 1e-4) < 1e-3


def test_error_shrinks_at_first_order(study):
    errors = np.array([error(study, dt) for dt in DTS])
    assert np.all(np.diff(errors) < 0), errors
    order = np.polyfit(np.log10(DTS), np.log10(errors), 1)[0]
    assert 0.8 < order < 1.3, (order, errors)


@pytest.mark.parametrize("name", ["repulsion", "fig5"])
def test_whole_trajectory_agrees_at_default_dt(name):
    scenario = tmem.preset(name)
    trajectory = tmem.simulate(scenario)
    t, states = integrate(scenario)
    # The reference is evaluated at the recorded times.  A loop that kept its clock another way (another
    # backend, float32 times) would round them otherwise: equal to a thousandth of a step, the same step.
    np.testing.assert_allclose(t, trajectory.time, rtol=0, atol=1e-3 * scenario.simulation.dt)
    assert states.shape == trajectory.state.shape
    assert np.max(np.abs(states[..., 1] - trajectory.state[..., 1])) < 1e-3
    assert np.max(np.abs(states[..., 0] - trajectory.state[..., 0])) < 1e-2


@pytest.mark.parametrize("name", ["repulsion", "fig5"])
def test_reference_keeps_total_momentum(name):
    # Pair pushes are equal and opposite, so the sum of velocities is constant.
    scenario = tmem.preset(name)
    _, states = integrate(scenario)
    total = states[..., 0, 1].sum(axis=1)
    np.testing.assert_allclose(total, total[0], atol=1e-8)


def test_reference_does_not_depend_on_tolerance():
    scenario = tmem.preset("fig5")
    loose = final_state(scenario, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(loose, final_state(scenario), atol=1e-6)


@pytest.mark.interface
@pytest.mark.parametrize("function", ["switching", "improved"])
def test_refuses_coupling_functions(function):
    data = tmem.preset("fig9").model_dump()
    data["interaction"]["function"] = function
    with pytest.raises(ValueError, match="coupling flag"):
        integrate(from_dict(data))


@pytest.mark.interface
def test_refuses_times_outside_the_run():
    with pytest.raises(ValueError, match="t_eval"):
        integrate(tmem.preset("repulsion"), t_eval=np.array([0.0, 61.0]))
