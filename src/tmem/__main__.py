"""``python -m tmem``: the same as the ``tmem`` command."""

from tmem.cli.main import main

main()
