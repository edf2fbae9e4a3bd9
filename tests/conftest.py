"""Shared fixtures: the paper's Table 1 parameters, a two-agent scenario in the plane."""

import pytest

TABLE1 = dict(kp=6.0, kd=25.0, g=9.8, r_l=12.0, im_l=0.1, im_r=0.55)


@pytest.fixture
def table1():
    return dict(TABLE1)


def write_pair_2d(path, duration, record_every):
    """Write two agents meeting head-on in the plane, (11), dt = 1 ms, to ``path``."""
    path.write_text(f"""
name = "pair2d"
[space]
axes = 2
[interaction]
function = "improved"
[simulation]
dt = 0.001
duration = {duration}
record_every = {record_every}
[[agents]]
position = [50.0, 0.0]
velocity = [-1.5, 0.0]
[[agents]]
position = [0.0, 0.0]
velocity = [3.0, 0.0]
""")
    return path


@pytest.fixture(scope="module")
def pair_2d_factory(tmp_path_factory):
    """``make(duration, record_every)``: the path of a new :func:`write_pair_2d` scenario file."""
    return lambda duration, record_every: write_pair_2d(tmp_path_factory.mktemp("pair2d") / "pair2d.toml", duration, record_every)
