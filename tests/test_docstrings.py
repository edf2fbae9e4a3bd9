"""Every public function and method documents each of its parameters (numpy style).

In the spirit of python-control's ``control/tests/docstrings_test.py``: walk the
public modules of :mod:`tmem`, take every public function, Numba dispatcher
(through ``.py_func``) and method of a public class, and check that its
docstring exists and that every parameter of its signature is named in its
``Parameters`` section.  A line ``name1, name2 : type`` documents both names.
The constructor of a class is checked against the class docstring, as numpydoc
renders it.  Records (dataclasses, NamedTuples, pydantic models) take their
fields as constructor arguments; the fields are described in their
``Attributes`` section or, for the scenario tables, in ``docs/parameters.md``,
so only their docstring is required here.

Public: no leading underscore, and listed in the module's ``__all__`` where it
has one, else defined in that module.  ``self``/``cls`` are skipped;
``*args``/``**kwargs`` count as documented when named as ``*args``/``**kwargs``
or by their bare name.

Run it alone to list what fails: ``python tests/test_docstrings.py``.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import re
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

import tmem

#: Modules skipped by the walk, with the reason.
SKIP_MODULES = {"tmem.__main__": "runs the command line on import"}

_HEADER = re.compile(r"^(\S[^\n]*)\n-{3,}[ \t]*$", re.MULTILINE)


def public_modules() -> list[str]:
    """The names of tmem's modules that have no underscore-led part, imported."""
    names = ["tmem"]
    for info in pkgutil.walk_packages(tmem.__path__, prefix="tmem."):
        if any(part.startswith("_") for part in info.name.split(".")) or info.name in SKIP_MODULES:
            continue
        names.append(info.name)
    return sorted(names)


def defined_in(module, name: str, value) -> bool:
    """Whether ``module`` defines ``value``: by its ``__module__``, or, for a function made at
    import time (``exec``, as the interaction dispatch is: no ``__module__``), by an assignment."""
    owner = getattr(value, "__module__", None)
    if owner is None:
        return re.search(rf"^{re.escape(name)}\s*(:[^=\n]*)?=", inspect.getsource(module), re.MULTILINE) is not None
    return owner == module.__name__


def public_names(module) -> list[str]:
    """``__all__`` if the module has one, else the public names it defines itself."""
    if hasattr(module, "__all__"):
        return list(module.__all__)
    return [
        name
        for name, value in vars(module).items()
        if not name.startswith("_") and (inspect.isclass(value) or callable(value)) and defined_in(module, name, value)
    ]


def unwrap(obj):
    """A Numba dispatcher's Python function (``.py_func``), else ``obj``."""
    return getattr(obj, "py_func", obj)


def sections(doc: str) -> dict[str, str]:
    """A cleaned numpy-style docstring split into its titled sections (the summary under ``""``)."""
    found = {}
    marks = list(_HEADER.finditer(doc))
    found[""] = doc[: marks[0].start()] if marks else doc
    for mark, after in zip(marks, marks[1:] + [None]):
        found[mark.group(1).strip()] = doc[mark.end() : after.start() if after else len(doc)]
    return found


def documented_parameters(doc: str | None) -> set[str]:
    """The names a docstring's ``Parameters`` (and ``Other Parameters``) section documents."""
    if not doc:
        return set()
    names = set()
    parts = sections(inspect.cleandoc(doc))
    for title in ("Parameters", "Other Parameters"):
        for line in parts.get(title, "").splitlines():
            if not line.strip() or line[0].isspace():
                continue
            head = line.split(" : ", 1)[0].rstrip(":").strip()
            for name in head.split(","):
                name = name.strip()
                names.add(name)
                names.add(name.lstrip("*"))
    return names


def undocumented(func: Callable, doc: str | None) -> list[str]:
    """The parameters of ``func``'s signature that ``doc`` does not name."""
    try:
        signature = inspect.signature(func)
    except (TypeError, ValueError):  # no signature to check against
        return []
    named = documented_parameters(doc)
    missing = []
    for index, (name, parameter) in enumerate(signature.parameters.items()):
        if index == 0 and name in ("self", "cls"):
            continue
        label = {parameter.VAR_POSITIONAL: f"*{name}", parameter.VAR_KEYWORD: f"**{name}"}.get(parameter.kind, name)
        if name not in named and label not in named:
            missing.append(label)
    return missing


def is_record(cls: type) -> bool:
    """A class whose constructor takes its fields: a dataclass, a NamedTuple or a pydantic model."""
    if dataclasses.is_dataclass(cls) or (issubclass(cls, tuple) and hasattr(cls, "_fields")):
        return True
    return any(base.__module__.startswith("pydantic") for base in cls.__mro__[1:])


def class_members(cls: type) -> Iterator[tuple[str, Callable | None, str | None]]:
    """``(name, function or None, docstring)`` of the class's own public methods and properties."""
    for name, value in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(value, property):
            yield name, None, value.__doc__
        elif isinstance(value, (staticmethod, classmethod)):
            yield name, value.__func__, value.__func__.__doc__
        elif inspect.isfunction(value) or hasattr(value, "py_func"):
            func = unwrap(value)
            yield name, func, func.__doc__


