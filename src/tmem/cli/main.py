"""The ``tmem`` command: ``run`` a scenario, reproduce the ``paper``, ``animate`` or ``plot`` a run, ``sweep`` many, ``export`` a run.

User mistakes (a bad scenario, an unusable output directory) end with one
line on standard error naming the field and the reason, exit status 2 and no
output written.

Each command imports what it needs (the compiled engine, xarray, matplotlib,
Dask) in its body, so that ``tmem --help`` and a mistyped command answer at
once.
"""

from __future__ import annotations

import sys
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

from tmem.cli.messages import Commands, error_line
from tmem.cli.terminal import LazyProgress, summary_table
from tmem.files.outputs.names import one_line

app = typer.Typer(
    cls=Commands, add_completion=False, no_args_is_help=True,
    help="Run a scenario, reproduce the paper, animate or plot a run, sweep many.",
)  # fmt: skip
console = Console(stderr=True)


def _print_version(value: bool) -> None:
    if value:
        from tmem import __version__

        _say(f"tmem {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: bool = typer.Option(False, "--version", callback=_print_version, is_eager=True, help="Print the version and exit."),
) -> None:
    """Run a scenario, reproduce the paper, animate or plot a run, sweep many."""

def _fail(message: str | Exception) -> None:
    """Say ``message`` as one line on standard error (:func:`tmem.cli.messages.error_line`) and exit with status 2.

    An error raised while a signal was being handled is the signal's: the command ends as interrupted
    (:func:`tmem.files.outputs.signals.interrupted`).
    """
    from tmem.files.outputs.signals import interrupted

    if interrupted():
        raise KeyboardInterrupt
    if isinstance(message, OSError) and message.filename and message.strerror:
        message = f"{message.filename}: {message.strerror}"
    console.print(f"[bold red]error:[/] {escape(error_line(str(message)))}", highlight=False, soft_wrap=True)
    raise typer.Exit(2)


def _say(text: str) -> None:
    """Print ``text`` to standard output as one line: no markup, no highlighting, no wrapping (a path stays
    whole), control characters escaped (:func:`tmem.files.outputs.one_line`)."""
    Console().print(one_line(text), markup=False, highlight=False, soft_wrap=True)


def _say_written(write, *args, **kwargs) -> None:
    """Write one file, ``write(*args, **kwargs)`` returning its path, and say ``written PATH``; a
    :class:`ValueError` or :class:`OSError` ends the command in one line (:func:`_fail`)."""
    try:
        path = write(*args, **kwargs)
    except (ValueError, OSError) as exc:
        _fail(exc)
    _say(f"written {path}")


def _resuming(time: float) -> None:
    console.print(f"going on from the checkpoint at t = {time:g} s", highlight=False, soft_wrap=True)


@app.command()
def run(
    scenario: Path = typer.Argument(..., metavar="SCENARIO", help="Scenario TOML file (see examples/)."),
    out: Path = typer.Option(..., "--out", "-o", help="Output directory; replaced only if it holds an earlier run."),
    checkpoint_every: float = typer.Option(
        None, "--checkpoint-every", metavar="SECONDS", show_default="none",
        help="Save the whole state every SECONDS (s) of simulated time beside OUT; run again, a killed run resumes.",
    ),  # fmt: skip
) -> None:
    """Simulate SCENARIO and write summary.json, trajectory.nc and figures to OUT.

    The figures: velocity.png, paths.png and, where the run has them, distance.png,
    formation.png, shape.png, gas.png, field.png.
    \f
    Parameters
    ----------
    scenario : Path
        Scenario TOML file.
    out : Path
        Output directory (replaced if it holds an earlier run).
    checkpoint_every : float or None
        Simulated seconds between checkpoints (:mod:`tmem.engine.checkpoint`); None: no checkpoints.
    """
    from tmem.engine import CheckpointError, Checkpoints, SimulationError, simulate
    from tmem.engine.checkpoint import checkpoint_path
    from tmem.files.io import OutputError, check_output_directory, write_run
    from tmem.scenario import ScenarioError, load

    progress = LazyProgress(console)
    checkpoints = None
    try:
        loaded = load(scenario)
        check_output_directory(out)
        if checkpoint_every is not None:
            checkpoints = Checkpoints(checkpoint_path(out), checkpoint_every, on_resume=_resuming)
        trajectory = simulate(loaded, progress=lambda done, total: progress(scenario.name, done, total), checkpoints=checkpoints)
        progress.close()
        summary = write_run(trajectory, out)
        if checkpoints is not None:
            checkpoints.remove()
    except (ScenarioError, OutputError, SimulationError, CheckpointError) as exc:
        progress.close()
        _fail(exc)
    except KeyboardInterrupt:
        progress.close()
        if checkpoints is None or checkpoints.saved_time is None:
            raise
        said = f"interrupted; no output was written; the same command goes on from t = {checkpoints.saved_time:g} s"
        console.print(said, highlight=False, soft_wrap=True)
        raise typer.Exit(130) from None
    Console().print(summary_table({loaded.name or scenario.stem: summary}))
    _say(f"written to {out}/")


