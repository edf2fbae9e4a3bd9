"""Which pairs of agents interact: neighbour lists over the corrected positions P* (6).

Agents interact when ``|P*_j - P*_i| < R + R_j``.  Each agent keeps a list
of candidates, sorted by index, in compressed rows (``ptr``, ``idx``):

* **all pairs** — every other agent; built once (small swarms);
* **Verlet lists** — every agent within ``R + R_j + skin``, found through a
  cell grid of that side in O(N) and rebuilt only once some agent's P* has
  moved more than ``skin / 2`` since the last build.  No pair that is not
  listed can come within ``R + R_j`` before then.

Because both kinds of list are sorted, an agent sums its neighbours'
contributions in the same order either way: the two give the same bits.
With a periodic box, differences are taken to the nearest image.
"""

from __future__ import annotations

import numba
import numpy as np


def all_pairs(n_agents: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows listing, for every agent, every other agent: ``(ptr, idx)``."""
    idx = np.empty(n_agents * (n_agents - 1), dtype=np.int32)
    for i in range(n_agents):
        idx[i * (n_agents - 1) : (i + 1) * (n_agents - 1)] = np.delete(np.arange(n_agents), i)
    return np.arange(0, n_agents * (n_agents - 1) + 1, n_agents - 1, dtype=np.int64), idx


@numba.njit(cache=True)
def nearest_image(delta, side):
    """``delta`` taken to the nearest periodic image along an axis of length ``side`` (0: not periodic)."""
    if side > 0.0:
        return delta - side * np.floor(delta / side + 0.5)
    return delta


@numba.njit(cache=True)
def _cells(points, active, cutoff, box):
    """Bin active points into a grid of cells of side >= cutoff; counting sort by cell.

    Returns ``(cell_of, n_cells_per_axis, start, order)``: the cell of each point
    (-1 if inactive), the grid shape, and the points sorted by cell with the
    first index of each cell.
    """
    n, axes = points.shape
    lo = np.zeros(axes)
    shape = np.ones(axes, dtype=np.int64)
    size = np.ones(axes)
    for a in range(axes):
        if box[a] > 0.0:
            lo[a] = 0.0
            k = int(box[a] // cutoff)
            shape[a] = k if k >= 3 else 1  # fewer than 3 cells would list a neighbour twice
            size[a] = box[a] / shape[a]
        else:
            low, high = np.inf, -np.inf
            for i in range(n):
                if active[i]:
                    low = min(low, points[i, a])
                    high = max(high, points[i, a])
            if low > high:
                low, high = 0.0, 0.0
            lo[a] = low
            shape[a] = max(1, int((high - low) // cutoff))
            size[a] = max(cutoff, (high - low) / shape[a] + 1e-9 * cutoff)
    # Never more cells than about 2 per agent along all axes together.
    while np.prod(shape) > 2 * n + 8:
        a = np.argmax(shape)
        shape[a] = max(1, shape[a] // 2)
        size[a] = (box[a] if box[a] > 0.0 else size[a] * 2 * shape[a]) / shape[a]
    n_cells = np.prod(shape)
    cell_of = np.full(n, -1, dtype=np.int64)
    count = np.zeros(n_cells + 1, dtype=np.int64)
    for i in range(n):
        if active[i]:
            c = 0
            for a in range(axes):
                position = points[i, a] - lo[a]
                if box[a] > 0.0:
                    position -= box[a] * np.floor(position / box[a])
                k = min(int(position / size[a]), shape[a] - 1)
                c = c * shape[a] + k
            cell_of[i] = c
            count[c + 1] += 1
    start = np.cumsum(count)
    fill = start[:-1].copy()
    order = np.empty(start[-1], dtype=np.int64)
    for i in range(n):
        if cell_of[i] >= 0:
            order[fill[cell_of[i]]] = i
            fill[cell_of[i]] += 1
    return cell_of, shape, start, order


@numba.njit(cache=True)
def _cell_coords(c, shape, coords):
    for a in range(shape.shape[0] - 1, -1, -1):
        coords[a] = c % shape[a]
        c //= shape[a]


@numba.njit(cache=True, parallel=True)
def verlet_lists(points, active, cutoff, box, ptr, idx):
    """Fill ``(ptr, idx)`` with, for each active agent, the active agents within ``cutoff``.

    Returns the number of entries needed.  If it exceeds ``len(idx)`` nothing
    is filled in ``idx`` and the caller must grow it and call again.
    """
    n, axes = points.shape
    cell_of, shape, start, order = _cells(points, active, cutoff, box)
    cutoff2 = cutoff * cutoff
    n_offsets = 3**axes
    count = np.zeros(n, dtype=np.int64)
    for fill in range(2):
        if fill == 1:
            ptr[0] = 0
            for i in range(n):
                ptr[i + 1] = ptr[i] + count[i]
            if ptr[n] > idx.shape[0]:
                return ptr[n]
        for i in numba.prange(n):
            if cell_of[i] < 0:
                continue
            home = np.empty(axes, dtype=np.int64)
            other = np.empty(axes, dtype=np.int64)
            _cell_coords(cell_of[i], shape, home)
            found = 0
            for o in range(n_offsets):
                code = o
                c = 0
                inside = True
                for a in range(axes):
                    step = code % 3 - 1
                    code //= 3
                    if shape[a] == 1 and step != 0:
                        inside = False  # a single cell along this axis holds every neighbour already
                        break
                    k = home[a] + step
                    if box[a] > 0.0:
                        k %= shape[a]
                    elif k < 0 or k >= shape[a]:
                        inside = False
                        break
                    other[a] = k
                    c = c * shape[a] + k
                if not inside:
                    continue
                for s in range(start[c], start[c + 1]):
                    j = order[s]
                    if j == i:
                        continue
                    r2 = 0.0
                    for a in range(axes):
                        delta = nearest_image(points[j, a] - points[i, a], box[a])
                        r2 += delta * delta
                    if r2 < cutoff2:
                        if fill == 1:
                            idx[ptr[i] + found] = j
                        found += 1
            if fill == 0:
                count[i] = found
            else:  # sort the row: contributions are then summed in index order
                row = idx[ptr[i] : ptr[i] + found]
                row.sort()
    return ptr[n]
