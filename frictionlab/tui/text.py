"""Text the TUI shows, shaped to fit (no Textual here): paths shortened from the
middle, run names keeping their time stamp, counts in one format, a realization's
error told as a person needs it."""

from __future__ import annotations

import math
import re

from ..errors import MEMORY_ADVICE, ran_out_of_memory

ELLIPSIS = "…"


def shorten_middle(text: str, width: int) -> str:
    """``text`` cut to ``width`` characters by dropping its middle: a path keeps
    its start (where) and its end (the run's name)."""
    if width <= 0:
        return ""
    if len(text) <= width:
        return text
    if width == 1:
        return ELLIPSIS
    tail = (width - 1) // 2 + (width - 1) % 2
    head = width - 1 - tail
    return text[:head] + ELLIPSIS + text[len(text) - tail :]


RUN_STAMP = re.compile(r"(.+)-(\d{4})(\d{4}-\d{6}(?:-\d+)?)")  # name-YYYYMMDD-HHMMSS[-n]: rundir.new_run_folder's
NAME_KEPT = 5  # of a run's name, at least this much (with its ellipsis) beside the whole time stamp


def shorten_run_name(name: str, width: int) -> str:
    """A run folder's name cut to ``width`` characters keeping its time stamp, which tells
    apart runs of one preset: the middle of the name goes first, then the stamp's year
    (``long…1127-172222``); a name with no stamp is cut from its middle."""
    match = RUN_STAMP.fullmatch(name)
    if len(name) <= width or match is None:
        return shorten_middle(name, width)
    prefix, year, rest = match.groups()
    room = width - len(year) - len(rest) - 1
    if room >= NAME_KEPT:
        return f"{shorten_middle(prefix, room)}-{year}{rest}"
    room = width - len(rest) - 1
    if room >= 1:
        return f"{prefix[:room]}{ELLIPSIS}{rest}"
    return shorten_middle(name, width)


def packed(pieces: list[str], width: int, indent: str = "  ") -> list[str]:
    """``pieces`` after ``indent``, as many a line as ``width`` holds: a narrow box (60x20)
    breaks between them, never within a number or an interval."""
    lines: list[str] = []
    for piece in pieces:
        if lines and len(lines[-1]) + 1 + len(piece) <= width:
            lines[-1] += " " + piece
        else:
            lines.append(indent + piece)
    return lines


def format_count(value: float) -> str:
    """A mean count (points in contact) to 3 significant digits, in plain digits below
    1e5 (``0.750``, ``30.6``, ``621``, ``1350``): one column reads alike from row to row."""
    rounded = float(f"{value:.3g}")
    if not math.isfinite(rounded) or abs(rounded) >= 1e5:
        return f"{value:.3g}"
    if rounded == 0:
        return "0"
    return f"{rounded:.{max(0, 2 - math.floor(math.log10(abs(rounded))))}f}"


_WHERE = re.compile(r"\s\([\w.-]+\.py:\d+\)$")  # the source location the engine appends
_INPUT_ERRORS = ("SolveFailed", "ValueError", "InputFileProblem", "FileNotFoundError", "PermissionError", "OSError")


def failure_message(error: str) -> str:
    """A realization's error as the engine records it (``Type: message (file.py:N)``)
    told to the user: an input problem (a file that cannot be read, a value the
    plugin refuses) as its message alone; running out of memory with what helps; anything else as an internal error, with
    its type and place, to report."""
    kind, _, message = error.partition(": ")
    if ran_out_of_memory(error):  # the machine's limit, not a bug to report
        detail = _WHERE.sub("", message).strip()
        return f"out of memory{f' ({detail})' if detail else ''}: run it again with {MEMORY_ADVICE}"
    if kind in _INPUT_ERRORS and message:
        return _WHERE.sub("", message)
    return f"internal error ({error}); please report it"


def problems_text(problems: list[str]) -> str:
    """A preset's problems on one line, as the status line says them: a problem of the
    file itself without the ``(file):`` its list marks it with (the file is named in the title)."""
    return "; ".join(problem.removeprefix("(file): ") for problem in problems)
