"""Scenario files: TOML reading and writing, editing by parameter path, and the shipped presets.

:func:`load` and :func:`loads` read a scenario, :func:`with_changes` edits one,
:func:`preset` gives one of the paper's, :meth:`Scenario.to_toml` writes one
back.  Every failure is a :class:`ScenarioError` with one line naming the
field and the reason (:func:`describe`).
"""

from __future__ import annotations

import json
import math
import os
import stat
import tomllib
import typing
from importlib import resources
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from tmem.scenario import crazyflies
from tmem.scenario.bounds import reading
from tmem.scenario.schema import Scenario
from tmem.scenario.tables import MODEL_KINDS, FieldError, ScenarioError

#: Largest scenario or sweep file read (bytes): a bigger one is a mistake, not a scenario.
MAX_FILE_BYTES = 16 * 2**20

#: Top-level keys of a sweep file that no scenario has: a file with one is a sweep file (``docs/sweeps.md``).
SWEEP_KEYS = ("base", "grid", "random", "case")

#: The shipped scenarios, ``src/tmem/presets/NAME.toml``.
PRESETS = ("fig5", "fig7", "fig9", "repulsion")


#: Tables chosen by a kind: pydantic names the kind in a location (``model.linear.kp``); a file does not.
_KINDS = {"model": MODEL_KINDS}


def _location(loc: tuple) -> str:
    if len(loc) > 1 and loc[1] in _KINDS.get(loc[0], ()):
        loc = loc[:1] + loc[2:]
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text


_REWORDING = (
    ("Input should be a valid dictionary or instance of", "must be a table, a"),
    ("Input should be a valid dictionary or object to extract fields from", "must be a table"),
    ("List should have", "must have"),
    ("Input should be", "must be"),
    (" after validation", ""),
)


def _explain(error: dict) -> str:
    where = _location(error["loc"])
    kind = error["type"]
    if kind == "extra_forbidden":
        reason = "unknown key (a typo?)"
    elif kind == "missing":
        reason = "is required"
    elif kind == "finite_number":
        reason = f"must be a finite number, got {error['input']}"
    elif kind == "union_tag_invalid":  # a table chosen by kind, of an unknown kind
        key = error["ctx"]["discriminator"].strip("'")
        where, tags = f"{where}.{key}", error["ctx"]["expected_tags"]
        reason = f"must be {'one of ' if ',' in tags else ''}{tags}, got {error['input'][key]!r}"
    else:
        ctx_error = error.get("ctx", {}).get("error")
        if isinstance(ctx_error, FieldError):
            where = f"{where}.{ctx_error.field}" if where and ctx_error.field else (where or ctx_error.field)
            reason = ctx_error.reason
        else:
            reason = error["msg"].removeprefix("Value error, ")
            for pydantic_words, ours in _REWORDING:
                reason = reason.replace(pydantic_words, ours)
            if "got" not in reason and "input" in error and not isinstance(error["input"], dict | list):
                reason += f", got {error['input']!r}"
    return f"{where}: {reason}" if where else reason


def describe(exc: ValidationError) -> str:
    """A validation failure as one line: each error's field and reason, in the file's words.

    Parameters
    ----------
    exc : pydantic.ValidationError
        The failure of validating a scenario.
    """
    return "; ".join(_explain(e) for e in exc.errors())


def from_dict(data: dict) -> Scenario:
    """Validate a scenario given as nested dicts; raise :class:`ScenarioError`.

    Parameters
    ----------
    data : dict
        The tables of a scenario file, as ``tomllib`` reads them.
    """
    try:
        return Scenario.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError(describe(exc)) from None
    except RecursionError:
        raise ScenarioError("a value is nested too deeply (lists or tables inside one another)") from None


def read_text(path: Path, what: str, error: type[ValueError]) -> str:
    """The text of the ``what`` file at ``path``; a missing or unreadable file raises ``error`` in one line.

    Only a regular file of at most :data:`MAX_FILE_BYTES` is read: a FIFO, a device such as
    ``/dev/zero`` or a huge file is refused before it is opened, so that reading always ends.

    Parameters
    ----------
    path : Path
        The file.
    what : str
        What the file holds, for the message (``"scenario"``, ``"sweep"``).
    error : type of ValueError
        The exception raised with the one-line message.
    """
    try:
        info = path.stat()
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError
        if not stat.S_ISREG(info.st_mode):
            raise error(f"{path}: is not a regular file (a pipe or a device?), not a {what} file")
        if info.st_size > MAX_FILE_BYTES:
            raise error(f"{path}: is {info.st_size} bytes, more than a {what} file may be ({MAX_FILE_BYTES // 2**20} MiB)")
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(f"{path}: no such file") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not a {what} file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{path}: cannot be read ({exc.__class__.__name__}: {exc})") from None


