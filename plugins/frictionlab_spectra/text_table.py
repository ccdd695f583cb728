"""Tables of bare numbers in text (.csv, .txt): one header line at most, numbers separated by
commas, semicolons or whitespace, read a line at a time into float64 (``read_text_table``)."""

from __future__ import annotations

import codecs
import io
import math
import os
import re
import warnings
from pathlib import Path

import numpy as np

from .instrument_file import open_input
from .instrument_reader import room_to_read


def _numbers(text: str, delimiter: str | None) -> bool:
    return all(is_number(token) for token in text.split(delimiter))


SAMPLE_BYTES = 65536  # the file's first bytes, whose numbers per byte size the whole table's
TABLE_COPIES = 3  # float64 arrays of the numbers: numpy's growing one (1.1 to 1.3 times them, measured), a column copied


def read_text_table(path: Path, where: str, copies: int = TABLE_COPIES) -> np.ndarray:
    """Rows x columns of float64; one header line (more of its cells text than numbers) is
    skipped. A problem names the line, never its content. The text is read a line at a time,
    never whole: what it takes is its numbers (8 bytes each), not its bytes. A table has no
    header that gives its size: one whose numbers, counted in its first bytes, cannot fit in
    the memory left is refused before it is read, and one that runs out while read so named.
    ``copies``: the arrays of its numbers its reader holds at once (a map's levelling, more)."""
    with open_input(path, where) as fh:
        size = os.fstat(fh.fileno()).st_size
        sample = fh.read(SAMPLE_BYTES)
        fh.seek(0)
        if (nul := sample.find(b"\x00")) >= 0:  # valid UTF-8, but no text's: UTF-16 without its mark, or binary
            raise ValueError(not_utf8(where, sample.count(b"\n", 0, nul) + 1))
        need = _numbers_in(sample, size) * 8 * copies
        room, source = room_to_read()
        if need > room:
            raise ValueError(_too_large_table(where, size, f"reading its numbers takes about {need / 2**30:.3g} GiB, "
                                              f"more than the {room / 2**30:.3g} GiB this process may use ({source})"))
        text = io.TextIOWrapper(fh, encoding="utf-8-sig")  # without the byte-order mark a spreadsheet writes first
        try:
            return _table(text, where)
        except MemoryError:
            raise ValueError(_too_large_table(where, size, "reading it ran out of memory")) from None
        except UnicodeDecodeError:
            raise ValueError(not_utf8(where, _undecodable_line(fh))) from None
        finally:
            text.detach()  # the file is open_input's to close


def first_not_finite(path: Path, where: str, column: int | None = None, skip: int = 0) -> tuple[int, int] | None:
    """The line and column (from 1, as an editor shows them) of the first number of a text table
    (in its ``column``, if given) that is not finite or is beyond MAX_MAGNITUDE (a NaN a
    profilometer writes for a point it did not measure), read a line at a time, past its first
    ``skip`` numbers (those a crop left out); None if there is none (a header's cells are no numbers)."""
    from frictionlab.plugin import MAX_MAGNITUDE  # here: only a table refused for such a number needs it

    with open_input(path, where) as fh:
        for lineno, raw in enumerate(io.TextIOWrapper(fh, encoding="utf-8-sig", errors="replace"), start=1):
            text = raw.split("#", 1)[0].strip()
            delimiter = _delimiter(text)
            if not text or not _numbers(text, delimiter):
                continue
            for at, cell in enumerate(text.split(delimiter), start=1):
                if column not in (None, at):
                    continue
                if skip <= 0 and not abs(float(e_exponents(cell))) <= MAX_MAGNITUDE:  # NaN too
                    return lineno, at
                skip -= 1
    return None


