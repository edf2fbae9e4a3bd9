"""Sweep files: a base scenario and what varies, checked and expanded into numbered cases.

A sweep file is TOML::

    name = "encounters"
    base = "fig7"            # a preset, or a scenario file (relative to this file)
    cases = 10000            # random draws; the same draws at every grid point
    seed = 1                 # of the random draws
    metrics = ["rms_change_percent", "coupled", "couple_time", "uncouple_time"]
    batch = 500              # cases per Dask task (optional)

    [set]                    # fixed changes to the base (optional)
    "agents.0.position" = 0.0

    [grid]                   # every combination of these lists
    "interaction.function" = ["switching", "improved"]

    [random]                 # drawn per case: uniform, loguniform, normal, choice or polar
    "agents.1.position" = { uniform = [45, 80] }
    "agents.0.velocity" = { polar = [[1, 5], [150, 210]] }   # 2-D: length 1-5, direction 150-210 degrees

    [[case]]                 # explicit cases, each a table of changes (optional)
    "interaction.c_max" = 0.05

Keys are dotted parameter paths of the scenario (``interaction.c_max``,
``agents.1.velocity``), as in :func:`tmem.scenario.with_changes`.  The cases
are every explicit case (or one empty case) times every grid point times
every random draw, numbered in that order; a case's number and its values
depend only on the file, so a sweep run again, or resumed, has the same
cases.  Drawing the same random starts at every grid point makes the grid's
settings compare on equal terms (a paired comparison).

Every mistake is a :class:`SweepError` with a one-line message naming the
key and the reason, found before anything runs: an empty grid, a range with
low > high, an unknown parameter path, a value the scenario refuses at some
grid point, an unknown metric.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from pydantic import Field, ValidationError, model_validator

from tmem.scenario import (
    PRESETS,
    FieldError,
    Number,
    Scenario,
    ScenarioError,
    StrictModel,
    describe,
    load,
    preset,
    read_text,
    with_changes,
)
from tmem.scenario.files import parse_toml

#: Metrics of ``summary.json`` (:func:`tmem.analysis.metrics.summarize`) a sweep can keep, with the batch's too.
SCALAR_METRICS = (
    "rms_velocity_initial",
    "rms_velocity_final",
    "rms_change_percent",
    "min_distance",
    "final_distance",
    "coupled",
    "couple_time",
    "uncouple_time",
    "uncouple_rule",
)
#: The column type of a metric that is not a number.
METRIC_TYPES = {"coupled": "boolean", "uncouple_rule": "string"}
_PAIR_KEYS = (
    "coupled_at|uncoupled_at|separated_at|min_distance|final_distance|mean_distance_coupled"
    "|oscillation_amplitude|distance_error\\.(mean|rms|max)"
)
_FORMATION_KEYS = (
    "formed_at|coupled_at_end|amplitude_max|direction_error_deg|settling_time|residual_error"
    "|distance_error(_last_20s)?\\.(mean|rms|max)"
)
_GAS_KEYS = (
    "rms_velocity|kinetic_energy_per_axis|density|pressure_virial|pressure_walls|pressure_wall_range"
    "|pressure_virial_walls|pressure_agreement_percent"
    "|pressure_ideal|encounter_rate|mean_free_path|breaches"
)
_COVERAGE_KEYS = "share_final|time_to_50|time_to_90"
_SAFETY_KEYS = (
    "radius|closing_speed_limit|order_mean|order_min|min_separation|near_misses|safety_share_max|safety_share_mean"
    "|closest_pass|collisions|union_max|algebraic_connectivity_min|min_obstacle_clearance|min_wall_clearance"
    "|edge_error_max|edge_error_rms|edge_error_max_final|edge_error_rms_final|shape_distance_final|time_to_goal"
)
#: Nested figures of ``summary.json`` by dotted path: per formation, per pair (by its index), of the
#: gas (:func:`tmem.analysis.observables.gas_summary`), of the coverage (:func:`~tmem.analysis.coverage.runs.coverage_summary`)
#: and of safety and the field's figures (:func:`tmem.analysis.safety.safety_summary`).
NESTED_METRIC = re.compile(
    rf"formation\.({_FORMATION_KEYS})|pairs\.\d+\.({_PAIR_KEYS})|gas\.({_GAS_KEYS})|coverage\.({_COVERAGE_KEYS})"
    rf"|safety\.({_SAFETY_KEYS})"
)
#: Most cases one sweep may have.
MAX_CASES = 1_000_000


class SweepError(ValueError):
    """A sweep that cannot be run; the message is one line naming the key."""


def _kind(value: Any) -> str:
    """The kind of a value as a results column sees it (an integer and a float are both numbers)."""
    if isinstance(value, bool):
        return "booleans"
    if isinstance(value, int | float):
        return "numbers"
    if isinstance(value, str):
        return "strings"
    return "lists or tables"


#: The kinds of :class:`Distribution`.
DISTRIBUTIONS = ("uniform", "loguniform", "normal", "choice", "polar")


class Distribution(StrictModel):
    """How one parameter is drawn: exactly one of the kinds of :data:`DISTRIBUTIONS`.

    ``polar = [[low, high], [from, to]]`` draws a vector in the plane, ``[L cos a, L sin a]``, of
    length ``L`` uniform in ``[low, high]`` and direction ``a`` uniform in ``[from, to]`` degrees:
    a start at a random bearing, or a velocity with a random heading.
    """

    uniform: list[Number] | None = Field(None, min_length=2, max_length=2)
    loguniform: list[Number] | None = Field(None, min_length=2, max_length=2)
    normal: list[Number] | None = Field(None, min_length=2, max_length=2)
    choice: list[Any] | None = Field(None, min_length=1)
    polar: list[Annotated[list[Number], Field(min_length=2, max_length=2)]] | None = Field(None, min_length=2, max_length=2)

    @model_validator(mode="after")
    def _one_kind(self) -> "Distribution":
        given = [k for k in DISTRIBUTIONS if getattr(self, k) is not None]
        if len(given) != 1:
            raise FieldError("", f"give exactly one of {', '.join(DISTRIBUTIONS)}")
        if self.polar is not None:
            (low, high), (start, end) = self.polar
            if not 0 <= low <= high:
                raise FieldError("polar", f"the lengths must have 0 <= low <= high, got [{low}, {high}]")
            if start > end:
                raise FieldError("polar", f"the directions must have from <= to, got [{start}, {end}]")
        for kind in ("uniform", "loguniform"):
            bounds = getattr(self, kind)
            if bounds is not None and bounds[0] > bounds[1]:
                raise FieldError(kind, f"low {bounds[0]} > high {bounds[1]}")
        if self.loguniform is not None and self.loguniform[0] <= 0:
            raise FieldError("loguniform", f"low must be > 0, got {self.loguniform[0]}")
        if self.normal is not None and self.normal[1] < 0:
            raise FieldError("normal", f"the standard deviation must be >= 0, got {self.normal[1]}")
        if self.choice is not None:
            kinds = {_kind(v) for v in self.choice}
            if len(kinds) > 1:  # one results column holds them all: it needs one type
                raise FieldError("choice", f"mixes {' and '.join(sorted(kinds))}; give values of one kind, got {self.choice}")
        return self

    def draw(self, rng: np.random.Generator, n: int) -> list:
        """``n`` values (Python numbers or the listed choices).

        Parameters
        ----------
        rng : numpy.random.Generator
            The sweep's generator, seeded by its ``seed``.
        n : int
            How many values.
        """
        if self.uniform is not None:
            return rng.uniform(*self.uniform, size=n).tolist()
        if self.loguniform is not None:
            low, high = np.log(self.loguniform)
            return np.exp(rng.uniform(low, high, size=n)).tolist()
        if self.normal is not None:
            return rng.normal(*self.normal, size=n).tolist()
        if self.polar is not None:
            length = rng.uniform(*self.polar[0], size=n)
            angle = np.radians(rng.uniform(*self.polar[1], size=n))
            return np.stack([length * np.cos(angle), length * np.sin(angle)], axis=1).tolist()
        return [self.choice[i] for i in rng.integers(len(self.choice), size=n)]


class SweepFile(StrictModel):
    """The sweep file's schema; see the module docstring."""

    name: str = ""
    base: str
    cases: int | None = Field(None, ge=1, le=MAX_CASES)
    seed: int = Field(0, ge=0)
    batch: int | None = Field(None, ge=1, le=1_000_000)
    metrics: list[str] = Field(list(SCALAR_METRICS), min_length=1)
    set: dict[str, Any] = {}
    grid: dict[str, list[Any]] = {}
    random: dict[str, Distribution] = {}
    case: list[dict[str, Any]] = []

    @model_validator(mode="after")
    def _consistent(self) -> "SweepFile":
        for path, values in self.grid.items():
            if not values:
                raise FieldError(f"grid.{path}", "is empty; give at least one value")
            kinds = {_kind(v) for v in values}
            if len(kinds) > 1:
                raise FieldError(f"grid.{path}", f"mixes {' and '.join(sorted(kinds))}; give values of one kind")
        if self.random and self.cases is None:
            raise FieldError("cases", "is required with a [random] table: how many draws")
        if self.cases is not None and not self.random:
            raise FieldError("cases", "counts random draws, but there is no [random] table")
        for m in self.metrics:
            if m not in SCALAR_METRICS and not NESTED_METRIC.fullmatch(m):
                raise FieldError("metrics", f"unknown metric {m!r}; choose from {', '.join(SCALAR_METRICS)}, "
                                 "formation.*, pairs.N.*, gas.*, coverage.*, safety.*")  # fmt: skip
        if len(set(self.metrics)) != len(self.metrics):
            raise FieldError("metrics", "lists a metric twice")
        where: dict[str, str] = {}  # path -> the table that gives it; explicit cases may share paths
        tables = [("set", self.set), ("grid", self.grid), ("random", self.random)]
        tables += [(f"case[{i}]", c) for i, c in enumerate(self.case)]
        for table_name, table in tables:
            for path in table:
                if path in ("case", "error", "seconds") or path in self.metrics:
                    raise FieldError(f"{table_name}.{path}", "is a column of the results, not a parameter path")
                kind = table_name.split("[")[0]
                if path in where and where[path].split("[")[0] != kind:
                    raise FieldError(f"{table_name}.{path}", f"is also given in {where[path]}")
                where.setdefault(path, table_name)
        if self.n_cases > MAX_CASES:
            raise FieldError("cases", f"the sweep has {self.n_cases} cases; at most {MAX_CASES}")
        return self

    @property
    def n_cases(self) -> int:
        """Explicit cases (at least one) × grid points × random draws."""
        grid_points = math.prod(len(v) for v in self.grid.values())
        return max(len(self.case), 1) * grid_points * (self.cases or 1)


