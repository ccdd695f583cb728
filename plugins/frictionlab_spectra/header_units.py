"""The length units a text file's header names, before its first row of numbers: in a column's
label (``x [µm]``, ``z (nm)``, ``z/nm``, ``z_nm``, ``z in nm``, ``z: nm``) or as a stated value (Gwyddion's ``# Width: 25.6 µm``,
``# Value units: m``). A table's numbers are read bare, so what its header says of their units
is checked against the preset, and is their unit where the preset gives none
(``check_table_header``); a text export read by SurfaceTopography
is checked the same way where its reader skips the header (``instrument_reader``). A column
labelled in a unit that is no length (``z [V]``, ``phase [deg]``; a bare ``A`` is the ampere)
holds no heights, and is refused (``check_heights_are_lengths``)."""

from __future__ import annotations

import re

from .file_kinds import LENGTH_UNITS

HEADER_BYTES = 4096  # of a text file read for the units its header names
HEADER_MOST = 1 << 20  # read while its header has not ended: a header longer than this is not a table's
LENGTH_UNIT = {"pm": "pm", "nm": "nm", "um": "um", "\u00b5m": "um", "\u03bcm": "um", "micron": "um", "microns": "um",
               "mm": "mm", "cm": "cm", "dm": "dm", "km": "km", "m": "m", "\u00c5": "\u00c5", "\u212b": "\u00c5",
               "angstrom": "\u00c5", "angstroms": "\u00c5"}  # fmt: skip
# inch- and foot-based lengths, as US instruments export them: named by a header, never converted, so refused
IMPERIAL = r"inch(?:es)?|in|mils?|thou|[u\u00b5\u03bc]in|micro-?inch(?:es)?|ft|feet|foot|yd|yards?"
# spelled out, in any case ("Micrometer", "nanometres", "Microns"): unambiguous, as an abbreviation in capitals is not
_WORDS = {"pico": "pm", "nano": "nm", "micro": "um", "milli": "mm", "centi": "cm", "deci": "dm", "kilo": "km", "": "m"}
_WORD = r"(?i:(?:pico|nano|micro|milli|centi|deci|kilo)?met(?:er|re)s?|microns?|angstroms?)"
_UNITS = rf"pm|nm|um|\u00b5m|\u03bcm|mm|cm|dm|km|m|\u00c5|\u212b|{_WORD}"
# units of what is no length, as instruments label a channel's column: volts, amperes (a bare "A" is
# an ampere here, as in SI: an angstrom is written \u00c5), angles, frequencies, forces, pressures, counts
NOT_LENGTH = (r"[fpn\u00b5\u03bcumkM]?V|[fpn\u00b5\u03bcum]?A|deg|\u00b0|m?rad|[kMG]?Hz|[pn\u00b5\u03bcum]?N|[kMG]?Pa|"
              r"a\.\s?u\.?|arb\.?(?:\s?units?)?|counts?|cps|%|dB")  # no second: "height(s)"
