"""The figures and tables of docs/gas.md: the swarm as a gas.

Prints Markdown tables to standard output and writes ``docs/gas/roots.png``,
``docs/gas/equation_of_state.png`` and ``docs/gas/field.png``::

    python docs/scripts/gas.py            # about 25 minutes on 2 cores

and, from the coverage sweep's results, the coverage table::

    tmem sweep examples/sweeps/coverage.toml --out out/coverage
    python docs/scripts/gas.py coverage out/coverage

Every number in docs/gas.md is printed here.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tmem  # noqa: E402
from tmem.law.modal import modal_gains  # noqa: E402
from tmem.vehicles.linear import state_matrices  # noqa: E402
from tmem.analysis.observables import gas_summary, temperature  # noqa: E402
from tmem.scenario import from_dict, with_changes  # noqa: E402

OUT = Path(__file__).resolve().parent.parent / "gas"
EXAMPLES = Path(__file__).resolve().parent.parent.parent / "examples" / "swarm"
KP, KD, G = 6.0, 25.0, 9.8
NEIGHBOURS = (1.0, 6.0, 12.0)


def _gas(neighbours: float, **changes) -> dict:
    """The 400-agent gas of docs/swarms.md at a density of ``neighbours`` within R + R_j, as a dict."""
    data = tmem.load(EXAMPLES / "gas2d.toml").model_dump(mode="json", exclude_none=True)
    side = math.sqrt(400 * math.pi * 40.0**2 / neighbours)
    data["space"]["box"] = [side, side]
    for key, value in changes.items():
        table, name = key.split("__")
        data.setdefault(table, {})[name] = value
    return data


def roots() -> None:
    """The slow pair of A - w B K against the summed weight w of an agent's neighbours (figure)."""
    a, b = state_matrices(KP, KD, G)
    k = np.asarray(modal_gains(kp=KP, kd=KD, g=G, r_l=12.0, im_l=0.1, im_r=0.55)).ravel()
    weights = np.linspace(0.05, 12.0, 400)
    slow = np.array([max(np.linalg.eigvals(a - w * np.outer(b, k)), key=lambda z: z.real) for w in weights])
    print("| summed weight w | slow pair of A - w B K (1/s) |\n| --- | --- |")
    for w in (0.5, 1, 2, 3, 4, 6, 8, 12):
        z = max(np.linalg.eigvals(a - w * np.outer(b, k)), key=lambda z: z.real)
        print(f"| {w:g} | {z.real:+.2e} ± {abs(z.imag):.3f} i |")
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
    left.plot(weights, slow.real, color="k")
    left.axhline(0.0, color="0.5", linewidth=0.8)
    left.axvspan(0.0, 2.0, color="tab:green", alpha=0.15, label="mean of pushes: w in [0, 2]")
    left.set(xlabel="summed weight w (n neighbours summed: w = n)", ylabel="real part of the slow pair, 1/s", yscale="symlog")
    left.set_yscale("symlog", linthresh=1e-6)
    left.set_ylim(-1e-6, 5e-2)
    left.legend(fontsize=8)
    right.plot(weights, np.abs(slow.imag), color="k")
    right.set(xlabel="summed weight w", ylabel="frequency of the slow pair, rad/s")
    for ax in (left, right):
        ax.grid(alpha=0.3)
    fig.suptitle("Closed loop A - w B K of an agent pushed by neighbours held still (Table 1, roots (5))")
    fig.savefig(OUT / "roots.png", dpi=110)


