"""What the ``tmem`` command prints to a terminal: a progress bar that appears only for long runs,
and the runs' headline figures as a table that fits the terminal: one row per run, or, on a terminal
too narrow for that, one block of rows per run, so that names and numbers are never folded."""

from __future__ import annotations

import time

from rich import box
from rich.console import Console
from rich.padding import Padding
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Column, Table
from rich.text import Text

from tmem.analysis.caveats import SWINGS as swinging_note
from tmem.analysis.caveats import swings

#: Runs expected to take less than this (s) show no progress bar.
PROGRESS_AFTER = 1.0


class LazyProgress:
    """A progress bar on ``console`` that appears only once a run has taken ``PROGRESS_AFTER`` seconds,
    and only on a terminal; called as ``progress(label, done, total)``, one bar per label.

    Parameters
    ----------
    console : Console
        Where the bar is drawn (the command's standard error).
    """

    def __init__(self, console: Console) -> None:
        self.console = console
        self.started = time.perf_counter()
        self.bar: Progress | None = None
        self.tasks: dict[str, int] = {}

    def __call__(self, label: str, done: int, total: int) -> None:
        if self.bar is None:
            if time.perf_counter() - self.started < PROGRESS_AFTER or not self.console.is_terminal:
                return
            self.bar = Progress(
                TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                TimeRemainingColumn(), console=self.console, transient=True,
            )  # fmt: skip
            self.bar.start()
        if label not in self.tasks:
            self.tasks[label] = self.bar.add_task(label, total=total)
        self.bar.update(self.tasks[label], completed=done)

    def close(self) -> None:
        """Take the bar off the terminal, if it was shown."""
        if self.bar is not None:
            self.bar.stop()


def _number(value: float | None, form: str) -> str:
    return "—" if value is None else form.format(value)


#: Under the table when a run ended with pairs coupled and still oscillating.
SWINGS = f"* {swinging_note}"
#: The table's columns, after the run's name.
HEADERS = ("function", "coupled", "couple (s)", "uncouple (s)", "ΔRMS (%)", "largest ΔRMS (%)", "min dist (m)")
#: The columns added where a run has a ``[safety]`` table.
SAFETY_HEADERS = ("near misses", "clearance (m)")


def _coupled_cell(s: dict) -> str:
    """``no``, or ``yes`` with how many of the pairs were coupled at the end (a formation starts coupled)."""
    if not s["coupled"]:
        return "no"
    return f"yes, {s['pairs_coupled_at_end']}/{len(s['pairs'])} at end"


def _safety_cells(s: dict) -> list[str]:
    """A run's near misses at its safety radius and its least clearance to obstacles and walls (:data:`SAFETY_HEADERS`)."""
    safety = s.get("safety")
    if not safety:
        return ["—", "—"]
    clear = [c for c in (safety["min_obstacle_clearance"], safety["min_wall_clearance"]) if c is not None]
    return [f"{safety['near_misses']} within {safety['radius']:g} m", _number(min(clear) if clear else None, "{:.2f}")]


def _headers(rows: dict[str, dict]) -> tuple[str, ...]:
    """The columns of these runs: :data:`HEADERS`, and :data:`SAFETY_HEADERS` where one has a ``[safety]`` table."""
    return HEADERS + (SAFETY_HEADERS if any(s.get("safety") for s in rows.values()) else ())


def _cells(s: dict, headers: tuple[str, ...] = HEADERS) -> list[str]:
    """The figures of one run, in the order of ``headers``."""
    peak, at = s.get("rms_change_peak_percent"), s.get("rms_change_peak_time")
    cells = [
        s["function"], _coupled_cell(s), _number(s["couple_time"], "{:.2f}"), _number(s["uncouple_time"], "{:.2f}"),
        _number(s["rms_change_percent"], "{:+.3f}") + (" *" if swings(s) else ""),
        "—" if peak is None else f"{peak:+.3f} at {at:.2f} s", _number(s["min_distance"], "{:.2f}"),
    ]  # fmt: skip
    return cells + (_safety_cells(s) if len(headers) > len(HEADERS) else [])


def _wide(rows: dict[str, dict]) -> Table:
    """One row per run."""
    headers = _headers(rows)
    table = Table(*(Column(h, no_wrap=True) for h in ("run", *headers)), box=box.SIMPLE_HEAD, pad_edge=False)
    for name, s in rows.items():
        table.add_row(Text(name), *_cells(s, headers))
    return table


def _block(s: dict, headers: tuple[str, ...]) -> Table:
    """One run's figures, one row each: (figure, value)."""
    table = Table(Column(no_wrap=True), Column(no_wrap=True), box=None, pad_edge=False, show_header=False)
    for header, cell in zip(headers, _cells(s, headers)):
        table.add_row(header, cell)
    return table


class RunsTable:
    """The runs' headline figures as the terminal shows them: one row each where the terminal is wide
    enough, else each run's name on a line of its own above a block of its figures, one row each, so
    that no name or number is folded.

    Parameters
    ----------
    rows : dict of str to dict
        Each run's name and its ``summary.json`` contents (:func:`tmem.analysis.metrics.summarize`).
    """

    def __init__(self, rows: dict[str, dict]) -> None:
        self.rows = rows

    def fits(self, width: int) -> bool:
        """Whether one row per run fits ``width`` characters.

        Parameters
        ----------
        width : int
            The width available (characters).
        """
        return Console(width=10**4).measure(_wide(self.rows)).maximum <= width

    def __rich_console__(self, console: Console, options):
        if self.fits(options.max_width):
            yield _wide(self.rows)
        else:
            for name, s in self.rows.items():
                yield Text(name, style="bold")
                yield Padding(_block(s, _headers(self.rows)), (0, 0, 1, 2))
        if any(swings(s) for s in self.rows.values()):
            yield Text(SWINGS)


def summary_table(rows: dict[str, dict]) -> RunsTable:
    """The runs' headline figures (:class:`RunsTable`), to print on a console of any width.

    ΔRMS is marked ``*`` where pairs coupled at the end still oscillate (``rms_change_swings``);
    "largest ΔRMS" is the change from the start with the largest magnitude over the recorded times,
    and when it came (``rms_change_peak_percent``, ``rms_change_peak_time``): the start-up transient
    that ΔRMS, from the start to the end, does not show.

    Parameters
    ----------
    rows : dict of str to dict
        Each run's name and its ``summary.json`` contents (:func:`tmem.analysis.metrics.summarize`).
    """
    return RunsTable(rows)