def blank_line_among_numbers(path: Path, where: str) -> int | None:
    """The first blank line (from 1) between two lines of numbers of a text table, else None:
    in a column of heights, a spreadsheet writes the cell it left empty (a point not measured)
    as such a line, which numpy skips, moving every height after it one point along."""
    with open_input(path, where) as fh:
        if not _has_blank_line(fh):  # the common case, a pass over bytes: the lines are read only where one is
            return None
        fh.seek(0)
        blank, numbers_before = None, False
        for lineno, raw in enumerate(io.TextIOWrapper(fh, encoding="utf-8-sig", errors="replace"), start=1):
            if not raw.strip():
                blank = blank or (lineno if numbers_before else None)
                continue
            text = raw.split("#", 1)[0].strip()
            if text and _numbers(text, _delimiter(text)):
                if blank is not None:
                    return blank
                numbers_before = True
    return None


_BLANK_LINE = re.compile(rb"\n[ \t]*\r?\n|\r[ \t]*\r")  # after LF or CRLF, or in a file of CR line ends


def _has_blank_line(fh) -> bool:
    """Whether the open binary file holds an empty (or whitespace) line, read a chunk at a time."""
    tail = b""
    while chunk := fh.read(1 << 20):
        text = tail + chunk
        if _BLANK_LINE.search(text):
            return True
        end = max(text.rfind(b"\n"), text.rfind(b"\r"))
        tail = text[end:] if end >= 0 and not text[end + 1 :].strip() else b""  # a blank line cut by the chunk's end
    return False


def not_utf8(where: str, line: int) -> str:
    return (f"{where}: not UTF-8 at line {line} (text in another encoding, as a Latin-1 header's µ or UTF-16's NUL "
            "bytes, or no text); an instrument's export (a profilometer's .csv) is read with format: instrument; a "
            "table of bare numbers is read as UTF-8: save it so (a spreadsheet's 'CSV UTF-8')")


def _numbers_in(sample: bytes, size: int) -> int:
    """The numbers a table of ``size`` bytes holds, as many per byte as in its first bytes
    ``sample`` (a number cut at their end not counted; at least one per 64 bytes: a first line
    of text is no measure)."""
    cells = sum(len(line.split(b"#", 1)[0].replace(b",", b" ").replace(b";", b" ").split()) for line in sample.splitlines())
    cells -= len(sample) == SAMPLE_BYTES and not sample[-1:].isspace()  # the last, cut
    return math.ceil(size * max(cells / max(len(sample), 1), 1 / 64))


def _too_large_table(where: str, size: int, why: str) -> str:
    return (f"{where}: a table of {size:,} bytes; {why}: save the heights as a .npy array (8 bytes a height, its "
            "size checked before it is read), or crop the scan before saving it")


def _undecodable_line(fh) -> int:
    """The line of the first bytes of the open file that are not UTF-8, found a chunk at a time."""
    decoder, line = codecs.getincrementaldecoder("utf-8")(), 1
    fh.seek(0)
    while chunk := fh.read(1 << 20):
        try:
            decoder.decode(chunk)
        except UnicodeDecodeError as exc:
            return line + chunk.count(b"\n", 0, exc.start)
        line += chunk.count(b"\n")
    return line


def _table(text, where: str) -> np.ndarray:
    """The numbers of the open text file ``text`` (``read_text_table``): its first lines say
    whether a header is to be skipped and how numbers are separated; numpy reads the rest."""
    skip, delimiter = 0, None
    for lineno, line in enumerate(text, start=1):
        cells = line.split("#", 1)[0].strip()
        if not cells:
            continue
        if skip:  # the first line after a header says how its numbers are separated
            delimiter = _delimiter(cells)
            break
        delimiter = _delimiter(cells)
        if _numbers(cells, delimiter):
            break
        if _ends_with_separator(cells, delimiter):  # numbers and an empty column: no header
            raise ValueError(f"{where}: {_trailing_text(lineno, delimiter)}")
        if _mostly_numbers(cells, delimiter):  # a row of heights with a cell that is not one: named below
            break
        if _numbers(cells.replace(",", "."), ";" if ";" in cells else None):  # 1,5;2,25: numbers, not a header
            raise ValueError(f"{where}: {decimal_commas(lineno)}")
        skip = lineno  # a header such as "x,z", or "z" over a matrix of commas
    text.seek(0)
    if delimiter == "," and COMMA_DECIMAL.fullmatch(cells):  # two whole numbers: x, z, or one decimal-comma height?
        if (lineno := _comma_decimal_line(text, skip)) is not None:
            raise ValueError(f"{where}: {decimal_commas(lineno)}")
        text.seek(0)
    try:
        data = _loadtxt(text, delimiter, skip)
    except ValueError:
        text.seek(0)
        try:  # numpy reads no Fortran exponent (1.0D-06): read again with e, only where one failed it
            data = _loadtxt((e_exponents(line) for line in text), delimiter, skip)
        except ValueError:
            text.seek(0)
            raise ValueError(f"{where}: {_first_bad_line(text, skip, delimiter)}") from None
    if data.size == 0:
        data = np.zeros((0, 1))
    return data


