"""A sweep's ``summary.md``: statistics per setting, and its figures.

A *setting* is one combination of the values that are not drawn at random
(grid points and explicit cases); the random draws within a setting make a
distribution, summarised by its mean, median and percentiles.  Cases that
failed are counted and left out of the statistics.

* RMS velocity change (10)-(11) per setting: mean, standard deviation,
  median, 5th / 25th / 75th / 95th percentiles, least and largest;
* coupling per setting: the share of cases whose pair coupled, the share of
  those that uncoupled again before the end (after the operator's uncouple
  command, if the scenario has one: "in time"), the median coupling time and
  the median delay from the command to the uncoupling;
* the other kept metrics: median, 5th and 95th percentiles;
* figures: ``rms_change_histogram.png`` (a histogram per setting) and
  ``rms_change_vs_<parameter>.png`` for each numeric parameter that varies, each setting in a
  colour and marker of its own, the legend beside the plot.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from tmem.law.coupling import RELEASES  # noqa: E402
from tmem.files.outputs import write_atomically  # noqa: E402
from tmem.sweep.spec import DISTRIBUTIONS, Sweep  # noqa: E402

RMS = "rms_change_percent"
PERCENTILES = (5, 25, 75, 95)
#: Failed cases listed one by one in the summary.
MAX_LISTED = 10


def settings(table: pd.DataFrame, sweep: Sweep) -> list[tuple[str, pd.DataFrame]]:
    """The table split by setting, each with a label such as ``interaction.function = improved``.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per case (:func:`tmem.sweep.tasks.row`).
    sweep : Sweep
        The sweep; its :attr:`~tmem.sweep.spec.Sweep.settings` name the columns to group by.
    """
    columns = [c for c in sweep.settings if c in table]
    if not columns:
        return [("all cases", table)]
    groups = table.groupby(columns, sort=False, dropna=False)
    return [(", ".join(f"{c} = {v}" for c, v in zip(columns, key if isinstance(key, tuple) else (key,))), g) for key, g in groups]


def uncouple_command_time(sweep: Sweep) -> float | None:
    """When the base scenario commands its pair to uncouple, if it does.

    Parameters
    ----------
    sweep : Sweep
        The sweep whose base scenario is read.

    Returns
    -------
    float or None
        The first uncouple command's time (s).
    """
    times = [c.time for c in sweep.base.commands if c.action == "uncouple"]
    return min(times) if times else None


def rms_statistics(values: pd.Series) -> dict:
    """Mean, standard deviation, median, percentiles and extremes of the finite values.

    Parameters
    ----------
    values : pandas.Series
        A metric over cases, such as ``rms_change_percent``.
    """
    v = values.to_numpy(dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return {"n": 0}
    stats = {"n": v.size, "mean": v.mean(), "std": v.std(ddof=1) if v.size > 1 else 0.0, "median": np.median(v)}
    stats.update({f"p{q}": np.percentile(v, q) for q in PERCENTILES})
    stats.update({"min": v.min(), "max": v.max()})
    return stats


def coupling_statistics(group: pd.DataFrame, command_time: float | None) -> dict:
    """Shares coupled and uncoupled (percent), median coupling time and uncoupling delay (s).

    Parameters
    ----------
    group : pandas.DataFrame
        The rows of one setting.
    command_time : float or None
        Time of the uncouple command (s), from which the delay counts.
    """
    ok = group[group["error"].isna()]
    coupled = ok["coupled"].astype(bool) if "coupled" in ok else ok["couple_time"].notna()
    stats = {"n": len(ok), "coupled_percent": 100.0 * coupled.mean() if len(ok) else np.nan}
    if "couple_time" in ok:
        stats["couple_time_median"] = ok.loc[coupled, "couple_time"].median()
    if "uncouple_time" in ok:
        uncoupled = ok.loc[coupled, "uncouple_time"]
        stats["uncoupled_percent"] = 100.0 * uncoupled.notna().mean() if coupled.any() else np.nan
        if command_time is not None:
            stats["uncouple_delay_median"] = (uncoupled.dropna() - command_time).median()
    return stats


def _cell(value, form: str = "{:.3g}") -> str:
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "—"
    return form.format(value)


def _markdown_table(header: list[str], rows: list[list[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    return lines + ["| " + " | ".join(r) + " |" for r in rows]


def _describe_varied(sweep: Sweep) -> list[str]:
    spec = sweep.spec
    rows = [[f"`{p}`", "grid", ", ".join(map(str, v))] for p, v in spec.grid.items()]
    for path, dist in spec.random.items():
        kind = next(k for k in DISTRIBUTIONS if getattr(dist, k) is not None)
        rows.append([f"`{path}`", f"random, {kind}", ", ".join(map(str, getattr(dist, kind)))])
    for path in sweep.parameters:
        if path not in spec.grid and path not in spec.random:
            rows.append([f"`{path}`", "cases", ", ".join(sorted({str(c[path]) for c in spec.case if path in c}))])
    return _markdown_table(["parameter", "varied by", "values"], rows) if rows else ["Nothing varies: one case."]


def _rms_section(groups: list[tuple[str, pd.DataFrame]]) -> list[str]:
    header = ["setting", "cases", "mean", "std", "median"] + [f"p{q}" for q in PERCENTILES] + ["min", "max"]
    rows = []
    for label, group in groups:
        s = rms_statistics(group.loc[group["error"].isna(), RMS])
        keys = ["mean", "std", "median"] + [f"p{q}" for q in PERCENTILES] + ["min", "max"]
        rows.append([label, str(s["n"])] + [_cell(s.get(k), "{:.3f}" if k == "std" else "{:+.3f}") for k in keys])
    return ["## RMS velocity change (%)", "", *_markdown_table(header, rows), ""]


def _coupling_section(groups: list[tuple[str, pd.DataFrame]], command_time: float | None) -> list[str]:
    header = ["setting", "cases", "coupled (%)", "median couple time (s)", "uncoupled (%)"]
    if command_time is not None:
        header.append(f"median delay after the {command_time:g} s command (s)")
    rows = []
    for label, group in groups:
        s = coupling_statistics(group, command_time)
        row = [label, str(s["n"]), _cell(s["coupled_percent"], "{:.1f}"), _cell(s.get("couple_time_median"), "{:.2f}")]
        row.append(_cell(s.get("uncoupled_percent"), "{:.1f}"))
        if command_time is not None:
            row.append(_cell(s.get("uncouple_delay_median"), "{:.2f}"))
        rows.append(row)
    note = "Uncoupled: the share of the coupled cases whose pair uncoupled again before the end."
    return ["## Coupling", "", *_markdown_table(header, rows), "", note, ""]


def _rule_section(groups: list[tuple[str, pd.DataFrame]]) -> list[str]:
    """What released the pairs that uncoupled, by setting (:data:`tmem.law.coupling.RELEASES`)."""
    rows = []
    for label, group in groups:
        rules = group.loc[group["error"].isna(), "uncouple_rule"].dropna()
        shares = rules.value_counts(normalize=True)
        rows.append([label, str(len(rules)), *(_cell(100.0 * shares.get(rule, 0.0), "{:.1f}") for rule in RELEASES)])
    header = ["setting", "uncoupled", *(f"by `{rule}` (%)" for rule in RELEASES)]
    return ["## What released the pairs", "", *_markdown_table(header, rows), ""]


def _other_section(groups: list[tuple[str, pd.DataFrame]], metrics: list[str]) -> list[str]:
    rows = []
    for metric in metrics:
        for label, group in groups:
            v = group.loc[group["error"].isna(), metric].to_numpy(dtype=float)
            v = v[np.isfinite(v)]
            cells = [_cell(np.percentile(v, q)) if v.size else "—" for q in (50, 5, 95)]
            rows.append([f"`{metric}`", label, str(v.size), *cells])
    return ["## Other metrics", "", *_markdown_table(["metric", "setting", "values", "median", "p5", "p95"], rows), ""]


def _figures(groups: list[tuple[str, pd.DataFrame]], table: pd.DataFrame, sweep: Sweep, out: Path) -> list[str]:
    names = []
    fig, axes = plt.subplots(len(groups), 1, figsize=(7, 2.2 * len(groups) + 0.8), squeeze=False)
    for ax, (label, group) in zip(axes[:, 0], groups):
        v = group.loc[group["error"].isna(), RMS].to_numpy(dtype=float)
        ax.hist(v[np.isfinite(v)], bins=60, color="tab:blue")
        ax.set_title(label, fontsize=9)
        ax.set_ylabel("cases")
    axes[-1, 0].set_xlabel("RMS velocity change (%)")
    fig.tight_layout()
    write_atomically(out / "rms_change_histogram.png", lambda tmp: fig.savefig(tmp, dpi=110))
    plt.close(fig)
    names.append("rms_change_histogram.png")
    for path in sweep.parameters:
        values = pd.to_numeric(table[path], errors="coerce")
        if values.isna().all() or values.nunique() < 2 or table[path].map(lambda v: isinstance(v, bool)).any():
            continue  # nothing to draw against, or settings rather than a scale
        fig = scatter_figure(groups, path)
        name = f"rms_change_vs_{path.replace('.', '_')}.png"
        write_atomically(out / name, lambda tmp: fig.savefig(tmp, dpi=110))
        plt.close(fig)
        names.append(name)
    return ["## Figures", "", *[f"![{n}]({n})" for n in names], ""]


#: Markers taken in turn past ten settings, so that settings of near colours differ in shape.
MARKERS = ("o", "s", "^", "D", "v")


def setting_styles(count: int) -> list[tuple[tuple, str]]:
    """A colour and a marker for each of ``count`` settings, no two alike: Matplotlib's ten colours
    up to ten settings, its twenty up to twenty, else colours spread over a colour map, with the
    markers of :data:`MARKERS` in turn past ten.

    Parameters
    ----------
    count : int
        How many settings.
    """
    from matplotlib import colormaps

    if count <= 10:
        colours = colormaps["tab10"].colors[:count]
    elif count <= 20:
        colours = colormaps["tab20"].colors[:count]
    else:
        colours = [tuple(c) for c in colormaps["turbo"](np.linspace(0.0, 1.0, count))]
    return [(tuple(colour), "o" if count <= 10 else MARKERS[k % len(MARKERS)]) for k, colour in enumerate(colours)]


def scatter_figure(groups: list[tuple[str, pd.DataFrame]], path: str):
    """The RMS change of every case against parameter ``path``, one colour and marker per setting
    (:func:`setting_styles`), the legend beside the axes, where it hides no point.

    Parameters
    ----------
    groups : list of (str, pandas.DataFrame)
        The settings and their rows (:func:`settings`).
    path : str
        The parameter on the horizontal axis: a column of the rows.
    """
    fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    for (label, group), (colour, marker) in zip(groups, setting_styles(len(groups))):
        ok = group["error"].isna()
        ax.scatter(pd.to_numeric(group.loc[ok, path], errors="coerce"), group.loc[ok, RMS], s=3, alpha=0.4,
                   color=colour, marker=marker, label=label)  # fmt: skip
    ax.set_xlabel(path)
    ax.set_ylabel("RMS velocity change (%)")
    if len(groups) > 1:
        columns = -(-len(groups) // 20)
        ax.legend(fontsize=8, markerscale=4, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, ncols=columns)
    return fig


def write_report(table: pd.DataFrame, sweep: Sweep, out: str | Path) -> Path:
    """Write ``out/summary.md`` and the figures for the complete ``table``; return the summary's path.

    Parameters
    ----------
    table : pandas.DataFrame
        One row per case, every case done.
    sweep : Sweep
        The sweep the table belongs to.
    out : str or Path
        The sweep's output directory.
    """
    out = Path(out)
    metrics = sweep.spec.metrics
    groups = settings(table, sweep)
    failed = table[table["error"].notna()]
    lines = [
        f"# Sweep {sweep.name}",
        "",
        f"Base scenario: `{sweep.spec.base}` ({sweep.base.interaction.function} function, "
        f"{sweep.base.simulation.duration:g} s at dt = {sweep.base.simulation.dt:g} s). "
        f"{sweep.n_cases} cases: {len(groups)} setting(s)"
        + (f" × {sweep.spec.cases} random draws (seed {sweep.spec.seed}, the same draws in every setting)." if sweep.spec.random else "."),
        "",
        *_describe_varied(sweep),
        "",
        f"Failed cases: {len(failed)}" + (" (left out of the statistics)." if len(failed) else "."),
        "",
    ]
    lines += [f"- case {int(r.case)}: {r.error}" for r in failed.head(MAX_LISTED).itertuples()]
    lines += [""] if len(failed) else []
    if RMS in metrics:
        lines += _rms_section(groups)
    if "coupled" in metrics or "couple_time" in metrics:
        lines += _coupling_section(groups, uncouple_command_time(sweep))
    if "uncouple_rule" in metrics:
        lines += _rule_section(groups)
    others = [m for m in metrics if m not in (RMS, "coupled", "couple_time", "uncouple_time", "uncouple_rule")]
    if others:
        lines += _other_section(groups, others)
    if RMS in metrics and len(table) > len(failed):
        lines += _figures(groups, table, sweep, out)
    path = out / "summary.md"
    write_atomically(path, lambda tmp: tmp.write_text("\n".join(lines).rstrip() + "\n", encoding="utf-8"))
    return path
