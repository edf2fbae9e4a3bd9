"""What a run measured: its summary, the gas's observables, coverage, and a continuous-time reference.

* :mod:`tmem.analysis.metrics` — a trajectory's summary (RMS velocity, events, distances, formation);
* :mod:`tmem.analysis.rms` — the RMS velocity at the start, at the end, and its largest change on the way;
* :mod:`tmem.analysis.observables` — the gas's pressure, temperature, encounter rate, mean free path;
* :mod:`tmem.analysis.coverage` — the share of a walled box the swarm visits;
* :mod:`tmem.analysis.field_metrics` — the flocking literature's figures: order, near misses, groups, connectivity ...;
* :mod:`tmem.analysis.safety` — those figures in the summary, where a scenario has a ``[safety]`` table;
* :mod:`tmem.analysis.reference` — the same closed loop integrated in continuous time, to test the engine against.
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
