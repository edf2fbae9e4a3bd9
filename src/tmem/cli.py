"""The ``tmem`` command: ``run`` a scenario, reproduce the ``paper``, ``animate`` a run, ``sweep`` many, ``export`` a run.

User mistakes (a bad scenario, an unusable output directory) end with one
line on standard error naming the field and the reason, exit status 2 and no
output written.

Each command imports what it needs (the compiled engine, xarray, matplotlib,
Dask) in its body, so that ``tmem --help`` and a mistyped command answer at
once.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Column, Table
from rich.text import Text

app = typer.Typer(add_completion=False, no_args_is_help=True, help=__doc__.split("\n")[0])
console = Console(stderr=True)

#: Runs expected to take less than this (s) show no progress bar.
PROGRESS_AFTER = 1.0


class _LazyProgress:
    """A progress bar that appears only once a run has taken ``PROGRESS_AFTER`` seconds."""

    def __init__(self) -> None:
        self.started = time.perf_counter()
        self.bar: Progress | None = None
        self.tasks: dict[str, int] = {}

    def __call__(self, label: str, done: int, total: int) -> None:
        if self.bar is None:
            if time.perf_counter() - self.started < PROGRESS_AFTER or not console.is_terminal:
                return
            self.bar = Progress(
                TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                TimeRemainingColumn(), console=console, transient=True,
            )  # fmt: skip
            self.bar.start()
        if label not in self.tasks:
            self.tasks[label] = self.bar.add_task(label, total=total)
        self.bar.update(self.tasks[label], completed=done)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


def _fail(message: str) -> None:
    console.print(f"[bold red]error:[/] {escape(message)}", highlight=False, soft_wrap=True)
    raise typer.Exit(2)


def _say(text: str) -> None:
    """Print ``text`` to standard output as it is: no markup, no highlighting, no wrapping (a path stays whole)."""
    Console().print(text, markup=False, highlight=False, soft_wrap=True)


def _number(value: float | None, form: str) -> str:
    return "—" if value is None else form.format(value)


#: Under the table when a run ended with pairs coupled.
SWINGS = "* pairs still coupled at the end: ΔRMS is an instantaneous value that swings with their oscillation"


def _coupled_cell(s: dict) -> str:
    """``no``, or ``yes`` with how many of the pairs were coupled at the end (a formation starts coupled)."""
    if not s["coupled"]:
        return "no"
    return f"yes, {s['pairs_coupled_at_end']}/{len(s['pairs'])} at end"


def _summary_table(rows: dict[str, dict]) -> Table:
    """The runs' headline figures, one row each; ΔRMS marked ``*`` where pairs were still coupled at the end."""
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


@app.command()
def run(
    scenario: Path = typer.Argument(..., help="Scenario TOML file (see examples/)."),
    out: Path = typer.Option(..., "--out", "-o", help="Output directory (replaced if it holds an earlier run)."),
) -> None:
    """Simulate SCENARIO and write summary.json, trajectory.nc and figures to OUT.

    \f
    Parameters
    ----------
    scenario : Path
        Scenario TOML file.
    out : Path
        Output directory (replaced if it holds an earlier run).
    """
    from .engine import SimulationError, simulate
    from .io import OutputError, check_output_directory, write_run
    from .scenario import ScenarioError, load

    progress = _LazyProgress()
    try:
        loaded = load(scenario)
        check_output_directory(out)
        trajectory = simulate(loaded, progress=lambda done, total: progress(scenario.name, done, total))
        progress.close()
        summary = write_run(trajectory, out)
    except (ScenarioError, OutputError, SimulationError) as exc:
        progress.close()
        _fail(str(exc))
    Console().print(_summary_table({loaded.name or scenario.stem: summary}))
    _say(f"written to {out}/")


@app.command()
def paper(
    out: Path = typer.Option(Path("out/paper"), "--out", "-o", help="Output directory."),
) -> None:
    """Reproduce the paper's Figs. 5, 7 and 9 into OUT/fig5, OUT/fig7, OUT/fig9 and OUT/report.md.

    \f
    Parameters
    ----------
    out : Path
        Output directory.
    """
    from .engine import SimulationError
    from .io import OutputError
    from .paper import run_paper

    progress = _LazyProgress()
    try:
        summaries, _ = run_paper(out, progress=progress)
    except (OutputError, SimulationError) as exc:
        progress.close()
        _fail(str(exc))
    progress.close()
    Console().print(_summary_table(summaries))
    _say(f"report: {out / 'report.md'}")


