"""The head-on encounter study's write-up, from the results of its sweep.

Run the sweep, then this script on its output directory; it writes
``docs/encounters_head_on.md`` and its figures under ``docs/encounters/``::

    tmem sweep examples/sweeps/encounters.toml --out out/encounters
    python docs/scripts/encounters.py out/encounters

Every number in the text is computed here from ``results.parquet``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from study import DOCS, FIGURES, FUNCTION, LABEL, PAPER_RMS, panels_by_function  # first: it selects matplotlib's file backend

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

COMMAND_TIME = 29.0
SPEED_BINS = np.arange(2.0, 10.5, 1.0)


def load(directory: Path) -> pd.DataFrame:
    table = pd.read_parquet(directory / "results.parquet")
    table["closing_speed"] = table["agents.1.velocity"] - table["agents.0.velocity"]
    return table


def describe(group: pd.DataFrame, function: str) -> dict:
    rms = group["rms_change_percent"].to_numpy()
    coupled = group["coupled"].to_numpy(dtype=bool)
    delay = group.loc[coupled, "uncouple_time"].to_numpy() - COMMAND_TIME
    return {
        "n": len(group),
        "failed": int(group["error"].notna().sum()),
        "mean": rms.mean(),
        "median": np.median(rms),
        "p5": np.percentile(rms, 5),
        "p95": np.percentile(rms, 95),
        "min": rms.min(),
        "max": rms.max(),
        "coupled": 100 * coupled.mean(),
        "uncoupled": 100 * np.isfinite(delay).mean(),
        "delay_median": np.nanmedian(delay),
        "delay_max": np.nanmax(delay),
        "held": 100 * np.mean(~(delay < 0)),  # coupled pairs that stayed coupled until the command
        "couple_median": np.median(group.loc[coupled, "couple_time"]),
        "rms_coupled_median": np.median(rms[coupled]),
        "rms_uncoupled_max": rms[~coupled].max() if (~coupled).any() else np.nan,
        "below_paper": 100 * np.mean(rms < PAPER_RMS[function]),
        "slowest_coupled": group.loc[coupled, "closing_speed"].min(),
        "fastest_failed": group.loc[~coupled, "closing_speed"].max() if (~coupled).any() else np.nan,
    }


def figures(table: pd.DataFrame) -> None:
    def draw(ax, function, group):
        ax.hist(group["rms_change_percent"], bins=60, color="tab:blue")
        ax.axvline(PAPER_RMS[function], color="tab:red", ls="--", label=f"paper: {PAPER_RMS[function]} %")

    panels_by_function(table, draw, "RMS velocity change (%)", "rms_change_histogram.png")

    fig, ax = plt.subplots(figsize=(7, 4))
    for function, group in table.groupby(FUNCTION, sort=False):
        ax.scatter(group["closing_speed"], group["rms_change_percent"], s=2, alpha=0.3, label=LABEL[function])
    ax.set_yscale("log")
    ax.set_xlabel("closing speed (m/s)")
    ax.set_ylabel("RMS velocity change (%)")
    ax.legend(markerscale=5, fontsize=8)
    fig.tight_layout()
    fig.savefig(FIGURES / "rms_change_vs_closing_speed.png", dpi=100)
    plt.close(fig)


def coupling_by_speed(table: pd.DataFrame) -> list[str]:
    lines = ["| closing speed (m/s) | encounters | (10) coupled | (11) coupled |", "| --- | --- | --- | --- |"]
    bins = pd.cut(table["closing_speed"], SPEED_BINS, right=False)
    shares = table.groupby([bins, FUNCTION], observed=True)["coupled"].agg(lambda c: 100 * c.astype(bool).mean())
    counts = table[table[FUNCTION] == "switching"].groupby(bins[table[FUNCTION] == "switching"], observed=True).size()
    for interval, n in counts.items():
        lines.append(
            f"| {interval.left:g}–{interval.right:g} | {n} | {shares[(interval, 'switching')]:.1f} % | "
            f"{shares[(interval, 'improved')]:.1f} % |"
        )
    return lines


def paired(table: pd.DataFrame) -> dict:
    draw = table["case"] % (len(table) // table[FUNCTION].nunique())  # the same start in every setting
    wide = table.assign(draw=draw).pivot(index="draw", columns=FUNCTION, values=["rms_change_percent", "coupled"])
    both = wide["coupled"]["switching"].astype(bool) & wide["coupled"]["improved"].astype(bool)
    ratio = (wide["rms_change_percent"]["switching"] / wide["rms_change_percent"]["improved"])[both]
    lower = (wide["rms_change_percent"]["improved"] < wide["rms_change_percent"]["switching"])[both]
    return {
        "both": int(both.sum()),
        "ratio_median": ratio.median(),
        "ratio_p5": ratio.quantile(0.05),
        "ratio_p95": ratio.quantile(0.95),
        "improved_lower": 100 * lower.mean(),
    }


def main(directory: Path) -> None:
    table = load(directory)
    d = {f: describe(g, f) for f, g in table.groupby(FUNCTION, sort=False)}
    s, i = d["switching"], d["improved"]
    p = paired(table)
    figures(table)
    n = s["n"]
    text = f"""# 10 000 random encounters: is the paper "similar under other initial conditions"?

