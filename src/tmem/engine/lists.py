"""A run's neighbour lists: the pairs of flying agents in the loop's order, listed again when they go stale.

The exact knowledge lists the pairs whose ``P*`` (6) lie within ``R + R_j`` and the skin of each
other; the sensed knowledge lists those whose positions lie within the sensing range and the skin
(:mod:`tmem.world.neighbors` builds them from cells, or takes every pair of a small swarm).  The
pairs are arranged in blocks of agents (:func:`tmem.world.neighbors.arrange`), so that each
agent adds its pushes in one order whatever the number of threads.
"""

from __future__ import annotations

import numba
import numpy as np

from tmem.engine.pushes import CHUNK
from tmem.engine.records import Neighbours
from tmem.scenario import Scenario
from tmem.world.neighbors import all_pairs, arrange, verlet_pairs

#: Agents per block of the neighbour sums (:func:`tmem.world.neighbors.arrange`); it fixes the order of
#: each agent's sum, so results do not depend on the number of threads.
BLOCK = 4096


def _partners(n_agents: int, edges: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each agent's formation partners, in rows ``(ptr, idx)``."""
    both = np.concatenate([edges, edges[:, ::-1]]) if len(edges) else np.empty((0, 2), dtype=np.int64)
    order = np.lexsort((both[:, 1], both[:, 0]))
    both = both[order]
    ptr = np.searchsorted(both[:, 0], np.arange(n_agents + 1)).astype(np.int64)
    return ptr, both[:, 1].astype(np.int64).copy()


class NeighbourLister:
    """Lists the pairs of flying agents in the loop's order, with Verlet lists or every pair.

    The lists hold the pairs within ``reach`` and the skin of each other in ``p_ref``: ``P*`` (6) and
    ``R + R_j`` on the exact path, the positions and the sensing range on the sensed one.

    Parameters
    ----------
    scenario : Scenario
        Its neighbour lists' skin.
    n_agents, n_axes : int
        The run's agents and axes.
    edges_in_slots : ndarray, shape (pairs, 2)
        The formation pairs, in slots: they are not listed (their own stage pushes them).
    use_lists : bool
        Verlet lists (True), or every pair of flying agents.
    reach : float
        The distance within which a pair is listed, before the skin (m).
    """

    def __init__(self, scenario: Scenario, n_agents: int, n_axes: int, edges_in_slots: np.ndarray, use_lists: bool,
                 reach: float):  # fmt: skip
        self.cutoff = reach + scenario.neighbors.skin
        self.use_lists = use_lists
        self.adj_ptr, self.adj_idx = _partners(n_agents, edges_in_slots)
        self.block_ptr = np.empty(n_agents // BLOCK + 2, dtype=np.int64)
        self.block_nearest2 = np.empty(len(self.block_ptr) - 1)
        self.block_shift2 = np.empty(len(self.block_ptr) - 1)
        self.chunks = np.empty((len(self.block_ptr), 2 * n_axes + 1, CHUNK))
        self.closest = np.full(1, np.inf)  # the smallest squared distance between neighbours so far
        self.p_ref = np.zeros((n_agents, n_axes))
        if use_lists:  # pairs are unsigned, as all_pairs gives them: no negative-index check in the loop
            self.pairs = np.empty((8 * n_agents, 2), dtype=np.uint32)
            self.found = np.empty((2, len(self.pairs) + 64), dtype=np.int32)
        self.builds = 0

    def list(self, active: np.ndarray, box: tuple) -> Neighbours:
        """The pairs within reach and skin of each other in ``p_ref``, each once; grow the arrays if needed.

        Parameters
        ----------
        active : ndarray, shape (agents,), bool
            The flying agents.
        box : tuple of float
            The periodic box's sides (0: open axis).
        """
        if self.use_lists:
            parts = numba.get_num_threads()
            listed, room = verlet_pairs(self.p_ref, active, self.cutoff, box, self.pairs, self.found, parts)
            if listed > len(self.pairs) or room > self.found.shape[1]:
                self.pairs = np.empty((int(1.5 * max(listed, len(self.pairs))) + 16, 2), dtype=np.uint32)
                self.found = np.empty((2, int(1.5 * max(room, self.found.shape[1])) + 16), dtype=np.int32)
                verlet_pairs(self.p_ref, active, self.cutoff, box, self.pairs, self.found, parts)
            self.builds += 1
        else:
            self.pairs = all_pairs(active)
            listed = len(self.pairs)
        n_inside, n_pairs = arrange(self.pairs, listed, self.adj_ptr, self.adj_idx, BLOCK, self.block_ptr)
        return Neighbours(self.pairs, n_inside, n_pairs, self.block_ptr, self.p_ref, self.block_nearest2,
                          self.block_shift2, self.closest, self.chunks)  # fmt: skip
