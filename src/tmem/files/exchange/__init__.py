"""A run passed on to the tools of the field: ``tmem export DIR --to mcap`` or ``--to csv``.

* :mod:`~tmem.files.exchange.recording` — the run directory read back (``trajectory.nc``);
* :mod:`~tmem.files.exchange.attitude` — an agent's attitude quaternion: the recorded body attitude, else its tilts';
* :mod:`~tmem.files.exchange.foxglove` — an MCAP file of Foxglove's messages (the 3-D scene, plots);
* :mod:`~tmem.files.exchange.crazyswarm` — Crazyswarm2-style CSV files, one per agent.

``trajectory.nc`` itself follows CF's trajectories (:mod:`tmem.files.trajectory_file`), and a
scenario's agents may come from a Crazyswarm2 ``crazyflies.yaml`` (:mod:`tmem.scenario.crazyflies`).
The formats, the frame and the numbering are in ``docs/exchange.md``.  Every export is written
under a temporary name and renamed into place when complete (:mod:`tmem.files.outputs`).
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["DEFAULT_OUT", "FORMATS", "export"]

#: The formats, and what each appends to the run directory's name when no ``out`` is given: the
#: export goes beside the run directory ``NAME``, as ``NAME.mcap`` or the folder ``NAME-crazyswarm``.
DEFAULT_OUT = {"mcap": ".mcap", "csv": "-crazyswarm"}
FORMATS = tuple(DEFAULT_OUT)


def export(run_dir: str | Path, to: str, out: str | Path | None = None) -> Path:
    """Write the run in ``run_dir`` as ``to`` (``"mcap"``: a file, ``"csv"``: a directory of files); return where.

    Parameters
    ----------
    run_dir : str or Path
        A directory written by ``tmem run`` (or its ``trajectory.nc``).
    to : str
        One of :data:`FORMATS`.
    out : str or Path, optional
        Where to write; by default beside the run directory ``NAME``: ``NAME.mcap``, or the folder
        ``NAME-crazyswarm`` (:data:`DEFAULT_OUT`, :func:`tmem.files.outputs.beside`).  An existing
        ``out`` is replaced only if ``tmem export`` wrote it and it is still as written.

    Raises
    ------
    ValueError
        In one line: an unknown format, a ``run_dir`` that is not a tmem run
        (:func:`~tmem.files.exchange.recording.read_recording`), an ``out`` that may not be written
        (:class:`tmem.files.outputs.OutputError`).
    """
    from tmem.files.outputs import beside, check_directory, check_file
    from tmem.files.exchange.recording import read_recording

    if to not in FORMATS:
        raise ValueError(f"--to: must be one of {', '.join(FORMATS)}, got {to!r}")
    run_dir = Path(run_dir)
    label = "--out " if out is not None else ""
    target = Path(out) if out is not None else beside(run_dir, DEFAULT_OUT[to])
    if to == "mcap":
        from tmem.files.exchange.foxglove import EXPORT_MARK, export_mcap

        check_file(target, mark=EXPORT_MARK, label=label)
        return export_mcap(read_recording(run_dir), target, label)
    from tmem.files.exchange.crazyswarm import export_csv

    check_directory(target, "export")
    return export_csv(read_recording(run_dir), target)
