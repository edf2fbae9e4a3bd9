"""Reading a run's files back to draw them: which agents and times are kept, and damaged files.

``tmem animate`` and ``tmem view`` draw a saved run.  Both thin large runs
the same way (:func:`evenly`: at most so many indices, evenly spread, the
first and the last kept; :func:`columns` finds a pair's agents among those
kept), and both refuse a damaged ``trajectory.nc`` in one
line: h5py, h5netcdf, xarray and NumPy each fail on one in their own way, and
:func:`reason` makes of any of these failures a short phrase, while
:func:`quiet_unraisable` keeps the half-opened file's errors at clean-up off
the screen.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

__all__ = ["columns", "evenly", "quiet_unraisable", "reason"]


def evenly(n: int, at_most: int) -> np.ndarray:
    """At most ``at_most`` indices into ``range(n)``, evenly spread, the first and the last kept.

    Parameters
    ----------
    n : int
        How many there are.
    at_most : int
        How many may be kept (at least 2 keeps both ends).
    """
    if n <= at_most:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, at_most)).astype(int))


def columns(ids: np.ndarray, wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where each of ``wanted`` is in ``ids``, and whether it is there at all.

    Maps a pair's agents (``pair_i``, ``pair_j``: agent numbers) to the columns
    of the agents kept; a pair is drawn when both of its agents are there.

    Parameters
    ----------
    ids : ndarray of int, shape (n,)
        The numbers of the agents kept, distinct, in their columns' order.
    wanted : ndarray of int, shape (m,)
        Agent numbers to look up.

    Returns
    -------
    column : ndarray of int, shape (m,)
        A column of ``ids`` for each of ``wanted``; meaningful only where ``found``.
    found : ndarray of bool, shape (m,)
        Whether each of ``wanted`` is in ``ids``.
    """
    order = np.argsort(ids)
    k = order[np.clip(np.searchsorted(ids, wanted, sorter=order), 0, len(ids) - 1)]
    return k, ids[k] == wanted


@contextmanager
def quiet_unraisable() -> Iterator[None]:
    """Silence errors raised while objects are freed in the block (h5netcdf's half-opened file on a damaged one)."""
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None
    try:
        yield
    finally:
        gc.collect()
        sys.unraisablehook = hook


def reason(exc: Exception) -> str:
    """An exception as a short phrase of one line: its message, or its class when it has none.

    Parameters
    ----------
    exc : Exception
        The failure, from any library.
    """
    text = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
    text = text.strip().splitlines()[0] if text.strip() else type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."
