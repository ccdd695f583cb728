"""Text the TUI shows, shaped to fit (no Textual here): paths shortened from the
middle, a realization's error told as a person needs it."""

from __future__ import annotations

import re

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


_WHERE = re.compile(r"\s\([\w.-]+\.py:\d+\)$")  # the source location the engine appends
_INPUT_ERRORS = ("ValueError", "InputFileProblem", "FileNotFoundError", "PermissionError", "OSError")


def failure_message(error: str) -> str:
    """A realization's error as the engine records it (``Type: message (file.py:N)``)
    told to the user: an input problem (a file that cannot be read, a value the
    plugin refuses) as its message alone; anything else as an internal error, with
    its type and place, to report."""
    kind, _, message = error.partition(": ")
    if kind in _INPUT_ERRORS and message:
        return _WHERE.sub("", message)
    return f"internal error ({error}); please report it"
