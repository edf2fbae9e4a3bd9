"""The animation's file writers: GIF through Pillow, MP4 through ffmpeg, each fed from the canvas as last drawn."""

from __future__ import annotations

from pathlib import Path

from matplotlib import animation
from PIL import Image

from tmem import __version__
from tmem.files.outputs import ANIMATE_MARK


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


def abandon(writer: animation.AbstractMovieWriter) -> None:
    """Stop a writer without writing the file (an ffmpeg process is ended).

    Parameters
    ----------
    writer : matplotlib.animation.AbstractMovieWriter
        A writer of :func:`writer_for`, set up.
    """
    process = getattr(writer, "_proc", None)
    if process is not None:
        process.kill()
        process.wait()


def writer_for(out: Path, fps: float) -> animation.AbstractMovieWriter:
    """The writer for ``out``'s suffix: Pillow for ``.gif``, ffmpeg for ``.mp4``.

    Parameters
    ----------
    out : Path
        The animation file.
    fps : float
        Frames per second.

    Raises
    ------
    ValueError
        In one line: another suffix, or MP4 without ffmpeg.
    """
    suffix = out.suffix.lower()
    if suffix == ".gif":
        return _CanvasPillowWriter(fps=fps)
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ValueError("animate: writing MP4 needs ffmpeg; write a .gif instead")
        return _CanvasFFMpegWriter(fps=fps, metadata={"comment": f"{ANIMATE_MARK} {__version__}"})
    raise ValueError(f"animate: cannot write {out.name!r}; name a .gif or .mp4 file")
