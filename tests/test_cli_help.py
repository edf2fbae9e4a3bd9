"""The command line looks finished: ``tmem --version``, and every command's help free of raw markup,
of ``--help <bool>``, with each numeric option's unit and default shown; docs/cli.md names every
command, argument and option, and none that does not exist."""

import re
import tomllib
import typing
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app

PYPROJECT = Path(__file__).parent.parent / "pyproject.toml"
#: Words that name what an option's number counts or measures.
UNITS = re.compile(r"\b(s|m|rad|m/s|frames|frames per second|processes|per core|agents)\b")


def commands() -> dict:
    """Every command of the app (``""`` for the app itself), as click sees them."""
    group = typer.main.get_command(app)
    return {"": group, **group.commands}


def help_of(name: str) -> str:
    result = CliRunner().invoke(app, [*([name] if name else []), "--help"], env={"COLUMNS": "250"})
    assert result.exit_code == 0, result.output
    return result.stdout


def test_version_is_the_packages():
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0, result.output
    version = tomllib.loads(PYPROJECT.read_text())["project"]["version"]
    assert result.stdout == f"tmem {version}\n" and version == tmem.__version__


def test_every_command_is_walked():
    assert {"run", "paper", "animate", "plot", "sweep"} <= set(commands())


@pytest.mark.parametrize("name", list(commands()), ids=lambda n: n or "tmem")
def test_help_has_no_raw_markup_and_no_typed_flags(name):
    text = help_of(name)
    assert "``" not in text and ":func:" not in text and ":mod:" not in text
    assert not re.search(r"--help\s+<bool>", text) and "<bool>" not in text
    help_line = next(line for line in text.splitlines() if "--help" in line)
    assert "Show this message and exit." in help_line


@pytest.mark.parametrize("name", [n for n in commands() if n], ids=str)
def test_numeric_options_show_their_unit_and_default(name):
    text = help_of(name)
    command = commands()[name]
    hints = typing.get_type_hints(command.callback)
    numeric = [p for p in command.params if p.param_type_name == "option" and (hints[p.name] in (int, float) or p.metavar == "N")]
    for param in numeric:
        line = next(line for line in text.splitlines() if param.opts[-1] in line)
        assert "[default:" in line, line
        assert UNITS.search(line.lower()), line
    for line in text.splitlines():  # any option line with a number in it says what the number is
        if line.lstrip("│ ").startswith("-") and re.search(r"\d", line.split(">", 1)[-1]):
            assert "[default:" in line or UNITS.search(line.lower()), line


def reference_sections() -> dict[str, str]:
    """docs/cli.md's section of each command, by name (from its heading ``## `tmem NAME` ``)."""
    text = (Path(__file__).parent.parent / "docs" / "cli.md").read_text()
    parts = re.split(r"^## `tmem (\w+)`\n", text, flags=re.M)
    return {name: re.split(r"^## ", body, flags=re.M)[0] for name, body in zip(parts[1::2], parts[2::2])}


def test_the_reference_has_a_section_for_every_command():
    assert set(reference_sections()) == {n for n in commands() if n}
    assert "`tmem --version`" in (Path(__file__).parent.parent / "docs" / "cli.md").read_text()


@pytest.mark.parametrize("name", [n for n in commands() if n], ids=str)
def test_the_reference_names_every_argument_and_option_of_a_command_and_no_other(name):
    """docs/cli.md, in the command's section: each argument and each option's flags; an option it names
    that the command does not have fails."""
    text = reference_sections()[name]
    params = [p for p in commands()[name].params if p.name != "help"]
    for param in params:
        if param.param_type_name == "argument":
            assert f"`{param.name.upper()}`" in text, param.name
        else:
            for flag in param.opts:
                assert re.search(rf"`{re.escape(flag)}\b", text), flag
    flags = {flag for p in params for flag in p.opts} | {"--help"}
    named = set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", text))
    assert named <= flags, named - flags
