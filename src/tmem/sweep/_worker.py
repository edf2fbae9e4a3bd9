"""Preload of the local cluster's worker processes: Ctrl-C is for the sweep's process, not theirs.

The first workers are started with SIGINT ignored, inherited from the
sweep's process (:func:`tmem.sweep.cluster.dask_client`); a worker that
Dask restarts after it died is started later, when that process handles
SIGINT again, and ignores it from here on.
"""

from __future__ import annotations

import signal
import threading


def dask_setup(worker) -> None:
    """Ignore SIGINT in this worker process (Dask calls this as the worker starts).

    Parameters
    ----------
    worker : distributed.Worker
        The worker starting; not used.
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
