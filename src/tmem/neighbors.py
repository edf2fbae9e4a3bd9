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


def all_pairs(n_agents: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows listing, for every agent, every other agent: ``(ptr, idx, order)`` with ``order`` the identity."""
    idx = np.empty(n_agents * (n_agents - 1), dtype=np.int32)
    for i in range(n_agents):
        idx[i * (n_agents - 1) : (i + 1) * (n_agents - 1)] = np.delete(np.arange(n_agents), i)
    ptr = np.arange(0, n_agents * (n_agents - 1) + 1, n_agents - 1, dtype=np.int64)
    return ptr, idx, np.arange(n_agents, dtype=np.int64)


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
        halved = max(1, shape[a] // 2)
        if box[a] > 0.0:
            shape[a] = halved if halved >= 3 else 1  # as above: never 2 cells round a periodic axis
            size[a] = box[a] / shape[a]
        else:
            size[a] = size[a] * shape[a] / halved
            shape[a] = halved
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


@numba.njit(cache=True, parallel=True)
def verlet_lists(points, active, cutoff, box, ptr, idx, order):
    """Verlet lists over *slots*: the active agents sorted by cell.

    Fills ``order[:m]`` with the agents in cell order (``m`` active agents) and,
    for each slot ``s``, row ``ptr[s]:ptr[s + 1]`` of ``idx`` with the slots of
    the agents within ``cutoff`` of agent ``order[s]``, sorted by agent index.
    Neighbours in one cell grid are then close in memory.  Returns ``(needed,
    m)``; if ``needed`` exceeds ``len(idx)`` the rows are not filled and the
    caller must grow ``idx`` and call again.
    """
    n, axes = points.shape
    cell_of, shape, start, cells_order = _cells(points, active, cutoff, box)
    m = cells_order.shape[0]
    order[:m] = cells_order
    cutoff2 = cutoff * cutoff
    s1 = shape[1] if axes > 1 else 1
    s2 = shape[2] if axes > 2 else 1
    count = np.zeros(m, dtype=np.int64)
    for fill in range(2):
        if fill == 1:
            ptr[0] = 0
            for s in range(m):
                ptr[s + 1] = ptr[s] + count[s]
            if ptr[m] > idx.shape[0]:
                return ptr[m], m
        for s in numba.prange(m):
            i = cells_order[s]
            c = cell_of[i]
            h0 = c // (s1 * s2)
            h1 = (c // s2) % s1
            h2 = c % s2
            found = 0
            for o0 in range(-1, 2) if shape[0] > 1 else range(0, 1):
                k0 = h0 + o0
                if box[0] > 0.0:
                    k0 %= shape[0]
                elif k0 < 0 or k0 >= shape[0]:
                    continue
                for o1 in range(-1, 2) if s1 > 1 else range(0, 1):
                    k1 = h1 + o1
                    if axes > 1 and box[1] > 0.0:
                        k1 %= s1
                    elif k1 < 0 or k1 >= s1:
                        continue
                    for o2 in range(-1, 2) if s2 > 1 else range(0, 1):
                        k2 = h2 + o2
                        if axes > 2 and box[2] > 0.0:
                            k2 %= s2
                        elif k2 < 0 or k2 >= s2:
                            continue
                        cell = (k0 * s1 + k1) * s2 + k2
                        for t in range(start[cell], start[cell + 1]):
                            j = cells_order[t]
                            if j == i:
                                continue
                            r2 = 0.0
                            for a in range(axes):
                                delta = nearest_image(points[j, a] - points[i, a], box[a])
                                r2 += delta * delta
                            if r2 < cutoff2:
                                if fill == 1:
                                    # insertion into the row, kept sorted by agent index
                                    q = ptr[s] + found
                                    while q > ptr[s] and cells_order[idx[q - 1]] > j:
                                        idx[q] = idx[q - 1]
                                        q -= 1
                                    idx[q] = t
                                found += 1
            if fill == 0:
                count[s] = found
    return ptr[m], m