# "z [V]", "height (nA)", "phase/deg": in brackets, or after a slash at a cell's end (not "S/N ratio")
_NOT_LENGTH_LABEL = re.compile(rf"[\[(]\s*(?:{NOT_LENGTH})\s*[\])]|/\s*(?:{NOT_LENGTH})\s*(?=[,;\t]|$)")
_LABEL = re.compile(  # x [µm], z (nm), z/nm; an inch only in brackets or after a slash ("z (in nm)" names nm)
    rf"[\[(/]\s*({_UNITS})\s*(?=[\])\s,;]|$)|[\[(]\s*({IMPERIAL})\s*[\])]|/\s*({IMPERIAL})\s*(?=[,;\t]|$)"
)
# x_um, "X, um", x in um, x {um}, x:um ("# x: um, z: nm" above the labels): a unit after an underscore, a comma
# inside quotes, "in", a brace or a colon, ending its label (not "time_ms", "# Cutoff: 0.8 mm")
_LOOSE_LABEL = re.compile(rf"(?:(?<=\w)_|\bin\s+|\{{\s*|(?<=\w):\s*|,\s*(?=[^\",]*\"))({_UNITS})(?=[\s,;\"'}})\]]|$)")
# a number a header states, its decimal mark a point or a comma (Gwyddion's export in a European locale: 25,6 µm)
_NUMBER = r"[-+]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][-+]?\d+)?"
# Gwyddion's words for its text export's width and height, in the languages it writes (as its reader reads them)
_WIDTH = "width|\u0161\u00ed\u0159ka|breite|anchura|largeur|larghezza|largura|\u0448\u0438\u0440\u0438\u043d\u0430"
_HEIGHT = "height|v\u00fd\u0161ka|h\u00f6he|altura|hauteur|altezza|\u0432\u044b\u0441\u043e\u0442\u0430"
_SIZE_KEYS = rf"{_WIDTH}|{_HEIGHT}|x-length|y-length|pixel\s+size|scale\s+[xy]"  # what text exports state sizes by
_UNIT_KEYS = r"value\s+units|[xyz]-unit|unit\s+(?:x|y|data)"
# "# Width: 25.6 µm", "# Value units: m": a length a header states by one of those keys (not "# Cutoff: 0.8 mm")
_STATED = re.compile(rf"\b(?i:{_SIZE_KEYS}|{_UNIT_KEYS})\s*[:=]\s*(?:{_NUMBER})?\s*(?P<unit>{_UNITS})\s*$")  # keys in any case
# "# Value units: nm", "z-unit = nm": the unit a text export states for its values, the heights
_STATED_VALUES = re.compile(rf"\b(?i:value\s+units|z-unit|unit\s+data)\s*[:=]\s*(?P<unit>{_UNITS})\s*$")
# "# Value units: V": a unit key of an instrument's text export (Gwyddion's) stating one that is no length
_STATED_NOT_LENGTH = re.compile(rf"\b(?i:{_UNIT_KEYS})\s*[:=]\s*(?P<unit>{NOT_LENGTH})\s*$")


def length_unit(name: str) -> str:
    """The unit a header's ``name`` of a length unit (``_UNITS``) is, as LENGTH_UNIT spells it."""
    if name in LENGTH_UNIT or not re.fullmatch(_WORD, name):
        return LENGTH_UNIT.get(name, name)
    word = name.lower()
    return LENGTH_UNIT[word] if word.startswith(("micron", "angstrom")) else _WORDS[word.removesuffix("s")[:-5]]


NUMBERS = re.compile(r"[\s,;]*[-+]?(\d|\.\d)")  # a line that starts with a number: the header has ended


def head_text(fh, encoding: str = "utf-8") -> str:
    """The start of the open file ``fh`` as text (bytes that are not ``encoding`` replaced), the
    file left at its start for a reader: its header, and its first rows. HEADER_BYTES, or more
    while no whole line of numbers has ended the header (a header of 100 comment lines hid its
    ``Value units: nm`` past 4 kB, and the numbers were taken in the preset's unit), up to HEADER_MOST."""
    fh.seek(0)
    head = fh.read(HEADER_BYTES)
    while len(head) < HEADER_MOST and not _numbers_begun(head.decode(encoding, errors="replace")):
        more = fh.read(len(head))  # twice as much each time
        if not more:
            break
        head += more
    fh.seek(0)
    return head.decode(encoding, errors="replace")


def _numbers_begun(text: str) -> bool:
    """Whether a whole line of ``text`` starts with a number: its header has ended."""
    return any(NUMBERS.match(line) for line in text.splitlines()[:-1])


def header_lines(text: str) -> list[str]:
    """The lines of the header of ``text``: those before the first that starts with a number
    (the last line of ``text`` left out: it may be cut short)."""
    lines = text.splitlines()[:-1]
    return lines[: next((i for i, line in enumerate(lines) if NUMBERS.match(line)), len(lines))]


def values_units(text: str) -> list[str]:
    """The length units the header of ``text`` states for its values (``Value units: nm``,
    ``z-unit = nm``), not its sizes (``Width: 25.6 µm``): a text export's heights."""
    stated = (_STATED_VALUES.search(line.rstrip()) for line in header_lines(text))
    return [length_unit(found["unit"]) for found in stated if found]


