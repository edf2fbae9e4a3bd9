"""The numbers and figures of "What survives" in docs/vehicles.md: the paper's runs on the quadrotor.

Two parts::

    python docs/scripts/survive.py reruns [NAME]   # the table of reruns, linear model beside quadrotor
    python docs/scripts/survive.py sweeps out      # tables and figures from the sweeps written under out/

``reruns`` flies the paper's Figs. 5, 7 and 9, the formation flights of docs/swarms.md and the gas
of examples/swarm/gas2d.toml on the linear model (2) and on the quadrotor under each inner loop (the
tilt loop's runs started level, the acceleration loop's as examples/vehicles/ starts them), and prints one Markdown table.  ``sweeps`` reads the ``results.parquet`` of the three sensing sweeps of
examples/sweeps/vehicles_*.toml (run with ``tmem sweep FILE --out out/vehicles_NAME``), prints their
tables and draws docs/images/vehicles-*.png, with the linear model's and the exact quadrotor's
values, flown here, as reference lines.  docs/scripts/survive_wind.py does the same for the two wind
sweeps, with this module's tables and panels.  The total runtime goes to standard error.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")  # files only
import matplotlib.pyplot as plt  # noqa: E402

import tmem  # noqa: E402
from tmem.analysis.metrics import summarize  # noqa: E402
from tmem.scenario import Scenario, from_dict, load, with_changes  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent
EXAMPLES = ROOT / "examples"
IMAGES = ROOT / "docs" / "images"
DASH = "—"
#: The quadrotor's step for the swarms (s): its flight controller then runs every step (docs/vehicles.md).
SWARM_DT = 1e-3
#: The paper's own figures where it states one: the RMS change (%) of Figs. 7 and 9.
PAPER = {"fig5": "no coupling", "fig7": "couples; uncouples after 30 s; +5.6 %", "fig9": "couples; uncouples after 30 s; +0.2 %"}
FORMATIONS = ("triangle", "chain5", "hex19", "ring8_loss", "hex19_settled")


def on_quadrotor(scenario: Scenario) -> Scenario:
    """``scenario`` flown by the Crazyflie (the quadrotor's defaults) at a step of at least :data:`SWARM_DT`."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    data["model"] = {"kind": "quadrotor"}
    data["simulation"]["dt"] = max(data["simulation"]["dt"], SWARM_DT)
    return from_dict(data)


def tilt_loop(scenario: Scenario) -> Scenario:
    """The quadrotor ``scenario`` under the tilt loop, its ``[[agents]]`` started level: the reruns' column
    that the acceleration loop is compared with (docs/vehicles.md)."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    data["model"]["inner_loop"] = "tilt"
    for agent in data.get("agents") or []:
        agent["tilt"] = 0.0
    return from_dict(data)


def _f(value, digits: int = 2, sign: bool = False) -> str:
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return DASH
    return f"{value:+.{digits}f}" if sign else f"{value:.{digits}f}"


def pair_figures(trajectory) -> dict:
    """Figures of merit of a two-agent run: coupling, uncoupling, parting, RMS change, closest approach."""
    summary = summarize(trajectory)
    pair = summary["pairs"][0]
    return {
        "couples at (s)": _f(pair["coupled_at"]) if summary["coupled"] else "never",
        "uncouples at (s)": _f(pair["uncoupled_at"]),
        "apart at (s)": _f(pair["separated_at"]),
        "RMS change (%)": _f(summary["rms_change_percent"], 2, sign=True),
        "smallest distance (m)": _f(summary["min_distance"]),
    }


def formation_figures(trajectory) -> dict:
    """Figures of merit of a formation flight: its edges' errors from ``d_t``, settling, RMS change."""
    summary = summarize(trajectory)
    formation = summary["formation"]
    figures = {
        "largest edge error, 60 s (m)": _f(formation["distance_error"]["max"]),
        "largest edge error, last 20 s (m)": _f(formation["distance_error_last_20s"]["max"]),
        "RMS edge error, 60 s (m)": _f(formation["distance_error"]["rms"]),
        "pairs coupled at the end": _f(formation["coupled_at_end"] * 100, 0) + " %",
        "RMS change (%)": _f(summary["rms_change_percent"], 2, sign=True),
    }
    if formation.get("direction_error_deg") is not None:
        figures["largest direction error (deg)"] = _f(formation["direction_error_deg"], 1)
    if summary["scenario"].endswith("settled"):
        figures["settled at (s)"] = _f(formation["settling_time"], 1)
        figures["edge error at 60 s (m)"] = _f(formation["residual_error"], 3)
    return figures


#: When the gas's random start has turned its overlaps into speed (s; docs/swarms.md, "A random start is not at rest").
RELAXED = 10.0


def gas_figures(trajectory) -> dict:
    """Figures of merit of the gas: its RMS velocity once relaxed and at the end, and how close agents come."""
    summary = summarize(trajectory)
    velocity = trajectory.model.velocity(trajectory.state)
    relaxed, end = (np.sqrt(np.mean(np.sum(velocity[k] ** 2, axis=-1))) for k in (np.searchsorted(trajectory.time, RELAXED), -1))
    return {
        "RMS change, 0-60 s (%)": _f(summary["rms_change_percent"], 2, sign=True),
        f"RMS velocity at {RELAXED:g} s, at 60 s (m/s)": f"{relaxed:.3f}, {end:.3f}",
        f"RMS change, {RELAXED:g}-60 s (%)": _f(100 * (end / relaxed - 1), 2, sign=True),
        "smallest distance (m)": _f(summary["min_distance"]),
    }


def reruns() -> list[tuple[str, str, Scenario, Scenario, object]]:
    """Each rerun: its name, the paper's figure, the linear model's scenario, the quadrotor's, its figures."""
    runs = [(f, PAPER[f], load(EXAMPLES / f"{f}.toml"), load(EXAMPLES / "vehicles" / f"{f}.toml"), pair_figures) for f in PAPER]
    for name in FORMATIONS:
        linear = load(EXAMPLES / "swarm" / f"{name}.toml")
        runs.append((name, DASH, linear, on_quadrotor(linear), formation_figures))
    gas = load(EXAMPLES / "swarm" / "gas2d.toml")
    return runs + [("gas2d (400 agents)", "keeps its RMS velocity", gas, on_quadrotor(gas), gas_figures)]


def print_reruns(names: list[str]) -> None:
    """The reruns' table; only the runs whose names start with one of ``names``, if any are given."""
    print("| run | paper | figure of merit | linear (2) | quadrotor, tilt loop | quadrotor, acceleration loop |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, paper, linear, quad, figures in reruns():
        if names and not any(name.startswith(n) for n in names):
            continue
        ours, tilt, theirs = (figures(tmem.simulate(s)) for s in (linear, tilt_loop(quad), quad))
        for k, key in enumerate(ours):
            print(f"| {name if k == 0 else ''} | {paper if k == 0 else ''} | {key} | {ours[key]} | {tilt[key]} | {theirs[key]} |",
                  flush=True)  # fmt: skip


#: The swept quantities of the one-at-a-time sweeps: (column, label, scale; ``None`` for named levels).
SENSING_AXES = (
    ("sensing.position_noise", "position noise (m); velocity noise = position / 3 s", "log"),
    ("sensing.delay", "fixed delay (s)", "log"),
    ("sensing.loss", "message loss (probability)", "linear"),
)
#: The wind sweeps' (vehicles_*_wind.toml): a constant wind along x, and Dryden turbulence by severity.
WIND_AXES = (
    ("wind along x", "constant wind along x (m/s)", "linear"),
    ("wind.turbulence.severity", "Dryden turbulence, no mean wind", None),
)
AXES = SENSING_AXES + WIND_AXES
#: How much later than the reference a coupling may come and still be on the first pass (s).
FIRST_PASS = 0.5
#: The band a formation must keep its edges within, once formed (m).
BAND = 1.0
#: A looser band, for the hex under (11) alone, whose edges swing by about 2 m with exact sensing (m).
LOOSE_BAND = 2.0


def axis_of(row) -> str | None:
    """Which swept quantity a case of a one-at-a-time sweep varies, ``None`` for the reference."""
    for column, _, _ in AXES:
        if column in row and row[column] == row[column] and row[column] not in (None, 0.0):
            return column
    return None


def read(out: Path, name: str):
    """The rows of ``out/vehicles_NAME/results.parquet``, each with the axis it varies.

    A constant wind's JSON ``wind.velocity`` becomes its x part, the column ``wind along x``.
    """
    import json

    import pandas as pd

    rows = pd.read_parquet(out / f"vehicles_{name}" / "results.parquet")
    if rows["error"].notna().any():
        print(f"{name}: {rows['error'].notna().sum()} cases failed: {rows['error'].dropna().unique()}", file=sys.stderr)
    if "wind.velocity" in rows:
        rows["wind along x"] = [json.loads(v)[0] if isinstance(v, str) else np.nan for v in rows["wind.velocity"]]
    rows["axis"] = [axis_of(r) for _, r in rows.iterrows()]
    return rows


def references() -> dict:
    """The linear model's and the exact quadrotor's summaries of Fig. 9 and the hex (the reference lines)."""
    runs = {
        ("fig9", "linear (2)"): load(EXAMPLES / "fig9.toml"),
        ("fig9", "quadrotor, exact"): load(EXAMPLES / "vehicles" / "fig9.toml"),
        ("hex19", "linear (2)"): load(EXAMPLES / "swarm" / "hex19.toml"),
        ("hex19", "quadrotor, exact"): load(EXAMPLES / "vehicles" / "hex19.toml"),
    }
    return {key: summarize(tmem.simulate(scenario)) for key, scenario in runs.items()}


def fig9_values(summary: dict) -> dict:
    """Fig. 9's figures of merit as the sweep's columns name them."""
    return {"rms_change_percent": summary["rms_change_percent"], "couple_time": summary["couple_time"],
            "uncouple_time": summary["uncouple_time"], "pairs.0.separated_at": summary["pairs"][0]["separated_at"]}  # fmt: skip


def hex_values(summary: dict) -> dict:
    """The hex's figures of merit as the sweep's columns name them."""
    f = summary["formation"]
    return {"formation.distance_error_last_20s.max": f["distance_error_last_20s"]["max"],
            "formation.distance_error_last_20s.rms": f["distance_error_last_20s"]["rms"],
            "formation.distance_error.max": f["distance_error"]["max"], "rms_change_percent": summary["rms_change_percent"]}  # fmt: skip


def _spread(values) -> str:
    values = [v for v in values if v is not None and v == v]
    if not values:
        return "never"
    if len(values) == 1 or max(values) == min(values):
        return f"{values[0]:.2f}"
    return f"{np.mean(values):.2f} [{min(values):.2f}, {max(values):.2f}]"


def _level(value) -> str:
    return value if isinstance(value, str) else f"{value:g}"


def table(rows, columns: dict[str, str], axes=SENSING_AXES) -> None:
    """One Markdown row per level of each of ``axes``: each column's mean [least, largest] over the seeds."""
    print("| swept | level | " + " | ".join(columns.values()) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in columns) + " |")
    print("| reference (100 Hz) | | " + " | ".join(_spread(rows[rows["axis"].isna()][c]) for c in columns) + " |")
    for column, label, _ in axes:
        for level, group in rows[rows["axis"] == column].groupby(column):
            missing = {c: int(group[c].isna().sum()) for c in columns}
            cells = [_spread(group[c]) + (f" ({missing[c]} of {len(group)} never)" if missing[c] else "") for c in columns]
            print(f"| {label.split(';')[0]} | {_level(level)} | " + " | ".join(cells) + " |")


def draw_panels(panels, rows, refs: dict, metrics: dict[str, str], axes=SENSING_AXES, band: float | None = None) -> None:
    """Into ``panels``, a row per metric and a column per swept quantity: the cases, their means and the reference lines."""
    reference = rows[rows["axis"].isna()].iloc[0]
    for r, (metric, label) in enumerate(metrics.items()):
        for c, (column, axis_label, scale) in enumerate(axes):
            ax = panels[r][c]
            cases = rows[rows["axis"] == column]
            ax.plot(cases[column], cases[metric], "o", ms=3, color="C0", alpha=0.6)
            means = cases.groupby(column)[metric].mean()
            ax.plot(means.index, means.values, "-", color="C0", label="quadrotor, sensed (dots: seeds)")
            never = cases[cases[metric].isna()]
            if len(never):
                top = np.nanmax(rows[metric]) if rows[metric].notna().any() else 1.0
                ax.plot(never[column], np.full(len(never), top), "x", color="C3", label="never")
            ax.axhline(reference[metric], color="0.4", lw=1, label="quadrotor, 100 Hz, nothing else (the reference)")
            for (style, name) in (("--", "linear (2)"), (":", "quadrotor, exact")):
                if refs.get(name, {}).get(metric) is not None:
                    ax.axhline(refs[name][metric], color="k", ls=style, lw=1, label=name)
            if band is not None and r == 0:
                ax.axhline(band, color="C3", lw=0.8, alpha=0.5)
            if scale is not None:  # named levels keep matplotlib's categorical axis
                ax.set_xscale(scale)
            ax.set_xlabel(axis_label if r == len(metrics) - 1 else "")
            ax.set_ylabel(label if c == 0 else "")
            ax.grid(alpha=0.3)


def save(fig, path: Path) -> None:
    """Write ``fig`` to ``path`` and close it."""
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path.relative_to(ROOT)}", file=sys.stderr)


