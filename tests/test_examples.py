"""Every shipped example loads and runs; the swarm examples briefly."""

from pathlib import Path

import numpy as np
import pytest

import tmem
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

EXAMPLES = Path(__file__).parent.parent / "examples"
SWARM = sorted((EXAMPLES / "swarm").glob("*.toml"))


@pytest.mark.parametrize("path", SWARM, ids=[p.stem for p in SWARM])
def test_swarm_example_runs(path):
    scenario = tmem.load(path)
    short = with_changes(scenario, {"simulation.duration": 5.0, "commands": []})
    s = summarize(tmem.simulate(short))
    assert s["agents"] == scenario.n_agents
    assert np.isfinite(s["rms_velocity_final"])
    if scenario.formation is not None and scenario.formation.coupled:
        assert s["formation"]["distance_error"]["max"] < 2.0


@pytest.mark.parametrize("name", tmem.scenario.PRESETS)
def test_examples_are_the_shipped_presets(name):
    assert tmem.load(EXAMPLES / f"{name}.toml") == tmem.preset(name)


ALL = sorted(p for p in EXAMPLES.rglob("*.toml") if "sweeps" not in p.parts)  # scenarios, not sweep files


@pytest.mark.parametrize("path", ALL, ids=[p.stem for p in ALL])
def test_scenario_survives_its_own_toml(path):
    """The TOML stored in trajectory.nc loads back to the same scenario."""
    scenario = tmem.load(path)
    assert tmem.loads(scenario.to_toml()) == scenario


def test_awkward_names_survive_toml():
    scenario = with_changes(tmem.preset("fig9"), {"name": 'a "quoted", \\ back-slashed é 😀 name'})
    assert tmem.loads(scenario.to_toml()) == scenario


def test_model_without_kind_is_the_linear_model():
    """Files written before ``[model] kind`` existed load as the linear model they meant."""
    text = tmem.preset("fig9").to_toml()
    assert '[model]\nkind = "linear"\n' in text
    older = text.replace('kind = "linear"\n', "", 1)
    assert tmem.loads(older) == tmem.preset("fig9")
    assert tmem.loads(older).model.kind == "linear"


def test_the_plane_encounter_is_fig7_in_the_plane():
    """examples/encounter_plane.toml, the base of the plane study, differs from the Fig. 7 preset only
    in its axes and in Table 2's start written as vectors along x."""
    plane, fig7 = tmem.load(EXAMPLES / "encounter_plane.toml"), tmem.preset("fig7")
    for table in ("model", "controller", "interaction", "simulation", "commands", "neighbors"):
        assert getattr(plane, table) == getattr(fig7, table), table
    assert plane.space.axes == 2
    for ours, theirs in zip(plane.agents, fig7.agents, strict=True):
        assert ours.position == [theirs.position, 0.0] and ours.velocity == [theirs.velocity, 0.0]
