"""Parameter sweeps: many runs of one base scenario, on Dask, resumable.

The pieces, in the order data flows:

* :mod:`tmem.sweep.spec` reads and checks a sweep file and expands it into
  numbered cases (each a set of changes to the base scenario);
* :mod:`tmem.sweep.tasks` runs a chunk of cases on a worker, two-agent
  one-axis cases as one vectorised batch (:mod:`tmem.batch.encounters`), others one by
  one (:func:`tmem.simulate`), and turns each into a row of metrics;
* :mod:`tmem.sweep.store` keeps the rows on disk as Parquet parts written as
  tasks finish, so an interrupted sweep resumes where it stopped;
* :mod:`tmem.sweep.runner` hands the chunks to a Dask cluster
  (:mod:`tmem.sweep.cluster`: local, or an existing one by address, checked)
  and collects them;
* :mod:`tmem.sweep.report` writes ``summary.md`` and the figures.
"""

from tmem.sweep.report import write_report
from tmem.sweep.runner import SweepInterrupted, SweepOutcome, run_sweep
from tmem.sweep.spec import Sweep, SweepError, load_sweep, loads_sweep

__all__ = ["Sweep", "SweepError", "SweepInterrupted", "SweepOutcome", "load_sweep", "loads_sweep", "run_sweep", "write_report"]
