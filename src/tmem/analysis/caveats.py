"""What a summary's ΔRMS does not show, said the same way by the printed table and the viewer.

Kept apart from :mod:`tmem.analysis.rms`, which computes the figures with NumPy, so that the command
line reads it without loading NumPy (``tmem --help`` stays light).
"""

from __future__ import annotations

#: What a reader of ΔRMS is told when it swings (:func:`swings`): the printed table and the viewer say it.
SWINGS = "pairs still coupled and oscillating at the end: ΔRMS is an instantaneous value that swings with their oscillation"


def swings(summary: dict) -> bool:
    """Whether a summary's ``rms_change_percent`` swings with an oscillation still going on at the end.

    A summary written before ``rms_change_swings`` existed counts every run that ends with pairs
    coupled as swinging.

    Parameters
    ----------
    summary : dict
        ``summary.json`` as read (:func:`tmem.analysis.metrics.summarize`).
    """
    swinging = summary.get("rms_change_swings", summary.get("rms_change_while_coupled"))
    return bool(swinging) and summary.get("rms_change_percent") is not None