def drift() -> None:
    """RMS velocity of the gas at 1, 6 and 12 neighbours, summed and averaged pushes, and averaged
    with the thermostat holding 3 m/s; dt = 1 ms.  Then the drift over four seeds at dt = 10 ms."""
    times = (0, 10, 20, 40, 60, 90, 120)
    print("\n| neighbours | pushes | " + " | ".join(f"t = {t} s" for t in times) + " | drift 10-120 s |")
    print("| --- | --- |" + " --- |" * (len(times) + 1))
    for n in NEIGHBOURS:
        for combine, held in (("sum", False), ("mean", False), ("mean", True)):
            data = _gas(n, interaction__combine=combine, simulation__dt=0.001, simulation__duration=120.0,
                        simulation__record_every=1000, simulation__observe_gas=True)  # fmt: skip
            if held:  # the thermostat at its default tau, holding 3 m/s
                data["thermostat"] = {"rms_velocity": 3.0}
            tr = tmem.simulate(from_dict(data))
            rms = temperature(tr)
            at = {t: rms[np.searchsorted(tr.time, t)] for t in times}
            print(f"| {n:g} | {combine}{', thermostat at 3 m/s' if held else ''} | " + " | ".join(f"{at[t]:.3f}" for t in times)
                  + f" | {100 * (at[120] / at[10] - 1):+.2f} % |", flush=True)  # fmt: skip
            if held:
                late = tr.time >= 20.0
                print(f"  (thermostat, {n:g} neighbours: largest error from 20 s {100 * np.abs(rms[late] / 3.0 - 1).max():.2f} %, "
                      f"largest RMS {rms.max():.3f} m/s at {tr.time[np.argmax(rms)]:.1f} s)")  # fmt: skip
    print("\n| neighbours | pushes | drift 10-120 s, seeds 1 / 2 / 3 / 4 (dt = 10 ms) |\n| --- | --- | --- |")
    for n in (1.0, 6.0):
        for combine in ("sum", "mean"):
            drifts = []
            for seed in (1, 2, 3, 4):
                data = _gas(n, interaction__combine=combine, simulation__dt=0.01, simulation__duration=120.0,
                            simulation__record_every=100, simulation__observe_gas=True)  # fmt: skip
                data["swarm"]["seed"] = seed
                tr = tmem.simulate(from_dict(data))
                rms = temperature(tr)
                drifts.append(100 * (rms[np.searchsorted(tr.time, 120.0)] / rms[np.searchsorted(tr.time, 10.0)] - 1))
            print(f"| {n:g} | {combine} | " + " / ".join(f"{d:+.1f} %" for d in drifts) + " |", flush=True)


def encounter_gain() -> None:
    """Energy an encounter of two agents adds under (8), head-on, against speed and step."""
    print("\n| speed of each (m/s) | dt = 1 ms | dt = 0.1 ms |\n| --- | --- | --- |")
    for v in (0.5, 1.0, 2.0, 3.0, 4.0, 6.0):
        row = []
        for dt in (1e-3, 1e-4):
            tr = tmem.simulate(from_dict({
                "name": "pair", "interaction": {"function": "repulsion"},
                "simulation": {"dt": dt, "duration": 100.0, "record_every": int(round(100.0 / dt))},
                "agents": [{"position": -60.0, "velocity": v}, {"position": 60.0, "velocity": -v}],
            }))  # fmt: skip
            row.append(100 * ((tr.final_state[:, 0, 1] ** 2).sum() / (2 * v * v) - 1))
        print(f"| {v:g} | {row[0]:+.3f} % | {row[1]:+.3f} % |")


def _thermostat_run(neighbours: float, seed: int, tau: float, **simulation):
    """gas_thermostat.toml at a density of ``neighbours`` within R + R_j, its swarm drawn by ``seed``,
    with time constant ``tau``, run to 120 s and recorded every 0.1 s."""
    data = tmem.load(EXAMPLES / "gas_thermostat.toml").model_dump(mode="json", exclude_none=True)
    side = math.sqrt(400 * math.pi * 40.0**2 / neighbours)
    data["space"]["box"] = [side, side]
    data["swarm"]["seed"] = seed
    data["thermostat"]["tau"] = tau
    data["simulation"].update(duration=120.0, record_every=10, **simulation)
    return tmem.simulate(from_dict(data))


