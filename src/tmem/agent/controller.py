"""One agent's TMEM controller, as a vehicle's companion computer runs it.

An :class:`AgentController` knows its own agent's state, its formation edges,
the operator's commands to them, and the messages the other agents sent
(:class:`tmem.agent.messages.AgentMessage`); nothing else.  At each update,
every ``dt`` seconds::

    message = controller.message(own_state, t)      # broadcast this
    setpoint = controller.update(own_state, received, t)   # the tilt set-point U, |U| <= c_max

``update`` carries out the commands due, then runs the law (6)-(11) on the
messages (:mod:`tmem.agent.kernel`) and returns the tilt set-point of each
axis.  What it keeps from update to update is what the engine keeps of the
agent: each edge's flag ``F_en``, whether it is armed, its ``|d|`` one update
earlier, its values at coupling (energy rule), its synchronisation state;
each agent of a pair keeps its own copy, and, fed the same messages, both
copies step alike.  A controller is an object rather than a pair of pure
functions because that state is a handful of arrays the compiled update
changes in place, as the engine's step does, with no allocation per update;
a flight-stack node holds the object and calls it from its timer.

A controller never returns a set-point that is not finite.  A message holding a number that is
not finite, in its stamp or its vectors, is refused: it counts as not received (as a message
older than ``max_age`` does: a formation neighbour not heard from pushes nothing at that update),
the controller's :attr:`~AgentController.refused` counts it, and a :class:`MessageWarning` says so
(Python shows it once for each sender and what was wrong).  Should the law still give a
set-point that is not finite (numbers so large that their squares overflow), the controller
holds its last finite one and says so the same way.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from numbers import Real

import numpy as np

from tmem.engine.driver import read_events
from tmem.law.params import ControllerLaw
from tmem.law.record import law_record
from tmem.engine.records import COMMANDS, Events
from tmem.engine.stages import command_pair
from tmem.engine.trajectory import Event
from tmem.agent.kernel import PAIR_FLOATS, PAIR_INTS, control, events_from, message_vectors, pairs_from
from tmem.agent.messages import AgentMessage
from tmem.agent.settings import ControllerError, ControllerSettings, Edge, OperatorCommand

#: Where the number of events logged in an update is kept (:class:`tmem.engine.records.Counters`).
_N_EVENTS = 3


class MessageWarning(UserWarning):
    """A message a controller refused, or a set-point it held, and why, in one line."""


class AgentController:
    """The TMEM law of one agent: its messages in, its tilt set-point out.

    Parameters
    ----------
    agent : int
        This agent's id, as the others' messages name it.
    gains : array_like, shape (4,)
        ``K = (K_P, K_V, K_phi, K_omega)`` placing the roots (5) for the vehicle
        (:func:`tmem.law.modal.gains_for`, :func:`tmem.law.modal.modal_gains`).
    dt : float
        The update period (s): ``update`` at time ``t`` runs the tick ``round(t / dt)``; commands
        and the energy rule's fallback are counted in ticks.
    axes : int
        Horizontal axes, 1 to 3.
    law : ControllerLaw or dict
        The law's parameters (:class:`tmem.law.params.ControllerLaw`: the function, ``c_max``,
        ``d_t``, ``eps``, the coupling rules, the reach, the energy rule's fallback time and the
        synchronising gain), or a dict of them; default: the scenario's defaults.  ``d_t`` is that
        of the edges that give none, and of the attraction.
    edges : sequence of Edge
        The formation edges: neighbour, ``d_t``, the direction to hold, ``F_en`` at the start.
        Their pulls are added in this order, after the other neighbours' pushes (the engine's:
        its pairs ``(i, j)`` in order, ``i < j``).
    commands : sequence of OperatorCommand
        The operator's commands to its edges.
    order : sequence of int or None
        The ids in the order the agent adds its neighbours' pushes (8); ids not listed come after,
        by increasing id.  ``None``: by increasing id.  The engine adds them in its own
        numbering of the agents, which :func:`tmem.agent.swarm.controllers_for` passes here.
    max_age : float or None
        Messages older than this at the update (s) are treated as not received; ``None``: all used.

    Raises
    ------
    ControllerError
        One line naming the field at fault.

    Attributes
    ----------
    settings : ControllerSettings
        What it was built from, checked.
    events : list of Event
        What happened, as :class:`tmem.Event`: the commands it carried out, and its edges'
        couplings and uncouplings (agents named by id, the lower first).
    refused : int
        The messages refused since the start (or :meth:`reset`): those holding a number that is
        not finite, counted as not received (module text).
    """

    def __init__(self, agent: int, gains, *, dt: float, axes: int = 1, law: ControllerLaw | dict | None = None,
                 edges: Sequence[Edge] = (), commands: Sequence[OperatorCommand] = (), order: Sequence[int] | None = None,
                 max_age: float | None = None):  # fmt: skip
        gains = list(gains) if isinstance(gains, Iterable) else gains
        self.settings = ControllerSettings(
            agent=agent, gains=gains, dt=dt, axes=axes, law=ControllerLaw() if law is None else law, edges=list(edges),
            commands=list(commands), order=None if order is None else list(order), max_age=max_age,
        )  # fmt: skip
        self._build()
        self.reset()

    def _build(self) -> None:
        """The arrays of the law, of the agent's view of its neighbours and of its edges."""
        s = self.settings
        self._gains = np.array(s.gains, dtype=float)[np.newaxis, :]
        fallback = 0 if s.law.fallback_time is None else int(round(s.law.fallback_time / s.dt))
        self._law = law_record(s.law, self._gains[0], fallback, s.law.sync_gain)
        self._ids = np.array([s.agent] + [edge.neighbour for edge in s.edges], dtype=np.int64)
        self._row = {int(n): row for row, n in enumerate(self._ids) if row > 0}
        n_edges, axes = len(self._ids) - 1, s.axes
        self._rank = {} if s.order is None else {int(n): r for r, n in enumerate(s.order)}
        self._known = np.full((n_edges + 1, axes, 4), np.nan)
        self._active = np.ones(n_edges + 1, dtype=np.bool_)
        self._corrected = np.zeros((n_edges + 1, axes, 2))
        self._setpoint = np.zeros((n_edges + 1, axes))
        self._heard = np.zeros(n_edges, dtype=np.bool_)
        self._stamps = np.zeros(n_edges + 1)
        self._inbox = np.zeros((n_edges + 1, 3, axes))  # P*, P, V of each neighbour's last message
        self._pair_ints = np.zeros((len(PAIR_INTS), n_edges), dtype=np.int64)
        self._pair_floats = np.zeros((len(PAIR_FLOATS), n_edges))
        self._direction = np.full((n_edges, axes), np.nan)
        self._pairs = pairs_from.py_func(self._pair_ints, self._pair_floats, self._direction, np.zeros(axes))
        self._event_table = np.zeros((len(Events._fields), max(n_edges, 1)), dtype=np.int64)
        self._counts = np.zeros(4, dtype=np.int64)
        self._events = events_from.py_func(self._event_table, self._counts)[0]
        self._box = (0.0,) * axes
        self._out = np.zeros(axes)
        self._commands = [self._command(c) for c in sorted(s.commands, key=lambda c: c.time)]

    def _command(self, command: OperatorCommand) -> tuple[int, int, tuple[int, ...], tuple[int, ...]]:
        """``(tick, kind, edges acted on, agents its event names)`` of an operator's command."""
        s = self.settings
        if command.pairs is None:
            edges = tuple(range(len(self._ids) - 1))
        else:
            edges = tuple(sorted({self._row[n] - 1 for pair in command.pairs if (n := s.partner_in(pair)) is not None}))
        named = tuple(sorted(command.pairs[0])) if command.pairs is not None and len(command.pairs) == 1 else ()
        return int(round(command.time / s.dt)), COMMANDS.index(command.action), edges, named

    def reset(self) -> None:
        """Back to the start: each edge's flag as given, armed, with nothing remembered; no command
        carried out yet; no events."""
        s = self.settings
        lower = [s.agent < edge.neighbour for edge in s.edges]  # the pair's i is the lower id: row 0 or the edge's
        rows = [(0, e + 1) if low else (e + 1, 0) for e, low in enumerate(lower)]
        start = {"i": [i for i, _ in rows], "j": [j for _, j in rows], "flag": [int(edge.coupled) for edge in s.edges],
                 "armed": 1, "disarmed_at": 0}  # fmt: skip
        for row, name in enumerate(PAIR_INTS):
            self._pair_ints[row] = start[name]
        self._pair_floats[:] = np.nan
        self._pair_floats[PAIR_FLOATS.index("d_t")] = [s.law.d_t if edge.d_t is None else edge.d_t for edge in s.edges]
        self._pair_floats[PAIR_FLOATS.index("min_distance")] = np.inf
        for e, (edge, low) in enumerate(zip(s.edges, lower)):  # held from i to j; the edge gives it from this agent
            if edge.direction is not None:
                self._direction[e] = [b if low else -b for b in edge.direction]
        self._next_command = 0
        self.events: list[Event] = []
        self.refused = 0
        self._held = np.zeros(s.axes)  # the last finite set-point, held should the law give none

    @property
    def agent(self) -> int:
        """This agent's id."""
        return self.settings.agent

    @property
    def neighbours(self) -> tuple[int, ...]:
        """The ids of its formation neighbours, in the order its edges were given (and are taken in)."""
        return tuple(int(n) for n in self._ids[1:])

    def flag(self, neighbour: int) -> int:
        """``F_en`` of the edge to ``neighbour``, as this agent holds it.

        Parameters
        ----------
        neighbour : int
            A formation neighbour's id.
        """
        if neighbour not in self._row:
            raise ControllerError(f"neighbour: agent {neighbour} is not a formation neighbour of agent {self.agent}")
        return int(self._pairs.flag[self._row[neighbour] - 1])

    def message(self, own_state, t: float) -> AgentMessage:
        """What this agent broadcasts at time ``t``: its ``P*`` (6), position and velocity.

        Parameters
        ----------
        own_state : array_like, shape (axes, 4)
            The agent's ``(P, V, phi, omega)`` on each axis.
        t : float
            The time (s).
        """
        vectors = np.empty((3, self.settings.axes))
        message_vectors(self._own(own_state)[np.newaxis], self._gains, vectors)
        return AgentMessage(self.agent, float(t), True, vectors)

    def update(self, own_state, messages: Iterable[AgentMessage], t: float) -> np.ndarray:
        """Run the law at time ``t``: the tilt set-point ``U`` of each axis (rad), ``|U| <= c_max``.

        Parameters
        ----------
        own_state : array_like, shape (axes, 4)
            The agent's ``(P, V, phi, omega)`` on each axis.
        messages : iterable of AgentMessage
            What the agent received; its own, if there, is skipped, and of several from one sender
            the newest is used.
        t : float
            The time (s), on the clock of the messages' stamps.
        """
        own = self._own(own_state)
        if not (isinstance(t, Real) and math.isfinite(t) and t >= 0.0):
            raise ControllerError(f"t: must be a finite time >= 0, got {t!r}")
        k = int(round(t / self.settings.dt))
        self._carry_out_commands(k)
        others = self._read(messages, t)
        self._counts[_N_EVENTS] = 0
        control(k, own, *self._law, self._inbox, self._known, self._active, self._corrected, self._setpoint,
                self._pair_ints, self._pair_floats, self._direction, self._pairs.d, self._heard, others, self._event_table,
                self._counts, self._box, self._out)  # fmt: skip
        if self._counts[_N_EVENTS]:
            self.events += read_events(self._events, int(self._counts[_N_EVENTS]), self._ids, self.settings.dt)
        if not np.isfinite(self._out).all():
            warnings.warn(f"update: the law gave the set-point {self._out.tolist()} at t = {t:g} s; the last finite "
                          f"one, {self._held.tolist()}, is held", MessageWarning, stacklevel=2)  # fmt: skip
            return self._held.copy()
        self._held[:] = self._out
        return self._out.copy()

    def _own(self, own_state) -> np.ndarray:
        own = np.ascontiguousarray(own_state, dtype=float)
        if own.shape[0] != self.settings.axes or own.ndim != 2 or own.shape[1] < 4:
            axes = self.settings.axes
            raise ControllerError(f"own_state: needs shape ({axes}, 4), (P, V, phi, omega) per axis, got {own.shape}")
        if not np.isfinite(own).all():
            raise ControllerError("own_state: every number must be finite")
        return own

    def _carry_out_commands(self, k: int) -> None:
        """The commands due at tick ``k``, as the engine carries them out (:func:`tmem.engine.stages.command_pair`)."""
        while self._next_command < len(self._commands) and self._commands[self._next_command][0] <= k:
            _, kind, edges, named = self._commands[self._next_command]
            for e in edges:
                command_pair(k, e, kind, self._pairs)
            self.events.append(Event(time=round(k * self.settings.dt, 12), kind="command", agents=named, action=COMMANDS[kind]))
            self._next_command += 1

    def _usable(self, message: AgentMessage) -> bool:
        """Whether every number of ``message`` is finite; if not, it is refused: counted and warned of."""
        stamp = message.stamp
        if not (isinstance(stamp, Real) and not isinstance(stamp, bool)):
            raise ControllerError(f"messages: the stamp of agent {message.sender}'s message must be a number (s), got {stamp!r}")
        vectors = np.asarray(message.vectors, dtype=float)
        finite = np.isfinite(vectors)
        if math.isfinite(stamp) and finite.all():
            return True
        what = f"the stamp {stamp!r}" if not math.isfinite(stamp) else f"{vectors[~finite][0]!r} in its vectors"
        self.refused += 1
        warnings.warn(f"messages: agent {message.sender}'s message holds {what}; refused, as not received",
                      MessageWarning, stacklevel=4)  # fmt: skip
        return False

    def _read(self, messages: Iterable[AgentMessage], t: float) -> np.ndarray:
        """The formation neighbours' messages into the inbox (``_heard``: which came); ``P*`` of the
        other flying senders, in the order their pushes are added.  Of several messages from one
        sender, the newest."""
        me, rows, max_age = self.settings.agent, self._row, self.settings.max_age
        heard, stamps, inbox, flying = self._heard, self._stamps, self._inbox, self._active
        heard[:] = False
        others: dict[int, AgentMessage] = {}
        try:
            for m in messages:
                sender = m.sender
                if sender == me or not self._usable(m) or (max_age is not None and t - m.stamp > max_age):
                    continue
                row = rows.get(sender)
                if row is None:
                    if sender not in others or m.stamp >= others[sender].stamp:
                        others[sender] = m
                elif not heard[row - 1] or m.stamp >= stamps[row]:
                    heard[row - 1], stamps[row], flying[row] = True, m.stamp, m.flying
                    inbox[row] = m.vectors
            ranked = sorted((self._rank.get(n, len(self._rank)), n) for n, m in others.items() if m.flying)
            table = np.empty((len(ranked), self.settings.axes))
            for q, (_, sender) in enumerate(ranked):
                table[q] = others[sender].vectors[0]
        except ControllerError:
            raise
        except ValueError:
            raise ControllerError(f"messages: the message of agent {sender} is not of {self.settings.axes} axes") from None
        return table
