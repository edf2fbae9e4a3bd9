"""Files written again into an existing output, all at once: the figures ``tmem plot`` draws into a run,
the report a sweep writes when its last case is in.

The files are written into a hidden temporary folder inside the directory (held by its writer's
lock); when all are complete, they replace their namesakes together (Ctrl-C and SIGTERM held back
meanwhile) and are added, with their digests, to the manifest that lists the directory's files.
A namesake is replaced only while it is still what tmem wrote: listed in the manifest, and with
the content its digest records (:mod:`tmem.files.outputs.digests`).  A file of the user's under a
figure's name, or a figure the user changed, is never replaced: the update is refused, naming it,
before anything is replaced.  Nothing else in the directory is touched.

The manifest is the directory's own (a ``tmem run`` output) or, for a run inside a ``tmem paper``
output, its parent's, which lists the run's files under the run's folder name.  A sweep's
manifest lists no files (its directory grows); the files of its report are tmem's when its digests
name them.  A sweep directory of an earlier tmem keeps no digests: its report's files are replaced
by name, as before.  A manifest of an
earlier tmem, without digests, is written again with the digests of the files it lists that are
still as tmem wrote them; a file it lists that was changed is no longer listed (it is the user's).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tmem.files.outputs.digests import record
from tmem.files.outputs.manifest import MANIFEST, Manifest, OutputError, _read_manifest, changed_files, manifest_text
from tmem.files.outputs.names import WRITING, discard, make_partial, remove_leftovers
from tmem.files.outputs.replace import write_atomically
from tmem.files.outputs.signals import _signals_held


def _manifest_of(directory: Path) -> tuple[Path, str, Manifest] | None:
    """The manifest listing ``directory``'s files, the prefix of their names in it, and what it says."""
    own = _read_manifest(directory) if (directory / MANIFEST).is_file() else None
    if own is not None:
        return directory, "", own
    parent = directory.resolve().parent
    prefix = directory.resolve().name + "/"
    above = _read_manifest(parent) if (parent / MANIFEST).is_file() else None
    if above is not None and above.files is not None and any(f.startswith(prefix) for f in above.files):
        return parent, prefix, above
    return None


def _check_namesakes(directory: Path, names: list[str], found: tuple[Path, str, Manifest] | None) -> None:
    """Refuse a namesake in ``directory`` that tmem did not write (not in the manifest), that was changed
    since, or that is not a file."""
    manifest = found[2] if found is not None else None
    prefix = found[1] if found is not None else ""
    grows = manifest is not None and manifest.files is None  # a sweep's: its report's files are in its digests
    ours = (manifest.files if not grows else manifest.digests) if manifest is not None else frozenset()
    for name in names:
        target = directory / name
        if target.is_symlink() or (target.exists() and not target.is_file()):
            raise OutputError(f"{target}: is not a file; move it out first")
        if target.exists() and ours is not None and prefix + name not in ours:
            raise OutputError(f"{target}: exists and was not written by tmem; move it out first")
    judged = manifest is not None and not (grows and manifest.digests is None)  # an earlier tmem's sweep: by name
    edited = changed_files(directory, manifest, names, prefix) if judged else []
    if edited:
        raise OutputError(f"{directory / edited[0]}: was changed since tmem wrote it; move it out first")


def _listing(found: tuple[Path, str, Manifest], added: dict[str, str]) -> str:
    """The manifest's text with the files ``added`` (name -> digest, relative to the manifest's directory)."""
    folder, _, manifest = found
    if manifest.files is None:  # a directory that grows (a sweep's): no list, the digests of what may be replaced
        return manifest_text(manifest.command, None, {**(manifest.digests or {}), **added})
    files = set(manifest.files) | set(added)
    digests = dict(manifest.digests or {})
    if manifest.digests is None:  # an earlier tmem's: keep what is still tmem's, with its digest from now on
        kept = [name for name in manifest.files if name not in added]
        edited = set(changed_files(folder, manifest, kept))
        files -= edited
        digests = record(folder, [name for name in kept if name not in edited])
    digests.update(added)
    return manifest_text(manifest.command, sorted(files), digests)


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
        In one line, before anything is replaced: a namesake that tmem did not write, that was
        changed since, or that is not a file; a directory that cannot be written.
    """
    directory = Path(directory)
    try:
        remove_leftovers(directory)
        tmp, fd = make_partial(directory, "figures")
    except OSError as exc:
        raise OutputError(f"{directory}: cannot be written ({exc.strerror or exc})") from None
    try:
        yield tmp
        names = sorted(p.name for p in tmp.iterdir() if p.name != WRITING)
        found = _manifest_of(directory)
        _check_namesakes(directory, names, found)
        prefix = found[1] if found is not None else ""
        added = {prefix + name: digest for name, digest in record(tmp, names).items()}
        text = _listing(found, added) if found is not None else None
        with _signals_held():
            for name in names:
                os.replace(tmp / name, directory / name)
            if text is not None:
                write_atomically(found[0] / MANIFEST, lambda path: path.write_text(text, encoding="utf-8"))
    except OSError as exc:
        raise OutputError(f"{directory}: cannot be written ({exc.strerror or exc})") from None
    finally:
        discard(tmp, fd)
