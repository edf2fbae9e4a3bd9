"""The command line, ``tmem``: :mod:`tmem.cli.main` (the commands) and :mod:`tmem.cli.terminal` (progress and messages)."""

from tmem._lazy import submodules

__getattr__ = submodules(__name__)
