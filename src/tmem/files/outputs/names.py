"""Temporary names, the lock that says their writer still works, and what killed tmem processes left.

Everything tmem writes is written inside a hidden temporary directory next to its destination,
``.NAME.tmem-partial-PID-RANDOM`` (:func:`partial_name`, :func:`make_partial`).  Its writer holds,
for as long as it writes, the operating system's lock (``flock``) on the file ``.tmem-writing``
inside it (:data:`WRITING`): the lock ends with the process, however it ends, and it is seen by
every process that opens the file, whichever process-id namespace (container, ``unshare --pid``)
or machine sharing the folder it runs in.  A temporary directory whose lock can be taken was left
by a writer that is gone (:func:`is_leftover`) and is removed by the next command writing into the
same folder (:func:`remove_leftovers`); so is the directory a writer killed while it made one left,
``.NAME.tmem-starting-PID-RANDOM``, once its lock file holds what the writer writes there after
locking it.  The process id in the name is for people: it is never used to decide.  Anything else
is left alone: a name that does not match exactly, a directory without the lock file (an earlier
tmem's, or one being made), one whose lock file is still empty (being locked this instant), one
whose lock is held, and every temporary name on a file system that has no locks.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import shutil
from pathlib import Path

#: Bytes of the destination's name kept in a temporary name (names stay under 255 bytes).
_NAME_KEPT = 180
#: The longest name of a file or folder (bytes) on common file systems.
_NAME_MAX = 255
_PARTIAL = re.compile(r"\.(?P<name>.*)\.tmem-(?:partial|starting)-(?P<pid>[0-9]{1,10})-(?P<tag>[0-9a-f]{8})(?:\.[A-Za-z0-9]{1,10})?", re.S)
#: The lock file inside a temporary directory: its writer holds ``flock`` on it while it writes.
WRITING = ".tmem-writing"


def _kept(name: str) -> str:
    """The first 180 bytes of ``name``, whole characters only."""
    return os.fsdecode(os.fsencode(name)[:_NAME_KEPT])


def partial_name(name: str, suffix: str = "") -> str:
    """A hidden temporary name for ``name`` in the same folder, owned by this process.

    ``suffix`` (such as ``.gif``) is kept at the end so that writers which
    choose the format by the suffix still do.

    Parameters
    ----------
    name : str
        The destination's name (its first 180 bytes are kept).
    suffix : str
        Appended to the temporary name as it is, such as ``".gif"``; empty for none.
    """
    return f".{_kept(name)}.tmem-partial-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def make_partial(folder: Path, name: str) -> tuple[Path, int]:
    """A new temporary directory for ``name`` in ``folder``, and the open lock file that marks it as in use.

    The directory is made under another hidden name, its lock file made and locked inside it, and
    only then renamed to its temporary name (:func:`partial_name`): no process ever sees a
    temporary directory of tmem's whose writer does not hold its lock yet.  Close the returned file
    descriptor (:func:`release`) once the directory is gone or renamed into place.

    Parameters
    ----------
    folder : Path
        The existing folder of the destination.
    name : str
        The destination's name.

    Raises
    ------
    OSError
        If ``folder`` cannot be written.
    """
    while True:
        start = folder / f".{_kept(name)}.tmem-starting-{os.getpid()}-{secrets.token_hex(4)}"
        try:
            start.mkdir()  # with the umask's permissions, like any directory the user makes
            break
        except FileExistsError:
            continue
    fd = -1
    try:
        fd = os.open(start / WRITING, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
        _lock(fd, block=False)
        os.write(fd, json.dumps({"pid": os.getpid(), "host": os.uname().nodename}).encode())
        target = folder / partial_name(name)
        while target.exists() or target.is_symlink():  # a name taken: a rename would replace it
            target = folder / partial_name(name)
        os.rename(start, target)
        return target, fd
    except BaseException:
        if fd >= 0:
            os.close(fd)
        shutil.rmtree(start, ignore_errors=True)
        raise


def _lock(fd: int, block: bool) -> bool:
    """Take ``flock`` on ``fd``; False if another open file holds it, or the file system has no locks."""
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_EX | (0 if block else fcntl.LOCK_NB))
    except OSError:  # held (EWOULDBLOCK), or no locks here (ENOLCK, EINVAL): not taken
        return False
    return True


def release(directory: Path, fd: int) -> None:
    """Give up a temporary directory of :func:`make_partial`: its lock file is removed (if it is still
    at ``directory``), then the lock let go.  Never raises: a read-only folder keeps the file.

    Parameters
    ----------
    directory : Path
        Where the directory is now: its temporary name, or the destination it was renamed to.
    fd : int
        The lock file's descriptor.
    """
    try:
        (directory / WRITING).unlink(missing_ok=True)
    except OSError:
        pass
    finally:
        os.close(fd)


def discard(directory: Path, fd: int) -> None:
    """Remove a temporary directory of :func:`make_partial` with everything in it, then let go of its
    lock.  Never raises: what cannot be removed stays, and the next writer removes it.

    Parameters
    ----------
    directory : Path
        The temporary directory.
    fd : int
        Its lock file's descriptor.
    """
    shutil.rmtree(directory, ignore_errors=True)
    os.close(fd)


def is_partial(path: Path) -> bool:
    """Whether ``path``'s name is a temporary name of tmem's (:func:`partial_name`, or
    :func:`make_partial`'s name while it makes one).

    Parameters
    ----------
    path : Path
        The entry; only its name is read.
    """
    return _PARTIAL.fullmatch(path.name) is not None


def is_leftover(path: Path) -> bool:
    """Whether ``path`` is a temporary directory of tmem's whose writer is gone: nobody holds its lock.

    Parameters
    ----------
    path : Path
        The entry to judge: its name must be a temporary name, and it must hold the lock file
        :data:`WRITING`, not empty (its writer writes into it only once it holds the lock), which
        this process can lock (and at once lets go).
    """
    if not is_partial(path):
        return False
    fd = -1
    for mode in (os.O_RDWR, os.O_RDONLY):  # writable where it can be: NFS locks a file only so
        try:
            fd = os.open(path / WRITING, mode | os.O_NOFOLLOW | os.O_NONBLOCK)
            break
        except PermissionError:
            continue
        except OSError:  # no lock file (an earlier tmem's, a file): not known to be dead
            return False
    if fd < 0:
        return False
    try:
        return os.fstat(fd).st_size > 0 and _lock(fd, block=False)
    finally:
        os.close(fd)


def remove_leftovers(folder: Path, everything: bool = False) -> list[Path]:
    """Remove from ``folder`` (not below it) what killed tmem processes left; return what was removed.

    Parameters
    ----------
    folder : Path
        The folder to clean; one that cannot be listed is left as it is.
    everything : bool
        Remove every temporary name, whatever its lock says: only for a caller holding a lock
        that no other writer of ``folder`` can hold meanwhile (a sweep's, in its directory).
    """
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        path = Path(entry.path)
        if not (is_partial(path) if everything else is_leftover(path)):
            continue
        try:
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
            else:
                path.unlink()
            removed.append(path)
        except OSError:
            continue  # another process removing it too, or no permission: leave it
    return removed


def beside(run_dir: str | Path, suffix: str) -> Path:
    """``NAME`` + ``suffix`` in the folder holding the run directory ``NAME``: where derived files go by default.

    Beside the run, never inside: a file added to a run directory would make ``tmem run`` refuse
    to replace it (:mod:`tmem.files.outputs`).  A run given by its ``trajectory.nc`` counts as its folder.

    Parameters
    ----------
    run_dir : str or Path
        The run directory, or its ``trajectory.nc``.
    suffix : str
        Appended to the run's name: ``".html"``, ``".gif"``, ``"-crazyswarm"``.
    """
    run_dir = Path(run_dir)
    if run_dir.suffix == ".nc":
        run_dir = run_dir.parent
    resolved = run_dir.absolute().resolve()
    return resolved.parent / f"{resolved.name or 'run'}{suffix}"


def one_line(text: str) -> str:
    """``text`` as one printable line: each control or invisible character escaped as Python writes
    it in a string (a newline as ``\\n``, an escape as ``\\x1b``); other text, accents included, as it is.

    Parameters
    ----------
    text : str
        A message, or a name (a path, an agent's) put into one.
    """
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape", "backslashreplace").decode("ascii") for c in text)


def missing_parents(out: Path) -> list[Path]:
    """The folders above ``out`` that do not exist, outermost first: those a writer makes, and removes
    again if it fails (:func:`remove_made`).

    Parameters
    ----------
    out : Path
        The destination.
    """
    return [p for p in reversed(out.absolute().parents) if not p.exists()]


def remove_made(directories: list[Path]) -> None:
    """Remove the folders of :func:`missing_parents` again, innermost first, while they are empty.  Never raises.

    Parameters
    ----------
    directories : list of Path
        The folders made.
    """
    for directory in reversed(directories):
        try:
            directory.rmdir()
        except OSError:
            return


class OneLineError(ValueError):
    """An error whose message is one printable line: control characters in it escaped (:func:`one_line`).

    Parameters
    ----------
    message : str
        What is wrong; a newline or an escape sequence in it (from a path, a name) is written as ``\\n``, ``\\x1b``.
    """

    def __init__(self, message: str) -> None:
        super().__init__(one_line(str(message)))


def _too_long(path: Path) -> str | None:
    """The first component of ``path`` longer than file systems allow (255 bytes), if any."""
    for part in path.parts:
        if len(os.fsencode(part)) > _NAME_MAX:
            return part
    return None
