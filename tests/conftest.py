"""Shared fixtures: the paper's Table 1 parameters."""

import pytest

TABLE1 = dict(kp=6.0, kd=25.0, g=9.8, r_l=12.0, im_l=0.1, im_r=0.55)


@pytest.fixture
def table1():
    return dict(TABLE1)
