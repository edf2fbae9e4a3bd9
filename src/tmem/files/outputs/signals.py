"""Signals: SIGTERM handled as Ctrl-C, and signals held back while an output is renamed into place."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager


_received: list[int] = []


def _raise_interrupt(signum: int, frame) -> None:
    _received.append(signum)
    raise KeyboardInterrupt


def interrupted() -> bool:
    """Whether Ctrl-C, SIGTERM or SIGHUP has come since :func:`handle_termination`.

    A library's compiled code that calls back into Python may turn the
    :class:`KeyboardInterrupt` raised there into an error of its own
    (Matplotlib: "Invalid affine transformation matrix"); a command that
    fails asks this first, and ends as interrupted rather than failed.
    """
    return bool(_received)


def handle_termination() -> None:
    """Handle Ctrl-C, SIGTERM and SIGHUP alike: raise :class:`KeyboardInterrupt` in the main thread, and
    remember that one came (:func:`interrupted`).

    A signal the parent process set to be ignored (``nohup``) stays ignored.
    Called by the ``tmem`` command before it runs; only the main thread can.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is not None and signal.getsignal(signum) is not signal.SIG_IGN:
            signal.signal(signum, _raise_interrupt)


def ignore_interrupts() -> None:
    """Ignore Ctrl-C, SIGTERM and SIGHUP from now on: called once a command's work and its exit status are settled.

    Python restores the default handlers while it shuts down, so a signal
    arriving then would end the process by that signal and replace the exit
    status the command had already chosen.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is not None:
            signal.signal(signum, signal.SIG_IGN)


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold back Ctrl-C, SIGTERM and SIGHUP for the block, then deliver the first that came."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = {}
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is None:
            continue
        handler = signal.getsignal(signum)
        if handler is signal.SIG_IGN or handler is None:
            continue
        previous[signum] = signal.signal(signum, lambda s, frame: caught.append(s))
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if caught:
            signal.raise_signal(caught[0])
