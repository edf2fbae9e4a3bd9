"""Which pairs of agents interact: neighbour lists over the corrected positions P* (6).

Agents interact when ``|P*_j - P*_i| < R + R_j``.  Candidates are kept in
compressed rows (``ptr``, ``idx``), sorted by index:

* **all pairs** — every pair; built once (small swarms);
* **Verlet lists** — every pair within ``R + R_j + skin``, found through a
  cell grid of that side in O(N) and rebuilt only once some agent's P* has
  moved more than ``skin / 2`` since the last build.  No pair that is not
  listed can come within ``R + R_j`` before then.

The step loop takes each candidate pair once, as a list of ``(i, j)`` with
``i < j`` sorted by ``i`` then ``j``, and gives the pair's pushes, equal and
opposite, to both agents.  Every agent thus gets its neighbours'
contributions in the order of their indices with either kind of list: the
two give the same bits.  The loop numbers the
agents in a spatial order (:func:`spatial_order`), so that neighbours are
close in memory.  With a periodic box, differences are taken to the nearest
image.
"""

from __future__ import annotations

import numba
import numpy as np


def all_pairs(n_agents: int) -> np.ndarray:
    """Every pair ``(i, j)``, ``i < j``, once, sorted: shape (pairs, 2), unsigned."""
    return np.stack(np.triu_indices(n_agents, k=1), axis=1).astype(np.uint32)


@numba.njit(cache=True)
def nearest_image(delta, side):
    """``delta`` taken to the nearest periodic image along an axis of length ``side`` (0: not periodic)."""
    if abs(delta) < 0.25 * side:
        return delta  # what the rounding below gives, without a division
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


@numba.njit(cache=True)
def _forward_rows(shape):
    """Offsets of the rows of cells (along all axes but the last) that visit every pair of
    neighbouring rows once: the row itself, then the offsets in {-1, 0, 1}^(axes - 1) whose first
    non-zero entry is +1 (only 0 along an axis of one cell)."""
    axes = shape.shape[0] - 1
    rows = np.zeros((3**axes, axes), dtype=np.int64)
    n = 1  # row 0: the row itself
    for code in range(3**axes):
        first = 0
        valid = True
        rest = code
        for a in range(axes - 1, -1, -1):
            o = rest % 3 - 1
            rest //= 3
            rows[n, a] = o
            if o != 0 and shape[a] == 1:
                valid = False
            if o != 0:
                first = o  # the last one set is the first axis's
        if valid and first == 1:
            n += 1
    return rows[:n]


