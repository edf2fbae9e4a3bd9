"""What one agent broadcasts to the others: the message the TMEM law needs of it.

At every update each agent sends one :class:`AgentMessage`, made by its own
controller (:meth:`tmem.agent.controller.AgentController.message`) from its own
state, and each controller reads the messages of the others.  The law needs of
a neighbour:

* its corrected position ``P* = x . K / K_P`` (6), per axis: the pair measure
  ``d = P*_j - P*_i`` of the pushes (8), (10), (11) and of the flag ``F_en`` (9).
  The sender computes it with its own gains, as the engine does;
* its position ``P`` and velocity ``V``, per axis: the pair's distance, its
  relative kinetic energy (the energy rule of :mod:`tmem.law.coupling`) and the
  speed synchronisation (S2) (:mod:`tmem.law.synchronise`);
* whether it flies: a pair whose agent no longer flies uncouples (the event
  names the rule ``"lost"``), and a grounded agent pushes nobody.

The three vectors travel as the rows of :attr:`AgentMessage.vectors`.  On a
link the message is ``3 + 3 axes`` numbers (:meth:`AgentMessage.to_floats`):
``[sender, stamp, flying, P*..., P..., V...]``: in 64-bit floats, 24 bytes and 24
more per axis, e.g. a ``std_msgs/Float64MultiArray`` on a ROS 2 topic.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from tmem.agent.settings import ControllerError

#: The numbers before the per-axis vectors on the wire: sender, stamp, flying.
HEADER = 3


class AgentMessage(NamedTuple):
    """One agent's broadcast at one update.

    Attributes
    ----------
    sender : int
        The agent's id.
    stamp : float
        When the message was made (s), on the sender's clock.
    flying : bool
        Whether the agent flies (and interacts).
    vectors : ndarray, shape (3, axes)
        Its rows: ``P*`` (6) on each axis (m), from the sender's own gains; the position ``P`` (m);
        the velocity ``V`` (m/s).  Also read as :attr:`corrected`, :attr:`position`, :attr:`velocity`.
    """

    sender: int
    stamp: float
    flying: bool
    vectors: np.ndarray

    @property
    def corrected(self) -> np.ndarray:
        """``P*`` (6) on each axis (m)."""
        return self.vectors[0]

    @property
    def position(self) -> np.ndarray:
        """``P`` on each axis (m)."""
        return self.vectors[1]

    @property
    def velocity(self) -> np.ndarray:
        """``V`` on each axis (m/s)."""
        return self.vectors[2]

    def to_floats(self) -> np.ndarray:
        """The message as ``3 + 3 axes`` floats: ``[sender, stamp, flying, P*..., P..., V...]``."""
        return np.concatenate(([self.sender, self.stamp, 1.0 if self.flying else 0.0], np.ravel(self.vectors)))

    @classmethod
    def from_floats(cls, values) -> "AgentMessage":
        """The message that :meth:`to_floats` wrote; a malformed one raises :class:`ControllerError`.

        Parameters
        ----------
        values : array_like of float
            ``[sender, stamp, flying, P*..., P..., V...]``, 6, 9 or 12 numbers (1 to 3 axes).
        """
        values = np.asarray(values, dtype=float)
        axes, rest = divmod(values.size - HEADER, 3)
        if values.ndim != 1 or rest or not 1 <= axes <= 3:
            raise ControllerError(f"message: needs 3 + 3 axes numbers (6, 9 or 12), got {values.size}")
        if not np.isfinite(values).all():
            raise ControllerError("message: every number must be finite")
        sender, stamp, flying = values[:HEADER]
        if sender != int(sender) or sender < 0 or flying not in (0.0, 1.0):
            raise ControllerError(f"message: the sender must be an id >= 0 and flying 0 or 1, got {sender:g} and {flying:g}")
        return cls(int(sender), float(stamp), flying == 1.0, values[HEADER:].reshape(3, axes).copy())