def draw_axes(rows, refs: dict, metrics: dict[str, str], path: Path, band: float | None = None) -> None:
    """A grid of panels: a row per metric, a column per swept quantity of the sensing sweeps."""
    fig, panels = plt.subplots(len(metrics), len(SENSING_AXES), figsize=(4.2 * len(SENSING_AXES), 2.6 * len(metrics)), squeeze=False)
    draw_panels(panels, rows, refs, metrics, SENSING_AXES, band)
    panels[0][0].legend(fontsize=7)
    save(fig, path)


FIG9_METRICS = {"rms_change_percent": "RMS change (%)", "couple_time": "couples at (s)", "uncouple_time": "uncouples at (s)"}
HEX_METRICS = {
    "formation.distance_error_last_20s.max": "largest edge error,\nlast 20 s (m)",
    "formation.distance_error_last_20s.rms": "RMS edge error,\nlast 20 s (m)",
    "formation.distance_error.max": "largest edge error,\nwhole run (m)",
    "rms_change_percent": "RMS change (%)",
}


#: The columns of the tables of Fig. 9 and of the hex.
FIG9_COLUMNS = {"couple_time": "couples at (s)", "uncouple_time": "uncouples at (s)", "pairs.0.separated_at": "apart at (s)",
                "rms_change_percent": "RMS change (%)", "min_distance": "smallest distance (m)"}  # fmt: skip
