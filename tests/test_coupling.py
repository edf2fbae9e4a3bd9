"""The pair flag F_en: coupling point and condition (9)."""

import pytest

from tmem.coupling import next_flag

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
def test_transitions(f_en, armed, r, expected):
    assert next_flag(f_en, armed, r, D_T, EPS) == expected
