"""What loads what: validation and the command line's help stay free of Numba, xarray and matplotlib.

Checked as modules present after an import, in a fresh interpreter; how fast a
start is belongs to benchmarks, not to tests.
"""

import subprocess
import sys

import pytest

import tmem
from tmem import _numba_cache

HEAVY = ("numba", "xarray", "matplotlib")


def loaded_after(code: str) -> set[str]:
    """The heavy libraries in ``sys.modules`` after running ``code`` in a new interpreter."""
    probe = f"{code}\nimport sys\nprint('loaded:', *(m for m in {HEAVY!r} if m in sys.modules))"
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return set(proc.stdout.rpartition("loaded:")[2].split())


def test_validating_a_scenario_loads_no_numba():
    assert "numba" not in loaded_after("import tmem.scenario; tmem.scenario.preset('fig9')")


def test_loading_a_file_and_editing_it_loads_no_numba():
    code = (
        "import tmem.scenario as s\n"
        "text = s.preset('fig9').to_toml()\n"
        "s.with_changes(s.loads(text), {'interaction.function': 'repulsion'})"
    )
    assert "numba" not in loaded_after(code)


def test_the_command_line_module_loads_nothing_heavy():
    assert loaded_after("import tmem.cli.main") == set()


@pytest.mark.parametrize("args", [["--help"], ["--version"], ["run", "--help"], ["sweep", "--help"], ["plot", "--help"], ["export", "--help"]])
def test_help_works_and_loads_nothing_heavy(args):
    code = f"import sys; sys.argv = ['tmem', *{args!r}]\nfrom tmem.cli.main import main\ntry:\n    main()\nexcept SystemExit as e:\n    assert not e.code, e.code"
    assert loaded_after(code) == set()


def test_the_package_names_load_on_first_use():
    assert tmem.simulate.__module__ == "tmem.engine.driver"
    assert tmem.preset("fig9").name
    assert set(tmem.__all__) <= set(dir(tmem))
    for name in tmem.__all__:
        assert getattr(tmem, name) is not None
    assert tmem.engine.simulate is tmem.simulate  # submodules too, as before
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        tmem.nonsense  # noqa: B018


def test_numba_cache_is_dropped_when_any_source_below_the_package_changes(tmp_path, monkeypatch):
    package = tmp_path / "pkg"
    (package / "sub" / "__pycache__").mkdir(parents=True)
    (package / "__pycache__").mkdir()
    (package / "a.py").write_text("x = 1\n")
    (package / "sub" / "b.py").write_text("y = 1\n")
    monkeypatch.setattr(_numba_cache, "_PACKAGE", package)
    monkeypatch.setattr(_numba_cache, "_STAMP", package / "__pycache__" / "numba-sources.sha256")
    caches = [package / "__pycache__" / "a.f-1.py311.nbi", package / "sub" / "__pycache__" / "b.g-2.py311.nbc"]

    def make_caches():
        for cache in caches:
            cache.write_bytes(b"compiled")

    make_caches()
    _numba_cache.refresh()  # no stamp yet: dropped
    assert not any(c.exists() for c in caches)
    make_caches()
    _numba_cache.refresh()  # nothing changed: kept
    assert all(c.exists() for c in caches)
    (package / "sub" / "b.py").write_text("y = 2\n")  # a subpackage's source changed
    _numba_cache.refresh()
    assert not any(c.exists() for c in caches)


def test_a_module_moved_by_role_still_imports_under_its_old_name(monkeypatch):
    import importlib

    for name in ("tmem.model", "tmem.model.linear"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    with pytest.warns(DeprecationWarning, match=r"tmem\.model\.linear is now tmem\.vehicles\.linear"):
        old = importlib.import_module("tmem.model.linear")
    from tmem.vehicles.linear import state_matrices

    assert old.state_matrices is state_matrices
    with pytest.raises(AttributeError):
        old.nonsense  # noqa: B018
