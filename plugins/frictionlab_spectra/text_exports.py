"""A text export's numbers against what the file says of them, before its reader parses it:
a last line shorter than the one before (a file cut short), an SDF's data holding more
numbers than its header declares (its reader stops at the count declared), numbers written
with decimal commas (its reader takes them for separators), or rows it does not read (a
matrix between commas, points with more columns than x, y, z)."""

from __future__ import annotations

import os
import re

from .header_units import NUMBERS, head_text
from .instrument_reader import AGAIN

TAIL_BYTES = 65536  # of a text export read for its last line
COMMA_BETWEEN_DIGITS = re.compile(r"\d,\d")  # 1,5: a decimal comma, where a cell holds one


def check_text_whole(fh, reader, where: str) -> None:
    """Refuse a text export whose last line of numbers holds fewer than the line before it: a file
    cut short (a copy or a transfer stopped). Its reader dropped the cut row, and a matrix export whose
    header states its size stretched the rows left over it: pixels 1.5 times too long along y, resampled."""
    size = os.fstat(fh.fileno()).st_size
    fh.seek(max(0, size - TAIL_BYTES))
    lines = [line for line in fh.read().decode("utf-8", errors="replace").splitlines()[1:] if line.strip()][-2:]
    fh.seek(0)
    if len(lines) < 2 or not all(NUMBERS.match(line) for line in lines):  # a footer, or one line: nothing to compare
        return
    before, last = (len(re.split(r"[\s,;]+", line.strip())) for line in lines)
    if last < before:
        raise ValueError(
            f"{where}: its last line holds {last} numbers and the line before it {before}: a {reader.name()} file "
            f"cut short (a copy or a transfer stopped); {AGAIN}"
        )


def check_declared_values(fh, reader, where: str) -> None:
    """Refuse a text SDF whose data (between the header's closing ``*`` and the next) holds more
    numbers than its header declares, NumPoints x NumProfiles: its reader reads lines until it has
    that many, so whole rows beyond them (a header stating too few profiles) were dropped without
    a word. Fewer, or more within the last line read, its reader names as damage itself."""
    if reader.format() != "sdf":
        return
    declared, count, in_data = {}, 0, False
    fh.seek(0)
    for raw in fh:  # a line at a time: no copy of the file
        line = raw.decode("utf-8", errors="replace").strip()
        if line == "*" and in_data:
            break
        if line == "*":
            in_data = True
        elif in_data:
            count += len(line.split())
        else:
            key, _, value = line.partition("=")
            declared[key.strip()] = value.strip()
    fh.seek(0)
    try:
        points, profiles = int(declared["NumPoints"]), int(declared["NumProfiles"])
    except (KeyError, ValueError):  # its reader names a header without them
        return
    if count > points * profiles:
        raise ValueError(
            f"{where}: a damaged {reader.name()} file: its header declares {points} x {profiles} points (x by y), and "
            f"its data holds {count} numbers, {count - points * profiles} more, which its reader would drop without a "
            f"word (a header that states too few points or profiles); {AGAIN}"
        )


def check_numbers_written(fh, reader, where: str) -> None:
    """Refuse a text export whose first row of numbers its reader would misread: decimal commas
    between its separators (tabs, spaces, semicolons: 1,5e-07;2,5e-07, as an export in a European
    locale writes them), which its reader took for separators (an x, y, z export was 'damaged, 6
    columns'); or a matrix separated by commas or semicolons, which no reader of SurfaceTopography
    reads (its matrix reader: tabs and spaces only; a .csv goes to its reader of points). Each was
    'damaged' or held 'no channel of heights ... a spelling such as micron'."""
    from .text_table import decimal_commas, is_number  # here: text_table reads files through instrument_file

    for lineno, line in enumerate(head_text(fh).splitlines()[:-1], start=1):  # the last line may be cut short
        if not NUMBERS.match(line):
            continue
        cells = re.split(r"[\s;]+", line.strip())
        if len(cells) > 1 and any(COMMA_BETWEEN_DIGITS.search(cell) for cell in cells) and all(
                is_number(cell.replace(",", ".")) for cell in cells):
            raise ValueError(f"{where}: {decimal_commas(lineno, 'scan')}")
        numbers = re.split(r"[\s,;]+", line.strip())
        if reader.format() == "xyz" and len(numbers) > 3 or reader.format() == "asc" and re.search(r"[,;]", line):
            raise ValueError(  # a .csv goes to the reader of points; a .txt of numbers between commas to the matrix one
                f"{where}: line {lineno} holds {len(numbers)} numbers separated by {_separators(line)}, which "
                "SurfaceTopography does not read: its readers take x, y, z points (three a line, or x, z) or a matrix "
                "of heights between tabs or spaces (in a .txt); export x, y and the heights alone, or read a matrix's "
                "bare numbers with format: table and spacing"
            )
        return


def _separators(line: str) -> str:
    """What separates the numbers of ``line``, in words."""
    found = [name for mark, name in ((",", "commas"), (";", "semicolons"), ("\t", "tabs")) if mark in line]
    return " and ".join(found) or "spaces"
