"""Error types and exit codes shared by every front end (``interrupts``: a signal's Ctrl-C told apart)."""

from __future__ import annotations

import codecs
import enum
import os
import re
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass


class ExitCode(enum.IntEnum):
    """What ``frictionlab`` returns to the shell (the table is in docs/data-safety.md)."""

    OK = 0
    RUNTIME_FAILURE = 1  # a realization, the executor or a write failed; what finished is kept
    USAGE = 2  # bad command line, invalid preset (a field's value), unknown or broken plugin
    INPUT_FILE = 3  # a preset file that cannot be used as one: missing, not a regular file, too large, not UTF-8
    OUTPUT_REFUSED = 4  # the output would replace or delete what frictionlab did not write (see --force)
    RUN_FOLDER = 5  # a run folder that cannot be resumed: damaged, in use, another preset, a changed input file, a fit failed with all done
    INTERNAL = 70  # a bug in frictionlab or a plugin (sysexits' EX_SOFTWARE)
    HUNG_UP = 129  # SIGHUP, the terminal closed (an SSH session that dropped): as Ctrl-C
    INTERRUPTED = 130  # Ctrl-C (SIGINT): finished work was kept, the run folder is resumable
    BROKEN_PIPE = 141  # stdout was closed by the reader (as a process killed by SIGPIPE)
    TERMINATED = 143  # SIGTERM: as Ctrl-C


class FrictionlabError(Exception):
    """Base of the errors a user can cause and fix; shown without a traceback."""

    exit_code = ExitCode.USAGE
    problems: list[str] | None = None  # one line per problem, where an error lists several (PresetError)


EXTRAS = {"dask": "dask", "distributed": "dask", "bokeh": "dask", "pandas": "pandas", "ipywidgets": "notebook",
          "tamaas": "bench"}
"""The optional packages by top-level module, and the extra of pyproject.toml that brings each."""


DISTRIBUTIONS = {"yaml": "pyyaml", "ruamel": "ruamel-yaml"}
"""The dependencies whose distribution is not named as their top-level module."""


def _normalized(name: str) -> str:
    import re

    return re.sub(r"[-_.]+", "-", name).lower()  # as pip compares distribution names


def dependency_command(module: str) -> str:
    """The pip command that brings back ``module``, a dependency of frictionlab's own: its
    requirement as frictionlab declares it. frictionlab is installed from a clone, not an
    index, so "reinstall frictionlab" would find nothing to install: for a module it does
    not declare, the clone's ``pip install .`` reinstalls it with every dependency."""
    import re
    from importlib.metadata import PackageNotFoundError, requires

    try:
        declared = [req for req in requires("frictionlab") or [] if "extra ==" not in req]
    except PackageNotFoundError:  # run from a source tree that was never installed
        declared = []
    wanted = _normalized(DISTRIBUTIONS.get(module, module))
    for req in declared:
        if _normalized(re.match(r"[\w.-]+", req).group(0)) == wanted:  # "scipy>=1.11": scipy
            return f'pip install "{req.strip()}"'
    return "pip install . in frictionlab's clone (it installs frictionlab again with every dependency)"


class MissingDependency(FrictionlabError):
    """A package a feature needs is not installed; the message says how to install it."""

    def __init__(self, module: str, purpose: str):
        self.module = module.partition(".")[0]
        extra = EXTRAS.get(self.module)
        command = f'pip install "frictionlab[{extra}]"' if extra else dependency_command(self.module)
        super().__init__(f"{purpose} needs {self.module}, which is not installed: {command}")


def require(module: str, purpose: str):
    """``import module`` (and return it), or raise ``MissingDependency`` naming the pip
    command that installs it: the one way an optional package is imported."""
    import importlib

    try:
        return importlib.import_module(module)
    except ModuleNotFoundError:  # it, or a package it needs (the same pip command brings both)
        raise MissingDependency(module, purpose) from None


