"""Animation of a 2-D run from its ``trajectory.nc``.

Each frame shows, in the (x, y) plane at one recorded time:

* the agents as dots at their positions ``P``;
* each agent's interaction circle of radius ``R`` (thin and translucent;
  left out when more than :data:`MAX_CIRCLES` agents are drawn);
* every coupled pair (``F_en = 1``) as a solid line, coloured by its strain
  ``|P_j - P_i| / d_t - 1`` (blue: closer than the set distance ``d_t``,
  red: farther), and every uncoupled formation edge as a faint dashed line
  (left out when there are more than :data:`MAX_DASHED_EDGES` of them);
* removed agents (``active`` went from 1 to 0) as grey crosses at their last
  active position; agents not yet added are hidden;
* a clock, ``t = 12.3 s``.

The view is fixed for the whole animation: equal aspect, limits covering every
drawn position with a margin of ``R``.  Runs of more than
:data:`MAX_AGENTS_DRAWN` agents are thinned to that many, chosen evenly; edges
are drawn between drawn agents only.  Artists are created once and updated per
frame, so a 400-frame GIF of 20 agents takes a few seconds.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib import animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from PIL import Image

#: Most agents drawn; larger runs are thinned evenly to this many.
MAX_AGENTS_DRAWN = 3000
#: Most agents drawn with their interaction circles.
MAX_CIRCLES = 2000
#: Most uncoupled formation edges drawn as dashed lines.
MAX_DASHED_EDGES = 2000
#: Strain ``|d| / d_t - 1`` at the ends of the colour scale of coupled edges.
STRAIN_RANGE = 0.5


def _evenly(n: int, at_most: int) -> np.ndarray:
    """At most ``at_most`` indices into ``range(n)``, evenly spread, first and last kept."""
    if n <= at_most:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, at_most)).astype(int))


def _open(run_dir: Path) -> xr.Dataset:
    path = run_dir if run_dir.suffix == ".nc" else run_dir / "trajectory.nc"
    if not path.is_file():
        raise ValueError(f"animate: no trajectory.nc in {run_dir}")
    ds = xr.open_dataset(path, engine="h5netcdf")
    n_axes = ds.sizes.get("axis", 0)
    if n_axes != 2:
        ds.close()
        noun = "axis" if n_axes == 1 else "axes"
        raise ValueError(f"animate: the run has {n_axes} {noun}; only 2-D runs can be animated")
    if ds.sizes["time"] == 0 or ds.sizes["agent"] == 0:
        ds.close()
        raise ValueError("animate: the run has no recorded times or agents")
    return ds


def _interaction(ds: xr.Dataset) -> tuple[float, float, str]:
    """``R``, the scalar ``d_t`` (NaN when not given) and the scenario's name."""
    try:
        scenario = tomllib.loads(ds.attrs["scenario"])
        radius = float(scenario["interaction"]["radius"])
    except (KeyError, TypeError, tomllib.TOMLDecodeError) as error:
        raise ValueError("animate: the run's scenario attribute gives no interaction.radius") from error
    d_t = float(scenario["interaction"].get("d_t", np.nan))
    return radius, d_t, str(scenario.get("name", ""))


class _CanvasPillowWriter(animation.PillowWriter):
    """Matplotlib's Pillow GIF writer, fed from the canvas as last drawn.

    The stock writer saves the whole figure again for every frame; here the
    frame is drawn by blitting (static background plus the moving artists)
    and taken from the canvas as it is, as a 256-colour image (what the GIF
    holds anyway, and a quarter of the memory).
    """

    def grab_frame(self, **savefig_kwargs) -> None:
        rgb = np.asarray(self.fig.canvas.buffer_rgba())[..., :3]
        self._frames.append(Image.fromarray(rgb).quantize(method=Image.Quantize.FASTOCTREE))


def _writer(out: Path, fps: float) -> animation.AbstractMovieWriter:
    suffix = out.suffix.lower()
    if suffix == ".gif":
        return _CanvasPillowWriter(fps=fps)
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ValueError("animate: writing MP4 needs ffmpeg; write a .gif instead")
        return animation.FFMpegWriter(fps=fps)
    raise ValueError(f"animate: cannot write {out.name!r}; name a .gif or .mp4 file")


