"""Olfati-Saber's flocking law as an agent term: α-agents, β-agents for obstacles and walls, a γ-agent.

R. Olfati-Saber, "Flocking for multi-agent dynamic systems: algorithms and theory", IEEE TAC
51(3):401-420, 2006 ("OS"; ``docs/flocking_laws.md`` writes the law out).  Each agent ``i`` asks
for the acceleration of Algorithm 2 (OS 24), with the β-agents of Algorithm 3 (OS, Section VII)::

    u_i = Σ_j φ_α(|q_j - q_i|_σ) n_ij + Σ_j a_ij (p_j - p_i)                       α: OS 23
          + c1_β Σ_k φ_β(|q̂_ik - q_i|_σ) n̂_ik + c2_β Σ_k b_ik (p̂_ik - p_i)          β: OS, Section VII
          - c1 (q_i - q_r) - c2 (p_i - p_r)                                       γ: OS 24

with ``n_ij = (q_j - q_i) / sqrt(1 + ε |q_j - q_i|^2)`` (OS 23), ``a_ij = ρ_h(|q_j - q_i|_σ / r_α)``
(OS 11), ``b_ik = ρ_h(|q̂_ik - q_i|_σ / d_β)``, and ``q̂_ik``, ``p̂_ik`` the β-agent: agent ``i``'s
projection on obstacle ``k`` (a circle: ``μ q_i + (1 - μ) y_k`` moving at ``μ P p_i``, ``μ = R_k / |q_i - y_k|``,
``P = I - â âᵀ``, ``â = (q_i - y_k) / |q_i - y_k|``), or on a wall of the box (its foot, moving at ``p_i``
without its normal part).  The scalar functions are :mod:`tmem.terms.flocking`'s.

``q`` and ``p`` are the position and velocity the agent knows (``known``, not ``P*`` (6)); the
acceleration becomes the set-point ``U = u / (acceleration per input)``, ``u / g`` rad for the
tilting multirotor, saturated on its norm at ``interaction.c_max`` here (F1) (the engine then
saturates the sum of all pushes again).  Distances are in metres as the user gives them: the
σ-norm and φ act on metres as the paper's do on its unitless numbers.
"""

from __future__ import annotations

from functools import cache
from typing import Annotated, NamedTuple

import numpy as np
from pydantic import Field

from tmem.scenario.fields import FieldError, NonNegative, Number, Positive, StrictModel, per_axis
from tmem.terms.base import AgentTerm, acceleration_per_input, check_gathered_knowledge, check_route, surroundings

#: Where a bump starts to fall, strictly between 0 and 1 (OS 10).
BumpStart = Annotated[float, Field(gt=0, lt=1)]


class OlfatiSaberParams(StrictModel):
    """``[olfati_saber]``: the law of :mod:`tmem.terms.olfati_saber`; defaults from OS, Section VIII, where it gives them.

    * ``d`` (m): the α-lattice's distance (OS, Section II); the paper's examples take 7, a user sets e.g. ``d_t``;
    * ``kappa``: ``r = kappa d``, the interaction range (OS, Section II), 1.2 (OS VIII);
    * ``beta_ratio``: ``d' = beta_ratio d``, the distance kept from obstacles and walls, 0.6 (OS VIII);
    * ``eps``: the σ-norm's ε (OS 8), 0.1 (OS VIII);
    * ``a``, ``b`` (m/s^2): the action function φ (OS 15), ``0 < a <= b``, 5 and 5 (OS VIII);
    * ``h_alpha``, ``h_beta``: the bumps of φ_α and φ_β (OS 10), 0.2 and 0.9 (OS VIII);
    * ``c1_beta``, ``c2_beta``: the β-agents' gains of Algorithm 3, chosen 1 and 1 (the
      scale of the α-agents' terms, whose gains Algorithms 1-2 fix at 1);
    * ``c1`` (1/s^2), ``c2`` (1/s): the γ-agent's gains (OS 24), 0 by default (no navigation: free
      flocking, Algorithm 1); ``q_r`` (m), ``p_r`` (m/s): its fixed reference, one value per axis
      (``q_r`` is needed with ``c1 > 0``; ``p_r`` is 0 if not given); or ``route`` (m), points one
      value per axis, and ``route_speed`` (m/s): the γ-agent as a virtual leader that flies the route
      from its first point at that speed and holds its last (OS Algorithm 2's moving γ-agent;
      :func:`tmem.terms.flocking.leader`).
    """

    d: Positive = 7.0
    kappa: Annotated[float, Field(gt=1, le=1e3)] = 1.2
    beta_ratio: Annotated[float, Field(gt=0, le=1e3)] = 0.6
    eps: Positive = 0.1
    a: Positive = 5.0
    b: Positive = 5.0
    h_alpha: BumpStart = 0.2
    h_beta: BumpStart = 0.9
    c1_beta: NonNegative = 1.0
    c2_beta: NonNegative = 1.0
    c1: NonNegative = 0.0
    c2: NonNegative = 0.0
    q_r: list[Number] | None = None
    p_r: list[Number] | None = None
    route: list[list[Number]] | None = None
    route_speed: Positive | None = None

    def check(self, scenario) -> None:
        """Check the table against the scenario: ``a <= b``, a reference per axis, one with ``c1 > 0``,
        and no sensing between agents (:func:`tmem.terms.base.check_gathered_knowledge`).

        Parameters
        ----------
        scenario : Scenario
            The whole scenario.
        """
        if self.a > self.b:
            raise FieldError("olfati_saber.a", f"{self.a:g} m/s^2 exceeds b = {self.b:g} m/s^2: the action function φ "
                             "(OS 15) needs 0 < a <= b for φ(0) = 0 with c = |a - b| / sqrt(4 a b)")  # fmt: skip
        axes = scenario.space.axes
        for name in ("q_r", "p_r"):
            value = getattr(self, name)
            if value is not None and len(value) != axes:
                raise FieldError(f"olfati_saber.{name}", per_axis(axes, len(value)))
        check_route("olfati_saber", self.route, self.route_speed, axes)
        for name in ("q_r", "p_r"):
            if self.route is not None and getattr(self, name) is not None:
                raise FieldError(f"olfati_saber.{name}", "is not used with a route: the γ-agent starts at its first point")
        if self.c1 > 0.0 and self.q_r is None and self.route is None:
            raise FieldError("olfati_saber.q_r", f"is required with c1 = {self.c1:g} > 0: the γ-agent (OS 24) pulls "
                             "towards it")  # fmt: skip
        check_gathered_knowledge(scenario, "olfati_saber")


