"""What to tell of a file the chosen reader of SurfaceTopography could not read: a damaged
file of its format, or (in the reader's own words, matched here) a valid file it does not
read: a revision or a kind of its format, units that differ or are no lengths, a text export
in another encoding. The reader's own words are shown on one line, cut short."""

from __future__ import annotations

import os
import re

import numpy as np

from .instrument_reader import AGAIN, parses_text, quoted


def _is_utf8(fh) -> bool:
    """Whether the open file's bytes, all of them, read as UTF-8 (a chunk at a time)."""
    import codecs

    decoder, position = codecs.getincrementaldecoder("utf-8")(), fh.tell()
    try:
        fh.seek(0)
        while chunk := fh.read(1 << 20):
            decoder.decode(chunk)
        decoder.decode(b"", final=True)
        return True
    except (UnicodeDecodeError, OSError):
        return False
    finally:
        fh.seek(position)


def describe_failure(reader, exc: BaseException, where: str, fh=None) -> ValueError:
    """What to tell of a file the chosen reader could not read: a damaged file of that
    format, or its length and height units that differ (named as such). ``fh``, the open
    file, tells a text export's encoding from its content where the reader blames the one."""
    from SurfaceTopography.Exceptions import CorruptFile, FileFormatMismatch

    name = reader.name()
    text = str(exc)
    if isinstance(exc, ValueError) and (unit := re.match(r"Unit '([^']*)' is of kind (\w+) while unit '[^']*' is of "
                                                         r"kind length", text)):  # SurfaceTopography's own words
        return ValueError(f"{where}: the file's heights are in {quoted(unit[1])}, a {unit[2]}, not a length: it holds no "
                          "heights; export the height channel (topography) with its length unit")  # fmt: skip
    if isinstance(exc, ValueError | CorruptFile) and re.search(r"Units for x- and y-coordinate|x and y units differ", text):
        return ValueError(f"{where}: the file's sizes along x and along y are in different length units, and "
                          f"SurfaceTopography reads a {name} file with one unit for both; convert them to one")  # fmt: skip
    if isinstance(exc, ValueError) and "Units for" in text and "differ" in text:
        return ValueError(
            f"{where}: the file's heights and its lateral sizes are in different units, and SurfaceTopography "
            f"reads a {name} file with one unit for both; convert its heights to the unit of its sizes (values in a "
            "unit that is no length, volts or degrees, are no heights: export the height channel)"
        )
    if isinstance(exc, ValueError) and "physical_sizes" in text:  # SurfaceTopography's own words: not damage
        return ValueError(
            f"{where}: the {name} file does not state its physical size; give spacing (the pixel side, in the "
            "run's length unit), or export the scan with its pixel size"
        )
    if isinstance(exc, UnicodeError) and parses_text(reader, fh) and fh is not None and _is_utf8(fh):
        return ValueError(f"{where}: this {name} file holds no points its reader can read (it is UTF-8 text: a "
                          "header alone, or lines that are not numbers); export the scan again")  # fmt: skip
    if isinstance(exc, UnicodeError) and parses_text(reader, fh):
        return ValueError(f"{where}: a text export that is not UTF-8 (a header in Latin-1: its µ?), which "
                          f"SurfaceTopography's {name} reader does not read; save it as UTF-8")  # fmt: skip
    if isinstance(exc, MemoryError):
        what = "ran out of memory reading this text export" if parses_text(reader, fh) else \
            "the file declares more points than this process can hold"
        return ValueError(f"{where}: {what} ({name}); crop it with the instrument's software")
    if isinstance(exc, CorruptFile) and (variant := re.fullmatch(r"(Revision|FeatureType) should be '([^']*)'\.", text)):
        return _unread_variant(name, *variant.groups(), where)  # SurfaceTopography's own words: a valid file
    if isinstance(exc, CorruptFile) and (axis := re.match(r"C([XY]) AxisType is not 'I'", text)):  # its own words
        return ValueError(f"{where}: this {name} file gives its {axis[1].lower()} positions point by point (AxisType A), "
                          "not on a regular grid (AxisType I), which is all SurfaceTopography reads (not damage): export "
                          "the scan on the instrument's grid, or its heights as a table with spacing")  # fmt: skip
    if isinstance(exc, CorruptFile) and (unknown := re.fullmatch(r"Unknown lateral unit '(.*)'\.", text)) and \
            re.match(r",\d", unknown[1]):  # 16,000 µm: the reader split the size at its decimal comma
        return ValueError(f"{where}: its header writes a size with a decimal comma (as 16,000 µm: its reader took "
                          f"{quoted(unknown[1])} for the unit); export it with decimal points")  # fmt: skip
    if isinstance(exc, CorruptFile) and (unknown := re.fullmatch(r"Unknown lateral unit '(.*)'\.", text)):
        return ValueError(f"{where}: its header names the lateral unit {quoted(unknown[1])}, which SurfaceTopography's "
                          f"{name} reader does not know (not damage); write it as one it knows: {_KNOWN_LENGTHS}")  # fmt: skip
    if isinstance(exc, CorruptFile) and reader.format() == "asc" and "Could not find any topography data" in text:
        return ValueError(f"{where}: this {name} file holds no channel of heights its reader knows: no rows of numbers, or "
                          "none under value units that are a length it reads (degrees, volts, or a spelling such as "
                          f"'micron'); export the heights with their unit written as one of {_KNOWN_LENGTHS}")  # fmt: skip
    said = reason_said(exc)
    if reader.format() == "xyz" and isinstance(exc, ValueError) and (
            "no negative elements" in text or "zero-size array" in text):  # one point: no step either way
        return ValueError(  # its grid's step along y (or x) came out zero, binned by numpy.bincount: not damage
            f"{where}: the points of this {name} file make no grid: there is one, two share a position, or all lie on "
            "one row or one column (a line scan written as x, y, z); export a line as its x and z for profile-file, a map with "
            "each point once on the instrument's grid")  # fmt: skip
    if isinstance(exc, CorruptFile) and "regular grid" in text and fh is not None and (gaps := _grid_gaps(fh)):
        return ValueError(f"{where}: this {name} file's points lie on a grid of {gaps}; write each point of the grid once, "
                          "one not measured with the height NaN (undefined: harmonic fills it), or export the map as a "
                          "matrix")  # fmt: skip
    if isinstance(exc, CorruptFile) and "regular grid" in text:  # SurfaceTopography's own words: a valid export
        return ValueError(f"{where}: the points of this {name} file are not on a regular grid ({said}); export the map "
                          "on the instrument's grid, or its heights as a matrix (a table) with spacing")  # fmt: skip
    if isinstance(exc, FileFormatMismatch) and reader.format() == "npz" and fh is not None and \
            (arrays := _npz_arrays(fh)) is not None:  # a valid archive of other arrays (a line saved with np.savez)
        return ValueError(f"{where}: this {name} file holds no two-dimensional array, the only kind SurfaceTopography "
                          f"reads from one ({arrays}; not damage): save a map as a 2D array, a line as .npy (np.save) "
                          "or a column of text for profile-file")  # fmt: skip
    kind = "not a valid" if isinstance(exc, FileFormatMismatch) else "a damaged"
    if isinstance(exc, CorruptFile):
        kind = "a damaged"
    return ValueError(f"{where}: {kind} {name} file ({type(exc).__name__}{': ' + said if said else ''}); the reader of "
                      f"its format cannot read it: {AGAIN}")  # fmt: skip


