"""The contract every vehicle model fulfils.

The engine steps a swarm of one vehicle model.  Agent ``i``'s state is kept
per horizontal axis ``a`` as ``state[i, a, :]``; a model names the components
and their units.  The TMEM law reads the first four, in the order of the
paper's model (2): position ``P`` (m), velocity ``V`` (m/s), tilt ``phi``
(rad) and tilt rate ``omega`` (rad/s); a model may keep more components
after them (a motor's state, say).

A model provides

* its state names, units and long names (:attr:`VehicleModel.state_names` ...);
* its linearisation ``(A, B)`` about hover, per axis, on ``(P, V, phi, omega)``
  with the tilt set-point as input: the modal gains (4) are designed on it
  (:func:`tmem.control.gains_for`);
* its compiled step: :meth:`VehicleModel.step_params` gives the record of
  numbers the step needs for a time step ``dt``, and :attr:`VehicleModel.step`
  is a Numba kernel ``step(x, u, i, scale, params, n_axes)`` that advances
  agent ``i`` over ``dt`` in place with the set-point ``u[i, :] * scale`` held.
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
    #: The compiled step ``step(x, u, i, scale, params, n_axes)``: see the module text.
    step: ClassVar[Any]

    #: Indices of position, velocity and tilt in the per-axis state.
    POSITION: ClassVar[int] = 0
    VELOCITY: ClassVar[int] = 1
    TILT: ClassVar[int] = 2

    def __init__(self, params: Any):
        self.params = params

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
