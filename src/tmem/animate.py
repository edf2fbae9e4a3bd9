"""Animation of a 2-D run from its ``trajectory.nc``.

Each frame shows, in the (x, y) plane at one recorded time:

* the agents as dots at their positions ``P``;
* each agent's interaction circle of radius ``R`` (thin and translucent;
  left out when more than :data:`MAX_CIRCLES` agents are drawn);
* every coupled pair (``F_en = 1``) as a solid line, coloured by its strain
  ``|P_j - P_i| / d_t - 1`` (black at the set distance ``d_t``, blue when
  closer, red when farther), and every uncoupled formation edge as a faint dashed line
  (left out when there are more than :data:`MAX_DASHED_EDGES` of them);
* removed agents (``active`` went from 1 to 0) as grey crosses at their last
  active position; agents not yet added are hidden;
* a clock, ``t = 12.3 s``.

The view is fixed for the whole animation: equal aspect, limits covering every
drawn position with a margin of ``R`` (at least 2 % of the extent).  Runs of
more than :data:`MAX_AGENTS_DRAWN` agents are thinned to that many, chosen
evenly; edges are drawn between drawn agents only.  The static part of the
figure is drawn once; each frame updates the moving artists and blits them
over it, so a 400-frame GIF of 20 agents takes a few seconds.
"""

from __future__ import annotations

import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib import animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.colors import LinearSegmentedColormap, Normalize, to_rgba_array
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from PIL import Image

from . import __version__
from .outputs import ANIMATE_MARK, check_file, replace_file
from .plot import draw_region
from .trajectory_file import Refused, open_trajectory, positions, read_run, run_axes

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


@dataclass
class _Run:
    """What is drawn of a run, at the chosen frames and agents."""

    time: np.ndarray  # (frame,)
    pos: np.ndarray  # (frame, agent, 2)
    active: np.ndarray  # (frame, agent), bool
    col_i: np.ndarray  # (edge,): column in ``pos`` of each edge's first agent
    col_j: np.ndarray  # (edge,)
    flag: np.ndarray  # (frame, edge): F_en
    d_t: np.ndarray  # (edge,): set distance, NaN when not known
    radius: float
    name: str
    box: list | None  # the walled box's sides, None without walls
    obstacles: list  # (center, radius) of each obstacle