def checked_objects() -> Iterator[tuple[str, Callable | None, str | None]]:
    """``(qualified name, function or None, docstring)`` of every public object, once each."""
    seen = set()
    for module_name in public_modules():
        module = importlib.import_module(module_name)
        for name in public_names(module):
            value = getattr(module, name)
            if not (inspect.isclass(value) or inspect.isfunction(value) or hasattr(value, "py_func")):
                continue  # constants and type aliases: documented by their comment
            obj = unwrap(value)
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            qualified = f"{obj.__module__ or module_name}.{obj.__qualname__}"
            if inspect.isfunction(obj):
                yield qualified, obj, value.__doc__  # a dispatcher's own, as autodoc shows it
                continue
            own_init = vars(obj).get("__init__")
            hand_written = own_init is not None and not is_record(obj)
            yield qualified, (obj if hand_written else None), obj.__doc__
            for member, func, doc in class_members(obj):
                yield f"{qualified}.{member}", func, doc


def problems(name: str, func: Callable | None, doc: str | None) -> list[str]:
    """What is wrong with one object's docstring, as lines naming it."""
    if not doc or not doc.strip():
        return [f"{name}: no docstring"]
    if func is None:
        return []
    missing = undocumented(func, doc)
    return [f"{name}: parameters not in its Parameters section: {', '.join(missing)}"] if missing else []


def test_the_walk_finds_the_public_modules():
    modules = set(public_modules())
    expected = {
        "tmem", "tmem.scenario", "tmem.world.initial", "tmem.vehicles", "tmem.vehicles.base", "tmem.vehicles.linear",
        "tmem.law.modal", "tmem.law.interaction", "tmem.law.interaction.registry", "tmem.law.interaction.kernels",
        "tmem.law.coupling", "tmem.world.sensing", "tmem.world.neighbors", "tmem.engine", "tmem.engine.records",
        "tmem.engine.stages", "tmem.engine.loop", "tmem.engine.driver", "tmem.engine.trajectory",
        "tmem.batch.encounters", "tmem.analysis.reference", "tmem.analysis.metrics", "tmem.files.io", "tmem.figures.plot", "tmem.figures.animate",
        "tmem.paper.report", "tmem.cli.main", "tmem.sweep", "tmem.sweep.spec", "tmem.sweep.runner",
    }  # fmt: skip
    assert expected <= modules, sorted(expected - modules)
    assert not any(part.startswith("_") for name in modules for part in name.split("."))


def test_every_public_module_has_a_page_in_the_api_reference():
    api = Path(__file__).resolve().parents[1] / "docs" / "api"
    pages = {m for page in api.glob("*.rst") for m in re.findall(r"^\.\. automodule:: (\S+)", page.read_text(), re.M)}
    assert set(public_modules()) <= pages, f"add a page to docs/api (and index.rst) for {sorted(set(public_modules()) - pages)}"
    index = (api / "index.rst").read_text()
    assert all(re.search(rf"^   {re.escape(page.stem)}$", index, re.M) for page in api.glob("tmem*.rst"))


def test_every_public_function_documents_its_parameters():
    checked = list(checked_objects())
    assert len(checked) > 100  # the walk reached the package, not a stub
    failures = [line for item in checked for line in problems(*item)]
    assert not failures, "\n".join(failures)


# --- the check itself: it must be able to fail -------------------------------------------------


def _complete(r, f_en, p):
    """A kernel.

    Parameters
    ----------
    r : float
        Distance (m).
    f_en, p
        The flag and the parameters.
    """


def _missing_one(r, f_en, p):
    """A kernel.

    Parameters
    ----------
    r, f_en : float
        Distance (m) and flag.

    Returns
    -------
    p : float
        Named under Returns, which does not document a parameter.
    """


def _no_section(r, *args, **kwargs):
    """A kernel of ``r``, ``args`` and ``kwargs`` named only in prose."""


def _variadic(r, *args, **kwargs):
    """A kernel.

    Parameters
    ----------
    r : float
        Distance (m).
    *args
        Passed on.
    **kwargs
        Passed on.
    """


class _Controller:
    """A hand-written class.

    Parameters
    ----------
    gains : ndarray
        ``K``.
    """

    def __init__(self, gains, limit):
        self.gains = gains

    def push(self, d, c_max):
        """The push.

        Parameters
        ----------
        d : float
            Pair measure (m).
        """


def test_the_check_finds_a_missing_parameter():
    assert undocumented(_complete, _complete.__doc__) == []
    assert undocumented(_missing_one, _missing_one.__doc__) == ["p"]
    assert undocumented(_no_section, _no_section.__doc__) == ["r", "*args", "**kwargs"]
    assert undocumented(_variadic, _variadic.__doc__) == []
    assert undocumented(_Controller, _Controller.__doc__) == ["limit"]
    assert undocumented(_Controller.push, _Controller.push.__doc__) == ["c_max"]
    assert problems("f", _complete, None) == ["f: no docstring"]
    assert problems("f", _missing_one, _missing_one.__doc__) == ["f: parameters not in its Parameters section: p"]


def test_the_check_reads_numba_dispatchers_through_py_func():
    numba = pytest.importorskip("numba")
    kernel = numba.njit(_missing_one)
    assert unwrap(kernel) is _missing_one
    assert undocumented(unwrap(kernel), unwrap(kernel).__doc__) == ["p"]


if __name__ == "__main__":
    items = list(checked_objects())
    lines = [line for item in items for line in problems(*item)]
    print("\n".join(lines))
    print(f"{len(items)} objects checked, {len(lines)} failing")