HEX_COLUMNS = {"formation.distance_error_last_20s.max": "largest edge error, last 20 s (m)",
               "formation.distance_error_last_20s.rms": "RMS edge error, last 20 s (m)",
               "formation.distance_error.max": "largest edge error, 60 s (m)",
               "rms_change_percent": "RMS change (%)", "min_distance": "smallest distance (m)"}  # fmt: skip


def describe_case(row) -> str:
    """``axis = level (seed s)``: which case of a one-at-a-time sweep a row is."""
    seeds = [row[c] for c in ("sensing.seed", "wind.turbulence.seed") if c in row and row[c] == row[c] and row[c] is not None]
    return f"{row.axis} = {_level(row[row.axis])}" + (f" (seed {seeds[0]:g})" if seeds else "")


def print_first_pass(rows) -> None:
    """Fig. 9's breaking points: the cases whose coupling (9) is off the reference's first pass, and those
    that coupled and did not uncouple after the command."""
    reference = rows[rows["axis"].isna()].iloc[0]
    off = rows["couple_time"].isna() | ((rows["couple_time"] - reference["couple_time"]).abs() > FIRST_PASS)
    print(f"coupled within {FIRST_PASS} s of the reference's {reference['couple_time']:.2f} s "
          f"except in {int(off.sum())} of {len(rows)} cases: " + ", ".join(f"{describe_case(r)}: {_f(r.couple_time)}" for _, r in rows[off].iterrows()))  # fmt: skip
    failed = rows[rows["coupled"].fillna(False).astype(bool) & rows["uncouple_time"].isna()]
    print(f"coupled but not uncoupled by the end: {len(failed)} cases " + ", ".join(describe_case(r) for _, r in failed.iterrows()))


