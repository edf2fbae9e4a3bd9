"""The columns of the gas's per-agent arrays, ``Gas.work`` and ``Gas.kept``
(:class:`tmem.engine.records.Gas`), shared by the gas's stages (:mod:`tmem.engine.gas`) and the
thermostat (:mod:`tmem.engine.thermostat`).

A row per agent, so that the counts of a pair touch two rows.  The counts are taken every
``gas_period`` (a *count*, :attr:`tmem.engine.records.Gas.every` steps apart); what the stages
hold between counts is kept.
"""

#: Columns of ``Gas.work``, cleared at each count: neighbours within reach, their pushes' squared
#: sizes over ``c_max^2`` (the agent's contacts), the agent's virial (rad m), its ``|V|^2``, the size
#: of the box walls' pushes (rad) and their moment about the walls (rad m) (both written at every
#: step), its neighbours' ``|V|^2`` and, from :data:`NEIGHBOUR_VELOCITY` on, one column per axis,
#: their velocities, each neighbour weighted by its contact (T3).
NEAR, CONTACT, VIRIAL, SPEED2, WALL_PUSH, WALL_MOMENT, NEIGHBOUR_SPEED2, NEIGHBOUR_VELOCITY = range(8)
#: Columns of ``Gas.kept``, kept from step to step: neighbours within reach at the count before,
#: the weight of its pushes, ``1 / max(1, contacts)`` (C1), its tilt limit this step, how far it is
#: in contact (T3: :data:`tmem.engine.thermostat.FULL_CONTACT`), and from :data:`COMMON` on, one
#: column per axis, the thermostat's push on its group (rad, T3), each from the last count.
NEAR_BEFORE, WEIGHT, LIMIT, TOGETHER, COMMON = range(5)
