"""Submodules loaded on first use: ``tmem.law.interaction`` works after ``import tmem`` alone.

Each package of :mod:`tmem` sets ``__getattr__ = submodules(__name__)`` (PEP 562), so that reading a
submodule as an attribute imports it, and importing the package imports nothing heavy.  The
registries (:data:`tmem.vehicles.VEHICLES`, :data:`tmem.terms.TERMS`) name their classes as
``"module:name"`` strings, imported when a run needs them (:func:`import_named`).
"""

from __future__ import annotations

from importlib import import_module
from importlib.util import find_spec


def submodules(package: str):
    """A module ``__getattr__`` that imports ``package.name`` when ``name`` is one of its submodules.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    """

    def __getattr__(name: str) -> object:
        if not name.startswith("_") and find_spec(f"{package}.{name}") is not None:
            return import_module(f".{name}", package)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__


def import_named(path: str) -> object:
    """The object ``path = "module:name"`` names, its module imported now (a registry's row).

    Parameters
    ----------
    path : str
        ``"module:name"``, e.g. ``"tmem.terms.pull:Pull"``.
    """
    module, name = path.split(":")
    return getattr(import_module(module), name)