class OlfatiSaberRecord(NamedTuple):
    """The record of the law: the σ-norm's ``eps``; φ's ``a``, ``b``; the bumps' ``h_alpha``, ``h_beta``;
    ``r_alpha = |r|_σ``, ``d_alpha = |d|_σ``, ``d_beta = |d'|_σ``; the gains ``c1_beta``, ``c2_beta``,
    ``c1``, ``c2``; the reference ``q_r``, ``p_r`` (per axis), or its ``route``, ``lengths`` and
    ``route_speed`` (0: none; :func:`tmem.terms.flocking.leader`), ``dt``; ``walls`` and ``obstacles``
    (:func:`tmem.terms.base.surroundings`); ``per_input``, the set-point per m/s^2; ``c_max``; and
    ``work``, shape (agents, 3, axes): ``u_i``, ``q̂ - q_i`` and ``p̂ - p_i`` of agent ``i``."""

    eps: float
    a: float
    b: float
    h_alpha: float
    h_beta: float
    r_alpha: float
    d_alpha: float
    d_beta: float
    c1_beta: float
    c2_beta: float
    c1: float
    c2: float
    q_r: np.ndarray
    p_r: np.ndarray
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
    """Agent ``i``'s u_i (module text) as a set-point (F1), saturated at ``c_max``, added to ``agents.setpoint[i]``."""
    n_axes = len(box)
    u = law.work
    for a in range(n_axes):  # the γ-agent (OS 24), fixed or flying its route, its point to the nearest periodic image
        q_r, p_r = law.q_r[a], law.p_r[a]
        if law.route_speed > 0.0:
            q_r, p_r = leader(k * law.dt, law.route, law.lengths, law.route_speed, a)  # noqa: F821  (bound)
        offset = nearest_image(known[i, a, 0] - q_r, box[a])  # noqa: F821  (bound)
        u[i, 0, a] = -law.c1 * offset - law.c2 * (known[i, a, 1] - p_r)
    for j in range(known.shape[0]):
        if j != i and agents.active[j]:
            _alpha(i, j, known, box, law)
    for a in range(n_axes):
        if law.walls[a] > 0.0:
            _wall_agent(i, a, 0.0, known, n_axes, law)
            _wall_agent(i, a, law.walls[a], known, n_axes, law)
    for o in range(law.obstacles.shape[0]):
        _obstacle_agent(i, o, known, box, law)
    add_push(agents.setpoint, u, i, n_axes, law.per_input, law.c_max)  # noqa: F821  (bound: tmem.terms.flocking)


def _alpha(i, j, known, box, law):
    """Neighbour ``j``'s ``φ_α(|q_j - q_i|_σ) n_ij + a_ij (p_j - p_i)`` (OS 23, 11), added to ``u_i``; 0 from ``r`` on."""
    n_axes = len(box)
    r2 = 0.0
    for a in range(n_axes):
        r2 += separation(known, i, j, a, box) ** 2  # noqa: F821  (bound)
    z = sigma_norm(np.sqrt(r2), law.eps)  # noqa: F821  (bound)
    if z < law.r_alpha:
        gradient = phi_alpha(z, law.r_alpha, law.d_alpha, law.h_alpha, law.a, law.b) / np.sqrt(1.0 + law.eps * r2)  # noqa: F821
        adjacency = bump(z / law.r_alpha, law.h_alpha)  # noqa: F821  (bound)
        for a in range(n_axes):
            along = separation(known, i, j, a, box)  # noqa: F821  (bound)
            law.work[i, 0, a] += gradient * along + adjacency * (known[j, a, 1] - known[i, a, 1])