def named_units(text: str) -> tuple[list[str], bool]:
    """The length units the header of ``text`` (its lines before the first that starts with a
    number) names, in order, and whether it states one by a key of an instrument's text export
    (``Width: 25.6 µm``, ``Value units: m``, ``z-unit = nm``): SurfaceTopography's reader reads them."""
    units, stated_by_key = [], False
    for line in header_lines(text):
        units += [length_unit(unit) for found in _LABEL.findall(line) for unit in found if unit]
        if stated := _STATED.search(line.rstrip()):
            units.append(length_unit(stated["unit"]))
            stated_by_key = True
        else:
            units += [length_unit(unit) for unit in _LOOSE_LABEL.findall(line)]
    return units, stated_by_key


_EXTENT = re.compile(rf"\b(?i:(?P<width>{_WIDTH})|{_HEIGHT})\s*[:=]\s*(?P<value>{_NUMBER})\s*(?P<unit>{_UNITS})\s*$")


def stated_pixel(path, where: str, shape: tuple[int, int]) -> tuple[float, float] | None:
    """The pixel (dx, dy) in metres of a map of ``shape`` (Ny, Nx) whose header states the scan's
    width and height (Gwyddion's text export: ``# Width: 32.000 µm``, ``# Height: 8.000 µm``; ``32,000 µm``
    in a locale whose decimal mark is a comma), or
    None unless it states both in length units: a table's reader takes its pixel from the preset."""
    from .instrument_file import open_input  # here: it imports this module

    with open_input(path, where) as fh:
        extent = stated_extent(head_text(fh, "utf-8-sig"))
    if len(extent) < 2 or not all(side > 0 for side in extent.values()):
        return None
    return extent["width"] / shape[1], extent["height"] / shape[0]


def stated_extent(text: str) -> dict[str, float]:
    """The width and height (in metres, by key) the header of ``text`` states in length units, as
    Gwyddion's text export of a matrix does; a file of x, y, z points states neither."""
    extent = {}
    for line in header_lines(text):
        if (found := _EXTENT.search(line.rstrip())) and length_unit(found["unit"]) in LENGTH_UNITS:
            value = float(found["value"].replace(",", "."))  # 25,6: a decimal comma (no export groups thousands)
            extent.setdefault("width" if found["width"] else "height", value * LENGTH_UNITS[length_unit(found["unit"])])
    return extent


def not_length_label(text: str) -> tuple[str, str] | None:
    """The column label of the header of ``text`` whose unit is no length (``z [V]``,
    ``height (nA)``, ``phase/deg``: on its last line, over the numbers, not in metadata such as
    ``# Setpoint (%): 50``; ``Value units: V`` on any), and that unit; None when there is none."""
    labels = ""
    for line in header_lines(text):
        if stated := _STATED_NOT_LENGTH.search(line.rstrip()):
            return line[stated.start() :].strip(), stated["unit"]
        labels = line if line.strip() else labels
    if found := _NOT_LENGTH_LABEL.search(labels):
        start = max(labels.rfind(mark, 0, found.start()) for mark in ",;\t#])") + 1  # the label's cell
        return labels[start : found.end()].strip(), found.group().strip("[]()/ \t")
    return None


_BRACKETED = re.compile(r"\[\s*([^\[\]\s,;]*[^\W\d_][^\[\]\s,;]*)\s*\]")  # "x [furlong]": a word in brackets


def unknown_unit_label(text: str) -> tuple[str, str] | None:
    """The column label over the numbers of ``text`` (its header's last line) that names in square
    brackets a unit that is neither a length unit nor one of what is no length (``x [furlong]``,
    ``t [s]``), and that unit; None when there is none."""
    labels = next((line for line in reversed(header_lines(text)) if line.strip()), "")
    known = re.compile(rf"{_UNITS}|{IMPERIAL}|{NOT_LENGTH}")
    for found in _BRACKETED.finditer(labels):
        if not known.fullmatch(found[1]):
            start = max(labels.rfind(mark, 0, found.start()) for mark in ",;\t#])") + 1  # the label's cell
            return labels[start : found.end()].strip(), found[1]
    return None


