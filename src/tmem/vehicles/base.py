"""The contract every vehicle model fulfils: the state the law reads, the input it takes, its step.

The engine steps a swarm of one vehicle model.  Agent ``i``'s state is kept per horizontal axis
``a`` as ``state[i, a, :]``; a model names the components and their units.  The TMEM law reads the
first :attr:`VehicleModel.law_states` of them: ``P* = x . K / K_P`` (6) over those, with the gains
``K`` the model places on its own linearisation.  A tilting multirotor's law state is the paper's
``(P, V, phi, omega)`` (2); a ground robot's is ``(P, V, a)`` (:mod:`tmem.vehicles.ground_robot`).
The law's set-point ``U`` is the model's input: a tilt (rad) for a multirotor, an acceleration
(m/s^2) for the robot (:attr:`VehicleModel.input_units`), and ``interaction.c_max`` bounds it in
those units.  A model may keep more per-axis components after the law's; what belongs to the whole
vehicle rather than to one axis (a quadrotor's height, attitude, body rates and rotor speeds) is
its *body state* ``body[i, :]``, named by :attr:`VehicleModel.body_names`: the engine carries it
beside the per-axis state, restores it with the state when an agent is added back, and records it.

A model provides

* its scenario table (:attr:`VehicleModel.table`, a :class:`tmem.scenario.fields.StrictModel` with
  ``kind``), which the scenario's ``[model]`` union is built from (:data:`tmem.vehicles.VEHICLES`),
  and which may ``check(scenario)`` itself against the rest of the scenario;
* its state names, units and long names (:attr:`VehicleModel.state_names` ...), and its input's;
* its linearisation ``(A, B)`` on the law's state, the law's set-point as input, and the gains it
  places there (:meth:`VehicleModel.gains`: the roots (5), or as many of them as it has states);
* the horizontal acceleration a held input gives (:meth:`VehicleModel.acceleration_per_input`: the
  gas's thermostat turns a wanted acceleration into a set-point with it);
* its per-axis and body states at the start, from the scenario's (:meth:`VehicleModel.initial_state`,
  :meth:`VehicleModel.initial_body`);
* its compiled step (:meth:`VehicleModel.kernel`): ``step(x, body, u, i, scale, params, n_axes)``
  advances agent ``i`` (its ``x[i]`` and ``body[i]``) over ``dt`` in place with the set-point
  ``u[i, :] * scale`` held; :meth:`VehicleModel.step_params` gives the flat record of numbers it
  needs for a step of ``dt``.  A linear model steps exactly (zero-order hold); a nonlinear one takes
  sub-steps of its own within ``dt``.

The step loop is compiled once for each model (:func:`tmem.engine.loop.advance_for`), with the
model's kernel inlined, so a model costs nothing at run time.  Nothing here loads a compiler: a
model compiles its kernel when a run asks for it, so that validating a scenario stays light.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar, NamedTuple

import numpy as np


class VehicleModel(ABC):
    """A vehicle model: its table, state names, linearisation and gains, compiled step.

    Parameters
    ----------
    params
        The scenario's ``[model]`` table (its validated record).
    """

    #: The scenario's ``[model] kind`` for this model.
    kind: ClassVar[str]
    #: The ``[model]`` table of this kind.
    table: ClassVar[type]
    #: Names of the per-axis state components, the law's first.
    state_names: ClassVar[tuple[str, ...]]
    #: Units of each component, as UDUNITS writes them (NetCDF files carry them).
    state_units: ClassVar[tuple[str, ...]]
    #: A longer name of each component, for files and figures.
    long_names: ClassVar[tuple[str, ...]]
    #: How many of the leading components the law reads (the length of ``K``).
    law_states: ClassVar[int] = 4
    #: What the law's set-point is, and its units.
    input_name: ClassVar[str] = "tilt set-point"
    input_units: ClassVar[str] = "rad"
    #: Names, units and longer names of the body state's components (none for a model without one).
    body_names: ClassVar[tuple[str, ...]] = ()
    body_units: ClassVar[tuple[str, ...]] = ()
    body_long_names: ClassVar[tuple[str, ...]] = ()

    #: Indices of position and velocity in the per-axis state.
    POSITION: ClassVar[int] = 0
    VELOCITY: ClassVar[int] = 1

    def __init__(self, params: Any):
        self.params = params

    @classmethod
    @abstractmethod
    def kernel(cls) -> Any:
        """The compiled step ``step(x, body, u, i, scale, params, n_axes)`` (module text)."""

    @abstractmethod
    def linearisation(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` on the law's state per axis, about the state the vehicle holds when at rest:
        shapes ``(law_states, law_states)`` and ``(law_states,)``."""

    @abstractmethod
    def step_params(self, dt: float) -> NamedTuple:
        """The flat record the compiled step needs to advance one step of ``dt`` seconds.

        Parameters
        ----------
        dt : float
            The time step (s).
        """

    def gains(self, r_l: float, im_l: float, im_r: float) -> np.ndarray:
        """``K`` placing the roots (5) on :meth:`linearisation` (:func:`tmem.law.modal.gains_for`).

        Parameters
        ----------
        r_l, im_l, im_r : float
            The roots (5) (1/s): ``-r_l -+ i im_l``, ``-+ i im_r``.
        """
        from tmem.law.modal import gains_for

        return gains_for(*self.linearisation(), r_l, im_l, im_r)

    def acceleration_per_input(self) -> float:
        """The horizontal acceleration (m/s^2) a held set-point of one unit gives once the vehicle's
        inner states settle: ``A[1, 2]`` of the linearisation (``g`` for a tilting multirotor)."""
        return float(self.linearisation()[0][1, 2])

    @classmethod
    def initial_state(cls, state: np.ndarray) -> np.ndarray:
        """The model's per-axis states from the scenario's starts ``(P, V, tilt, tilt rate)`` per axis.

        Parameters
        ----------
        state : ndarray, shape (agents, axes, 4)
        """
        return state

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
