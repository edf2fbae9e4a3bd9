"""``tmem view``: a saved run as one self-contained HTML page that plays it in a browser.

The page (:mod:`tmem.figures.viewer.page`) shows the run in 1-D, 2-D or 3-D: the
agents, their interaction spheres (circles in 1-D and 2-D) of radius ``R`` on
demand, the formation edges coloured by strain ``(|d| - d_t) / d_t`` on a
scale fitted to the run, removed agents as grey crosses where they stopped, the
obstacles, and a mission's route and goal (a scenario with ``[navigation]``); a
time slider, play/pause and a speed control; the RMS velocity and the pair
distances in panels linked to the time shown.  Agents are numbered from 1, as
in the paper.  Large runs are thinned (:mod:`tmem.figures.viewer.data`) and the page
says what it shows.

It needs no server and no network: three.js and uPlot, shipped in
``tmem/figures/viewer/vendor`` with their licences, are inlined.  ``docs/viewer.md``
describes the controls, the thinning and the measured sizes and load times.
"""

from __future__ import annotations

from pathlib import Path

from tmem.files.outputs import beside, check_file, replace_file
from tmem.files.trajectory_file import RunReadError
from tmem.figures.viewer.data import MAX_AGENTS, read_view
from tmem.figures.viewer.page import VIEW_MARK, render

__all__ = ["MAX_AGENTS", "RunReadError", "default_out", "write_view"]


def default_out(run_dir: str | Path) -> Path:
    """Where the page of ``run_dir`` goes by default: ``NAME.html`` beside the run directory ``NAME``.

    Beside, not inside, as every file derived from a run (:func:`tmem.files.outputs.beside`): a
    file added to a run directory would make ``tmem run`` refuse to replace it.

    Parameters
    ----------
    run_dir : str or Path
        The run directory.
    """
    return beside(run_dir, ".html")


def write_view(run_dir: str | Path, out: str | Path | None = None, max_agents: int = MAX_AGENTS, max_frames: int | None = None) -> Path:
    """Write the viewer page of the run in ``run_dir`` to ``out``, atomically; return ``out``.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``tmem run`` (``trajectory.nc``, ``summary.json``).
    out : str or Path, optional
        The HTML file.  Default: :func:`default_out`.  An existing file is
        replaced only if ``tmem view`` wrote it.
    max_agents : int
        Most agents shown; more are thinned evenly.
    max_frames : int, optional
        Most recorded times shown; default: :data:`tmem.figures.viewer.data.MAX_FRAMES`,
        fewer for large swarms (:func:`tmem.figures.viewer.data.read_view`).

    Raises
    ------
    ValueError
        In one line: a limit below 1, a directory that is not a readable run
        (:class:`~tmem.files.trajectory_file.RunReadError`), or an ``out`` that may not be written
        (:class:`tmem.files.outputs.OutputError`).  Nothing is written then; an
        interrupted write leaves ``out`` as it was.
    """
    for option, value in (("max_agents", max_agents), ("max_frames", max_frames)):
        if value is not None and not (isinstance(value, int) and value >= 1):
            raise ValueError(f"{option}: must be a whole number of at least 1, got {value!r}")
    label = "--out " if out is not None else ""
    out = Path(out) if out is not None else default_out(run_dir)
    check_file(out, mark=VIEW_MARK, label=label)
    text = render(read_view(run_dir, max_agents=max_agents, max_frames=max_frames))
    with replace_file(out, mark=VIEW_MARK, label=label) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return out