def print_band(rows) -> None:
    """The hex's shape: each case's largest edge error over the last 20 s beside the reference's, and how many
    cases keep it within :data:`BAND` and :data:`LOOSE_BAND`."""
    metric = "formation.distance_error_last_20s.max"
    reference = rows[rows["axis"].isna()][metric].iloc[0]
    for band in (BAND, LOOSE_BAND):
        print(f"within {band:g} m over the last 20 s: {int((rows[metric] <= band).sum())} of {len(rows)} cases")
    print(f"largest edge error over the last 20 s against the reference's {reference:.2f} m: "
          + ", ".join(f"{describe_case(r)}: {r[metric]:.2f}" for _, r in rows[rows['axis'].notna()].iterrows()))  # fmt: skip


def fig9_report(out: Path, refs: dict) -> None:
    rows = read(out, "fig9_sensing")
    print("\n### Fig. 9\n")
    print_first_pass(rows)
    print()
    table(rows, FIG9_COLUMNS)
    draw_axes(rows, {k[1]: fig9_values(v) for k, v in refs.items() if k[0] == "fig9"}, FIG9_METRICS, IMAGES / "vehicles-fig9-sensing.png")


def hex_report(out: Path, refs: dict) -> None:
    rows = read(out, "hex19_sensing")
    print("\n### hex19\n")
    print_band(rows)
    print()
    table(rows, HEX_COLUMNS)
    draw_axes(rows, {k[1]: hex_values(v) for k, v in refs.items() if k[0] == "hex19"}, HEX_METRICS, IMAGES / "vehicles-hex19-sensing.png", BAND)


