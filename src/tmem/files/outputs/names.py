"""Temporary names, and what killed tmem processes left under them.

A directory or file is written under a hidden temporary name next to its
destination, ``.NAME.tmem-partial-PID-RANDOM`` (:func:`partial_name`).  A
process killed outright leaves that name behind; it is recognised by the
name and by its process being gone from this machine (:func:`is_leftover`),
and removed by the next command writing into the same folder
(:func:`remove_leftovers`).
"""

from __future__ import annotations

import os
import re
import secrets
import shutil
from pathlib import Path

#: Bytes of the destination's name kept in a temporary name (names stay under 255 bytes).
_NAME_KEPT = 180
#: The longest name of a file or folder (bytes) on common file systems.
_NAME_MAX = 255
_PARTIAL = re.compile(r"\.(?P<name>.*)\.tmem-partial-(?P<pid>[0-9]{1,10})-(?P<tag>[0-9a-f]{8})(?:\.[A-Za-z0-9]{1,10})?", re.S)


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
    """Whether ``path`` is a temporary file or directory of a tmem process that is gone.

    Parameters
    ----------
    path : Path
        The entry to judge; only its name is read, and whether the process
        id in it still runs on this machine.
    """
    pid = _partial_owner(path.name)
    return pid is not None and not _alive(pid)


def remove_leftovers(folder: Path) -> list[Path]:
    """Remove from ``folder`` (not below it) what killed tmem processes left; return what was removed.

    Parameters
    ----------
    folder : Path
        The folder to clean; one that cannot be listed is left as it is.
    """
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

def _too_long(path: Path) -> str | None:
    """The first component of ``path`` longer than file systems allow (255 bytes), if any."""
    for part in path.parts:
        if len(os.fsencode(part)) > _NAME_MAX:
            return part
    return None
