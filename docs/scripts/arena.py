"""The table and figure of "Beside the field's flocking laws" in docs/missions.md, from the arena sweep.

    tmem sweep examples/sweeps/arena.toml --out out/arena --workers 2     # about 5 minutes on 2 cores
    python docs/scripts/arena.py out/arena                                # the table; docs/images/arena.png

Each law's figures over its 20 starts (``swarm.seed`` 1-20), as median and worst: the summary's
``safety`` figures (:mod:`tmem.analysis.safety`) and the RMS velocity at the end.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

IMAGE = Path(__file__).resolve().parent.parent / "images" / "arena.png"
#: The figures of the table: column, heading, format, which way is worse.
FIGURES = [
    ("safety.order_mean", "order, second half", "{:.2f}", min),
    ("safety.near_misses", "near misses at 3 m", "{:.0f}", max),
    ("safety.min_separation", "least separation (m)", "{:.2f}", min),
    ("safety.safety_share_max", "largest share of pairs within 3 m", "{:.1e}", max),
    ("safety.union_max", "most groups", "{:.0f}", max),
    ("safety.algebraic_connectivity_min", "least connectivity", "{:.1f}", min),
    ("safety.min_wall_clearance", "least wall clearance (m)", "{:.2f}", min),
    ("rms_velocity_final", "RMS velocity at the end (m/s)", "{:.2f}", min),
]


#: Each law's name under the figure's boxes.
SHORT = {"TMEM (8), thermostat at 4 m/s": "TMEM", "Olfati-Saber, d = 25.7 m, c2 = 3 /s": "Olfati-Saber",
         "Vásárhelyi, C_Frict = 0.15": "Vásárhelyi\nC_Frict 0.15", "Vásárhelyi, robotsim's C_Frict = 0.0238": "Vásárhelyi\nrobotsim"}


def law(row: pd.Series) -> str:
    """The law a case of the sweep flies."""
    if row["interaction.function"] != "none":
        return "TMEM (8), thermostat at 4 m/s"
    if not pd.isna(row.get("olfati_saber.d")):
        return "Olfati-Saber, d = 25.7 m, c2 = 3 /s"
    return "Vásárhelyi, C_Frict = 0.15" if not pd.isna(row.get("vasarhelyi.c_frict")) else "Vásárhelyi, robotsim's C_Frict = 0.0238"


def main(out: Path) -> None:
    results = pd.read_parquet(out / "results.parquet")
    results["interaction.function"] = results["interaction.function"].fillna("repulsion")
    results["law"] = results.apply(law, axis=1)
    print("| law | " + " | ".join(h for _, h, _, _ in FIGURES) + " |")
    print("| --- |" + " --- |" * len(FIGURES))
    for name, group in results.groupby("law", sort=False):
        cells = [f"{form.format(group[c].median())} / {form.format(worse(group[c]))}" for c, _, form, worse in FIGURES]
        print(f"| {name} ({len(group)} starts) | " + " | ".join(cells) + " |")
    _figure(results)


def _figure(results: pd.DataFrame) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = FIGURES[:3]
    fig, axes = plt.subplots(1, len(shown), figsize=(12, 3.6))
    names = list(dict.fromkeys(results["law"]))
    for ax, (column, heading, _, _) in zip(axes, shown):
        ax.boxplot([results.loc[results["law"] == n, column].to_numpy(float) for n in names], whis=(0, 100))
        ax.set_xticks(np.arange(1, len(names) + 1), [SHORT[n] for n in names], fontsize=8)
        ax.set_title(heading, fontsize=9)
    fig.suptitle("Vásárhelyi et al.'s arena: 100 agents, 230 m, 600 s; 20 starts per law (whiskers: least and largest)", fontsize=9)
    fig.tight_layout()
    fig.savefig(IMAGE, dpi=110)
    print(f"\n![The arena's figures per law](images/{IMAGE.name})")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
