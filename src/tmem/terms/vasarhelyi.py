"""Vásárhelyi's flocking law as an agent term: repulsion, velocity alignment, shill agents, self-propulsion.

G. Vásárhelyi, C. Virágh, G. Somorjai, T. Nepusz, A. E. Eiben, T. Vicsek, "Optimized flocking of
autonomous drones in confined environments", Science Robotics 3(20):eaat3536, 2018 ("VV",
Methods; ``docs/flocking_laws.md`` writes the law out), as its authors' simulator implements it
(github:csviragh/robotsim, ``src/algo_spp_evol.c``, ``src/utilities/interactions.c``,
``src/utilities/math_utils.c``, ``src/robotmodel.c``).  Agent ``i`` wants the velocity::

    v_d = v_flock v_i / |v_i|      (or v_flock (g - q_i) / |g - q_i|)          self-propulsion (or a goal g)
          + Σ_j p_rep (r0_rep - r_ij) (q_i - q_j) / r_ij         for r_ij < r0_rep, repulsion
          + Σ_j C_frict (v_ij - v_ij^max) (v_j - v_i) / v_ij     for v_ij > v_ij^max, alignment
          + Σ_s (v_is - v_is^max) (v_s - v_i) / v_is             for v_is > v_is^max, shill agents

then cut to ``|v_d| <= v_max``.  With a ``route``, the self-propulsion steers to a goal ``g`` instead, as
SwarmLab's goal mode does (github:lis-epfl/swarmlab, ``compute_vel_vasarhelyi.m``): the route's point
where a reference flying it at ``route_speed`` is (:func:`tmem.terms.flocking.leader`; a fixed goal for a
route of one point).  ``r_ij = |q_j - q_i| < R_C`` (the communication range),
``v_ij = |v_j - v_i|``, ``v_ij^max = max(v_frict, D(r_ij - r0_frict, a_frict, p_frict))`` with the
braking curve D (:func:`tmem.terms.flocking.braking`).  A shill agent ``s`` sits at the point of a
wall or obstacle nearest agent ``i``, moving at ``v_shill`` along the surface's normal towards the
agent, ``v_is^max = D(r_is - r0_shill, a_shill, p_shill)``.

The vehicle follows ``v_d`` through robotsim's velocity loop (``robotmodel.c``,
``RealCoptForceLaw``, then ``Step``): the acceleration ``a_d = (v_d - v_i) / tau``, cut to
``|a_d| <= a_max`` (F2), becomes the set-point ``U = a_d / (acceleration per input)`` (``a_d / g`` rad
for the tilting multirotor), saturated on its norm at ``interaction.c_max`` here (F1) (the engine
then saturates the sum of all pushes again).
"""

from __future__ import annotations

from functools import cache
from typing import Annotated, NamedTuple

import numpy as np
from pydantic import Field

from tmem.scenario.fields import FieldError, NonNegative, Number, Positive, StrictModel
from tmem.terms.base import AgentTerm, acceleration_per_input, check_gathered_knowledge, check_route, surroundings