@dataclass(frozen=True)
class Case:
    """One run of the sweep: its number and its changes to the base scenario (path to value)."""

    index: int
    changes: dict[str, Any]


@dataclass(frozen=True)
class Sweep:
    """A checked sweep: the file's content, the base scenario (with its ``[set]`` changes), where it came from."""

    spec: SweepFile
    base: Scenario
    source: str
    text: str

    @property
    def name(self) -> str:
        """The sweep file's ``name``, else its file name without ``.toml``."""
        return self.spec.name or Path(self.source).stem

    @property
    def parameters(self) -> list[str]:
        """The parameter paths that vary from case to case, in file order."""
        paths = list(self.spec.grid) + list(self.spec.random)
        for case in self.spec.case:
            paths += [p for p in case if p not in paths]
        return paths

    @property
    def settings(self) -> list[str]:
        """The varied paths that are not drawn at random: each of their combinations is a setting."""
        return [p for p in self.parameters if p not in self.spec.random]

    @property
    def n_cases(self) -> int:
        """Number of cases: explicit cases times grid points times random draws."""
        return self.spec.n_cases

    def _settings(self) -> list[dict[str, Any]]:
        """Every explicit case times every grid point, in case order."""
        explicit = self.spec.case or [{}]
        grid = [dict(zip(self.spec.grid, values)) for values in itertools.product(*self.spec.grid.values())]
        return [{**e, **g} for e in explicit for g in grid]

    @cached_property
    def _draws(self) -> list[dict[str, Any]]:
        n = self.spec.cases or 1
        rng = np.random.default_rng(self.spec.seed)
        columns = {path: dist.draw(rng, n) for path, dist in sorted(self.spec.random.items())}
        return [{path: values[r] for path, values in columns.items()} for r in range(n)]

    def cases(self) -> list[Case]:
        """Every case, numbered from 0: explicit case, then grid point, then random draw."""
        draws = self._draws
        return [
            Case(s * len(draws) + r, {**setting, **draw})
            for s, setting in enumerate(self._settings())
            for r, draw in enumerate(draws)
        ]

    @property
    def fingerprint(self) -> str:
        """A digest of everything that decides the cases and their rows (not ``batch``)."""
        content = self.spec.model_dump(mode="json", exclude={"batch"})
        content["base"] = self.base.model_dump(mode="json")
        return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()

    def check(self) -> None:
        """Build the scenario of every setting with the first random draw; raise :class:`SweepError`."""
        draw = self._draws[0]
        for setting in self._settings():
            try:
                with_changes(self.base, {**setting, **draw})
            except ScenarioError as exc:
                values = ", ".join(f"{p} = {v!r}" for p, v in setting.items() if p in self.settings)
                where = f" (at {values})" if values else ""
                raise SweepError(f"{self.source}: {exc}{where}") from None


