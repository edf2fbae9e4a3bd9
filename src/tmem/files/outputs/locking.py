"""The lock of a directory that a long command (a sweep) writes into, taken before the directory is looked at.

A sweep holds ``.NAME.tmem-lock`` beside its directory ``NAME`` (:func:`lock_beside`) from before
it decides anything about the directory (whether it is new, whose results it holds, which cases
are done) until it ends: of two sweeps started at the same instant into one directory, the second
is refused at once, whether the directory exists yet or not.  Once the directory exists it also
holds ``NAME/.tmem-lock`` (:func:`lock`), the lock earlier tmem versions take.  Both are the
operating system's locks (``flock``): they end with their process however it ends, and are seen
from every process-id namespace.
"""

from __future__ import annotations

import errno
import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tmem.files.outputs.manifest import LOCK, OutputError, _cannot_write
from tmem.files.outputs.names import _kept, missing_parents, remove_made


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists in this process-id namespace (only where files cannot be locked)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # someone else's process
    except (OverflowError, OSError, ValueError):
        return False
    return True


def _holder(fd: int) -> dict:
    """What an open lock file says of its holder: ``pid``, ``host``, ``command`` (what can be read)."""
    try:
        said = json.loads(os.pread(fd, 4096, 0) or b"{}")
    except (OSError, ValueError):
        return {}
    return said if isinstance(said, dict) else {}


def _who(holder: dict) -> str:
    pid = holder.get("pid")
    who = f"process {pid}" if isinstance(pid, int) else "process ?"
    host = holder.get("host")
    return who + (f" on {host}" if isinstance(host, str) and host != os.uname().nodename else "")


@contextmanager
def _held(path: Path, where: Path, command: str) -> Iterator[None]:
    """Hold the lock file ``path`` for the block; refuse, in one line naming ``where``, one held elsewhere."""
    import fcntl

    for _ in range(10):
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
        except OSError as exc:
            raise _cannot_write(where, exc) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            held = False
        except BlockingIOError:
            held = True
        except OSError:  # no locks on this file system: the process id alone can say whether it is held
            pid = _holder(fd).get("pid")
            held = isinstance(pid, int) and pid != os.getpid() and _alive(pid)
        if held:
            holder = _holder(fd)
            os.close(fd)
            raise OutputError(f"--out {where}: another `tmem {command}` ({_who(holder)}) is writing to it; wait for it to end or stop it")
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)  # removed by its holder as it ended: open the new one
    else:
        raise OutputError(f"--out {where}: its lock {path.name} keeps changing; try again")
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps({"pid": os.getpid(), "host": os.uname().nodename, "command": command}).encode(), 0)
        yield
    finally:
        try:
            path.unlink(missing_ok=True)
        except OSError:
            pass  # a read-only folder: the lock file stays, unheld
        finally:
            os.close(fd)


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
    with _held(directory / LOCK, directory, command):
        yield


def lock_path(out: Path) -> Path:
    """The lock beside the directory ``out``: ``.NAME.tmem-lock`` in its folder (the name's first 180 bytes).

    Parameters
    ----------
    out : Path
        The directory (which may not exist yet).
    """
    return out.parent / f".{_kept(out.name)}.tmem-lock"


@contextmanager
def lock_beside(out: str | Path, command: str) -> Iterator[None]:
    """Hold the lock beside ``out`` (:func:`lock_path`) for the block, before anything about ``out`` is decided.

    Folders above ``out`` that are missing are made for the lock, and removed again when the block
    ends if they are still empty.  Where the folder holding ``out`` cannot be written and ``out`` is
    an existing directory, nobody can make, rename or remove ``out`` meanwhile, and the lock inside
    it (:func:`lock`) is enough: the block runs without this one.

    Parameters
    ----------
    out : str or Path
        The output directory.
    command : str
        The command holding it (``"sweep"``), named in the message of a second one.

    Raises
    ------
    OutputError
        In one line: another process holds the lock, or it cannot be made.
    """
    out = Path(out)
    path = lock_path(out)
    made = missing_parents(out)
    try:
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            os.close(os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644))
            beside = True
        except OSError as exc:
            if exc.errno not in (errno.EACCES, errno.EPERM, errno.EROFS) or out.is_symlink() or not out.is_dir():
                raise _cannot_write(out, exc) from None
            beside = False
        if beside:
            with _held(path, out, command):
                yield
        else:
            yield
    finally:
        remove_made(made)
