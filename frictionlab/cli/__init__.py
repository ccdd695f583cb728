"""The headless front end, ``frictionlab COMMAND``: one module per command, each
with ``add_parser(subparsers)`` and ``run(args) -> ExitCode``; ``main`` builds
the parser and runs the command, ``program`` is the ``frictionlab`` command itself.
Importing it is cheap: a command imports what it needs when it runs, and only
``tui`` ever imports Textual."""

from .main import build_parser, main, program

__all__ = ["build_parser", "main", "program"]