def refuse_unusable_matplotlib() -> None:
    """Import matplotlib before a command whose figures are its output does any work, and
    before the API draws: a bad MPLBACKEND makes matplotlib's import itself raise (the study
    found it only after it had computed; the report, exact3d and ``Result.plot`` as
    matplotlib's own ValueError). A FrictionlabError naming it and what is allowed."""
    import os
    import re

    try:
        import matplotlib  # noqa: F401  (its import reads MPLBACKEND)
    except ModuleNotFoundError:
        return  # said where a figure is drawn, with the pip command that installs it
    except ValueError as exc:
        backend = os.environ.get("MPLBACKEND")
        if backend is None:
            raise
        allowed = ", ".join(re.findall(r"'([^']+)'", str(exc).partition("supported values are ")[2])) or "agg, pdf, svg"
        raise FrictionlabError(
            f"MPLBACKEND={backend!r} is no matplotlib backend; allowed: {allowed}. Unset it, or set "
            "MPLBACKEND=agg: frictionlab draws its figures into PNG files and needs no display"
        ) from None


class PluginError(FrictionlabError):
    """A plugin is missing, broken, or clashes with another."""


class PresetError(FrictionlabError):
    """A preset failed validation. ``problems`` holds one line per problem, each
    starting with the dotted path of the offending field; the message shows the first
    ``SHOWN_PROBLEMS`` (a preset of thousands of unknown keys said megabytes of them)."""

    SHOWN_PROBLEMS = 50

    def __init__(self, problems: list[str], source: str | None = None):
        self.problems = list(problems)
        self.source = source
        where = f"{shown_name(source)}: " if source else ""  # a file name typed with an escape sequence, a line break
        count = len(self.problems)
        head = f"{where}{count} problem{'s' if count != 1 else ''} in preset"
        lines = ["  " + p for p in self.problems[: self.SHOWN_PROBLEMS]]
        if count > self.SHOWN_PROBLEMS:
            lines.append(f"  (and {count - self.SHOWN_PROBLEMS} more; frictionlab validate --json lists every one)")
        super().__init__("\n".join([head, *lines]))


class PresetFileError(PresetError):
    """The preset file itself cannot be used: missing, not a regular file, too
    large, not UTF-8 text, or beyond the YAML limits (nesting, aliases)."""

    exit_code = ExitCode.INPUT_FILE


class RunError(FrictionlabError):
    """The run could not complete (every realization failed, a write failed)."""

    exit_code = ExitCode.RUNTIME_FAILURE


class OutputRefused(FrictionlabError):
    """Writing where asked would replace or delete files frictionlab did not
    write (or the output path cannot be a folder)."""

    exit_code = ExitCode.OUTPUT_REFUSED


class RunFolderError(FrictionlabError):
    """A run folder cannot be resumed or used: its manifest or stored preset is
    damaged, another run holds it, or an input file changed since it started."""

    exit_code = ExitCode.RUN_FOLDER


_CONTROL = {c: f"\\x{c:02x}" for c in (*range(0x20), *range(0x7F, 0xA0)) if chr(c) not in "\n\t"}  # C0, DEL, C1 (CSI)
# characters that show nothing or turn the text around it (zero-width, bidirectional overrides,
# a byte-order mark): a name or a key that holds one reads as another on the terminal
_HIDING = (*range(0x200B, 0x2010), *range(0x202A, 0x202F), *range(0x2066, 0x206A), 0xFEFF)
_CONTROL.update({c: f"\\u{c:04x}" for c in _HIDING})


_LINES = {ord("\n"): "\\n", ord("\t"): "\\t"}


def shown(text) -> str:
    """``text`` (or a path) as any terminal takes it: bytes that are not UTF-8, control
    characters (C0 and C1) and characters that hide or reorder text escaped (an escape
    sequence typed in a ``--set`` or a file name must not drive the terminal, nor a key read
    as another); a message's lines and tabs kept, a path's escaped (``shown_name``)."""
    said = _bytes_of(text).decode("utf-8", "backslashreplace").translate(_CONTROL)
    return said.translate(_LINES) if isinstance(text, os.PathLike) else said


def _bytes_of(text) -> bytes:
    """The bytes ``text`` stands for: a name's own bytes where they are not UTF-8 (Python
    decodes them as lone surrogates), every other character in UTF-8, whatever the locale:
    os.fsencode under LC_ALL=C (ASCII) raised on the 'ü' of a folder's name shown once
    already, as the table that names it was shown, after the run."""
    text = os.fspath(text)
    if isinstance(text, bytes):
        return text
    try:
        return text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:  # a surrogate no byte gave (a forged JSON's \ud800): escaped below
        return text.encode("utf-8", "surrogatepass")


