"""Files written again into an existing output, all at once: the figures ``tmem plot`` draws into a run.

The files are written into a hidden temporary folder inside the directory; when all are complete,
they replace their namesakes together (Ctrl-C and SIGTERM held back meanwhile) and are added to the
manifest that lists the directory's files.  A namesake the manifest does not list was not written
by tmem (a file of the user's) and is never replaced: the update is refused before anything is
replaced.  Nothing else in the directory is touched.

The manifest is the directory's own (a ``tmem run`` output) or, for a run inside a ``tmem paper``
output, its parent's, which lists the run's files under the run's folder name.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tmem import __version__
from tmem.files.outputs.manifest import MANIFEST, OutputError, _read_manifest
from tmem.files.outputs.names import partial_name, remove_leftovers
from tmem.files.outputs.replace import write_atomically
from tmem.files.outputs.signals import _signals_held


def _manifest_of(directory: Path) -> tuple[Path, str, object] | None:
    """The manifest listing ``directory``'s files, the prefix of their names in it, and what it says."""
    own = _read_manifest(directory) if (directory / MANIFEST).is_file() else None
    if own is not None:
        return directory / MANIFEST, "", own
    parent = directory.resolve().parent
    prefix = directory.resolve().name + "/"
    above = _read_manifest(parent) if (parent / MANIFEST).is_file() else None
    if above is not None and above.files is not None and any(f.startswith(prefix) for f in above.files):
        return parent / MANIFEST, prefix, above
    return None


def _check_namesakes(directory: Path, names: list[str], listed: frozenset[str], prefix: str) -> None:
    """Refuse a namesake in ``directory`` that tmem did not write (not in the manifest), or that is not a file."""
    for name in names:
        target = directory / name
        if target.is_symlink() or (target.exists() and not target.is_file()):
            raise OutputError(f"{target}: is not a file; move it out first")
        if target.exists() and prefix + name not in listed:
            raise OutputError(f"{target}: exists and was not written by tmem; move it out first")


def _write_listing(path: Path, command: str, files: frozenset[str]) -> None:
    data = {"command": command, "tmem": __version__, "files": sorted(files)}
    write_atomically(path, lambda tmp: tmp.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8"))


@contextmanager
def update_files(directory: str | Path) -> Iterator[Path]:
    """Yield a temporary folder; the files written into it then replace their namesakes in ``directory``.

    Parameters
    ----------
    directory : str or Path
        An existing output directory (a run's).

    Raises
    ------
    OutputError
        In one line, before anything is replaced: a namesake that tmem did not write, or that is
        not a file; a directory that cannot be written.
    """
    directory = Path(directory)
    try:
        remove_leftovers(directory)
        tmp = directory / partial_name("figures")
        tmp.mkdir()
    except OSError as exc:
        raise OutputError(f"{directory}: cannot be written ({exc.strerror or exc})") from None
    try:
        yield tmp
        names = sorted(p.name for p in tmp.iterdir())
        found = _manifest_of(directory)
        listed = found[2].files if found is not None and found[2].files is not None else frozenset()
        prefix = found[1] if found is not None else ""
        _check_namesakes(directory, names, listed, prefix)
        with _signals_held():
            for name in names:
                os.replace(tmp / name, directory / name)
            if found is not None and found[2].files is not None:
                _write_listing(found[0], found[2].command, listed | {prefix + name for name in names})
    except OSError as exc:
        raise OutputError(f"{directory}: cannot be written ({exc.strerror or exc})") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
