"""Which of SurfaceTopography's readers opens an instrument file, chosen before any of them
parses it, and the checks made on the file's own declarations before its data is read.

SurfaceTopography's own detection tries its readers in turn until one accepts the file,
its text readers first: a 128 MiB binary NetCDF was parsed as CSV for minutes. Here a
reader is chosen once, from the file's first bytes (its magic number) and its suffix, and
only that reader opens the file: a binary file never reaches a text reader. A file whose
bytes and suffix name no format is refused at once. A ZIP container (X3P) has the sizes
of its members checked from its directory before anything is inflated: an XML member
above ``XML_LIMIT`` is refused (a 0.4 MiB file can inflate to gigabytes of blanks).
"""

from __future__ import annotations

import math
import os
import re
import zipfile

from .header_units import (
    NUMBERS, check_heights_are_lengths, check_units_named, head_text, named_units, stated_extent,
)

MAGIC_BYTES = 512  # what SurfaceTopography's own detection reads
XML_LIMIT = 64 * 2**20  # bytes an XML member of a ZIP container (X3P's main.xml) may inflate to
TEXT_FORMATS = ("xyz", "asc", "sdf")  # readers that parse text: never given a binary file
BINARY_VARIANTS = {"sdf": b"bISO-1.0"}  # the magic of a text format's binary variant, which its reader reads too
ZIP_MAGIC = b"PK\x03\x04"
EMPTY_ZIP_MAGIC = b"PK\x05\x06"
UTF8_BOM = b"\xef\xbb\xbf"
GSF_MAGIC = b"Gwyddion Simple Field"  # a Gwyddion export no reader of the extra reads
# the first bytes of formats whose reader states no magic (it answers 'maybe' to any file): a
# Nanoscope header's first section (binary data: \*; data as text: ?*), under .di, .spm or .000
HEADER_MAGIC = {"di": (b"\\*File list", b"\\*EC File list", b"?*File list", b"?*EC File list")}
# numpy, MATLAB and HDF5 files hold bare arrays, without axes: a map there is z[row, column] =
# z[y, x], as a .npy map and as numpy saves it (SurfaceTopography takes their first index as x)
BARE_ARRAY_FORMATS = ("npz", "mat", "h5")
AGAIN = "copy it again from the instrument, or export it from there again"  # the advice for a damaged file


def choose_reader(fh, path_suffix: str, where: str, *, text: bool | None = None):
    """The SurfaceTopography reader class for the open file ``fh`` (suffix without the dot,
    lower case): one the first bytes match (the suffix breaking ties), else one the suffix
    names whose magic does not rule the file out. ValueError naming ``where`` when none."""
    from SurfaceTopography.IO import MagicMatch, readers

    fh.seek(0)
    head = fh.read(MAGIC_BYTES)
    fh.seek(0)
    matches = [reader for reader in readers
               if reader.can_read(head) == MagicMatch.YES or head.startswith(HEADER_MAGIC.get(reader.format(), ()))]
    if not matches and (head.startswith(GSF_MAGIC) or path_suffix == "gsf"):  # under any suffix: not text, no reader
        raise ValueError(
            f"{where}: a Gwyddion Simple Field (.gsf) file, a format SurfaceTopography does not read (renaming it would "
            "not help): open it in Gwyddion and save it as .gwy, which is read with its units and pixel sizes"
        )
    by_suffix = [reader for reader in readers if path_suffix in getattr(reader, "_file_extensions", ())]
    chosen = next((r for r in matches if r in by_suffix), matches[0] if matches else None)
    if chosen is None:
        chosen = next((r for r in by_suffix if r.can_read(head) != MagicMatch.NO), None)
    if chosen is None and head.startswith(UTF8_BOM):  # a text format's magic behind a byte-order mark
        chosen = next((r for r in by_suffix if r.can_read(head[len(UTF8_BOM) :]) == MagicMatch.YES), None)
    if chosen is None and head.startswith(EMPTY_ZIP_MAGIC):  # a ZIP of no member is its directory's end alone
        raise ValueError(f"{where}: an empty ZIP archive: it holds no file{' (no array)' * (path_suffix == 'npz')}, so "
                         "no heights; save or export the scan again")  # fmt: skip
    if chosen is None and by_suffix:
        names = " or ".join(dict.fromkeys(reader.name() for reader in by_suffix))
        raise ValueError(f"{where}: its suffix .{path_suffix} names {names}, but its first bytes are not that "
                         "format's: a damaged file, or another format under that suffix; copy or export it again")
    if chosen is None:
        told = f"its suffix .{path_suffix}" if path_suffix else "its name (no suffix)"
        raise ValueError(
            f"{where}: neither {told} nor its first bytes name an instrument format SurfaceTopography reads; give "
            "it the suffix of its format (.x3p, .sur, .datx, .nc, .spm...); a table of bare numbers (a .tsv) is "
            "read with format: table and spacing"
        )
    if chosen.format() == "asc" and _coordinate_rows(fh):  # x, y, z per line under .txt: not a matrix of heights
        chosen = next(reader for reader in readers if reader.format() == "xyz")
    if parses_text(chosen, head) and _utf16(head):
        raise ValueError(
            f"{where}: a text export in UTF-16 (as a Windows program saves 'Unicode text'), whose header (units, "
            "sizes) frictionlab reads only in UTF-8: save it as UTF-8 (or plain ASCII)"
        )
    if parses_text(chosen, head) and not _looks_like_text(head):
        raise ValueError(
            f"{where}: a .{path_suffix} file that is not text (binary bytes at its start): not a "
            f"{chosen.name()} file; give a binary format its own suffix"
        )
    if parses_text(chosen, head) and head.startswith(UTF8_BOM):  # its readers fail on it, as on damage
        raise ValueError(
            f"{where}: a text export that starts with a UTF-8 byte-order mark (as a spreadsheet saves 'CSV UTF-8'), "
            f"which SurfaceTopography's {chosen.name()} reader does not read; save it without one (plain CSV or text)"
        )
    if head.startswith(ZIP_MAGIC):
        check_zip_members(fh, chosen, where)
    return chosen