@app.command("animate")
def animate_command(
    run_dir: Path = typer.Argument(..., help="A run directory written by `tmem run` (2-D runs)."),
    out: Path = typer.Option(None, "--out", "-o", help="Animation file (.gif, or .mp4 with ffmpeg); default RUN_DIR/animation.gif."),
    fps: int = typer.Option(20, help="Frames per second."),
    max_frames: int = typer.Option(400, help="Most frames; the recorded times are thinned evenly."),
) -> None:
    """Animate a 2-D run: agents, interaction circles, coupled pairs and a clock.

    \f
    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``.
    out : Path or None
        Animation file (``.gif``, or ``.mp4`` with ffmpeg); default ``RUN_DIR/animation.gif``.
    fps : int
        Frames per second.
    max_frames : int
        Most frames; the recorded times are thinned evenly.
    """
    for option, value in (("--fps", fps), ("--max-frames", max_frames)):
        if value < 1:
            _fail(f"{option}: must be at least 1, got {value}")
    from .animate import animate

    try:
        path = animate(run_dir, out, fps=fps, max_frames=max_frames)
    except (ValueError, OSError) as exc:
        _fail(str(exc))
    _say(f"written {path}")


@app.command("export")
def export_command(
    run_dir: Path = typer.Argument(..., help="A run directory written by `tmem run`."),
    to: str = typer.Option(..., "--to", help="mcap: Foxglove's messages in one file; csv: Crazyswarm2-style, a file per agent."),
    out: Path = typer.Option(None, "--out", "-o", help="Where to write; default RUN_DIR/trajectory.mcap or RUN_DIR/crazyswarm/."),
) -> None:
    """Export a run for the field's tools: an MCAP file for Foxglove, or CSV files for Crazyswarm2.

    \f
    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``.
    to : str
        ``mcap`` or ``csv`` (``docs/exchange.md``).
    out : Path or None
        Where to write; default ``RUN_DIR/trajectory.mcap`` or ``RUN_DIR/crazyswarm/``.
    """
    from .exchange import export

    try:
        path = export(run_dir, to, out)
    except (ValueError, OSError) as exc:
        _fail(str(exc))
    _say(f"written {path}")


@app.command("sweep")
def sweep_command(
    sweep_file: Path = typer.Argument(..., help="Sweep TOML file (see examples/sweeps/ and docs/sweeps.md)."),
    out: Path = typer.Option(..., "--out", "-o", help="Output directory; run again to resume an interrupted sweep."),
    scheduler: str = typer.Option(None, help="Address of an existing Dask scheduler; default: a local cluster."),
    workers: str = typer.Option(None, metavar="N", help="Worker processes of the local cluster; default: one per core."),
) -> None:
    """Run every case of SWEEP_FILE on Dask; write results.parquet, summary.md and figures to OUT.

    \f
    Parameters
    ----------
    sweep_file : Path
        Sweep TOML file (``docs/sweeps.md``).
    out : Path
        Output directory; run again to resume an interrupted sweep.
    scheduler : str or None
        Address of an existing Dask scheduler; default: a local cluster.
    workers : str or None
        Worker processes of the local cluster (a whole number); default: one per core.
    """
    from .io import OutputError
    from .sweep import SweepError, SweepInterrupted, load_sweep, run_sweep
    from .sweep.cluster import check_workers

    try:
        count = check_workers(workers, scheduler)
        sweep = load_sweep(sweep_file)
    except SweepError as exc:
        _fail(str(exc))
    bar = Progress(
        TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total} cases"),
        TimeRemainingColumn(), console=console, transient=True, disable=not console.is_terminal,
    )  # fmt: skip
    task = bar.add_task(sweep.name, total=sweep.n_cases)
    try:
        with bar:
            outcome = run_sweep(
                sweep, out, scheduler=scheduler, workers=count,
                progress=lambda done, total: bar.update(task, completed=done),
                notify=lambda line: console.print(f"[yellow]warning:[/] {escape(line)}", highlight=False, soft_wrap=True),
            )  # fmt: skip
    except (SweepError, OutputError) as exc:
        _fail(str(exc))
    except SweepInterrupted as exc:
        console.print(escape(str(exc)), highlight=False)
        raise typer.Exit(130) from None
    _say(
        f"{len(outcome.table)} cases ({outcome.ran} run now, {outcome.failed} failed) in {outcome.seconds:.1f} s; "
        f"written to {out}/results.parquet and {out}/summary.md"
    )


def main() -> None:
    """Entry point of the ``tmem`` console script."""
    from .outputs import handle_termination

    handle_termination()  # SIGTERM and SIGHUP as Ctrl-C: interrupted writes leave nothing behind
    try:
        app()
    except KeyboardInterrupt:
        console.print("interrupted; no output was written")
        sys.exit(130)
