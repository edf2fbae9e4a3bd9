"""The manifest, and the rule for which output directory a command may write (see :mod:`tmem.files.outputs`).

Each command marks the directory it writes with ``.tmem-output.json``
(:data:`MANIFEST`); :func:`check_directory` reads it and refuses, in one line
(:class:`OutputError`), a directory the command may not write to.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from tmem import __version__
from tmem.files.outputs.names import _NAME_MAX, _too_long, is_leftover

#: The manifest every command writes into its output directory.
MANIFEST = ".tmem-output.json"
#: The lock file of a directory being written by a long command (a sweep).
LOCK = ".tmem-lock"
#: Commands that write output directories, as their manifests name them.
COMMANDS = ("run", "paper", "sweep", "plot", "export")
#: Entries of an output directory that are tmem's bookkeeping, not its products.
_BOOKKEEPING = frozenset({MANIFEST, LOCK})
#: The largest manifest read (bytes).
_MANIFEST_MAX = 1 << 20
#: Names shown in a message before "and N more".
_SHOWN = 6


class OutputError(ValueError):
    """An output that cannot be written; the message is one line."""


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
    """What ``directory`` holds, for a one-line message: ``a `tmem paper` output (fig5/, …)``.

    Parameters
    ----------
    directory : Path
        An existing directory.
    """
    entries = _top_entries(directory)
    manifest = _read_manifest(directory)
    if manifest is None:
        return f"files that are not marked as a tmem output ({_listing(entries)})"
    return f"a `tmem {manifest.command}` output ({_listing(entries)})"


def _refuse(out: Path, why: str) -> OutputError:
    return OutputError(f"--out {out}: {why}")


def check_directory(out: str | Path, command: str, adopt: Callable[[Path], bool] | None = None) -> Path:
    """Refuse an ``out`` that ``command`` may not write to (the rule in :mod:`tmem.files.outputs`); return it.

    Reads only; writes nothing.  For ``sweep``, a directory holding a sweep's
    output passes: whether it is the same sweep is for the sweep's store to say.

    Parameters
    ----------
    out : str or Path
        The output directory (``--out``).
    command : str
        The command that would write it: ``"run"``, ``"paper"`` or ``"sweep"``.
    adopt : callable, optional
        ``adopt(out) -> bool``: may accept an existing directory without a
        manifest that the command recognises as its own (a sweep's, cut
        short).  None: no such directory is accepted.

    Raises
    ------
    OutputError
        If ``command`` may not write to ``out``, in one line saying why.
    """
    out = Path(out)
    try:
        return _check_directory(out, command, adopt)
    except OutputError:
        raise
    except OSError as exc:  # a name too long, a folder that cannot be searched
        raise _refuse(out, f"cannot be used ({exc.strerror or exc})") from None


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


def _cannot_write(out: Path, exc: OSError) -> OutputError:
    return _refuse(out, f"cannot be written ({exc.strerror or exc})")


def _write_manifest_file(path: Path, command: str) -> None:
    data = {"command": command, "tmem": __version__, "files": None}
    path.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
