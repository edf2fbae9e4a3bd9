"""A run says, in one line on standard error, when its step loop compiles, and only then.

``tmem.engine.variants.compiles`` is checked against what Numba does in fresh processes with a cache
of their own (a tiny function: compiled, then loaded from the cache); the driver's line against a
run whose loop is taken as uncompiled, and against a run whose loop is already compiled.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import tmem
from tmem.engine import driver
from tmem.scenario import with_changes

PROBE = """
import numba
from tmem.engine.variants import bound, compiles

def template(x):
    return x + 1.0

twice = bound(template, "notice_probe", {"cache": True})
print(compiles(twice, (1.0,)), end=" ")
twice(1.0)
print(compiles(twice, (1.0,)), end=" ")
print(compiles(twice, (1,)))  # compiled in this process: any overload counts
"""


def probe(folder) -> str:
    """The probe run from a file of ``folder`` (Numba caches functions of files only), its cache there too."""
    (folder / "probe.py").write_text(PROBE)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(folder / "cache"))
    return subprocess.run([sys.executable, str(folder / "probe.py")], capture_output=True, text=True, env=env, check=True).stdout


def test_compiles_says_true_before_the_first_compilation_and_false_once_cached(tmp_path):
    assert probe(tmp_path) == "True False False\n"  # a new cache: it compiles, then it is compiled
    assert probe(tmp_path) == "False False False\n"  # the next process finds it in the cache


def run_fig9(monkeypatch, capsys, compiling: bool):
    monkeypatch.delenv(driver.QUIET, raising=False)
    monkeypatch.setattr(driver, "compiles", lambda advance, args: compiling)
    tmem.simulate(with_changes(tmem.preset("fig9"), {"simulation.duration": 1.0, "commands": []}))
    return capsys.readouterr().err


def test_a_run_whose_loop_compiles_says_so_in_one_line_naming_its_kind(monkeypatch, capsys):
    err = run_fig9(monkeypatch, capsys, True)
    assert err.count("\n") == 1 and err.startswith("tmem: compiling the step loop for this kind of run (advance__linear__exact")
    assert "about 30 s" in err


@pytest.mark.parametrize("quiet", [False, True])
def test_a_run_whose_loop_is_compiled_or_a_quiet_one_says_nothing(monkeypatch, capsys, quiet):
    if quiet:
        monkeypatch.setenv(driver.QUIET, "1")
        monkeypatch.setattr(driver, "compiles", lambda advance, args: True)
        tmem.simulate(with_changes(tmem.preset("fig9"), {"simulation.duration": 1.0, "commands": []}))
        assert capsys.readouterr().err == ""
    else:
        assert run_fig9(monkeypatch, capsys, False) == ""
