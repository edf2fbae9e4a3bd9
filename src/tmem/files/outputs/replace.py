"""Atomic replacement: output directories and files written under a temporary name, renamed into place when complete."""

from __future__ import annotations

import errno
import os
import shutil
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from tmem.files.outputs.manifest import MANIFEST, OutputError, _cannot_write, _write_manifest, _write_manifest_file, check_directory
from tmem.files.outputs.names import _NAME_MAX, _too_long, partial_name, remove_leftovers
from tmem.files.outputs.signals import _signals_held

#: The mark of a file written by ``tmem animate`` (a GIF comment, MP4 metadata).
ANIMATE_MARK = "written by tmem animate"


# --------------------------------------------------------------------------------------------
# Directories


def _missing_parents(out: Path) -> list[Path]:
    return [p for p in reversed(out.absolute().parents) if not p.exists()]


def _remove_made(directories: list[Path]) -> None:
    for directory in reversed(directories):
        try:
            directory.rmdir()
        except OSError:
            return


def _new_partial_directory(out: Path) -> Path:
    while True:
        tmp = out.parent / partial_name(out.name)
        try:
            tmp.mkdir()  # with the umask's permissions, like any directory the user makes
            return tmp
        except FileExistsError:
            continue


@contextmanager
def replace_directory(out: str | Path, command: str) -> Iterator[Path]:
    """Yield a temporary directory that becomes ``out`` only if the block completes.

    ``out`` is checked first (:func:`check_directory`) and again just before
    it is replaced.  On success the manifest listing every file written is
    added and the temporary directory takes ``out``'s place; on any error or
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
    tmp, missing = _partial_beside(out)
    try:
        yield tmp
        _write_manifest(tmp, command)
        with _signals_held():
            check_directory(out, command)  # what was there may have changed while we worked
            old = None
            if out.exists():
                old = out.parent / partial_name(out.name)
                out.rename(old)
            tmp.rename(out)
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_made(missing)
        if isinstance(exc, OSError):
            raise _cannot_write(out, exc) from None
        raise


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
    tmp, missing = _partial_beside(out)
    try:
        yield tmp
        _write_manifest(tmp, command, listed=False)
        with _signals_held():
            try:
                tmp.rename(out)  # onto an empty directory too, atomically
            except OSError as exc:
                if exc.errno in (errno.ENOTEMPTY, errno.EEXIST):
                    raise FileExistsError(errno.EEXIST, "filled meanwhile", str(out)) from None
                raise
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_made(missing)
        if isinstance(exc, OSError) and not isinstance(exc, FileExistsError):
            raise _cannot_write(out, exc) from None
        raise


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
    """Call ``write(tmp)`` for a temporary path beside ``path`` (same suffix), then rename it to ``path``.

    Parameters
    ----------
    path : Path
        The file to write; its folder must exist.
    write : callable
        ``write(tmp)`` writes the whole file at ``tmp``; what it returns is
        ignored.  If it raises, ``path`` is left as it was.
    """
    tmp = path.with_name(partial_name(path.name, path.suffix))
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _has_mark(path: Path, mark: bytes) -> bool:
    """Whether ``mark`` is in the first 64 KiB or the last 1 MiB of ``path`` (GIF comment, MP4 metadata)."""
    try:
        with path.open("rb") as f:
            head = f.read(1 << 16)
            f.seek(max(0, path.stat().st_size - (1 << 20)))
            tail = f.read()
    except OSError:
        return False
    return mark in head or mark in tail


def check_file(out: str | Path, mark: str = ANIMATE_MARK, label: str = "--out ") -> Path:
    """Refuse a file ``out`` that may not be written: a directory, a link, or a file without ``mark``; return it.

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
    if out.exists() and not _has_mark(out, mark.encode()):
        raise OutputError(f"{where}: exists and was not {mark}; choose another --out or remove it")
    return out


@contextmanager
def replace_file(out: str | Path, mark: str = ANIMATE_MARK, label: str = "--out ") -> Iterator[Path]:
    """Yield a temporary path (with ``out``'s suffix) that becomes ``out`` only if the block completes.

    ``out`` is checked first (:func:`check_file`) and again just before it is
    replaced; on any error or interruption the temporary file is removed,
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
    missing = _missing_parents(out)
    tmp = out.with_name(partial_name(out.name, out.suffix))
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_leftovers(out.parent)
        yield tmp
        with _signals_held():
            check_file(out, mark, label)
            os.replace(tmp, out)
    except BaseException as exc:
        tmp.unlink(missing_ok=True)
        _remove_made(missing)
        if isinstance(exc, OSError):
            raise OutputError(f"{label}{out}: cannot be written ({exc.strerror or exc})") from None
        raise


def _partial_beside(out: Path) -> tuple[Path, list[Path]]:
    """A new partial directory beside ``out`` (its parents made as needed, dead writers' leftovers
    removed), and the parents that had to be made, to remove again if the writing fails."""
    missing = _missing_parents(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_leftovers(out.parent)
        return _new_partial_directory(out), missing
    except OSError as exc:
        _remove_made(missing)
        raise _cannot_write(out, exc) from None
