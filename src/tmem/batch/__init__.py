"""Many two-agent encounters at once, for studies: the step loop's pair law, free flight in closed form.

* :mod:`tmem.batch.encounters` — the cases side by side on 1 to 3 axes (:func:`run_batch`);
* :mod:`tmem.batch.relative` — the paper's one-axis case on the pair's relative state.
"""

from tmem.batch.encounters import BatchResult, run_batch, unsupported

__all__ = ["BatchResult", "run_batch", "unsupported"]
