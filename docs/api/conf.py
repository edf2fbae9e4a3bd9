"""Sphinx configuration of tmem's API reference, built from the docstrings.

Build from the repository root (``pip install -e '.[docs]'`` first)::

    sphinx-build -W --keep-going -b html docs/api docs/api/_build/html

numpydoc renders the numpy-style sections (Parameters, Returns, Attributes).
autodoc documents Numba-compiled functions as functions: a ``CPUDispatcher``
is a routine carrying its Python function's docstring, and its signature
through ``__wrapped__`` (its ``py_func``).  ``tests/test_docstrings.py``
checks that every public module has a page here and every parameter is
documented.
"""

from __future__ import annotations

import importlib
import inspect
import sys
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.pycode import ModuleAnalyzer
from sphinx.util.docutils import SphinxDirective

# The checkout's source first, so that the reference describes the code beside it.
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "src"))

import tmem  # noqa: E402

project = "tmem"
author = "tmem developers"
release = version = tmem.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.viewcode",
    "numpydoc",
]

exclude_patterns = ["_build"]
root_doc = "index"
html_theme = "alabaster"
html_static_path: list[str] = []

autodoc_member_order = "bysource"
autodoc_default_options = {"show-inheritance": True}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True

# autodoc documents the members; numpydoc's own member tables would list them twice.
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True


def _first_paragraph(doc: str | None) -> str:
    """The summary of a docstring as one line."""
    return " ".join(inspect.cleandoc(doc or "").split("\n\n")[0].split())


def _defined_in(package: str, name: str, value: object) -> tuple[str, str]:
    """``(target, summary)`` of an exported name, looked up where it is defined (and documented)."""
    obj = getattr(value, "py_func", value)  # a Numba dispatcher's Python function
    if inspect.isclass(obj) or inspect.isfunction(obj):
        return f"{obj.__module__}.{obj.__qualname__}", _first_paragraph(obj.__doc__)
    for module in sorted(m for m in sys.modules if m.startswith(package + ".")):
        try:
            comments = ModuleAnalyzer.for_module(module).find_attr_docs()
        except Exception:  # noqa: BLE001  (a module without source: not where it is documented)
            continue
        if ("", name) in comments:
            return f"{module}.{name}", _first_paragraph("\n".join(comments["", name]))
    return f"{package}.{name}", ""


class ExportedNames(SphinxDirective):
    """``.. exported-names:: package``: a package's ``__all__``, each name linked to its definition.

    A package re-exports names defined in its submodules; documenting them again
    here would describe each object twice, so the package page lists them.
    """

    required_arguments = 1
    option_spec = {"caption": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        package = self.arguments[0]
        module = importlib.import_module(package)
        lines = [f".. rubric:: {self.options.get('caption', 'Names exported here')}", ""]
        for name in module.__all__:
            target, summary = _defined_in(package, name, getattr(module, name))
            lines.append(f"* :py:obj:`{name} <{target}>`" + (f" — {summary}" if summary else ""))
        return self.parse_text_to_nodes("\n".join(lines))


def _no_signature_for_data(app, what, name, obj, options, signature, return_annotation):
    """Keep numpydoc from handing a signature to an object that has none.

    Sphinx 9.0 stores a handler's signature at ``signatures[0]`` even when the
    list is empty (data, type aliases, extension types), which drops the object
    with "error while formatting signature" (sphinx-doc/sphinx#14576).  An
    empty, non-None result stops the event there; objects with a signature go
    on to numpydoc as usual.
    """
    return () if signature is None else None


def _skip_field_aliases(app, what, name, obj, skip, options):
    """Leave out a NamedTuple's generated "Alias for field number n": its Attributes section says more."""
    if what == "class" and (getattr(obj, "__doc__", None) or "").startswith("Alias for field number"):
        return True
    return None


def setup(app):
    app.add_directive("exported-names", ExportedNames)
    app.connect("autodoc-skip-member", _skip_field_aliases)
    app.connect("autodoc-process-signature", _no_signature_for_data, priority=400)
