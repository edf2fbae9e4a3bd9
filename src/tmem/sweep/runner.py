"""Running a sweep on Dask: local by default, or an existing cluster by its scheduler's address.

:func:`run_sweep` takes the lock beside the output directory
(:func:`tmem.files.outputs.lock_beside`) before it looks at the directory: of two sweeps
started into one directory at the same instant, the second is refused at once.  Under the lock
it opens the output directory (:mod:`tmem.sweep.store`),
leaves out the cases already done, groups the others into chunks
(:func:`tmem.sweep.tasks.plan_chunks`), submits one task per chunk and
writes rows as tasks finish.  The local cluster and a remote one take the
same path: a :class:`dask.distributed.Client` and its futures
(:mod:`tmem.sweep.cluster`).  A remote cluster's workers need tmem
installed, in the same version.

Nothing is lost when a sweep stops early: on Ctrl-C the rows received are
written before :class:`SweepInterrupted` is raised (SIGTERM and SIGHUP alike); a killed worker's tasks
are run again by Dask on the others; after a killed client, the parts on
disk are whole; tasks the cluster loses (a scheduler gone, a connection
closed) leave their cases without rows.  The same command then runs only
what is missing.  A task that fails as a whole for its own sake (its worker
killed again and again by it) gives its cases rows with the error, like a
case that raises.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import CancelledError
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

import tmem.engine  # noqa: F401 - before tmem.law.record (through the tasks), which the engine's driver imports back
from tmem.files.outputs import lock_beside, update_files
from tmem.sweep.cluster import check_workers, dask_client, takes_signals
from tmem.sweep.report import write_report
from tmem.sweep.spec import Sweep
from tmem.sweep.store import ResultStore
from tmem.sweep.tasks import one_line, plan_chunks, row, run_chunk

#: Rows are written to disk at least this often (s) while tasks finish, and whenever this many wait.
FLUSH_SECONDS = 2.0
FLUSH_ROWS = 2000
#: How often (s) the collecting loop looks for finished tasks and for Ctrl-C.
POLL_SECONDS = 0.05


class SweepInterrupted(Exception):
    """The sweep stopped early after writing the rows it had; ``done`` of ``total`` cases are saved.

    Raised on Ctrl-C, and when the cluster lost tasks (a scheduler gone, a
    connection closed): their cases have no rows and run when the sweep is
    started again.

    Parameters
    ----------
    done, total : int
        Cases saved, and cases of the sweep.
    why : str
        What stopped it, at the start of the message.
    """

    def __init__(self, done: int, total: int, why: str = "interrupted"):
        super().__init__(f"{why}: {done} of {total} cases saved; run the same command again to go on")
        self.done = done
        self.total = total


@dataclass(frozen=True)
class SweepOutcome:
    """What :func:`run_sweep` did: every case's row, how many ran now, how many failed."""

    table: pd.DataFrame
    ran: int
    failed: int
    seconds: float


