"""``python -m frictionlab`` and the ``frictionlab`` command."""

import sys


def program() -> None:
    """The ``frictionlab`` command (``cli.program``). A Ctrl-C while it loads, before a
    command's own handling, ends as one at any other time does: a line and exit code 130."""
    held = None
    if sys.argv[1:2] == ["tui"]:  # first thing: keys typed while it loads wait for the app as typed
        from .tui.terminal import hold_keys

        held = hold_keys()
    try:
        from .cli import program as run_program

        run_program()
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        raise SystemExit(130) from None
    finally:
        if held is not None:  # the keys the app never read do not reach the shell
            from .tui.terminal import release_keys

            release_keys(held)


if __name__ == "__main__":
    program()
