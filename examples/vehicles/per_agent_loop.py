"""Per-agent TMEM controllers driven from a plain loop, the way a flight-stack bridge drives them.

Every simulated vehicle below stands for a real one.  On a real swarm each vehicle's companion
computer runs one ``AgentController`` inside a node (for instance a ROS 2 node next to
Crazyswarm2's server), and at every tick of a timer of period dt:

1. reads the vehicle's state estimate: position, velocity, tilt and tilt rate on each axis;
2. publishes this agent's message (``controller.message``) on a topic all agents share;
3. takes the latest message of every other agent from that topic;
4. updates the controller (``controller.update``), which returns the tilt set-point of each axis;
5. sends the set-point to the vehicle's attitude loop (on a Crazyflie, e.g. as roll and pitch
   of an attitude set-point).

Here the topic is a dictionary, the vehicles are the scenario's vehicle model stepped with its own
compiled step, and all agents tick together.  At the end the run is set beside ``tmem.simulate``
of the same scenario: the per-agent controllers fly the engine's trajectories to the bit.

Usage::

    python examples/vehicles/per_agent_loop.py [SCENARIO] [--duration SECONDS]

SCENARIO defaults to examples/swarm/triangle.toml, flown for 5 s.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import tmem
from tmem.agent import AgentController, AgentMessage, controllers_for
from tmem.vehicles import vehicle_model
from tmem.scenario import with_changes

HERE = Path(__file__).resolve().parent


class Topic:
    """The shared radio topic: the last message each agent published, as the floats on the wire."""

    def __init__(self):
        self.latest: dict[int, np.ndarray] = {}

    def publish(self, message: AgentMessage) -> None:
        self.latest[message.sender] = message.to_floats()  # 3 + 3 axes float64 numbers

    def messages(self) -> list[AgentMessage]:
        return [AgentMessage.from_floats(floats) for floats in self.latest.values()]


class SimulatedVehicle:
    """One vehicle: its state (P, V, phi, omega per axis), its body state (what the model keeps beyond
    the axes: the quadrotor's attitude, rotors and height; nothing for the linear model) and the
    model's step over dt."""

    def __init__(self, model, start: np.ndarray, dt: float):
        self.state = start[np.newaxis].copy()  # the model's step works on an array of agents: here one
        self.body = model.initial_body(self.state)
        self.setpoint = np.zeros((1, start.shape[0]))
        self._step, self._hold = model.kernel(), model.step_params(dt)

    def state_estimate(self) -> np.ndarray:
        return self.state[0]  # a real vehicle: its state estimator's output

    def send_setpoint(self, tilt: np.ndarray) -> None:
        self.setpoint[0] = tilt  # a real vehicle: an attitude set-point message

    def advance(self) -> None:
        """Fly one period dt with the set-point held (already within c_max: scale 1)."""
        self._step(self.state, self.body, self.setpoint, 0, 1.0, self._hold, self.state.shape[1])


class AgentNode:
    """What runs on one companion computer: the controller, between the vehicle and the topic."""

    def __init__(self, controller: AgentController, vehicle: SimulatedVehicle, topic: Topic):
        self.controller, self.vehicle, self.topic = controller, vehicle, topic

    def publish(self, t: float) -> None:
        self.topic.publish(self.controller.message(self.vehicle.state_estimate(), t))

    def on_timer(self, t: float) -> None:
        received = self.topic.messages()  # its own message is among them: the controller skips it
        setpoint = self.controller.update(self.vehicle.state_estimate(), received, t)
        self.vehicle.send_setpoint(setpoint)


def fly_nodes(scenario: tmem.Scenario) -> list[SimulatedVehicle]:
    """Fly the scenario's swarm as separate nodes and vehicles; return the vehicles at the end."""
    dt = scenario.simulation.dt
    model = vehicle_model(scenario.model)
    topic = Topic()
    starts = tmem.world.initial.build(scenario).state
    vehicles = [SimulatedVehicle(model, start, dt) for start in starts]
    nodes = [AgentNode(c, v, topic) for c, v in zip(controllers_for(scenario), vehicles)]
    for k in range(scenario.simulation.n_steps + 1):
        t = k * dt  # each node's clock; the tick is round(t / dt)
        for node in nodes:
            node.publish(t)
        for node in nodes:
            node.on_timer(t)
        if k < scenario.simulation.n_steps:
            for vehicle in vehicles:
                vehicle.advance()
    # Both agents of a pair log its couplings; the first agent's log is printed.
    logged = [e for node in nodes for e in node.controller.events if e.kind != "command" and e.agents[0] == node.controller.agent]
    for event in sorted(logged, key=lambda e: e.time):
        rule = f" ({event.rule})" if event.rule else ""
        print(f"  t = {event.time:7.3f} s  pair {event.agents}: {event.kind}{rule}")
    return vehicles


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scenario", nargs="?", default=str(HERE.parent / "swarm" / "triangle.toml"))
    parser.add_argument("--duration", type=float, default=5.0, help="seconds to fly (commands after it are dropped)")
    args = parser.parse_args()
    scenario = tmem.load(args.scenario)
    commands = [c.model_dump(exclude_none=True) for c in scenario.commands if c.time <= args.duration]
    scenario = with_changes(scenario, {"simulation.duration": args.duration, "commands": commands})
    sim = scenario.simulation
    print(f"{scenario.name or args.scenario}: {scenario.n_agents} agents, {sim.n_steps} ticks of {sim.dt:g} s")
    vehicles = fly_nodes(scenario)
    final = np.array([v.state[0] for v in vehicles])
    engine = tmem.simulate(scenario).final_state
    print("final positions (m):", np.round(final[:, :, 0], 3).tolist())
    print("the same bits as tmem.simulate:", "yes" if np.array_equal(final, engine) else "NO")


if __name__ == "__main__":
    main()
