"""Keep Numba's on-disk cache in step with the package's sources.

Numba re-compiles a cached function when the file defining it changes, but
not when a function it calls, defined in another file, changes: the step
loop in engine.py would keep running an old interaction function after
interaction.py was edited.  So the compiled caches of the whole package are
dropped whenever any of its source files changes.  Every module that
compiles with Numba imports this one first; the check runs once, on that
first import.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_PACKAGE = Path(__file__).parent
_STAMP = _PACKAGE / "__pycache__" / "numba-sources.sha256"


def refresh() -> None:
    """Remove Numba's cache files of this package if its sources changed since they were made."""
    digest = hashlib.sha256()
    for source in sorted(_PACKAGE.rglob("*.py")):
        digest.update(source.relative_to(_PACKAGE).as_posix().encode())
        digest.update(source.read_bytes())
    fingerprint = digest.hexdigest()
    try:
        if _STAMP.exists() and _STAMP.read_text() == fingerprint:
            return
        for cached in _PACKAGE.rglob("__pycache__/*.nb[ic]"):
            cached.unlink()
        _STAMP.parent.mkdir(exist_ok=True)
        _STAMP.write_text(fingerprint)
    except OSError:
        return  # a read-only installation: Numba then caches elsewhere or not at all


refresh()
