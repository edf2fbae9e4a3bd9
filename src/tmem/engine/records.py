"""The records the step loop works on: what a run carries from step to step.

Each record is a ``NamedTuple`` of arrays and numbers, so the compiled
stages take a handful of named records instead of dozens of arguments, and
Numba compiles them into plain loads and stores.  Arrays are changed in
place; a record itself is rebuilt only when the neighbour lists are.

Agents live in *slots*, numbered in a spatial order so that neighbours are
close in memory (:func:`tmem.world.neighbors.spatial_order`); pairs and records
name slots.  The engine translates back to the scenario's agent numbers.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Command kinds, in the order of their integer codes.
#: ``reshape`` is a mission's (:mod:`tmem.terms.navigation`): the listed pairs couple, every other lets go.
COMMANDS = ("uncouple", "couple", "remove", "add", "temperature", "reshape")
UNCOUPLE, COUPLE, REMOVE, ADD, TEMPERATURE, RESHAPE = range(6)
#: What a chunk of the loop returns: it ran to its end, or the neighbour lists must be built first.
DONE, LISTS_STALE = 0, -1


class Run(NamedTuple):
    """What stays fixed over a run.

    Attributes
    ----------
    n_steps, record_every : int
        Steps of the run; record every this many (0: record nothing).
    box : tuple of float
        Periodic box sides (0 on an open axis); its length is the number of axes,
        which the loop is compiled for.
    use_lists : bool
        Verlet lists (True) or every pair of flying agents.
    skin : float
        The lists' skin (m): they are built again once some ``P*`` has moved half of it.
    """

    n_steps: int
    record_every: int
    box: tuple
    use_lists: bool
    skin: float


class Agents(NamedTuple):
    """Every agent's state and the set-point summed for it.

    Attributes
    ----------
    state : ndarray, shape (agents, axes, n_state)
    start : ndarray, shape (agents, axes, n_state)
        Where an added agent starts.
    active : ndarray, shape (agents,), bool
        Flying; a removed agent stops where it is and no longer interacts.
    corrected : ndarray, shape (agents, axes, 2)
        ``(P*, P)`` on each axis: ``P*`` as the agent knows itself (:mod:`tmem.world.sensing`; exact
        without sensing effects), ``P`` true.
    setpoint : ndarray, shape (agents, axes)
        The sum of pushes ``U`` of this step, before saturation.
    body : ndarray, shape (agents, n_body)
        The vehicle model's body state (:attr:`tmem.vehicles.base.VehicleModel.body_names`; no
        columns for the linear model).
    body_start : ndarray, shape (agents, n_body)
        The body state an added agent starts with.
    """

    state: np.ndarray
    start: np.ndarray
    active: np.ndarray
    corrected: np.ndarray
    setpoint: np.ndarray
    body: np.ndarray
    body_start: np.ndarray

    @classmethod
    def at_start(cls, state: np.ndarray, active: np.ndarray, body: np.ndarray) -> "Agents":
        """The agents at the start of a run: these states, flying flags and body states (each also kept
        as where an added agent starts), nothing pushed yet.

        Parameters
        ----------
        state : ndarray, shape (agents, axes, n_state)
        active : ndarray, shape (agents,), bool
        body : ndarray, shape (agents, n_body)
        """
        n_agents, n_axes = state.shape[:2]
        return cls(state=state, start=state.copy(), active=active, corrected=np.empty((n_agents, n_axes, 2)),
                   setpoint=np.zeros((n_agents, n_axes)), body=body, body_start=body.copy())  # fmt: skip


class Pairs(NamedTuple):
    """The formation pairs (or every pair of a small swarm), each ``(i, j)`` with its flag.

    Attributes
    ----------
    i, j : ndarray, shape (pairs,)
        Slots of the two agents.
    d_t : ndarray, shape (pairs,)
        Set distance (m).
    direction : ndarray, shape (pairs, axes)
        Required unit direction from ``i`` to ``j``; NaN rows where none is held.
    flag : ndarray, shape (pairs,), int
        ``F_en``.
    armed : ndarray, shape (pairs,), int
        The operator's intent (:mod:`tmem.law.coupling`).
    r_before : ndarray, shape (pairs,)
        ``|d|`` one step earlier (NaN before the first step).
    min_distance : ndarray, shape (pairs,)
        Smallest ``|P_j - P_i|`` so far.
    coupled_gap, coupled_energy : ndarray, shape (pairs,)
        ``f1 - f2`` and the relative kinetic energy at the pair's last coupling
        (:mod:`tmem.law.coupling`; NaN before it).
    entry_speed2, kept_speed2 : ndarray, shape (pairs,)
        Under synchronisation (:mod:`tmem.law.synchronise`): the pair's mean square speed
        ``(|V_i|^2 + |V_j|^2) / 2`` when it last came within reach (or at the start), and ``E*``,
        the value (S2) holds from its coupling until it is out of reach again (NaN: none).
    disarmed_at : ndarray, shape (pairs,), int
        The step of the last uncouple command to the pair.
    d : ndarray, shape (axes,)
        Work space: one pair's ``d = P*_j - P*_i``.  The loop allocates nothing at each step;
        at two agents an allocation per step costs as much as the step itself.
    """

    i: np.ndarray
    j: np.ndarray
    d_t: np.ndarray
    direction: np.ndarray
    flag: np.ndarray
    armed: np.ndarray
    r_before: np.ndarray
    min_distance: np.ndarray
    coupled_gap: np.ndarray
    coupled_energy: np.ndarray
    entry_speed2: np.ndarray
    kept_speed2: np.ndarray
    disarmed_at: np.ndarray
    d: np.ndarray

    @classmethod
    def at_start(cls, i: np.ndarray, j: np.ndarray, d_t: np.ndarray, direction: np.ndarray, flag: np.ndarray) -> "Pairs":
        """The pairs at the start of a run: armed, with nothing measured or remembered yet.

        Parameters
        ----------
        i, j : ndarray, shape (pairs,), int
            Slots of the two agents.
        d_t : ndarray, shape (pairs,)
            Set distances (m).
        direction : ndarray, shape (pairs, axes)
            Directions to hold (NaN rows: none).
        flag : ndarray, shape (pairs,), int
            ``F_en`` at the start.
        """
        n = len(i)
        nothing = lambda: np.full(n, np.nan)  # noqa: E731
        return cls(i=i, j=j, d_t=d_t, direction=direction, flag=flag, armed=np.ones(n, dtype=np.int64), r_before=nothing(),
                   min_distance=np.full(n, np.inf), coupled_gap=nothing(), coupled_energy=nothing(),
                   entry_speed2=nothing(), kept_speed2=nothing(), disarmed_at=np.zeros(n, dtype=np.int64),
                   d=np.empty(direction.shape[1]))  # fmt: skip


class Neighbours(NamedTuple):
    """The other neighbouring pairs, in the loop's order (:func:`tmem.world.neighbors.arrange`).

    Attributes
    ----------
    pairs : ndarray, shape (>= n_pairs, 2), uint32
    n_inside, n_pairs : int
        Pairs ``[:n_inside]`` lie within blocks, ``[n_inside:n_pairs]`` cross between them.
    block_ptr : ndarray
        Pairs of block ``b``: ``pairs[block_ptr[b]:block_ptr[b + 1]]``.
    p_ref : ndarray, shape (agents, axes)
        ``P*`` when the lists were built.
    block_nearest2 : ndarray, shape (blocks,)
        Work space: each block's smallest squared distance this step.
    block_shift2 : ndarray, shape (blocks,)
        Work space: the largest squared shift of ``P*`` since ``p_ref`` in each block of agents this step.
    closest : ndarray, shape (1,)
        Smallest squared distance of two agents within reach so far.
    chunks : ndarray, shape (blocks + 1, 2 axes + 1, :data:`tmem.engine.pushes.CHUNK`)
        Work space: the chunk of pairs each block sums (the last row: the pairs between blocks).
    """

    pairs: np.ndarray
    n_inside: int
    n_pairs: int
    block_ptr: np.ndarray
    p_ref: np.ndarray
    block_nearest2: np.ndarray
    block_shift2: np.ndarray
    closest: np.ndarray
    chunks: np.ndarray


class Commands(NamedTuple):
    """The operator's commands, sorted by step; command ``c`` acts on ``target[ptr[c]:ptr[c + 1]]``.

    ``target`` holds pair indices for couple / uncouple (none: every pair) and reshape (the new shape's pairs),
    the agent's slot for remove / add; ``value`` the set RMS velocity of a
    temperature command (m/s; NaN for the others); ``direction`` (one row per target) the unit direction
    a reshape's pair holds from ``i`` to ``j`` (NaN rows: none, and every other command's).
    """

    step: np.ndarray
    kind: np.ndarray
    ptr: np.ndarray
    target: np.ndarray
    value: np.ndarray
    direction: np.ndarray


class Records(NamedTuple):
    """What is recorded at each recorded step, for the agents in ``slots`` and every pair; ``gas``
    the swarm's totals (:data:`tmem.engine.gas.TOTALS`, no columns when the gas is not observed);
    ``body`` the recorded agents' body states (no columns for a model without one)."""

    slots: np.ndarray
    state: np.ndarray
    control: np.ndarray
    active: np.ndarray
    flag: np.ndarray
    distance: np.ndarray
    measure: np.ndarray
    gas: np.ndarray
    body: np.ndarray


