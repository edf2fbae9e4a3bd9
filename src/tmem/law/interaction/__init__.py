"""Interaction functions of a pair of agents: (8), Fig. 3, (10) and (11), and ``"none"`` (the law off).

* :mod:`tmem.law.interaction.registry` — the list of functions and what each
  claims (no compiled code: the scenario schema reads it);
* :mod:`tmem.law.interaction.kernels` — one compiled scalar kernel per function,
  the dispatch the step loop inlines, and :func:`evaluate` over arrays.

``evaluate`` is reachable here too; it loads the compiled kernels on first use.
"""

from __future__ import annotations

from tmem.law.interaction.registry import FUNCTION_NAMES, FUNCTIONS, InteractionFunction, code, pushes, uses_coupling

__all__ = ["FUNCTIONS", "FUNCTION_NAMES", "InteractionFunction", "code", "evaluate", "pushes", "uses_coupling"]


def __getattr__(name: str):
    if name == "evaluate":
        from tmem.law.interaction.kernels import evaluate

        return evaluate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
