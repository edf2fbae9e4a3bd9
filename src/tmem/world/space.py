"""The space the agents fly in: open axes, or a periodic box of side ``box[a]`` along axis ``a``.

Differences of positions are taken to the nearest periodic image, and positions are kept inside
the box; an open axis has side 0.  Compiled, and inlined where they are called.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)


@numba.njit(cache=True, inline="always")
def nearest_image(delta, side):
    """``delta`` taken to the nearest periodic image along an axis of length ``side`` (0: not periodic).

    Parameters
    ----------
    delta : float
        A difference of positions along the axis (m).
    side : float
        The box side along the axis (m); 0 on an open axis.
    """
    if abs(delta) < 0.25 * side:
        return delta  # what the rounding below gives, without a division
    if side > 0.0:
        return delta - side * np.floor(delta / side + 0.5)
    return delta


@numba.njit(cache=True, inline="always")
def into_box(position, side):
    """``position`` taken into ``[0, side)`` along a periodic axis (``side > 0``).

    Parameters
    ----------
    position, side : float
        A position along the axis, and the box side along it (m).
    """
    return position - side * np.floor(position / side)