class VasarhelyiParams(StrictModel):
    """``[vasarhelyi]``: the law of :mod:`tmem.terms.vasarhelyi` (m, m/s, m/s^2; ``p_*`` in 1/s, ``tau`` in s).

    Defaults: robotsim's ``parameters/flockingparams.dat`` (in cm, x 0.01) and
    ``parameters/unitparams.dat`` (github:csviragh/robotsim); beside each, SwarmLab's value
    (github:lis-epfl/swarmlab, ``parameters/param_swarm/param_vasarhelyi.m`` and ``param_swarm.m``):

    * ``v_flock`` 4.0: V_Flock = 400 (SwarmLab v_ref = 6);
    * ``v_max`` 8.0: V_Max = 800 (SwarmLab max_v = 7);
    * ``r0_rep`` 25.6668: R_0 = 2566.68 (SwarmLab r0_rep = d_ref = 25);
    * ``p_rep`` 0.4: Slope_Rep (SwarmLab 0.03);
    * ``r0_frict`` 35.6668: R_0 + R_0_Offset_Frict = 2566.68 + 1000, robotsim's stopping point of the
      alignment (SwarmLab r0_fric = 85.3);
    * ``c_frict`` 0.023802: C_Frict (SwarmLab 0.05);
    * ``v_frict`` 0.5: V_Frict = 50 (SwarmLab 0.63);
    * ``p_frict`` 0.4: Slope_Frict (SwarmLab 3.2);
    * ``a_frict`` 2.5: Acc_Frict = 250 (SwarmLab 4.16);
    * ``r0_shill`` 0.0: R_0_Shill (SwarmLab 0.3);
    * ``v_shill`` 6.52174: V_Shill = 652.174 (SwarmLab 13.6);
    * ``p_shill`` 0.4: Slope_Shill (SwarmLab 3.55);
    * ``a_shill`` 2.5: Acc_Shill = 250 (SwarmLab 3.02);
    * ``tau`` 1.0: tau_PID_XY, the velocity loop's relaxation time (SwarmLab has none);
    * ``a_max`` 6.0: a_max = 600 (SwarmLab max_a = 10);
    * ``r_c`` 100.0: R_C = 10000, the communication range (SwarmLab r = 150);
    * ``route`` (m), ``route_speed`` (m/s): the goal the self-propulsion steers to, flying the route's
      points from the first at that speed (none by default: self-propulsion along the agent's velocity).

    ``c_frict`` is at most 1: more would ask for more than the velocity difference it corrects.
    """

    v_flock: NonNegative = 4.0
    v_max: Positive = 8.0
    r0_rep: Positive = 25.6668
    p_rep: Positive = 0.4
    r0_frict: NonNegative = 35.6668
    c_frict: Annotated[float, Field(ge=0, le=1)] = 0.023802
    v_frict: NonNegative = 0.5
    p_frict: Positive = 0.4
    a_frict: Positive = 2.5
    r0_shill: NonNegative = 0.0
    v_shill: NonNegative = 6.52174
    p_shill: Positive = 0.4
    a_shill: Positive = 2.5
    tau: Positive = 1.0
    a_max: Positive = 6.0
    r_c: Positive = 100.0
    route: list[list[Number]] | None = None
    route_speed: Positive | None = None

    def check(self, scenario) -> None:
        """Check the table against the scenario: ``v_flock <= v_max``, ``r0_rep < r_c``, ``tau >= dt``, and no
        sensing between agents (:func:`tmem.terms.base.check_gathered_knowledge`).

        Parameters
        ----------
        scenario : Scenario
            The whole scenario.
        """
        if self.v_flock > self.v_max:
            raise FieldError("vasarhelyi.v_flock", f"{self.v_flock:g} m/s exceeds v_max = {self.v_max:g} m/s: the cut at "
                             "v_max would cut the self-propulsion itself")  # fmt: skip
        if self.r0_rep >= self.r_c:
            raise FieldError("vasarhelyi.r0_rep", f"{self.r0_rep:g} m is not less than the communication range r_c = "
                             f"{self.r_c:g} m: neighbours within the repulsion's range would not be seen")  # fmt: skip
        dt = scenario.simulation.dt
        if self.tau < dt:
            raise FieldError("vasarhelyi.tau", f"{self.tau:g} s is shorter than the step dt = {dt:g} s: the velocity loop "
                             "a = (v_d - v) / tau, held over a step, would overshoot v_d (dt / tau > 1)")  # fmt: skip
        check_route("vasarhelyi", self.route, self.route_speed, scenario.space.axes)
        check_gathered_knowledge(scenario, "vasarhelyi")