def _dotted(table: dict, prefix: str = "") -> dict:
    """``{"interaction": {"c_max": [..]}}`` as ``{"interaction.c_max": [..]}``: both spellings mean a path.

    A table whose keys are a distribution's kinds is a value, not a level of the path.
    """
    flat = {}
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict) and value and not value.keys() <= Distribution.model_fields.keys():
            flat.update(_dotted(value, f"{path}."))
        else:
            flat[path] = value
    return flat


def loads_sweep(text: str, source: str = "<sweep>", directory: Path | None = None) -> Sweep:
    """Parse and check a sweep given as TOML text; ``directory`` anchors a relative ``base`` path.

    Parameters
    ----------
    text, source : str
        The sweep, in TOML, and where it came from, as :func:`tmem.scenario.loads` takes a scenario's.
    directory : Path or None
        Where a relative ``base`` file is found; default: the current directory.
    """
    data = parse_toml(text, source, SweepError)
    for table in ("set", "grid", "random"):
        if isinstance(data.get(table), dict):
            data[table] = _dotted(data[table])
    if isinstance(data.get("case"), list):
        data["case"] = [_dotted(c) if isinstance(c, dict) else c for c in data["case"]]
    try:
        spec = SweepFile.model_validate(data)
    except ValidationError as exc:
        raise SweepError(f"{source}: {describe(exc)}") from None
    try:
        if spec.base.endswith(".toml"):
            base = load((directory or Path.cwd()) / spec.base)
        elif spec.base in PRESETS:
            base = preset(spec.base)
        else:
            raise ScenarioError(f"base: {spec.base!r} is neither a preset ({', '.join(PRESETS)}) nor a .toml file")
    except ScenarioError as exc:
        raise SweepError(f"{source}: {exc}") from None
    try:
        base = with_changes(base, spec.set)
    except ScenarioError as exc:
        raise SweepError(f"{source}: set: {exc}") from None
    sweep = Sweep(spec=spec, base=base, source=source, text=text)
    sweep.check()
    return sweep


def load_sweep(path: str | Path) -> Sweep:
    """Read and check a sweep file; raise :class:`SweepError`.

    Parameters
    ----------
    path : str or Path
        The sweep file; a relative ``base`` is found beside it.
    """
    path = Path(path)
    return loads_sweep(read_text(path, "sweep", SweepError), source=str(path), directory=path.parent)