def _loadtxt(lines, delimiter: str | None, skip: int) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpy warns on empty input; the point count reports it
        return np.loadtxt(lines, dtype=np.float64, delimiter=delimiter, comments="#", ndmin=2, skiprows=skip)


# 1.0D-06, -2.5d+03: a number as Fortran writes it (D for a double's exponent), a whole cell
FORTRAN_NUMBER = re.compile(r"(?<![\w.+-])([-+]?(?:\d+\.?\d*|\.\d+))[dD]([-+]?\d+)(?![\w.])")


def e_exponents(text: str) -> str:
    """``text`` with each number written with Fortran's exponent (``1.0D-06``) written with
    numpy's (``1.0e-06``): the same number; any other text left as it is."""
    return FORTRAN_NUMBER.sub(r"\1e\2", text) if "d" in text or "D" in text else text


def _first_bad_line(lines, skip: int, delimiter: str | None) -> str:
    """Where a table stops being one: the first line after ``skip`` that is not numbers, or
    whose column count differs from the first data line's."""
    columns = None
    for lineno, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if lineno <= skip or not text:
            continue
        if not _numbers(text, delimiter):
            if _ends_with_separator(text, delimiter) and len(text.split(delimiter)) != columns:  # else: an empty cell
                return _trailing_text(lineno, delimiter)
            if _numbers(text.replace(",", "."), ";" if ";" in text else None):  # 1,5;2,25 or 1,5 2,25
                return decimal_commas(lineno)
            if ('"' in text or "'" in text) and _numbers(re.sub("[\"']", "", text), delimiter):  # "0.5","1.25"
                return (f"numbers in quotes at line {lineno} (as \"1.5\"); a table's numbers are bare: export it "
                        "without quotes around numbers")  # fmt: skip
            words = not is_number(text.split(delimiter)[0]) and not _mostly_numbers(text, delimiter)  # no row of data
            footer = columns is not None and words and _footer(lines, delimiter)
            return (f"non-numeric content at line {lineno} (expected numbers separated by {_separator(delimiter)})"
                    + (footer or (_MORE_HEADER if columns is None and words else _bad_cell(text, delimiter))))
        count = len(text.split(delimiter))
        if columns is not None and count != columns:
            return f"line {lineno} has {count} columns, the lines before it {columns}"
        columns = count
    return "not a table of numbers"


_MORE_HEADER = (": a second line of text before the numbers; a table has one header line at most: start the others "
                "with #, or read an instrument's export (its header of settings and units) with format: instrument")


def _footer(rest, delimiter: str | None) -> str:
    """What a table's first line of text after its numbers is when no line of ``rest`` (the lines
    after it) holds numbers: a footer, which an export writes after its data ('End of data')."""
    if any(_numbers(text, delimiter) for line in rest if (text := line.split("#", 1)[0].strip())):
        return ""
    return (": text, and no line after it holds numbers: a footer after the table (an export's summary, 'End of "
            "data'), which a table of numbers does not have; delete it, or start its lines with #")


def _bad_cell(text: str, delimiter: str | None) -> str:
    """Which cell of a line is no number, by its column (never its content); an empty cell is a
    point an export left out, which NaN stands for (then refused, or cropped out, by name)."""
    cells = text.split(delimiter)
    column = next(i for i, cell in enumerate(cells, start=1) if not is_number(cell))
    if any(char.isdigit() for char in cells[column - 1]):
        return f": column {column} is not a number"
    if cells[column - 1].strip():  # ***, N/A, --: how exports mark a point not measured
        return (f": column {column} is not a number, and holds no digit: if it marks a point not measured (as ***, N/A "
                "or -- do), write NaN there, which undefined: harmonic fills")
    return (f": column {column} is empty, a point the export left out; write NaN there to mark it missing, which "
            "undefined: harmonic fills")


