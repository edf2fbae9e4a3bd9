"""The paper's claim "the results are similar under other initial conditions", tested.

Two agents start 50 m apart and close at 1 to 8 m/s (Table 2 closes at
4.5 m/s); every other parameter is the presets'.  For each start the four
functions are run, and the script prints ``docs/other_starts.md`` in full::

    python docs/scripts/other_starts.py > docs/other_starts.md
"""

from __future__ import annotations

import tmem
from tmem.analysis.metrics import summarize
from tmem.scenario import with_changes

#: (velocity of agent 0 at 50 m, velocity of agent 1 at 0 m), m/s.
STARTS = [(-v0 + 0.0, v1) for v0 in (0.0, 0.5, 1.5, 2.5, 4.0) for v1 in (1.0, 2.0, 3.0, 4.0)]
DASH = "—"


def run(function: str, v0: float, v1: float) -> dict:
    agents = [{"position": 50.0, "velocity": v0}, {"position": 0.0, "velocity": v1}]
    scenario = with_changes(tmem.preset("fig7"), {"interaction.function": function, "agents": agents})
    return summarize(tmem.simulate(scenario))


def cell(s: dict) -> str:
    if not s["coupled"]:
        return f"no coupling, {s['rms_change_percent']:+.2f} %"
    return f"{s['couple_time']:.1f} → {s['uncouple_time']:.1f} s, {s['rms_change_percent']:+.2f} %"


def main() -> None:
    print("# Other initial conditions\n")
    print("The paper says its results are similar under other initial conditions. Here two agents start 50 m")
    print("apart and close at 1 to 8 m/s (Table 2 closes at 4.5 m/s); every other parameter is the presets'.")
    print("Regenerate with `python docs/scripts/other_starts.py > docs/other_starts.md`.\n")
    print("Cells for (10) and (11): coupling time → uncoupling time (command at 29 s), RMS velocity change. ")
    print("Ratio: RMS change of (10) over that of (11), where both couple.\n")
    print("| V0, V1 (m/s) | closing speed | (8) RMS | Fig. 3 final distance | (10) switching | (11) improved | ratio |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    both, failing = [], []
    for v0, v1 in STARTS:
        r = {f: run(f, v0, v1) for f in tmem.FUNCTION_NAMES}
        ratio = DASH
        if r["switching"]["coupled"] and r["improved"]["coupled"]:
            value = r["switching"]["rms_change_percent"] / r["improved"]["rms_change_percent"]
            ratio = f"{value:.1f}"
            both.append(value)
        if not r["switching"]["coupled"]:
            failing.append(v1 - v0)
        print(
            f"| {v0:g}, {v1:g} | {v1 - v0:g} m/s | {r['repulsion']['rms_change_percent']:+.2f} % | "
            f"{r['attraction']['final_distance']:.0f} m | {cell(r['switching'])} | {cell(r['improved'])} | {ratio} |"
        )
    print()
    print(
        f"Attraction alone never couples (every final distance is beyond R + R_j = 40 m), and repulsion alone "
        f"keeps the RMS velocity throughout. Switching (10) fails to couple at closing speeds up to "
        f"{max(failing):g} m/s: its uncoupled branch is the full repulsion (8), which turns a slow pair "
        f"round before |d| reaches d_t. Where both couple, the ratio of the RMS changes of (10) and (11) ranges "
        f"from {min(both):.1f} to {max(both):.1f}."
    )


if __name__ == "__main__":
    main()
