"""``python -m frictionlab`` and the ``frictionlab`` command."""

import signal
import sys


class _TerminatedWhileLoading(KeyboardInterrupt):
    """SIGTERM before the command's own handling (``signals.RaiseOnSignals``) is in place."""


def _terminated(signum, frame):
    raise _TerminatedWhileLoading()


def program() -> None:
    """The ``frictionlab`` command (``cli.program``). A Ctrl-C while it loads, before a
    command's own handling, ends as one at any other time does: a line and exit code 130
    (SIGTERM: 143)."""
    held = None
    try:
        if sys.argv[1:2] == ["tui"]:  # first thing: keys typed while it loads wait for the app as typed
            from .tui.terminal import hold_keys

            # before the terminal is held: a SIGTERM while it loads (its default ends the process
            # at once) raises here, so the finally below gives the terminal back its echo and line mode;
            # inside the try: a background job (`timeout 5 frictionlab tui`) stops at the hold until signalled
            signal.signal(signal.SIGTERM, _terminated)
            held = hold_keys()
        from .cli import program as run_program

        run_program()
    except _TerminatedWhileLoading:
        print("terminated", file=sys.stderr)
        raise SystemExit(143) from None
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        raise SystemExit(130) from None
    finally:
        if held is not None:  # the keys the app never read do not reach the shell
            from .tui.terminal import release_keys

            release_keys(held)


if __name__ == "__main__":
    program()
