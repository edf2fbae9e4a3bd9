"""A swarm's starting places from a Crazyswarm2 ``crazyflies.yaml``: the scenario key ``agents_from``.

Crazyswarm2 lists a lab's robots in ``crazyflies.yaml``::

    robots:
      cf231:
        enabled: true
        uri: radio://0/80/2M/E7E7E7E7E7
        initial_position: [0.0, 0.0, 0.0]
        type: cf21

A scenario with ``agents_from = "crazyflies.yaml"`` (a path relative to the scenario file) gets
one agent per *enabled* robot, in the file's order, named after the robot and starting at rest at
its ``initial_position`` (m, Crazyswarm2's world frame: z up).  A run with fewer than three axes
keeps the first ones (x, or x and y) and needs the robots to agree on the others: robots that
differ in height cannot start a 2-D run.  The file's other keys (``uri``, ``type``,
``robot_types``, ``all``) say how to fly the robots, not where they start, and are not read.

The agents replace ``agents_from`` before the scenario is validated, so the scenario stored with
a run lists them as ``[[agents]]`` and loads again without the YAML file.
"""

from __future__ import annotations

import math
import reprlib
from pathlib import Path

from tmem.scenario.agents_table import AGENT_NAME
from tmem.scenario.tables import ScenarioError

#: The scenario key naming the file.
KEY = "agents_from"
#: How the file's layout is said in messages.
LAYOUT = "robots: NAME: {enabled, uri, initial_position: [x, y, z], type}"


#: The most characters of a value or a name shown in a message.
SHOWN = 80
_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxdict, _REPR.maxstring, _REPR.maxother = 2, 4, 4, 40, 40


def _refuse(where: str, reason: str) -> ScenarioError:
    return ScenarioError(f"{KEY}: {where}: {reason}")


def _shown(value: object) -> str:
    """``value`` as a short ``repr``: nested lists cut after a few items and levels, so that a YAML alias
    repeated level after level ("billion laughs") is never written out; at most :data:`SHOWN` characters."""
    text = _REPR.repr(value)
    return text if len(text) <= SHOWN else text[: SHOWN - 3] + "..."


def _name(name: str) -> str:
    """A robot's name for a message: control characters escaped (a newline cannot start a line), cut short."""
    text = name if name.isprintable() else repr(name)[1:-1]
    return text if len(text) <= SHOWN else text[: SHOWN - 3] + "..."


def _parse(path: Path, text: str) -> dict:
    """The file's ``robots`` table; a YAML syntax error or another layout is refused in one line."""
    import yaml  # here: only scenarios with agents_from need it

    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" (line {mark.line + 1}, column {mark.column + 1})" if mark is not None else ""
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise _refuse(str(path), f"YAML syntax error{at}: {problem}") from None
    robots = document.get("robots") if isinstance(document, dict) else None
    if not isinstance(robots, dict):
        raise _refuse(str(path), f"has no robots table; Crazyswarm2's crazyflies.yaml has {LAYOUT}")
    return robots


def _position(path: Path, name: str, robot: object) -> list[float] | None:
    """The robot's ``initial_position`` if it is enabled, ``None`` if not; a malformed entry is refused."""
    where = f"{path}: robots.{_name(name)}"
    if not isinstance(robot, dict):
        raise _refuse(where, f"must be a table ({LAYOUT.removeprefix('robots: NAME: ')})")
    enabled = robot.get("enabled")
    if not isinstance(enabled, bool):
        raise _refuse(f"{where}.enabled", f"must be true or false, got {_shown(enabled)}")
    if not enabled:
        return None
    if not AGENT_NAME.fullmatch(name):
        raise _refuse(where, "a robot's name must be 1 to 64 letters, digits, '_', '.' or '-'")
    place = robot.get("initial_position")
    numbers = isinstance(place, list) and all(isinstance(v, int | float) and not isinstance(v, bool) for v in place)
    if not numbers or len(place) != 3 or not all(math.isfinite(v) for v in place):
        raise _refuse(f"{where}.initial_position", f"must be 3 finite numbers [x, y, z] (m), got {_shown(place)}")
    return [float(v) for v in place]


def _check_plane(path: Path, places: dict[str, list[float]], axes: int) -> None:
    """A run on fewer than three axes drops the others: the robots must agree on them."""
    first = next(iter(places.items()), None)
    for name, place in places.items():
        for a in range(axes, 3):
            if place[a] != first[1][a]:
                axis = "xyz"[a]
                raise _refuse(
                    f"{path}: robots.{_name(name)}.initial_position",
                    f"{axis} = {place[a]:g} differs from robots.{_name(first[0])}'s {first[1][a]:g}, but the run has "
                    f"space.axes = {axes} (it keeps {'x' if axes == 1 else 'x and y'}); set axes = 3 in [space], "
                    f"or give every enabled robot the same {axis}",
                )


def agents_from(path: Path, axes: int) -> list[dict]:
    """The ``[[agents]]`` of a Crazyswarm2 ``crazyflies.yaml``: one per enabled robot, named, at rest.

    Parameters
    ----------
    path : Path
        The file.
    axes : int
        The scenario's ``space.axes``: each agent keeps that many of its robot's coordinates.
    """
    from tmem.scenario.files import read_text  # the reader of every scenario file; it imports this module

    try:
        text = read_text(path, "crazyflies.yaml", ScenarioError)
    except ScenarioError as exc:
        raise ScenarioError(f"{KEY}: {exc}") from None
    robots = _parse(path, text)
    places = {}
    for name, robot in robots.items():
        place = _position(path, str(name), robot)
        if place is not None:
            places[str(name)] = place
    if not places:
        raise _refuse(str(path), "no robot is enabled (enabled: true)")
    _check_plane(path, places, axes)
    return [{"name": name, "position": place[0] if axes == 1 else place[:axes]} for name, place in places.items()]


def expand(data: dict, directory: Path) -> dict:
    """The scenario's tables with ``agents_from`` replaced by the ``[[agents]]`` it names.

    Parameters
    ----------
    data : dict
        A scenario's tables as ``tomllib`` reads them.
    directory : Path
        The directory ``agents_from`` is relative to: the scenario file's.
    """
    if KEY not in data:
        return data
    value = data[KEY]
    if not isinstance(value, str) or not value:
        raise ScenarioError(f"{KEY}: must be the path of a Crazyswarm2 crazyflies.yaml (a string), got {_shown(value)}")
    formation = data.get("formation")
    generated = isinstance(formation, dict) and formation.get("kind") != "edges"
    for other, given in (("agents", "agents" in data), ("swarm", "swarm" in data), ("formation", generated)):
        if given:
            raise ScenarioError(f"{KEY}: give the agents once: by {KEY} or {other}, not both")
    space = data.get("space")
    axes = space.get("axes", 1) if isinstance(space, dict) else 1
    axes = axes if axes in (1, 2, 3) and not isinstance(axes, bool) else 3  # a bad axes is space.axes's error
    agents = agents_from(directory / value, axes)
    return {**{k: v for k, v in data.items() if k != KEY}, "agents": agents}
