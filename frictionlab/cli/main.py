"""The parser and the dispatch of ``frictionlab COMMAND``.

Conventions every command keeps (tested in tests/cli/test_conventions.py):

* results go to stdout, progress and errors to stderr; ``--json`` puts the results as
  one JSON object on stdout (run, validate, plugins, presets, study, report, predict),
  an error too, each of a shape named in ``jsonout``;
* a bare ``frictionlab`` prints a short help with examples; ``-V``/``--version`` the
  version; every ``COMMAND --help`` a description and examples;
* a mistyped command, option, plugin, preset name or preset field is answered with the
  closest names; an unknown option with its own command's usage;
* tables fit the terminal (rich) and are plain aligned columns in a pipe; colour only
  on a terminal, never with ``NO_COLOR`` set; progress is a bar on a terminal and a
  line per tenth in a log, shown once a run passes 2 s, none with ``--quiet``;
* ``frictionlab completion bash|zsh|fish`` prints a completion script made from the parser;
* a missing optional package is said with the pip command that installs it;
* exit codes are ``ExitCode``; a user error never prints a traceback (set
  ``FRICTIONLAB_DEBUG=1`` to see one for an internal error); SIGTERM ends a run as
  Ctrl-C does; a closed stdout ends the command quietly (141).
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import gc
import os
import re
import sys
import warnings

from .. import __version__
from ..errors import (ExitCode, FrictionlabError, FrontEnd, advising, escape_unencodable_output, limit_advice,
                      out_of_memory_loading, output_failed, shell_word, short_repr, shown, shown_name, too_long_path)  # fmt: skip
from ..compute.heap import (keep_freed_memory, one_blas_thread_unless_chosen, refuse_blas_without_room,
                            spare_address_space_under_a_limit)  # fmt: skip
from ..compute.signals import RaiseOnSignals, interrupted_exit_code, interrupted_word, received
from . import (completion, exact3d, follow, plot, plugins, predict, presets, report, resume, run, runs, schema, study, tui,
               validate)  # fmt: skip
from .console import error_label

COMMANDS = (run, resume, runs, follow, plot, validate, schema, plugins, presets, report, predict, tui, study, exact3d, completion)
"""Each a module with ``add_parser(subparsers)`` and a handler ``run(args) -> ExitCode``."""


DESCRIPTION = "rms slope in contact against normal force, over ensembles of random rough lines and surfaces."
EXAMPLES = """examples:
  frictionlab run quickstart                  a first run: the fit, the table, plot.png
  frictionlab presets                         the built-in presets
  frictionlab run my.yaml --set seed=3        a preset of your own, one value changed
  frictionlab tui                             edit, run and compare in the terminal
  frictionlab COMMAND --help                  what a command does, with examples
