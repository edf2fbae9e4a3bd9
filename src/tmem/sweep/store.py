"""A sweep's results on disk: Parquet parts written as tasks finish, one table when all are in.

The output directory of ``tmem sweep`` holds:

* ``sweep.toml``: the sweep file as given, and ``sweep.json``: its
  fingerprint (:attr:`tmem.sweep.spec.Sweep.fingerprint`) and case count;
* ``parts/part-*.parquet``: the rows of finished tasks, while the sweep runs.
  Each part is written under a temporary name and renamed when complete, so
  a part on disk is whole, and the cases in it are done.  Its pages carry
  checksums: a part (or ``results.parquet``) that cannot be read whole, or
  whose rows are not this sweep's, is set aside as ``NAME.corrupt`` in the
  directory (never deleted), said in one line, and its cases run again;
* ``results.parquet``: every row, one per case, sorted by case, once every
  case is done (the parts are then removed);
* ``summary.md`` and the figures (:mod:`tmem.sweep.report`).

Started again on the same directory with the same sweep, a run reads which
cases are done from these files and runs only the others.  A directory
holding another sweep's results is refused, not mixed with; one holding
anything but a sweep's output too (:func:`tmem.files.outputs.check_directory`).

The directory appears whole: ``sweep.toml``, ``sweep.json``, the manifest
``.tmem-output.json`` and ``parts/`` are written into a temporary directory
that is renamed into place (a directory holding only ``sweep.toml``, as an
earlier tmem could leave when killed, is taken up again).  While a sweep
writes, it holds the lock beside the directory (taken by :func:`tmem.sweep.runner.run_sweep`
before the directory is looked at) and the directory's own (:func:`tmem.files.outputs.lock`); it
removes what killed processes left (temporary parts, a temporary ``results.parquet``) when it
takes the lock.  Only regular files are read, each of bounded size: a FIFO or a device under the
name of a file of rows is set aside as corrupt, never opened.
"""

from __future__ import annotations

import json
import re
import stat
import uuid
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pandas as pd
import pyarrow as pa

from tmem import __version__
from tmem.files.outputs import (
    MANIFEST,
    OutputError,
    check_directory,
    create_directory,
    lock,
    mark_directory,
    remove_leftovers,
    write_atomically,
)
from tmem.files.outputs.digests import read_regular
from tmem.scenario.files import MAX_FILE_BYTES
from tmem.sweep.spec import METRIC_TYPES, Sweep

RESULTS = "results.parquet"
PARTS = "parts"
#: Appended to the name of a file of rows that cannot be read, set aside in the sweep's directory.
CORRUPT = ".corrupt"
#: The largest ``sweep.json`` read (bytes).
_IDENTITY_MAX = 1 << 16
#: What reading a damaged Parquet file may raise.
_UNREADABLE = (pa.ArrowException, OSError, ValueError, TypeError, KeyError, IndexError, MemoryError, NotImplementedError)
#: Temporary files of an earlier tmem (no process id in the name), removed under the lock.
_OLD_TEMPORARY = re.compile(r"\.(results\.parquet|part-[0-9]+-[0-9a-f]{8}\.parquet)\.[0-9a-f]{8}\.tmp")


