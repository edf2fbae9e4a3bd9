"""What tmem wrote, by content: the SHA-256 of each file of an output, kept in its manifest.

A command replaces or removes a file of an output only while its content is still what tmem wrote
(:func:`unchanged`): a file the user edited since (notes in ``summary.json``, marks on
``velocity.png``) is refused by name, and nothing is changed.  The manifest keeps each file's
digest under ``sha256`` (:func:`record`).

A manifest of an earlier tmem keeps no digests.  Its files count as tmem's while none was modified
after the manifest was written: tmem writes the manifest last, so a file whose modification time is
later than the manifest's was changed since (an edit, a copy over it).  A file changed and given
back an older time (``touch -d``, ``cp -p`` of another file) cannot be told; the first command
that writes such an output again records the digests of the files it keeps.
"""

from __future__ import annotations

import errno
import hashlib
import os
import stat
from pathlib import Path

__all__ = ["NotRegularError", "file_digest", "read_regular", "record", "unchanged"]

#: Bytes read at a time while hashing.
_CHUNK = 1 << 20


class NotRegularError(ValueError):
    """A file that is not read: not a regular file (a FIFO, a device, a link), or larger than allowed."""


def read_regular(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, if it holds at most ``limit`` of them.

    A symbolic link is not followed and a FIFO or a device is never read (opening does not wait
    for a writer); a file growing past ``limit`` while it is read is refused too.

    Parameters
    ----------
    path : Path
        The file.
    limit : int
        The most bytes read.

    Raises
    ------
    NotRegularError
        Not a regular file, or more than ``limit`` bytes; the message says which.
    OSError
        If it cannot be opened or read (no such file included).
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise NotRegularError("is a symbolic link") from None
        raise
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise NotRegularError("is not a regular file (a FIFO, a device or a socket)")
        data = f.read(limit + 1) if info.st_size <= limit else b""
    if info.st_size > limit or len(data) > limit:
        raise NotRegularError(f"is larger than {limit} bytes")
    return data


def file_digest(path: Path) -> str | None:
    """The SHA-256 of the regular file at ``path`` (hexadecimal); None for anything else.

    A symbolic link is not followed, and a FIFO or a device is never opened: only a regular file
    is read, to its end (its size is what it holds).

    Parameters
    ----------
    path : Path
        The file.

    Raises
    ------
    OSError
        If a regular file cannot be read.
    """
    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return None
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except FileNotFoundError:
        return None
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # swapped for something else meanwhile
            return None
        sha = hashlib.sha256()
        while chunk := f.read(_CHUNK):
            sha.update(chunk)
    return sha.hexdigest()


def record(directory: Path, names: list[str]) -> dict[str, str]:
    """The digest of each regular file among ``names`` (paths relative to ``directory``), by name.

    Parameters
    ----------
    directory : Path
        The folder the names are relative to.
    names : list of str
        The files; folders (named with a final ``/``) and what is not a regular file are left out.
    """
    found = {}
    for name in names:
        if not name.endswith("/"):
            value = file_digest(directory / name)
            if value is not None:
                found[name] = value
    return found


def unchanged(path: Path, recorded: str | None, written_ns: int | None) -> bool:
    """Whether ``path`` is still as tmem wrote it, so that it may be replaced or removed.

    Parameters
    ----------
    path : Path
        A file an output's manifest lists.  One that is gone is unchanged: there is nothing to lose.
    recorded : str or None
        Its digest in the manifest; None when the manifest keeps none for it.
    written_ns : int or None
        For a manifest of an earlier tmem (no digests): when the manifest was last modified (ns
        since the epoch); the file must not have been modified later.  None: a manifest with
        digests, in which a file without one is not tmem's.
    """
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return True
    if recorded is not None:
        return file_digest(path) == recorded
    return written_ns is not None and stat.S_ISREG(info.st_mode) and info.st_mtime_ns <= written_ns
