"""What each agent knows of itself and its neighbours: the measurement stage.

The controller of an agent reads only what the agent measures.  Without a
``[sensing]`` table every agent knows every state exactly, and the step loop
hands the true states on (:func:`exact`).  With one, the loop takes its
sensed path (:mod:`tmem.engine.sensed`), where each receiver works from its
own measurement; the model, in ``docs/sensing.md``:

* **Broadcast.**  Every ``period`` (by default at every step) every agent
  sends its state ``(P, V, phi, omega)``, a *message*; :func:`measure` keeps
  the states of the last ``depth`` steps, a ring buffer
  (:attr:`Sensing.history`).  Between messages a receiver holds the last.
* **Delay.**  Message ``s`` from ``j`` reaches ``i`` ``tau`` later: from the
  first step at which it is ``tau`` old, step ``s + lag(tau)`` with
  ``lag(tau) = ceil(tau / dt)`` (:func:`tmem.scenario.sensing_table.lag`).
  A fixed ``tau`` not a multiple of ``dt`` is honoured so: the data used at
  ``t`` is the latest broadcast at or before ``t - tau``.  A random ``tau`` is
  drawn for each message, uniform on ``[min, max]``; messages may then arrive
  out of order, and a receiver uses the newest that has arrived.
* **Loss.**  Each message to each receiver is lost with probability
  ``loss``.  A receiver uses the newest message it got (:func:`latest_message`),
  which it holds, with its age, until a newer one arrives or it is ``hold``
  older than the largest delay; then the neighbour is no longer measured.
* **Noise.**  A received message's position and velocity carry Gaussian
  noise, drawn once per message and receiver (a held message keeps its
  noise): :func:`known_state`.  An agent's own state carries noise of
  its own, drawn once a period and held over it (:func:`measure`).
* **Range.**  A neighbour farther than ``range`` (true distance now) is not
  measured at all.
* **Start.**  Until a neighbour's first message is due, a receiver knows the
  neighbour's start, as if sent at ``t = 0``.

Every draw is a hash of ``(seed, receiver, sender, step, draw)``
(:mod:`tmem.world.streams`), so what ``i`` knows of ``j`` does not depend on
threads, on the kind of neighbour list, or on the order of pairs.

A new effect is a parameter in :class:`Sensing` (with a value that turns it
off) and a line in :func:`known_state`, or in :func:`measure` for an agent's
own state (``docs/architecture.md`` walks through one).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.scenario.sensing_table import LAG_TOLERANCE, SensingParams, lag
from tmem.world.streams import message_key, normal_pair, uniform

#: The uniform draws of a message: whether it is lost, and its delay.
LOSS, DELAY = 0, 1
#: The first pair of normal draws of the noise (it takes the uniform draws 2 and 3): on axis ``a``
#: the pair ``NOISE + a`` gives the position's noise and the velocity's.
NOISE = 1


class Sensing(NamedTuple):
    """The measurement stage's settings and work space (module text for the model).

    Attributes
    ----------
    seed : int
        Seed of the random streams (:mod:`tmem.world.streams`).
    agent : ndarray, shape (agents,), int
        The scenario's number of the agent in each slot: the streams are the agents', not the slots'.
    position_noise, velocity_noise : float
        Standard deviation of the noise on a neighbour's position (m) and velocity (m/s), per axis.
    own_position_noise, own_velocity_noise : float
        The same on an agent's own state.
    every : int
        Steps between two messages of an agent, and between two measurements of its own state.
    lag_min, lag_max : int
        ``lag`` of the smallest and largest delay (steps); equal for a fixed delay.
    delay_min, delay_max : float
        The smallest and largest delay (s).
    dt : float
        The step (s).
    loss : float
        Probability that a message is lost.
    range2 : float
        The square of the sensing range (m^2; ``inf``: unlimited).
    history : ndarray, shape (depth, agents, axes, n_state)
        The messages of the last ``depth`` steps, step ``s`` in row ``s % depth`` (no rows when
        nothing is delayed or lost: the states of the step are read instead).
    own : ndarray, shape (agents, axes, n_state)
        Work space: each agent's own state as it measures it this step.
    pair_states : ndarray, shape (2, axes, n_state)
        Work space: a formation pair's two states as one of its agents knows them.
    seen : ndarray, shape (blocks + 1, axes, n_state)
        Work space: the state of a sender as its receiver knows it, in each block of the neighbour sums.
    pushes : ndarray, shape (2, axes)
        Work space: a pair's synchronising pushes as one of its agents computes them.
    work : ndarray, shape (blocks + 1, axes)
        Work space: the ``d`` of a receiver in each block of the neighbour sums.
    """

    seed: int
    agent: np.ndarray
    position_noise: float
    velocity_noise: float
    own_position_noise: float
    own_velocity_noise: float
    every: int
    lag_min: int
    lag_max: int
    delay_min: float
    delay_max: float
    dt: float
    loss: float
    range2: float
    history: np.ndarray
    own: np.ndarray
    pair_states: np.ndarray
    seen: np.ndarray
    pushes: np.ndarray
    work: np.ndarray


def sensing_of(settings: SensingParams, order: np.ndarray, shape: tuple, dt: float, n_blocks: int) -> Sensing:
    """The measurement stage of a run: the ``[sensing]`` table's effects and their work space.

    Parameters
    ----------
    settings : SensingParams
        The scenario's ``[sensing]`` table.
    order : ndarray, shape (agents,), int
        ``order[s]``: the scenario's number of the agent in slot ``s``.
    shape : tuple
        ``(agents, axes, n_state)`` of the run's states.
    dt : float
        The step (s).
    n_blocks : int
        Blocks of the neighbour sums (:func:`tmem.world.neighbors.arrange`).
    """
    delay_min, delay_max = settings.delays
    return Sensing(
        seed=settings.seed,
        agent=np.asarray(order, dtype=np.int64),
        position_noise=settings.position_noise,
        velocity_noise=settings.velocity_noise,
        own_position_noise=settings.own_position_noise,
        own_velocity_noise=settings.own_velocity_noise,
        every=settings.every(dt),
        lag_min=lag(delay_min, dt),
        lag_max=lag(delay_max, dt),
        delay_min=delay_min,
        delay_max=delay_max,
        dt=dt,
        loss=settings.loss,
        range2=np.inf if settings.range is None else settings.range**2,
        history=np.zeros((settings.depth(dt),) + tuple(shape)),
        own=np.empty(shape),
        pair_states=np.empty((2,) + tuple(shape[1:])),
        seen=np.empty((n_blocks + 1,) + tuple(shape[1:])),
        pushes=np.empty((2, shape[1])),
        work=np.empty((n_blocks + 1, shape[1])),
    )


def exact(state: np.ndarray) -> Sensing:
    """Every agent knows every state exactly: the record the loop's exact path carries, unused.

    Parameters
    ----------
    state : ndarray, shape (agents, axes, n_state)
        The states of the run (only their shape is used).
    """
    return sensing_of(SensingParams(), np.arange(state.shape[0]), (0,) + state.shape[1:], 1.0, 0)


@numba.njit(cache=True, inline="always")
def message_of(sensing, i, j, s):
    """The stream key of message ``s`` from slot ``j`` to slot ``i`` (:func:`tmem.world.streams.message_key`).

    Parameters
    ----------
    sensing : Sensing
        The measurement stage.
    i, j : int
        Slots of the receiver and the sender (the same for an agent's measure of itself).
    s : int
        The step the message was sent.
    """
    return message_key(sensing.seed, sensing.agent[i], sensing.agent[j], s)


@numba.njit(cache=True, inline="always")
def _arrived(k, s, key, sensing):
    """Whether message ``s`` (stream key ``key``) has reached its receiver by step ``k``."""
    if sensing.lag_min == sensing.lag_max:
        return k - s >= sensing.lag_min
    tau = sensing.delay_min + (sensing.delay_max - sensing.delay_min) * uniform(key, DELAY)
    return k - s >= max(0, int(np.ceil(tau / sensing.dt - LAG_TOLERANCE)))  # tmem.scenario.sensing_table.lag


@numba.njit(cache=True, inline="always")
def latest_message(k, i, j, sensing):
    """The step at which ``j`` sent the newest message ``i`` holds at step ``k``; -1 when it holds none.

    Messages, sent at the multiples of ``every``, are searched from the newest that can have arrived
    back to the oldest kept, ``depth - 1`` steps old; the first that has arrived and was not lost is
    the one held.  Before the first message is due, a receiver knows its neighbour's start (step 0).

    Parameters
    ----------
    k : int
        The step.
    i, j : int
        Slots of the receiver and the sender.
    sensing : Sensing
        The measurement stage.
    """
    depth = sensing.history.shape[0]
    if depth == 0:
        return k
    s = k - sensing.lag_min
    s -= s % sensing.every  # Python's %: a step before the start stays before it
    while s > k - depth:
        if s <= 0:
            return 0
        key = message_of(sensing, i, j, s)
        if _arrived(k, s, key, sensing) and not (sensing.loss > 0.0 and uniform(key, LOSS) < sensing.loss):
            return s
        s -= sensing.every
    return -1


@numba.njit(cache=True, error_model="numpy", inline="always")
def known_state(state, sensing, key, j, s, out, row):
    """The state of ``j`` as its receiver knows it from ``j``'s message ``s``, into ``out[row]``: every
    component as sent, and the noise on position and velocity, per axis.

    Parameters
    ----------
    state : ndarray, shape (agents, axes, n_state)
        The true states of this step (read when nothing is delayed, held or lost).
    sensing : Sensing
        The measurement stage.
    key : uint64
        The message's stream key (:func:`message_of`).
    j : int
        Slot of the sender.
    s : int
        The message (the step it was sent; :func:`latest_message`).
    out : ndarray, shape (rows, axes, n_state)
        Work space; row ``row`` is written.
    row : int
    """
    depth = sensing.history.shape[0]
    noisy = sensing.position_noise > 0.0 or sensing.velocity_noise > 0.0
    for a in range(state.shape[1]):
        for m in range(state.shape[2]):
            out[row, a, m] = state[j, a, m] if depth == 0 else sensing.history[s % depth, j, a, m]
        if noisy:
            noise_p, noise_v = normal_pair(key, NOISE + a)
            out[row, a, 0] += sensing.position_noise * noise_p
            out[row, a, 1] += sensing.velocity_noise * noise_v


@numba.njit(cache=True, error_model="numpy", inline="always")
def measure(k, state, sensing):
    """Broadcast step ``k``'s states (into the history) and return each agent's own state as it measures it.

    Parameters
    ----------
    k : int
        The step.
    state : ndarray, shape (agents, axes, n_state)
        The true states.
    sensing : Sensing
        The measurement stage; its ``history`` and ``own`` change in place.
    """
    history, own = sensing.history, sensing.own  # parallel loops take arrays
    sigma_p, sigma_v = sensing.own_position_noise, sensing.own_velocity_noise
    depth = history.shape[0]
    sample = k - k % sensing.every  # the own noise is drawn once a period
    for i in numba.prange(state.shape[0]):
        for a in range(state.shape[1]):
            for m in range(state.shape[2]):
                own[i, a, m] = state[i, a, m]
                if depth > 0:
                    history[k % depth, i, a, m] = state[i, a, m]
        if sigma_p > 0.0 or sigma_v > 0.0:
            key = message_of(sensing, i, i, sample)
            for a in range(state.shape[1]):
                noise_p, noise_v = normal_pair(key, NOISE + a)
                own[i, a, 0] += sigma_p * noise_p
                own[i, a, 1] += sigma_v * noise_v
    return own