def shown_name(text) -> str:
    """A name (a path, a folder typed as ``--out``) as ``shown`` says it, on one line: its line
    breaks and tabs escaped too (a folder 'x\\nrun completed' read as two lines of a message)."""
    return shown(text).translate(_LINES)


def first_names(names: list[str], count: int = 3) -> str:
    """The first ``count`` of ``names`` as a message lists what a folder holds: ``'a', 'b', ...``."""
    return ", ".join(repr(shown_name(name)) for name in names[:count]) + (", ..." if len(names) > count else "")


def _escape_unencodable(exc: UnicodeError):
    """Codec error handler: a byte of a path that was not UTF-8 (a lone surrogate, as
    Python decodes it) written as ``\xff``, as ``shown`` does; any other character the
    stream cannot encode as ``\u03be``."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    text = exc.object[exc.start : exc.end]
    escaped = "".join(
        f"\\x{ord(c) - 0xDC00:02x}" if 0xDC80 <= ord(c) <= 0xDCFF else c.encode("ascii", "backslashreplace").decode()
        for c in text
    )
    return escaped, exc.end


codecs.register_error("frictionlab-escape", _escape_unencodable)


def escape_unencodable_output() -> None:
    """Make stdout and stderr escape what they cannot encode (a path that is not UTF-8, a
    character beyond a latin-1 terminal) instead of raising UnicodeEncodeError after the
    work is done and its files are written; called once by the CLI."""
    for stream in (sys.stdout, sys.stderr):
        if hasattr(stream, "reconfigure") and getattr(stream, "errors", None) in ("strict", "surrogateescape"):
            stream.reconfigure(errors="frictionlab-escape")


OUT_OF_MEMORY = "MemoryError"  # the kind of a realization's error (``Type: message (file.py:N)``) that ran out of memory
MEMORY_ADVICE = "fewer workers, fewer points, or where more memory is free"


def ran_out_of_memory(error: str) -> bool:
    """Whether a realization's recorded error is the machine's limit, not a bug or bad input."""
    return error.startswith(f"{OUT_OF_MEMORY}:") or error == OUT_OF_MEMORY


def process_limit() -> tuple[int, str] | None:
    """The smallest process limit on memory set here (``ulimit -v``, ``ulimit -d``) in
    bytes, with the ulimit option that sets it; None without one (or on Windows)."""
    try:
        import resource
    except ImportError:
        return None
    limits = [(resource.getrlimit(getattr(resource, name))[0], flag)
              for name, flag in (("RLIMIT_AS", "-v"), ("RLIMIT_DATA", "-d"))]  # fmt: skip
    set_ = [(soft, flag) for soft, flag in limits if soft != resource.RLIM_INFINITY]
    return min(set_) if set_ else None


def out_of_memory_loading(exc: BaseException) -> str | None:
    """The library a process limit left no room to load, else None: an ``ImportError`` ('failed to map
    segment'; numpy's message, scipy's 'install seems to be broken', quoting or raised from it), or
    under a limit a ``SystemError`` ('error return without exception set') or ``MemoryError`` of an import."""
    match = re.search(r"([^\s/:]+\.so[\w.]*): failed to map segment", str(exc))
    if isinstance(exc, ImportError) and match:
        return match.group(1)
    if isinstance(exc, (SystemError, MemoryError)) and process_limit() is not None:
        return _package_being_imported(exc)
    cause = exc.__cause__ or exc.__context__
    return out_of_memory_loading(cause) if isinstance(exc, ImportError) and cause is not None else None


def _package_being_imported(exc: BaseException) -> str | None:
    """The installed package whose import raised ``exc`` ('a library' if none), None if no
    import raised it; importing nothing, as the memory that failed one may fail another."""
    files, tb = [], exc.__traceback__
    while tb is not None:
        files.append(tb.tb_frame.f_code.co_filename)
        tb = tb.tb_next
    if not any(name.startswith("<frozen importlib") for name in files):
        return None
    parts = next((name for name in reversed(files) if not name.startswith("<")), "").split(os.sep)
    return parts[parts.index("site-packages") + 1].split(".")[0] if "site-packages" in parts[:-1] else "a library"


@dataclass(frozen=True)
class FrontEnd:
    """What the user in front of a refusal can type: the options of the command in use
    (``options``), or ``frictionlab.run``'s keywords (``python``). A refusal's advice names
    only those."""

    options: frozenset[str] = frozenset({"--workers"})
    python: bool = False


_front_end: ContextVar[FrontEnd] = ContextVar("front_end", default=FrontEnd())


@contextmanager
def advising(front_end: FrontEnd) -> Iterator[None]:
    """Within the block, refusals advise as ``front_end`` takes it."""
    token = _front_end.set(front_end)
    try:
        yield
    finally:
        _front_end.reset(token)


def workers_advice(workers: int) -> str:
    """A worker count to run with, as the front end in use takes it."""
    front = _front_end.get()
    if front.python:
        return f"workers={workers}"
    return f"--workers {workers}" if "--workers" in front.options else f"{workers} worker(s)"


def for_python() -> bool:
    """Whether a refusal is read by a caller of ``frictionlab.run`` (keywords), not a command's user."""
    return _front_end.get().python


def option_given(option: str, value: str | None = None) -> str:
    """An option of the command line (``--scheduler``), with the ``value`` given it, as the front end
    in use spells it: ``--scheduler tcp://...``, or ``scheduler='tcp://...'`` for ``frictionlab.run``."""
    if for_python():
        name = option.removeprefix("--").replace("-", "_")
        return name if value is None else f"{name}={value!r}"
    return option if value is None else f"{option} {value}"


def skip_hint() -> str:
    """The refusal's last sentence: how the front end in use skips the estimate, where it can."""
    front = _front_end.get()
    if front.python:
        return " (memory_check=False skips this estimate, an upper bound.)"
    if "--no-memory-check" in front.options:
        return " (--no-memory-check skips this estimate, an upper bound.)"
    return " (The estimate is an upper bound.)"


def limit_advice() -> str:
    """What a command out of memory adds under a process limit: the limit, to raise."""
    limit = process_limit()
    return f", or raise the process limit (ulimit {limit[1]} is {limit[0] // 1024} here)" if limit else ""


def resume_hint(folder) -> str:
    """How to go on with a run that stopped before its end: what finished is in ``folder``."""
    return f"what finished is kept in {shown_name(folder)}/: `frictionlab resume {command_word(folder)}` computes the rest"


def write_failed(exc: OSError, kept: str) -> RunError:
    """A write that failed (a full disk) as a RunError (exit code 1; under --json, the error
    object): the file and the system's reason, then ``kept``, what finished and how to go on."""
    where = f" {shown_name(exc.filename)}" if exc.filename else ""
    return RunError(f"cannot write{where}: {exc.strerror or exc}; {kept}")


def command_word(path) -> str:
    """``path`` as a word of a command to copy (``not_an_option``, ``shell_word``)."""
    return shell_word(not_an_option(os.fsdecode(path)))


def shell_word(word: str) -> str:
    """``word`` as bash takes it back, pasted into a command: quoted where a shell splits it (a
    space), and, where it holds what ``shown_name`` escapes (bytes that are not UTF-8, control
    characters, a line break), in bash's $'...' with those escaped: ``shown_name``'s ``\\xff``
    inside plain quotes named another folder, one with a backslash in its name."""
    import shlex

    if shown_name(word) == word:  # printable UTF-8
        return shlex.quote(word)
    return "$'" + "".join(map(_ansi_c, word)) + "'"


def _ansi_c(char: str) -> str:
    """One character of a word in bash's $'...': a byte that is not UTF-8 (a lone surrogate, as
    Python decodes it) as \\xHH, a character ``shown_name`` escapes as its code, quote and backslash escaped."""
    code = ord(char)
    if 0xDC80 <= code <= 0xDCFF:
        return f"\\x{code - 0xDC00:02x}"
    if char in "\\'":
        return "\\" + char
    if code in _LINES:
        return _LINES[code]
    if code in _CONTROL:  # $'\x85' would be the byte, not the character U+0085
        return f"\\x{code:02x}" if code < 0x80 else f"\\u{code:04x}"
    return char


def not_an_option(name: str) -> str:
    """A name as a word a command takes back as a name: ./-r2, not -r2 (`frictionlab resume -r2`
    takes it for an option)."""
    return f"./{name}" if name.startswith("-") else name


def counted(count: int, noun: str) -> str:
    """``1 point``, ``2 points``: a count and its noun in the number it takes."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def path_limits() -> dict[str, int]:
    """The longest name and path this system's file system takes, in bytes ({} if it does not say)."""
    limits = {}
    for what, name in (("name", "PC_NAME_MAX"), ("path", "PC_PATH_MAX")):
        try:
            limits[what] = os.pathconf(".", name)
        except (OSError, ValueError):
            pass
    return limits


def too_long_path(path, *, known: bool = False) -> str | None:
    """Why ``path`` is longer than the file system allows (one of its names, or the whole), with
    the limits; None if it is not. ``known``: the system said so (ENAMETOOLONG), say it anyway."""
    limits = path_limits()
    raw = os.fsencode(path)
    longest = max(len(name) for name in raw.split(b"/"))
    if not known and longest <= limits.get("name", longest) and len(raw) < limits.get("path", len(raw) + 1):
        return None
    allowed = f" (at most {' and '.join(f'a {what} {size} bytes' for what, size in limits.items())})" if limits else ""
    return f"{short_repr(os.fsdecode(path), 120)}: a file name too long for this file system{allowed}; give a shorter path"


def short_repr(value, limit: int = 80) -> str:
    """``repr(value)`` cut to about ``limit`` characters, built without ever
    forming the whole repr (a value from a hostile preset may be huge or deep)."""
    import reprlib

    shortener = reprlib.Repr()
    shortener.maxlevel, shortener.maxstring, shortener.maxother, shortener.maxlong = 3, limit, limit, limit
    shortener.maxlist = shortener.maxtuple = shortener.maxdict = shortener.maxset = 8
    try:
        text = shortener.repr(value)
    except ValueError:  # an int past Python's digit limit
        text = f"<{type(value).__name__} too long to show>"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def close_names(word: str, names, cutoff: float = 0.5) -> list[str]:
    """The (at most three) of ``names`` closest to ``word``, closest first."""
    import difflib

    return difflib.get_close_matches(word, list(names), n=3, cutoff=cutoff)


def did_you_mean(word: str, names, cutoff: float = 0.5) -> str:
    """``"; did you mean 'run'?"`` naming the closest of ``names``, or ``""``: the hint
    every unknown-name message (commands, options, plugins, presets, fields) ends with."""
    close = close_names(word, names, cutoff)
    return f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """A warning (a UserWarning by default) attributed to the first caller outside frictionlab
    (a script's or a notebook cell's line): a notebook shows that line, not one of ours, and a
    warning shown once per place is shown again for each place of the user's that causes it."""
    import warnings

    package, frame, level = os.path.dirname(os.path.dirname(__file__)) + os.sep, sys._getframe(1), 1  # frictionlab/
    while frame is not None and frame.f_code.co_filename.startswith(package):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level + 1 if frame is not None else 2)


def raised_here(entry):
    """For the Python API's entry points (``frictionlab.run``, ``load``, ``validate``): a
    FrictionlabError (bad input, a refusal) comes out of the entry point with its traceback
    cut there: a notebook shows the caller's line, the call and the message, not a screen of
    frictionlab's own frames that say nothing about what to change."""
    import functools

    @functools.wraps(entry)
    def called(*args, **keys):
        try:
            return entry(*args, **keys)
        except FrictionlabError as exc:
            raise exc.with_traceback(None)  # its message says what is wrong: frictionlab's frames are left out

    return called


def _quiet_stdout() -> None:
    """After a BrokenPipeError: point stdout at /dev/null so the interpreter's
    final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout without a descriptor (a test's capture)
        pass


def output_failed(exc: OSError) -> int:
    """stdout could not be written: a closed pipe ends quietly (its reader has enough),
    anything else (a full disk) is said on stderr."""
    _quiet_stdout()  # the interpreter's last flush must not fail again
    if isinstance(exc, BrokenPipeError):
        return int(ExitCode.BROKEN_PIPE)
    print(f"error: cannot write the output: {exc.strerror or exc}", file=sys.stderr)
    return int(ExitCode.RUNTIME_FAILURE)
