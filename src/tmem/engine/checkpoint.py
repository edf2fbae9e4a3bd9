"""Checkpoints of a long run: its whole state at a step, written atomically, and the run resumed from it.

``tmem run SCENARIO --out DIR --checkpoint-every SECONDS`` saves, every SECONDS of *simulated*
time, everything the step loop carries from one step to the next, into one file beside DIR:
``.DIR.tmem-checkpoint.npz`` (:func:`checkpoint_path`).  Run again after the process was killed,
the same command goes on from the last checkpoint and ends with the same bits as a run that was
never stopped.  Once the run is complete and its output in place, the file is removed.

What a checkpoint holds
-----------------------
The records of :mod:`tmem.engine.records` that change during a run (:data:`CHANGING`), field by
field under ``record.field`` in a NumPy ``.npz`` file.  Every field is saved except those
:data:`REBUILT` names, each with the reason it can be made again exactly: numbers fixed for the
run, work space that every step writes before it reads it, and the neighbour lists, which are
listed again from ``P*`` at their last build (``neighbours.p_ref``, saved) and the flying agents.
The rows recorded so far and the events so far are saved up to the counters that count them
(:data:`ROWS`).  The records that never change (:data:`FIXED_RECORDS`, the vehicle model's) and
the agents' slots are made again from the scenario.  The list is derived from the records'
fields, so a field added to a record later is saved without a change here.

A scenario's random streams (a ``[swarm]``'s starts, a formation's jitter) are drawn from their
seeds before the first step, and drawn again identically when a run resumes.  The measurement
stage's noise, delays and losses are counter-based draws (:mod:`tmem.world.streams`), a function of the
seed, the agent and the step alone: there is no generator state to save.

A checkpoint is used only by the run that made it (:func:`fingerprint`): the same scenario as tmem
reads it, the same recording and sensing, and the same versions of tmem, Numba and NumPy.  Any
other is refused in one line (:class:`CheckpointError`), never used and never removed.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numba
import numpy as np

from tmem import __version__
from tmem.law.interaction.kernels import FunctionParams
from tmem.files.arrays import NpzArrays
from tmem.files.outputs import write_atomically
from tmem.scenario import Scenario
from tmem.world.sensing import Sensing
from tmem.engine.records import Agents, Commands, Counters, Events, Gas, Neighbours, Pairs, Records, Run
from tmem.law.record import Law
from tmem.terms import term_class

#: The records that change during a run, under the names a checkpoint gives their fields.
CHANGING = {
    "agents": Agents,
    "pairs": Pairs,
    "neighbours": Neighbours,
    "records": Records,
    "events": Events,
    "counters": Counters,
    "gas": Gas,
    "sensing": Sensing,
}
#: The records that no step changes: a resumed run makes them again from the scenario.
FIXED_RECORDS = (Run, Law, FunctionParams, Commands)

_FIXED = "a number fixed for the run, made again from the scenario"
_WORK = "work space, written at every step before it is read"
_COUNTED = "work space, written at each count of the gas before it is read"
_LISTED = "the neighbour lists, listed again from neighbours.p_ref and the flying agents as at their last build"
#: The fields of :data:`CHANGING` records that a checkpoint does not hold, and why each is made again exactly.
REBUILT = {
    "pairs": {"d": _WORK},
    "neighbours": {
        "pairs": _LISTED, "n_inside": _LISTED, "n_pairs": _LISTED, "block_ptr": _LISTED,
        "block_nearest2": _WORK, "block_shift2": _WORK, "chunks": _WORK,
    },
    "gas": {
        **dict.fromkeys(("observe", "mean", "rate", "inv_g", "g_dt", "dt", "every", "wall_reach", "c_max"), _FIXED),
        "work": _COUNTED, "pushed": _WORK,
    },
    "sensing": {
        **dict.fromkeys((f for f in Sensing._fields if f not in ("history", "own", "pair_states", "seen", "pushes", "work")), _FIXED),
        **dict.fromkeys(("own", "pair_states", "seen", "pushes", "work"), _WORK),
    },
}  # fmt: skip
#: Fields filled row by row, and the counter of filled rows: a checkpoint holds those rows only.
ROWS = {
    **{("records", f): "next_record" for f in Records._fields if f != "slots"},
    **{("events", f): "n_events" for f in Events._fields},
}
#: Raised to the checkpoint's file format when it changes.
FORMAT = 4


class CheckpointError(ValueError):
    """A checkpoint that cannot be made or used; the message is one line."""


class Saved(NamedTuple):
    """A checkpoint read back: its arrays by ``record.field``, and where the run stood.

    Attributes
    ----------
    path : Path
        The file it was read from.
    arrays : dict of str to ndarray
    step : int
        The step the run goes on from (not yet taken).
    list_builds : int
        How often the neighbour lists had been built.
    """

    path: Path
    arrays: dict
    step: int
    list_builds: int


def saved_fields(name: str) -> list[str]:
    """The fields of the changing record ``name`` that a checkpoint holds: all but :data:`REBUILT`'s.

    Parameters
    ----------
    name : str
        A key of :data:`CHANGING`.
    """
    return [f for f in CHANGING[name]._fields if f not in REBUILT.get(name, {})]


def checkpoint_path(out: str | Path) -> Path:
    """Where the checkpoints of a run into ``out`` are kept: beside it, hidden, ``.NAME.tmem-checkpoint.npz``.

    Outside the output directory, so that it is never taken for output, and not a temporary name
    of :mod:`tmem.files.outputs`, so that no command removes it as a leftover.  The name keeps the first
    180 bytes of ``out``'s, as temporary names do.

    Parameters
    ----------
    out : str or Path
        The run directory (``--out``).
    """
    out = Path(out)
    kept = os.fsdecode(os.fsencode(out.name)[:180])
    return out.parent / f".{kept}.tmem-checkpoint.npz"


def fingerprint(scenario: Scenario, record: bool, sensing: dict | None) -> str:
    """What a checkpoint must have been made by: a SHA-256 of the scenario and the run's settings.

    The scenario as tmem reads it (:meth:`~tmem.scenario.Scenario.to_toml`, every value written
    out: comments and layout do not count, its ``[sensing]`` table included), whether it is recorded,
    and the measurement stage's fields set over that table.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario.
    record : bool
        Whether the run records (:func:`tmem.simulate`'s ``record``).
    sensing : dict or None
        :func:`tmem.simulate`'s ``sensing``: fields of the measurement stage set over the table.
    """
    overrides = None if sensing is None else sorted((k, repr(v)) for k, v in sensing.items())
    text = f"{scenario.to_toml()}\nrecord = {record}\nsensing = {overrides}\n"
    return hashlib.sha256(text.encode()).hexdigest()


def made_by() -> str:
    """The versions whose compiled code a checkpoint's bits depend on: tmem, Numba and NumPy."""
    return f"tmem {__version__} (Numba {numba.__version__}, NumPy {np.__version__})"


def _arrays(state: dict) -> dict[str, tuple[np.ndarray, str | None]]:
    """Every array a checkpoint holds, by ``record.field`` (an agent term's by ``terms.NAME.field``), with
    the counter of its filled rows (or None)."""
    fields = [(name, state[name], saved_fields(name)) for name in CHANGING]
    for term, record in state.get("terms", {}).items():  # each declares what it rebuilds (tmem.terms.base)
        fields.append((f"terms.{term}", record, [f for f in record._fields if f not in term_class(term).rebuilt]))
    found = {}
    for name, record, saved in fields:
        for f in saved:
            value = getattr(record, f)
            if not isinstance(value, np.ndarray):
                raise TypeError(f"{name}.{f} is not an array: save it as one, or declare it in REBUILT")
            found[f"{name}.{f}"] = (value, ROWS.get((name, f)))
    return found


def restore(saved: Saved, state: dict) -> None:
    """Copy a checkpoint's arrays into the run's records, in place.

    Parameters
    ----------
    saved : Saved
        The checkpoint the run goes on from (:meth:`Checkpoints.start`).
    state : dict
        The run's :data:`CHANGING` records, by name, as built for its start.

    Raises
    ------
    CheckpointError
        If an array is missing or has another shape or type than the run's.
    """
    for key, (target, rows) in _arrays(state).items():
        value = saved.arrays.get(key)
        fits = value is not None and value.dtype == target.dtype and value.ndim == target.ndim
        if fits and rows is not None:
            fits = value.shape[1:] == target.shape[1:] and len(value) <= len(target)
        elif fits:
            fits = value.shape == target.shape
        if not fits:
            raise CheckpointError(f"checkpoint {saved.path}: its {key} does not fit this run; remove it to run from the start")
        target[: len(value)] = value


@dataclass
class Checkpoints:
    """The checkpoints of one run: the file, and the simulated time between two of them.

    Parameters
    ----------
    path : Path
        The checkpoint file (:func:`checkpoint_path` for ``tmem run``); its folder is made if needed.
    every : float
        Simulated seconds between checkpoints, rounded to whole steps; checkpoints fall at
        multiples of it from the start, whenever the run was resumed.
    on_resume : callable, optional
        ``on_resume(time)`` is called when a run goes on from a checkpoint, with its simulated time (s).

    Raises
    ------
    CheckpointError
        If ``every`` is not a positive number.
    """

    path: Path
    every: float
    on_resume: Callable[[float], None] | None = None
    #: The step of the checkpoint last written or read; None before.
    saved_step: int | None = field(default=None, init=False)
    _interval: int = field(default=0, init=False, repr=False)
    _dt: float = field(default=0.0, init=False, repr=False)
    _fingerprint: str = field(default="", init=False, repr=False)

    def __post_init__(self) -> None:
        self.path = Path(self.path)
        if not (math.isfinite(self.every) and self.every > 0.0):
            raise CheckpointError(f"--checkpoint-every: must be a positive number of seconds, got {self.every:g}")

    @property
    def saved_time(self) -> float | None:
        """The simulated time (s) of the checkpoint last written or read; None before."""
        return None if self.saved_step is None else round(self.saved_step * self._dt, 12)

    def start(self, scenario: Scenario, record: bool = True, sensing: dict | None = None) -> Saved | None:
        """Begin a run: check ``every`` against its time step, and read the checkpoint it left, if any.

        Parameters
        ----------
        scenario : Scenario
            The run's scenario.
        record : bool
            Whether the run records.
        sensing : dict or None
            :func:`tmem.simulate`'s ``sensing``: fields of the measurement stage set over the table.

        Returns
        -------
        Saved or None
            The checkpoint to go on from; None when there is none.

        Raises
        ------
        CheckpointError
            If ``every`` is shorter than a step, the file is not a checkpoint of this run, or its
            folder cannot be written.
        """
        sim = scenario.simulation
        if self.every < sim.dt * (1.0 - 1e-9):
            raise CheckpointError(f"--checkpoint-every: must be at least the time step dt = {sim.dt:g} s, got {self.every:g}")
        self._interval, self._dt = sim.step_of(self.every), sim.dt
        self._fingerprint = fingerprint(scenario, record, sensing)
        folder = next(p for p in (self.path.parent, *self.path.parent.absolute().parents) if p.exists())
        if not os.access(folder, os.W_OK | os.X_OK):
            raise CheckpointError(f"checkpoint {self.path}: cannot be written (no permission to write in {folder})")
        saved = self._read()
        self.saved_step = None if saved is None else saved.step
        if saved is not None and self.on_resume is not None:
            self.on_resume(self.saved_time)
        return saved

    def due(self, step: int) -> int:
        """The step of the next checkpoint after ``step``.

        Parameters
        ----------
        step : int
            A step of the run.
        """
        return (step // self._interval + 1) * self._interval

    def save(self, step: int, state: dict, list_builds: int) -> None:
        """Write the checkpoint of the run before step ``step``: temporary name, fsync, rename.

        Parameters
        ----------
        step : int
            The step the run stands at (not yet taken).
        state : dict
            The run's :data:`CHANGING` records, by name, and its agent terms' records (``terms``: by name).
        list_builds : int
            How often the neighbour lists have been built.
        """
        step, counters = int(step), state["counters"]
        arrays = {key: value[: int(getattr(counters, rows)[0])] if rows else value for key, (value, rows) in _arrays(state).items()}
        meta = {"format": FORMAT, "made_by": made_by(), "fingerprint": self._fingerprint, "step": step,
                "time": round(step * self._dt, 12), "list_builds": int(list_builds)}  # fmt: skip

        def write(tmp: Path) -> None:
            with open(tmp, "wb") as f:
                np.savez(f, meta=np.array(json.dumps(meta)), **arrays)
                f.flush()
                os.fsync(f.fileno())

        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            write_atomically(self.path, write)
        except OSError as exc:
            raise CheckpointError(f"checkpoint {self.path}: cannot be written ({exc.strerror or exc})") from None
        _sync_folder(self.path.parent)
        self.saved_step = step

    def remove(self) -> None:
        """Remove the checkpoint: the run is complete and its output in place.  A file that cannot be
        removed stays (the same command would go on from it, to the same output)."""
        try:
            self.path.unlink(missing_ok=True)
        except OSError:
            return
        _sync_folder(self.path.parent)

    def _read(self) -> Saved | None:
        path = self.path
        if path.is_symlink() or (path.exists() and not path.is_file()):
            raise CheckpointError(f"checkpoint {path}: exists and is not a tmem checkpoint; move it away or choose another --out")
        if not path.exists():
            return None
        damaged = (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile)
        try:  # the meta first, and only then the arrays: a foreign file is refused before any is read
            data = NpzArrays(path)
            with data:
                meta = json.loads(str(data.read("meta")))
                step, builds, by, made_for = int(meta["step"]), int(meta["list_builds"]), str(meta["made_by"]), meta["fingerprint"]
                if by == made_by() and meta.get("format") == FORMAT and made_for == self._fingerprint:
                    arrays = {key: data.read(key) for key in data.names if key != "meta"}
        except damaged as exc:
            raise CheckpointError(
                f"checkpoint {path}: is not a tmem checkpoint, or is damaged ({type(exc).__name__}); move it away or choose another --out"
            ) from None
        if by != made_by() or meta.get("format") != FORMAT:
            raise CheckpointError(f"checkpoint {path}: was written by {by}, this is {made_by()}; remove it to run from the start")
        if made_for != self._fingerprint:
            raise CheckpointError(
                f"checkpoint {path}: was written for another scenario or other settings; remove it to run from the start"
            )
        return Saved(path, arrays, step, builds)


def _sync_folder(folder: Path) -> None:
    """Flush ``folder``'s entries to disk (a rename survives a power cut); where folders cannot be opened, nothing."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