def parses_text(reader, file) -> bool:
    """Whether ``reader`` parses ``file`` (the open file, its first bytes, or None: unknown) as
    text: a text format, unless the file starts with the magic of its binary variant (an SDF's)."""
    magic = BINARY_VARIANTS.get(reader.format())
    if reader.format() not in TEXT_FORMATS or magic is None or file is None:
        return reader.format() in TEXT_FORMATS
    if isinstance(file, bytes):
        return not file.startswith(magic)
    position = file.tell()
    file.seek(0)
    head = file.read(len(magic))
    file.seek(position)
    return head != magic


def _coordinate_rows(fh) -> bool:
    """Whether a text file's first row of numbers (whole within its ``head_text``) holds two or
    three: x, z or x, y, z per point, which SurfaceTopography's matrix reader, chosen by the
    suffix .txt, took for a map two or three pixels wide. Not under a header that states the
    map's width and height (Gwyddion's export of a matrix, however narrow: its XYZ reader refused
    it, and the file was called damaged)."""
    text = head_text(fh)
    if len(stated_extent(text)) == 2:
        return False
    for line in text.splitlines()[:-1]:  # the last line may be cut short
        if NUMBERS.match(line):
            return len(re.split(r"[\s,;]+", line.strip())) in (2, 3)
    return False


UTF16_MARKS = (b"\xff\xfe", b"\xfe\xff")  # UTF-16's byte-order marks, little and big endian