def _beta(i, gap, n_axes, law):
    """The β-agent in ``work[i, 1:]``, ``q̂ - q_i`` and ``p̂ - p_i``, at ``gap = |q̂ - q_i|``:
    ``c1_β φ_β(z) n̂ + c2_β b (p̂ - p_i)`` added to ``u_i`` (OS, Section VII); 0 from ``d'`` on."""
    z = sigma_norm(gap, law.eps)  # noqa: F821  (bound)
    if z < law.d_beta:
        repel = law.c1_beta * phi_beta(z, law.d_beta, law.h_beta) / np.sqrt(1.0 + law.eps * gap * gap)  # noqa: F821
        damp = law.c2_beta * bump(z / law.d_beta, law.h_beta)  # noqa: F821  (bound)
        for a in range(n_axes):
            law.work[i, 0, a] += repel * law.work[i, 1, a] + damp * law.work[i, 2, a]


def _wall_agent(i, axis, wall, known, n_axes, law):
    """The β-agent of the wall at ``wall`` across ``axis``: the agent's foot on it, moving with the
    agent's velocity less its normal part (OS, Section VII, a hyperplane), through :func:`_beta`."""
    for a in range(n_axes):
        law.work[i, 1, a] = wall - known[i, a, 0] if a == axis else 0.0
        law.work[i, 2, a] = -known[i, a, 1] if a == axis else 0.0
    _beta(i, abs(wall - known[i, axis, 0]), n_axes, law)


def _obstacle_agent(i, o, known, box, law):
    """The β-agent of obstacle ``o`` (a circle, OS, Section VII): ``q̂ - q_i = (1 - μ)(y - q_i)``,
    ``p̂ - p_i = μ P p_i - p_i`` with ``μ = R / |q_i - y|``, ``P = I - â âᵀ``, through :func:`_beta`;
    none inside the circle."""
    n_axes = len(box)
    rho2 = 0.0
    along = 0.0  # (q_i - y) . p_i
    for a in range(n_axes):
        e = nearest_image(known[i, a, 0] - law.obstacles[o, a], box[a])  # noqa: F821  (bound)
        law.work[i, 1, a] = e
        rho2 += e * e
        along += e * known[i, a, 1]
    radius = law.obstacles[o, n_axes]
    gap = np.sqrt(rho2) - radius
    if gap > 0.0:
        mu = radius / np.sqrt(rho2)
        for a in range(n_axes):
            e = law.work[i, 1, a]
            law.work[i, 1, a] = (mu - 1.0) * e
            law.work[i, 2, a] = (mu - 1.0) * known[i, a, 1] - mu * along / rho2 * e
        _beta(i, gap, n_axes, law)


class OlfatiSaber(AgentTerm):
    """Olfati-Saber's flocking law, Algorithm 2 with the β-agents of Algorithm 3 (module text)."""

    name = "olfati_saber"
    table = OlfatiSaberParams
    local = False
    rebuilt = {**{f: "fixed for the run" for f in OlfatiSaberRecord._fields},
               "work": "work space each step writes before it reads it"}  # fmt: skip

    @classmethod
    def record(cls, settings: OlfatiSaberParams, scenario, gains) -> OlfatiSaberRecord:
        """The record of the law for a run of ``scenario``: the σ-norms of ``r``, ``d`` and ``d'``, the
        reference, the surroundings, the vehicle's set-point per m/s^2.

        Parameters
        ----------
        settings : OlfatiSaberParams
            The ``[olfati_saber]`` table.
        scenario : Scenario
            The whole scenario.
        gains : ndarray
            ``K`` of the law (unused).
        """
        from tmem.terms.flocking import route_record, sigma_norm  # the run binds the compiled law: its σ-norm (OS 8) here too

        s, axes = settings, scenario.space.axes
        route, lengths = route_record(s.route or [[0.0] * axes], axes)
        walls, obstacles = surroundings(scenario)
        return OlfatiSaberRecord(
            eps=s.eps, a=s.a, b=s.b, h_alpha=s.h_alpha, h_beta=s.h_beta, r_alpha=sigma_norm(s.kappa * s.d, s.eps),
            d_alpha=sigma_norm(s.d, s.eps), d_beta=sigma_norm(s.beta_ratio * s.d, s.eps), c1_beta=s.c1_beta,
            c2_beta=s.c2_beta, c1=s.c1, c2=s.c2, q_r=np.asarray(s.q_r or [0.0] * axes, dtype=float),
            p_r=np.asarray(s.p_r or [0.0] * axes, dtype=float), route=route, lengths=lengths,
            route_speed=float(s.route_speed or 0.0), dt=scenario.simulation.dt, walls=walls, obstacles=obstacles,
            per_input=1.0 / acceleration_per_input(scenario), c_max=float(scenario.interaction.c_max),
            work=np.zeros((scenario.n_agents, 3, axes)),
        )  # fmt: skip

    @classmethod
    @cache
    def kernel(cls):
        """The compiled push :func:`_push` with its helpers (compiled on first use: validating a scenario loads no compiler)."""
        from tmem.terms.flocking import compile_push

        return compile_push(_push, _alpha, _beta, _wall_agent, _obstacle_agent)
