"""Output directories and files: when tmem may write or replace them, and how it survives interruptions.

Every command that writes (``tmem run``, ``tmem paper``, ``tmem animate``,
``tmem sweep``) goes through this module.

The rule for output directories
-------------------------------
Each command marks the directory it writes with ``.tmem-output.json``, a
manifest naming the command and (for ``run`` and ``paper``) every file it
wrote.  A command writes to ``--out DIR`` only when:

1. DIR does not exist, or is empty: it is created;
2. DIR holds an output of the *same* command (its manifest names that
   command) and nothing the manifest does not list: ``tmem run`` and
   ``tmem paper`` replace it whole; ``tmem sweep`` resumes it, and only if it
   holds the same sweep (it never replaces one).

Anything else is refused with one line that says what is there: another
command's output, an output with files added to it (an ``animation.gif``
that ``tmem animate`` wrote into a run directory, a note of the user's),
files that are not marked as a tmem output.  Files added to an output are
never deleted and never carried over: rerunning into a run directory that
holds an animation is refused, since the animation would no longer show the
run.  The current directory and the directories containing it, symbolic
links and files are never output directories, for any command.  ``tmem
animate`` replaces an existing file only if it wrote it (its GIFs carry the
comment ``written by tmem animate``, its MP4s the same metadata).

Interruptions
-------------
A directory or file is written under a hidden temporary name next to its
destination, ``.NAME.tmem-partial-PID-RANDOM`` (PID: the writing process),
and renamed into place only when complete; the old output is moved aside and
removed in the same step, with Ctrl-C and SIGTERM held back until it is done.
So Ctrl-C, SIGTERM (handled like Ctrl-C: :func:`handle_termination`) or an
error leave the destination as it was.  A process killed outright (SIGKILL,
power cut) leaves its temporary name behind; the next command writing into
the same folder recognises it by the name and by its process being gone from
this machine, and removes it (:func:`remove_leftovers`).  Nothing else is ever
removed: a name that does not match exactly, or whose process still runs, is
left alone.

Two commands at once
--------------------
A sweep, which writes into its directory for a long time, holds
``.tmem-lock`` there (:func:`lock`): a lock held by the operating system for
as long as the process lives, with the holder's process id written in it.  A
second sweep into the same directory is refused in one line naming that
process; once the holder ends, even killed, the next one takes the lock.
"""

from __future__ import annotations

import errno
import json
import os
import re
import secrets
import shutil
import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from . import __version__

#: The manifest every command writes into its output directory.
MANIFEST = ".tmem-output.json"
#: The lock file of a directory being written by a long command (a sweep).
LOCK = ".tmem-lock"
#: The mark of a file written by ``tmem animate`` (a GIF comment, MP4 metadata).
ANIMATE_MARK = "written by tmem animate"
#: Commands that write output directories, as their manifests name them.
COMMANDS = ("run", "paper", "sweep")

#: Bytes of the destination's name kept in a temporary name (names stay under 255 bytes).
_NAME_KEPT = 180
#: The longest name of a file or folder (bytes) on common file systems.
_NAME_MAX = 255
_PARTIAL = re.compile(r"\.(?P<name>.*)\.tmem-partial-(?P<pid>[0-9]{1,10})-(?P<tag>[0-9a-f]{8})(?:\.[A-Za-z0-9]{1,10})?", re.S)
#: Entries of an output directory that are tmem's bookkeeping, not its products.
_BOOKKEEPING = frozenset({MANIFEST, LOCK})
#: The largest manifest read (bytes).
_MANIFEST_MAX = 1 << 20
#: Names shown in a message before "and N more".
_SHOWN = 6


class OutputError(ValueError):
    """An output that cannot be written; the message is one line."""


# --------------------------------------------------------------------------------------------
# Temporary names and what killed processes left


def partial_name(name: str, suffix: str = "") -> str:
    """A hidden temporary name for ``name`` in the same folder, owned by this process.

    ``suffix`` (such as ``.gif``) is kept at the end so that writers which
    choose the format by the suffix still do.
    """
    kept = os.fsdecode(os.fsencode(name)[:_NAME_KEPT])
    return f".{kept}.tmem-partial-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def _partial_owner(name: str) -> int | None:
    """The process id in a temporary name of tmem's, or None for any other name."""
    match = _PARTIAL.fullmatch(name)
    return int(match["pid"]) if match else None


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine (a zombie counts as alive)."""
    if pid == os.getpid():
        return True
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # someone else's process
    except (OverflowError, OSError):
        return False
    return True


def is_leftover(path: Path) -> bool:
    """Whether ``path`` is a temporary file or directory of a tmem process that is gone."""
    pid = _partial_owner(path.name)
    return pid is not None and not _alive(pid)


def remove_leftovers(folder: Path) -> list[Path]:
    """Remove from ``folder`` (not below it) what killed tmem processes left; return what was removed."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        path = Path(entry.path)
        if not is_leftover(path):
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


