"""Planning for formation missions: who goes where, by which way, from which starts.

Pure NumPy and SciPy, nothing of the engine: each function takes arrays of places (m) and returns
arrays, for a scenario to fly or for a study to check.

* :mod:`tmem.plan.assignment` — CAPT (Turpin, Michael and Kumar 2014): the start-to-goal
  assignment that minimises the sum of squared distances, the synchronised straight-line
  trajectories, their shortest duration under speed and acceleration limits, their clearance,
  and the separation that guarantees it;
* :mod:`tmem.plan.shapes` — target shapes as slot offsets about their centroid (hexagonal patch,
  line, ring, grid), each with the pairs of neighbouring slots;
* :mod:`tmem.plan.route` — a group's route around circular obstacles in the plane: the shortest
  path in the visibility graph of the obstacles inflated by a clearance;
* :mod:`tmem.plan.starts` — random starts at least a given distance apart (Poisson-disk
  sampling), refused where that many cannot fit.

The package imports nothing on import (PEP 562, :func:`tmem._lazy.submodules`): SciPy loads with
the first submodule used.
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
