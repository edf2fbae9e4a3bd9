"""The interaction functions tmem knows, one row each: (8), Fig. 3, (10), (11), and ``"none"`` (the law off).

This module is the one list of functions.  The scenario schema takes its
choices from it, :func:`tmem.law.interaction.kernels.pair_control` dispatches on
its codes, and the documentation's table is written from it.  It imports no
compiled code, so a scenario can be validated without loading Numba.

A row's ``code`` is its place in :data:`FUNCTIONS`; its ``kernel`` names the
scalar kernel in :mod:`tmem.law.interaction.kernels`.  Adding a function is one
kernel there and one row here (see ``docs/architecture.md``).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class InteractionFunction:
    """One interaction function and the properties it claims (tests check each claim).

    Attributes
    ----------
    name : str
        The scenario's ``interaction.function`` value.
    kernel : str
        Name of its scalar kernel ``kernel(r, f_en, params)`` in :mod:`tmem.law.interaction.kernels`.
    equation : str
        Where the paper gives it.
    couples : bool
        Whether it switches on the pair flag ``F_en`` (and so can hold a formation).
    continuous : bool
        Whether it is continuous in ``|d|`` while uncoupled (``F_en = 0``).
    summary : str
        One line for the documentation's table.
    pushes : bool
        Whether it pushes at all: ``False`` for ``"none"``, the TMEM law off, so that a scenario can
        run an agent term alone (a flocking law of :mod:`tmem.terms`).
    """

    name: str
    kernel: str
    equation: str
    couples: bool
    continuous: bool
    summary: str
    pushes: bool = True


FUNCTIONS: tuple[InteractionFunction, ...] = (
    InteractionFunction("repulsion", "repulsion", "(8)", couples=False, continuous=True,
                        summary="K_P c inside the spheres, 0 outside: pushes apart"),
    InteractionFunction("attraction", "attraction", "Fig. 3", couples=False, continuous=False,
                        summary="K_P (d - s_d d_t) inside the spheres, 0 outside: apart closer than d_t, together farther"),
    InteractionFunction("switching", "switching", "(10)", couples=True, continuous=True,
                        summary="repulsion (8) while uncoupled; K_P (d - s_d d_t) at any distance while coupled"),
    InteractionFunction("improved", "improved_switching", "(11)", couples=True, continuous=True,
                        summary="a continuous f1 equal to f2 closer than d_t; f2 of (10) while coupled"),
    InteractionFunction("none", "no_push", "the law off", couples=False, continuous=True, pushes=False,
                        summary="0 at any distance: no pair pushes, so that an agent term (a flocking law) acts alone"),
)  # fmt: skip

#: The names, in the order of their integer codes.
FUNCTION_NAMES: tuple[str, ...] = tuple(row.name for row in FUNCTIONS)


def code(name: str) -> int:
    """The integer code of the function called ``name`` (its place in :data:`FUNCTIONS`).

    Parameters
    ----------
    name : str
        A name in :data:`FUNCTION_NAMES`.
    """
    return FUNCTION_NAMES.index(name)


def pushes(name: str) -> bool:
    """False for ``"none"``, the function that pushes nothing (the TMEM law off).

    Parameters
    ----------
    name : str
        A name in :data:`FUNCTION_NAMES`.
    """
    return FUNCTIONS[code(name)].pushes


def uses_coupling(name: str) -> bool:
    """True for the functions that switch on the pair flag ``F_en``, such as (10) and (11).

    Parameters
    ----------
    name : str
        A name in :data:`FUNCTION_NAMES`.
    """
    return FUNCTIONS[code(name)].couples
