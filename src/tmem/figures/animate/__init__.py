"""Animation of a run from its ``trajectory.nc``: on one axis, in the plane or in space.

Each frame shows, at one recorded time (:mod:`tmem.figures.animate.scene`):

* the agents as dots at their positions ``P``, numbered from 1 as in the paper (up to
  :data:`tmem.figures.drawing.MAX_NUMBERED` agents);
* each agent's interaction circle of radius ``R`` (thin and translucent; left out when more than
  :data:`~tmem.figures.animate.scene.MAX_CIRCLES` agents are drawn);
* every coupled pair (``F_en = 1``) as a solid line, coloured by its strain
  ``|P_j - P_i| / d_t - 1`` (black at the set distance ``d_t``, blue when closer, red when
  farther) on a scale fitted to the run: symmetric about 0, reaching the largest ``|strain|`` of a
  coupled pair in the frames drawn, at least 1 % (:func:`tmem.figures.drawing.strain_limit`); every
  uncoupled pair as a faint dashed line (left out when there are more than
  :data:`MAX_DASHED_EDGES` of them);
* removed agents (``active`` went from 1 to 0) as grey crosses at their last active position;
  agents not yet added are hidden;
* a clock, ``t = 12.3 s``.

A run on one axis (the paper's) is drawn on the line ``y = 0``; a 2-D run in the (x, y) plane; a
3-D run as a 3-D view beside its (x, y) projection.
Runs of more than :data:`~tmem.figures.animate.frames.MAX_AGENTS_DRAWN` agents are thinned to that many,
chosen evenly, and the title says so; pairs are drawn between drawn agents only.  The static part
of the figure is drawn once; each frame updates the moving artists and blits them over it, so a
400-frame GIF of 20 agents takes a few seconds.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from tmem.files.outputs import beside, check_file, replace_file
from tmem.figures.animate.frames import read_frames
from tmem.figures.animate.scene import positions, scene, update
from tmem.figures.animate.writers import abandon, writer_for

__all__ = ["MAX_DASHED_EDGES", "animate"]

#: Most uncoupled pairs drawn as dashed lines.
MAX_DASHED_EDGES = 2000


def _draw(fig, moving: dict, background) -> None:
    """Restore the static background and draw the moving artists over it (3-D ones projected first)."""
    fig.canvas.restore_region(background)
    for artist in moving.values():
        if hasattr(artist, "do_3d_projection"):
            artist.do_3d_projection()
        artist.axes.draw_artist(artist)


def animate(
    run_dir: str | Path,
    out: str | Path | None = None,
    fps: float = 20,
    max_frames: int = 400,
    dpi: int = 100,
) -> Path:
    """Write an animation of a run on 1, 2 or 3 axes.

    Parameters
    ----------
    run_dir : str or Path
        Run directory holding ``trajectory.nc`` (or the path of that file).
    out : str or Path, optional
        Output file, ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).  Default:
        ``NAME.gif`` beside the run directory ``NAME`` (:func:`tmem.files.outputs.beside`).
    fps : float
        Frames per second of the animation.
    max_frames : int
        Most frames; the recorded times are subsampled evenly to this many.
    dpi : int
        Resolution; the figure is 7 x 6 inches (9 x 3.6 for a run on one axis, 12 x 6 in 3-D).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        With a one-line message: a missing folder, no ``trajectory.nc``, one
        that cannot be read (damaged or truncated), nothing recorded,
        no ``interaction.radius`` in the scenario, an output that is neither
        ``.gif`` nor ``.mp4``, or MP4 without ffmpeg; an ``out`` that
        exists and was not written by ``animate`` (:func:`tmem.files.outputs.check_file`).

    The file is written under a temporary name beside ``out`` and renamed
    when complete: an interrupted animation leaves nothing at ``out``.
    """
    run_dir = Path(run_dir)
    for name, value in (("fps", fps), ("max_frames", max_frames), ("dpi", dpi)):
        if not value > 0:
            raise ValueError(f"animate: {name} must be positive, got {value}")
    label = "--out " if out is not None else ""
    out = Path(out) if out is not None else beside(run_dir, ".gif")
    check_file(out, label=label)  # before anything is read: what stands at out is never opened unless tmem wrote it
    writer = writer_for(out, fps)
    run = read_frames(run_dir, max_frames)
    _write(run, writer, out, label, dpi)
    return out


def _write(run, writer, out: Path, label: str, dpi: int) -> None:
    """Draw the figure once, then every frame of ``run`` over it into ``writer``, under a temporary
    name beside ``out`` that becomes ``out`` when the last frame is in."""
    shown, cross = positions(run)
    with warnings.catch_warnings():  # a name in a script the font lacks is drawn as boxes, without a warning per glyph
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .* missing from font", category=UserWarning)
        fig, moving = scene(run, shown, dpi)
    background = fig.canvas.copy_from_bbox(fig.bbox)
    draw_dashed = np.count_nonzero(run.flag == 0, axis=1).max(initial=0) <= MAX_DASHED_EDGES
    with replace_file(out, label=label) as tmp:
        writer.setup(fig, str(tmp), dpi)
        try:
            for f in range(len(run.time)):
                update(moving, run, f, shown, cross, draw_dashed)
                _draw(fig, moving, background)
                writer.grab_frame()
        except BaseException:
            abandon(writer)
            raise
        writer.finish()