NPZ_SHOWN = 3  # arrays of an archive named in a message, the rest counted
NPY_HEADER_BYTES = 65536  # what is read of an array in an archive: its header, never its data


def _npy_shape(start: bytes) -> str:
    """The shape a .npy header at ``start`` declares, or 'unknown' where it does not read as one."""
    import io

    head = io.BytesIO(start)
    try:
        version = np.lib.format.read_magic(head)
        read_header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
        return str(read_header(head)[0])
    except Exception:  # noqa: BLE001 - a header longer than NPY_HEADER_BYTES, or none
        return "unknown"


def _npz_arrays(fh) -> str | None:
    """The arrays of an NPZ archive with their shapes, from their headers alone (a member
    that inflates to gigabytes is never read whole), in words; None where it reads as no archive."""
    import zipfile

    try:
        fh.seek(0)
        with zipfile.ZipFile(fh) as archive:
            shapes = []
            for member in [n for n in archive.namelist() if n.endswith(".npy")]:
                with archive.open(member) as array:
                    shapes.append((member[:-4], _npy_shape(array.read(NPY_HEADER_BYTES))))
    except Exception:  # noqa: BLE001 - a damaged archive: the reader's words say it
        return None
    finally:
        fh.seek(0)
    said = [f"{quoted(name)} of shape {shape}" for name, shape in shapes[:NPZ_SHOWN]]
    more = f" and {len(shapes) - NPZ_SHOWN} more" if len(shapes) > NPZ_SHOWN else ""
    return f"its arrays: {', '.join(said)}{more}" if said else "no array at all"