def grid_report(out: Path) -> None:
    """The delay x noise grid: the largest edge error over the last 20 s, and where it keeps the band."""
    rows = read(out, "hex19_grid")
    metric = "formation.distance_error_last_20s.max"
    fig, panels = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for ax, (synchronised, group) in zip(panels, rows.groupby("interaction.synchronise")):
        worst = group.groupby(["sensing.position_noise", "sensing.delay"])[metric].max().unstack()
        title = "synchronised (S2)" if synchronised else "(11) alone"
        print(f"\n### hex19 grid, {title}: largest edge error over the last 20 s (m)\n")
        print("| position noise (m) \\ delay (s) | " + " | ".join(f"{d:g}" for d in worst.columns) + " |")
        print("| --- | " + " | ".join("---" for _ in worst.columns) + " |")
        for noise, line in worst.iterrows():
            print(f"| {noise:g} | " + " | ".join(f"**{v:.2f}**" if v <= BAND else f"{v:.2f}" for v in line) + " |")
        print()
        for band in (BAND, LOOSE_BAND):
            print(f"- within {band:g} m, the delays (s) at each noise (m): "
                  + "; ".join(f"{n:g}: {', '.join(f'{d:g}' for d in line.index[line <= band]) or 'none'}" for n, line in worst.iterrows()))  # fmt: skip
        image = ax.imshow(worst.values, origin="lower", cmap="viridis_r", aspect="auto", vmin=0, vmax=max(3.0, BAND))
        for (i, j), v in np.ndenumerate(worst.values):
            ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=7, color="w" if v > 1.5 else "k",
                    fontweight="bold" if v <= BAND else "normal")  # fmt: skip
        ax.set_xticks(range(len(worst.columns)), [f"{d:g}" for d in worst.columns])
        ax.set_yticks(range(len(worst.index)), [f"{n:g}" for n in worst.index])
        ax.set_xlabel("fixed delay (s)")
        ax.set_ylabel("position noise (m); velocity = position / 3 s" if ax is panels[0] else "")
        ax.set_title(f"hex19 on the quadrotor, {title}", fontsize=9)
    fig.colorbar(image, ax=panels, label=f"largest edge error, last 20 s (m); bold: within {BAND} m")
    path = IMAGES / "vehicles-hex19-grid.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path.relative_to(ROOT)}", file=sys.stderr)


def print_braking() -> None:
    """The hex's mean velocity along its flight after 60 s, on both vehicles, exact and with stale data."""
    print("\n### the hex's mean velocity at 60 s (m/s; 3 at the start)\n")
    quad = load(EXAMPLES / "vehicles" / "hex19.toml")
    for vehicle in ("quadrotor", "linear"):
        base = quad if vehicle == "quadrotor" else with_changes(quad, {"model": {"kind": "linear"}})
        for changes in ({}, {"sensing.period": 0.01}, {"sensing.period": 0.01, "sensing.delay": 0.05}):
            trajectory = tmem.simulate(with_changes(base, changes))
            mean = trajectory.model.velocity(trajectory.final_state).mean(axis=0)
            print(f"- {vehicle}, {changes or 'exact'}: {mean[0]:.3f}")


def print_references(refs: dict) -> None:
    print("\n### references\n")
    for (name, vehicle), summary in refs.items():
        values = fig9_values(summary) if name == "fig9" else hex_values(summary)
        print(f"- {name}, {vehicle}: " + ", ".join(f"{k} = {_f(v, 3)}" for k, v in values.items()))


def main(argv: list[str]) -> None:
    started = time.perf_counter()
    if argv[:1] == ["reruns"]:
        print_reruns(argv[1:])
    elif argv[:1] == ["sweeps"] and len(argv) == 2:
        refs = references()
        print_references(refs)
        fig9_report(Path(argv[1]), refs)
        hex_report(Path(argv[1]), refs)
        grid_report(Path(argv[1]))
        print_braking()
    else:
        sys.exit("usage: python docs/scripts/survive.py reruns [NAME ...] | sweeps OUT")
    print(f"{time.perf_counter() - started:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1:])