def load(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file; raise :class:`ScenarioError`.

    Parameters
    ----------
    path : str or Path
        The scenario file.
    """
    path = Path(path)
    return loads(read_text(path, "scenario", ScenarioError), source=str(path), directory=path.parent)


def parse_toml(text: str, source: str, error: type[ValueError]) -> dict:
    """``text`` parsed as TOML; a syntax error, or nesting too deep to parse, raises ``error`` in one line.

    Parameters
    ----------
    text : str
        The TOML text.
    source : str
        Where the text came from, at the start of an error message.
    error : type of ValueError
        The exception raised with the one-line message.
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{source}: TOML syntax error: {exc}") from None
    except RecursionError:
        raise error(f"{source}: TOML nested too deeply (arrays or inline tables inside one another)") from None


def loads(text: str, source: str = "<scenario>", directory: Path | None = None) -> Scenario:
    """Parse and validate scenario TOML text; raise :class:`ScenarioError`.

    Parameters
    ----------
    text : str
        The scenario, in TOML.
    source : str
        Where the text came from, at the start of an error message.
    directory : Path or None
        The directory a path in the text (``agents_from``) is relative to: the scenario file's;
        by default the current directory.

    Text with the keys of a sweep file (:data:`SWEEP_KEYS`) is refused in one line that says so.
    """
    data = parse_toml(text, source, ScenarioError)
    sweep_keys = [key for key in SWEEP_KEYS if key in data]
    if sweep_keys:
        raise ScenarioError(
            f"{source}: is a sweep file (it has {', '.join(sweep_keys)}), not a scenario; run it with tmem sweep"
        )
    try:
        with reading(source):
            return from_dict(crazyflies.expand(data, directory or Path.cwd()))
    except ScenarioError as exc:
        raise ScenarioError(f"{source}: {exc}") from None


def as_scenario(value: Scenario | str | os.PathLike | dict, argument: str = "scenario") -> Scenario:
    """A validated scenario from what a caller passed: a :class:`Scenario`, the path of a scenario
    file (:func:`load`) or a dict of its tables (:func:`from_dict`).

    Parameters
    ----------
    value : Scenario, str, os.PathLike or dict
        The scenario, its file or its tables.
    argument : str
        The caller's name for it, at the start of the message of anything else.

    Raises
    ------
    ScenarioError
        One line: the file's or the tables' first fault, or ``argument`` of another type.
    """
    if isinstance(value, Scenario):
        return value
    if isinstance(value, str | os.PathLike):
        return load(value)
    if isinstance(value, dict):
        return from_dict(value)
    raise ScenarioError(f"{argument}: must be a Scenario, the path of a scenario file or a dict of its tables, "
                        f"got {type(value).__name__}")  # fmt: skip


def _optional_table(table: type[BaseModel] | None, key: str) -> type[BaseModel] | None:
    """The table (a model) that key ``key`` of ``table`` holds, if it is one; ``None`` past a list."""
    field = table.model_fields.get(key) if table is not None and isinstance(key, str) else None
    kinds = typing.get_args(field.annotation) if field is not None else ()
    return next((k for k in kinds if isinstance(k, type) and issubclass(k, BaseModel)), None)


def with_changes(scenario: Scenario, changes: dict[str, Any]) -> Scenario:
    """A copy of ``scenario`` with values replaced by dotted path, validated again.

    Example: ``with_changes(s, {"interaction.function": "repulsion", "agents[1].velocity": 2.0})``.
    A whole list can be replaced too: ``{"agents": [{"position": 0.0}, {"position": 50.0}]}``.
    A key of an optional table the scenario leaves out (``sensing.delay`` without a ``[sensing]``
    table, ``wind.turbulence.severity`` without a ``[wind]`` table) adds the table, and any optional
    table on the path, with their defaults for the keys not given.

    Parameters
    ----------
    scenario : Scenario
        The scenario to copy.
    changes : dict
        New values by dotted path (``"table.key"``, ``"agents[i].key"``).
    """
    data = scenario.model_dump()
    added = set()  # optional tables left out, added here: validation checks their keys
    for path, value in changes.items():
        parts = [int(p) if p.isdigit() else p for p in path.replace("[", ".").replace("]", "").split(".")]
        node = data
        try:
            table: type[BaseModel] | None = Scenario
            for depth, part in enumerate(parts[:-1]):
                table = _optional_table(table, part)
                if isinstance(node, dict) and node.get(part, 0) is None and table is not None:
                    node[part] = table.model_construct().model_dump()  # its defaults
                    added.add(tuple(parts[: depth + 1]))
                node = node[part]
            if isinstance(node, dict) and parts[-1] not in node and tuple(parts[:-1]) not in added:
                raise KeyError(parts[-1])
            node[parts[-1]] = value
        except (KeyError, IndexError, TypeError):
            raise ScenarioError(f"{path}: unknown parameter path") from None
    return from_dict(data)


def preset(name: str) -> Scenario:
    """One of the shipped scenarios: the paper's ``fig5``, ``fig7``, ``fig9`` or ``repulsion``.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS`.
    """
    if name not in PRESETS:
        raise ScenarioError(f"preset: unknown name {name!r}; choose from {', '.join(PRESETS)}")
    text = resources.files("tmem").joinpath("presets", f"{name}.toml").read_text(encoding="utf-8")
    return loads(text, source=f"preset {name}")


def _to_toml(data: dict) -> str:
    lines: list[str] = []
    scalars = {k: v for k, v in data.items() if not isinstance(v, dict | list)}
    lines += [f"{k} = {_toml_value(v)}" for k, v in scalars.items()]
    for key, value in data.items():
        if isinstance(value, dict):
            lines += ["", f"[{key}]"] + [f"{k} = {_toml_value(v)}" for k, v in value.items()]
        elif isinstance(value, list):
            for item in value:
                lines += ["", f"[[{key}]]"]
                lines += [f"{k} = {_toml_value(v)}" for k, v in item.items() if v is not None]
    return "\n".join(lines).lstrip() + "\n"


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        # A JSON string is a TOML basic string, given raw non-ASCII text and an escaped DEL.
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007F")
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else str(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):  # a table inside a table ([wind.turbulence]), written inline
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    return str(v)