def decimal_commas(lineno: int, what: str = "table") -> str:
    return (f"decimal commas at line {lineno} (as 1,5); numbers are read with a decimal point (1.5): "
            f"export the {what} with decimal points")


COMMA_DECIMAL = re.compile(r"[-+]?\d+,\d+(?:[eE][-+]?\d+)?")  # 0,0677: decimal commas, or x, z in whole numbers
LEADING_ZERO = re.compile(r"[-+]?\d+,0\d")  # 0,0677: a fraction; no program writes a whole number 0677


def _comma_decimal_line(lines, skip: int) -> int | None:
    """The first line of a column of numbers with decimal commas (0,0677 read as x = 0, z = 677,
    refused as a grid that is not uniform), if every line is two whole numbers and a second starts
    with 0 and a digit; None otherwise. ``lines`` is read through once, a line at a time."""
    first = None
    for lineno, line in enumerate(lines, start=1):
        text = line.split("#", 1)[0].strip()
        if lineno <= skip or not text:
            continue
        if not COMMA_DECIMAL.fullmatch(text):
            return None
        if first is None and LEADING_ZERO.match(text):
            first = lineno
    return first


def _mostly_numbers(text: str, delimiter: str | None) -> bool:
    """Whether more of the line's cells are numbers than not: a row of data with a bad cell
    (``0.1,x,0.3``, ``0.1,,0.3``), which is no header (``x,z``; ``z [nm]``; ``Height 1``)."""
    cells = text.split(delimiter)
    numbers = sum(is_number(cell) for cell in cells)
    return numbers > len(cells) - numbers


def is_number(cell: str) -> bool:
    """Whether ``cell`` is a number, written as Python or as Fortran (``1.0D-06``) writes one."""
    try:
        float(e_exponents(cell))
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




EVEN = 1e-5  # of its range: a line of numbers this close to evenly spaced is positions (printed to 6 digits), not heights


def axes_warning(data: np.ndarray, kept: tuple[bool, bool] = (True, True)) -> str | None:
    """The caveat of a table map whose first row (past its corner) or first column holds evenly
    spaced numbers: an export's axes, x over the columns and y beside the rows (a matrix with its
    positions, a spreadsheet's row numbers), read as heights; no measured row is a line to 1e-5.
    ``kept``: whether a crop keeps the first row, and the first column."""
    ny, nx = data.shape
    lines = (("row", data[0, 1:], f"y: [1, {ny}]"), ("column", data[1:, 0], f"x: [1, {nx}]"))
    found = [(name, line, crop) for (name, line, crop), keep in zip(lines, kept) if keep and _evenly_spaced(line)]
    if not found:
        return None
    corner = data[0, 0]
    said = " and ".join(f"first {name} ({corner if _evenly_spaced(np.r_[corner, line]) else line[0]:.6g} to {line[-1]:.6g})"
                        for name, line, _ in found)  # fmt: skip
    return (f"the table's {said} {'are' if len(found) > 1 else 'is'} evenly spaced: an export's positions (x over the "
            "columns, y beside the rows) or row numbers, read here as heights, a ramp along the map's edge; leave "
            f"{'them' if len(found) > 1 else 'it'} out with region: {{{', '.join(crop for *_, crop in found[::-1])}}}, "
            "if they are not heights")  # fmt: skip


def _evenly_spaced(line: np.ndarray) -> bool:
    """Whether ``line`` (more than 2 numbers) rises or falls by one step, to EVEN of its range."""
    if line.size < 3 or not np.all(np.abs(line) < 1e300):  # NaN, inf, the huge: refused by name once read
        return False
    span = float(line[-1] - line[0])
    even = line[0] + span * np.arange(line.size) / (line.size - 1)
    return bool(span) and float(np.max(np.abs(line - even))) <= EVEN * abs(span)
