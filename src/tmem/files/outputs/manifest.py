"""The manifest, and the rule for which output directory a command may write (see :mod:`tmem.files.outputs`).

Each command marks the directory it writes with ``.tmem-output.json``
(:data:`MANIFEST`); :func:`check_directory` reads it and refuses, in one line
(:class:`OutputError`), a directory the command may not write to.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from tmem import __version__
from tmem.files.outputs.digests import read_regular, record, unchanged
from tmem.files.outputs.names import _NAME_MAX, WRITING, OneLineError, _too_long, is_leftover, one_line

#: The manifest every command writes into its output directory.
MANIFEST = ".tmem-output.json"
#: The lock file of a directory being written by a long command (a sweep).
LOCK = ".tmem-lock"
#: Commands that write output directories, as their manifests name them.
COMMANDS = ("run", "paper", "sweep", "plot", "export")
#: Entries of an output directory that are tmem's bookkeeping, not its products.
_BOOKKEEPING = frozenset({MANIFEST, LOCK, WRITING})
#: The largest manifest read (bytes).
_MANIFEST_MAX = 1 << 20
#: Names shown in a message before "and N more".
_SHOWN = 6
_SHA256 = re.compile(r"[0-9a-f]{64}")


class OutputError(OneLineError):
    """An output that cannot be written; the message is one line (control characters escaped).

    Parameters
    ----------
    message : str
        What is wrong.
    """


@dataclass(frozen=True)
class Manifest:
    """What ``.tmem-output.json`` says: the command that wrote the directory, the files it wrote, their digests.

    Attributes
    ----------
    command : str
        The command, one of :data:`COMMANDS`.
    files : frozenset of str or None
        The files it wrote, as paths relative to the directory; None: the command does not list
        them (a sweep's directory grows).
    digests : dict of str to str or None
        The SHA-256 of each file as written (:mod:`tmem.files.outputs.digests`); None in a
        manifest of an earlier tmem, which keeps none.
    written_ns : int or None
        For such a manifest, when it was last modified (ns since the epoch); else None.
    """

    command: str
    files: frozenset[str] | None
    digests: dict[str, str] | None = None
    written_ns: int | None = None


def _listing(names: list[str]) -> str:
    shown = [one_line(n) for n in names[:_SHOWN]]
    more = len(names) - len(shown)
    return ", ".join(shown) + (f" and {more} more" if more > 0 else "")


def _parse_manifest(data: dict, info: os.stat_result) -> Manifest:
    command = data["command"]
    files = data.get("files")
    digests = data.get("sha256")
    if command not in COMMANDS:
        raise ValueError
    if files is not None:
        if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
            raise ValueError
        files = frozenset(files)
    if "sha256" not in data:  # an earlier tmem's: no digests, judged by the manifest's time
        return Manifest(command, files, None, info.st_mtime_ns)
    if not isinstance(digests, dict) or not all(isinstance(k, str) and isinstance(v, str) and _SHA256.fullmatch(v)
                                                for k, v in digests.items()):  # fmt: skip
        raise ValueError
    return Manifest(command, files, dict(digests), None)


def _read_manifest(directory: Path) -> Manifest | None:
    """The directory's manifest; a sweep directory of an earlier tmem, marked by ``sweep.json``, counts."""
    path = directory / MANIFEST
    if not path.exists() and not path.is_symlink():
        if (directory / "sweep.json").is_file():
            return Manifest("sweep", None)
        return None
    try:
        data = read_regular(path, _MANIFEST_MAX)
        return _parse_manifest(json.loads(data.decode("utf-8")), os.lstat(path))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        raise _refuse(directory, f"its {MANIFEST} cannot be read; choose another --out or remove it") from None


def changed_files(directory: Path, manifest: Manifest, names: frozenset[str] | list[str], prefix: str = "") -> list[str]:
    """Those of ``names`` (in ``directory``) that are no longer as tmem wrote them, as the manifest lists them.

    Parameters
    ----------
    directory : Path
        The folder the names are in.
    manifest : Manifest
        The manifest listing them, under ``prefix + name``.
    names : collection of str
        The files to judge (paths relative to ``directory``); folders (a final ``/``) are skipped.
    prefix : str
        Put before each name in the manifest (``"fig9/"`` for a run of a paper's output).
    """
    digests = manifest.digests or {}
    return sorted(
        name for name in names
        if not name.endswith("/") and not unchanged(directory / name, digests.get(prefix + name), manifest.written_ns)
    )  # fmt: skip


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
        if manifest.files is None:  # a sweep's: what it will replace (its report) must still be as written
            others, edited = [], changed_files(out, manifest, list(manifest.digests or ()))
        else:
            others = sorted(f for f in _files_below(out) if f not in manifest.files)
            edited = [] if others else changed_files(out, manifest, manifest.files)
    except OSError as exc:
        raise _refuse(out, f"cannot be read ({exc.strerror or exc})") from None
    for found, what in ((others, "and files it did not write"), (edited, "whose files were changed since it wrote them")):
        if found:
            raise _refuse(out, f"holds a `tmem {command}` output {what} ({_listing(found)}); choose another --out, or move them out first")
    return out


def manifest_text(command: str, files: list[str] | None, digests: dict[str, str]) -> str:
    """The text of a manifest: the command, tmem's version, the files (or None) and their digests.

    Parameters
    ----------
    command : str
        The command that wrote the directory, one of :data:`COMMANDS`.
    files : list of str or None
        The files it wrote; None for a directory that grows (a sweep's).
    digests : dict of str to str
        The SHA-256 of each file it wrote that it may replace (:func:`tmem.files.outputs.digests.record`).
    """
    data = {"command": command, "tmem": __version__, "files": None if files is None else sorted(files),
            "sha256": dict(sorted(digests.items()))}  # fmt: skip
    return json.dumps(data, indent=1) + "\n"


def _write_manifest(directory: Path, command: str, listed: bool = True) -> None:
    files = sorted(_files_below(directory)) if listed else None
    text = manifest_text(command, files, record(directory, files or []))
    (directory / MANIFEST).write_text(text, encoding="utf-8")


def _cannot_write(out: Path, exc: OSError) -> OutputError:
    return _refuse(out, f"cannot be written ({exc.strerror or exc})")


def _write_manifest_file(path: Path, command: str) -> None:
    path.write_text(manifest_text(command, None, {}), encoding="utf-8")
