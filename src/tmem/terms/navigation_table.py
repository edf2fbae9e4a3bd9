"""The ``[navigation]`` table: a group's mission as timed legs, and the loop that flies it::

    [navigation]
    bandwidth = 0.5            # 1/s, the group's velocity loop (N2)
    share = 0.5                # of interaction.c_max, the most the mission may ask of the set-point

    [[navigation.legs]]
    time = 0.0
    action = "route"           # "goto", "route", "velocity" or "hold"
    waypoints = [[300.0, 0.0], [300.0, 300.0]]
    speed = 5.0                # m/s: one for the route, or one per waypoint
    avoid = true               # plan the route around the [[obstacles]]

A leg starts at its ``time`` and lasts until the next one; before the first, the group flies free.
``goto`` flies to ``target`` at ``speed``, and holds there; ``route`` flies through ``waypoints``
(the last one held); ``velocity`` holds ``velocity``; ``hold`` holds ``target``, or where the group
is when the leg starts; ``assemble`` flies each agent of a ``[formation]`` to its place in the shape
(centred on ``target``, by default the formation's ``center``), no faster than ``speed``, on the
synchronised straight lines of CAPT, and holds it there; ``reshape`` changes the formation's shape in
flight to ``shape`` (a generated kind): each agent flies to its place in the new shape (CAPT from its
place in the old one) about the group's centre, moving on with the group's velocity at the leg's start,
the pairs letting go when the leg starts and those of the new shape coupling when the lines end.  The
equations are in :mod:`tmem.terms.navigation`.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from tmem.scenario.tables import FieldError, NonNegative, Number, Positive, StrictModel, per_axis


class Leg(StrictModel):
    """One leg of a mission, from ``time`` (s) to the next leg's (see the module text)."""

    time: NonNegative
    action: Literal["goto", "route", "velocity", "hold", "assemble", "reshape"]
    target: list[Number] | None = None
    waypoints: list[list[Number]] | None = None
    speed: Positive | list[Positive] | None = None
    velocity: list[Number] | None = None
    avoid: bool = False
    shape: Literal["chain", "ring", "triangle", "hex"] | None = None

    def points(self) -> list[list[float]]:
        """The leg's points: its waypoints, or its target as the one waypoint (none for ``velocity``)."""
        if self.action == "route":
            return list(self.waypoints)
        return [] if self.target is None else [list(self.target)]

    def speeds(self) -> list[float]:
        """The speed towards each point (m/s); ``inf`` for ``hold`` (its approach has no cruise); an assembly's or
        a reshape's one speed, every agent's top speed on its line."""
        if self.action in ("assemble", "reshape"):
            return [float(self.speed)]
        n = len(self.points())
        if self.speed is None:
            return [np.inf] * n
        return list(self.speed) if isinstance(self.speed, list) else [float(self.speed)] * n

    def check(self, where: str, axes: int) -> None:
        """The leg's own keys: the ones its action needs, none it ignores, one value per axis.

        Parameters
        ----------
        where : str
            The leg's place in the scenario, e.g. ``"navigation.legs[0]"``.
        axes : int
            The space's axes.
        """
        needs = {"goto": ("target", "speed"), "route": ("waypoints", "speed"), "velocity": ("velocity",), "hold": (),
                 "assemble": ("speed",), "reshape": ("shape", "speed")}  # fmt: skip
        used = {"goto": ("target", "speed", "avoid"), "route": ("waypoints", "speed", "avoid"), "velocity": ("velocity",),
                "hold": ("target",), "assemble": ("target", "speed"), "reshape": ("shape", "speed")}  # fmt: skip
        for key in ("target", "waypoints", "speed", "velocity", "shape"):
            given = getattr(self, key) is not None
            if key in needs[self.action] and not given:
                raise FieldError(f"{where}.{key}", f"is required for {self.action}")
            if given and key not in used[self.action]:
                raise FieldError(f"{where}.{key}", f"is not used by {self.action}")
        if self.avoid and "avoid" not in used[self.action]:
            raise FieldError(f"{where}.avoid", f"is not used by {self.action}")
        if self.action == "route" and not self.waypoints:
            raise FieldError(f"{where}.waypoints", "is empty: give at least one waypoint")
        if isinstance(self.speed, list) and self.action in ("assemble", "reshape"):
            raise FieldError(f"{where}.speed", f"is one speed for {self.action}: every agent's top speed (m/s)")
        if isinstance(self.speed, list) and len(self.speed) != len(self.points()):
            raise FieldError(f"{where}.speed", f"gives {len(self.speed)} speeds for {len(self.points())} waypoints: "
                             "give one for the route, or one per waypoint")  # fmt: skip
        for k, point in enumerate(self.points()):
            if len(point) != axes:
                key = f"waypoints[{k}]" if self.action == "route" else "target"
                raise FieldError(f"{where}.{key}", per_axis(axes, len(point)))
        if self.velocity is not None and len(self.velocity) != axes:
            raise FieldError(f"{where}.velocity", per_axis(axes, len(self.velocity)))


