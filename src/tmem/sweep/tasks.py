"""One Dask task: a chunk of a sweep's cases run on a worker, each turned into a row.

A chunk holds cases that differ only in the agents' starting positions and
velocities (:func:`plan_chunks` groups them so).  If the scenario is the
paper's two-agent, one-axis case and every kept metric is one the batch
computes, the whole chunk runs as one vectorised batch
(:func:`tmem.batch.encounters.run_batch`); otherwise each case is simulated on its own
and summarised (:func:`tmem.analysis.metrics.summarize`).  Either way a case that
fails (a value the scenario refuses, a run that diverges) becomes a row with
its error and no metrics; it never stops the chunk.

A row is ``{"case": number, <parameter path>: value, ..., <metric>: value,
..., "error": message or None, "seconds": compute time}``.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Iterable
from typing import Any

import numpy as np

from tmem.batch.encounters import run_batch, unsupported
from tmem.engine import DIVERGED, simulate
from tmem.analysis.metrics import summarize
from tmem.scenario import Scenario, ScenarioError, with_changes
from tmem.sweep.spec import SCALAR_METRICS, Case

#: The parameter paths a batch takes per case: the two agents' starts.
START_PATH = re.compile(r"agents\.([01])\.(position|velocity)")
#: Cases per task when the sweep file gives no ``batch``: batched chunks, and one-by-one runs.
BATCH_CHUNK = 500
SINGLE_CHUNK = 1


def _shared(case: Case) -> dict[str, Any]:
    return {p: v for p, v in case.changes.items() if not START_PATH.fullmatch(p)}


def batchable(scenario: Scenario, metrics: tuple[str, ...]) -> bool:
    """Whether cases of ``scenario`` run as one batch: the paper's case, and only the batch's metrics kept.

    Parameters
    ----------
    scenario : Scenario
        The scenario the cases share.
    metrics : tuple of str
        The metrics kept in each row.
    """
    return unsupported(scenario) is None and set(metrics) <= set(SCALAR_METRICS)


def plan_chunks(base: Scenario, cases: Iterable[Case], metrics: tuple[str, ...], size: int | None) -> list[list[Case]]:
    """Group cases with the same changes apart from the agents' starts, and cut each group into chunks.

    ``size`` is the sweep's ``batch``; by default :data:`BATCH_CHUNK` cases
    where a group runs as a batch and :data:`SINGLE_CHUNK` where its cases
    run one by one (so that they spread over the workers).

    Parameters
    ----------
    base : Scenario
        The sweep's base scenario.
    cases : list of Case
        The cases, each a set of changes to ``base``.
    metrics : tuple of str
        The metrics kept in each row (the sweep file's ``metrics``).
    size : int or None
        Cases per chunk; ``None``: as above.
    """
    groups: dict[str, list[Case]] = {}
    for case in cases:
        groups.setdefault(repr(sorted(_shared(case).items())), []).append(case)
    chunks = []
    for group in groups.values():
        n = size or SINGLE_CHUNK
        if size is None and len(group) > 1:
            try:
                n = BATCH_CHUNK if batchable(with_changes(base, _shared(group[0])), metrics) else SINGLE_CHUNK
            except ScenarioError:
                pass  # the cases fail one by one, each with its error
        chunks += [group[k : k + n] for k in range(0, len(group), n)]
    return chunks


def _value(summary: dict, metric: str) -> Any:
    node: Any = summary
    for part in metric.split("."):
        if isinstance(node, list):
            node = node[int(part)] if int(part) < len(node) else None
        elif isinstance(node, dict):
            node = node.get(part)
        if node is None:
            return None
    return node


def one_line(exc: BaseException) -> str:
    """An exception as one line: its class and its message with whitespace folded.

    Parameters
    ----------
    exc : BaseException
        The exception a case raised.
    """
    message = " ".join(str(exc).split())
    return f"{exc.__class__.__name__}: {message}" if message else exc.__class__.__name__


def row(case: Case, metrics: tuple[str, ...], values: dict | None, error: str | None, seconds: float) -> dict:
    """One case's row: its number, its changes, the metrics, the error and the compute time.

    Parameters
    ----------
    case : Case
        The case.
    metrics : tuple of str
        The metrics kept.
    values : dict or None
        Each metric's value; ``None`` for a case that failed (every metric ``None``).
    error : str or None
        Why the case failed (:func:`one_line`), or ``None``.
    seconds : float
        Compute time of the case (s).
    """
    row = {"case": case.index, **case.changes}
    row.update({m: None if values is None else values[m] for m in metrics})
    row["error"] = error
    row["seconds"] = seconds
    return row


def _run_one(base: Scenario, case: Case, metrics: tuple[str, ...]) -> dict:
    started = time.perf_counter()
    try:
        summary = summarize(simulate(with_changes(base, case.changes)))
    except Exception as exc:  # a failing case is a row with its error, never the end of the sweep
        return row(case, metrics, None, one_line(exc), time.perf_counter() - started)
    return row(case, metrics, {m: _value(summary, m) for m in metrics}, None, time.perf_counter() - started)


def _run_as_batch(scenario: Scenario, cases: list[Case], starts: np.ndarray, metrics: tuple[str, ...]) -> list[dict]:
    """Rows of ``cases`` run as one batch of ``scenario`` from ``starts`` (case, agent, position / velocity)."""
    started = time.perf_counter()
    result = run_batch(scenario, starts[:, :, 0], starts[:, :, 1])
    columns = {m: getattr(result, m) for m in metrics}
    seconds = (time.perf_counter() - started) / len(cases)
    rows = []
    for c, case in enumerate(cases):
        values = {m: _python(columns[m][c]) for m in metrics}
        diverged = not np.all(np.isfinite(result.final_velocities[c])) or not np.isfinite(result.final_distance[c])
        rows.append(row(case, metrics, None if diverged else values, DIVERGED if diverged else None, seconds))
    return rows


def _python(value: Any) -> Any:
    """A batch figure as ``summary.json`` has it: NaN (an event that did not happen) as None."""
    value = value.item() if isinstance(value, np.generic) else value
    return None if isinstance(value, float) and math.isnan(value) else value


def run_chunk(base: Scenario, cases: list[Case], metrics: tuple[str, ...]) -> list[dict]:
    """The rows of ``cases`` (one chunk of :func:`plan_chunks`), in order.

    Parameters
    ----------
    base, cases, metrics
        As :func:`plan_chunks` takes them; ``cases`` one of the chunks it plans.
    """
    try:
        scenario = with_changes(base, _shared(cases[0]))
    except ScenarioError:
        scenario = None  # every case fails alike; _run_one words its error
    if scenario is None or not batchable(scenario, metrics):
        return [_run_one(base, case, metrics) for case in cases]
    # Each case's scenario is checked as a single run's would be (two agents at one point, a
    # value out of range...); one the scenario refuses runs alone, so that its error is worded.
    fits, starts = [], []
    for case in cases:
        try:
            agents = with_changes(base, case.changes).agents
        except ScenarioError:
            continue
        fits.append(case)
        starts.append([[a.position, a.velocity] for a in agents])
    rows = {row["case"]: row for row in (_run_as_batch(scenario, fits, np.array(starts), metrics) if fits else [])}
    return [rows.get(c.index) or _run_one(base, c, metrics) for c in cases]