class ResultStore:
    """The rows of one sweep in its output directory; see the module docstring.

    Parameters
    ----------
    out : Path
        The sweep's output directory (``--out``); :meth:`check` makes a store
        after checking it.
    sweep : Sweep
        The sweep whose rows it holds (:func:`tmem.sweep.load_sweep`).
    notify : callable, optional
        ``notify(line)`` is told, in one line, of a file of rows set aside as
        corrupt; by default a :class:`UserWarning`.
    """

    def __init__(self, out: Path, sweep: Sweep, notify: Callable[[str], None] | None = None):
        self.out = out
        self.sweep = sweep
        self.metrics = tuple(sweep.spec.metrics)
        self.notify = notify or (lambda line: warnings.warn(line, stacklevel=4))

    @classmethod
    def check(cls, out: str | Path, sweep: Sweep, notify: Callable[[str], None] | None = None) -> "ResultStore":
        """The store of ``sweep`` at ``out``: new, empty, or holding this sweep's results so far.

        Reads only: nothing is written until :meth:`opened`.

        Parameters
        ----------
        out : str or Path
            The sweep's output directory (``--out``).
        sweep : Sweep
            The sweep to run there.
        notify : callable, optional
            Told of a file of rows set aside as corrupt (see :class:`ResultStore`).

        Raises
        ------
        OutputError
            If ``out`` holds anything but this sweep's output, in one line.
        """
        out = Path(out)
        check_directory(out, "sweep", adopt=lambda directory: _only_a_first_sweep_toml(directory, sweep))
        _check_identity(out, sweep)
        return cls(out, sweep, notify)

    @property
    def exists(self) -> bool:
        """Whether the directory holds this sweep's output already (else :meth:`opened` makes it)."""
        return (self.out / "sweep.toml").exists()

    @contextmanager
    def opened(self) -> Iterator["ResultStore"]:
        """Hold the directory (made if new) for writing: its lock, the leftovers of killed runs removed."""
        if not self.exists:
            try:
                with create_directory(self.out, "sweep") as tmp:
                    self._write_identity(tmp)
                    (tmp / PARTS).mkdir()
            except FileExistsError:
                pass  # another sweep made it meanwhile: take it up as an existing one, below
            else:
                with lock(self.out, "sweep"):
                    yield self
                return
            type(self).check(self.out, self.sweep)
        with lock(self.out, "sweep"):
            try:
                if not (self.out / "sweep.json").exists():  # left so by a killed earlier tmem
                    self._write_identity(self.out)
                if not (self.out / MANIFEST).exists():
                    mark_directory(self.out, "sweep")
                (self.out / PARTS).mkdir(exist_ok=True)
                for folder in (self.out, self.out / PARTS):
                    remove_leftovers(folder, everything=True)  # under the sweep's locks: no writer but this one
                    for stale in folder.iterdir():
                        if _OLD_TEMPORARY.fullmatch(stale.name):
                            stale.unlink()
            except OSError as exc:
                raise OutputError(f"--out {self.out}: cannot be written ({exc.strerror or exc})") from None
            yield self

    def _write_identity(self, directory: Path) -> None:
        sweep = self.sweep
        write_atomically(directory / "sweep.toml", lambda tmp: tmp.write_text(sweep.text, encoding="utf-8"))
        identity = {"fingerprint": sweep.fingerprint, "cases": sweep.n_cases, "name": sweep.name, "tmem": __version__}
        write_atomically(directory / "sweep.json", lambda tmp: tmp.write_text(json.dumps(identity, indent=2) + "\n"))

    def _files(self) -> list[Path]:
        results = self.out / RESULTS
        parts = self.out / PARTS
        return ([results] if results.exists() else []) + (sorted(parts.glob("part-*.parquet")) if parts.is_dir() else [])

    def _read(self, path: Path) -> pd.DataFrame | None:
        """The rows in ``path``; None once it is set aside, if it cannot be read whole or its rows are not this sweep's."""
        try:
            if path.is_symlink() or not stat.S_ISREG(path.stat().st_mode):
                raise ValueError("it is not a regular file")
            frame = pd.read_parquet(path, page_checksum_verification=True)
            self._check_rows(frame)
        except _UNREADABLE as exc:
            self._set_aside(path, " ".join(f"{exc.__class__.__name__}: {exc}".split())[:200])
            return None
        return frame

    def _check_rows(self, frame: pd.DataFrame) -> None:
        """Raise ValueError unless ``frame`` has the columns of this sweep's rows and case numbers within it."""
        needed = {"case", *self.metrics, "error", "seconds"}
        if not needed <= set(frame.columns) <= needed | set(self.sweep.parameters):
            raise ValueError("its columns are not this sweep's")
        cases = frame["case"]
        if not pd.api.types.is_integer_dtype(cases) or not cases.between(0, self.sweep.n_cases - 1).all():
            raise ValueError("its case numbers are not this sweep's")

    def _set_aside(self, path: Path, why: str) -> None:
        """Rename ``path`` to a free ``NAME.corrupt`` (``NAME.2.corrupt``, …) in the sweep's directory; say so."""
        target, n = self.out / f"{path.name}{CORRUPT}", 1
        while target.exists() or target.is_symlink():
            n += 1
            target = self.out / f"{path.name}.{n}{CORRUPT}"
        shown = path.relative_to(self.out)
        try:
            path.rename(target)
        except OSError as exc:
            raise OutputError(f"--out {self.out}: {shown} cannot be read ({why}) nor set aside ({exc.strerror or exc})") from None
        self.notify(f"{shown} in {self.out} cannot be read ({why}); set aside as {target.name}, its cases run again")

    def done_cases(self) -> set[int]:
        """The cases with a row on disk; a file of rows that cannot be read is set aside, its cases not done."""
        done: set[int] = set()
        for path in self._files():
            frame = self._read(path)
            if frame is not None:
                done.update(frame["case"].tolist())
        return done

    def add(self, rows: list[dict]) -> None:
        """Write ``rows`` as a new part (whole or not at all).

        Parameters
        ----------
        rows : list of dict
            One row per finished case: ``case``, the swept parameters, the
            metrics, ``error`` and ``seconds``.  An empty list writes nothing.
        """
        if not rows:
            return
        frame = self._frame(rows)
        name = f"part-{int(frame['case'].min()):09d}-{uuid.uuid4().hex[:8]}.parquet"
        write_atomically(self.out / PARTS / name, lambda tmp: frame.to_parquet(tmp, index=False, write_page_checksum=True))

    def _frame(self, rows: list[dict]) -> pd.DataFrame:
        """Rows as a table with the same column types in every part."""
        frame = pd.DataFrame(rows)
        for column in self.sweep.parameters:
            if column not in frame:  # set by other explicit cases than these
                frame[column] = None
            if frame[column].map(lambda v: isinstance(v, list | dict)).any():  # a vector value, as JSON text;
                frame[column] = frame[column].map(lambda v: None if v is None or v != v else json.dumps(v))  # left out: none
        for metric in self.metrics:
            frame[metric] = frame[metric].astype(METRIC_TYPES.get(metric, "float64"))
        frame["error"] = frame["error"].astype("string")
        return frame

    def table(self) -> pd.DataFrame:
        """Every row on disk, one per case, sorted by case (a file that cannot be read is set aside)."""
        frames = [frame for frame in map(self._read, self._files()) if frame is not None]
        if not frames:
            return pd.DataFrame(columns=["case", *self.sweep.parameters, *self.metrics, "error", "seconds"])
        frame = pd.concat(frames, ignore_index=True)
        return frame.drop_duplicates("case").sort_values("case", ignore_index=True)

    def finish(self) -> pd.DataFrame:
        """Gather every row into ``results.parquet`` (all cases must be done), remove the parts."""
        frame = self.table()
        if len(frame) != self.sweep.n_cases:
            raise RuntimeError(f"finish: {len(frame)} of {self.sweep.n_cases} cases have rows")
        write_atomically(self.out / RESULTS, lambda tmp: frame.to_parquet(tmp, index=False, write_page_checksum=True))
        parts = self.out / PARTS
        if parts.is_dir():
            for part in parts.glob("part-*.parquet"):
                part.unlink()
            remove_leftovers(parts, everything=True)
            parts.rmdir()
        return frame


