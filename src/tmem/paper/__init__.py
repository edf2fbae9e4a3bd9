"""The paper reproduced: Figs. 5, 7 and 9 run and set beside the paper's numbers (``tmem paper``).

* :mod:`tmem.paper.report` — the three runs, their report and figures;
* :mod:`tmem.paper.further` — Figs. 7 and 9 rerun under the paper's further work (energy-matched
  uncoupling, speed synchronisation).
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