@contextmanager
def _ctrl_c_as_flag() -> Iterator[threading.Event]:
    """While the sweep runs, Ctrl-C (and SIGTERM, SIGHUP) set a flag that the collecting loop reads between tasks.

    A KeyboardInterrupt raised at a random point inside Dask's client machinery
    leaves it half-stopped and logging tracebacks; read as a flag, Ctrl-C stops
    the sweep in order.  (Only the main thread can take signals; elsewhere the
    flag is never set.  A signal set to be ignored stays ignored.)
    """
    flag = threading.Event()
    if not takes_signals():
        yield flag
        return
    previous = {}
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is not None and signal.getsignal(signum) not in (signal.SIG_IGN, None):
            previous[signum] = signal.signal(signum, lambda signum, frame: flag.set())
    try:
        yield flag
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def run_sweep(
    sweep: Sweep,
    out: str | Path,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    notify: Callable[[str], None] | None = None,
) -> SweepOutcome:
    """Run every case of ``sweep`` not yet done in ``out``; write the table, ``summary.md`` and figures.

    Parameters
    ----------
    sweep
        The checked sweep (its file is kept in ``out/sweep.toml``).
    out
        The output directory: new, or holding this sweep's results so far.
    scheduler
        Address of an existing Dask scheduler (``tcp://host:8786``); by
        default a local cluster of ``workers`` processes (all cores).
    workers
        Worker processes of the local cluster; ``None``: one per core.
    progress
        Called as ``progress(cases_done, cases_total)`` as tasks finish.
    notify
        Called as ``notify(line)`` when a file of rows that cannot be read is
        set aside and its cases run again; by default a :class:`UserWarning`.

    Raises :class:`SweepInterrupted` on Ctrl-C, after saving what finished.
    """
    started = time.perf_counter()
    out = Path(out)
    workers = check_workers(workers, scheduler)
    ResultStore.check(out, sweep, notify)  # a directory that is no sweep's refused before any lock is made for it
    with ExitStack() as held:
        held.enter_context(lock_beside(out, "sweep"))  # before anything about the directory is decided
        store = ResultStore.check(out, sweep, notify)
        metrics = store.metrics
        if store.exists:
            held.enter_context(store.opened())  # the lock, before reading what is done
        done_before = store.done_cases()
        todo = [c for c in sweep.cases() if c.index not in done_before]
        done = sweep.n_cases - len(todo)
        ran = 0
        if progress:
            progress(done, sweep.n_cases)
        if todo:
            with _ctrl_c_as_flag() as ctrl_c, dask_client(scheduler, workers) as client:
                if not store.exists:  # made only once the cluster answers: a bad --scheduler leaves nothing
                    held.enter_context(store.opened())
                base = client.scatter(sweep.base, broadcast=True)
                chunks = plan_chunks(sweep.base, todo, metrics, sweep.spec.batch)
                futures = {client.submit(run_chunk, base, chunk, metrics, pure=False): chunk for chunk in chunks}
                ran, lost = _collect(client, futures, store, metrics, ctrl_c, progress, done, sweep.n_cases)
            if lost:
                raise SweepInterrupted(done + ran, sweep.n_cases, why=f"tasks lost, {lost}")
        if not store.exists:  # a sweep of no cases
            held.enter_context(store.opened())
        table = store.finish()
        with update_files(out) as folder:  # the report replaces an earlier one only while it is as tmem wrote it
            write_report(table, sweep, folder)
    return SweepOutcome(table=table, ran=ran, failed=int(table["error"].notna().sum()), seconds=time.perf_counter() - started)


def _collect(
    client, futures: dict, store: ResultStore, metrics, ctrl_c, progress, done: int, total: int
) -> tuple[int, str]:
    """Save the rows of ``futures`` (future -> its chunk of cases) as they finish, in batches.

    Returns the number of cases run and why tasks were lost ("" if none were).  Raises
    :class:`SweepInterrupted` once ``ctrl_c`` is set, after saving the rows that came back.
    """
    from dask.distributed import as_completed

    waiting: list[dict] = []
    ran = 0
    lost = ""
    last_flush = -math.inf  # the first rows go to disk at once
    finished = as_completed(futures, loop=client.loop)
    try:
        while not finished.is_empty():
            if ctrl_c.is_set():
                raise KeyboardInterrupt
            ready = finished.next_batch(block=False)
            if not ready:
                time.sleep(POLL_SECONDS)
            for future in ready:
                chunk = futures.pop(future)
                try:
                    waiting += future.result()
                    ran += len(chunk)
                except (CancelledError, OSError) as exc:  # the cluster's failure, not the cases': no rows
                    lost = f"{one_line(exc)} (from the cluster)"
                except Exception as exc:  # e.g. a worker killed again and again by this chunk
                    waiting += [row(case, metrics, None, one_line(exc), None) for case in chunk]
                    ran += len(chunk)
            if waiting and (len(waiting) >= FLUSH_ROWS or time.perf_counter() - last_flush > FLUSH_SECONDS):
                store.add(waiting)
                waiting, last_flush = [], time.perf_counter()
            if progress and ready:
                progress(done + ran, total)
        if ctrl_c.is_set():  # came as the last tasks finished: still a stop, not a finish
            raise KeyboardInterrupt
        store.add(waiting)
    except KeyboardInterrupt:
        store.add(waiting)
        client.cancel(list(futures))
        raise SweepInterrupted(done + ran, total) from None
    return ran, lost
