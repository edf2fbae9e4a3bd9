"""A run's files: writing them safely, reading them back, and the field's exchange formats.

* :mod:`tmem.files.io` — a run's output folder: ``summary.json``, ``trajectory.nc``, the figures;
* :mod:`tmem.files.trajectory_file` — the layout of ``trajectory.nc`` (CF trajectories) and how tmem reads it;
* :mod:`tmem.files.saved` — a saved run read back as a :class:`~tmem.engine.Trajectory`;
* :mod:`tmem.files.arrays` — ``.npz`` files (checkpoints) read one array at a time, within the bytes they hold;
* :mod:`tmem.files.outputs` — writing outputs: atomically, never over a user's files, cleaned up when interrupted;
* :mod:`tmem.files.exchange` — a run as MCAP (Foxglove) or Crazyswarm2 CSV files.
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