def check_heights_are_lengths(text: str, where: str) -> None:
    """Refuse a file whose header labels a column in a unit that is no length (an AFM's channel
    in volts, amperes, degrees, hertz): its numbers are not heights, and were read as heights in
    the preset's unit without a word."""
    from .instrument_reader import quoted

    if (found := not_length_label(text)) is None:
        return
    label, unit = found
    ampere = " (A is the ampere; an angstrom is written \u00c5)" if unit == "A" else ""
    raise ValueError(
        f"{where}: its header's {quoted(label)} says numbers in {unit}{ampere}, which is not a length unit "
        f"(allowed: {', '.join(LENGTH_UNITS)}): they are not heights; export the height channel alone, with "
        "its length unit (an instrument file's other channels are picked with channel)"
    )


def check_table_header(path, where: str, unit: str | None, format: str) -> str | None:
    """The length unit the header of a table (read as bare numbers) names for them, None if it
    names none: the table's unit where the preset gives none. Refuse a header that says its
    numbers are not what the preset takes them for: a header of an instrument's text export that
    states its size or units (read with ``format: auto``), columns in different length units, or
    one unit other than the preset's ``unit``."""
    from .instrument_file import open_input  # here: it imports this module

    with open_input(path, where) as fh:
        head = head_text(fh, "utf-8-sig")
    if (undecoded := next((i for i, line in enumerate(header_lines(head), 1) if "\ufffd" in line), None)) is not None:
        from .text_table import not_utf8  # here: it reads files through instrument_file, which imports this module

        raise ValueError(not_utf8(where, undecoded))  # a Latin-1 'z [µm]' was 'no unit frictionlab knows'
    check_heights_are_lengths(head, where)
    if (unknown := unknown_unit_label(head)) is not None:  # read bare, in the preset's unit, without a word
        from .instrument_reader import quoted

        raise ValueError(
            f"{where}: its header's {quoted(unknown[0])} names the unit {quoted(unknown[1])}, which is no unit "
            f"frictionlab knows (length units: {', '.join(LENGTH_UNITS)}): its numbers would be taken bare, the "
            "slopes off by an unknown ratio; convert the column to a length unit and label it so"
        )
    units, export = named_units(head)
    if export and format == "auto":
        raise ValueError(
            f"{where}: its header states the scan's units ({', '.join(dict.fromkeys(units))}), as an "
            "instrument's text export (Gwyddion's, say) does, and a table's numbers are read bare, without them: "
            "read it with format: instrument, which takes the units and the pixel size from the header (or with "
            "format: table and spacing, for its bare numbers in the unit it states for its values)"
        )
    if export:  # with format: table, an instrument's export asked for its bare numbers: its values' unit is theirs
        units = values_units(head)
    check_units_named(units, unit, where, "which a table's reader does not read")
    return units[0] if units else None


def check_units_named(units: list[str], unit: str | None, where: str, ignored: str) -> None:
    """Refuse a file whose header names ``units`` (``named_units``) that its reader ignores
    (``ignored`` says which reader): different length units, or one other than the preset's ``unit``;
    its numbers would be taken bare, in the preset's unit."""

    if imperial := [u for u in units if re.fullmatch(IMPERIAL, u)]:
        taken = f"in the preset's unit, {unit}" if unit else "bare"
        raise ValueError(
            f"{where}: its header names the length unit {imperial[0]!r}, {ignored} and frictionlab does not "
            f"convert: its numbers would be taken {taken}, the slopes or heights off by the units' ratio; convert "
            f"the columns to one of {', '.join(LENGTH_UNITS)}"
        )
    if len(set(units)) > 1:
        raise ValueError(
            f"{where}: its header names the length units {', '.join(dict.fromkeys(units))}, {ignored}: its numbers "
            "are taken bare, all in one unit, the slopes off by their ratio; convert the columns to one length unit"
        )
    if units and unit is not None and units[0] != unit:
        to = f"set unit: {units[0]}, or convert" if units[0] in LENGTH_UNITS else "convert"
        raise ValueError(
            f"{where}: its header names the length unit {units[0]}, {ignored}: its numbers are taken to be in the "
            f"preset's unit, {unit}; {to} the numbers to {unit}"
        )
