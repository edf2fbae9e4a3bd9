"""The per-agent controllers' cost: one update, and a whole per-agent loop against the engine.

For each swarm, after a warm-up run (Numba's compilation), prints:

* ``update``: the median time of one ``AgentController.update`` with every other agent's
  message (what a companion computer spends per tick), and of one ``message``;
* ``fly``: agent-steps per second of :func:`tmem.agent.fly` (messages, updates and the vehicles'
  steps in Python), and of :func:`tmem.simulate` on the same scenario, nothing recorded.

Swarms: the triangle and the 19-agent hex of examples/swarm/, and 40 agents of a random 2-D
swarm under the repulsion (every agent hears 39 messages, a few within reach at once).

Usage::

    PYTHONPATH=src python benchmarks/bench_agent.py [--seconds 0.5] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import tmem
from tmem.agent import controllers_for, fly
from tmem.scenario import with_changes

ROOT = Path(__file__).resolve().parents[1]
SWARM40 = ('[space]\naxes = 2\n[interaction]\nfunction = "repulsion"\n'
           '[swarm]\nn = 40\nseed = 3\nregion = [150.0, 150.0]\nspeed_rms = 4.0\n')  # fmt: skip


def _swarms(seconds: float) -> dict[str, tmem.Scenario]:
    timing = {"simulation.dt": 1e-3, "simulation.duration": seconds, "simulation.record_every": 10}
    return {
        "triangle": with_changes(tmem.load(ROOT / "examples/swarm/triangle.toml"), timing),
        "hex19": with_changes(tmem.load(ROOT / "examples/swarm/hex19.toml"), timing),
        "swarm40": with_changes(tmem.loads(SWARM40), timing),
    }


def _update_times(scenario: tmem.Scenario, rounds: int = 2000) -> tuple[float, float]:
    """Median seconds of one message and of one update of agent 0, all messages of the swarm given."""
    controllers = controllers_for(scenario)
    states = tmem.world.initial.build(scenario).state
    made, updated = [], []
    for k in range(rounds):
        t = k * scenario.simulation.dt
        started = time.perf_counter()
        messages = [c.message(x, t) for c, x in zip(controllers, states)]
        made.append((time.perf_counter() - started) / len(controllers))
        started = time.perf_counter()
        controllers[0].update(states[0], messages, t)
        updated.append(time.perf_counter() - started)
    return statistics.median(made), statistics.median(updated)


def _rate(run, scenario: tmem.Scenario, repeat: int) -> float:
    """Agent-steps per second of ``run(scenario)``, the best of ``repeat``."""
    best = min(_timed(run, scenario) for _ in range(repeat))
    return scenario.n_agents * scenario.simulation.n_steps / best


def _timed(run, scenario: tmem.Scenario) -> float:
    started = time.perf_counter()
    run(scenario)
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=0.5, help="simulated seconds of each loop (dt = 1 ms)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"cores {os.cpu_count()}, load average {os.getloadavg()[0]:.1f}")
    for name, scenario in _swarms(args.seconds).items():
        fly(with_changes(scenario, {"simulation.duration": 0.01}))  # compiles
        tmem.simulate(scenario, record=False)
        message, update = _update_times(scenario)
        ours = _rate(fly, scenario, args.repeat)
        engine = _rate(lambda s: tmem.simulate(s, record=False), scenario, args.repeat)
        print(f"{name:9s} {scenario.n_agents:3d} agents: message {message * 1e6:6.1f} us, update {update * 1e6:6.1f} us; "
              f"fly {ours:9.3g} agent-steps/s, simulate {engine:9.3g} ({engine / ours:.0f} x)")  # fmt: skip


if __name__ == "__main__":
    main()
