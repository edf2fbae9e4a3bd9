"""Figures of a run: plots, the formation's shape, the animation and the browser viewer.

* :mod:`tmem.figures.plot` — velocity, distance, pushes and paths against time (``tmem plot``);
* :mod:`tmem.figures.shape_plot` — the paths and the formation's shape;
* :mod:`tmem.figures.drawing` — what every figure shares (agents numbered from 1, which are drawn);
* :mod:`tmem.figures.animate` — a run as a video (``tmem animate``);
* :mod:`tmem.figures.viewer` — a run as one HTML page that plays it in a browser (``tmem view``).
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
