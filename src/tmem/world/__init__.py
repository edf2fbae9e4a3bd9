"""The world the agents fly in: space, starts, neighbours, walls and what each agent senses.

* :mod:`tmem.world.space` — open axes or a periodic box: the nearest image, positions kept inside;
* :mod:`tmem.world.formation` — the shapes a formation is generated in (chain, ring, triangle, hex);
* :mod:`tmem.world.initial` — a scenario's starting arrays: states, flying agents, pairs, the box;
* :mod:`tmem.world.neighbors` — which pairs interact: all pairs, cell-built Verlet lists, the loop's order;
* :mod:`tmem.world.walls` — walls and obstacles as neighbours held still (W1)-(W2);
* :mod:`tmem.world.sensing` — what each agent knows of itself and its neighbours (noise, delay, loss,
  range); :mod:`tmem.world.streams`, the counter-based random draws it takes.
"""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