"""
EXIT_CODES = {  # each of ExitCode, for a script to tell the endings apart (the full table: docs/data-safety.md)
    ExitCode.OK: "done", ExitCode.RUNTIME_FAILURE: "a run failed or would not fit in memory (what finished is kept)",
    ExitCode.USAGE: "bad command line or preset value", ExitCode.INPUT_FILE: "the preset file cannot be used",
    ExitCode.OUTPUT_REFUSED: "output refused (see --force)", ExitCode.RUN_FOLDER: "run folder cannot be resumed or is in use",
    ExitCode.INTERNAL: "internal error (a bug)", ExitCode.HUNG_UP: "hung up (SIGHUP), resumable",
    ExitCode.INTERRUPTED: "Ctrl-C, resumable", ExitCode.BROKEN_PIPE: "stdout closed by its reader",
    ExitCode.TERMINATED: "SIGTERM, resumable",
}  # fmt: skip
EPILOG = EXAMPLES + "\nexit codes:\n" + "".join(f"  {int(code):<4}{meaning}\n" for code, meaning in EXIT_CODES.items())


# \d+(?:\.\d*)? and not \d+\.?\d*: a run of digits splits one way only, so a word of 20,000 digits
# that is no number is refused at once (it took a minute: each split was tried)
_NUMBER = r"(?:(?:\d+(?:\.\d*)?|\.\d+)(?:e[+-]?\d+)?|inf|infinity|nan)"
NEGATIVE_NUMBER = re.compile(rf"^-{_NUMBER}(?:,[+-]?{_NUMBER})*$", re.IGNORECASE)  # or a list of numbers, the first < 0


class _Parser(argparse.ArgumentParser):
    """Every parser keeps the line breaks of its description and examples, and lets a
    failed write of its help through (argparse drops it), so that ``--help`` into a
    closed pipe ends as any other output does."""

    refusal: tuple[str, str] | None = None  # (prog, message) of the last usage error
    words: list[str] = []  # what this parser was last given to parse

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", argparse.RawDescriptionHelpFormatter)
        super().__init__(*args, **kwargs)
        # A word that is a negative number (or a list of numbers starting with one) is an option's
        # value in any notation float() reads: argparse takes only -1 and -0.5, and said
        # "expected one argument" to `--b -1e-3`.
        self._negative_number_matcher = NEGATIVE_NUMBER

    def _print_message(self, message, file=None):
        if message:
            (file or sys.stderr).write(message)

    def error(self, message):
        choice = re.search(r"invalid choice: '(.*)' \(choose from (.*)\)$", message)
        if choice:  # argparse lists the choices; the closest goes first
            from ..errors import did_you_mean

            choices = [c.strip("'") for c in choice.group(2).split(", ")]  # quoted before Python 3.12.8, bare after
            close = did_you_mean(choice.group(1), choices, 0.7)
            if not close and choices == ["copy"] and self.prog.endswith(" presets"):  # `presets quickstart f.yaml`
                close = f"; to copy a preset out: {self.prog} copy {shell_word(choice.group(1))} [DEST]"
            message += close
        if message.startswith("the following arguments are required"):
            # argparse says so before it looks at words it does not know: `run --hlep` is a
            # misspelt option more often than a forgotten preset
            options = self.option_names()
            strays = [w for w in self.words if _stray_option(w, options)]
            if strays:
                message = f"{unrecognized(strays, options)} ({message})"
        message += _dash_value_hint(message, self.words)
        message = re.sub(r"invalid (int|float) value: '(.*)'$", _invalid_value, message)
        message = shown(message)  # the words it quotes as typed: an escape sequence must not drive the terminal
        _Parser.refusal = (self.prog, message)  # for the JSON error object of a usage error under --json
        super().error(message)

    def option_names(self) -> list[str]:
        return [name for action in self._actions for name in action.option_strings]

    def parse_known_args(self, args=None, namespace=None):
        """Words no option takes are refused by the parser that met them, with its own
        usage (``usage: frictionlab run ...``, not the top level's) and the closest options."""
        self.words = list(sys.argv[1:] if args is None else args)
        namespace, extras = super().parse_known_args(args, namespace)
        if extras:
            self.error(unrecognized(extras, self.option_names()))
        return namespace, extras


def _dash_value_hint(message: str, words: list[str]) -> str:
    """How to give an option a value that starts with '-' (`--out -r2`: argparse takes -r2
    for an option and says only 'expected one argument')."""
    option = re.match(r"argument (?:\S+/)?(--\S+): expected one argument$", message)
    if option is None or option.group(1) not in words[:-1]:
        return ""
    value = words[words.index(option.group(1)) + 1]
    if not value.startswith("-") or value == "--":
        return ""
    return f"; a value that starts with '-' is given as {option.group(1)}={value}"


def _invalid_value(match: re.Match) -> str:
    """argparse's 'invalid int value' with the value cut short (a 5000-digit --seed was said in
    full, and, past the 4300 digits Python reads as a number, as if it were not a whole number)."""
    kind, value = match.groups()  # the value as argparse quotes it (its repr, escapes and all)
    digits = len(value.strip().lstrip("+-"))
    cut = value if len(value) <= 120 else f"{value[:57]}...{value[-57:]}"
    if kind == "int" and value.strip().lstrip("+-").isdigit() and digits > sys.get_int_max_str_digits():
        return f"invalid int value: '{cut}', a whole number of {digits} digits, too long to be one here"
    return f"invalid {kind} value: '{cut}'"


def unrecognized(words: list[str], options: list[str]) -> str:
    """argparse's message for words it did not take, with the options closest to each."""
    from ..errors import close_names

    named = [word for word in words if word.startswith("-") and os.path.lexists(word)]
    if named:  # a file or folder whose name starts with '-' (`run -x.yaml`) is not an option
        return (f"unrecognized arguments: {' '.join(words)}; {named[0]} is a file here: a name that starts with "
                f"'-' is given as ./{named[0]}")  # fmt: skip
    if any(word.partition("=")[0] in options for word in words):  # `run -- -x.yaml --out DIR`: --out is a name
        return (f"unrecognized arguments: {' '.join(words)}; every word after -- is a name, never an option: "
                "give the options before --")  # fmt: skip
    close = [name for word in words if word.startswith("-") for name in close_names(word.partition("=")[0], options, 0.7)]
    hint = f"; did you mean {' or '.join(repr(name) for name in dict.fromkeys(close))}?" if close else ""
    return f"unrecognized arguments: {' '.join(words)}{hint}"


def _stray_option(word: str, options: list[str]) -> bool:
    """Whether ``word`` looks like an option that none of ``options`` (nor a prefix of one) is."""
    name = word.partition("=")[0]
    return name.startswith("-") and name != "-" and name != "--" and not NEGATIVE_NUMBER.match(word) and not any(
        option.startswith(name) for option in options
    )


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser of every command, or with ``only`` of that one command (what parsing its
    own words needs: its help, usage and errors are the same; building all of them,
    fourteen then, was a tenth of a short run's start)."""
    parser = _Parser(prog="frictionlab", description=DESCRIPTION, epilog=EPILOG)
    parser.add_argument(
        "-V", "--version", action="version", version=f"frictionlab {__version__}", help="print the version and exit"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for command in COMMANDS:
        if only is None or _name(command) == only:
            command.add_parser(sub)
    return parser


def _name(command) -> str:
    return command.__name__.rsplit(".", 1)[-1]


def _sole_command(argv: list[str]) -> str | None:
    """The command ``argv`` starts with, when parsing needs no other's parser: not
    ``completion``, which describes them all."""
    first = argv[0] if argv else None
    return first if first in command_names() and first != "completion" else None


def command_names() -> list[str]:
    return [_name(command) for command in COMMANDS]


def short_help() -> str:
    """What a bare ``frictionlab`` prints: what it is, its commands, examples."""
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    width = max(len(c.dest) for c in sub._choices_actions)
    lines = [f"frictionlab: {DESCRIPTION}", "", "usage: frictionlab COMMAND [options]", "", "commands:"]
    lines += [f"  {c.dest.ljust(width)}  {c.help}" for c in sub._choices_actions]
    return "\n".join([*lines, "", EXAMPLES.rstrip()])


def _unknown_command(argv: list[str]) -> str | None:
    """The error for a first word that is no command (argparse's own names no close one)."""
    from ..errors import did_you_mean

    first = next((word for word in argv if not word.startswith("-")), None)
    names = command_names()
    if first is None or first in names or any(word in ("-h", "--help", "-V", "--version") for word in argv[: argv.index(first)]):
        return None
    hint = did_you_mean(first, names)
    return f"frictionlab: no command {first!r}{hint or '.'} Commands: {', '.join(names)} (frictionlab --help)"


def _missing_package(exc: Exception, purpose: str):
    """A package that is not installed (an optional one reached without ``errors.require``,
    or a dependency of a broken install) as the message with its pip command; None for
    anything else, a module of frictionlab itself included (that is a bug)."""
    from ..errors import MissingDependency

    name = exc.name if isinstance(exc, ModuleNotFoundError) else None
    if not name or name.partition(".")[0].startswith("frictionlab"):
        return None
    return MissingDependency(name, purpose)


def _plugin_at_fault(exc: BaseException):
    """The PluginError that names the installed plugin whose code raised ``exc``, or None; a
    ``SolveFailed`` (a failure the plugin explains) as its message, naming it without blame."""
    if "frictionlab.plugin.registry" not in sys.modules:  # no plugin was loaded: none is at fault
        return None
    from ..plugin.registry import installed_plugin_fault, solve_failed

    return solve_failed(exc) or installed_plugin_fault(exc)


def _plugin_place(exc: BaseException) -> tuple[str, str] | None:
    """The installed plugin whose code raised ``exc``, and where (``fault_place``), or None."""
    if "frictionlab.plugin.registry" not in sys.modules:  # no plugin was loaded: none raised it
        return None
    from ..plugin.registry import installed_plugin_place

    return installed_plugin_place(exc)


def _plain_warning(message, category, filename, lineno, file=None, line=None):
    return f"warning: {shown(str(message))}\n"  # a resume's warning names a folder


def program() -> None:
    """The ``frictionlab`` command (and ``python -m frictionlab``): ``main``, then exit."""
    # Start-up makes some 10^5 objects that live as long as the process (modules, classes,
    # validators), and the cycle collector would walk them about a hundred times for nothing
    # (15 ms of a short run); collect every 10^5 new objects instead of every 700. The
    # numbers live in numpy arrays, which the collector does not walk. The TUI keeps
    # Python's defaults: it lives long, and wants many short pauses rather than a few long.
    if sys.argv[1:2] != ["tui"]:
        gc.set_threshold(100_000, 20, 20)
    one_blas_thread_unless_chosen()  # before numpy is imported
    spare_address_space_under_a_limit()
    refuse_blas_without_room()  # before numpy is imported
    for name in ("stdout", "stderr"):  # started with it closed (`>&-`): it writes nowhere, as to /dev/null
        if getattr(sys, name) is None:
            setattr(sys, name, open(os.devnull, "w", encoding="utf-8"))
    code = main()
    gc.freeze()  # the interpreter's exit then skips a last collection of everything imported (40 ms)
    _leave_an_abandoned_solve(code)
    if sys.argv[1:2] != ["tui"]:
        _end_now(code)
    sys.exit(code)


def _end_now(code: int) -> None:
    """End the process without the interpreter's teardown of the ~500 modules a run
    imports (25 ms of CPU on the loaded 2-core machine, a tenth of numpy's import): the
    atexit functions run (logging's flush, multiprocessing's, weakref finalizers), the
    output streams are flushed, then os._exit. Not while a thread that is no daemon
    runs: the interpreter's exit waits for it, and so does this one."""
    import atexit

    threading = sys.modules.get("threading")  # never imported: no thread was started (--help)
    if threading is not None and any(
        t.is_alive() and not t.daemon for t in threading.enumerate() if t is not threading.main_thread()
    ):
        return
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe: what the interpreter's exit would have met
            return
    os._exit(code)


def _leave_an_abandoned_solve(code: int) -> None:
    """End the process now if a cancelled run left its solve inside a step (SIGTERM or
    Ctrl-C mid-solve): the interpreter's exit would wait for that step's FFT to end (the
    FFT library joins its threads as the process ends, and one running on several threads
    aborted the process instead). The run has written what it keeps by now; the output
    streams and the log files are flushed first."""
    realization = sys.modules.get("frictionlab.compute.realization")  # not imported: no run, nothing left
    if realization is None or not realization.solve_abandoned():
        return
    import logging

    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe, a closed stream: nothing more to say
            pass
    os._exit(code)


def main(argv: list[str] | None = None) -> int:
    warnings.formatwarning = _plain_warning
    escape_unencodable_output()  # a path that is not UTF-8 is printed escaped, never exit 70 after the work
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv:
        return _print(short_help())
    problem = _unknown_command(argv)
    if problem:
        print(problem, file=sys.stderr)
        if "--json" in argv:
            from .jsonout import emit_error

            emit_error(None, problem.removeprefix("frictionlab: "), ExitCode.USAGE)
        return int(ExitCode.USAGE)
    parser = build_parser(_sole_command(argv))
    _Parser.refusal = None
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version or a usage error: argparse has printed it
        if exc.code not in (0, None):
            refusal = _Parser.refusal
            if "--json" in argv and refusal is not None:  # a script reading stdout gets the error as JSON too
                from .jsonout import emit_error

                emit_error(refusal[0].removeprefix("frictionlab").strip() or None, refusal[1], exc.code)
            raise
        return _print(None)  # a closed pipe under --help shows in this flush, as under any command
    except OSError as exc:  # the help could not be written: `| head -1` (a closed pipe), `> /dev/full`
        return output_failed(exc)
    args.parser = parser  # a command that describes the CLI itself (completion) reads it
    if args.command is None:  # only options, none of which exits (there are none today)
        return _print(short_help())
    with RaiseOnSignals():
        return _run_command(args)


def _print(text: str | None) -> int:
    """Print ``text`` (None: only flush what is already written) and say how it went."""
    try:
        if text is not None:
            print(text)
        sys.stdout.flush()
    except OSError as exc:
        return output_failed(exc)
    return int(ExitCode.OK)


def _run_command(args) -> int:
    keep_freed_memory()  # this process's realizations reuse freed pages, not fault in fresh ones
    try:
        from .options import command_options, refuse_empty_paths

        refuse_empty_paths(args.parser, args)
        from .jsonout import json_only

        stdout = json_only() if getattr(args, "json", False) else contextlib.nullcontext()
        with advising(FrontEnd(options=command_options(args.parser, args))), stdout:  # a refusal advises this command's options
            code = int(args.handler(args))
        sys.stdout.flush()  # a closed pipe or a full disk shows here, not at exit
        return code
    except BrokenPipeError as exc:  # `frictionlab plugins --json | head -c 10`: the reader has enough
        return output_failed(exc)
    except FrictionlabError as exc:
        return _refused(args, shown(str(exc)), exc.exit_code, f"{error_label()}: ", exc.problems)
    except OSError as exc:  # the machine said no (disk full, permission denied): not a bug
        if not exc.filename:  # stdout itself (`> /dev/full`)
            return output_failed(exc)
        if exc.errno == errno.ENAMETOOLONG:  # a path argument no file can have: the command line is wrong
            return _refused(args, too_long_path(exc.filename, known=True), ExitCode.USAGE)
        return _refused(args, f"{exc.strerror or exc}: {shown_name(exc.filename)}", ExitCode.RUNTIME_FAILURE)
    except MemoryError as exc:  # numpy could not allocate: the machine's limit, not a bug
        library = out_of_memory_loading(exc)
        if library is not None:  # the program itself does not fit: fewer points would not help
            return _out_of_memory_loading(args, library)
        detail = f": {exc}" if str(exc) else ""
        if (place := _plugin_place(exc)) is not None:  # met in a plugin's own code: which, and where
            detail += f" (in {place[0]}, {place[1]})"
        message = f"out of memory{detail}; ask for fewer points, realizations or workers{limit_advice()}"
        folder = getattr(args, "out_dir", None)  # a run's folder, once made: what it holds is not lost
        if folder is not None:
            from .run import resumable

            message += f"; {resumable(folder)}"
        return _refused(args, message, ExitCode.RUNTIME_FAILURE)
    except (SystemExit, KeyboardInterrupt) as exc:  # a plugin's sys.exit() or raise outside a realization (validate)
        fault = None if received else _plugin_at_fault(exc)  # after a signal: Ctrl-C's, wherever it landed
        if fault is not None:
            return _refused(args, str(fault), fault.exit_code, f"{error_label()}: ")
        if isinstance(exc, SystemExit):
            raise
        # Ctrl-C, SIGTERM or SIGHUP (signals.Terminated), or a command of several runs
        code = interrupted_exit_code()  # stopped after one (signals.WorkInterrupted: it says what is kept)
        said = f": {shown(str(exc))}" if str(exc) else ""
        return _refused(args, f"{interrupted_word()}{said}", code, "")
    except Exception as exc:  # an internal error (a bug): say so plainly, traceback on request
        if os.environ.get("FRICTIONLAB_DEBUG"):
            raise
        library = out_of_memory_loading(exc)
        if library is not None:  # a process limit too small to load numpy or scipy: not a bug either
            return _out_of_memory_loading(args, library)
        missing = _missing_package(exc, f"frictionlab {args.command}") or _plugin_at_fault(exc)
        if missing is not None:
            return _refused(args, str(missing), missing.exit_code, f"{error_label()}: ")
        message = f"{type(exc).__name__}: {short_repr(str(exc), 300)[1:-1]}"
        return _refused(args, message, ExitCode.INTERNAL, "internal error: ",
                        suffix="\n(this is a bug; set FRICTIONLAB_DEBUG=1 for the traceback)")  # fmt: skip


def _out_of_memory_loading(args, library: str) -> int:
    return _refused(args, f"out of memory loading {library}{limit_advice().replace(', or raise', '; raise')}",
                    ExitCode.RUNTIME_FAILURE)  # fmt: skip


def _refused(args, message: str, code: int, label: str = "error: ", problems=None, suffix: str = "") -> int:
    """Say why the command stopped on stderr and, under ``--json``, as the error object
    on stdout (``jsonout``); return the exit code."""
    print(f"{label}{message}{suffix}", file=sys.stderr)
    if getattr(args, "json", False):  # a Namespace holds the flags of its own command only
        from . import jsonout

        try:
            jsonout.emit_error(_command_path(args), message, int(code), problems)
            sys.stdout.flush()
        except OSError as exc:
            output_failed(exc)
    return int(code)


def _command_path(args) -> str:
    return " ".join(filter(None, [args.command, getattr(args, "action", None)]))
