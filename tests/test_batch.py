"""The batched two-agent loop against the full engine, case by case.

The batch gives the engine's figures (its claim): each case's RMS change, distances, final
velocities and coupling times equal tmem.simulate's of the same start within rounding (the batch
skips free flight in closed form and steps the pair's relative state), and its uncoupling rule
is the same.
"""

import numpy as np
import pytest

import tmem
from tmem.batch.encounters import run_batch
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

STARTS = [((50.0, 0.0), (-1.5, 3.0)), ((60.0, 0.0), (-2.0, 2.0)), ((0.0, 45.0), (4.0, -4.0)), ((100.0, 0.0), (-0.5, 1.0))]


def _agrees_with_the_engine(batch, k, base, start):
    """Case ``k`` of ``batch`` against tmem.simulate of ``base`` from ``start`` = (positions, velocities)."""
    (p0, p1), (v0, v1) = start
    agents = [{"position": p0, "velocity": v0}, {"position": p1, "velocity": v1}]
    tr = tmem.simulate(with_changes(base, {"agents": agents}))
    one = summarize(tr)
    assert batch.rms_change_percent[k] == pytest.approx(one["rms_change_percent"], abs=1e-7)
    assert batch.min_distance[k] == pytest.approx(one["min_distance"], abs=1e-7)
    assert batch.final_distance[k] == pytest.approx(one["final_distance"], abs=1e-6)
    np.testing.assert_allclose(np.ravel(batch.final_velocities[k]), np.ravel(one["final_velocities"]), atol=1e-9)
    for ours, theirs in ((batch.couple_time[k], one["couple_time"]), (batch.uncouple_time[k], one["uncouple_time"])):
        assert (np.isnan(ours) and theirs is None) or ours == pytest.approx(theirs, abs=1e-9)
    released = [e.rule for e in tr.events if e.kind == "uncouple"]
    assert batch.uncouple_rule[k] == (released[0] if released else None) == one["uncouple_rule"]


@pytest.mark.parametrize("function", tmem.FUNCTION_NAMES)
@pytest.mark.parametrize("switch_at", ["window", "crossing"])
def test_batch_equals_the_engine(function, switch_at):
    base = with_changes(
        tmem.preset("fig9"),
        {"interaction.function": function, "interaction.switch_at": switch_at, "simulation.duration": 45.0},
    )
    positions = np.array([p for p, _ in STARTS])
    velocities = np.array([v for _, v in STARTS])
    batch = run_batch(base, positions, velocities)
    for k, (p, v) in enumerate(STARTS):
        _agrees_with_the_engine(batch, k, base, (p, v))


@pytest.mark.slow  # compiles the batch that steps both agents on one axis for this test alone
@pytest.mark.parametrize("function", ["switching", "improved"])
def test_the_two_paths_agree_on_one_axis(function):
    """Under the window rule, one axis runs on the relative state (tmem.batch.relative); with the energy
    rule or synchronisation it steps both agents.  Each against the engine.  The default run checks
    the path that steps both agents in the plane (test_batch_equals_the_engine_in_the_plane:
    energy-11, energy-sync-10), the same source on two axes."""
    base = with_changes(tmem.preset("fig9"), {"interaction.function": function, "simulation.duration": 45.0})
    positions = np.array([p for p, _ in STARTS])
    velocities = np.array([v for _, v in STARTS])
    for changes in ({"interaction.uncouple_when": "energy"}, {"interaction.synchronise": True}):
        varied = with_changes(base, changes)
        batch = run_batch(varied, positions, velocities)
        for k, (p, v) in enumerate(STARTS):
            _agrees_with_the_engine(batch, k, varied, (p, v))


# Encounters in the plane: head-on, at an angle, passing wide (no contact), and a glancing one.
STARTS_2D = [
    (((50.0, 0.0), (0.0, 0.0)), ((-1.5, 0.0), (3.0, 0.0))),
    (((45.0, 20.0), (0.0, 0.0)), ((-3.0, -1.0), (1.0, 0.5))),
    (((60.0, 80.0), (0.0, 0.0)), ((-1.0, 1.0), (1.0, -0.5))),
    (((48.0, 12.0), (0.0, -3.0)), ((-2.5, 0.0), (2.0, 0.3))),
]


