"""A table of numbers in a text file (``.csv``, ``.txt``): a column, a row, x and z, or a map's
rows, separated by commas, semicolons or whitespace, read as UTF-8 with one header line at most.
A problem names the line, never its content (the file is the user's, its text any bytes)."""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import numpy as np

from .instrument_file import open_input
from .instrument_reader import room_to_read


def _numbers(text: str, delimiter: str | None) -> bool:
    return all(_number(token) for token in text.split(delimiter))


TABLE_COPIES = 3  # reading a table takes at least 3 times its bytes (its bytes, text, lines and numbers: 3 to 6 measured)


def read_text_table(path: Path, where: str) -> np.ndarray:
    """Rows x columns of float64; one header line (more of its cells text than numbers) is
    skipped. A problem names the line, never its content. A table has no header that gives its
    size: one that cannot be read in the memory left is refused by its size, before or while read."""
    with open_input(path, where) as fh:
        size = os.fstat(fh.fileno()).st_size
        room, source = room_to_read()
        if size * TABLE_COPIES > room:
            raise ValueError(_too_large_table(where, size, f"reading it takes at least {size * TABLE_COPIES / 2**30:.3g} "
                                              f"GiB, more than the {room / 2**30:.3g} GiB this process may use ({source})"))
        try:
            return _table(fh.read(), where)
        except MemoryError:
            raise ValueError(_too_large_table(where, size, "reading it ran out of memory")) from None


def _too_large_table(where: str, size: int, why: str) -> str:
    return (f"{where}: a table of {size:,} bytes; {why}: save the heights as a .npy array (8 bytes a height, its "
            "size checked before it is read), or crop the scan before saving it")


def _table(raw: bytes, where: str) -> np.ndarray:
    """The numbers of a table's bytes ``raw`` (``read_text_table``)."""
    try:
        if (nul := raw.find(b"\x00")) >= 0:  # valid UTF-8, but no text's: UTF-16 without its mark, or binary
            raise UnicodeDecodeError("utf-8", raw, nul, nul + 1, "a NUL byte")
        lines = raw.decode("utf-8-sig").splitlines()  # without the byte-order mark a spreadsheet writes first
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start + (3 if raw.startswith(b"\xef\xbb\xbf") else 0)) + 1
        raise ValueError(f"{where}: not UTF-8 at line {line} (text in another encoding, as a Latin-1 header's µ or "
                         "UTF-16's NUL bytes, or no text); an instrument's export (a profilometer's .csv) is read with "
                         "format: instrument; a table of bare numbers is read as UTF-8: save it so (a spreadsheet's "
                         "'CSV UTF-8')") from None
    skip, delimiter = 0, None
    for lineno, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        if skip:  # the first line after a header says how its numbers are separated
            delimiter = _delimiter(text)
            break
        delimiter = _delimiter(text)
        if _numbers(text, delimiter):
            break
        if _ends_with_separator(text, delimiter):  # numbers and an empty column: no header
            raise ValueError(f"{where}: {_trailing_text(lineno, delimiter)}")
        if _mostly_numbers(text, delimiter):  # a row of heights with a cell that is not one: named below
            break
        skip = lineno  # a header such as "x,z", or "z" over a matrix of commas
    if delimiter == "," and (lineno := _comma_decimal_line(lines, skip)) is not None:
        raise ValueError(f"{where}: {_decimal_commas(lineno)}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # numpy warns on empty input; the point count reports it
            data = np.loadtxt(lines[skip:], dtype=np.float64, delimiter=delimiter, comments="#", ndmin=2)
    except ValueError:
        raise ValueError(f"{where}: {_first_bad_line(lines, skip, delimiter)}") from None
    if data.size == 0:
        data = np.zeros((0, 1))
    return data


def _first_bad_line(lines: list[str], skip: int, delimiter: str | None) -> str:
    """Where a table stops being one: the first line that is not numbers, or
    whose column count differs from the first data line's."""
    columns = None
    for lineno, line in enumerate(lines[skip:], start=skip + 1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        if not _numbers(text, delimiter):
            if _ends_with_separator(text, delimiter):
                return _trailing_text(lineno, delimiter)
            if _numbers(text.replace(",", "."), ";" if ";" in text else None):  # 1,5;2,25 or 1,5 2,25
                return _decimal_commas(lineno)
            return f"non-numeric content at line {lineno} (expected numbers separated by {_separator(delimiter)})"
        count = len(text.split(delimiter))
        if columns is not None and count != columns:
            return f"line {lineno} has {count} columns, the lines before it {columns}"
        columns = count
    return "not a table of numbers"


def _decimal_commas(lineno: int) -> str:
    return (f"decimal commas at line {lineno} (as 1,5); numbers are read with a decimal point (1.5): "
            "export the table with decimal points")


COMMA_DECIMAL = re.compile(r"[-+]?\d+,\d+(?:[eE][-+]?\d+)?")  # 0,0677: decimal commas, or x, z in whole numbers
LEADING_ZERO = re.compile(r"[-+]?\d+,0\d")  # 0,0677: a fraction; no program writes a whole number 0677


def _comma_decimal_line(lines: list[str], skip: int) -> int | None:
    """The first line of a column of numbers with decimal commas (0,0677 read as x = 0, z = 677,
    refused as a grid that is not uniform), if every line is two whole numbers and a second starts
    with 0 and a digit; None otherwise."""
    rows = [(n, t) for n, line in enumerate(lines[skip:], start=skip + 1) if (t := line.split("#", 1)[0].strip())]
    if rows and all(COMMA_DECIMAL.fullmatch(t) for _, t in rows):
        return next((n for n, t in rows if LEADING_ZERO.match(t)), None)
    return None


def _mostly_numbers(text: str, delimiter: str | None) -> bool:
    """Whether more of the line's cells are numbers than not: a row of data with a bad cell
    (``0.1,x,0.3``, ``0.1,,0.3``), which is no header (``x,z``; ``z [nm]``; ``Height 1``)."""
    cells = text.split(delimiter)
    numbers = sum(_number(cell) for cell in cells)
    return numbers > len(cells) - numbers


def _number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _ends_with_separator(text: str, delimiter: str | None) -> bool:
    """Numbers followed by a separator and nothing (``1.5,2.5,``): an empty last column."""
    return delimiter is not None and text.endswith(delimiter) and _numbers(text[: -len(delimiter)].rstrip(), delimiter)


def _trailing_text(lineno: int, delimiter: str | None) -> str:
    return (f"line {lineno} ends with a separator ({_separator(delimiter)[:-1]}), an empty column after its last "
            "number; export the table without a separator at the end of its lines")


def _delimiter(text: str) -> str | None:
    """Semicolons (a spreadsheet's export where the comma is the decimal mark), else commas, else whitespace."""
    return ";" if ";" in text else "," if "," in text else None


def _separator(delimiter: str | None) -> str:
    return {",": "commas", ";": "semicolons"}.get(delimiter, "spaces")
