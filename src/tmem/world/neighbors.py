"""Which pairs of agents interact: neighbour lists over the corrected positions P* (6).

Agents interact when ``|P*_j - P*_i| < R + R_j``.  The step loop takes a list
of candidate pairs ``(i, j)``, ``i < j``, of flying agents:

* **all pairs** (:func:`all_pairs`) — every pair; for small swarms;
* **Verlet lists** (:func:`verlet_pairs`) — every pair within
  ``R + R_j + skin``, found through a cell grid of that side in O(N) and
  rebuilt only once some agent's P* has moved more than ``skin / 2`` since the
  last build.  No pair that is not listed can come within ``R + R_j`` before
  then.

Both lists come sorted by ``i`` then ``j``, and :func:`arrange` puts them in
the loop's order: it drops formation pairs, and cuts the agents into blocks of
consecutive indices, the pairs inside each block first and the pairs crossing
between blocks after.  The loop sums the blocks on separate threads, then the
crossing pairs, giving each pair's pushes, equal and opposite, to both agents.
Every agent thus adds its neighbours' pushes in one fixed order: those from
its own block by increasing index, then those from other blocks by
increasing index.  The order depends on the agents' indices and the block
size only, not on the kind of list or the number of threads, so all of these
give the same bits.  The loop numbers the agents in a spatial order
(:func:`spatial_order`), so that neighbours are close in memory and few
pairs cross between blocks.  With a periodic box, differences are taken to
the nearest image.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.world.space import into_box, nearest_image


def all_pairs(active: np.ndarray) -> np.ndarray:
    """Every pair ``(i, j)``, ``i < j``, of active agents, once, sorted: shape (pairs, 2), unsigned.

    Parameters
    ----------
    active : ndarray, shape (agents,), bool
        The flying agents.
    """
    flying = np.flatnonzero(active)
    first, second = np.triu_indices(len(flying), k=1)
    return np.stack([flying[first], flying[second]], axis=1).astype(np.uint32)


@numba.njit(cache=True, inline="always")
def _cell_count(shape):
    """The number of cells of a grid of ``shape``."""
    count = 1
    for k in shape:
        count *= k
    return count


@numba.njit(cache=True)
def _cells(points, active, cutoff, box):
    """Bin active points into a grid of cells of side >= cutoff; counting sort by cell.

    Returns ``(cell_of, n_cells_per_axis, start, order)``: the cell of each point
    (-1 if inactive), the grid shape, and the points sorted by cell with the
    first index of each cell.

    Only ``np.empty`` and loops: each other NumPy function Numba compiles on
    first use, and a two-agent run pays for every one of them.
    """
    n, axes = points.shape
    lo = np.empty(axes)
    shape = np.empty(axes, dtype=np.int64)
    size = np.empty(axes)
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
    while _cell_count(shape) > 2 * n + 8:
        a = 0
        for b in range(1, axes):  # the axis with the most cells, the first of equals
            if shape[b] > shape[a]:
                a = b
        halved = max(1, shape[a] // 2)
        if box[a] > 0.0:
            shape[a] = halved if halved >= 3 else 1  # as above: never 2 cells round a periodic axis
            size[a] = box[a] / shape[a]
        else:
            size[a] = size[a] * shape[a] / halved
            shape[a] = halved
    n_cells = _cell_count(shape)
    cell_of = np.empty(n, dtype=np.int64)
    start = np.empty(n_cells + 1, dtype=np.int64)  # counts first, then where each cell starts
    start[:] = 0
    for i in range(n):
        cell_of[i] = -1
        if active[i]:
            c = 0
            for a in range(axes):
                position = points[i, a] - lo[a]
                if box[a] > 0.0:
                    position = into_box(position, box[a])
                k = min(int(position / size[a]), shape[a] - 1)
                c = c * shape[a] + k
            cell_of[i] = c
            start[c + 1] += 1
    for c in range(n_cells):
        start[c + 1] += start[c]
    fill = np.empty(n_cells, dtype=np.int64)
    for c in range(n_cells):
        fill[c] = start[c]
    order = np.empty(start[n_cells], dtype=np.int64)
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
def _search(local, start, shape, box, cutoff, c_first, c_stop, found, offset, room):
    """The pairs of points within ``cutoff``, one of them in cells ``c_first:c_stop``.

    Each pair of neighbouring cells is searched once, from the first in cell
    order; the cells along the last axis are contiguous in slots, so a row of
    them is searched in one run.  The pairs of slots found go to
    ``found[:, offset:offset + room]``; returns how many there are (past
    ``room - 1``, only counted).
    """
    axes = len(box)  # a tuple: compiled for each number of axes
    rows = _forward_rows(shape)
    last = axes - 1
    width = shape[last]
    cutoff2 = cutoff * cutoff
    n_found = 0
    home = np.zeros(axes, dtype=np.int64)  # the cell's indices along the axes, counted up as c goes
    rest = c_first
    for a in range(last, -1, -1):
        home[a] = rest % shape[a]
        rest //= shape[a]
    home[last] -= 1  # the loop counts up before each cell
    runs = np.empty((2, 2), dtype=np.int64)  # up to two runs of cells along the last axis
    for c in range(c_first, c_stop):
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
                for q in range(n_runs):
                    t_first = start[base + runs[q, 0]]
                    if r == 0 and runs[q, 0] == home[last]:
                        t_first = s + 1  # in its own cell, each pair once
                    for t in range(t_first, start[base + runs[q, 1] + 1]):
                        r2 = 0.0
                        for a in range(axes):
                            delta = nearest_image(local[t, a] - local[s, a], box[a])
                            r2 += delta * delta
                        slot = offset + min(n_found, room - 1)  # written always, kept if close: no branch
                        found[0, slot] = s
                        found[1, slot] = t
                        n_found += r2 < cutoff2
    return n_found


@numba.njit(cache=True, parallel=True)
def verlet_pairs(points, active, cutoff, box, pairs, found, parts):
    """Every pair of active points within ``cutoff`` of each other: a Verlet list, each pair once.

    Fills the rows of ``pairs`` with ``(i, j)``, ``i < j``, sorted by ``i`` then
    ``j``, and returns ``(count, room)``: how many pairs there are, and the room
    ``found`` needs.  ``box`` is a tuple (one entry per axis).  The points are
    binned into cells of side ``>= cutoff`` (:func:`_cells`), cut into
    ``parts`` with about as many points each (one per thread), and the parts
    searched side by side (:func:`_search`), each into its share of ``found``
    (shape (2, room), int32).  If ``pairs`` or a share of ``found`` is too
    small, nothing is filled; the caller must grow them and call again.

    Parameters
    ----------
    points : ndarray, shape (agents, axes)
        The points, ``P*`` (m).
    active : ndarray, shape (agents,), bool
        The points that take part.
    cutoff : float
        The list's reach, ``R + R_j + skin`` (m).
    box : tuple of float
        Periodic box sides (m); 0 on an open axis.
    pairs : ndarray, shape (capacity, 2), uint32
        Filled with the pairs.
    found : ndarray, shape (2, room), int32
        Work space of the parts.
    parts : int
        Number of parts searched side by side.
    """
    n = points.shape[0]
    axes = len(box)  # a tuple: compiled for each number of axes
    cell_of, shape, start, cells_order = _cells(points, active, cutoff, np.array(box))
    m = cells_order.shape[0]
    local = np.empty((m, axes))  # the points in cell order: neighbours close in memory
    for s in numba.prange(m):
        local[s] = points[cells_order[s]]
    share = found.shape[1] // parts
    if share == 0:  # room to count in, at least
        found = np.empty((2, parts), dtype=np.int32)
        share = 1
    bounds = np.searchsorted(start, np.arange(parts + 1) * m // parts)  # first cell of each part
    bounds[parts] = start.shape[0] - 1
    counts = np.empty(parts, dtype=np.int64)
    for p in numba.prange(parts):
        counts[p] = _search(local, start, shape, box, cutoff, bounds[p], bounds[p + 1], found, p * share, share)
    n_found = counts.sum()
    room = parts * (counts.max() + 1)
    if n_found > pairs.shape[0] or room > found.shape[1]:
        return n_found, room
    # Counting sort by the first point, then each point's run by the second, by insertion.
    end = np.zeros(n + 1, dtype=np.int64)
    for p in range(parts):
        for q in range(p * share, p * share + counts[p]):
            end[min(cells_order[found[0, q]], cells_order[found[1, q]]) + 1] += 1
    for i in range(n):
        end[i + 1] += end[i]
    for p in range(parts):
        for q in range(p * share, p * share + counts[p]):
            i = cells_order[found[0, q]]
            j = cells_order[found[1, q]]
            if i > j:
                i, j = j, i
            pairs[end[i], 0] = i
            pairs[end[i], 1] = j
            end[i] += 1
    begin = 0
    for i in range(n):  # end[i] is now where i's run ends
        for e in range(begin + 1, end[i]):
            j = pairs[e, 1]
            q = e
            while q > begin and pairs[q - 1, 1] > j:
                pairs[q, 1] = pairs[q - 1, 1]
                q -= 1
            pairs[q, 1] = j
        begin = end[i]
    return n_found, room


@numba.njit(cache=True)
def is_partner(adj_ptr, adj_idx, i, j):
    """Whether agents ``i`` and ``j`` are a formation pair (rows ``adj_ptr``, ``adj_idx`` of partners).

    Parameters
    ----------
    adj_ptr, adj_idx : ndarray
        Partners of agent ``i``: ``adj_idx[adj_ptr[i]:adj_ptr[i + 1]]``.
    i, j : int
        The agents.
    """
    for e in range(adj_ptr[i], adj_ptr[i + 1]):
        if adj_idx[e] == j:
            return True
    return False


@numba.njit(cache=True)
def arrange(pairs, n_pairs, adj_ptr, adj_idx, block, block_ptr):
    """Put sorted pairs in the order the step loop takes them; returns ``(n_inside, n_kept)``.

    Formation pairs (partners in rows ``adj_ptr``, ``adj_idx``) are dropped:
    they interact through their own function.  The agents are cut into blocks
    of ``block`` consecutive indices.  Pairs within one block come first, in
    their sorted order, and ``block_ptr[b]`` is where block ``b``'s begin; the
    pairs that cross from one block to another follow, also sorted.  Blocks
    can then be summed on separate threads without two writing to the same
    agent, and the crossing pairs after them on one.

    Parameters
    ----------
    pairs : ndarray, shape (>= n_pairs, 2)
        Sorted pairs, rearranged in place.
    n_pairs : int
        Number of pairs listed.
    adj_ptr, adj_idx : ndarray
        Formation partners of each agent, as for :func:`is_partner`.
    block : int
        Agents per block.
    block_ptr : ndarray, shape (blocks + 1,)
        Filled with where each block's pairs begin.
    """
    crossing = np.empty((n_pairs, 2), dtype=pairs.dtype)
    n_inside = 0
    n_crossing = 0
    block_ptr[:] = 0
    for e in range(n_pairs):
        i = pairs[e, 0]
        j = pairs[e, 1]
        if adj_ptr[i] < adj_ptr[i + 1] and is_partner(adj_ptr, adj_idx, i, j):
            continue
        if i // block == j // block:
            pairs[n_inside, 0] = i
            pairs[n_inside, 1] = j
            n_inside += 1
            block_ptr[i // block + 1] += 1
        else:
            crossing[n_crossing, 0] = i
            crossing[n_crossing, 1] = j
            n_crossing += 1
    for b in range(block_ptr.shape[0] - 1):
        block_ptr[b + 1] += block_ptr[b]
    for e in range(n_crossing):  # element by element: a slice copy compiles Numba's shape-error messages, seconds
        pairs[n_inside + e, 0] = crossing[e, 0]
        pairs[n_inside + e, 1] = crossing[e, 1]
    return n_inside, n_inside + n_crossing


def spatial_order(points: np.ndarray, active: np.ndarray, side: float, box: np.ndarray) -> np.ndarray:
    """A numbering of the agents in which neighbours are close: active agents by cells of ``side``, then the rest.

    Parameters
    ----------
    points : ndarray, shape (agents, axes)
        The points, ``P*`` (m).
    active : ndarray, shape (agents,), bool
        The flying agents.
    side : float
        Side of the cells (m).
    box : ndarray, shape (axes,)
        Periodic box sides (m); 0 on an open axis.
    """
    cells_order = _cells(points, active, side, box)[3]
    return np.concatenate([cells_order, np.flatnonzero(~active)]).astype(np.int64)
