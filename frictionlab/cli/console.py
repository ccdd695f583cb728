"""How the CLI writes for people: tables that fit the terminal, colour on a
terminal only (never when ``NO_COLOR`` is set), plain text in a pipe or a file.

rich is imported only when stdout is a terminal: a pipe gets tab-free aligned
columns, one line per row, that ``grep`` and ``cut`` can read.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from ..errors import shown


def use_colour(stream=None) -> bool:
    """Colour (and rich's layout) only on a terminal, and never with NO_COLOR set (no-color.org)."""
    return is_terminal(stream) and not os.environ.get("NO_COLOR")


def error_label(stream=None) -> str:
    """``error``, in red on a terminal that takes colour."""
    return "\x1b[31merror\x1b[0m" if use_colour(stream or sys.stderr) else "error"


def is_terminal(stream=None) -> bool:
    stream = stream or sys.stdout
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False


def _cell(value) -> str:
    """``value`` as one line of a table (``shown``, its line breaks and tabs escaped too): a run
    folder named 'x\\nfake  completed' drew a second row."""
    from ..errors import shown_name

    return shown_name(str(value))


def print_table(header: Sequence[str], rows: Sequence[Sequence[str]], *, stream=None) -> None:
    """Rows under a header: on a terminal a rich table that fits its width (the last
    column wraps), elsewhere plain columns padded to the widest cell."""
    stream = stream or sys.stdout
    header, rows = [_cell(cell) for cell in header], [[_cell(cell) for cell in row] for row in rows]  # cells from folders
    if is_terminal(stream):
        from rich.console import Console
        from rich.table import Table

        table = Table(box=None, header_style="bold cyan", pad_edge=False)
        for i, name in enumerate(header):
            table.add_column(name, overflow="fold", no_wrap=i < len(header) - 1)
        for row in rows:
            table.add_row(*map(str, row))
        Console(file=stream, no_color=not use_colour(stream), highlight=False).print(table)
        return
    widths = [max(len(str(r[c])) for r in [header, *rows]) for c in range(len(header) - 1)]
    for row in [header, *rows]:
        cells = [str(cell).ljust(w) for cell, w in zip(row[:-1], widths)]
        print("  ".join([*cells, str(row[-1])]), file=stream)


def stderr_log(quiet: bool):
    """A long command's ``log``: each line on stderr, escaped (it names folders and files as typed,
    and an escape code in a name must not drive the terminal); nothing under ``--quiet``."""
    if quiet:
        return lambda text: None
    return lambda text: print(shown(text), file=sys.stderr, flush=True)
