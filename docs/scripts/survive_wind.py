"""The wind axis of "What survives" in docs/vehicles.md: Fig. 9 and the hex in wind, from the sweeps.

::

    python docs/scripts/survive_wind.py out

reads the ``results.parquet`` of examples/sweeps/vehicles_fig9_wind.toml and vehicles_hex19_wind.toml
(run with ``tmem sweep FILE --out out/vehicles_NAME``), prints Fig. 9's breaking points (coupling (9)
off the first pass, no uncoupling after the command), the hex's largest edge error over the last
20 s beside the 1 m band, under (11) alone and synchronised, and their tables, and draws
docs/images/vehicles-wind.png with the linear model's and the exact quadrotor's calm values, flown
here, as reference lines; then the hex's velocity at 60 s, calm and in 16 m/s, flown here.  Where
the sensing sweeps were run under the same ``out``, it checks that their reference case gave the
wind sweeps'.  The total runtime goes to standard error.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from survive import (  # first: it selects matplotlib's file backend
    BAND, EXAMPLES, FIG9_COLUMNS, FIG9_METRICS, HEX_COLUMNS, HEX_METRICS, IMAGES, WIND_AXES, draw_panels, fig9_values,
    hex_values, load, print_band, print_first_pass, print_references, read, references, save, table, tmem, with_changes,
)

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def check_reference(out: Path, name: str, rows) -> None:
    """Say whether the wind sweep's reference case gave the sensing sweep's figures, where both were run."""
    if not (out / f"vehicles_{name}_sensing" / "results.parquet").exists():
        return
    earlier = read(out, f"{name}_sensing")
    columns = [c for c in FIG9_COLUMNS | HEX_COLUMNS if c in rows]
    ours, theirs = (r[r["axis"].isna()].iloc[0][columns].astype(float).to_numpy() for r in (rows, earlier))
    same = np.array_equal(ours, theirs, equal_nan=True)
    print(f"{name}: the wind sweep's reference case {'gives' if same else 'does NOT give'} the sensing sweep's figures", file=sys.stderr)


#: The hex's panels in wind: its shape over the last 20 s and its speed, under (11) alone and synchronised.
HEX_WIND_METRICS = {k: HEX_METRICS[k] for k in ("formation.distance_error_last_20s.max", "rms_change_percent")}
MODES = {False: "hex19, (11) alone", True: "hex19, synchronised (S2)"}


def wind_report(out: Path, refs: dict) -> None:
    """The wind sweeps: Fig. 9's and the hex's tables and breaking points, and docs/images/vehicles-wind.png."""
    pair, hexagon = read(out, "fig9_wind"), read(out, "hex19_wind")
    print("\n### Fig. 9 in wind\n")
    print_first_pass(pair)
    print()
    table(pair, FIG9_COLUMNS, WIND_AXES)
    modes = dict(list(hexagon.groupby("interaction.synchronise")))
    for synchronised, rows in modes.items():
        print(f"\n### {MODES[synchronised]} in wind\n")
        print_band(rows)
        print()
        table(rows, HEX_COLUMNS, WIND_AXES)
    check_reference(out, "fig9", pair)
    check_reference(out, "hex19", modes[False])
    n = len(FIG9_METRICS) + len(HEX_WIND_METRICS) * len(modes)
    fig, panels = plt.subplots(n, len(WIND_AXES), figsize=(9, 2.2 * n), squeeze=False)
    draw_panels(panels[: len(FIG9_METRICS)], pair, {k[1]: fig9_values(v) for k, v in refs.items() if k[0] == "fig9"},
                {k: f"Fig. 9: {v}" for k, v in FIG9_METRICS.items()}, WIND_AXES)  # fmt: skip
    for m, (synchronised, rows) in enumerate(modes.items()):
        first = len(FIG9_METRICS) + m * len(HEX_WIND_METRICS)
        refs_hex = {k[1]: hex_values(v) for k, v in refs.items() if k[0] == "hex19" and not synchronised}
        draw_panels(panels[first : first + len(HEX_WIND_METRICS)], rows, refs_hex,
                    {k: f"{MODES[synchronised]}:\n{v}" for k, v in HEX_WIND_METRICS.items()}, WIND_AXES, BAND)  # fmt: skip
    panels[0][0].legend(fontsize=7)
    save(fig, IMAGES / "vehicles-wind.png")


def print_drift() -> None:
    """The hex's mean velocity along its flight and its agents' spread about it at 60 s, calm and in 16 m/s."""
    print("\n### the hex's velocity at 60 s, at 100 Hz (m/s; 3 at the start)\n")
    base = with_changes(load(EXAMPLES / "vehicles" / "hex19.toml"), {"sensing.period": 0.01})
    for synchronised in (False, True):
        for wind in ({}, {"wind.velocity": [16.0, 0.0]}):
            trajectory = tmem.simulate(with_changes(base, {"interaction.synchronise": synchronised, **wind}))
            velocity = trajectory.model.velocity(trajectory.final_state)
            print(f"- {MODES[synchronised]}, {wind or 'calm'}: mean {velocity[:, 0].mean():.3f}, spread (std) {velocity[:, 0].std():.3f}")


def main(argv: list[str]) -> None:
    if len(argv) != 1:
        sys.exit("usage: python docs/scripts/survive_wind.py OUT")
    started = time.perf_counter()
    refs = references()
    print_references(refs)
    wind_report(Path(argv[0]), refs)
    print_drift()
    print(f"{time.perf_counter() - started:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1:])