class VasarhelyiRecord(NamedTuple):
    """The record of the law: the keys of :class:`VasarhelyiParams`; ``walls`` and ``obstacles``
    (:func:`tmem.terms.base.surroundings`); the goal's ``route``, ``lengths`` and ``route_speed`` (``goal``:
    whether there is one), ``dt``; ``per_input``, the set-point per m/s^2; ``c_max``; and
    ``work``, shape (agents, 2, axes): ``v_d`` (then ``a_d``) of agent ``i``, and a shill agent's normal."""

    v_flock: float
    v_max: float
    r0_rep: float
    p_rep: float
    r0_frict: float
    c_frict: float
    v_frict: float
    p_frict: float
    a_frict: float
    r0_shill: float
    v_shill: float
    p_shill: float
    a_shill: float
    tau: float
    a_max: float
    r_c: float
    goal: bool
    route: np.ndarray
    lengths: np.ndarray
    route_speed: float
    dt: float
    walls: np.ndarray
    obstacles: np.ndarray
    per_input: float
    c_max: float
    work: np.ndarray


def _push(i, k, known, agents, box, law):
    """Agent ``i``'s ``v_d`` (module text) through the velocity loop (F2), as a set-point (F1) added to ``agents.setpoint[i]``."""
    n_axes = len(box)
    v = law.work
    speed2 = 0.0
    for a in range(n_axes):
        speed2 += known[i, a, 1] * known[i, a, 1]
    for a in range(n_axes):  # self-propulsion along the agent's own velocity
        v[i, 0, a] = law.v_flock * known[i, a, 1] / np.sqrt(speed2) if speed2 > 0.0 else 0.0
    if law.goal:  # or to the goal
        gap2 = 0.0
        for a in range(n_axes):
            v[i, 0, a] = leader(k * law.dt, law.route, law.lengths, law.route_speed, a)[0] - known[i, a, 0]  # noqa: F821
            gap2 += v[i, 0, a] * v[i, 0, a]
        for a in range(n_axes):
            v[i, 0, a] *= law.v_flock / np.sqrt(gap2) if gap2 > 0.0 else 0.0
    for j in range(known.shape[0]):
        if j != i and agents.active[j]:
            _neighbour(i, j, known, box, law)
    for a in range(n_axes):
        if law.walls[a] > 0.0:
            _wall_shill(i, a, 0.0, 1.0, known, n_axes, law)
            _wall_shill(i, a, law.walls[a], -1.0, known, n_axes, law)
    for o in range(law.obstacles.shape[0]):
        _obstacle_shill(i, o, known, box, law)
    cap(v, i, n_axes, law.v_max)  # noqa: F821  (bound: tmem.terms.flocking)
    for a in range(n_axes):  # the velocity loop (F2)
        v[i, 0, a] = (v[i, 0, a] - known[i, a, 1]) / law.tau
    cap(v, i, n_axes, law.a_max)  # noqa: F821  (bound)
    add_push(agents.setpoint, v, i, n_axes, law.per_input, law.c_max)  # noqa: F821  (bound)


def _neighbour(i, j, known, box, law):
    """Neighbour ``j``'s repulsion and alignment (module text), added to ``v_d``; nothing from ``r_c`` on."""
    n_axes = len(box)
    r2 = 0.0
    dv2 = 0.0
    for a in range(n_axes):
        r2 += separation(known, i, j, a, box) ** 2  # noqa: F821  (bound)
        dv2 += (known[j, a, 1] - known[i, a, 1]) ** 2
    if r2 < law.r_c * law.r_c:
        r = np.sqrt(r2)
        repel = law.p_rep * (law.r0_rep - r) / r if 0.0 < r < law.r0_rep else 0.0
        dv = np.sqrt(dv2)
        slack = max(law.v_frict, braking(r - law.r0_frict, law.a_frict, law.p_frict))  # noqa: F821  (bound)
        align = law.c_frict * (dv - slack) / dv if dv > slack else 0.0
        for a in range(n_axes):
            along = separation(known, i, j, a, box)  # noqa: F821  (bound)
            law.work[i, 0, a] += -repel * along + align * (known[j, a, 1] - known[i, a, 1])