def _columns(ids: np.ndarray, wanted: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where each of ``wanted`` is in ``ids``, and whether it is there at all."""
    order = np.argsort(ids)
    k = order[np.clip(np.searchsorted(ids, wanted, sorter=order), 0, len(ids) - 1)]
    return k, ids[k] == wanted


def _load(run_dir: Path, max_frames: int) -> _Run:
    """Read the frames and agents to draw; a missing, damaged or truncated ``trajectory.nc`` is refused in one line."""
    return read_run(run_dir, "animate", lambda path: _read(path, max_frames))


def _read(path: Path, max_frames: int) -> _Run:
    """Read the frames and agents to draw from ``path``; refuse runs that are not 2-D."""
    with open_trajectory(path) as ds:
        n_axes = len(run_axes(ds))
        if n_axes != 2:
            noun = "axis" if n_axes == 1 else "axes"
            raise Refused(f"animate: the run has {n_axes} {noun}; only 2-D runs can be animated")
        if ds.sizes["time"] == 0 or ds.sizes["agent"] == 0:
            raise Refused("animate: the run has no recorded times or agents")
        try:
            scenario = tomllib.loads(ds.attrs["scenario"])
            radius = float(scenario["interaction"]["radius"])
        except (KeyError, TypeError, ValueError) as error:
            raise Refused(f"animate: {path}: the run's scenario attribute gives no interaction.radius") from error
        sub = ds.isel(time=_evenly(ds.sizes["time"], max_frames), agent=_evenly(ds.sizes["agent"], MAX_AGENTS_DRAWN))
        pos = positions(sub)
        active = sub["active"].transpose("time", "agent").values.astype(bool) if "active" in sub else np.ones(pos.shape[:2], bool)
        # Edges whose two agents are both drawn (``pair_i``/``pair_j`` hold agent indices).
        col_i, ok_i = _columns(sub["agent"].values, ds["pair_i"].values)
        col_j, ok_j = _columns(sub["agent"].values, ds["pair_j"].values)
        kept = np.flatnonzero(ok_i & ok_j)
        if "d_t" in ds:
            d_t = ds["d_t"].values[kept].astype(float)
        else:
            d_t = np.full(kept.size, float(scenario["interaction"].get("d_t", np.nan)))
        return _Run(
            time=sub["time"].values.astype(float),
            pos=pos,
            active=active,
            col_i=col_i[kept],
            col_j=col_j[kept],
            flag=sub["F_en"].isel(pair=kept).transpose("time", "pair").values if kept.size else np.zeros((sub.sizes["time"], 0), np.int8),
            d_t=d_t,
            radius=radius,
            name=str(scenario.get("name", "")),
            box=scenario["space"]["box"] if scenario.get("space", {}).get("walls") else None,
            obstacles=[(o["center"], o["radius"]) for o in scenario.get("obstacles", [])],
        )


class _CanvasPillowWriter(animation.PillowWriter):
    """Matplotlib's Pillow GIF writer, fed from the canvas as last drawn.

    The stock writer saves the whole figure again for every frame; here each
    frame is drawn by blitting (static background plus the moving artists)
    and taken from the canvas as it is.  Frames are mapped onto one
    256-colour palette made from the first frame, which already shows every
    colour in use (agents, legend, strain colour bar): far quicker than an
    adaptive palette per frame, and a quarter of the memory of RGB frames.
    """

    def grab_frame(self, **savefig_kwargs) -> None:
        size = self.fig.canvas.get_width_height()
        rgb = Image.frombuffer("RGBA", size, self.fig.canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
        if not self._frames:
            self._palette = rgb.quantize(method=Image.Quantize.FASTOCTREE)
        self._frames.append(rgb.quantize(palette=self._palette, dither=Image.Dither.NONE))

    def finish(self) -> None:
        self._frames[0].save(
            self.outfile, format="GIF", save_all=True, append_images=self._frames[1:],
            duration=int(1000 / self.fps), loop=0, comment=f"{ANIMATE_MARK} {__version__}".encode(),
        )  # fmt: skip


class _CanvasFFMpegWriter(animation.FFMpegWriter):
    """Matplotlib's ffmpeg writer, fed from the canvas as last drawn (raw RGBA)."""

    def grab_frame(self, **savefig_kwargs) -> None:
        self._proc.stdin.write(self.fig.canvas.buffer_rgba())


def _abandon(writer: animation.AbstractMovieWriter) -> None:
    """Stop a writer without writing the file (an ffmpeg process is ended)."""
    process = getattr(writer, "_proc", None)
    if process is not None:
        process.kill()
        process.wait()


def _polyline(segments: np.ndarray) -> np.ndarray:
    """Segments (n, 2, 2) as one line broken by NaN rows: one path to draw, not n."""
    gaps = np.full((len(segments), 1, 2), np.nan)
    return np.concatenate([segments, gaps], axis=1).reshape(-1, 2)


def _writer(out: Path, fps: float) -> animation.AbstractMovieWriter:
    """The writer for ``out``'s suffix: Pillow for ``.gif``, ffmpeg for ``.mp4``."""
    suffix = out.suffix.lower()
    if suffix == ".gif":
        return _CanvasPillowWriter(fps=fps)
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ValueError("animate: writing MP4 needs ffmpeg; write a .gif instead")
        return _CanvasFFMpegWriter(fps=fps, metadata={"comment": f"{ANIMATE_MARK} {__version__}"})
    raise ValueError(f"animate: cannot write {out.name!r}; name a .gif or .mp4 file")


def _figure(run: _Run, shown: np.ndarray, dpi: int) -> tuple[Figure, dict]:
    """The static figure, drawn once, and its moving artists (not yet drawn)."""
    fig = Figure(figsize=(7, 6), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    seen = shown[np.isfinite(shown).all(axis=-1)]
    if run.box is not None:  # the whole walled box
        seen = np.concatenate([seen, [[0.0, 0.0], run.box]])
    low, high = (seen.min(axis=0), seen.max(axis=0)) if len(seen) else (np.zeros(2), np.zeros(2))
    margin = max(run.radius, 0.02 * (high - low).max())  # R, or enough that no dot is cut at the edge
    ax.set(xlim=(low[0] - margin, high[0] + margin), ylim=(low[1] - margin, high[1] + margin))
    ax.set(aspect="equal", xlabel="x, m", ylabel="y, m")
    ax.grid(alpha=0.3)
    draw_region(ax, run.box, run.box is not None, run.obstacles)
    n_drawn = shown.shape[1]
    title = f"{run.name + ': ' if run.name else ''}{n_drawn} agents drawn, R = {run.radius:g} m"
    ax.set_title(title, parse_math=False)  # the name as written: a ``$`` is not mathtext

    colors = [f"C{i % 10}" for i in range(n_drawn)] if n_drawn <= 20 else "tab:blue"
    # Black at the set distance (or with no d_t known), blue when closer, red when farther.
    strain = LinearSegmentedColormap.from_list("strain", ["tab:blue", "k", "tab:red"]).with_extremes(bad="k")
    moving = {  # drawn in this order over the static background
        "circles": EllipseCollection(
            2 * run.radius, 2 * run.radius, 0, units="xy", offsets=shown[0], offset_transform=ax.transData,
            facecolors=to_rgba_array(colors, 0.06), edgecolors=to_rgba_array(colors, 0.4), linewidths=0.6,
            visible=n_drawn <= MAX_CIRCLES,
        ),
        "dashed": ax.plot([], [], color="0.5", linewidth=0.8, linestyle="--", alpha=0.5)[0],
        "coupled": LineCollection([], cmap=strain, norm=Normalize(-STRAIN_RANGE, STRAIN_RANGE), linewidths=2),
        "crosses": ax.scatter([], [], s=30, marker="x", c="0.5"),
        "dots": ax.scatter(shown[0, :, 0], shown[0, :, 1], s=16 if n_drawn <= 200 else 4, c=colors),
        "clock": ax.text(
            0.02, 0.97, "", transform=ax.transAxes, va="top", family="monospace",
            bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"},
        ),
    }
    for key in ("circles", "coupled"):
        ax.add_collection(moving[key], autolim=False)
    for artist in moving.values():
        artist.set_animated(True)

    handles = [Line2D([], [], ls="", marker="o", color="C0", label="agent")]
    if n_drawn <= MAX_CIRCLES:
        handles.append(Line2D([], [], ls="", marker="o", mfc="none", ms=12, color="C0", label=f"R = {run.radius:g} m"))
    if not run.active.all():
        handles.append(Line2D([], [], ls="", marker="x", color="0.5", label="removed"))
    if run.flag.size:
        handles.append(Line2D([], [], color="k", lw=2, label="coupled (F_en = 1)"))
        handles.append(Line2D([], [], color="0.5", ls="--", label="uncoupled edge"))
        fig.colorbar(moving["coupled"], ax=ax, shrink=0.6, label="coupled edge strain |d| / d_t - 1")
    fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)
    fig.canvas.draw()
    fig.set_layout_engine("none")  # keep the layout of this first draw
    return fig, moving


def _shown_and_removed(run) -> tuple[np.ndarray, np.ndarray]:
    """Positions of the flying agents (NaN otherwise), and of removed agents (inactive after having
    been active), which stay as crosses where last seen flying (NaN otherwise); each (frame, agent, 2)."""
    frame = np.arange(len(run.time))[:, None]
    last = np.maximum.accumulate(np.where(run.active, frame, -1), axis=0)
    seen_last = run.pos[np.maximum(last, 0), np.arange(run.pos.shape[1])]
    cross = np.where((~run.active & (last >= 0))[..., None], seen_last, np.nan)
    shown = np.where(run.active[..., None], run.pos, np.nan)
    return shown, cross


def _update(moving: dict, run, f: int, shown: np.ndarray, cross: np.ndarray, draw_dashed: bool) -> None:
    """Move the artists to frame ``f``: coupled edges coloured by strain, uncoupled ones dashed, agents, clock."""
    ends = np.stack([run.pos[f, run.col_i], run.pos[f, run.col_j]], axis=1)  # (edge, 2, 2)
    flying = run.active[f, run.col_i] & run.active[f, run.col_j]
    on = flying & (run.flag[f] == 1)
    moving["coupled"].set_segments(ends[on])
    moving["coupled"].set_array(np.linalg.norm(ends[on, 1] - ends[on, 0], axis=-1) / run.d_t[on] - 1)
    moving["dashed"].set_data(*_polyline(ends[flying & (run.flag[f] == 0)] if draw_dashed else ends[:0]).T)
    moving["circles"].set_offsets(shown[f])
    moving["dots"].set_offsets(shown[f])
    moving["crosses"].set_offsets(cross[f])
    moving["clock"].set_text(f"t = {run.time[f]:.1f} s")


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
        With a one-line message: a missing folder, no ``trajectory.nc``, one
        that cannot be read (damaged or truncated), a run that is not 2-D,
        no ``interaction.radius`` in the scenario, an output that is neither
        ``.gif`` nor ``.mp4``, or MP4 without ffmpeg; an ``out`` that
        exists and was not written by ``animate`` (:func:`tmem.outputs.check_file`).

    The file is written under a temporary name beside ``out`` and renamed
    when complete: an interrupted animation leaves nothing at ``out``.
    """
    run_dir = Path(run_dir)
    for name, value in (("fps", fps), ("max_frames", max_frames), ("dpi", dpi)):
        if not value > 0:
            raise ValueError(f"animate: {name} must be positive, got {value}")
    label = "--out " if out is not None else ""
    out = Path(out) if out is not None else (run_dir.parent if run_dir.suffix == ".nc" else run_dir) / "animation.gif"
    run = _load(run_dir, max_frames)
    writer = _writer(out, fps)
    check_file(out, label=label)

    shown, cross = _shown_and_removed(run)
    with warnings.catch_warnings():  # a name in a script the font lacks is drawn as boxes, without a warning per glyph
        warnings.filterwarnings("ignore", message=r"Glyph \d+ .* missing from font", category=UserWarning)
        fig, moving = _figure(run, shown, dpi)
    ax = fig.axes[0]
    background = fig.canvas.copy_from_bbox(fig.bbox)
    draw_dashed = np.count_nonzero(run.flag == 0, axis=1).max(initial=0) <= MAX_DASHED_EDGES
    with replace_file(out, label=label) as tmp:
        writer.setup(fig, str(tmp), dpi)
        try:
            for f in range(len(run.time)):
                _update(moving, run, f, shown, cross, draw_dashed)
                fig.canvas.restore_region(background)
                for artist in moving.values():
                    ax.draw_artist(artist)
                writer.grab_frame()
        except BaseException:
            _abandon(writer)
            raise
        writer.finish()
    return out
