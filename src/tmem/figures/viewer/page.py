"""The viewer's page: one HTML file holding the run, the libraries and the viewer's own scripts.

Nothing is fetched when the page opens.  The libraries shipped in
``tmem/figures/viewer/vendor`` (three.js and its ``OrbitControls``, uPlot) and the
viewer's modules in ``tmem/figures/viewer/web`` are inlined: the ES modules through
an import map of ``data:`` URLs, uPlot as a classic script.  The run is a JSON
block (:func:`page_data`) whose large arrays are base64 strings of typed
arrays: positions and speeds as 16-bit steps above a low value (per axis), the
rest as 32-bit floats and bytes.
"""

from __future__ import annotations

import base64
import html
import json
import re
from importlib import resources

import numpy as np

from tmem import __version__
from tmem.analysis.caveats import SWINGS, swings
from tmem.figures.viewer.data import View

#: The mark of a file written by ``tmem view`` (in the page's first line of comment).
VIEW_MARK = "written by tmem view"
#: The ES modules of the import map: name -> (folder, file); the viewer's own, ``tmem/NAME``, are
#: ``web/NAME.js``.
MODULES = {
    "three": ("vendor", "three.module.min.js"),
    "three/addons/OrbitControls": ("vendor", "OrbitControls.js"),
    **{f"tmem/{name}": ("web", f"{name}.js") for name in ("run", "edges", "axes", "route", "scene", "charts", "main")},
}
#: The licences of the libraries inlined, appended to the page.
LICENCES = ("LICENSE.three.txt", "LICENSE.uPlot.txt")
#: Steps of the 16-bit positions and speeds.
_LEVELS = 65535


def _asset(folder: str, name: str) -> str:
    return resources.files(__package__).joinpath(folder, name).read_text(encoding="utf-8")


def _b64(values: np.ndarray, dtype: str) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype=dtype).tobytes()).decode("ascii")


def quantised(values: np.ndarray, axis_last: bool = True) -> dict:
    """``values`` as 16-bit steps above a low value: ``{"low", "step", "data"}``, per last axis.

    A value is ``low + q * step`` with ``q`` in ``0 .. 65535``, within ``step / 2``
    of the original (``step`` is 1/65535 of the range).  Non-finite values are
    stored as ``low``.

    Parameters
    ----------
    values : ndarray
        The values, with the quantities side by side on the last axis (each
        gets its own ``low`` and ``step``) or, with ``axis_last=False``, all
        one quantity.
    axis_last : bool
        Whether the last axis holds different quantities (the axes of a position).
    """
    flat = values.reshape(-1, values.shape[-1] if axis_last else 1)
    finite = np.isfinite(flat)
    low = np.array([flat[finite[:, c], c].min(initial=np.inf) for c in range(flat.shape[1])])
    high = np.array([flat[finite[:, c], c].max(initial=-np.inf) for c in range(flat.shape[1])])
    low = np.where(np.isfinite(low), low, 0.0)
    step = np.where(high > low, (high - low) / _LEVELS, 1.0)
    q = np.where(finite, np.round((flat - low) / step), 0).astype("<u2")
    return {"low": low.tolist(), "step": step.tolist(), "data": _b64(q, "<u2")}


