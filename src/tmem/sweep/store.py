"""A sweep's results on disk: Parquet parts written as tasks finish, one table when all are in.

The output directory of ``tmem sweep`` holds:

* ``sweep.toml``: the sweep file as given, and ``sweep.json``: its
  fingerprint (:attr:`tmem.sweep.spec.Sweep.fingerprint`) and case count;
* ``parts/part-*.parquet``: the rows of finished tasks, while the sweep runs.
  Each part is written under a temporary name and renamed when complete, so
  a part on disk is whole, and the cases in it are done;
* ``results.parquet``: every row, one per case, sorted by case, once every
  case is done (the parts are then removed);
* ``summary.md`` and the figures (:mod:`tmem.sweep.report`).

Started again on the same directory with the same sweep, a run reads which
cases are done from these files and runs only the others.  A directory
holding another sweep's results is refused, not mixed with.
"""

from __future__ import annotations

import json
import os
import uuid
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

from .. import __version__
from ..io import OutputError
from .spec import Sweep

RESULTS = "results.parquet"
PARTS = "parts"


class ResultStore:
    """The rows of one sweep in its output directory; see the module docstring.

    Parameters
    ----------
    out : Path
        The sweep's output directory.
    sweep : Sweep
        The sweep whose rows it keeps.
    """

    def __init__(self, out: Path, sweep: Sweep):
        self.out = out
        self.sweep = sweep
        self.metrics = tuple(sweep.spec.metrics)

    @classmethod
    def open(cls, out: str | Path, sweep: Sweep) -> "ResultStore":
        """Open ``out`` for ``sweep``: new, empty, or holding this sweep's results so far.

        Parameters
        ----------
        out : str or Path
            The sweep's output directory; refused with :class:`~tmem.io.OutputError` if it holds
            anything else.
        sweep : Sweep
            The sweep whose rows it keeps.
        """
        out = Path(out)
        _check_directory(out, sweep)
        store = cls(out, sweep)
        try:
            (out / PARTS).mkdir(parents=True, exist_ok=True)
            for stale in (out / PARTS).glob(".*.tmp"):  # a part whose writing was cut off
                stale.unlink()
            if not (out / "sweep.json").exists():
                (out / "sweep.toml").write_text(sweep.text, encoding="utf-8")
                identity = {"fingerprint": sweep.fingerprint, "cases": sweep.n_cases, "name": sweep.name, "tmem": __version__}
                _write_atomically(out / "sweep.json", lambda tmp: tmp.write_text(json.dumps(identity, indent=2) + "\n"))
        except OSError as exc:
            raise OutputError(f"--out {out}: cannot be written ({exc.strerror or exc})") from None
        return store

    def _files(self) -> list[Path]:
        results = self.out / RESULTS
        return ([results] if results.exists() else []) + sorted((self.out / PARTS).glob("part-*.parquet"))

    def done_cases(self) -> set[int]:
        """The cases with a row on disk."""
        done: set[int] = set()
        for path in self._files():
            done.update(pq.read_table(path, columns=["case"]).column("case").to_pylist())
        return done

    def add(self, rows: list[dict]) -> None:
        """Write ``rows`` as a new part (whole or not at all).

        Parameters
        ----------
        rows : list of dict
            Rows of finished cases (:func:`tmem.sweep.tasks.row`).
        """
        if not rows:
            return
        frame = self._frame(rows)
        name = f"part-{int(frame['case'].min()):09d}-{uuid.uuid4().hex[:8]}.parquet"
        _write_atomically(self.out / PARTS / name, lambda tmp: frame.to_parquet(tmp, index=False))

    def _frame(self, rows: list[dict]) -> pd.DataFrame:
        """Rows as a table with the same column types in every part."""
        frame = pd.DataFrame(rows)
        for column in self.sweep.parameters:
            if frame[column].map(lambda v: isinstance(v, list | dict)).any():
                frame[column] = frame[column].map(json.dumps)  # a vector value, as JSON text
        for metric in self.metrics:
            frame[metric] = frame[metric].astype("boolean" if metric == "coupled" else "float64")
        frame["error"] = frame["error"].astype("string")
        return frame

    def table(self) -> pd.DataFrame:
        """Every row on disk, one per case, sorted by case."""
        files = self._files()
        if not files:
            return pd.DataFrame(columns=["case", *self.sweep.parameters, *self.metrics, "error", "seconds"])
        frame = pd.concat([pd.read_parquet(path) for path in files], ignore_index=True)
        return frame.drop_duplicates("case").sort_values("case", ignore_index=True)

    def finish(self) -> pd.DataFrame:
        """Gather every row into ``results.parquet`` (all cases must be done), remove the parts."""
        frame = self.table()
        if len(frame) != self.sweep.n_cases:
            raise RuntimeError(f"finish: {len(frame)} of {self.sweep.n_cases} cases have rows")
        _write_atomically(self.out / RESULTS, lambda tmp: frame.to_parquet(tmp, index=False))
        for part in (self.out / PARTS).glob("part-*.parquet"):
            part.unlink()
        (self.out / PARTS).rmdir()
        return frame


def _write_atomically(path: Path, write) -> None:
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _check_directory(out: Path, sweep: Sweep) -> None:
    if out.is_symlink():
        raise OutputError(f"--out {out}: is a symbolic link; give the directory itself")
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out}: exists and is not a directory")
    for parent in out.absolute().parents:
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"--out {out}: {parent} is a file, not a directory")
    if not out.is_dir() or not any(out.iterdir()):
        return
    identity = out / "sweep.json"
    if not identity.exists():
        raise OutputError(f"--out {out}: holds files that are not a sweep's results; choose another directory")
    try:
        fingerprint = json.loads(identity.read_text(encoding="utf-8"))["fingerprint"]
    except (OSError, ValueError, KeyError, TypeError):
        raise OutputError(f"--out {out}: its sweep.json cannot be read; choose another directory") from None
    if fingerprint != sweep.fingerprint:
        raise OutputError(
            f"--out {out}: holds the results of a different sweep (another file, base or seed); "
            "choose another directory, or remove it to start over"
        )
