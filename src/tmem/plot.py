"""Figures of a run, in the layout of the paper's Figs. 5, 7 and 9.

``velocity.png``: each agent's velocity and the RMS velocity against time.
``distance.png``: the pair distance against time with ``R + R_j`` and
``d_t`` marked and the coupling events, above the flag ``F_en``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import metrics  # noqa: E402
from .engine import Trajectory  # noqa: E402

#: Most pairs drawn in one figure; the closest ones are chosen.
MAX_PAIRS_DRAWN = 8
_EVENT_STYLE = {"couple": ("tab:green", "-"), "uncouple": ("tab:red", "-"), "command": ("0.4", ":")}


def _title(trajectory: Trajectory) -> str:
    s = trajectory.scenario
    name = f"{s.name}: " if s.name else ""
    return f"{name}{s.interaction.function} function, c_max = {s.interaction.c_max:g} rad"


def _mark_events(ax, trajectory: Trajectory) -> None:
    seen = set()
    for e in trajectory.events:
        color, style = _EVENT_STYLE[e.kind]
        label = e.kind if e.kind not in seen else None
        seen.add(e.kind)
        ax.axvline(e.time, color=color, linestyle=style, linewidth=1, label=label)


def velocity_figure(trajectory: Trajectory):
    """Velocities of the agents and their RMS velocity against time."""
    fig, ax = plt.subplots(figsize=(8, 4.5), layout="constrained")
    t = trajectory.time
    velocity = trajectory.state[..., 1]
    n_axes = velocity.shape[2]
    for i in range(velocity.shape[1]):
        for a in range(n_axes):
            suffix = f" ({'xyz'[a]})" if n_axes > 1 else ""
            ax.plot(t, velocity[:, i, a], linewidth=1.2, label=f"V{i}{suffix}")
    ax.plot(t, metrics.rms_velocity(velocity), color="k", linestyle="--", linewidth=1.5, label="RMS velocity")
    _mark_events(ax, trajectory)
    ax.set_xlabel("time, s")
    ax.set_ylabel("velocity, m/s")
    ax.set_title(_title(trajectory))
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig


def distance_figure(trajectory: Trajectory):
    """Pair distance with ``R + R_j`` and ``d_t`` marked, above the coupling flag."""
    fig, (top, bottom) = plt.subplots(
        2, 1, figsize=(8, 6), sharex=True, height_ratios=(3, 1), layout="constrained"
    )
    t = trajectory.time
    dist = metrics.distance(trajectory)
    shown = np.argsort(trajectory.min_distance)[:MAX_PAIRS_DRAWN]
    ia = trajectory.scenario.interaction
    for p in shown:
        i, j = trajectory.pairs[p]
        top.plot(t, dist[:, p], linewidth=1.2, label=f"|P{j} - P{i}|")
        bottom.step(t, trajectory.flag[:, p], where="post", linewidth=1.2, label=f"pair {i}-{j}")
    top.axhline(ia.reach, color="tab:purple", linestyle="--", linewidth=1, label=f"R + R_j = {ia.reach:g} m")
    top.axhline(ia.d_t, color="tab:olive", linestyle="--", linewidth=1, label=f"d_t = {ia.d_t:g} m")
    _mark_events(top, trajectory)
    top.set_ylabel("distance, m")
    top.set_title(_title(trajectory))
    top.grid(alpha=0.3)
    top.legend(loc="best", fontsize=8)
    bottom.set_ylabel("F_en")
    bottom.set_yticks([0, 1])
    bottom.set_ylim(-0.1, 1.1)
    bottom.set_xlabel("time, s")
    bottom.grid(alpha=0.3)
    return fig


def write_figures(trajectory: Trajectory, directory: Path) -> list[Path]:
    """Write ``velocity.png`` and ``distance.png`` into ``directory``."""
    paths = []
    for name, make in (("velocity.png", velocity_figure), ("distance.png", distance_figure)):
        fig = make(trajectory)
        path = Path(directory) / name
        fig.savefig(path, dpi=120)
        plt.close(fig)
        paths.append(path)
    return paths
