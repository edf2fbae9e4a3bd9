"""The contract every vehicle model fulfils.

The engine steps a swarm of one vehicle model.  Agent ``i``'s state is kept
per horizontal axis ``a`` as ``state[i, a, :]``; a model names the components
and their units.  The TMEM law reads the first four, in the order of the
paper's model (2): position ``P`` (m), velocity ``V`` (m/s), tilt ``phi``
(rad) and tilt rate ``omega`` (rad/s); a model may keep more components
after them (a motor's state, say).  What belongs to the whole vehicle rather
than to one axis (a quadrotor's height, attitude, body rates and rotor
speeds) is its *body state* ``body[i, :]``, named by :attr:`VehicleModel.body_names`:
the engine carries it beside the per-axis state, restores it with the state
when an agent is added back, and records it.  The linear model has none.

A model provides

* its state names, units and long names (:attr:`VehicleModel.state_names` ...);
* its linearisation ``(A, B)`` about hover, per axis, on ``(P, V, phi, omega)``
  with the tilt set-point as input: the modal gains (4) are designed on it
  (:func:`tmem.law.modal.gains_for`);
* its body state at the start, from the per-axis one (:meth:`VehicleModel.initial_body`);
* its compiled step: :meth:`VehicleModel.step_params` gives the record of
  numbers the step needs for a time step ``dt``, and :attr:`VehicleModel.step`
  is a Numba kernel ``step(x, body, u, i, scale, params, n_axes)`` that advances
  agent ``i`` (its ``x[i]`` and ``body[i]``) over ``dt`` in place with the
  set-point ``u[i, :] * scale`` held.
  A linear model can step exactly (zero-order hold); a nonlinear one takes
  sub-steps of its own within ``dt``.

The step loop is compiled once for each model (:func:`tmem.engine.loop.advance_for`),
with the model's kernel inlined, so a model costs nothing at run time.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar, NamedTuple

import numpy as np


class VehicleModel(ABC):
    """A vehicle model: state names, linearisation for the gains, compiled step.

    Parameters
    ----------
    params
        The scenario's ``[model]`` table (its validated record).
    """

    #: The scenario's ``[model] kind`` for this model.
    kind: ClassVar[str]
    #: Names of the per-axis state components, the first four ``(P, V, phi, omega)``.
    state_names: ClassVar[tuple[str, ...]]
    #: Units of each component, as UDUNITS writes them (NetCDF files carry them).
    state_units: ClassVar[tuple[str, ...]]
    #: A longer name of each component, for files and figures.
    long_names: ClassVar[tuple[str, ...]]
    #: Names, units and longer names of the body state's components (none for a model without one).
    body_names: ClassVar[tuple[str, ...]] = ()
    body_units: ClassVar[tuple[str, ...]] = ()
    body_long_names: ClassVar[tuple[str, ...]] = ()
    #: The compiled step ``step(x, body, u, i, scale, params, n_axes)``: see the module text.
    step: ClassVar[Any]

    #: Indices of position, velocity and tilt in the per-axis state.
    POSITION: ClassVar[int] = 0
    VELOCITY: ClassVar[int] = 1
    TILT: ClassVar[int] = 2

    def __init__(self, params: Any):
        self.params = params

    @classmethod
    def kernel(cls) -> Any:
        """The compiled step the loop binds to ``vehicle_step`` (:mod:`tmem.engine.loop`)."""
        return cls.step

    @abstractmethod
    def linearisation(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` about hover on ``(P, V, phi, omega)`` per axis: shapes (4, 4) and (4,)."""

    @abstractmethod
    def step_params(self, dt: float) -> NamedTuple:
        """The record the compiled :attr:`step` needs to advance one step of ``dt`` seconds.

        Parameters
        ----------
        dt : float
            The time step (s).
        """

    def initial_body(self, state: np.ndarray) -> np.ndarray:
        """The body states of agents starting in the per-axis states ``state``: shape ``(agents, len(body_names))``.

        Parameters
        ----------
        state : ndarray, shape (agents, axes, n_state)
        """
        return np.zeros((state.shape[0], len(self.body_names)))

    def position(self, state: np.ndarray) -> np.ndarray:
        """Positions (m) from states shaped ``(..., axes, n_state)``: shape ``(..., axes)``.

        Parameters
        ----------
        state : ndarray, shape (..., axes, n_state)
        """
        return state[..., self.POSITION]

    def velocity(self, state: np.ndarray) -> np.ndarray:
        """Velocities (m/s) from states shaped ``(..., axes, n_state)``: shape ``(..., axes)``.

        Parameters
        ----------
        state : ndarray, shape (..., axes, n_state)
        """
        return state[..., self.VELOCITY]

    def tilt(self, state: np.ndarray) -> np.ndarray:
        """Tilts (rad) from states shaped ``(..., axes, n_state)``: shape ``(..., axes)``.

        Parameters
        ----------
        state : ndarray, shape (..., axes, n_state)
        """
        return state[..., self.TILT]