def _shill(i, gap, known, n_axes, law):
    """The shill agent at ``gap`` (m, negative past the surface) moving at ``v_shill`` along the normal in
    ``work[i, 1]``: ``(v_is - D) (v_s - v_i) / v_is`` added to ``v_d`` where ``v_is > D(gap - r0_shill, a_shill, p_shill)``."""
    dv2 = 0.0
    for a in range(n_axes):
        dv2 += (law.v_shill * law.work[i, 1, a] - known[i, a, 1]) ** 2
    dv = np.sqrt(dv2)
    allowed = braking(gap - law.r0_shill, law.a_shill, law.p_shill)  # noqa: F821  (bound)
    if dv > allowed:
        for a in range(n_axes):
            law.work[i, 0, a] += (dv - allowed) * (law.v_shill * law.work[i, 1, a] - known[i, a, 1]) / dv


def _wall_shill(i, axis, wall, inwards, known, n_axes, law):
    """The shill agent of the wall at ``wall`` across ``axis``, whose normal into the box is ``inwards``
    (+1 or -1) times the axis, through :func:`_shill`."""
    for a in range(n_axes):
        law.work[i, 1, a] = inwards if a == axis else 0.0
    _shill(i, inwards * (known[i, axis, 0] - wall), known, n_axes, law)


def _obstacle_shill(i, o, known, box, law):
    """The shill agent of obstacle ``o`` (a circle), at its point nearest the agent, moving away from
    its centre, through :func:`_shill`; none with the agent at the centre."""
    n_axes = len(box)
    rho2 = 0.0
    for a in range(n_axes):
        law.work[i, 1, a] = nearest_image(known[i, a, 0] - law.obstacles[o, a], box[a])  # noqa: F821  (bound)
        rho2 += law.work[i, 1, a] ** 2
    if rho2 > 0.0:
        rho = np.sqrt(rho2)
        for a in range(n_axes):
            law.work[i, 1, a] /= rho
        _shill(i, rho - law.obstacles[o, n_axes], known, n_axes, law)


class Vasarhelyi(AgentTerm):
    """Vásárhelyi's flocking law (module text)."""

    name = "vasarhelyi"
    table = VasarhelyiParams
    local = False
    rebuilt = {**{f: "fixed for the run" for f in VasarhelyiRecord._fields},
               "work": "work space each step writes before it reads it"}  # fmt: skip

    @classmethod
    def record(cls, settings: VasarhelyiParams, scenario, gains) -> VasarhelyiRecord:
        """The record of the law for a run of ``scenario``: the table's keys, the surroundings, the
        vehicle's set-point per m/s^2.

        Parameters
        ----------
        settings : VasarhelyiParams
            The ``[vasarhelyi]`` table.
        scenario : Scenario
            The whole scenario.
        gains : ndarray
            ``K`` of the law (unused).
        """
        from tmem.terms.flocking import route_record

        walls, obstacles = surroundings(scenario)
        axes = scenario.space.axes
        route, lengths = route_record(settings.route or [[0.0] * axes], axes)
        keys = settings.model_dump(exclude={"route", "route_speed"})
        return VasarhelyiRecord(**keys, goal=settings.route is not None, route=route, lengths=lengths,
                                route_speed=float(settings.route_speed or 0.0), dt=scenario.simulation.dt, walls=walls,
                                obstacles=obstacles, per_input=1.0 / acceleration_per_input(scenario),
                                c_max=float(scenario.interaction.c_max), work=np.zeros((scenario.n_agents, 2, axes)))  # fmt: skip

    @classmethod
    @cache
    def kernel(cls):
        """The compiled push :func:`_push` with its helpers (compiled on first use: validating a scenario loads no compiler)."""
        from tmem.terms.flocking import compile_push

        return compile_push(_push, _neighbour, _shill, _wall_shill, _obstacle_shill)
