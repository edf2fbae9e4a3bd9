"""The engine: a scenario in, a recorded trajectory and its events out.

The step, for every agent at every step ``k`` (time ``k dt``), in the order the compiled loop runs
it (:mod:`tmem.engine.loop`)::

    commands -> measurement -> P* (6) -> neighbour pushes (8) -> formation pairs (9)-(11)
             -> agent terms (the gas's walls and thermostat last) -> record
             -> saturate |U| <= c_max -> the vehicle's step over dt

* :mod:`tmem.engine.records` — the named records the stages work on;
* :mod:`tmem.engine.stages` — commands, ``P*`` and the record; the neighbours' pushes
  (:mod:`tmem.engine.pushes`), the formation pairs (:mod:`tmem.engine.pairs`), both as each agent
  senses them (:mod:`tmem.engine.sensed`); the agent terms (:mod:`tmem.engine.terms`) and the gas
  (:mod:`tmem.engine.gas`, :mod:`tmem.engine.thermostat`);
* :mod:`tmem.engine.variants` — a variant of the step: which kernel stands for each stage that
  varies (the knowledge, :mod:`tmem.engine.knowledge`; the terms; the gas; the vehicle);
* :mod:`tmem.engine.loop` — the loop, compiled once per variant;
* :mod:`tmem.engine.driver` — builds the records from a scenario and drives the loop;
* :mod:`tmem.engine.checkpoint` — a run's state saved at checkpoints, and the run resumed from one;
* :mod:`tmem.engine.trajectory` — what a run returns.

``docs/architecture.md`` describes each stage and record, and how to extend them.
"""

from __future__ import annotations

from tmem.engine.checkpoint import CheckpointError, Checkpoints
from tmem.engine.driver import record_steps, simulate
from tmem.engine.trajectory import DIVERGED, Event, SimulationError, Trajectory

__all__ = ["DIVERGED", "CheckpointError", "Checkpoints", "Event", "SimulationError", "Trajectory", "record_steps", "simulate"]
