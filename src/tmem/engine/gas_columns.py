"""The columns of the gas's per-agent tables, ``Gas.work`` and ``Gas.held``
(:class:`tmem.engine.records.Gas`), shared by the gas's stages (:mod:`tmem.engine.gas`) and the
thermostat (:mod:`tmem.engine.thermostat`).

A row per agent, so that the counts of a pair touch two rows.  The counts are taken every
``gas_period`` (a *count*, :attr:`tmem.engine.records.Gas.every` steps apart); what the stages
hold between counts is kept.
"""

#: Columns of ``Gas.work``, cleared at each count: neighbours within reach, their pushes' squared
#: sizes over ``c_max^2`` (the agent's contacts), the agent's virial (rad m), its ``|V|^2``, its
#: neighbours' ``|V|^2`` and, from :data:`NEIGHBOUR_VELOCITY` on, one column per axis, their
#: velocities, each neighbour weighted by its contact (T3).
NEAR, CONTACT, VIRIAL, SPEED2, NEIGHBOUR_SPEED2, NEIGHBOUR_VELOCITY = range(6)
#: Columns of ``Gas.held``, what the thermostat holds from one count to the next (T3): how far the
#: agent is in contact (:data:`tmem.engine.thermostat.FULL_CONTACT`), and from :data:`COMMON` on, one
#: column per axis, its push on the agent's group (rad).  The thermostat reads them at every step.
TOGETHER, COMMON = range(2)