@pytest.mark.parametrize(
    "interaction",
    [{"function": "switching"}, {"function": "improved"}, {"function": "improved", "uncouple_when": "energy"},
     {"function": "switching", "uncouple_when": "energy", "synchronise": True}, {"function": "repulsion"}],
    ids=["window-10", "window-11", "energy-11", "energy-sync-10", "repulsion"],
)  # fmt: skip
def test_batch_equals_the_engine_in_the_plane(interaction):
    """Each case of a 2-D batch against tmem.simulate of the same start: the same step, with free
    flight skipped in closed form (agreement to rounding)."""
    base = with_changes(
        tmem.preset("fig9"),
        {"space.axes": 2, "simulation.duration": 45.0, "agents": [{"position": [50.0, 0.0]}, {"position": [0.0, 0.0]}],
         **{f"interaction.{k}": v for k, v in interaction.items()}},
    )  # fmt: skip
    positions = np.array([p for p, _ in STARTS_2D])
    velocities = np.array([v for _, v in STARTS_2D])
    batch = run_batch(base, positions, velocities)
    for k, (p, v) in enumerate(STARTS_2D):
        _agrees_with_the_engine(batch, k, base, ([list(p[0]), list(p[1])], [list(v[0]), list(v[1])]))
    if interaction["function"] != "repulsion":
        assert batch.coupled[:2].all() and not batch.coupled[2]  # head-on and angled couple; the wide pass does not


@pytest.mark.interface
def test_batch_refuses_what_it_cannot_run():
    with pytest.raises(ValueError, match="two agents"):
        run_batch(tmem.load("examples/swarm/triangle.toml"), np.zeros((1, 2)), np.zeros((1, 2)))
    periodic = with_changes(tmem.preset("fig9"), {"space.periodic": True, "space.box": [500.0]})
    with pytest.raises(ValueError, match="open space"):
        run_batch(periodic, [[50.0, 0.0]], [[-1.5, 3.0]])


BAD_STARTS = {
    "nan position": ([[np.nan, 0.0]], [[-1.5, 3.0]], "positions[0, 0]"),
    "inf velocity": ([[50.0, 0.0]], [[-1.5, np.inf]], "velocities[0, 1]"),
    "huge position": ([[50.0, 1e300]], [[-1.5, 3.0]], "positions[0, 1]"),
    "same place": ([[50.0, 0.0], [7.0, 7.0]], [[-1.5, 3.0], [1.0, -1.0]], "positions[1]"),
    "one agent": ([[50.0]], [[-1.5]], "positions: must have shape (cases, 2)"),
    "flat": ([50.0, 0.0], [-1.5, 3.0], "positions: must have shape (cases, 2)"),
    "no cases": (np.empty((0, 2)), np.empty((0, 2)), "positions: must have shape"),
    "cases differ": ([[50.0, 0.0]], [[-1.5, 3.0], [1.0, 1.0]], "velocities: has 2 cases"),
    "text": ([["a", "b"]], [[-1.5, 3.0]], "positions: must be numbers"),
}


@pytest.mark.interface
@pytest.mark.parametrize("name", BAD_STARTS, ids=list(BAD_STARTS))
def test_bad_starts_are_refused_in_one_line(name):
    """As ``tmem run`` refuses them (regression: these ran, returning NaN or +167 %)."""
    positions, velocities, where = BAD_STARTS[name]
    with pytest.raises(ValueError) as info:
        run_batch(tmem.preset("fig9"), positions, velocities)
    message = str(info.value)
    assert "\n" not in message and message.startswith("run_batch: ") and where in message, message


@pytest.mark.interface
def test_a_scenario_that_is_not_one_is_refused():
    with pytest.raises(ValueError, match="run_batch: scenario: must be a tmem Scenario"):
        run_batch({"name": "fig9"}, [[50.0, 0.0]], [[-1.5, 3.0]])
