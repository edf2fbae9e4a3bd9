"""``python -m tmem``: the same as the ``tmem`` command."""

from .cli import main

main()
