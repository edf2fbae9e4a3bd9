"""What the ``tmem`` command prints to a terminal: a progress bar that appears only for long runs,
and the runs' headline figures as a table."""

from __future__ import annotations

import time

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Column, Table
from rich.text import Text

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


#: Under the table when a run ended with pairs coupled.
SWINGS = "* pairs still coupled at the end: ΔRMS is an instantaneous value that swings with their oscillation"


def _coupled_cell(s: dict) -> str:
    """``no``, or ``yes`` with how many of the pairs were coupled at the end (a formation starts coupled)."""
    if not s["coupled"]:
        return "no"
    return f"yes, {s['pairs_coupled_at_end']}/{len(s['pairs'])} at end"


def summary_table(rows: dict[str, dict]) -> Table:
    """The runs' headline figures, one row each; ΔRMS marked ``*`` where pairs were still coupled at the end.

    Parameters
    ----------
    rows : dict of str to dict
        Each run's name and its ``summary.json`` contents (:func:`tmem.analysis.metrics.summarize`).
    """
    headers = ("run", "function", "coupled", "couple (s)", "uncouple (s)", "ΔRMS (%)", "min dist (m)")
    table = Table(*(Column(h, overflow="fold") for h in headers))  # whole names, folded, not cut with "…"
    for name, s in rows.items():
        swings = s["rms_change_while_coupled"] and s["rms_change_percent"] is not None
        table.add_row(
            Text(name), s["function"], _coupled_cell(s), _number(s["couple_time"], "{:.2f}"),
            _number(s["uncouple_time"], "{:.2f}"), _number(s["rms_change_percent"], "{:+.3f}") + (" *" if swings else ""),
            _number(s["min_distance"], "{:.2f}"),
        )  # fmt: skip
        if swings:
            table.caption, table.caption_justify = SWINGS, "left"
    return table
