"""Shared fixtures (the paper's Table 1 parameters, a two-agent scenario in the plane) and each test's kind.

Every test has one kind, a marker (registered in pyproject.toml; docs/architecture.md, "Tests"):

* ``unit``: compiled kernels and small functions on small inputs against closed forms or brute
  force; seconds in all.
* ``physics``: runs against independent references with tolerances (closed forms, scipy's
  integration, python-control, RotorPy, conservation laws, symmetries), and the bit-equalities that
  are the product's claims (threads, resumed checkpoints, per-agent controllers), each saying so.
* ``pins``: regression pins of the bits (tests/test_pins.py).
* ``interface``: what the user meets: the command line, the files, the figures, the viewer, the
  documentation, and the refusals of bad input.

A test module's tests get its kind from :data:`MODULE_KINDS`; a test marked with a kind of its own
keeps that one.
"""

import gc
import os
import signal
from fnmatch import fnmatch

import pytest

# The suite plays a user's Ctrl-C on the commands it starts. Where it was itself started with SIGINT
# ignored (a background job of a non-interactive shell), the commands would inherit that and, as
# they should, leave it ignored: take Python's own handler back, so that they start with the default.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# A run says on standard error when its step loop compiles (tmem.engine.driver.COMPILING), whichever test
# comes first to a kind of run: the tests of what commands write there would depend on their order.
# They run without it (inherited by the commands they start); tests/test_compile_notice.py turns it on.
os.environ["TMEM_NO_COMPILE_NOTICE"] = "1"

KINDS = ("unit", "physics", "pins", "interface")

#: Each test module's kind, by the name of its module (shell patterns allowed), for the tests that
#: are not marked with a kind of their own.
MODULE_KINDS = {
    "unit": ["test_kernels", "test_interaction", "test_coupling", "test_metrics", "test_coverage", "test_plan",
             "test_field_metrics"],
    "physics": [
        "test_model", "test_control", "test_reference", "test_settling", "test_paper_results", "test_engine",
        "test_terms", "test_flocking_laws", "test_swarm", "test_gas", "test_sensing", "test_sensing_runs", "test_batch",
        "test_agent_controller", "test_checkpoint", "test_quadrotor", "test_quadrotor_runs",
        "test_flight_controller", "test_wind", "test_ground_robot", "test_physical_bounds", "test_navigation", "test_reshape", "test_safety",
    ],
    "pins": ["test_pins"],
    "interface": [
        "test_animate", "test_api_inputs", "test_bad_*", "test_cli_help", "test_compile_notice", "test_crazyflies", "test_docs_text", "test_docstrings",
        "test_examples", "test_exchange", "test_exchange_cf", "test_extensions", "test_figures", "test_interruptions",
        "test_light_imports", "test_literal_text", "test_output_directories", "test_outputs", "test_plot_command",
        "test_sweep_failures", "test_sweep_run", "test_sweep_spec", "test_trajectory_file", "test_vehicle_sweeps",
        "test_viewer", "test_viewer_browser",
    ],
}  # fmt: skip


def module_kind(module: str) -> str | None:
    """The kind of a test module's tests (its name without the package), or None if it has none."""
    for kind, patterns in MODULE_KINDS.items():
        if any(fnmatch(module, pattern) for pattern in patterns):
            return kind
    return None


@pytest.hookimpl(tryfirst=True)  # before ``-m`` chooses by the markers
def pytest_collection_modifyitems(config, items):
    unknown = {}
    for item in items:
        if any(item.get_closest_marker(kind) for kind in KINDS):
            continue
        module = item.module.__name__.rpartition(".")[2] if getattr(item, "module", None) else ""
        kind = module_kind(module)
        if kind is None:
            unknown.setdefault(module, item)
        else:
            item.add_marker(kind)
    for module, item in unknown.items():
        item.warn(pytest.PytestWarning(f"tests/{module}.py has no kind: add it to MODULE_KINDS in tests/conftest.py"))


@pytest.hookimpl(trylast=True)
def pytest_runtest_teardown(item, nextitem):
    """Collect a test's garbage, then freeze what is left (``gc.freeze``) out of later collections.

    What outlives a test is mostly Numba's: its first compiled loop leaves some 280 000 objects
    alive for the session (types, signatures, the compiled library), each later one tens of
    thousands more, and each full collection of Python's cyclic garbage collector scanned them all
    again.  Measured on 2 cores:
    the per-agent controllers' tests, then the viewer's and the exchange's, took 139 s of CPU with
    them scanned and 106 s frozen.  Nothing a test checks depends on the collector.
    """
    gc.collect()
    gc.freeze()


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