def _utf16(head: bytes) -> bool:
    """Text in UTF-16: its byte-order mark, or printable ASCII with a NUL beside every character."""
    sample = head[: len(head) // 2 * 2][:256]
    printable = set(range(32, 127)) | set(b"\t\n\r")
    ascii_pairs = any(sample[odd::2].count(0) == len(sample) // 2 and set(sample[1 - odd :: 2]) <= printable
                      for odd in (0, 1))  # fmt: skip
    return head.startswith(UTF16_MARKS) or len(sample) >= 8 and ascii_pairs


def _looks_like_text(head: bytes) -> bool:
    """No NUL and hardly any control byte: text in any 8-bit encoding (an export's header in
    Latin-1, its "\xb5m") is text; a binary header is not."""
    control = sum(1 for byte in head if byte < 32 and byte not in b"\t\n\r\f")
    return b"\0" not in head and control <= len(head) // 100


def check_zip_members(fh, reader, where: str) -> None:
    """Refuse a ZIP container (X3P...) whose directory declares an XML member larger than
    ``XML_LIMIT`` once inflated (a reader inflates it whole to parse it), or that is no ZIP
    at all: from the central directory, before anything is inflated. Python's zipfile
    stops inflating a member at the size its directory declares, so the check holds."""
    try:
        with zipfile.ZipFile(fh) as archive:
            members = archive.infolist()
    except (zipfile.BadZipFile, OSError, ValueError, EOFError):
        raise ValueError(f"{where}: a damaged {reader.name()} file (its ZIP directory cannot be read); "
                         "the file may be truncated: copy it again from the instrument") from None  # fmt: skip
    finally:
        fh.seek(0)
    for member in members:
        if member.filename.lower().endswith(".xml") and member.file_size > XML_LIMIT:
            raise ValueError(
                f"{where}: its XML member {member.filename!r} would inflate to {member.file_size / 2**20:.0f} MiB, "
                f"more than the {XML_LIMIT // 2**20} MiB an instrument file's description may take; refused unread "
                "(a damaged or forged file)"
            )


X3P_ITEM_BYTES = {"I": 2, "L": 4, "F": 4, "D": 8}  # ISO 5436-2 data types: int16, int32, float32, float64


def header_units(fh, reader) -> list[str]:
    """The length units the header of a text export names (``x [\u00b5m]``, ``z (nm)``, ``z/nm``),
    in order, from the lines before its first row of numbers; empty for a binary format."""
    if not parses_text(reader, fh):
        return []
    return named_units(head_text(fh))[0]


def check_text_heights(fh, reader, where: str) -> None:
    """Refuse a text export whose header labels a column in a unit that is no length
    (``header_units.check_heights_are_lengths``): its reader skips the header."""
    if parses_text(reader, fh):
        check_heights_are_lengths(head_text(fh), where)


def check_header_units(fh, reader, file_unit: str | None, unit: str | None, where: str) -> str | None:
    """The length unit the header of a text export names (``x [\u00b5m]``, ``z [nm]``) where its
    reader gives none: the scan's unit where the preset gives none. Refuse units that differ, or
    differ from the preset's ``unit``: the heights and the pixel would be taken as bare numbers
    in that unit, the slopes off by their ratio."""
    if file_unit is not None:
        return None
    units = header_units(fh, reader)
    check_units_named(units, unit, where, f"which SurfaceTopography's {reader.name()} reader does not read")
    return units[0] if units else None


def check_channel_of_heights(reader, channel, where: str) -> None:
    """Refuse a channel whose values are no lengths, in any reader: one that lists the channels
    of currents, voltages and phases beside the heights (IBW, MI) gives each a kind, and a
    channel's values in A, V or deg were read as heights of 1 m per unit when it was picked
    (``channel:``) or was the file's default. A Gwyddion channel in A is the ampere
    (``_gwyddion_amperes``), which its reader takes for the angstrom."""
    found = _not_heights(reader, channel)
    if found is None:
        return
    kind, data_unit = found
    if data_unit == "A" and _gwyddion_amperes(reader, channel):
        what = "values in A, Gwyddion's symbol of the ampere (a current, not heights; Gwyddion stores an angstrom as m)"
    else:
        said = f"values in {quoted(data_unit)}" if data_unit else "values without a unit"
        what = f"{'' if kind in ('height', 'other') else kind + ' '}{said}, not heights"
    lengths = [c for c in reader.channels if _not_heights(reader, c) is None]
    named = [c for c in lengths if not names_a_signal(c)] or lengths  # an amplitude in m is no height either
    heights = [f"{int(c.index)}: {quoted(c.name)}" for c in named]
    choose = f"choose a channel of heights with channel ({', '.join(heights)})" if heights else "the file holds no channel of heights"
    raise ValueError(f"{where}: channel {channel.index} ({quoted(channel.name)}) holds {what}: {choose}, or export "
                     "the height channel alone")  # fmt: skip


SIGNAL_WORDS = ("amplitude", "deflection", "error", "phase", "friction", "lateral", "adhesion", "dissipation")
HEIGHT_WORDS = ("height", "topograph", "z sensor")


def says(channel, words) -> bool:
    """Whether the channel's name holds one of ``words``."""
    return any(word in str(channel.name).casefold() for word in words)


def names_a_signal(channel) -> bool:
    """Whether the channel's name is an AFM's signal other than heights (an amplitude or a
    deflection error, in m like heights), and not also the heights'."""
    return says(channel, SIGNAL_WORDS) and not says(channel, HEIGHT_WORDS)


def _not_heights(reader, channel) -> tuple[str, str | None] | None:
    """The kind and unit of ``channel``'s values where they are no heights, else None."""
    kind = getattr(getattr(channel, "data_kind", None), "value", "height")  # a reader older than data_kind: heights
    amperes = _gwyddion_amperes(reader, channel)
    data_unit = "A" if amperes else _said_unit(channel)
    if kind == "height" and not amperes and (data_unit in (None, channel.unit) or _is_length(data_unit)):
        return None  # the lateral unit, checked where the sizes are converted (length_factor)
    return kind, data_unit


def _said_unit(channel) -> str | None:
    """The unit of a channel's values as its reader says it (None where it cannot say)."""
    try:
        unit = channel.data_unit
    except Exception:  # noqa: BLE001 - a reader that cannot say: its reading stands
        return None
    return unit if isinstance(unit, str) and unit else None


def _is_length(unit: str) -> bool:
    """Whether SurfaceTopography reads ``unit`` as a length (its spellings: 'MicroMeters', 'um')."""
    from SurfaceTopography.Support.UnitConversion import is_length_unit, mangle_length_unit_utf8  # the extra's

    return is_length_unit(mangle_length_unit_utf8(unit))


def _gwyddion_entry(reader, channel, part: str) -> dict:
    """The raw entry ``/<index>/<part>`` (``data``, ``mask``) of ``channel`` of a Gwyddion file; {}
    where there is none, for another format, or a file this does not follow (its reader's reading
    then stands)."""
    if reader.format() != "gwy":
        return {}
    try:
        entry = channel.info["raw_metadata"].get(f"/{channel.tags['index']}/{part}")
    except (AttributeError, KeyError, TypeError):
        return {}
    return entry if isinstance(entry, dict) else {}


def _gwyddion_field(reader, channel) -> dict:
    """The raw data field of ``channel`` of a Gwyddion file ({}: ``_gwyddion_entry``)."""
    field = _gwyddion_entry(reader, channel, "data").get("GwyDataField")
    return field if isinstance(field, dict) else {}


def gwyddion_masked(reader, channel) -> bool:
    """Whether ``channel`` of a Gwyddion file has a mask (its undefined points then include those
    under it; without one, they are the file's NaN heights)."""
    return bool(_gwyddion_entry(reader, channel, "mask"))


def _gwyddion_amperes(reader, channel) -> bool:
    """Whether ``channel`` of a Gwyddion file holds values in A (``check_channel_of_heights``)."""
    try:
        return _gwyddion_field(reader, channel)["si_unit_z"]["GwySIUnit"]["unitstr"] == "A"
    except (KeyError, TypeError):
        return False


def check_stated_sides(reader, channel, where: str) -> None:
    """Refuse a Gwyddion map whose width (xreal) or height (yreal) is 0 along a side of more than
    one pixel: Gwyddion, and its reader here, take a size of 0 as 1 m, so a 32 um wide map of 0
    height was read with pixels 31000 times longer along y, and resampled onto a million rows.
    Called only where the preset gives no spacing (its pixel is then used instead)."""
    field = _gwyddion_field(reader, channel)
    zero = [f"{side} ({key})" for side, key, points in (("width", "xreal", "xres"), ("height", "yreal", "yres"))
            if field.get(key) == 0 and field.get(points, 2) != 1]  # fmt: skip
    if zero:
        raise ValueError(f"{where}: channel {channel.index} ({quoted(channel.name)}) states a {' and a '.join(zero)} "
                         "of 0, which Gwyddion shows as 1 m: its pixels have no size; give the pixel side with "
                         "spacing (and spacing_y for pixels that are not square), or set the size in Gwyddion "
                         "and save the file again")  # fmt: skip


def check_payload(fh, reader, where: str, *, checksum: bool = True) -> None:
    """Refuse an X3P whose binary heights are not the size its main.xml declares (points times
    the bytes of its data type), or not the bytes its MD5 checksum declares: SurfaceTopography's
    reader checks neither, so a payload longer than declared, of another type (doubles declared
    as floats: heights of 1e37), or damaged in copying, was read without a word. Other formats,
    an X3P with its heights in the XML, or one whose description this cannot follow, are left to
    the reader. The size first, with ``checksum`` false (cheap: a forged header's 10^9 points are
    damage, not a map too large to read); the checksum after ``check_declared_points``, so a map
    declared too large, and so stored, is refused as such before its heights are hashed."""
    import hashlib
    import xml.etree.ElementTree as ElementTree

    if reader.format() != "x3p":
        return
    found = None
    try:
        with zipfile.ZipFile(fh) as archive:
            root = ElementTree.fromstring(archive.read("main.xml"))  # at most XML_LIMIT (check_zip_members)
            kind = root.findtext("Record1/Axes/CZ/DataType", "").strip()
            points = math.prod(int(root.findtext(f"Record3/MatrixDimension/Size{axis}", "")) for axis in "XYZ")
            link = root.findtext("Record3/DataLink/PointDataLink", "").strip()
            stored = archive.getinfo(link).file_size
            declared_sum = root.findtext("Record3/DataLink/MD5ChecksumPointData", "").strip().lower()
            sized = kind not in X3P_ITEM_BYTES or stored == points * X3P_ITEM_BYTES[kind]
            if sized and checksum and re.fullmatch(r"[0-9a-f]{32}", declared_sum):
                digest = hashlib.md5(usedforsecurity=False)
                with archive.open(link) as member:  # in blocks: no second copy of the heights
                    for block in iter(lambda: member.read(1 << 20), b""):
                        digest.update(block)
                found = digest.hexdigest()
    except (KeyError, ValueError, OSError, EOFError, zipfile.BadZipFile, ElementTree.ParseError):
        return
    finally:
        fh.seek(0)
    if not sized:
        declared = points * X3P_ITEM_BYTES[kind]
        raise ValueError(
            f"{where}: a damaged {reader.name()} file: its binary heights take {stored} bytes, and its description "
            f"declares {points} points of data type {kind} ({X3P_ITEM_BYTES[kind]} bytes each: {declared} bytes); "
            + AGAIN
        )
    if found is not None and found != declared_sum:
        raise ValueError(
            f"{where}: a damaged {reader.name()} file: its binary heights' MD5 checksum is {found}, and its "
            f"description declares {declared_sum}; {AGAIN}"
        )


def check_declared_bytes(points: tuple[int, ...], where: str, fh, reader=None) -> None:
    """Refuse a header that declares more points than the open file ``fh``'s bytes could hold
    even compressed (a forged or truncated file: damage, not a map too large to read, which the
    memory estimate said), named as of ``reader``'s format when known."""
    size = os.fstat(fh.fileno()).st_size
    if math.prod(points) > size * MOST_POINTS_A_BYTE:
        shape = " x ".join(map(str, points))
        raise ValueError(
            f"{where}: a damaged or truncated {'' if reader is None else reader.name() + ' '}file: its header declares "
            f"{shape} points (x by y), and the file has {size:,} bytes, too few to hold them even compressed (at most "
            f"{MOST_POINTS_A_BYTE} points a byte); {AGAIN}"
        )


HEIGHT_COPIES = 4  # float64 arrays of the map alive at once while it is read: the reader's, ours, levelled, resampled


def room_to_read() -> tuple[int, str]:
    """Bytes this process may still allocate, and what sets that: the memory the system has
    available, or the room left under the process's address-space limit (``ulimit -v``)."""
    return min((room, source) for room, source, _ in memory_rooms())


def memory_rooms() -> list[tuple[int, str, bool]]:
    """Each limit on what this process may still allocate: (bytes, what sets it, whether it
    limits the address space, ``ulimit -v``, rather than the memory in use)."""
    import psutil

    found = [(int(psutil.virtual_memory().available), "the memory the system has available", False)]
    try:
        import resource
    except ImportError:  # not on Windows
        return found
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft != resource.RLIM_INFINITY:
        found.append((soft - psutil.Process().memory_info().vms, "the room left under this process's limit ulimit -v", True))
    return found


def check_fill_room(where: str, shape: tuple[int, ...], holes: int) -> None:
    """Refuse, before it starts, a harmonic fill (``undefined: harmonic``) of ``holes`` points not
    measured in a scan of ``shape`` that cannot fit in the memory left: its sparse solve took the
    memory mid-read, and ended in MemoryError, or the process killed."""
    from .scan_shaping.filling import harmonic_fill_bytes

    for room, source, address_space in memory_rooms():  # what it keeps resident, or the address space it reserves
        need = harmonic_fill_bytes(shape, holes, reserved=address_space)
        if need <= room:
            continue
        raise ValueError(
            f"{where}: filling its {holes:,} points not measured (undefined: harmonic) takes about {need / 2**30:.3g} "
            f"GiB, more than the {room / 2**30:.3g} GiB this process may use ({source}); leave them out with region "
            "(the measured part of the scan), or fill fewer: fix the scan, or export it with its holes filled"
        )


MOST_POINTS_A_BYTE = 1032  # deflate's greatest ratio: a point of one byte, compressed, takes at least 1/1032 byte


def check_declared_points(points: tuple[int, ...], where: str, fh=None, reader=None) -> None:
    """Refuse, from the header alone, a file that declares more points than this process can
    read (a forged NetCDF of 100000^2, an X3P of 22000^2), naming the limit; or a side of fewer
    than 1 point (a Gwyddion reader took -40 for 40 and read the map as if it were sound); or,
    first, more points than the open file ``fh``'s bytes hold (``check_declared_bytes``)."""
    shape = " x ".join(map(str, points))
    if min(points, default=1) < 1:
        raise ValueError(f"{where}: the file declares {shape} points (x by y), a side of fewer than 1: a damaged "
                         f"header; {AGAIN}")  # fmt: skip
    if fh is not None:
        check_declared_bytes(points, where, fh, reader)
    need = math.prod(points) * 8 * HEIGHT_COPIES
    room, source = room_to_read()
    if need > room:
        raise ValueError(
            f"{where}: the file declares {shape} points (x by y); reading them takes about {need / 2**30:.3g} GiB, "
            f"more than the {room / 2**30:.3g} GiB this process may use ({source}); crop the scan with the "
            "instrument's software, or export a region of it"
        )


TEXT_READER_COPIES = 2  # SurfaceTopography's text readers hold 1.2 (x, y, z rows) to 1.9 (a matrix) times the file's bytes


def check_text_room(fh, reader, where: str) -> None:
    """Refuse, before SurfaceTopography's reader parses it whole, a text export whose reading
    cannot fit in the memory left (it has no header that gives its points), naming the limit."""
    size = os.fstat(fh.fileno()).st_size
    need, (room, source) = size * TEXT_READER_COPIES, room_to_read()
    if need > room:
        raise ValueError(
            f"{where}: a text export ({reader.name()}) of {size:,} bytes; SurfaceTopography's reader takes about "
            f"{need / 2**30:.3g} GiB to read it, more than the {room / 2**30:.3g} GiB this process may use ({source}); "
            "crop the scan with the instrument's software, or save its heights as a .npy array"
        )


def xy_order(reader, values: tuple) -> tuple:
    """``values`` given per axis in SurfaceTopography's order (points, pixel sides) in x, y order:
    reversed for a bare array (``BARE_ARRAY_FORMATS``), whose first index is y."""
    values = tuple(values)
    return values[::-1] if len(values) == 2 and reader.format() in BARE_ARRAY_FORMATS else values


def channel_list(reader) -> list[dict]:
    """Every channel of an open reader: index, name, dimension, points (x, y), units; JSON-ready."""
    listed = []
    for channel in reader.channels:
        try:
            data_unit = channel.data_unit
        except Exception:  # noqa: BLE001 - a reader that cannot say: nothing to list
            data_unit = None
        data_unit = "A" if _gwyddion_amperes(type(reader), channel) else data_unit  # not m, as its reader says
        listed.append({
            "index": int(channel.index), "name": str(channel.name),
            "points": [int(n) for n in xy_order(reader, channel.nb_grid_pts)] if channel.nb_grid_pts is not None else None,
            "unit": channel.unit if isinstance(channel.unit, str) else None,
            "data_unit": data_unit if isinstance(data_unit, str) else None,
        })  # fmt: skip
    return listed


NAME_SHOWN = 60  # characters of a file's text (a channel's name, a unit) a message quotes: it may be of any length


def quoted(name) -> str:
    """A channel's name (or any text from a file) as a message quotes it, its middle cut past
    NAME_SHOWN characters."""
    text = str(name)
    half = NAME_SHOWN // 2
    return repr(text) if len(text) <= NAME_SHOWN else f"{text[:half]!r}...{text[-half:]!r}"
