"""Which pairs of agents interact.

For the paper's small swarms every pair is checked at every step; the
interaction function itself returns zero beyond ``R + R_j`` (and keeps a
coupled pair's attraction at any distance, as (10) requires).
"""

from __future__ import annotations

import numpy as np


def all_pairs(n_agents: int) -> np.ndarray:
    """All pairs ``(i, j)`` with ``i < j``, shape ``(n_agents (n_agents - 1) / 2, 2)``.

    Pairs are ordered as in ``itertools.combinations(range(n_agents), 2)``.
    """
    i, j = np.triu_indices(n_agents, k=1)
    return np.stack([i, j], axis=1).astype(np.int64)