class NavigationParams(StrictModel):
    """``[navigation]``: the mission's legs, the group's velocity loop ``bandwidth`` (1/s) and the
    ``share`` of the tilt limit the mission may use (module text; :mod:`tmem.terms.navigation`)."""

    bandwidth: Positive = 0.5
    share: Positive = 0.5
    legs: list[Leg]

    def check(self, scenario) -> None:
        """The table against the scenario: legs in time order within the run, an open space, a
        bandwidth the vehicle's tilt loop can follow, a share of the tilt limit below 1.

        Parameters
        ----------
        scenario : Scenario
            The whole scenario.
        """
        from tmem.terms.navigation import loop_gains

        if not self.legs:
            raise FieldError("navigation.legs", "is empty: give at least one leg")
        if self.share >= 1.0:
            raise FieldError("navigation.share", f"must be below 1 (the pairs keep the rest of c_max), got {self.share:g}")
        if scenario.space.periodic:
            raise FieldError("navigation", "needs an open space: in a periodic box the group has no one centre to steer")
        times = [leg.time for leg in self.legs]
        for k, leg in enumerate(self.legs):
            leg.check(f"navigation.legs[{k}]", scenario.space.axes)
            if leg.time > scenario.simulation.duration:
                raise FieldError(f"navigation.legs[{k}].time",
                                 f"must not be later than duration = {scenario.simulation.duration:g} s, got {leg.time:g}")
            if k and scenario.simulation.step_of(leg.time) <= scenario.simulation.step_of(times[k - 1]):
                raise FieldError(f"navigation.legs[{k}].time", f"must come after the leg before ({times[k - 1]:g} s), "
                                 f"at least one step dt later, got {leg.time:g}")  # fmt: skip
            if leg.action in ("assemble", "reshape"):
                self._check_shaping(k, leg, scenario)
            if leg.action == "assemble" and [other.action for other in self.legs[:k]].count("assemble"):
                raise FieldError(f"navigation.legs[{k}].action", "a mission assembles its formation once")
            if leg.action == "assemble" and "reshape" in [other.action for other in self.legs[:k]]:
                raise FieldError(f"navigation.legs[{k}].action", "an assemble leg comes before any reshape: it flies "
                                 "the agents from their starts to the formation's first shape")  # fmt: skip
            if leg.avoid and not scenario.obstacles:
                raise FieldError(f"navigation.legs[{k}].avoid", "has no [[obstacles]] to plan around")
        loop_gains(scenario, self.bandwidth)  # refuses a bandwidth the tilt loop cannot follow
        if any(leg.avoid for leg in self.legs):
            from tmem.terms.navigation_plan import planned_points

            planned_points(scenario)  # refuses a route that cannot clear the obstacles (N4)
        shaping = [k for k, leg in enumerate(self.legs[:-1]) if leg.action in ("assemble", "reshape")]
        if shaping:  # the next leg waits for the lines' end, where the shape's pairs couple
            from tmem.terms.navigation_plan import shapes_flown

            ends = {shape.leg: self.legs[shape.leg].time + shape.span for shape in shapes_flown(scenario)[1:]}
            for k in shaping:
                if self.legs[k + 1].time < ends[k]:
                    raise FieldError(f"navigation.legs[{k + 1}].time", f"{self.legs[k + 1].time:g} s is before the "
                                     f"{self.legs[k].action} of legs[{k}] ends its lines at {ends[k]:.4g} s, where the "
                                     "shape's pairs couple: start it then or later")  # fmt: skip

    @staticmethod
    def _check_shaping(k: int, leg: Leg, scenario) -> None:
        """An ``assemble`` or ``reshape`` leg: a generated formation, a shape its agents can take."""
        action, f = leg.action, scenario.formation
        where = f"navigation.legs[{k}]"
        if f is None or f.kind == "edges":
            raise FieldError(f"{where}.action", f"'{action}' needs a [formation] of a generated kind "
                             "(chain, ring, triangle, hex): the shape its agents take")  # fmt: skip
        n = scenario.n_agents
        if leg.shape == "triangle" and n != 3 or leg.shape == "ring" and n < 3:
            raise FieldError(f"{where}.shape", f"a {leg.shape} cannot hold the formation's {n} agents")