class Gas(NamedTuple):
    """The swarm as a gas (:mod:`tmem.engine.gas`): how pushes combine, the thermostat, the walls and
    obstacles, and the running totals its observables come from.

    Attributes
    ----------
    observe : bool
        Count neighbours and keep the totals: on when any option below is, or when asked.
    mean : bool
        ``interaction.combine == "mean"``: pushes divided by the pair's contacts (C1).
    rate : float
        ``1 / (2 tau)`` of the thermostat (T1) (1/s).
    target2 : ndarray, shape (1,)
        The set mean square speed (m^2/s^2); 0: the thermostat waits for a command.
    inv_g : float
        ``1 / g``: a wanted acceleration (m/s^2) as a tilt (rad).
    g_dt : float
        ``g dt``: a tilt (rad) held over a step as a change of velocity (m/s).
    dt : float
        The step (s).
    every : int
        Steps from one count to the next (``simulation.gas_period / dt``, at least 1): the pairs'
        counts and what they set are taken at the steps that are multiples of it.
    walls : ndarray, shape (axes,)
        Sides of the walled box, from 0 to ``walls[a]`` on axis ``a`` (0: no walls on that axis).
    obstacles : ndarray, shape (obstacles, axes + 1)
        Centre and radius of each circle (sphere in 3-D).
    wall_reach : float
        ``R + R_w`` (m): a wall or obstacle pushes an agent whose ``P*`` is closer to it than that.
    c_max : float
        The scenario's tilt limit (rad).
    first : ndarray, shape (1,), bool
        True until the first step's neighbours are counted: they are not encounters.
    work : ndarray, shape (agents, 5 + axes) (no rows when not observed)
        Each agent's work space of a count, in the columns :data:`tmem.engine.gas_counts.NEAR` ...
        :data:`tmem.engine.gas_counts.NEIGHBOUR_VELOCITY`: one row per agent, so that a pair's
        counts touch two rows.
    weight : ndarray, shape (agents,)
        The weight of each agent's pushes, ``1 / max(1, contacts)`` (C1), which it broadcasts at each
        count.
    near_before : ndarray, shape (agents,)
        Each agent's neighbours within reach at the count before.
    limit : ndarray, shape (agents,)
        Each agent's tilt limit this step: ``c_max``, more in a corner (W2) or with the thermostat's
        push (:mod:`tmem.engine.thermostat`).
    held : ndarray, shape (agents, 1 + axes)
        What the thermostat holds from one count to the next, in the columns of
        :mod:`tmem.engine.gas_counts` (T3).
    pushed : ndarray, shape (agents, axes)
        Work space: the pushes of the walls and obstacles this step.
    totals : ndarray, shape (agents, 6)
        Each agent's running totals, in the order of :data:`tmem.engine.gas.TOTALS`.
    """

    observe: bool
    mean: bool
    rate: float
    target2: np.ndarray
    inv_g: float
    g_dt: float
    dt: float
    every: int
    walls: np.ndarray
    obstacles: np.ndarray
    wall_reach: float
    c_max: float
    first: np.ndarray
    work: np.ndarray
    weight: np.ndarray
    near_before: np.ndarray
    limit: np.ndarray
    held: np.ndarray
    pushed: np.ndarray
    totals: np.ndarray


class Events(NamedTuple):
    """Coupling transitions and commands, as they happen: step, kind, agents (slots; -1: none), action,
    and the rule that released a pair (:data:`tmem.law.coupling.RELEASES`; -1: none)."""

    step: np.ndarray
    kind: np.ndarray
    i: np.ndarray
    j: np.ndarray
    action: np.ndarray
    rule: np.ndarray


class Counters(NamedTuple):
    """Where the loop stands, kept between chunks (each an array of one integer)."""

    step: np.ndarray
    next_command: np.ndarray
    next_record: np.ndarray
    n_events: np.ndarray

    @classmethod
    def zero(cls) -> "Counters":
        """The counters at the start of a run: every one 0."""
        return cls(*(np.zeros(1, dtype=np.int64) for _ in cls._fields))
