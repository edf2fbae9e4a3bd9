"""The scenario schema: the whole scenario, its tables checked against each other.

A scenario is a TOML file with the tables ``[model]`` (Table 1),
``[controller]`` (roots (5)), ``[interaction]``, ``[simulation]``,
``[[agents]]`` (Table 2) and ``[[commands]]``, and optionally ``[space]``,
``[neighbors]``, ``[formation]``, ``[swarm]``, ``[sensing]`` and ``[wind]`` (:mod:`tmem.scenario.tables`
and the ``*_table`` modules beside it; a table's checks against the others live with it where they
concern that table alone, the memory a run needs in :mod:`tmem.scenario.budget`).
Every key is checked: unknown keys, non-finite numbers and values out of range
are refused; :func:`tmem.scenario.files.describe` turns the errors into the one
line of a :class:`ScenarioError`.  Defaults are documented in
``docs/parameters.md``.
"""

from __future__ import annotations

import math
import unicodedata

import numpy as np
from pydantic import create_model, field_validator, model_validator

from tmem.analysis.coverage import MAX_CELLS
from tmem.analysis.coverage.grid import finest_cell
from tmem.terms import TERMS, term_class
from tmem.world.formation import generate
from tmem.law.interaction.registry import uses_coupling
from tmem.scenario.agents_table import Agent, SwarmParams, check_agents
from tmem.scenario.bounds import warn
from tmem.scenario.budget import check_memory, check_record_size, memory_limit
from tmem.scenario.commands_table import Command, check_commands
from tmem.scenario.formation_table import FormationParams, check_formation
from tmem.scenario.motion_bounds import check_motion
from tmem.scenario.safety_table import SafetyParams, check_safety
from tmem.scenario.sensing_table import SensingParams, check_sensing
from tmem.scenario.space_table import CoverageParams, Obstacle, SpaceParams, ThermostatParams
from tmem.scenario.tables import (
    ControllerParams,
    FieldError,
    InteractionParams,
    LinearModelParams,
    ModelParams,
    NeighborParams,
    SimulationParams,
    StrictModel,
    per_axis,
)
from tmem.scenario.vehicle_bounds import check_vehicle
from tmem.scenario.wind_table import WindParams, check_wind