ON_GRID = 1e-3  # of a step: a position this far from the grid's is on it (a text export's rounding)
GAPS_BYTES = 2**26  # an export read again, point by point, for its gaps: larger ones get the reader's words alone


def _grid_gaps(fh) -> str | None:
    """What keeps an x, y, z export's points from a full grid when they lie on one (their x and
    y each a whole number of steps from the first): points left out (an export that drops those
    it did not measure) or listed twice, in words; None when they lie on no grid (or the file is large)."""
    if os.fstat(fh.fileno()).st_size > GAPS_BYTES:
        return None
    points = []
    fh.seek(0)
    for raw in fh:  # a line at a time; a header's words are no numbers
        try:
            points.append([float(word) for word in re.split(r"[\s,;]+", raw.decode("utf-8", "replace").strip())][:2])
        except ValueError:
            continue
    fh.seek(0)
    xy = np.array([point for point in points if len(point) == 2])
    if xy.shape[0] < 4:
        return None
    index = []
    for axis in xy.T:
        steps = np.diff(np.unique(axis))
        step = float(np.median(steps)) if steps.size else 0.0
        if not step > 0 or np.any(np.abs((axis - axis.min()) / step - np.round((axis - axis.min()) / step)) > ON_GRID):
            return None
        index.append(np.round((axis - axis.min()) / step).astype(np.int64))
    nx, ny = int(index[0].max()) + 1, int(index[1].max()) + 1
    distinct = np.unique(index[1] * nx + index[0]).size
    missing, twice = nx * ny - distinct, xy.shape[0] - distinct
    said = [f"{missing} of its points missing" if missing else "", f"{twice} listed twice" if twice else ""]
    return f"{nx} x {ny} points (x by y), {' and '.join(part for part in said if part)}" if missing or twice else None


REASON_SHOWN = 160
_KNOWN_LENGTHS = "m, mm, \u00b5m (or um), nm, \u00c5, pm"  # as SurfaceTopography's text readers spell them


def reason_said(exc: BaseException) -> str:
    """The reader's own words for a failure, on one line, cut in the middle past REASON_SHOWN
    characters (they may quote the file)."""
    text = " ".join(str(exc).split())
    half = REASON_SHOWN // 2
    return text if len(text) <= REASON_SHOWN else f"{text[:half]}...{text[-half:]}"


def _unread_variant(name: str, field: str, value: str, where: str) -> ValueError:
    """A file of a revision or a kind of its format that SurfaceTopography's reader does not
    read (an X3P of ISO 25178-72, an X3P profile): named as such, not as damage."""
    if field == "Revision":
        return ValueError(f"{where}: this {name} file is of a revision SurfaceTopography does not read (it reads revision "
                          f"{value!r} only, not ISO 25178-72); export the scan as an ISO 5436-2 (2000) X3P, or in "
                          "another format")  # fmt: skip
    return ValueError(f"{where}: this {name} file is not an areal map (SurfaceTopography reads feature type "
                      f"{value!r} only: no profile or point cloud); export a profile as a .csv of x, z for "
                      "profile-file, or the map as an areal X3P")  # fmt: skip
