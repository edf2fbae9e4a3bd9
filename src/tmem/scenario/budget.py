"""What a run may take of the machine: the memory it needs and the size of its records, checked
before anything is generated.

The estimates are upper bounds in bytes: the records (five numbers per agent and axis and a flag per
agent, 32 bytes per tracked pair, at every record) plus the working memory per agent, per agent and
axis and per tracked pair.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from tmem.scenario.tables import FieldError, SimulationParams

if TYPE_CHECKING:
    from tmem.scenario.schema import Scenario

#: Most bytes a run may set aside for its records.
MAX_RECORD_BYTES = 8 * 2**30
#: Bytes of working memory a run needs per agent and axis (state, its copy, the control, the
#: neighbour search's cells) and per agent (Verlet pairs, found lists, sort order), rounded up.
WORK_BYTES_PER_AGENT_AXIS = 128
WORK_BYTES_PER_AGENT = 256
#: Bytes of the gas's work space per agent and per agent and axis, when it is observed
#: (:class:`tmem.engine.records.Gas`: 15 numbers, and on each axis its neighbours' velocity, the
#: thermostat's held push and the walls' push).
GAS_BYTES_PER_AGENT = 120
GAS_BYTES_PER_AGENT_AXIS = 24
#: Bytes per tracked pair while running (flag, distances, both directions of the edge), rounded up.
WORK_BYTES_PER_PAIR = 96


def memory_limit() -> int:
    """Most bytes a run may need: 16 GiB, or half this machine's memory if that is less."""
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        physical = 0
    return min(16 * 2**30, physical // 2) if physical > 0 else 16 * 2**30


def record_bytes(simulation: SimulationParams, axes: int, n: int, pairs: int) -> int:
    """Bytes of a run's records: per record, five numbers per recorded agent and axis, a flag per
    recorded agent, and 32 bytes per tracked pair.

    Parameters
    ----------
    simulation : SimulationParams
        The ``[simulation]`` table (how often, and which agents, are recorded).
    axes : int
        ``space.axes``.
    n : int
        The number of agents.
    pairs : int
        The number of tracked pairs.
    """
    records = simulation.n_steps // simulation.record_every + 2
    recorded = n if simulation.record_agents is None else len(simulation.record_agents)
    return records * (recorded * (5 * axes * 8 + 1) + pairs * 32)


def check_memory(scenario: Scenario, n: int, pairs: int) -> None:
    """The records and working memory of a run against :func:`memory_limit`; raise :class:`FieldError`
    naming what to shrink: the agents, or, where they fit, how often they are recorded.

    Parameters
    ----------
    scenario, n
        The scenario, its tables valid on their own, and its number of agents.
    pairs : int
        How many pairs it tracks, at most.
    """
    axes = scenario.space.axes
    kept = record_bytes(scenario.simulation, axes, n, pairs)
    per_agent = WORK_BYTES_PER_AGENT + axes * WORK_BYTES_PER_AGENT_AXIS
    if scenario.gas_observed:
        per_agent += GAS_BYTES_PER_AGENT + axes * GAS_BYTES_PER_AGENT_AXIS
    work = n * per_agent + pairs * WORK_BYTES_PER_PAIR
    need, limit = kept + work, memory_limit()
    if need > limit:
        field = "swarm.n" if scenario.swarm is not None else ("formation.n" if scenario.formation and scenario.formation.n else "agents")
        if work <= limit:  # the agents fit: their records are what does not
            field = "simulation.record_every"
        raise FieldError(
            field,
            f"{n} agents would need about {need / 2**30:.3g} GiB to run (at most {limit / 2**30:.3g} GiB); "
            "fewer agents, or record less (record_every, record_agents)",
        )


def check_record_size(scenario: Scenario, n: int, pairs: int) -> None:
    """The records of a run against :data:`MAX_RECORD_BYTES`; raise :class:`FieldError` if they exceed it.

    Parameters
    ----------
    scenario, n, pairs
        As :func:`check_memory` takes them, ``pairs`` now the number of pairs the run tracks.
    """
    size = record_bytes(scenario.simulation, scenario.space.axes, n, pairs)
    if size > MAX_RECORD_BYTES:
        raise FieldError(
            "simulation.record_every",
            f"the records would take {size / 2**30:.1f} GiB (at most {MAX_RECORD_BYTES / 2**30:g}); "
            "record less often or fewer agents (record_agents)",
        )