@app.command()
def paper(
    out: Path = typer.Option(Path("out/paper"), "--out", "-o", help="Output directory; replaced only if it holds an earlier paper."),
) -> None:
    """Reproduce the paper's Figs. 5, 7 and 9 into OUT/fig5, OUT/fig7, OUT/fig9 and OUT/report.md.

    Each figure's folder holds a run as tmem run writes it; the report's reruns under the paper's
    further work go to OUT/fig7-energy, OUT/fig9-energy, OUT/fig7-sync and OUT/fig9-sync.
    \f
    Parameters
    ----------
    out : Path
        Output directory.
    """
    from tmem.engine import SimulationError
    from tmem.files.io import OutputError
    from tmem.paper.report import run_paper

    progress = LazyProgress(console)
    try:
        summaries, _ = run_paper(out, progress=progress)
    except (OutputError, SimulationError) as exc:
        progress.close()
        _fail(exc)
    progress.close()
    Console().print(summary_table(summaries))
    _say(f"report: {out / 'report.md'}")


@app.command("animate")
def animate_command(
    run_dir: Path = typer.Argument(..., metavar="RUN_DIR", help="A run directory written by tmem run (a 2-D or 3-D run)."),
    out: Path = typer.Option(
        None, "--out", "-o", show_default="RUN_DIR.gif beside RUN_DIR",
        help="Animation file: .gif, or .mp4 with ffmpeg; replaced only if tmem animate wrote it.",
    ),
    fps: int = typer.Option(20, help="Frames per second of the animation."),
    max_frames: int = typer.Option(400, help="Most frames drawn; the recorded times are thinned evenly to this many."),
) -> None:
    """Animate a run: agents, interaction circles, coupled pairs coloured by strain, and a clock.

    A 3-D run is drawn as a 3-D view beside its projection on (x, y). The file goes beside the run
    directory, never into it, as tmem view's and tmem export's do.
    \f
    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``.
    out : Path or None
        Animation file (``.gif``, or ``.mp4`` with ffmpeg); default ``RUN_DIR.gif`` beside the run directory.
    fps : int
        Frames per second.
    max_frames : int
        Most frames; the recorded times are thinned evenly.
    """
    for option, value in (("--fps", fps), ("--max-frames", max_frames)):
        if value < 1:
            _fail(f"{option}: must be at least 1, got {value}")
    from tmem.figures.animate import animate

    _say_written(animate, run_dir, out, fps=fps, max_frames=max_frames)


@app.command("plot")
def plot_command(
    run_dir: Path = typer.Argument(..., metavar="RUN_DIR", help="A run directory written by tmem run, or a run of tmem paper."),
    out: Path = typer.Option(
        None, "--out", "-o", show_default="RUN_DIR", help="Directory for the figures; replaced only if it holds earlier ones."
    ),
) -> None:
    """Draw a saved run's figures again, from its trajectory.nc and summary.json.

    The figures are those tmem run writes; in RUN_DIR they replace their namesakes all at once.
    \f
    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``.
    out : Path or None
        Directory for the figures; default ``RUN_DIR``.
    """
    from tmem.figures.plot import redraw

    try:
        paths = redraw(run_dir, out)
    except (ValueError, OSError) as exc:
        _fail(exc)
    if not paths:
        _say(f"{run_dir}: the run recorded nothing to draw")
        return
    _say(f"written {', '.join(p.name for p in paths)} to {paths[0].parent}/")