def animate(
    run_dir: str | Path,
    out: str | Path | None = None,
    fps: float = 20,
    max_frames: int = 400,
    dpi: int = 100,
) -> Path:
    """Write an animation of a 2-D run.

    Parameters
    ----------
    run_dir : str or Path
        Run directory holding ``trajectory.nc`` (or the path of that file).
    out : str or Path, optional
        Output file, ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).  Default:
        ``animation.gif`` in the run directory.
    fps : float
        Frames per second of the animation.
    max_frames : int
        Most frames; the recorded times are subsampled evenly to this many.
    dpi : int
        Resolution; the figure is 7 x 6 inches.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        With a one-line message: no ``trajectory.nc``, a run that is not 2-D,
        no scenario radius, an unknown output format, or MP4 without ffmpeg.
    """
    run_dir = Path(run_dir)
    if fps <= 0 or max_frames < 1 or dpi <= 0:
        raise ValueError("animate: fps, max_frames and dpi must be positive")
    base = run_dir.parent if run_dir.suffix == ".nc" else run_dir
    out = Path(out) if out is not None else base / "animation.gif"
    with _open(run_dir) as ds:
        writer = _writer(out, fps)
        radius, d_t, name = _interaction(ds)
        frames = _evenly(ds.sizes["time"], max_frames)
        drawn = _evenly(ds.sizes["agent"], MAX_AGENTS_DRAWN)
        sub = ds.isel(time=frames, agent=drawn)
        time = sub["time"].values.astype(float)
        pos = sub["P"].values.astype(float)  # (frame, agent, 2)
        active = sub["active"].values.astype(bool) if "active" in sub else np.ones(pos.shape[:2], bool)
        # Pairs whose two agents are both drawn, as columns of ``pos``.
        ids = sub["agent"].values
        order = np.argsort(ids)
        ends = []
        for name_ij in ("pair_i", "pair_j"):
            want = ds[name_ij].values if name_ij in ds else np.empty(0, int)
            k = np.clip(np.searchsorted(ids, want, sorter=order), 0, len(ids) - 1)
            ends.append((order[k], ids[order[k]] == want))
        (col_i, ok_i), (col_j, ok_j) = ends
        kept = np.flatnonzero(ok_i & ok_j)
        col_i, col_j = col_i[kept], col_j[kept]
        flag = sub["F_en"].isel(pair=kept).values if kept.size else np.zeros((len(frames), 0), np.int8)
        set_distance = sub["d_t"].values[kept].astype(float) if "d_t" in sub else np.full(kept.size, d_t)

    # Last active frame of each agent: removed agents are drawn there as crosses.
    last = np.maximum.accumulate(np.where(active, np.arange(len(frames))[:, None], -1), axis=0)
    removed = ~active & (last >= 0)
    cross = np.where(removed[..., None], pos[np.maximum(last, 0), np.arange(pos.shape[1])], np.nan)
    shown = np.where(active[..., None], pos, np.nan)
    n_drawn = pos.shape[1]

    fig = Figure(figsize=(7, 6), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    seen = shown[np.isfinite(shown).all(axis=-1)]
    low, high = (seen.min(axis=0), seen.max(axis=0)) if len(seen) else (np.zeros(2), np.zeros(2))
    ax.set_xlim(low[0] - radius, high[0] + radius)
    ax.set_ylim(low[1] - radius, high[1] + radius)
    ax.set_aspect("equal")
    ax.set_xlabel("x, m")
    ax.set_ylabel("y, m")
    ax.grid(alpha=0.3)
    title = f"{name}: " if name else ""
    ax.set_title(f"{title}{n_drawn} agents drawn, R = {radius:g} m")

    colors = [f"C{i % 10}" for i in range(n_drawn)] if n_drawn <= 20 else "tab:blue"
    circles = EllipseCollection(
        2 * radius, 2 * radius, 0, units="xy", offsets=shown[0], offset_transform=ax.transData,
        facecolors=colors, edgecolors=colors, alpha=0.08, linewidths=0.5, visible=n_drawn <= MAX_CIRCLES,
    )
    ax.add_collection(circles)
    dashed = ax.add_collection(LineCollection([], colors="0.5", linewidths=0.8, linestyles="--", alpha=0.5))
    coupled = LineCollection([], cmap="coolwarm", norm=Normalize(-STRAIN_RANGE, STRAIN_RANGE), linewidths=2)
    coupled.get_cmap().set_bad("k")  # no d_t known
    ax.add_collection(coupled)
    crosses = ax.scatter(cross[0, :, 0], cross[0, :, 1], s=30, marker="x", c="0.5")
    dots = ax.scatter(shown[0, :, 0], shown[0, :, 1], s=16 if n_drawn <= 200 else 4, c=colors)
    clock = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", family="monospace")
    moving = [circles, dashed, coupled, crosses, dots, clock]  # drawn in this order over the background
    for artist in moving:
        artist.set_animated(True)
    handles = [
        Line2D([], [], ls="", marker="o", color="C0", label="agent"),
        Line2D([], [], ls="", marker="x", color="0.5", label="removed"),
        Line2D([], [], color="k", lw=2, label="coupled (F_en = 1)"),
        Line2D([], [], color="0.5", ls="--", label="uncoupled edge"),
    ]
    if circles.get_visible():
        handles.insert(1, Line2D([], [], ls="", marker="o", mfc="none", ms=12, color="C0", label=f"R = {radius:g} m"))
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)
    if kept.size:
        fig.colorbar(coupled, ax=ax, shrink=0.6, label="coupled edge strain |d| / d_t - 1")
    fig.canvas.draw()  # the static part, laid out once
    fig.set_layout_engine("none")
    background = fig.canvas.copy_from_bbox(fig.bbox)

    draw_dashed = int(np.count_nonzero(flag == 0, axis=1).max(initial=0)) <= MAX_DASHED_EDGES
    out.parent.mkdir(parents=True, exist_ok=True)
    with writer.saving(fig, str(out), dpi):
        for f in range(len(frames)):
            both = active[f, col_i] & active[f, col_j]
            segments = np.stack([pos[f, col_i], pos[f, col_j]], axis=1)
            on = both & (flag[f] == 1)
            coupled.set_segments(segments[on])
            length = np.linalg.norm(segments[on, 1] - segments[on, 0], axis=-1)
            coupled.set_array(length / set_distance[on] - 1)
            dashed.set_segments(segments[both & (flag[f] == 0)] if draw_dashed else [])
            circles.set_offsets(shown[f])
            dots.set_offsets(shown[f])
            crosses.set_offsets(cross[f])
            clock.set_text(f"t = {time[f]:.1f} s")
            fig.canvas.restore_region(background)
            for artist in moving:
                ax.draw_artist(artist)
            writer.grab_frame()
    return out
