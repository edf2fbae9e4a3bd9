"""Random starts at least a given distance apart, by Poisson-disk sampling, refused where they cannot fit.

:func:`spaced_points` fills the box ``[lower, upper]`` with Bridson's Poisson-disk sampling [1]_
(:class:`scipy.stats.qmc.PoissonDisk`, ``fill_space``: points are added around earlier ones until
no candidate fits, so the sample is spread over the whole box), then takes ``n`` of them at random.
Any subset of a sample ``s`` apart is ``s`` apart.

The spacing holds in metres whatever the box's shape: PoissonDisk's ``radius`` is in the units of
the space it samples.  With SciPy >= 1.15 that space is the box itself (``l_bounds``,
``u_bounds``).  Before, it is the unit cube: the cube is sampled with ``radius = s / L``, ``L``
the box's longest side, scaled by ``L`` (distances scale by ``L`` alike on every axis) and the
points beyond the shorter sides dropped; the same spacing, at the cost of sampling ``L^d / V``
times the volume.  Bridson's loop runs in Python: about 1 ms a point (a box that holds 10^4
points at the spacing takes some 10 s, whatever ``n``).

Before sampling, ``n`` is refused when the densest packing cannot hold it:

* in the plane, Oler's inequality [2]_: at most ``(2 / sqrt 3) A / s^2 + P / (2 s) + 1`` points
  of a convex region of area ``A`` and perimeter ``P`` are ``s`` apart (its leading term is the
  hexagonal packing's, ``A / ((sqrt 3 / 2) s^2)``; the others count the points on the border, so
  that four points fit in a square of side ``s``); on a line, ``L / s + 1``;
* in space, the balls of radius ``s / 2`` about the points lie in the box grown by ``s / 2`` on
  each side and fill at most ``pi / sqrt 18`` of it (Kepler's conjecture, Hales [3]_):
  ``n <= sqrt 2 prod(L_k + s) / s^3``.

A random sample fills only about half the densest packing (in the plane about ``0.6 / s^2`` points
a unit area against ``1.15 / s^2``), so a box can pass the bound and still yield fewer than ``n``
points; that is refused too, saying how many it gave.

References
----------
.. [1] R. Bridson, "Fast Poisson disk sampling in arbitrary dimensions", ACM SIGGRAPH 2007
   sketches, article 22 (2007), doi:10.1145/1278780.1278807.
.. [2] N. Oler, "An inequality in the geometry of numbers", Acta Mathematica 105, 19-48 (1961).
.. [3] T. C. Hales, "A proof of the Kepler conjecture", Annals of Mathematics 162(3), 1065-1185
   (2005).
"""

from __future__ import annotations

import inspect
import math

import numpy as np

__all__ = ["packing_bound", "spaced_points"]


def _box(lower: object, upper: object) -> tuple[np.ndarray, np.ndarray]:
    lower, upper = np.atleast_1d(np.asarray(lower, dtype=float)), np.atleast_1d(np.asarray(upper, dtype=float))
    if lower.ndim != 1 or lower.shape != upper.shape or not 1 <= len(lower) <= 3:
        raise ValueError(f"lower and upper must be the box's corners on 1 to 3 axes, got shapes {lower.shape} and {upper.shape}")
    if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper)) and np.all(upper > lower)):
        raise ValueError(f"the box needs finite corners, upper > lower on every axis: got {lower.tolist()}, {upper.tolist()}")
    return lower, upper


def _spacing(min_spacing: float) -> float:
    if not (math.isfinite(min_spacing) and min_spacing > 0.0):
        raise ValueError(f"min_spacing must be a finite distance > 0 m, got {min_spacing}")
    return float(min_spacing)


def packing_bound(lower: object, upper: object, min_spacing: float) -> int:
    """The most points of the box ``[lower, upper]`` that can be ``min_spacing`` apart, bounded above (module text).

    Parameters
    ----------
    lower, upper : array_like, shape (d,)
        The box's corners (m), ``d`` = 1, 2 or 3, ``upper > lower``.
    min_spacing : float
        ``s`` (m), > 0.

    Returns
    -------
    int
        No more than this many points fit (Oler's inequality in the plane; sphere packing in space).
    """
    lower, upper = _box(lower, upper)
    s = _spacing(min_spacing)
    sides = upper - lower
    if len(sides) == 1:
        bound = sides[0] / s + 1.0
    elif len(sides) == 2:
        bound = 2.0 / math.sqrt(3.0) * sides[0] * sides[1] / s**2 + (sides[0] + sides[1]) / s + 1.0
    else:
        bound = math.sqrt(2.0) * float(np.prod(sides + s)) / s**3
    return int(math.floor(bound * (1.0 + 1e-12)))


