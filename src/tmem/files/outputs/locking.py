"""The lock of a directory that a long command (a sweep) writes into: ``.tmem-lock``."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tmem.files.outputs.manifest import LOCK, OutputError, _cannot_write
from tmem.files.outputs.names import _alive


def _holder(fd: int) -> int | None:
    """The process id written in an open lock file, if any."""
    try:
        pid = json.loads(os.pread(fd, 4096, 0) or b"{}").get("pid")
    except (OSError, ValueError, AttributeError):
        return None
    return pid if isinstance(pid, int) else None


@contextmanager
def lock(directory: Path, command: str) -> Iterator[None]:
    """Hold ``directory/.tmem-lock`` for the block; refuse, in one line, a directory another process holds.

    The lock is the operating system's (``flock``), so it ends with its
    process, however that ends; the file holds the holder's process id for
    the message and is removed when the block ends.

    Parameters
    ----------
    directory : Path
        The existing directory to lock.
    command : str
        The command holding it (``"sweep"``), written in the lock and named
        in the message of a second one.
    """
    import fcntl

    path = directory / LOCK
    for _ in range(10):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            raise _cannot_write(directory, exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            held = False
        except BlockingIOError:
            held = True
        except OSError:  # no locks on this file system: the process id alone says whether it is held
            holder = _holder(fd)
            held = holder is not None and holder != os.getpid() and _alive(holder)
        if held:
            holder = _holder(fd)
            os.close(fd)
            raise OutputError(
                f"--out {directory}: another `tmem {command}` (process {holder or '?'}) is writing to it; "
                "wait for it to end or stop it"
            )
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)  # removed by its holder as it ended: open the new one
    else:
        raise OutputError(f"--out {directory}: its {LOCK} keeps changing; try again")
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps({"pid": os.getpid(), "command": command}).encode(), 0)
        yield
    finally:
        try:
            path.unlink(missing_ok=True)
        finally:
            os.close(fd)
