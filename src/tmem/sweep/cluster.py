"""The Dask cluster of a sweep: a local one, or an existing one checked before use; its log kept to what matters.

* :func:`check_scheduler` asks a ``--scheduler`` address, once and within
  :data:`CONNECT_SECONDS`, whether a Dask scheduler answers there.
  distributed's own client waits for the other end's handshake without a
  timeout: a web server there hangs it forever, and garbage makes it
  allocate what the garbage's first bytes ask for.
* :func:`dask_client` gives a client of that cluster, or of a new local
  cluster whose worker processes ignore Ctrl-C (the sweep's process answers
  it for them, saving the rows it has).
* While the client is open, Dask's own log says, each in one line without
  its traceback, only errors that are news: not those of its recovery from
  a lost worker (whose tasks it runs again), and nothing at all once the
  sweep stops and the cluster shuts down (comms closing, heartbeats
  missed).  The local cluster's worker processes log nothing below
  CRITICAL: what fails in them reaches the sweep through its tasks.
"""

from __future__ import annotations

import logging
import os
import re
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

from tmem.sweep.spec import SweepError
from tmem.sweep.tasks import one_line

#: A ``--scheduler`` must answer as a Dask scheduler within this time (s), or the sweep is refused.
CONNECT_SECONDS = 10.0
#: Dask's error messages that say it is recovering by itself (a lost worker's results computed again).
RECOVERING = ("Couldn't gather keys",)
#: Runs in each worker process of the local cluster, restarted ones too (:mod:`tmem.sweep._worker`).
WORKER_PRELOAD = "tmem.sweep._worker"
#: How often (s) the start of the local cluster's worker processes is looked for.
SPAWN_POLL_SECONDS = 0.01
#: The most worker processes of a local cluster, per core: more would only compete for the cores.
WORKERS_PER_CORE = 8


def takes_signals() -> bool:
    """Whether this is the main thread: only it can install signal handlers."""
    return threading.current_thread() is threading.main_thread()


async def _identity(address: str, seconds: float) -> dict:
    """What the Dask server at ``address`` says it is (its ``identity``), over one short connection."""
    from distributed.comm import connect
    from distributed.security import Security

    # distributed's connect retries until its timeout, but then waits for the other end's
    # handshake without one: the caller bounds the whole.
    comm = await connect(address, timeout=0.9 * seconds, **Security().get_connection_args("client"))
    try:
        await comm.write({"op": "identity", "reply": True})  # any Dask server answers it, with its type
        return await comm.read()
    finally:
        comm.abort()


def check_scheduler(address: str, seconds: float | None = None) -> None:
    """Refuse, within about ``seconds``, an ``address`` where no Dask scheduler answers.

    Parameters
    ----------
    address : str
        The ``--scheduler`` address, such as ``tcp://host:8786``.
    seconds : float, optional
        The longest wait for the answer (s); by default :data:`CONNECT_SECONDS`.

    Raises
    ------
    SweepError
        In one line naming ``--scheduler`` and the reason.
    """
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    seconds = CONNECT_SECONDS if seconds is None else seconds
    try:
        with ThreadPoolExecutor(1) as thread:  # a loop of its own, even where one runs (a notebook)
            identity = thread.submit(asyncio.run, asyncio.wait_for(_identity(address, seconds), seconds)).result()
    except TimeoutError:
        why = f"nothing answered as a Dask scheduler within {seconds:g} s"
    except (OSError, ValueError) as exc:  # unreachable, refused, closed, or a malformed address
        why = f"cannot connect ({one_line(exc)})"
    except Exception:  # e.g. a length prefix of 3 EiB: what answered does not speak Dask's protocol
        why = "what answers there is not a Dask scheduler"
    else:
        kind = identity.get("type") if isinstance(identity, dict) else None
        if kind == "Scheduler":
            return
        why = "what answers there is not a Dask scheduler"
        if isinstance(kind, str):
            why = f"what answers there is a Dask {kind}, not a scheduler"
    raise SweepError(f"--scheduler {address}: {why}")


def check_workers(workers: int | str | None, scheduler: str | None = None) -> int | None:
    """The number of worker processes of the local cluster, checked; ``None``: one per core.

    Parameters
    ----------
    workers : int, str or None
        ``--workers`` as given (a string from the command line).
    scheduler : str or None
        ``--scheduler``: an existing cluster brings its own workers.

    Raises
    ------
    SweepError
        In one line naming ``--workers`` and the reason.
    """
    if workers is None:
        return None
    count = None
    if isinstance(workers, int) and not isinstance(workers, bool):
        count = workers
    elif isinstance(workers, str) and re.fullmatch(r"\s*[+-]?[0-9]{1,30}\s*", workers):
        count = int(workers)
    cores = os.cpu_count() or 1
    if count is None:
        why = "must be a whole number of worker processes"
    elif count < 1:
        why = "must be at least 1"
    elif count > WORKERS_PER_CORE * cores:
        why = f"more than {WORKERS_PER_CORE} per core ({cores} here) would only compete for the cores"
    elif scheduler:
        why = "is for the local cluster; with --scheduler the cluster's own workers run the cases"
    else:
        return count
    raise SweepError(f"--workers {workers}: {why}")