@numba.njit(cache=True)
def verlet_lists(points, active, cutoff, box, ptr, idx, order):
    """Verlet lists over *slots*: the active agents sorted by cell.

    Fills ``order[:m]`` with the agents in cell order (``m`` active agents) and,
    for each slot ``s``, row ``ptr[s]:ptr[s + 1]`` of ``idx`` with the slots of
    the agents within ``cutoff`` of agent ``order[s]``, sorted by agent index.
    Each pair of neighbouring cells is searched once; the cells along the last
    axis are contiguous in slots, so a row of them is searched in one run.
    Returns ``(needed, m)``; if ``needed`` exceeds ``len(idx)`` the rows are
    not filled and the caller must grow ``idx`` and call again.
    """
    n, axes = points.shape
    cell_of, shape, start, cells_order = _cells(points, active, cutoff, box)
    m = cells_order.shape[0]
    order[:m] = cells_order
    local = np.empty((m, axes))  # the points in slot order: neighbours close in memory
    for s in range(m):
        local[s] = points[cells_order[s]]
    rows = _forward_rows(shape)
    last = axes - 1
    width = shape[last]
    cutoff2 = cutoff * cutoff
    capacity = idx.shape[0] // 2
    first = np.empty(capacity + 1, dtype=np.int32)  # the pairs found, by slot (one spare entry)
    second = np.empty(capacity + 1, dtype=np.int32)
    count = np.zeros(m + 1, dtype=np.int64)
    n_pairs = 0
    home = np.zeros(axes, dtype=np.int64)  # the cell's indices along the axes, counted up as c goes
    home[last] = -1
    runs = np.empty((2, 2), dtype=np.int64)  # up to two runs of cells along the last axis
    for c in range(start.shape[0] - 1):
        a = last
        home[a] += 1
        while home[a] == shape[a]:
            home[a] = 0
            a -= 1
            home[a] += 1
        if start[c] == start[c + 1]:
            continue
        for r in range(rows.shape[0]):
            base = 0  # the neighbouring row's first cell
            for a in range(last):
                k = home[a] + rows[r, a]
                if k < 0 or k >= shape[a]:
                    if box[a] == 0.0:
                        base = -1
                        break
                    k += shape[a] if k < 0 else -shape[a]  # round the periodic axis
                base = base * shape[a] + k
            if base < 0:
                continue
            base *= width
            # cells home - 1 .. home + 1 along the last axis (from home itself in the same row)
            low = home[last] if r == 0 else home[last] - 1
            high = home[last] + 1
            if width == 1:
                low, high = 0, 0
            n_runs = 1
            runs[0, 0], runs[0, 1] = low, high
            if box[last] == 0.0:
                runs[0, 0], runs[0, 1] = max(low, 0), min(high, width - 1)
            elif low < 0:
                runs[0, 0], runs[1, 0], runs[1, 1] = 0, width - 1, width - 1
                n_runs = 2
            elif high == width:
                runs[0, 1], runs[1, 0], runs[1, 1] = width - 1, 0, 0
                n_runs = 2
            for s in range(start[c], start[c + 1]):
                found = 0
                for q in range(n_runs):
                    t_first = start[base + runs[q, 0]]
                    if r == 0 and runs[q, 0] == home[last]:
                        t_first = s + 1  # in its own cell, each pair once
                    for t in range(t_first, start[base + runs[q, 1] + 1]):
                        r2 = 0.0
                        for a in range(axes):
                            delta = nearest_image(local[t, a] - local[s, a], box[a])
                            r2 += delta * delta
                        close = r2 < cutoff2
                        slot = min(n_pairs, capacity)  # past capacity, only counted
                        first[slot] = s
                        second[slot] = t
                        n_pairs += close
                        found += close
                        count[t + 1] += close
                count[s + 1] += found
    ptr[: m + 1] = np.cumsum(count)
    if ptr[m] > idx.shape[0]:
        return ptr[m], m
    fill = ptr[:m].copy()
    for p in range(n_pairs):
        s = first[p]
        t = second[p]
        idx[fill[s]] = t
        fill[s] += 1
        idx[fill[t]] = s
        fill[t] += 1
    for s in range(m):  # each row sorted by agent index, by insertion
        for e in range(ptr[s] + 1, ptr[s + 1]):
            t = idx[e]
            q = e
            while q > ptr[s] and cells_order[idx[q - 1]] > cells_order[t]:
                idx[q] = idx[q - 1]
                q -= 1
            idx[q] = t
    return ptr[m], m


@numba.njit(cache=True)
def pair_list(ptr, idx, order, m, pairs):
    """The pairs of Verlet lists (:func:`verlet_lists`), each once, in the points' own numbering.

    Fills the rows of ``pairs`` (at least ``ptr[m] // 2``) with ``(i, j)``,
    ``i < j``, sorted by ``i`` then ``j``, and returns how many there are.
    """
    start = np.zeros(order.shape[0] + 1, dtype=np.int64)
    above = np.empty(m, dtype=np.int64)  # where each row's neighbours j > i begin: the row is sorted
    for s in range(m):
        i = order[s]
        e = ptr[s]
        while e < ptr[s + 1] and order[idx[e]] < i:
            e += 1
        above[s] = e
        start[i + 1] = ptr[s + 1] - e
    for i in range(order.shape[0]):
        start[i + 1] += start[i]
    for s in range(m):
        i = order[s]
        q = start[i]
        for e in range(above[s], ptr[s + 1]):
            pairs[q, 0] = i
            pairs[q, 1] = order[idx[e]]
            q += 1
    return start[-1]


def spatial_order(points: np.ndarray, active: np.ndarray, side: float, box: np.ndarray) -> np.ndarray:
    """A numbering of the agents in which neighbours are close: active agents by cells of ``side``, then the rest."""
    cells_order = _cells(points, active, side, box)[3]
    return np.concatenate([cells_order, np.flatnonzero(~active)]).astype(np.int64)