The paper shows one start (Table 2: 50 m apart, −1.5 and 3 m/s) and says that other initial
conditions give similar results. This study runs {n:,} random two-agent encounters, each with the
switching function (10) and with the improved one (11): {2 * n:,} runs of 60 s, every parameter
but the start the presets' (Table 1, c_max = 0.1 rad, d_t = 35 m, ε = 0.2 m, dt = 1e-4 s, the
uncouple command at 29 s). Both functions meet the same starts (a paired comparison).

The starts (`examples/sweeps/encounters.toml`, seed 20261122): agent 1 at 0 m; agent 0 at 45 to 80 m,
beyond R + R_j = 40 m so that every pair starts uncoupled; each flies towards the other at 1 to 5 m/s
(uniform), so the closing speed runs from 2 to 10 m/s and every pair meets before the command. In one
axis the only direction that makes an encounter is towards each other; the sampled speeds set the
pair's common velocity as well as its closing speed.

Reproduce (43 s on this project's 2-core machine, median of 3 runs of `python benchmarks/bench_sweep.py`):

    tmem sweep examples/sweeps/encounters.toml --out out/encounters
    python docs/scripts/encounters.py out/encounters

## RMS velocity change

| | paper (one start) | mean | median | 5–95 % of encounters | least – largest | encounters below the paper's value |
| --- | --- | --- | --- | --- | --- | --- |
| switching (10) | ≈ {PAPER_RMS['switching']} % | {s['mean']:+.2f} % | {s['median']:+.2f} % | {s['p5']:+.2f} to {s['p95']:+.2f} % | {s['min']:+.3f} to {s['max']:+.2f} % | {s['below_paper']:.1f} % |
| improved (11) | ≈ {PAPER_RMS['improved']} % | {i['mean']:+.3f} % | {i['median']:+.3f} % | {i['p5']:+.3f} to {i['p95']:+.3f} % | {i['min']:+.3f} to {i['max']:+.3f} % | {i['below_paper']:.1f} % |

Where both functions couple ({p['both']:,} starts), (10) changes the RMS velocity {p['ratio_median']:.1f} times as much as
(11) (median; 5–95 %: {p['ratio_p5']:.1f} to {p['ratio_p95']:.1f}), and (11) changes it less in {p['improved_lower']:.1f} % of them.

![RMS change histograms](encounters/rms_change_histogram.png)

![RMS change against closing speed](encounters/rms_change_vs_closing_speed.png)

## Coupling and uncoupling

| | coupled | median coupling time | held until the command (of those coupled) | uncoupled by the end (of those coupled) | delay after the 29 s command: median, largest |
| --- | --- | --- | --- | --- | --- |
| switching (10) | {s['coupled']:.1f} % | {s['couple_median']:.2f} s | {s['held']:.1f} % | {s['uncoupled']:.1f} % | {s['delay_median']:.2f} s, {s['delay_max']:.2f} s |
| improved (11) | {i['coupled']:.1f} % | {i['couple_median']:.2f} s | {i['held']:.1f} % | {i['uncoupled']:.1f} % | {i['delay_median']:.2f} s, {i['delay_max']:.2f} s |

By closing speed:

{chr(10).join(coupling_by_speed(table))}

Pairs that did not couple met through the repulsion branch alone and parted; their RMS change is at most
{s['rms_uncoupled_max']:+.3f} % with (10). The fastest pair that (10) failed to couple closed at
{s['fastest_failed']:.2f} m/s; with (11) the fastest failure closed at {i['fastest_failed']:.2f} m/s.

## Verdict

* **(11) keeps the temperature under every start tried.** Its RMS change stays between
  {i['min']:+.3f} % and {i['max']:+.3f} % over all {n:,} encounters. The paper's ≈ {PAPER_RMS['improved']} % lies below
  {100 - i['below_paper']:.1f} % of them: our typical value ({i['median']:+.2f} %) is about twice the paper's, as it is for the
  Table 2 start itself (+0.33 %, see docs/reproduction.md). Neither the start nor the unpublished
  c_max, d_t and ε (docs/sensitivity.md: +0.23 to +0.43 %) bring it down to 0.2 %; the gap stays unexplained.
* **(10)'s number is not a property of the method but of the start.** Its RMS change runs from
  {s['min']:+.2f} % to {s['max']:+.2f} % (median {s['median']:+.2f} %); the paper's ≈ {PAPER_RMS['switching']} % is above
  {s['below_paper']:.1f} % of encounters. That (11) beats (10) holds in {p['improved_lower']:.1f} % of the paired
  starts, by a factor of {p['ratio_median']:.1f} in the median: the paper's qualitative claim holds.
* **Coupling is not guaranteed.** (10) couples {s['coupled']:.1f} % of encounters and (11) {i['coupled']:.1f} %;
  the failures are the slow ones (table above), where the repulsion branch turns the pair round before
  |d| reaches d_t. Of the pairs that coupled, {s['held']:.1f} % ((10)) and {i['held']:.1f} % ((11)) held
  until the command and {s['uncoupled']:.1f} % and {i['uncoupled']:.1f} % uncoupled by the end, a median
  {s['delay_median']:.1f} s ((10)) and {i['delay_median']:.1f} s ((11)) after it — the paper's "t > 30 s".

So "similar under other initial conditions" holds for (11), and for the ranking of (10) against (11); it
does not hold for the size of (10)'s RMS change, and coupling fails for slow approaches.
"""
    (DOCS / "encounters_head_on.md").write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "out/encounters"))
