"""The command line, ``tmem``: :mod:`tmem.cli.main` (the commands) and :mod:`tmem.cli.terminal` (progress and messages)."""
