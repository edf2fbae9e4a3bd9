"""The pair flag F_en: coupling point and condition (9), in both readings of where it flips."""

import pytest

import tmem
from tmem.law.coupling import next_flag
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

D_T, EPS = 35.0, 0.2


@pytest.mark.parametrize(
    "f_en,armed,r,expected",
    [
        (0, 1, 35.0, 1),  # armed pair at the coupling point couples
        (0, 1, 35.19, 1),
        (0, 1, 34.81, 1),
        (0, 1, 35.2, 0),  # window is open: |r - d_t| < eps
        (0, 1, 36.0, 0),
        (0, 0, 35.0, 0),  # disarmed (after an uncouple command): stays uncoupled
        (1, 1, 35.0, 1),  # armed and coupled: holds
        (1, 1, 50.0, 1),
        (1, 0, 50.0, 1),  # uncouple commanded: waits for (9)
        (1, 0, 35.1, 0),  # ... and lets go where (9) holds
        (1, 0, 34.9, 0),
    ],
)
def test_window_transitions(f_en, armed, r, expected):
    assert next_flag(f_en, armed, r + 0.001, r, D_T, EPS, False) == expected


@pytest.mark.parametrize(
    "f_en,armed,r_before,r,expected",
    [
        (0, 1, 35.19, 35.18, 0),  # inside the window but not yet at d_t
        (0, 1, 35.004, 34.999, 1),  # crosses d_t coming in
        (0, 1, 34.999, 35.004, 1),  # crosses d_t going out
        (0, 1, 35.0, 35.003, 1),  # leaves d_t exactly
        (0, 1, 36.0, 34.0, 0),  # a step across d_t wider than the window does not count
        (1, 0, 34.99, 35.01, 0),  # uncouples where it crosses
        (1, 0, 35.15, 35.1, 1),
    ],
)
def test_crossing_transitions(f_en, armed, r_before, r, expected):
    assert next_flag(f_en, armed, r_before, r, D_T, EPS, True) == expected


@pytest.mark.physics
@pytest.mark.parametrize("preset", ["fig7", "fig9"])
def test_crossing_switches_closer_to_d_t_than_the_window(preset):
    """The crossing rule flips the flag where the interaction distance is d_t, the window rule
    about eps farther out, where the pair first enters the window."""
    every_step = {"simulation.record_every": 1, "simulation.duration": 6.0, "commands": []}
    for rule in ("window", "crossing"):
        tr = tmem.simulate(with_changes(tmem.preset(preset), {"interaction.switch_at": rule, **every_step}))
        assert summarize(tr)["coupled"]
        k = tr.flag[:, 0].argmax()  # the step at which the flag flipped
        gap = tr.interaction_distance[k, 0] - D_T
        if rule == "crossing":
            assert -0.001 < gap <= 0.0  # the pair closes by ~0.0005 m per step
        else:
            assert EPS - 0.001 < gap < EPS