def thermostat() -> None:
    """The set-point from 3 to 4 m/s at t = 30 s, at 1, 6 and 12 neighbours, mean of pushes, against
    the thermostat's time constant, over seeds 1 to 12 of the swarm's start; held from 60 to 120 s.
    Then tau = 1 s with the gas counted at every step instead of every 0.1 s, seeds 1 to 6, and the
    spread of the speeds at one neighbour against Maxwell's."""
    print("\n| tau | counted every | neighbours | within 5 % of 4 m/s after (s), slowest | largest error, 60-120 s: "
          "median / largest | bias, 60-120 s | std of the RMS, 60-120 s |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    runs = [(tau, 0.1, range(1, 13)) for tau in (0.5, 1.0, 2.0, 5.0)] + [(1.0, 0.01, range(1, 7))]
    for tau, period, seeds in runs:
        for n in NEIGHBOURS:
            reached, largest, bias, std = [], [], [], []
            for seed in seeds:
                tr = _thermostat_run(n, seed, tau, gas_period=period)
                rms, since = temperature(tr), tr.time - 30.0
                reached.append(since[np.argmax((np.abs(rms / 4.0 - 1.0) <= 0.05) & (since > 0))])
                held = since >= 30.0
                largest.append(100 * np.abs(rms[held] / 4.0 - 1.0).max())
                bias.append(100 * (rms[held].mean() / 4.0 - 1.0))
                std.append(100 * rms[held].std() / 4.0)
            print(f"| {tau:g} s | {period:g} s | {n:g} | {max(reached):.1f} | {np.median(largest):.2f} % / "
                  f"{max(largest):.2f} % | {min(bias):+.2f} to {max(bias):+.2f} % | {min(std):.2f}-{max(std):.2f} % |",
                  flush=True)  # fmt: skip
    tr = _thermostat_run(1.0, 1, 1.0)
    held = tr.time >= 60.0
    speeds = np.linalg.norm(tr.state[held, :, :, 1], axis=-1).ravel()
    low, high = np.percentile(speeds, [5, 95])
    print(f"\none neighbour, tau = 1 s, seed 1, 60-120 s: 5-95 % of speeds within {low:.2f}-{high:.2f} m/s; "
          f"Maxwell's 2-D distribution at 4 m/s RMS: {4 * math.sqrt(-math.log(0.95)):.2f}-{4 * math.sqrt(math.log(20)):.2f} m/s")
    side = math.sqrt(400 * math.pi * 40.0**2)
    near = _in_reach(tr, side)[held].mean(axis=1)
    print(f"agents within reach of another, 60-120 s: {100 * near.min():.0f}-{100 * near.max():.0f} %")
    print("\nsummed pushes, tau = 1 s, largest error 60-120 s, seeds 1 / 2 / 3:")
    for n in (6.0, 12.0):
        errors = []
        for seed in (1, 2, 3):
            data = tmem.load(EXAMPLES / "gas_thermostat.toml").model_dump(mode="json", exclude_none=True)
            data["space"]["box"] = [math.sqrt(400 * math.pi * 40.0**2 / n)] * 2
            data["swarm"]["seed"] = seed
            data["interaction"]["combine"] = "sum"
            data["simulation"].update(duration=120.0, record_every=10)
            run = tmem.simulate(from_dict(data))
            errors.append(100 * np.abs(temperature(run)[run.time >= 60.0] / 4.0 - 1.0).max())
        print(f"  {n:g} neighbours: " + " / ".join(f"{e:.2f} %" for e in errors))
    for tau in (0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0, 2.0):  # a lone agent's speed loop, linearised (Routh-Hurwitz)
        roots = np.roots([tau, KD * tau, KP * KD * tau, KP * KD])
        print(f"tau = {tau:g} s: roots of tau s^3 + kd tau s^2 + kp kd tau s + kp kd: "
              + ", ".join(f"{z.real:.3g}{z.imag:+.3g}i" for z in roots))


def _encounter(speed: float, angle: float, offset: float, tau: float | None) -> float:
    """Closest approach of two agents meeting at ``speed`` each (the second at ``angle`` degrees from
    head-on, the first ``offset`` m off its line), the thermostat holding that speed with time
    constant ``tau`` (``None``: off)."""
    turn = math.radians(angle)
    data = {"name": "pair", "space": {"axes": 2}, "interaction": {"function": "repulsion"},
            "simulation": {"dt": 0.01, "duration": 80.0, "record_every": 1},
            "agents": [{"position": [-150.0, offset], "velocity": [speed, 0.0]},
                       {"position": [150.0 * math.cos(turn), 150.0 * math.sin(turn)],
                        "velocity": [-speed * math.cos(turn), -speed * math.sin(turn)]}]}  # fmt: skip
    if tau is not None:
        data["thermostat"] = {"rms_velocity": speed, "tau": tau}
    places = tmem.simulate(from_dict(data)).state[:, :, :, 0]
    return float(np.linalg.norm(places[:, 0] - places[:, 1], axis=1).min())


def _in_reach(trajectory, side: float) -> np.ndarray:
    """Whether each agent has another within R + R_j = 40 m, at each record (nearest periodic image)."""
    from scipy.spatial import cKDTree

    near = np.zeros(trajectory.state.shape[:2], dtype=bool)
    for k, places in enumerate(np.mod(trajectory.state[:, :, :, 0], side)):
        near[k, cKDTree(places, boxsize=side).query_pairs(40.0, output_type="ndarray").ravel()] = True
    return near


def head_on() -> None:
    """Closest approach of two agents meeting, each at the speed the thermostat holds, against the
    thermostat's time constant (none: the thermostat off)."""
    cases = [(3.0, 0.0, 0.0), (4.0, 0.0, 0.0), (6.0, 0.0, 0.0), (4.0, 30.0, 0.0), (4.0, 0.0, 10.0)]
    print("\n| tau | " + " | ".join(f"{v:g} m/s, {'head-on' if not a and not o else f'{a:g} deg' if a else f'{o:g} m off'}"
                                   for v, a, o in cases) + " |\n| --- |" + " --- |" * len(cases))  # fmt: skip
    for tau in (None, 10.0, 5.0, 2.0, 1.0, 0.5, 0.2):
        closest = [_encounter(v, a, o, tau) for v, a, o in cases]
        print(f"| {'off' if tau is None else f'{tau:g} s'} | " + " | ".join(f"{c:.2f} m" for c in closest) + " |")


def stopping_speed(reach: float = 40.0, c_max: float = 0.1) -> float:
    """The fastest head-on approach a wall stops before the agent reaches it (m/s), by bisection."""

    def breaches(v: float) -> bool:
        tr = tmem.simulate(from_dict({
            "name": "wall", "space": {"axes": 1, "walls": True, "box": [4000.0], "wall_radius": reach - 20.0},
            "interaction": {"function": "repulsion", "c_max": c_max},
            "simulation": {"dt": 0.01, "duration": 400.0, "record_every": 40000},
            "agents": [{"position": 1900.0, "velocity": -v}, {"position": 2100.0, "velocity": v}],
        }))  # fmt: skip
        return tr.gas[-1, 5] > 0

    low, high = 0.5, 40.0
    while high - low > 1e-3:
        low, high = (low, (low + high) / 2) if breaches((low + high) / 2) else ((low + high) / 2, high)
    lead = 0.0049388 / 0.0296347  # K_V / K_P: how far P* leads P per m/s
    a = 1.0 / (2.0 * G * c_max)  # full braking from the moment P* is within reach: v^2 a = reach + lead v
    bound = (lead + math.sqrt(lead**2 + 4 * a * reach)) / (2 * a)
    print(f"\nwalls, R + R_w = {reach:g} m, c_max = {c_max:g} rad: stops up to {low:.2f} m/s head-on; "
          f"braking at the tilt limit from the moment P* is within reach would stop {bound:.2f} m/s")  # fmt: skip
    return low


def pressure() -> None:
    """The walled box of gas_box.toml: the pressures (G1)-(G3)."""
    tr = tmem.simulate(tmem.load(EXAMPLES / "gas_box.toml"))
    s = gas_summary(tr, since=20.0)
    print("\n| quantity | value |\n| --- | --- |")
    for key in ("rms_velocity", "density", "pressure_walls", "pressure_virial", "pressure_wall_range", "pressure_virial_walls",
                "pressure_agreement_percent", "pressure_ideal", "encounter_rate", "mean_free_path", "breaches"):  # fmt: skip
        print(f"| {key} | {s[key]:.5g} |")
    walls, virial = s["pressure_walls"], s["pressure_virial"]
    print(f"\n(G1) + (G3) against (G2): {s['pressure_agreement_percent']:+.2f} %; (G1) alone: {100 * (virial / walls - 1):+.2f} %")
    slow = gas_summary(tmem.simulate(with_changes(tmem.load(EXAMPLES / "gas_box.toml"), {"thermostat.tau": 5.0})), since=20.0)
    print(f"(G2) over the ideal gas's: {walls / s['pressure_ideal']:.3f} at tau = 1 s, "
          f"{slow['pressure_walls'] / slow['pressure_ideal']:.3f} at tau = 5 s (RMS {slow['rms_velocity']:.4f} m/s)")
    pressure_over_seeds()


#: The seeds of the swarm's start over which gas_box.toml's figures are given.
SEEDS = range(1, 21)


def _spread(values: list[float], form: str = "{:+.2f}") -> str:
    """``median / worst (seed s)``: the worst the largest in magnitude."""
    k = int(np.argmax(np.abs(values)))
    return f"{form.format(np.median(values))} / {form.format(values[k])} (seed {SEEDS[k]})"


def pressure_over_seeds() -> None:
    """gas_box.toml from each seed of :data:`SEEDS`: how far the virial's wall pressure (G1) + (G3)
    (``pressure_virial_walls``) and (G1) alone are from (G2), over the summary's window (the second
    half) and from 20 s; and the RMS velocity's change, end against start and largest on the way."""
    from tmem.analysis.metrics import summarize

    base = tmem.load(EXAMPLES / "gas_box.toml")
    rows = {"summary's window, 100-200 s": [], "from 20 s": []}
    ends, peaks, times = [], [], []
    for seed in SEEDS:
        tr = tmem.simulate(with_changes(base, {"swarm.seed": seed}))
        summary = summarize(tr)
        for window, g in zip(rows, (summary["gas"], gas_summary(tr, since=20.0))):
            rows[window].append((g["pressure_agreement_percent"], 100 * (g["pressure_virial"] / g["pressure_walls"] - 1)))
        ends.append(summary["rms_change_percent"])
        peaks.append(summary["rms_change_peak_percent"])
        times.append(summary["rms_change_peak_time"])
    print(f"\nSeeds {SEEDS.start}-{SEEDS.stop - 1} of the start; median / worst:\n")
    print("| window | (G1) + (G3) against (G2) (%) | (G1) alone against (G2) (%) |\n| --- | --- | --- |")
    for window, values in rows.items():
        agreement, alone = zip(*values)
        print(f"| {window} | {_spread(agreement)} | {_spread(alone)} |")
    print(f"\nRMS velocity, end against start: median {np.median(ends):+.2f} %, from {min(ends):+.2f} to {max(ends):+.2f} %; "
          f"largest change on the way: median {np.median(peaks):+.1f} %, from {min(peaks):+.1f} to {max(peaks):+.1f} %, "
          f"at {min(times):g} to {max(times):g} s")  # fmt: skip


def equation_of_state() -> None:
    """Pressure (virial) against density at 3 m/s, in a periodic box, against the ideal gas (figure)."""
    densities, measured, ideal, mfp = [], [], [], []
    print("\n| neighbours | density (1/m^2) | p (virial) | p (ideal) | p / p_ideal | mean free path (m) | hard disks (m) |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for n in (0.25, 0.5, 1.0, 2.0, 4.0, 6.0, 9.0, 12.0):
        data = _gas(n, interaction__combine="mean", thermostat__rms_velocity=3.0, simulation__dt=0.01,
                    simulation__duration=300.0, simulation__record_every=100)  # fmt: skip
        tr = tmem.simulate(from_dict(data))
        s = gas_summary(tr, since=60.0)
        # 2-D kinetic theory: a disk of diameter d = R + R_j sweeps a strip 2 d wide
        hard_disks = 1.0 / (2.0 * math.sqrt(2.0) * s["density"] * 40.0)
        densities.append(s["density"])
        measured.append(s["pressure_virial"])
        ideal.append(s["pressure_ideal"])
        mfp.append(s["mean_free_path"])
        path = "—" if s["mean_free_path"] is None else f"{s['mean_free_path']:.1f}"
        print(f"| {n:g} | {s['density']:.3e} | {s['pressure_virial']:.4g} | {s['pressure_ideal']:.4g} | "
              f"{s['pressure_virial'] / s['pressure_ideal']:.3f} | {path} | {hard_disks:.1f} |", flush=True)  # fmt: skip
    fig, ax = plt.subplots(figsize=(6.5, 4.5), layout="constrained")
    ax.plot(densities, measured, "o-", color="k", label="TMEM swarm (virial, mean of pushes)")
    ax.plot(densities, ideal, "--", color="tab:red", label="ideal gas, p = n <|V|^2> / 2")
    ax.set(xlabel="density, agents per m^2", ylabel="pressure per unit agent mass, 1/s^2",
           title="Equation of state of a 2-D TMEM swarm held at 3 m/s")  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(OUT / "equation_of_state.png", dpi=110)


def field() -> None:
    """The coverage map of examples/swarm/field.toml (figure) and its coverage summary."""
    from tmem.analysis.coverage import coverage_summary
    from tmem.figures.plot import field_figure

    tr = tmem.simulate(tmem.load(EXAMPLES / "field.toml"))
    field_figure(tr).savefig(OUT / "field.png", dpi=110)
    print("\nfield.toml:", coverage_summary(tr), "breaches:", gas_summary(tr)["breaches"])
    for seconds in (0.1, 10.0, 50.0):  # how much coverage records far apart lose
        few = with_changes(tmem.load(EXAMPLES / "field.toml"), {"swarm.n": 20, "simulation.record_every": round(seconds / 0.01)})
        print(f"field.toml with 20 agents, recorded every {seconds:g} s: "
              f"{100 * coverage_summary(tmem.simulate(few))['share_final']:.1f} % covered")


def coverage(directory: str) -> None:
    """The coverage sweep's table, from its results.parquet."""
    import pandas as pd

    table = pd.read_parquet(Path(directory) / "results.parquet").sort_values(["swarm.n", "thermostat.rms_velocity"])
    print("\n| agents | set RMS (m/s) | covered in 20 min | half covered after (s) | 90 % after (s) | encounters per agent per s |")
    print("| --- | --- | --- | --- | --- | --- |")
    for _, row in table.iterrows():
        t90 = "—" if pd.isna(row["coverage.time_to_90"]) else f"{row['coverage.time_to_90']:.0f}"
        print(f"| {row['swarm.n']} | {row['thermostat.rms_velocity']:g} | {100 * row['coverage.share_final']:.1f} % | "
              f"{row['coverage.time_to_50']:.0f} | {t90} | {row['gas.encounter_rate']:.3f} |")  # fmt: skip


def main() -> None:
    OUT.mkdir(exist_ok=True)
    if sys.argv[1:2] == ["coverage"]:
        coverage(sys.argv[2])
        return
    parts = sys.argv[1:] or ["roots", "encounter_gain", "drift", "thermostat", "head_on", "stopping_speed",
                             "pressure", "equation_of_state", "field"]  # fmt: skip
    for name in parts:
        globals()[name]()


if __name__ == "__main__":
    main()
