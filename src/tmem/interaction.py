"""Interaction functions of a pair of agents: (8), Fig. 3, (10) and (11).

Each function takes the paper's pair measure ``d = P*_j - P*_i`` (m), the
difference of the neighbour's and the agent's corrected positions (6), and
returns the agent's tilt set-point contribution ``U`` (rad), saturated at
``|U| <= c_max``.  Negative ``U`` for positive ``d`` pushes the agent away from
its neighbour; the neighbour gets ``-U`` (the functions are odd in ``d``).
In 2-D and 3-D the same functions are evaluated at ``|d|`` and act along
``d / |d|``.

Notation, with ``reach = R + R_j``::

    s_d = sign(d),  c = d - s_d reach   (7),   b = (d_t + reach) / 2

* repulsion (8):      K_P c inside the spheres, 0 outside.
* attraction (Fig. 3): K_P (d - s_d d_t) inside the spheres, 0 outside:
  pushes apart closer than d_t, pulls together farther than d_t.
* switching (10):     f1 = repulsion (8) while the pair is uncoupled
  (``f_en = 0``); f2 = K_P (d - s_d d_t) at any distance while coupled.
* improved (11):      f1 = 0 outside, K_P c on (b, reach), -K_P (d - s_d d_t)
  on [d_t, b], K_P (d - s_d d_t) closer than d_t; f2 as in (10).  f1 is
  continuous, and f1 = f2 for ``|d| <= d_t``, so coupling at ``|d| = d_t``
  causes no jump in control.

The paper writes the saturation as ``max(s_d C_max, .)``; it is read here as
``|U| <= c_max`` with the sign set by the function.

``K_P`` is the modal gain on position (the paper's ``K1``).  Each function is
written once and compiled by Numba twice: as a NumPy ufunc that broadcasts
over arrays, and as a scalar function that the compiled step loop calls one
pair at a time (:func:`pair_control`).  The scalar functions are inlined by
Numba itself (``inline="always"``): a function loaded from Numba's on-disk
cache cannot be inlined by the compiler, and a call left inside the loop of
neighbour pushes would keep that loop from being vectorised (measured: 1.6
times slower at 10^5 agents).
"""

from __future__ import annotations

import numba
import numpy as np

from . import _numba_cache  # noqa: F401  (drops stale compiled caches before any load)

#: Interaction function names, in the order of their integer codes.
FUNCTIONS = ("repulsion", "attraction", "switching", "improved")
REPULSION, ATTRACTION, SWITCHING, IMPROVED = range(4)


def uses_coupling(function: str) -> bool:
    """True for the functions that switch on the pair flag ``F_en``: (10) and (11)."""
    return function in ("switching", "improved")


@numba.njit(cache=True, inline="always")
def _saturate(u: float, c_max: float) -> float:
    return min(max(u, -c_max), c_max)


@numba.njit(cache=True, inline="always")
def _sign(d: float) -> float:
    return (d > 0.0) - (d < 0.0)


@numba.njit(cache=True, inline="always")
def _overlap(d: float, k_p: float, reach: float) -> float:
    """``K_P c`` with ``c = d - s_d reach`` (7): the push of (8) inside the spheres, 0 outside."""
    return k_p * (d - _sign(d) * reach) if abs(d) < reach else 0.0


@numba.njit(cache=True, inline="always")
def _spring(d: float, k_p: float, d_t: float) -> float:
    """``K_P (d - s_d d_t)``: apart closer than ``d_t``, together farther."""
    return k_p * (d - _sign(d) * d_t)


@numba.njit(cache=True, inline="always")
def _repulsion(d, k_p, reach, c_max):
    """Repulsion (8): ``K_P (d - s_d reach)`` for ``|d| < reach``, else 0; saturated."""
    return _saturate(_overlap(d, k_p, reach), c_max)


@numba.njit(cache=True, inline="always")
def _attraction(d, k_p, reach, d_t, c_max):
    """Attraction (Fig. 3): ``K_P (d - s_d d_t)`` for ``|d| < reach``, else 0; saturated."""
    return _saturate(_spring(d, k_p, d_t), c_max) if abs(d) < reach else 0.0


@numba.njit(cache=True, inline="always")
def _switching(d, f_en, k_p, reach, d_t, c_max):
    """Switching (10): f1 = repulsion (8) if ``f_en == 0``, else f2 = ``K_P (d - s_d d_t)``; saturated."""
    return _saturate(_overlap(d, k_p, reach) if f_en == 0 else _spring(d, k_p, d_t), c_max)


@numba.njit(cache=True, inline="always")
def _improved_switching(d, f_en, k_p, reach, d_t, c_max):
    """Improved switching (11): the continuous f1 if ``f_en == 0``, else f2; saturated."""
    r = abs(d)
    if f_en != 0 or r < d_t:
        u = _spring(d, k_p, d_t)
    elif r <= 0.5 * (d_t + reach):
        u = -_spring(d, k_p, d_t)
    else:
        u = _overlap(d, k_p, reach)
    return _saturate(u, c_max)


def _ufunc(signature: str, scalar):
    """The same function as a NumPy ufunc (the step loop calls the scalar one, which it can inline)."""
    ufunc = numba.vectorize([signature], cache=True)(scalar.py_func)
    ufunc.__doc__ = scalar.__doc__
    return ufunc


repulsion = _ufunc("float64(float64, float64, float64, float64)", _repulsion)
attraction = _ufunc("float64(float64, float64, float64, float64, float64)", _attraction)
switching = _ufunc("float64(float64, int64, float64, float64, float64, float64)", _switching)
improved_switching = _ufunc("float64(float64, int64, float64, float64, float64, float64)", _improved_switching)


@numba.njit(cache=True, inline="always")
def pair_control(function, d, f_en, k_p, reach, d_t, c_max):
    """Dispatch to the function with integer code ``function`` (see :data:`FUNCTIONS`), for one pair."""
    if function == REPULSION:
        return _repulsion(d, k_p, reach, c_max)
    if function == ATTRACTION:
        return _attraction(d, k_p, reach, d_t, c_max)
    if function == SWITCHING:
        return _switching(d, f_en, k_p, reach, d_t, c_max)
    return _improved_switching(d, f_en, k_p, reach, d_t, c_max)


def evaluate(function: str, d, f_en=0, *, k_p: float, reach: float, d_t: float, c_max: float) -> np.ndarray:
    """Evaluate the named interaction function on an array of pair measures ``d``."""
    code = FUNCTIONS.index(function)
    d = np.asarray(d, dtype=float)
    if code == REPULSION:
        return repulsion(d, k_p, reach, c_max)
    if code == ATTRACTION:
        return attraction(d, k_p, reach, d_t, c_max)
    if code == SWITCHING:
        return switching(d, np.asarray(f_en, dtype=np.int64), k_p, reach, d_t, c_max)
    return improved_switching(d, np.asarray(f_en, dtype=np.int64), k_p, reach, d_t, c_max)
