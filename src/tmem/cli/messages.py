"""What the ``tmem`` command says when something is wrong: one line, exit status 2.

Every error, whether the command's (a bad scenario, an output that may not be written) or a usage
error (an unknown command, a missing ``--out``, text given for ``--fps``), is one line on standard
error starting ``error:``, with every control character escaped as Python writes it in a string
(``\\n``, ``\\x1b``, :func:`tmem.files.outputs.one_line`): a newline in a path, an agent's or a
robot's name cannot split the line or forge another, and no escape sequence reaches the terminal.
A usage error ends with where to read more: ``see tmem run --help``.
"""

from __future__ import annotations

import re
import sys

import typer
from rich.console import Console
from rich.markup import escape
from typer.core import TyperGroup

from tmem.files.outputs.names import one_line

try:  # Typer bundles its own click since 0.2x; earlier, it used click's
    from typer._click import exceptions as _errors
except ImportError:  # pragma: no cover - an earlier Typer
    from click import exceptions as _errors

#: ``tmem`` alone shows its help: click says so by this error (click 8.2 and later).
_NO_ARGS = getattr(_errors, "NoArgsIsHelpError", ())

__all__ = ["Commands", "error_line", "show_warning", "usage_line"]


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Print a warning as the one line ``warning: ...`` on standard error (a doubtful value's, say,
    :class:`tmem.scenario.ScenarioWarning`), escaped as an error is; :func:`warnings.showwarning`'s
    signature, so that the ``tmem`` command installs it in its place.

    Parameters
    ----------
    message : Warning or str
        The warning.
    category, filename, lineno, file, line
        As :func:`warnings.showwarning` takes them; only ``message`` is shown.
    """
    print(f"warning: {one_line(str(message))}", file=sys.stderr)


def error_line(message: str) -> str:
    """``message`` as the one line ``tmem`` prints for an error (without ``error:``).

    Parameters
    ----------
    message : str
        The error's text; line breaks and other control characters are escaped.
    """
    return one_line(str(message))


def usage_line(exc: Exception) -> str:
    """A usage error (click's) as one line: what is wrong, and which ``--help`` to read.

    Parameters
    ----------
    exc : click.ClickException
        The error click (or Typer's own click) raised while reading the command line.
    """
    param = getattr(exc, "param", None)
    if isinstance(exc, _errors.MissingParameter) and param is not None:
        kind = "option" if getattr(param, "param_type_name", "") == "option" else "argument"
        name = param.opts[0] if kind == "option" else (param.metavar or param.name or "").upper().strip("{}[]")
        text = f"missing {kind} {name}"
    else:
        text = " ".join(exc.format_message().split())
        text = re.sub(r"'(-[^' ]*)'", r"\1", text)  # '--fps' -> --fps
        text = text[:1].lower() + text[1:]
    ctx = getattr(exc, "ctx", None)
    where = ctx.command_path if ctx is not None else "tmem"
    return error_line(f"{text.rstrip('.')}; see {where} --help")


def _print_error(line: str) -> None:
    Console(stderr=True).print(f"[bold red]error:[/] {escape(line)}", highlight=False, soft_wrap=True)


class Commands(TyperGroup):
    """Typer's group of commands, each one's flags shown without a type in its help, and every usage
    error or file system error said in one line (:func:`usage_line`) with exit status 2."""

    def get_command(self, ctx, cmd_name):
        """The command ``cmd_name``, its flags shown without a type.

        Parameters
        ----------
        ctx : click.Context
            The context of the group.
        cmd_name : str
            The command's name.
        """
        command = super().get_command(ctx, cmd_name)
        if command is not None:
            _untyped_flags(command, ctx)
        return command

    def format_help(self, ctx, formatter):
        """Write the group's help, its flags shown without a type.

        Parameters
        ----------
        ctx : click.Context
            The context of the group.
        formatter : click.HelpFormatter
            Where the help is written.
        """
        _untyped_flags(self, ctx)
        super().format_help(ctx, formatter)

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        """Run the command line as click does, saying a usage error or a file system error in one line.

        Parameters
        ----------
        args, prog_name, complete_var, standalone_mode, **extra
            As :meth:`click.Command.main` takes them.
        """
        try:
            code = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except _NO_ARGS as exc:  # `tmem` alone: its help, as click shows it
            if not standalone_mode:
                raise
            Console(stderr=True).print(exc.ctx.get_help(), markup=False, highlight=False, soft_wrap=True)
            code = exc.exit_code
        except _errors.ClickException as exc:
            if not standalone_mode:
                raise
            _print_error(usage_line(exc))
            code = 2
        except typer.Abort:
            if not standalone_mode:
                raise
            _print_error("aborted")
            code = 1
        except OSError as exc:  # a file system error no command foresaw: one line, not a traceback
            if not standalone_mode:
                raise
            _print_error(error_line(f"{exc.filename}: {exc.strerror}" if exc.filename and exc.strerror else str(exc)))
            code = 2
        if not standalone_mode:
            return code
        sys.exit(code if isinstance(code, int) else 0)


def _untyped_flags(command, ctx) -> None:
    """Show flags (``--help``, ``--version``) in help without a type: Typer would write ``--help <bool>``."""
    for param in command.get_params(ctx):
        if getattr(param, "is_flag", False):
            param.metavar = ""