def _given(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _number(value, form: str, unit: str = "") -> str:
    return form.format(value) + unit if _given(value) else "—"


def headline(summary: dict) -> list[tuple[str, str]]:
    """The figures of ``summary.json`` shown above the view, as (label, text); "—" for one missing.

    ΔRMS, from the start to the end, is marked ``*`` where it swings (:func:`tmem.analysis.caveats.swings`,
    explained by :func:`caveat`); "largest ΔRMS" is the change from the start with the largest
    magnitude on the way, and when (``rms_change_peak_percent``, ``rms_change_peak_time``).  A
    ``safety`` dict adds the smallest separation, the near misses (closer than its ``radius``) and the
    smallest clearance to an obstacle, each where it is given (not None).

    Parameters
    ----------
    summary : dict
        ``summary.json`` as read (:func:`tmem.analysis.metrics.summarize`).
    """
    pairs = summary.get("pairs")
    peak, at = summary.get("rms_change_peak_percent"), summary.get("rms_change_peak_time")
    rows = [
        ("agents", _number(summary.get("agents"), "{:d}")),
        ("function", str(summary.get("function", "—"))),
        ("duration", _number(summary.get("duration"), "{:g}", " s")),
        ("ΔRMS", _number(summary.get("rms_change_percent"), "{:+.3f}", " %") + (" *" if swings(summary) else "")),
        ("largest ΔRMS", _number(peak, "{:+.3f}", " %") + (_number(at, " at {:.2f}", " s") if isinstance(peak, float) else "")),
        ("min distance", _number(summary.get("min_distance"), "{:.2f}", " m")),
    ]
    if isinstance(pairs, list) and pairs:
        rows.append(("pairs coupled at end", f"{_number(summary.get('pairs_coupled_at_end'), '{:d}')}/{len(pairs)}"))
    return rows + _safety(summary.get("safety"))


def _safety(safety) -> list[tuple[str, str]]:
    """The headline's rows of ``summary["safety"]``: those of its figures that are given."""
    if not isinstance(safety, dict):
        return []
    radius = safety.get("radius")
    within = f" (< {radius:.2f} m)" if _given(radius) else ""
    rows = [("min separation", _number(safety.get("min_separation"), "{:.2f}", " m")),
            ("near misses" + within, _number(safety.get("near_misses"), "{:d}")),
            ("min obstacle clearance", _number(safety.get("min_obstacle_clearance"), "{:.2f}", " m"))]  # fmt: skip
    return [(label, text) for label, text in rows if text != "—"]


def caveat(summary: dict) -> str:
    """What the page says under its headline of a ΔRMS that swings (:data:`tmem.analysis.caveats.SWINGS`,
    as the printed table says it); empty when it does not.

    Parameters
    ----------
    summary : dict
        ``summary.json`` as read (:func:`tmem.analysis.metrics.summarize`).
    """
    return f"* {SWINGS}" if swings(summary) else ""


def page_data(view: View) -> dict:
    """The run as the page's scripts read it (``run.js``): plain JSON and base64 typed arrays.

    Parameters
    ----------
    view : View
        What is shown (:func:`tmem.figures.viewer.data.read_view`).
    """
    return {
        "name": view.name,
        "axes": view.axis_names,
        "radius": view.radius,
        "reach": view.reach,
        "space": view.space,
        "agents": view.agents.tolist(),
        "frames": len(view.time),
        "time": _b64(view.time, "<f8"),
        "position": quantised(view.position),
        "speed": quantised(view.speed, axis_last=False),
        "status": _b64(view.status, "u1"),
        "edges": view.edges.reshape(-1).tolist(),
        "strain": _b64(view.strain, "<f4"),
        "coupled": _b64(view.coupled, "u1"),
        "drawn": _b64(view.drawn, "u1"),
        "strainScale": view.strain_scale,
        "rms": _b64(view.rms, "<f4"),
        "pairLabels": view.pair_labels,
        "pairDistance": _b64(view.pair_distance, "<f4"),
        "dT": view.d_t,
        "headline": headline(view.summary),
        "caveat": caveat(view.summary),
        "note": view.note,
    } | ({} if view.route is None else {"route": view.route})


def _import_map() -> str:
    """The import map naming every ES module as a ``data:`` URL of its source."""
    urls = {}
    for name, (folder, file) in MODULES.items():
        source = _asset(folder, file).encode("utf-8")
        urls[name] = "data:text/javascript;base64," + base64.b64encode(source).decode("ascii")
    return json.dumps({"imports": urls})


def render(view: View) -> str:
    """The whole page for ``view``, as text.

    Parameters
    ----------
    view : View
        What is shown (:func:`tmem.figures.viewer.data.read_view`).
    """
    licences = "\n\n".join(_asset("vendor", name).strip() for name in LICENCES)
    parts = {
        "version": __version__,
        "title": html.escape(f"{view.name or 'run'}: tmem view"),
        "style": _asset("vendor", "uPlot.min.css") + "\n" + _asset("web", "viewer.css"),
        "importmap": _import_map(),
        "uplot": _asset("vendor", "uPlot.iife.min.js"),
        "run": json.dumps(page_data(view), ensure_ascii=True, allow_nan=False).replace("<", "\\u003c"),
        "licences": f"<!--\nLicences of the libraries inlined above:\n\n{licences}\n-->",
    }
    return re.sub(r"<!--tmem:(\w+)-->", lambda m: parts[m.group(1)], _asset("web", "viewer.html"))
