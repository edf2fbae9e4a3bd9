"""Convergence of the engine in the time step ``dt``; prints the Markdown tables of docs/convergence.md.

Run from the repository root::

    python docs/scripts/convergence.py

For repulsion (8) and attraction (Fig. 3), the engine (exact zero-order hold
of (2), control sampled every ``dt``) is compared with the continuous-time
reference of :mod:`tmem.analysis.reference`.  For switching (10) and improved
switching (11) there is no reference (the coupling flag changes at sampled
instants), so the smallest ``dt`` stands for the converged value.
"""

from __future__ import annotations

import numpy as np

import tmem
from tmem.analysis.metrics import rms_velocity
from tmem.analysis.reference import final_state
from tmem.scenario import Scenario, with_changes
from tmem.world.initial import build

DTS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)


def rms_change_percent(initial: np.ndarray, final: np.ndarray) -> float:
    """Change of the RMS velocity over the run (%), velocities shaped (agents, axes)."""
    return float(100.0 * (rms_velocity(final) / rms_velocity(initial) - 1.0))


def engine_final(scenario: Scenario, dt: float) -> tuple[np.ndarray, float]:
    """Final velocities (agents,) and RMS change (%) of the engine at ``dt``."""
    velocity = tmem.simulate(with_changes(scenario, {"simulation.dt": dt})).state[..., 1]
    return velocity[-1, :, 0], rms_change_percent(velocity[0], velocity[-1])


def reference_table() -> list[str]:
    rows = [
        "| preset | function | dt (s) | V0 (m/s) | V1 (m/s) | max abs(ΔV) vs reference (m/s) "
        "| RMS change (%) | reference RMS change (%) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name in ("repulsion", "fig5"):
        scenario = tmem.preset(name)
        function = scenario.interaction.function
        reference = final_state(scenario)[..., 1]
        v_ref = reference[:, 0]
        rms_ref = rms_change_percent(build(scenario).state[..., 1], reference)
        for dt in DTS:
            v, rms = engine_final(scenario, dt)
            error = np.max(np.abs(v - v_ref))
            rows.append(
                f"| {name} | {function} | {dt:.0e} | {v[0]:.6f} | {v[1]:.6f} "
                f"| {error:.2e} | {rms:.4f} | {rms_ref:.4f} |"
            )
        rows.append(
            f"| {name} | {function} | continuous | {v_ref[0]:.6f} | {v_ref[1]:.6f} "
            f"| – | {rms_ref:.4f} | {rms_ref:.4f} |"
        )
    return rows


def switching_table() -> list[str]:
    rows = [
        "| preset | function | dt (s) | V0 (m/s) | V1 (m/s) | RMS change (%) "
        f"| abs(Δ RMS change) vs dt = {DTS[-1]:.0e} (% points) |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in ("fig7", "fig9"):
        scenario = tmem.preset(name)
        results = {dt: engine_final(scenario, dt) for dt in DTS}
        converged = results[DTS[-1]][1]
        for dt, (v, rms) in results.items():
            rows.append(
                f"| {name} | {scenario.interaction.function} | {dt:.0e} | {v[0]:.6f} | {v[1]:.6f} "
                f"| {rms:.4f} | {abs(rms - converged):.4f} |"
            )
    return rows


def main() -> None:
    print("Repulsion (8) and attraction (Fig. 3) against the continuous-time reference:\n")
    print("\n".join(reference_table()))
    print("\nSwitching (10) and improved switching (11), engine only:\n")
    print("\n".join(switching_table()))


if __name__ == "__main__":
    main()