def _engine(d: int, radius: float, rng: np.random.Generator, bounds: tuple[np.ndarray, np.ndarray] | None) -> object:
    """A PoissonDisk over ``bounds`` (SciPy >= 1.15) or the unit cube, drawing from ``rng``."""
    from scipy.stats import qmc

    taken = inspect.signature(qmc.PoissonDisk).parameters
    options = {"rng" if "rng" in taken else "seed": rng}
    if bounds is not None:
        options.update(l_bounds=bounds[0], u_bounds=bounds[1])
    return qmc.PoissonDisk(d, radius=radius, **options)


def _fill(lower: np.ndarray, upper: np.ndarray, spacing: float, rng: np.random.Generator, bounded: bool) -> np.ndarray:
    """A Poisson-disk sample of the box, every two points at least ``spacing`` apart (m).

    ``bounded``: sample the box itself (SciPy >= 1.15); else the unit cube scaled by the longest
    side, the points beyond the box dropped.  The radius is raised by 1e-9 relative so that the
    spacing survives the scaling's rounding.
    """
    sides = upper - lower
    radius = spacing * (1.0 + 1e-9)
    if bounded:
        return _engine(len(sides), radius, rng, (lower, upper)).fill_space()
    longest = float(sides.max())
    points = _engine(len(sides), radius / longest, rng, None).fill_space() * longest
    return points[np.all(points <= sides, axis=1)] + lower


def _bounded() -> bool:
    """Whether this SciPy's PoissonDisk samples a box of its own (``l_bounds``, SciPy >= 1.15)."""
    from scipy.stats import qmc

    return "l_bounds" in inspect.signature(qmc.PoissonDisk).parameters


def spaced_points(
    n: int, lower: object, upper: object, min_spacing: float, seed: int | np.random.Generator | None = None
) -> np.ndarray:
    """``n`` random points of the box ``[lower, upper]``, every two at least ``min_spacing`` apart.

    Parameters
    ----------
    n : int
        How many points, >= 0.
    lower, upper : array_like, shape (d,)
        The box's corners (m), ``d`` = 1, 2 or 3, ``upper > lower`` on every axis.
    min_spacing : float
        The least distance between two points (m), > 0.
    seed : int or numpy.random.Generator, optional
        The random draws' seed: the same seed gives the same points.

    Returns
    -------
    ndarray, shape (n, d)
        The points (m), in random order.

    Raises
    ------
    ValueError
        When ``n`` points cannot be ``min_spacing`` apart in the box (:func:`packing_bound`), or
        when the sample holds fewer than ``n``.
    """
    lower, upper = _box(lower, upper)
    spacing = _spacing(min_spacing)
    if isinstance(n, bool) or int(n) != n or n < 0:
        raise ValueError(f"n must be an integer >= 0, got {n}")
    n = int(n)
    region = " x ".join(f"[{a:g}, {b:g}]" for a, b in zip(lower, upper)) + " m"
    most = packing_bound(lower, upper, spacing)
    if n > most:
        raise ValueError(
            f"{n} points cannot be {spacing:g} m apart in {region}: at most {most} fit"
            f" ({'Oler' if len(lower) < 3 else 'densest sphere packing'} bound)"
        )
    rng = np.random.default_rng(seed)
    if n == 0:
        return np.zeros((0, len(lower)))
    points = _fill(lower, upper, spacing, rng, _bounded())
    if len(points) < n:
        raise ValueError(
            f"Poisson-disk sampling placed only {len(points)} points {spacing:g} m apart in {region}, fewer than"
            f" n = {n} (the densest packing holds at most {most}): enlarge the box or lower the spacing"
        )
    return points[rng.choice(len(points), size=n, replace=False)]
