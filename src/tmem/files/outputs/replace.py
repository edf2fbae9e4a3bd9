"""Atomic replacement: output directories and files written in a temporary directory, renamed into place when complete.

Every temporary directory is held by its writer's lock while it is written
(:func:`tmem.files.outputs.names.make_partial`), so that no other tmem takes it for a leftover.
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from tmem.files.outputs.manifest import MANIFEST, OutputError, _cannot_write, _write_manifest, _write_manifest_file, check_directory
from tmem.files.outputs.names import (
    _NAME_MAX, _too_long, discard, make_partial, missing_parents, release, remove_leftovers, remove_made,
)  # fmt: skip
from tmem.files.outputs.signals import _signals_held

#: The mark of a file written by ``tmem animate`` (a GIF comment, MP4 metadata).
ANIMATE_MARK = "written by tmem animate"
#: Bytes read from the start and from the end of an existing file, looking for a mark.
_HEAD, _TAIL = 1 << 16, 1 << 20


# --------------------------------------------------------------------------------------------
# Directories


@contextmanager
def _partial_beside(out: Path) -> Iterator[Path]:
    """A new temporary directory beside ``out``, held for the block (parents made as needed, dead
    writers' leftovers removed); on an error or an interruption it is removed, with the parents made.
    The block may rename it to ``out``; whatever it leaves at the temporary name is removed."""
    made = missing_parents(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_leftovers(out.parent)
        tmp, fd = make_partial(out.parent, out.name)
    except OSError as exc:
        remove_made(made)
        raise _cannot_write(out, exc) from None
    try:
        yield tmp
    except BaseException:
        discard(tmp, fd)
        remove_made(made)
        raise
    if tmp.exists():
        discard(tmp, fd)
    else:  # renamed into place: its lock file goes
        release(out, fd)


def _swap(out: Path, tmp: Path) -> None:
    """Put ``tmp`` in ``out``'s place; the old ``out`` is moved into a held temporary directory and removed
    with it (a process killed meanwhile leaves that to the next writer).  If the swap fails, ``out`` stays."""
    bin_, fd = make_partial(out.parent, out.name)
    try:
        out.rename(bin_ / "old")
        try:
            tmp.rename(out)
        except BaseException:
            (bin_ / "old").rename(out)
            raise
    finally:
        discard(bin_, fd)


@contextmanager
def replace_directory(out: str | Path, command: str) -> Iterator[Path]:
    """Yield a temporary directory that becomes ``out`` only if the block completes.

    ``out`` is checked first (:func:`check_directory`) and again just before
    it is replaced.  On success the manifest listing every file written, with
    its digest, is added and the temporary directory takes ``out``'s place; on any error or
    interruption it is removed, with the parent directories made for it.
    File system errors become :class:`OutputError`.

    Parameters
    ----------
    out : str or Path
        The output directory (``--out``).
    command : str
        The command writing it, as its manifest names it: ``"run"`` or ``"paper"``.
    """
    out = check_directory(out, command)
    try:
        with _partial_beside(out) as tmp:
            yield tmp
            _write_manifest(tmp, command)
            with _signals_held():
                check_directory(out, command)  # what was there may have changed while we worked
                if out.exists():
                    _swap(out, tmp)
                else:
                    tmp.rename(out)
    except OSError as exc:
        raise _cannot_write(out, exc) from None


@contextmanager
def create_directory(out: Path, command: str) -> Iterator[Path]:
    """Yield a temporary directory that becomes the new ``out`` (absent or empty) when the block completes.

    For outputs that are written in place afterwards (a sweep): the block
    puts the first files into the temporary directory; together with the
    manifest (which lists no files) they appear at ``out`` at once.  Raises
    :class:`FileExistsError` if ``out`` was filled meanwhile.

    Parameters
    ----------
    out : Path
        The output directory, absent or empty (checked by the caller,
        :func:`~tmem.files.outputs.manifest.check_directory`).
    command : str
        The command writing it, as its manifest names it (``"sweep"``).
    """
    try:
        with _partial_beside(out) as tmp:
            yield tmp
            _write_manifest(tmp, command, listed=False)
            with _signals_held():
                try:
                    tmp.rename(out)  # onto an empty directory too, atomically
                except OSError as exc:
                    if exc.errno in (errno.ENOTEMPTY, errno.EEXIST):
                        raise FileExistsError(errno.EEXIST, "filled meanwhile", str(out)) from None
                    raise
    except FileExistsError:
        raise
    except OSError as exc:
        raise _cannot_write(out, exc) from None


def mark_directory(directory: Path, command: str) -> None:
    """Write the manifest of a directory written in place (a sweep's, recovered).

    Parameters
    ----------
    directory : Path
        The existing output directory; its manifest lists no files.
    command : str
        The command that wrote it, as the manifest names it (``"sweep"``).
    """
    write_atomically(directory / MANIFEST, lambda tmp: _write_manifest_file(tmp, command))

# --------------------------------------------------------------------------------------------
# Files


def write_atomically(path: Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp)`` for a temporary path (same name, in a held temporary directory beside ``path``), then rename it to ``path``.

    Parameters
    ----------
    path : Path
        The file to write; its folder must exist.
    write : callable
        ``write(tmp)`` writes the whole file at ``tmp``; what it returns is
        ignored.  If it raises, ``path`` is left as it was.
    """
    folder, fd = make_partial(path.parent, path.name)
    try:
        tmp = folder / path.name
        write(tmp)
        os.replace(tmp, path)
    finally:
        discard(folder, fd)


def _has_mark(path: Path, mark: bytes) -> bool:
    """Whether ``mark`` is in the first 64 KiB or the last 1 MiB of the regular file ``path`` (GIF comment, MP4 metadata)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return False
    with os.fdopen(fd, "rb") as f:
        size = os.fstat(fd)
        if not stat.S_ISREG(size.st_mode):
            return False
        head = f.read(_HEAD)
        f.seek(max(0, size.st_size - _TAIL))
        tail = f.read(_TAIL)
    return mark in head or mark in tail


def check_file(out: str | Path, mark: str = ANIMATE_MARK, label: str = "--out ") -> Path:
    """Refuse a file ``out`` that may not be written: a directory, a link, a FIFO or device, or a file without ``mark``; return it.

    Reads at most 64 KiB and 1 MiB of an existing regular file, and nothing of anything else.

    Parameters
    ----------
    out : str or Path
        The output file.
    mark : str
        The text an existing file must hold (in its first 64 KiB or last
        1 MiB) to be replaced: tmem wrote it.  It reads after "was not" in
        the message: ``"written by tmem animate"``.
    label : str
        Put before ``out`` in the message, such as ``"--out "``.

    Raises
    ------
    OutputError
        If ``out`` may not be written, in one line saying why.
    """
    out = Path(out)
    where = f"{label}{out}"
    try:
        return _check_file(out, mark, where)
    except OutputError:
        raise
    except OSError as exc:  # a name too long, a folder that cannot be searched
        raise OutputError(f"{where}: cannot be used ({exc.strerror or exc})") from None


def _check_file(out: Path, mark: str, where: str) -> Path:
    if _too_long(out):
        raise OutputError(f"{where}: has a name longer than {_NAME_MAX} bytes")
    if out.is_symlink():
        raise OutputError(f"{where}: is a symbolic link; give the file itself")
    if out.is_dir():
        raise OutputError(f"{where}: is a directory; name a file")
    for parent in out.absolute().parents:
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"{where}: {parent} is a file, not a directory")
    try:
        kind = os.lstat(out).st_mode
    except FileNotFoundError:
        return out
    if not stat.S_ISREG(kind):
        raise OutputError(f"{where}: exists and is not a regular file (a FIFO, a device or a socket); name a file")
    if not _has_mark(out, mark.encode()):
        raise OutputError(f"{where}: exists and was not {mark}; choose another --out or remove it")
    return out


@contextmanager
def replace_file(out: str | Path, mark: str = ANIMATE_MARK, label: str = "--out ") -> Iterator[Path]:
    """Yield a temporary path (``out``'s name, in a held temporary directory beside it) that becomes ``out``
    only if the block completes.

    ``out`` is checked first (:func:`check_file`) and again just before it is
    replaced; on any error or interruption the temporary directory is removed,
    with the parent directories made for it.

    Parameters
    ----------
    out : str or Path
        The output file.
    mark : str
        The text an existing ``out`` must hold to be replaced (:func:`check_file`).
    label : str
        Put before ``out`` in messages, such as ``"--out "``.
    """
    out = check_file(out, mark, label)
    try:
        with _partial_beside(out) as folder:
            yield folder / out.name
            with _signals_held():
                check_file(out, mark, label)
                os.replace(folder / out.name, out)
    except OSError as exc:
        raise OutputError(f"{label}{out}: cannot be written ({exc.strerror or exc})") from None