# --------------------------------------------------------------------------------------------
# Signals


def _raise_interrupt(signum: int, frame) -> None:
    raise KeyboardInterrupt


def handle_termination() -> None:
    """Handle SIGTERM (and SIGHUP) as Ctrl-C: raise :class:`KeyboardInterrupt` in the main thread.

    A signal the parent process set to be ignored (``nohup``) stays ignored.
    Called by the ``tmem`` command before it runs; only the main thread can.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    for name in ("SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is not None and signal.getsignal(signum) is not signal.SIG_IGN:
            signal.signal(signum, _raise_interrupt)


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


# --------------------------------------------------------------------------------------------
# What a directory holds


@dataclass(frozen=True)
class Manifest:
    """What ``.tmem-output.json`` says: the command that wrote the directory and the files it wrote."""

    command: str
    files: frozenset[str] | None  # None: the command does not list them (a sweep grows)


def _show(name: str) -> str:
    """A name as one printable line."""
    return name if name.isprintable() else ascii(name)[1:-1]


def _listing(names: list[str]) -> str:
    shown = [_show(n) for n in names[:_SHOWN]]
    more = len(names) - len(shown)
    return ", ".join(shown) + (f" and {more} more" if more > 0 else "")


def _read_manifest(directory: Path) -> Manifest | None:
    """The directory's manifest; a sweep directory of an earlier tmem, marked by ``sweep.json``, counts."""
    path = directory / MANIFEST
    if not path.exists() and not path.is_symlink():
        if (directory / "sweep.json").is_file():
            return Manifest("sweep", None)
        return None
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size > _MANIFEST_MAX:
            raise ValueError  # a FIFO, a device, or too big to be ours: not read
        data = json.loads(path.read_text(encoding="utf-8"))
        command = data["command"]
        files = data.get("files")
        if command not in COMMANDS:
            raise ValueError
        if files is not None:
            if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
                raise ValueError
            files = frozenset(files)
    except (OSError, ValueError, KeyError, TypeError):
        raise _refuse(directory, f"its {MANIFEST} cannot be read; choose another --out or remove it") from None
    return Manifest(command, files)


def _top_entries(directory: Path) -> list[str]:
    """The entries of ``directory`` a user sees: no bookkeeping, no leftovers; folders with a slash."""
    names = []
    for entry in sorted(os.scandir(directory), key=lambda e: e.name):
        if entry.name in _BOOKKEEPING or is_leftover(Path(entry.path)):
            continue
        names.append(entry.name + ("/" if entry.is_dir(follow_symlinks=False) else ""))
    return names


def _files_below(directory: Path, prefix: str = "") -> Iterator[str]:
    """Every non-directory below ``directory`` as a relative path (symbolic links included, not followed)."""
    for entry in os.scandir(directory):
        relative = prefix + entry.name
        if not prefix and entry.name in _BOOKKEEPING:
            continue
        if is_leftover(Path(entry.path)):
            continue
        if entry.is_dir(follow_symlinks=False):
            inside = list(_files_below(Path(entry.path), relative + "/"))
            yield from inside if inside else [relative + "/"]  # an empty folder is something too
        else:
            yield relative


def describe(directory: Path) -> str:
    """What ``directory`` holds, for a one-line message: ``a `tmem paper` output (fig5/, …)``."""
    entries = _top_entries(directory)
    manifest = _read_manifest(directory)
    if manifest is None:
        return f"files that are not marked as a tmem output ({_listing(entries)})"
    return f"a `tmem {manifest.command}` output ({_listing(entries)})"


def _refuse(out: Path, why: str) -> OutputError:
    return OutputError(f"--out {out}: {why}")


