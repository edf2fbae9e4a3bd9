"""The step loop: the stages of :mod:`tmem.engine.stages` in order, compiled once per vehicle model.

:func:`advance_for` gives the loop of a vehicle model, serial or on threads.
The loop's source is written once (:func:`_advance_source`); each model gets
its own compiled copy with the model's step kernel bound to the name
``vehicle_step``, so the model's step is inlined and a model costs nothing at
run time.  Each copy has a name of its own: Numba keys its on-disk cache by
the function's name, not by ``parallel`` or by what a global name is bound
to, and copies sharing a name would stand in for each other.

Both loops are compiled without Numba's runtime (``_nrt=False``), so without
reference counts.  Every record a stage receives, and every field read from
it, would otherwise cost an atomic reference-count change per array, each
step: 20 to 60 of them, which made a two-agent step take more than twice as
long as its arithmetic.  It is safe because the caller keeps every array
alive and nothing in a step allocates; a stage that allocated would not
compile.  For the same reason no parallel loop reduces into a variable (Numba
allocates for that): blocks write their partial results into work space.
"""

from __future__ import annotations

import types
from functools import cache

import numba
import numpy as np

from tmem import _numba_cache  # noqa: F401  (drops stale compiled code before any is loaded)
from tmem.world.space import into_box
from tmem.world.sensing import measure
from tmem.engine.records import DONE, LISTS_STALE
from tmem.law.modal import tilt_scale
from tmem.engine.gas import gas_pushes, tally, tilt_limit
from tmem.engine.pairs import formation_pairs
from tmem.engine.sensed import sensed_formation_pairs, sensed_neighbour_pushes
from tmem.engine.pushes import neighbour_pushes
from tmem.engine.stages import apply_commands, commands_due, corrected_positions, is_recorded, record

#: Whether the loop takes the sensed path (:mod:`tmem.engine.sensed`); bound for each compiled copy by
#: :func:`advance_for`.  Numba prunes the branch not taken before it types the loop, so the exact
#: copy is compiled as if the sensed stages did not exist.
SENSED = False
#: Whether the gas is observed (:attr:`tmem.engine.records.Gas.observe`), bound for each compiled copy
#: in the same way: a run without the gas's options steps its agents in a loop with no branch for
#: them (the vehicles' step took a fifth longer with the branches, on 3·10^4 agents).
OBSERVED = False


def vehicle_step(x, body, u, i, scale, params, n_axes):
    """Placeholder for the vehicle model's compiled step, bound by :func:`advance_for`.

    Parameters
    ----------
    x, body, u, i, scale, params, n_axes
        As :attr:`tmem.vehicles.base.VehicleModel.step` takes them.
    """
    raise NotImplementedError("the step loop is compiled by advance_for, which binds the vehicle model's step")


def _advance_source(k_stop, run, law, params, vehicle, sensing, agents, pairs, neighbours, commands, records, events, counters,
                    gas, wall_params):
    """Advance from step ``counters.step`` to ``k_stop``; return ``DONE``, or ``LISTS_STALE`` when the
    neighbour lists must be built before the step ``counters.step`` (the caller builds them from
    ``neighbours.p_ref`` and calls again).

    Each step: commands -> measurement -> P* (6) -> neighbour pushes -> formation pairs -> thermostat,
    walls and obstacles (when the gas is observed) -> record -> saturate the set-point and step the
    vehicles (held over ``dt``).  On the sensed path each agent measures, and pushes from what it
    measured.  When the gas is observed, its counts are taken at the steps that are multiples of
    ``gas.every``."""
    listed = 1 if SENSED else 0  # the lists hold P* (6); with sensing, P (the range is one of positions)
    box = run.box
    n_axes = len(box)
    c_max = params.c_max
    x = agents.state
    u = agents.setpoint
    body = agents.body
    active = agents.active
    observe = OBSERVED
    work, limit, totals = gas.work, gas.limit, gas.totals  # parallel loops take arrays, not records
    walls, obstacles, g_dt, dt, every = gas.walls, gas.obstacles, gas.g_dt, gas.dt, gas.every
    for k in range(counters.step[0], k_stop):
        counters.step[0] = k
        counting = OBSERVED and k % every == 0
        rebuild = commands_due(k, commands, counters) and apply_commands(k, commands, agents, pairs, events, counters, gas)
        known = x
        if SENSED:
            known = measure(k, x, sensing)
        moved2 = corrected_positions(known, agents, law, run, neighbours, gas, listed, counting)
        if rebuild or (run.use_lists and np.sqrt(moved2) > 0.5 * run.skin):
            for i in range(x.shape[0]):
                for a in range(n_axes):
                    neighbours.p_ref[i, a] = agents.corrected[i, a, listed]
            return LISTS_STALE
        if SENSED:
            sensed_neighbour_pushes(k, agents, neighbours, law, params, run, sensing)
            sensed_formation_pairs(k, agents, pairs, law, params, run, events, counters, sensing)
        else:
            neighbour_pushes(agents, neighbours, law, params, run, gas, counting)
            formation_pairs(k, known, agents, pairs, law, params, run, events, counters, gas, counting)
        if OBSERVED:
            gas_pushes(known, agents, gas, wall_params, run, neighbours.block_shift2.shape[0], counting)
        if is_recorded(k, run):
            record(agents, pairs, records, c_max, run, counters, gas, SENSED)
        if k < run.n_steps:
            sampled = min(every, run.n_steps - k) if counting else 0  # the steps this count stands for
            for i in numba.prange(x.shape[0]):
                if active[i]:
                    scale = tilt_scale(u, i, n_axes, tilt_limit(observe, limit, i, c_max))
                    vehicle_step(x, body, u, i, scale, vehicle, n_axes)
                    for a in range(n_axes):
                        if box[a] > 0.0 and not 0.0 <= x[i, a, 0] < box[a]:  # inside, the floor is 0
                            x[i, a, 0] = into_box(x[i, a, 0], box[a])
                    if observe:
                        tally(x, i, scale, work, totals, walls, obstacles, box, g_dt, dt, n_axes, sampled)
    counters.step[0] = k_stop
    return DONE


@cache
def advance_for(model_class, threaded: bool, sensed: bool = False, observed: bool = False):
    """The compiled loop of a vehicle model (a :class:`tmem.vehicles.base.VehicleModel` subclass).

    Parameters
    ----------
    model_class
        Its ``step`` kernel is bound to ``vehicle_step``; its ``kind`` names the copy.
    threaded
        Per-agent stages and blocks of neighbour sums on threads (large swarms).
    sensed
        The sensed path (:mod:`tmem.engine.sensed`): a copy of its own, named ``..._sensed``.
    observed
        The gas observed (its stages and totals, :mod:`tmem.engine.gas`): a copy named ``..._gas``.
    """
    name = (f"_advance_{model_class.kind}_{'threaded' if threaded else 'serial'}{'_sensed' if sensed else ''}"
            f"{'_gas' if observed else ''}")  # fmt: skip
    namespace = dict(_advance_source.__globals__, vehicle_step=model_class.step, SENSED=sensed, OBSERVED=observed)
    source = types.FunctionType(_advance_source.__code__, namespace, name)
    source.__qualname__ = name
    return numba.njit(cache=True, parallel=threaded, error_model="numpy", _nrt=False)(source)
