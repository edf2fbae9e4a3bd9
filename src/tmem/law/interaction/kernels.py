"""Compiled interaction functions: one scalar kernel per row of the registry.

Every kernel has one signature, ``kernel(r, f_en, p) -> U``: the pair
measure's size ``r = |d| >= 0`` (m, a float), with ``d = P*_j - P*_i`` of (6),
the pair flag ``F_en`` (an int), and the parameters record :class:`FunctionParams`
(``K_P``, ``R + R_j``, ``d_t``, ``c_max``).  It
returns agent ``i``'s tilt set-point contribution ``U`` (rad) for ``d > 0``,
saturated at ``|U| <= c_max``; negative ``U`` pushes the agent away from its
neighbour.  The functions are odd in ``d``, so for ``d < 0`` the contribution
is ``-U``, and the neighbour gets ``-U``: in 1-D ``U sign(d)``, in 2-D and 3-D
``U d / |d|``.

Notation, with ``reach = R + R_j``::

    c = r - reach   (7, for d > 0),   b = (d_t + reach) / 2

* repulsion (8):      K_P c inside the spheres, 0 outside.
* attraction (Fig. 3): K_P (r - d_t) inside the spheres, 0 outside:
  pushes apart closer than d_t, pulls together farther than d_t.
* switching (10):     f1 = repulsion (8) while the pair is uncoupled
  (``f_en = 0``); f2 = K_P (r - d_t) at any distance while coupled.
* improved (11):      f1 = 0 outside, K_P c on (b, reach), -K_P (r - d_t)
  on [d_t, b], K_P (r - d_t) closer than d_t; f2 as in (10).  f1 is
  continuous, and f1 = f2 for ``r <= d_t``, so coupling at ``r = d_t``
  causes no jump in control.
* none:               0 at any distance: the TMEM law off, so that an agent
  term (a flocking law of :mod:`tmem.terms`) acts alone.

The paper writes the saturation as ``max(s_d C_max, .)``; it is read here as
``|U| <= c_max`` with the sign set by the function.  ``K_P`` is the modal gain
on position (the paper's ``K1``).

:func:`pair_control` dispatches on a function's integer code; it is composed
from the registry when this module is imported, one branch per row (each a
compiled closure over its row's kernel), and the step loop, the batch and
:func:`evaluate` call it.  The kernels and the
dispatch are inlined by Numba itself (``inline="always"``): a function loaded
from Numba's on-disk cache cannot be inlined by the compiler, and a call left
inside the loop of neighbour pushes would keep that loop from being vectorised
(measured: 1.6 times slower at 10^5 agents).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.law.interaction.registry import FUNCTIONS, code


class FunctionParams(NamedTuple):
    """Parameters every kernel receives.

    Attributes
    ----------
    k_p : float
        ``K_P``, the modal gain on position (1/m · rad).
    reach : float
        ``R + R_j`` (m): the distance below which two agents interact.
    d_t : float
        Set distance of the pair (m).
    c_max : float
        Tilt limit (rad).
    """

    k_p: float
    reach: float
    d_t: float
    c_max: float


#: Where ``d_t`` and ``reach`` sit in :class:`FunctionParams`, and the fields after them (slices of a
#: record in compiled code need bounds known before it is typed).
_D_T, _REACH = FunctionParams._fields.index("d_t"), FunctionParams._fields.index("reach")
_AFTER_D_T, _AFTER_REACH = _D_T + 1, _REACH + 1


@numba.njit(cache=True, inline="always")
def with_d_t(p, d_t):
    """``p`` with the set distance ``d_t`` (a formation pair's own), every other field as it is.

    Parameters
    ----------
    p : FunctionParams
        The interaction functions' parameters.
    d_t : float
        The set distance (m).
    """
    return FunctionParams(*(p[:_D_T] + (d_t,) + p[_AFTER_D_T:]))


@numba.njit(cache=True, inline="always")
def with_reach(p, reach):
    """``p`` with the reach ``reach`` (a wall's ``R + R_w``), every other field as it is.

    Parameters
    ----------
    p, reach
        The interaction functions' parameters, and the reach (m) that replaces theirs.
    """
    return FunctionParams(*(p[:_REACH] + (reach,) + p[_AFTER_REACH:]))


@numba.njit(cache=True, inline="always")
def _saturate(u, c_max):
    return min(max(u, -c_max), c_max)


@numba.njit(cache=True, inline="always")
def _overlap(r, p):
    """``K_P c`` with ``c = r - reach`` (7): the push of (8) inside the spheres, 0 outside."""
    return p.k_p * (r - p.reach) if r < p.reach else 0.0


@numba.njit(cache=True, inline="always")
def _spring(r, p):
    """``K_P (r - d_t)``: apart closer than ``d_t``, together farther."""
    return p.k_p * (r - p.d_t)


@numba.njit(cache=True, inline="always")
def repulsion(r, f_en, p):
    """Repulsion (8): ``K_P (r - reach)`` for ``r < reach``, else 0; saturated.

    Parameters
    ----------
    r, f_en, p
        As every kernel takes them (module text); ``f_en`` is unused.
    """
    return _saturate(_overlap(r, p), p.c_max)


@numba.njit(cache=True, inline="always")
def attraction(r, f_en, p):
    """Attraction (Fig. 3): ``K_P (r - d_t)`` for ``r < reach``, else 0; saturated.

    Parameters
    ----------
    r, f_en, p
        As every kernel takes them (module text); ``f_en`` is unused, as in :func:`repulsion`.
    """
    return _saturate(_spring(r, p), p.c_max) if r < p.reach else 0.0


@numba.njit(cache=True, inline="always")
def switching(r, f_en, p):
    """Switching (10): f1 = repulsion (8) if ``f_en == 0``, else f2 = ``K_P (r - d_t)``; saturated.

    Parameters
    ----------
    r, f_en, p
        As every kernel takes them (module text); ``f_en`` chooses between f1 and f2.
    """
    return _saturate(_overlap(r, p) if f_en == 0 else _spring(r, p), p.c_max)


@numba.njit(cache=True, inline="always")
def improved_switching(r, f_en, p):
    """Improved switching (11): the continuous f1 if ``f_en == 0``, else f2; saturated.

    Parameters
    ----------
    r, f_en, p
        As every kernel takes them (module text); ``f_en`` chooses, as in :func:`switching`.
    """
    if f_en != 0 or r < p.d_t:
        u = _spring(r, p)
    elif r <= 0.5 * (p.d_t + p.reach):
        u = -_spring(r, p)
    else:
        u = _overlap(r, p)
    return _saturate(u, p.c_max)


@numba.njit(cache=True, inline="always")
def no_push(r, f_en, p):
    """The function ``"none"``: 0 at any distance, the TMEM law off.

    Parameters
    ----------
    r, f_en, p
        As every kernel takes them (module text); all unused.
    """
    return 0.0


#: The docstring of :func:`pair_control` and of each branch it is composed of.
_DISPATCH_DOC = """``U`` of the function with the integer code ``function`` (its registry row) for one pair.

Parameters
----------
function : int
    The registry code (:func:`tmem.law.interaction.registry.code`).
r, f_en, p
    As the kernels take them: ``|d|`` (m), ``F_en``, :class:`FunctionParams`.
"""


def _dispatch(rows) -> object:
    """:func:`pair_control` over the registry's ``rows``: the first row's kernel where ``function`` is
    its code, else the dispatch over the rest (the last row's kernel where no code matched)."""
    kernel, number = globals()[rows[0].kernel], code(rows[0].name)
    if len(rows) == 1:
        @numba.njit(inline="always")
        def dispatch(function, r, f_en, p):
            return kernel(r, f_en, p)
    else:
        rest = _dispatch(rows[1:])

        @numba.njit(inline="always")
        def dispatch(function, r, f_en, p):
            if function == number:
                return kernel(r, f_en, p)
            return rest(function, r, f_en, p)

    dispatch.__doc__ = _DISPATCH_DOC
    return dispatch


#: ``pair_control(function, r, f_en, p)``: the kernel of the function with code ``function``.
pair_control = _dispatch(FUNCTIONS)


@numba.njit(cache=True, error_model="numpy", inline="always")
def push_factor(function, r2, p):
    """``f(|d|) / |d|`` of a pair without a flag (``F_en = 0``) at ``|d|^2 = r2``: times ``d_a`` it is
    the push on agent ``i`` along axis ``a``; 0 beyond reach and at ``|d| = 0``.

    The step loop's neighbour stage and the per-agent controller (:mod:`tmem.agent`) push with it,
    so both get the same bits.  Both branches are computed and one kept: a loop over pairs
    that calls it still vectorises.

    Parameters
    ----------
    function : int
        The registry code (:func:`tmem.law.interaction.registry.code`).
    r2 : float
        ``|d|^2`` (m^2), ``d = P*_j - P*_i``.
    p : FunctionParams
        The functions' parameters.
    """
    inside = (r2 < p.reach * p.reach) & (r2 > 0.0)
    r = np.sqrt(r2)
    push = pair_control(function, r, 0, p) / r
    return push if inside else 0.0


@numba.njit(cache=True)
def _evaluate(function, d, f_en, p, out):
    for t in range(d.size):
        r = abs(d[t])
        out[t] = pair_control(function, r, f_en[t], p) * (1.0 if d[t] > 0 else -1.0 if d[t] < 0 else 0.0)


def evaluate(function: str, d, f_en=0, *, k_p: float, reach: float, d_t: float, c_max: float) -> np.ndarray:
    """Evaluate the named interaction function on an array of signed pair measures ``d``.

    Parameters
    ----------
    function
        A name in :data:`tmem.law.interaction.registry.FUNCTION_NAMES`.
    d
        Pair measures ``P*_j - P*_i`` (m), any shape.
    f_en
        Pair flags, broadcast against ``d``.
    k_p, reach, d_t, c_max
        The fields of :class:`FunctionParams`.

    Returns
    -------
    ndarray
        ``U`` (rad) on agent ``i``, shaped as ``d`` and ``f_en`` broadcast together.
    """
    d, flags = np.broadcast_arrays(np.asarray(d, dtype=float), np.asarray(f_en, dtype=np.int64))
    out = np.empty(d.shape)
    params = FunctionParams(k_p=float(k_p), reach=float(reach), d_t=float(d_t), c_max=float(c_max))
    _evaluate(code(function), np.ascontiguousarray(d).ravel(), np.ascontiguousarray(flags).ravel(), params, out.reshape(-1))
    return out