def check_directory(out: str | Path, command: str, adopt: Callable[[Path], bool] | None = None) -> Path:
    """Refuse an ``out`` that ``command`` may not write to (the rule in the module docstring); return it.

    Reads only; writes nothing.  For ``sweep``, a directory holding a sweep's
    output passes: whether it is the same sweep is for the sweep's store to say.
    ``adopt(out)``, if given, may accept an existing directory without a
    manifest that the command recognises as its own (a sweep's, cut short).
    """
    out = Path(out)
    try:
        return _check_directory(out, command, adopt)
    except OutputError:
        raise
    except OSError as exc:  # a name too long, a folder that cannot be searched
        raise _refuse(out, f"cannot be used ({exc.strerror or exc})") from None


def _too_long(path: Path) -> str | None:
    """The first component of ``path`` longer than file systems allow (255 bytes), if any."""
    for part in path.parts:
        if len(os.fsencode(part)) > _NAME_MAX:
            return part
    return None


def _check_directory(out: Path, command: str, adopt: Callable[[Path], bool] | None) -> Path:
    if _too_long(out):
        raise _refuse(out, f"has a name longer than {_NAME_MAX} bytes")
    if out.is_symlink():
        raise _refuse(out, "is a symbolic link; give the directory itself")
    if out.exists() and not out.is_dir():
        raise _refuse(out, "exists and is not a directory")
    try:
        resolved = out.resolve()
        here = Path.cwd().resolve()
    except (OSError, RuntimeError) as exc:
        raise _refuse(out, f"cannot be resolved ({getattr(exc, 'strerror', None) or exc})") from None
    if resolved == here or resolved in here.parents:
        raise _refuse(out, "is the current directory or contains it; give a new subdirectory")
    for parent in resolved.parents:
        if parent.exists() and not parent.is_dir():
            raise _refuse(out, f"{parent} is a file, not a directory")
    if not out.is_dir():
        return out
    try:
        if not _top_entries(out) and not (out / MANIFEST).exists():
            return out  # empty, or only tmem's leftovers
        manifest = _read_manifest(out)
        if manifest is None and adopt is not None and adopt(out):
            return out
        if manifest is None or manifest.command != command:
            raise _refuse(out, f"holds {describe(out)}; choose another --out or remove it")
        if manifest.files is None:
            return out
        others = sorted(f for f in _files_below(out) if f not in manifest.files)
    except OSError as exc:
        raise _refuse(out, f"cannot be read ({exc.strerror or exc})") from None
    if others:
        raise _refuse(
            out,
            f"holds a `tmem {command}` output and files it did not write ({_listing(others)}); "
            "choose another --out, or move them out first",
        )
    return out


def _write_manifest(directory: Path, command: str, listed: bool = True) -> None:
    files = sorted(_files_below(directory)) if listed else None
    data = {"command": command, "tmem": __version__, "files": files}
    (directory / MANIFEST).write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")


def _missing_parents(out: Path) -> list[Path]:
    return [p for p in reversed(out.absolute().parents) if not p.exists()]


def _remove_made(directories: list[Path]) -> None:
    for directory in reversed(directories):
        try:
            directory.rmdir()
        except OSError:
            return


def _cannot_write(out: Path, exc: OSError) -> OutputError:
    return _refuse(out, f"cannot be written ({exc.strerror or exc})")


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
    """
    out = check_directory(out, command)
    missing = _missing_parents(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_leftovers(out.parent)
        tmp = _new_partial_directory(out)
    except OSError as exc:
        _remove_made(missing)
        raise _cannot_write(out, exc) from None
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
    """
    missing = _missing_parents(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_leftovers(out.parent)
        tmp = _new_partial_directory(out)
    except OSError as exc:
        _remove_made(missing)
        raise _cannot_write(out, exc) from None
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
    """Write the manifest of a directory written in place (a sweep's, recovered)."""
    write_atomically(directory / MANIFEST, lambda tmp: _write_manifest_file(tmp, command))


def _write_manifest_file(path: Path, command: str) -> None:
    data = {"command": command, "tmem": __version__, "files": None}
    path.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")


# --------------------------------------------------------------------------------------------
# Files


def write_atomically(path: Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp)`` for a temporary path beside ``path`` (same suffix), then rename it to ``path``."""
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
    """Refuse a file ``out`` that may not be written: a directory, a link, or a file without ``mark``."""
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
        raise OutputError(f"{where}: exists and was not written by tmem animate; choose another --out or remove it")
    return out


@contextmanager
def replace_file(out: str | Path, mark: str = ANIMATE_MARK, label: str = "--out ") -> Iterator[Path]:
    """Yield a temporary path (with ``out``'s suffix) that becomes ``out`` only if the block completes."""
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


# --------------------------------------------------------------------------------------------
# Locks


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