@app.command("export")
def export_command(
    run_dir: Path = typer.Argument(..., help="A run directory written by `tmem run`."),
    to: str = typer.Option(..., "--to", help="mcap: Foxglove's messages in one file; csv: Crazyswarm2-style, a file per agent."),
    out: Path = typer.Option(
        None, "--out", "-o", show_default="RUN_DIR.mcap or RUN_DIR-crazyswarm/ beside RUN_DIR",
        help="Where to write; replaced only if tmem export wrote it.",
    ),
) -> None:
    """Export a run for the field's tools: an MCAP file for Foxglove, or CSV files for Crazyswarm2.

    The export goes beside the run directory, never into it, as tmem view's and tmem animate's do.

    \f
    Parameters
    ----------
    run_dir : Path
        The run to export: a directory written by ``tmem run``.
    to : str
        ``mcap`` or ``csv`` (``docs/exchange.md``).
    out : Path or None
        Where to write; default ``RUN_DIR.mcap`` or ``RUN_DIR-crazyswarm/`` beside the run directory.
    """
    from tmem.files.exchange import export

    _say_written(export, run_dir, to, out)


@app.command("sweep")
def sweep_command(
    sweep_file: Path = typer.Argument(..., metavar="SWEEP_FILE", help="Sweep TOML file (see examples/sweeps/ and docs/sweeps.md)."),
    out: Path = typer.Option(..., "--out", "-o", help="Output directory; run again to resume an interrupted sweep."),
    scheduler: str = typer.Option(None, show_default="a local cluster", help="Address of an existing Dask scheduler."),
    workers: str = typer.Option(None, metavar="N", show_default="one per core", help="Worker processes of the local cluster."),
) -> None:
    """Run every case of SWEEP_FILE on Dask; write results.parquet, summary.md and figures to OUT.

    OUT also holds sweep.toml and sweep.json, and parts/ while cases run (docs/sweeps.md).
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
    from tmem.files.io import OutputError
    from tmem.sweep import SweepError, SweepInterrupted, load_sweep, run_sweep
    from tmem.sweep.cluster import check_workers

    try:
        count = check_workers(workers, scheduler)
        sweep = load_sweep(sweep_file)
    except SweepError as exc:
        _fail(exc)
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
                notify=lambda line: console.print(f"[yellow]warning:[/] {escape(one_line(line))}", highlight=False, soft_wrap=True),
            )  # fmt: skip
    except (SweepError, OutputError) as exc:
        _fail(exc)
    except SweepInterrupted as exc:
        console.print(escape(one_line(str(exc))), highlight=False, soft_wrap=True)
        raise typer.Exit(130) from None
    _say(
        f"{len(outcome.table)} cases ({outcome.ran} run now, {outcome.failed} failed) in {outcome.seconds:.1f} s; "
        f"written to {out}/results.parquet and {out}/summary.md"
    )


@app.command("view")
def view_command(
    run_dir: Path = typer.Argument(..., metavar="RUN_DIR", help="A run directory written by tmem run (1-D, 2-D or 3-D)."),
    out: Path = typer.Option(
        None, "--out", "-o", show_default="RUN_DIR.html beside RUN_DIR", help="The HTML file; replaced only if tmem view wrote it."
    ),
    max_agents: int = typer.Option(None, show_default="1000 agents", help="Most agents shown; larger swarms are thinned evenly."),
    max_frames: int = typer.Option(None, show_default="1000 frames, fewer for large swarms", help="Most recorded times shown."),
) -> None:
    """Write a viewer of a run: one HTML file that plays it in a browser, offline.

    The page goes beside the run directory, never into it, as tmem animate's and tmem export's do.

    \f
    Parameters
    ----------
    run_dir : Path
        A run directory written by ``tmem run``.
    out : Path or None
        The HTML file; default ``RUN_DIR.html`` beside the run directory.
    max_agents : int or None
        Most agents shown; default :data:`tmem.figures.viewer.data.MAX_AGENTS`.
    max_frames : int or None
        Most recorded times shown; default :data:`tmem.figures.viewer.data.MAX_FRAMES`, fewer for large swarms.
    """
    for option, value in (("--max-agents", max_agents), ("--max-frames", max_frames)):
        if value is not None and value < 1:
            _fail(f"{option}: must be at least 1, got {value}")
    from tmem.figures.viewer import MAX_AGENTS, write_view

    _say_written(write_view, run_dir, out, max_agents=max_agents or MAX_AGENTS, max_frames=max_frames)


def main() -> None:
    """Entry point of the ``tmem`` console script."""
    import warnings

    from tmem.cli.messages import show_warning
    from tmem.files.outputs import handle_termination, ignore_interrupts

    warnings.showwarning = show_warning  # a doubtful value is one line, "warning: ...", as an error is
    handle_termination()  # SIGTERM and SIGHUP as Ctrl-C: interrupted writes leave nothing behind
    try:
        app()
    except KeyboardInterrupt:
        console.print("interrupted; no output was written")
        sys.exit(130)
    finally:
        ignore_interrupts()  # the work is over: a signal while Python shuts down must not become the exit status
