"""One TMEM controller per agent: the law as a vehicle's companion computer runs it.

The engine (:mod:`tmem.engine`) steps every agent of a swarm in one compiled
loop.  This package gives each agent its own controller, which knows only its
own state, its formation edges, the operator's commands to them and the
messages the others broadcast::

    from tmem.agent import controllers_for

    controllers = controllers_for(tmem.load("examples/fig9.toml"))
    for step ...:
        messages = [c.message(state[i], t) for i, c in enumerate(controllers)]   # each agent broadcasts
        for i, c in enumerate(controllers):
            setpoint[i] = c.update(state[i], messages, t)                        # each agent's law
        ... each vehicle takes its set-point ...

* :mod:`~tmem.agent.messages` — what one agent broadcasts (:class:`AgentMessage`);
* :mod:`~tmem.agent.settings` — what a controller is built from, checked (:class:`Edge`,
  :class:`OperatorCommand`, :class:`ControllerError`);
* :mod:`~tmem.agent.controller` — :class:`AgentController`;
* :mod:`~tmem.agent.kernel` — its compiled update, the engine's stages for one agent;
* :mod:`~tmem.agent.swarm` — the controllers of a scenario (:func:`controllers_for`) and a
  plain loop flying them (:func:`fly`), bit for bit as :func:`tmem.simulate`.

``docs/agent_controller.md`` describes the message, the mapping to the
paper's equations and the conditions of the bit-identity.
"""

from __future__ import annotations

from tmem.agent.controller import AgentController, MessageWarning
from tmem.agent.messages import AgentMessage
from tmem.agent.settings import ControllerError, Edge, OperatorCommand
from tmem.agent.swarm import Flight, controllers_for, fly

__all__ = ["AgentController", "AgentMessage", "ControllerError", "Edge", "Flight", "MessageWarning", "OperatorCommand", "controllers_for",
           "fly"]
