"""Random obstacle fields: discs of random radii at random in a box, apart from each other.

A mission's test ground (``docs/missions.md``): ``n`` discs with radii uniform in ``radii``, centres
uniform in the box ``[lower, upper]``, each disc at least ``gap`` from every other, drawn one after the
other and drawn again where it would overlap, from one seed.
"""

from __future__ import annotations

import numpy as np

__all__ = ["random_discs"]

#: Draws of one disc before the field is declared too crowded.
MAX_TRIES = 10_000


def random_discs(n: int, lower, upper, radii: tuple[float, float], gap: float = 0.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``n`` discs in the box ``[lower, upper]`` (2-D), radii uniform in ``radii``, each ``gap`` from the others.

    Parameters
    ----------
    n : int
        How many discs.
    lower, upper : array_like, shape (2,)
        The box the centres lie in (m).
    radii : (float, float)
        The least and largest radius (m).
    gap : float
        The least distance between two discs' edges (m).
    seed : int
        The draws' seed: the same seed gives the same field.

    Returns
    -------
    centres : ndarray, shape (n, 2)
    radii : ndarray, shape (n,)

    Raises
    ------
    ValueError
        When a disc finds no room after :data:`MAX_TRIES` draws.
    """
    rng = np.random.default_rng(seed)
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    centres, sizes = np.zeros((0, 2)), np.zeros(0)
    for k in range(n):
        for _ in range(MAX_TRIES):
            radius, centre = rng.uniform(*radii), rng.uniform(lower, upper)
            if np.all(np.linalg.norm(centres - centre, axis=1) >= sizes + radius + gap):
                centres, sizes = np.vstack([centres, centre]), np.append(sizes, radius)
                break
        else:
            raise ValueError(f"disc {k} of {n} finds no room in the box after {MAX_TRIES} draws: fewer discs or a larger box")
    return centres, sizes
