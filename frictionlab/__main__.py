"""``python -m frictionlab`` and the ``frictionlab`` command."""

import sys


def program() -> None:
    """The ``frictionlab`` command (``cli.program``). A Ctrl-C while it loads, before a
    command's own handling, ends as one at any other time does: a line and exit code 130."""
    try:
        from .cli import program as run_program

        run_program()
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        raise SystemExit(130) from None


if __name__ == "__main__":
    program()