#: Beyond this many agents, a coupling function needs a [formation]: without one every pair
#: would be a formation pair, and their number grows as the square of the swarm.
MAX_AGENTS_ALL_PAIRS = 2000
#: Without a formation, swarms up to this size have every pair tracked (recorded distances,
#: per-pair figures) even when the function has no coupling flag.
TRACK_ALL_PAIRS = 32
#: Most characters in a scenario's ``name`` (it titles figures and tables).
MAX_NAME_LENGTH = 200
#: Most of (fastest closed-loop root) x dt.  The control is held over a step, and the error this
#: makes grows about linearly with it: Fig. 9's RMS change is +0.33 % at 0.0012 (dt = 1e-4 s),
#: +0.54 % at 0.012, +2.6 % at 0.12, +5.0 % at 0.24 and +12.6 % at 0.6 (dt = 0.05 s).  Beyond
#: 0.15 the error (over 3 percentage points) is of the size of the difference between (10) and
#: (11) that the paper reports, so a run could no longer tell them apart (docs/parameters.md).
MAX_ROOT_DT = 0.15
#: Smallest position gain K_P: below it the gains (4) lose their precision and soon underflow to 0.
MIN_K_P = 1e-150
class _Scenario(StrictModel):
    """A whole scenario; see the module docstring.

    The agents come from exactly one of ``[[agents]]`` (Table 2),
    ``[formation]`` with a generated ``kind`` (chain, ring, triangle, hex) or
    ``[swarm]`` (random); ``[formation] kind = "edges"`` couples listed
    ``[[agents]]``.  Without a formation, a coupling function (10) or (11)
    treats every pair as a formation pair with the set distance
    ``interaction.d_t``: the paper's two-agent case.
    """

    name: str = ""
    model: ModelParams = LinearModelParams()
    controller: ControllerParams = ControllerParams()
    interaction: InteractionParams = InteractionParams()
    simulation: SimulationParams = SimulationParams()
    space: SpaceParams = SpaceParams()
    neighbors: NeighborParams = NeighborParams()
    formation: FormationParams | None = None
    swarm: SwarmParams | None = None
    thermostat: ThermostatParams | None = None
    coverage: CoverageParams | None = None
    sensing: SensingParams | None = None
    wind: WindParams | None = None
    safety: SafetyParams | None = None
    obstacles: list[Obstacle] = []
    agents: list[Agent] = []
    commands: list[Command] = []

    @field_validator("name")
    @classmethod
    def _printable_name(cls, v: str) -> str:
        if len(v) > MAX_NAME_LENGTH:
            raise ValueError(f"must be at most {MAX_NAME_LENGTH} characters (it titles the figures), got {len(v)}")
        for k, ch in enumerate(v):
            if unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Co", "Cn") and ch != " ":
                raise ValueError(f"must be printable text: character {k} is {ch!r}")
        return v

    @property
    def n_agents(self) -> int:
        """Number of agents: of the swarm, of the formation, or the ``[[agents]]`` listed."""
        if self.swarm is not None:
            return self.swarm.n
        if self.formation is not None and self.formation.kind != "edges":
            return 3 if self.formation.kind == "triangle" else self.formation.n
        return len(self.agents)

    @property
    def wall_reach(self) -> float:
        """``R + R_w``: walls and obstacles push an agent whose ``P*`` is closer than this (m)."""
        radius = self.space.wall_radius
        return self.interaction.radius + (self.interaction.radius if radius is None else radius)

    @property
    def coverage_cell(self) -> float:
        """Side of the coverage map's cells (m): ``coverage.cell``; by default ``R``, or, in a box that
        cells of side ``R`` would cut into more than :data:`~tmem.analysis.coverage.grid.DEFAULT_CELLS`,
        the smallest side that cuts it into that many at most
        (:func:`~tmem.analysis.coverage.grid.finest_cell`)."""
        cell = self.coverage.cell if self.coverage is not None else None
        if cell is not None:
            return cell
        return finest_cell(self.space.box[:2], self.interaction.radius) if self.space.box else self.interaction.radius

    @property
    def agent_terms(self) -> tuple[str, ...]:
        """The agent terms the scenario gives (their tables' names, in the order of :data:`tmem.terms.TERMS`)."""
        return tuple(name for name in TERMS if getattr(self, name) is not None)

    @property
    def keeps_energy(self) -> bool:
        """Whether the speed synchronisation holds each pair's mean square speed (S3): ``interaction.keep_energy``,
        by default unless an agent term steers the group's mean motion (:attr:`tmem.terms.base.AgentTerm.steers_group`)."""
        if self.interaction.keep_energy is not None:
            return self.interaction.keep_energy
        return not any(term_class(name).steers_group for name in self.agent_terms)

    @property
    def position_gain(self) -> float:
        """``K_P`` of the law (rad/m): the modal gain on position that places the roots (5) (:func:`tmem.law.modal.modal_gains`)."""
        c = self.controller
        return self.model.position_gain(c.r_l, c.im_l, c.im_r)

    @property
    def gas_observed(self) -> bool:
        """Whether the run keeps the gas's totals (:mod:`tmem.engine.gas`): asked for, or needed by the
        mean of pushes, a thermostat, walls or obstacles."""
        return (
            self.simulation.observe_gas
            or self.interaction.combine == "mean"
            or self.thermostat is not None
            or self.space.walls
            or bool(self.obstacles)
            or any(c.action == "temperature" for c in self.commands)
        )

    def pairs(self) -> np.ndarray:
        """The pairs handled one by one, ``(i, j)`` with ``i < j``, shape ``(m, 2)``.

        The formation's edges; without a formation, every pair when the function
        couples (the paper's case) or the swarm is small (at most
        :data:`TRACK_ALL_PAIRS` agents), else none.  These pairs carry the flag
        ``F_en`` and a distance record; all other neighbours only repel.
        """
        if self.formation is None:
            n = self.n_agents
            if not uses_coupling(self.interaction.function) and n > TRACK_ALL_PAIRS:
                return np.empty((0, 2), dtype=np.int64)
            i, j = np.triu_indices(n, k=1)
            return np.stack([i, j], axis=1).astype(np.int64)
        if self.formation.kind == "edges":
            return np.array(sorted(sorted(e[:2]) for e in self.formation.edges), dtype=np.int64).reshape(-1, 2)
        if self.reshapes:  # every pair of every shape the mission takes (tmem.terms.navigation_plan)
            from tmem.terms.navigation_plan import shapes_flown

            return np.unique(np.concatenate([shape.edges for shape in shapes_flown(self)]), axis=0)
        f = self.formation
        return generate(f.kind, self.n_agents, f.d_t or self.interaction.d_t, self.space.axes).edges

    @property
    def reshapes(self) -> bool:
        """Whether a ``[navigation]`` leg changes the formation's shape in flight (``reshape``)."""
        nav = getattr(self, "navigation", None)
        return nav is not None and any(leg.action == "reshape" for leg in nav.legs)

    @property
    def shapes_change(self) -> bool:
        """Whether the mission sets which pairs are coupled: an ``assemble`` or ``reshape`` leg."""
        nav = getattr(self, "navigation", None)
        return nav is not None and any(leg.action in ("assemble", "reshape") for leg in nav.legs)

    @model_validator(mode="after")
    def _consistent(self) -> "Scenario":
        axes = self.space.axes
        self._check_sources()
        check_agents(self, axes)
        n = self.n_agents
        if n < 2:
            raise FieldError("agents", f"needs at least 2 agents, got {n}")
        self._check_space()
        max_axes = getattr(self.model, "max_axes", 3)  # a [model] table may say how many axes its model flies
        if axes > max_axes:
            raise FieldError("space.axes", f"the {self.model.kind} model flies runs of at most {max_axes} axes, "
                             f"got {axes}: its vertical axis is held by the altitude hold, not steered by the TMEM law")  # fmt: skip
        self._check_obstacles(axes)
        self._check_coverage()
        self._check_sampling()
        if self.formation is not None:
            check_formation(self, axes, n)
        elif uses_coupling(self.interaction.function) and n > MAX_AGENTS_ALL_PAIRS:
            raise FieldError(
                "interaction.function",
                f"{self.interaction.function!r} without a [formation] makes all {n * (n - 1) // 2} pairs "
                f"formation pairs; give a [formation] or use 'repulsion' beyond {MAX_AGENTS_ALL_PAIRS} agents",
            )
        if self.swarm is not None:
            region = self.swarm.region or self.space.box
            if region is None:
                raise FieldError("swarm.region", "is required unless space.box is given")
            if len(region) != axes:
                raise FieldError("swarm.region", per_axis(axes, len(region)))
            self._check_swarm_room(axes)
        if self.simulation.record_agents is not None:
            for k, a in enumerate(self.simulation.record_agents):
                if not 0 <= a < n:
                    raise FieldError(f"simulation.record_agents[{k}]", f"names agent {a}, outside 0..{n - 1}")
        check_memory(self, n, self._pair_count(n))  # before generating anything
        check_sensing(self, n, self.neighbors.uses_lists(n), memory_limit())
        check_wind(self)
        for table in (self.model, *(getattr(self, name) for name in self.agent_terms)):
            if hasattr(table, "check"):  # a vehicle's or a term's own checks against the scenario (a mission's shapes)
                table.check(self)
        pairs = self.pairs()  # generating a large formation is not free: once per validation
        if self.simulation.record_agents == [] and not len(pairs):
            raise FieldError(
                "simulation.record_agents", "is empty and there are no pairs to record: the run would record nothing"
            )
        check_commands(self, n, pairs)
        check_record_size(self, n, len(pairs))
        self._check_formation_room(axes, n)
        doubts = check_vehicle(self) + check_motion(self)  # the physical bounds (docs/parameters.md, "Bounds")
        doubts += check_safety(self) if self.safety else []
        warn(doubts)  # only once every check has passed: a refused scenario warns of nothing
        return self

    def _check_formation_room(self, axes: int, n: int) -> None:
        """A generated formation starts inside the walls and off every obstacle, jitter included."""
        f = self.formation
        if f is None or f.kind == "edges" or not (self.space.walls or self.obstacles):
            return
        shape = generate(f.kind, n, f.d_t or self.interaction.d_t, axes, f.bearing)
        places = shape.positions + np.asarray(f.center or [0.0] * axes)
        low, high = places.min(axis=0) - f.jitter, places.max(axis=0) + f.jitter
        if self.space.walls and (np.any(low < 0.0) or np.any(high > np.asarray(self.space.box))):
            raise FieldError("formation.center", f"places the formation (from {low.tolist()} to {high.tolist()}) "
                             f"outside the walled box 0..{self.space.box}")  # fmt: skip
        for o, obstacle in enumerate(self.obstacles):
            if np.any(np.linalg.norm(places - np.asarray(obstacle.center), axis=1) < obstacle.radius + f.jitter):
                raise FieldError("formation.center", f"places an agent of the formation inside obstacles[{o}]")

    def _check_space(self) -> None:
        space, reach = self.space, self.interaction.reach
        if space.periodic and space.box is not None:
            for k, side in enumerate(space.box):
                if side < reach:
                    raise FieldError(
                        f"space.box[{k}]",
                        f"{side:g} m is shorter than R + R_j = {reach:g} m: in a periodic box every agent "
                        "would meet its own images; make the box at least that wide",
                    )

    def _check_obstacles(self, axes: int) -> None:
        """Obstacles sized for the space; listed agents start inside the walls and off every obstacle."""
        for k, obstacle in enumerate(self.obstacles):
            if len(obstacle.center) != axes:
                raise FieldError(f"obstacles[{k}].center", per_axis(axes, len(obstacle.center)))
            if self.space.walls and not all(0.0 <= c <= side for c, side in zip(obstacle.center, self.space.box)):
                raise FieldError(f"obstacles[{k}].center", f"{obstacle.center} lies outside the walled box 0..{self.space.box}")
        box = self.space.box if self.space.walls else None
        for k, agent in enumerate(self.agents):
            place = np.ravel(agent.position) * np.ones(axes)
            if box is not None and not np.all((place >= 0.0) & (place <= np.asarray(box))):
                raise FieldError(f"agents[{k}].position", f"{place.tolist()} lies outside the walled box 0..{box}")
            for o, obstacle in enumerate(self.obstacles):
                if np.linalg.norm(place - np.asarray(obstacle.center)) < obstacle.radius:
                    raise FieldError(f"agents[{k}].position", f"{place.tolist()} lies inside obstacles[{o}]")

    def _check_coverage(self) -> None:
        """A coverage map needs a walled box, and at most :data:`~tmem.analysis.coverage.grid.MAX_CELLS` cells."""
        settings = self.coverage
        if settings is None:
            return
        if not self.space.walls:
            raise FieldError("coverage", "measures a walled box: set space.walls = true and space.box")
        cells = math.prod(math.ceil(side / self.coverage_cell) for side in self.space.box[:2])
        if cells > MAX_CELLS:
            raise FieldError("coverage.cell", f"{self.coverage_cell:g} m cuts the box into {cells:.3g} cells, "
                             f"at most {MAX_CELLS:.3g}; take larger cells")  # fmt: skip
        if settings.sensor_radius > 1000.0 * self.coverage_cell:
            raise FieldError("coverage.sensor_radius", f"must be at most 1000 cells ({1000.0 * self.coverage_cell:g} m), "
                             f"got {settings.sensor_radius:g}")  # fmt: skip

    def _check_swarm_room(self, axes: int) -> None:
        """A swarm in a walled box starts clear of the walls' reach; the obstacles leave it room."""
        inset = self.wall_reach if self.space.walls else 0.0
        box = self.space.box
        if self.space.walls:
            for a, side in enumerate(self.swarm.region or np.asarray(box) - 2.0 * inset):
                if not 0.0 < side <= box[a] - 2.0 * inset:
                    field = "swarm.region" if self.swarm.region else "space.box"
                    raise FieldError(f"{field}[{a}]", f"leaves no room for the swarm clear of the walls' reach "
                                     f"R + R_w = {inset:g} m on each side of the {box[a]:g} m box")  # fmt: skip
        region = self.swarm.region or (np.asarray(box) - 2.0 * inset if box is not None else None)
        if region is not None and self.obstacles:
            reach = self.wall_reach
            ball = math.pi ** (axes / 2) / math.gamma(axes / 2 + 1)
            covered = sum(ball * (o.radius + reach) ** axes for o in self.obstacles)
            if covered > 0.5 * math.prod(region):
                raise FieldError("obstacles", "with the walls' reach they cover more than half the swarm's region: "
                                 "there is no room to place it")  # fmt: skip
        if self.swarm.min_spacing is not None:
            from tmem.world.initial import spaced_swarm

            try:  # the draw itself: the starts a run takes, or the one line that says why there are none
                spaced_swarm(self, inset, np.asarray(region, dtype=float))
            except ValueError as error:
                raise FieldError("swarm.min_spacing", str(error)) from None

    def _check_sampling(self) -> None:
        """The gains must not underflow, and dt must resolve the closed loop A - B K (roots (5))."""
        c, dt = self.controller, self.simulation.dt
        left = c.r_l**2 + c.im_l**2
        k_p = self.position_gain
        if not k_p >= MIN_K_P:
            field, value = ("controller.im_r", c.im_r) if c.im_r**2 < left else ("controller.r_l", c.r_l)
            raise FieldError(
                field, f"{value:g} makes the position gain K_P = {k_p:.3g} (at least {MIN_K_P:g}): the gains (4) underflow"
            )
        # The modal gains place the roots (5) exactly; the fastest has the largest modulus.
        fastest = max(math.hypot(c.r_l, c.im_l), c.im_r)
        if fastest * dt > MAX_ROOT_DT:
            raise FieldError(
                "simulation.dt",
                f"{dt:g} s is too coarse for the closed loop: its fastest root ({fastest:.4g} rad/s) x dt = "
                f"{fastest * dt:.3g}, at most {MAX_ROOT_DT:g} (dt <= {MAX_ROOT_DT / fastest:.3g} s; see docs/parameters.md)",
            )

    def _pair_count(self, n: int) -> int:
        """How many pairs :meth:`pairs` gives, without generating them (an upper bound for a hex)."""
        f = self.formation
        if f is None:
            coupled = uses_coupling(self.interaction.function) or n <= TRACK_ALL_PAIRS
            return n * (n - 1) // 2 if coupled else 0
        return {"chain": n - 1, "ring": n, "triangle": 3, "hex": 3 * n}.get(f.kind, len(f.edges or ()))

    def _check_sources(self) -> None:
        generated = self.formation is not None and self.formation.kind != "edges"
        sources = [name for name, given in (("agents", bool(self.agents)), ("formation", generated),
                                            ("swarm", self.swarm is not None)) if given]  # fmt: skip
        if len(sources) > 1:
            raise FieldError(sources[1], f"give the agents once: by {' or '.join(sources)}, not both")
        if not sources:
            raise FieldError("agents", "no agents: give [[agents]], a [formation] or a [swarm]")

    def to_toml(self) -> str:
        """The scenario as TOML text, every default written out."""
        from tmem.scenario.files import _to_toml  # the writer lives with the reader

        return _to_toml(self.model_dump(mode="json", exclude_none=True))


#: The whole scenario: the tables above, and one optional table per agent term (:data:`tmem.terms.TERMS`).
Scenario = create_model(
    "Scenario", __base__=_Scenario, __module__=__name__, __doc__=_Scenario.__doc__,
    **{name: (term_class(name).table | None, None) for name in TERMS},
)  # fmt: skip