def _only_a_first_sweep_toml(out: Path, sweep: Sweep) -> bool:
    """Whether ``out`` holds just this sweep's ``sweep.toml`` (and perhaps an empty ``parts/``).

    An earlier tmem, killed between writing ``sweep.toml`` and ``sweep.json``,
    left such a directory; it is this sweep's, started.
    """
    try:
        if (out / "sweep.json").exists():
            return False
        names = {p.name for p in out.iterdir()}
        if not names <= {"sweep.toml", PARTS} or "sweep.toml" not in names:
            return False
        if PARTS in names and ((out / PARTS).is_symlink() or any((out / PARTS).iterdir())):
            return False
        return read_regular(out / "sweep.toml", MAX_FILE_BYTES).decode("utf-8") == sweep.text
    except (OSError, ValueError):
        return False


def _check_identity(out: Path, sweep: Sweep) -> None:
    """Refuse a sweep directory that holds another sweep's results."""
    identity = out / "sweep.json"
    if not identity.exists():
        return  # new or empty
    try:
        fingerprint = json.loads(read_regular(identity, _IDENTITY_MAX).decode("utf-8"))["fingerprint"]
    except (OSError, ValueError, KeyError, TypeError):
        raise OutputError(f"--out {out}: its sweep.json cannot be read; choose another directory") from None
    if fingerprint != sweep.fingerprint:
        raise OutputError(
            f"--out {out}: holds the results of a different sweep (another file, base or seed); "
            "choose another directory, or remove it to start over"
        )
