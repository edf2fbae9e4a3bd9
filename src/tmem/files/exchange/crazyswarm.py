"""A run as Crazyswarm2-style CSV files: one per agent, ``timestamp,x,y,z,qw,qx,qy,qz``.

Each recorded agent gets ``agentN.csv``, ``N`` its number as the paper counts agents (the
scenario's index plus 1), with one row per recorded time: the seconds from the start of the run,
the position (m, the run's local frame, z up; 0 on the axes the run does not have) and the
attitude quaternion (the body attitude the run recorded, else the tilts', yaw 0:
:mod:`tmem.files.exchange.attitude`).  Numbers are written in full (the shortest text that reads
back to the same double).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from tmem.files.outputs import replace_directory
from tmem.files.exchange.recording import Recording

__all__ = ["HEADER", "csv_name", "write_csv_files", "export_csv"]

#: The columns of every file.
HEADER = ("timestamp", "x", "y", "z", "qw", "qx", "qy", "qz")


def csv_name(number: int) -> str:
    """The file of agent ``number`` (counted from 1, as in the paper).

    Parameters
    ----------
    number : int
        The agent's number.
    """
    return f"agent{number}.csv"


def write_csv_files(recording: Recording, directory: Path) -> list[Path]:
    """Write one CSV file per recorded agent into ``directory``; return the files.

    Parameters
    ----------
    recording : Recording
        The run (:func:`tmem.files.exchange.recording.read_recording`).
    directory : Path
        An existing directory.
    """
    quaternions = recording.attitude
    written = []
    for k in range(len(recording.agents)):
        rows = np.column_stack([recording.time, recording.positions[:, k], quaternions[:, k]]) + 0.0  # no -0.0
        path = directory / csv_name(recording.number(k))
        with path.open("w", newline="", encoding="ascii") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(HEADER)
            writer.writerows(rows.tolist())  # Python floats: the shortest text that reads back exactly
        written.append(path)
    return written


def export_csv(recording: Recording, out: Path) -> Path:
    """Write the CSV files into the directory ``out``, atomically (:func:`tmem.files.outputs.replace_directory`).

    Parameters
    ----------
    recording : Recording
        The run.
    out : Path
        The directory: absent, empty, or an earlier ``tmem export --to csv`` output, which is replaced.
    """
    with replace_directory(out, "export") as tmp:
        write_csv_files(recording, tmp)
    return out
