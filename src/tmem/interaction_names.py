"""The interaction functions' names, without Numba: what a scenario may name.

The scenario schema validates ``[interaction] function`` against these names
and asks :func:`uses_coupling` which functions switch on the pair flag; it
must not import the compiled kernels of :mod:`tmem.interaction` to do so
(validating a file would then load Numba).
"""

from __future__ import annotations

#: Interaction function names, in the order of their integer codes in :mod:`tmem.interaction`.
FUNCTION_NAMES: tuple[str, ...] = ("repulsion", "attraction", "switching", "improved")


def uses_coupling(name: str) -> bool:
    """True for the functions that switch on the pair flag ``F_en``: (10) and (11)."""
    return name in ("switching", "improved")