class DaskLog(logging.Filter):
    """A filter on the handlers of Dask's log: errors that are news, each as one line; nothing once ``closing``."""

    def __init__(self) -> None:
        super().__init__()
        self.closing = False

    def filter(self, record: logging.LogRecord) -> bool:
        """Whether to show ``record``; one shown loses its traceback and has its whitespace folded.

        Parameters
        ----------
        record : logging.LogRecord
            A record of Dask's log, on its way to a handler.
        """
        message = record.getMessage()
        if self.closing or record.levelno < logging.ERROR or message.startswith(RECOVERING):
            return False
        record.msg, record.args = " ".join(message.split()), ()
        record.exc_info, record.exc_text, record.stack_info = None, None, None
        return True


def _dask_handlers() -> list[logging.Handler]:
    """The handlers of the ``distributed`` logger and those below it (its import sets them up)."""
    import distributed  # noqa: F401

    names = [name for name in logging.root.manager.loggerDict if name == "distributed" or name.startswith("distributed.")]
    handlers = {id(h): h for name in names for h in logging.getLogger(name).handlers}
    return list(handlers.values())


@contextmanager
def _dask_log() -> Iterator[DaskLog]:
    """Hold a :class:`DaskLog` on the handlers of Dask's log."""
    handlers = _dask_handlers()
    log = DaskLog()
    for handler in handlers:
        handler.addFilter(log)
    try:
        yield log
    finally:
        for handler in handlers:
            handler.removeFilter(log)


@contextmanager
def _errors_shown(log: DaskLog) -> Iterator[None]:
    """Let errors through the handlers' levels while the client is used; then close ``log``."""
    handlers = _dask_handlers()
    levels = [handler.level for handler in handlers]
    for handler in handlers:
        handler.setLevel(logging.ERROR)  # the local cluster set them to CRITICAL for its worker processes' sake
    try:
        yield
    finally:
        for handler, level in zip(handlers, levels):
            handler.setLevel(level)  # before the cluster closes, which sets back the levels it found
        log.closing = True


@contextmanager
def _remote_client(scheduler: str) -> Iterator:
    from dask.distributed import Client

    check_scheduler(scheduler)
    try:
        client = Client(scheduler, timeout="20s", set_as_default=False)  # a failed one must not linger as the default
    except (OSError, TimeoutError, ValueError) as exc:
        raise SweepError(f"--scheduler {scheduler}: cannot connect ({one_line(exc)})") from None
    try:
        yield client
    finally:
        client.close()


def _start_local_cluster(workers: int):
    """A new local cluster of ``workers`` processes, each started with SIGINT ignored.

    Ctrl-C reaches every process of the terminal's group.  The worker
    processes inherit SIGINT ignored from this one while they are being
    started (and a restarted one ignores it in its preload), so that only
    this process answers it: it saves the rows it has and shuts the cluster
    down, instead of every worker dying with a traceback.  This process
    ignores SIGINT only until its workers exist, not while they start up
    (seconds): the cluster is made in a thread while the main thread
    watches for them, so that a Ctrl-C then is not lost.
    """
    import multiprocessing
    from concurrent.futures import ThreadPoolExecutor

    from dask.distributed import LocalCluster

    main_thread = takes_signals()
    before = set(multiprocessing.active_children())
    interrupt = signal.signal(signal.SIGINT, signal.SIG_IGN) if main_thread else None
    with ThreadPoolExecutor(1) as thread:
        try:
            made = thread.submit(
                LocalCluster, n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                silence_logs=logging.CRITICAL, preload=[WORKER_PRELOAD],
                env={"NUMBA_NUM_THREADS": "1"},  # one process per core; no threads within
            )  # fmt: skip
            while not made.done() and len(set(multiprocessing.active_children()) - before) < workers:
                time.sleep(SPAWN_POLL_SECONDS)
        finally:
            if main_thread:
                signal.signal(signal.SIGINT, interrupt)
        return made.result()


@contextmanager
def _local_client(workers: int | None) -> Iterator:
    from dask.distributed import Client

    import multiprocessing

    before = set(multiprocessing.active_children())
    cluster = _start_local_cluster(workers or os.cpu_count() or 1)
    client = Client(cluster, set_as_default=False)
    try:
        yield client
    finally:
        client.close()
        try:
            cluster.close()
        except TimeoutError:  # a worker too slow to answer (a loaded or paused machine): its rows are saved
            for nanny in getattr(cluster, "workers", {}).values():  # a nanny would start a killed worker again
                if hasattr(nanny, "close_gracefully"):
                    nanny.close_gracefully(reason="the cluster did not close in time")
            for worker in set(multiprocessing.active_children()) - before:  # none may outlive the command
                worker.kill()
                worker.join(timeout=5)


@contextmanager
def dask_client(scheduler: str | None, workers: int | None) -> Iterator:
    """A client of the cluster at ``scheduler``, or of a new local cluster of ``workers`` processes.

    Parameters
    ----------
    scheduler : str or None
        Address of an existing Dask scheduler (checked by
        :func:`check_scheduler`); ``None`` starts a local cluster.
    workers : int or None
        Worker processes of the local cluster; ``None``: one per core.

    Raises
    ------
    SweepError
        If ``scheduler`` is given and no Dask scheduler answers there.
    """
    with _dask_log() as log:
        with (_remote_client(scheduler) if scheduler else _local_client(workers)) as client:
            with _errors_shown(log):
                yield client
