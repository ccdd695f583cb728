"""The parser and the dispatch of ``frictionlab COMMAND``.

Results go to stdout, progress and errors to stderr. Exit codes are
``ExitCode``. A user error never prints a traceback (set ``FRICTIONLAB_DEBUG=1``
to see one for an internal error). SIGTERM ends a run as Ctrl-C does; a closed
stdout ends the command quietly.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

from .. import __version__
from ..errors import ExitCode, FrictionlabError, short_repr
from ..signals import RaiseOnSigterm, interrupted_exit_code
from . import exact3d, plugins, predict, report, resume, run, schema, study, tui, validate

COMMANDS = (run, resume, validate, schema, plugins, report, predict, tui, study, exact3d)
"""Each a module with ``add_parser(subparsers)`` and a handler ``run(args) -> ExitCode``."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="frictionlab",
        description="rms slope in contact against normal force, over ensembles of random rough lines.",
    )
    parser.add_argument("--version", action="version", version=f"frictionlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def _plain_warning(message, category, filename, lineno, file=None, line=None):
    return f"warning: {message}\n"


def _quiet_stdout() -> None:
    """After a BrokenPipeError: point stdout at /dev/null so the interpreter's
    final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout without a descriptor (a test's capture)
        pass


def main(argv: list[str] | None = None) -> int:
    warnings.formatwarning = _plain_warning
    args = build_parser().parse_args(argv)
    with RaiseOnSigterm():
        return _run_command(args)


def _run_command(args) -> int:
    try:
        code = int(args.handler(args))
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return code
    except BrokenPipeError:  # `frictionlab plugins --json | head -c 10`: the reader has enough
        _quiet_stdout()
        return int(ExitCode.BROKEN_PIPE)
    except FrictionlabError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return int(exc.exit_code)
    except OSError as exc:  # the machine said no (disk full, permission denied): not a bug
        where = f": {exc.filename}" if exc.filename else ""
        print(f"error: {exc.strerror or exc}{where}", file=sys.stderr)
        return int(ExitCode.RUNTIME_FAILURE)
    except KeyboardInterrupt:  # Ctrl-C, or SIGTERM (signals.Terminated), outside a run's own handling
        code = interrupted_exit_code()
        print("terminated" if code == ExitCode.TERMINATED else "interrupted", file=sys.stderr)
        return int(code)
    except Exception as exc:  # an internal error (a bug): say so plainly, traceback on request
        if os.environ.get("FRICTIONLAB_DEBUG"):
            raise
        print(
            f"internal error: {type(exc).__name__}: {short_repr(str(exc), 300)[1:-1]}\n"
            "(this is a bug; set FRICTIONLAB_DEBUG=1 for the traceback)",
            file=sys.stderr,
        )
        return int(ExitCode.INTERNAL)
