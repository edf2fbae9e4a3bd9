"""Keep Numba's on-disk cache in step with the package's sources.

Numba re-compiles a cached function when the file defining it changes, but
not when a function it calls, defined in another file, changes: the step
loop in engine.py would keep running an old interaction function after
interaction.py was edited.  So the compiled caches of the whole package (every
``__pycache__`` below it) are dropped whenever any of its source files, in any
subpackage, changes.

Every module that compiles with Numba imports this one (``from . import
_numba_cache``) before its compiled functions can load; the first such import
in a process runs :func:`refresh`, once.  Modules that only validate or read
files never import it, nor Numba.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_PACKAGE = Path(__file__).parent
_STAMP = _PACKAGE / "__pycache__" / "numba-sources.sha256"


def _fingerprint() -> str:
    digest = hashlib.sha256()
    for source in sorted(_PACKAGE.rglob("*.py")):
        digest.update(source.relative_to(_PACKAGE).as_posix().encode())
        digest.update(source.read_bytes())
    return digest.hexdigest()


def refresh() -> None:
    """Remove Numba's cache files of this package if its sources changed since they were made."""
    fingerprint = _fingerprint()
    try:
        if _STAMP.exists() and _STAMP.read_text() == fingerprint:
            return
        for cache_dir in _PACKAGE.rglob("__pycache__"):
            for cached in cache_dir.glob("*.nb[ic]"):
                cached.unlink()
        _STAMP.parent.mkdir(exist_ok=True)
        _STAMP.write_text(fingerprint)
    except OSError:
        return  # a read-only installation: Numba then caches elsewhere or not at all


refresh()  # on the first import, before any compiled function of the package is loaded
