"""A measured line as a spectrum generator: ``profile-file``.

The file holds heights on a uniform grid, optionally with their x positions:

- ``.csv`` / ``.txt``: one column (heights), one row of heights, or two columns
  (x, z), separated by commas, semicolons or whitespace (a UTF-8 byte-order mark is
  skipped); lines starting with ``#`` are comments and one header line before the data
  (e.g. ``x,z``: more of its cells text than numbers) is skipped.
- ``.npy``: a 1D array of heights, or a 2 x N / N x 2 array of x and z;
- any other file: an instrument's line scan (X3P, SUR, NetCDF...) read by the optional
  extra ``topography`` (``instrument_file.py``), with its own spacing and unit, converted
  to ``unit``; ``spacing`` then replaces the file's.

A measured line is not periodic (``periodic`` unset: as an instrument file says, else
false): a scan's
ends do not meet, so no slope is taken across them and solvers of periodic
lines refuse it. ``periodic: true`` declares a profile whose last point is
followed by its first (one period of a periodic surface, say); removing the
tilt (``detrend="tilt"``, the least-squares line) is what can make the ends of
an unlevelled scan meet, and any step left between them is then part of the
profile the solver sees.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field

from frictionlab import InputFile
from frictionlab.plugin import MAX_MAGNITUDE

# The readers (instrument_file, text_table, scan_shaping) are imported where a file is read:
# a run of a generated surface, and every command, registers this class without them.
from .file_kinds import ScanHeader, is_instrument_file
from .map_pipeline import LineRegion
from .measured import Measured, MeasuredFile, MeasuredParams, table_unit
from .params_cache import cached_on_params

MIN_POINTS = 8
SPACING_TOLERANCE = 1e-6  # allowed relative disagreement of the spacing param with the file's x


class ProfileFile(MeasuredFile):
    """A measured height profile read from a file; every ``generate`` returns the same line."""

    name: ClassVar[str] = "profile-file"
    summary: ClassVar[str] = (
        "Measured line read from an instrument's line scan, or a .csv/.txt/.npy file of heights (or x, z) on a "
        "uniform grid"
    )
    references: ClassVar[tuple[str, ...]] = ()

    class Params(MeasuredParams):
        path: InputFile = Field(description="file of heights (.csv, .txt or .npy), one column z or two columns x, z; "
                                "a relative path is taken from the preset file's folder", min_length=1)
        spacing: float | None = Field(
            None,
            description="grid spacing dx in the run's length unit; required if a table has only heights, must agree "
            "with its x otherwise; for an instrument file it replaces the file's spacing",
            gt=0.0,
        )
        detrend: Literal["none", "mean", "tilt", "quadratic"] | None = Field(
            None, description="remove nothing, the mean, the least-squares line (tilt) or parabola (quadratic: a bowed "
            "scan) before use; default: tilt for an instrument file (a scan is rarely level), mean for a table; a "
            "periodic line takes mean or none only (a tilt taken off it would leave a step where it repeats)",
        )
        region: LineRegion | None = Field(
            None, description="a crop, {x: [start, stop], units: pixels | length}: a half-open span along the line, in "
            "the file's points (default) or in the run's length unit from the first point; before the levelling and "
            "every check, so undefined points left out of it are not refused",
        )
        despike: float | None = Field(
            None, gt=0.0, description="replace points more than this many rms heights from the median of the 5 "
            "points around them by the straight line between their nearest kept neighbours (off by default; a value "
            "that would replace more than 5 % of the points is refused)",
        )

    # ------------------------------------------------------------ contract

    def grid_shape(self) -> tuple[int]:
        """The line's points, from the file's header when it has one (a .npy, an instrument
        file's metadata) and no crop is asked: the memory estimate refuses a line too long before
        it is read."""
        header = self._header() if self.params.region is None else None
        return header.shape if header is not None else self._measured().heights.shape

    # ------------------------------------------------------------ reading

    @cached_on_params
    def _header(self) -> ScanHeader | None:
        """The line's points (and an instrument file's periodicity) without reading its heights;
        None for a text table, or a header that does not describe a valid line."""
        from .instrument_file import scan_header

        path = Path(self.params.path)
        where = f"profile-file {str(path)!r}"
        if is_instrument_file(path, self.params.format):
            header = scan_header(path, where, dimension=1, channel=self.params.channel)
        elif file_suffix(path, where) == ".npy" and (shape := npy_shape(path, where)) is not None:
            points = _npy_line_points(shape)
            header = None if points is None else ScanHeader((points,), bool(self.params.periodic))
        else:
            return None
        return header if header is not None and header.shape[0] >= MIN_POINTS else None

    @cached_on_params
    def _measured(self) -> Measured:
        from .instrument_file import read_scan, scan_summary
        from .line_crop import crop_line
        from .scan_shaping.edge_lines import edge_points_warning
        from .scan_shaping.height_caveats import FLAT, flat_neighbours_warning, flat_rms, outlier_warning, units_warning
        from .scan_shaping.levelling import level_line, line_form_warning, periodic_levelling_problem
        from .scan_shaping.spikes import line_spike_warning

        p = self.params
        path = Path(p.path)
        where = f"profile-file {str(path)!r}"
        instrument = is_instrument_file(path, p.format)
        scan = None
        if instrument:
            undefined = "keep" if p.region is not None else p.undefined  # refused or filled inside the region alone
            scan = read_scan(path, where, dimension=1, unit=p.unit, undefined=undefined, channel=p.channel,
                             spacing_given=p.spacing is not None)  # fmt: skip
            x, z = None, scan.heights
            summary = scan_summary(scan, p)
            periodic = scan.periodic if p.periodic is None else p.periodic
        else:
            x, z = _read_columns(path)
            summary = {
                "format": path.suffix.lower(), "spacing_from": "file" if x is not None else "preset",
                **table_unit(path, where, p, file_suffix(path, where) != ".npy"),
                "periodic_from": "preset" if p.periodic is not None else "default",
                **({"x_decreasing": True} if x is not None and x[-1] < x[0] else {}),  # read mirrored: uniform_spacing
            }  # fmt: skip
            if p.region is None:  # else inside the region alone, once cropped
                summary.update(fill_table(where, z, p))
            periodic = bool(p.periodic)
        if z.size < MIN_POINTS:
            raise ValueError(f"{where}: {z.size} points, at least {MIN_POINTS} are needed")
        text = None if instrument or file_suffix(path, where) == ".npy" else path
        # the heights are checked before the spacing, but for a crop in the run's length unit, taken in it
        dx = _line_spacing(where, x, scan, p, summary, text) if p.region is not None and p.region.units == "length" \
            else None  # fmt: skip
        start = 0
        if p.region is not None:
            z = crop_line(z, 1.0 if dx is None else dx, p, where, periodic, summary, instrument)  # pixels: no spacing
            start = summary["region_pixels"][0][0]
        what = "heights" if p.region is None else "the region's heights"
        check_finite(where, what, z, table_fill_advice(p, instrument), text, None if x is None else 2, start)
        check_heights_not_underflowing(where, z)
        if dx is None:
            dx = _line_spacing(where, x, scan, p, summary, text)
        if periodic and (problem := periodic_levelling_problem(p.detrend, "line")):
            raise ValueError(f"{where}: {problem}")
        mode = p.detrend if p.detrend is not None else "tilt" if instrument and not periodic else "mean"  # as a map's
        heights = level_line(z, mode)
        if p.despike is not None:
            z, heights = _despiked(z, heights, mode, p.despike, where, summary)
        rms = float(np.std(heights))
        scale = float(np.max(np.abs(z)))
        if not rms > FLAT * scale:  # also true for scale == 0
            said = flat_rms(rms, scale)
            raise ValueError(
                f"{where}: the profile is constant (rms height {said[0]} after detrend={mode!r}{said[1]}); "
                "a flat line has no roughness"
            )
        heights.flags.writeable = False
        rms_before = float(np.std(z))
        summary = {"file": str(path), **summary, "shape": [int(z.size)], "spacing": float(dx), "periodic": periodic,
                   "detrend": mode, "detrend_from": "preset" if p.detrend is not None else "default",
                   "rms_before_detrend": rms_before, "rms_removed_fraction": 1.0 - rms / rms_before if rms_before else 0.0,
                   "rms_height": rms}  # fmt: skip
        caveats = [*summary.get("caveats", ()), None if periodic else line_form_warning(z, mode), None if p.despike is not None else line_spike_warning(heights, rms, float(dx)),
                   outlier_warning(heights, "line"), flat_neighbours_warning(z, rms, "line"),
                   None if periodic else edge_points_warning(heights, float(dx), summary.get("region_pixels")),
                   units_warning(heights, float(dx), summary, "line")]  # as a map's
        if any(caveats):
            summary["caveats"] = [caveat for caveat in caveats if caveat is not None]
        return Measured(heights, float(dx), rms, periodic, summary)


def _despiked(z: np.ndarray, levelled: np.ndarray, mode: str, k: float, where: str, summary: dict):
    """The line ``z`` (``levelled`` by ``mode``) with its spikes and pits (``despike``, as a map's)
    replaced, and it levelled again (as a map is: what levelling removed is then said of the
    line without them); said in ``summary``."""
    from .scan_shaping.levelling import level_line
    from .scan_shaping.spikes import despike

    try:
        despiked, count = despike(levelled.reshape(1, -1), k, float(np.std(levelled)))
    except ValueError as exc:  # k too small: said with the file's name
        raise ValueError(f"{where}: {exc}") from None
    summary["despiked"] = {"k": k, "points": count}
    if not count:
        return z, levelled
    z = z + (despiked[0] - levelled)
    return z, level_line(z, mode)


def _line_spacing(where: str, x: np.ndarray | None, scan, p, summary: dict, text: Path | None) -> float:
    """The line's spacing dx: the preset's, else its x column's (which it must agree with), else an
    instrument file's; the x column checked whole, as the file holds it."""
    from .instrument_file import check_spacing, uniform_spacing

    if x is None:
        if p.spacing is None and scan is None:
            raise ValueError(f"{where}: the file has only heights, so the parameter spacing is required")
        return scan.pixel[0] if p.spacing is None else p.spacing
    check_finite(where, "x", x, table=text, column=1)
    dx = check_spacing(where, "x spaced by", uniform_spacing(where, x), summary["unit"])
    if p.spacing is not None and not math.isclose(p.spacing, dx, rel_tol=SPACING_TOLERANCE):
        raise ValueError(
            f"{where}: parameter spacing={p.spacing!r} disagrees with the spacing "
            f"of the file's x column ({dx!r}); drop the parameter or fix the file"
        )
    return dx if p.spacing is None else p.spacing


def _npy_line_points(shape: tuple[int, ...]) -> int | None:
    """The points of the line a .npy array of ``shape`` holds, as ``_read_columns`` reads it."""
    if len(shape) == 2 and 1 in shape:
        return shape[0] * shape[1]
    if len(shape) == 1:
        return shape[0]
    if len(shape) == 2 and 2 in shape:
        return shape[0] if shape[1] == 2 else shape[1]
    return None


def _read_columns(path: Path) -> tuple[np.ndarray | None, np.ndarray]:
    """(x or None, z) as float64 arrays, from a .npy or a text file."""
    from .text_table import blank_line_among_numbers, read_text_table

    where = f"profile-file {str(path)!r}"
    suffix = file_suffix(path, where)
    if suffix == ".npy":
        data = load_npy(path, where)
        if data.ndim == 2 and 1 in data.shape:
            data = data.reshape(-1)
        if data.ndim == 1:
            return None, data.astype(np.float64)
        if data.ndim == 2 and data.shape[1] == 2:
            return data[:, 0].astype(np.float64), data[:, 1].astype(np.float64)
        if data.ndim == 2 and data.shape[0] == 2:
            return data[0].astype(np.float64), data[1].astype(np.float64)
        raise ValueError(f"{where}: array of shape {data.shape}; expected (N,), (N, 2) or (2, N)"
                         + (MAP_ADVICE if data.ndim == 2 else ""))
    data = read_text_table(path, where)
    if data.shape[1] == 1:
        if data.shape[0] > 1 and (blank := blank_line_among_numbers(path, where)) is not None:
            raise ValueError(f"{where}: line {blank} is empty, between heights: in a column of heights that is a "
                             "point the export left out, and read past it every height after it would move one point "
                             "along; write NaN there to mark it missing (undefined: harmonic fills it), or delete the "
                             "line if no point is missing")  # fmt: skip
        return None, data[:, 0].copy()
    if data.shape[0] == 1 and data.shape[1] > 2:  # one row of heights (a map one pixel high, as surface-file says)
        return None, data[0].copy()
    if data.shape[1] == 2:
        return data[:, 0].copy(), data[:, 1].copy()
    raise ValueError(f"{where}: {data.shape[1]} columns; expected 1 (z), 2 (x, z) or a single row of heights"
                     + (CHANNELS_ADVICE if data.shape[1] <= MAX_POINT_COLUMNS < data.shape[0] else MAP_ADVICE))


MAP_ADVICE = "; a height map (rows of heights, each a line across it) is read by surface-file"
MAX_POINT_COLUMNS = 4  # a point's x, z (or x, y, z) and another channel, as instruments export them
CHANNELS_ADVICE = ("; a few columns over many rows are a channel per column (x, z and an intensity, a second height): "
                   "export x and the heights alone (x, y and z per point, a map's, are read by surface-file with "
                   "format: instrument)")  # fmt: skip


def file_suffix(path: Path, where: str) -> str:
    """".npy", ".csv" or ".txt" (lower case) of an existing table (any other suffix is an
    instrument file: ``instrument_file.py``); ValueError otherwise."""
    if not path.exists():
        raise ValueError(f"{where}: no such file")
    return path.suffix.lower()


def load_npy(path: Path, where: str) -> np.ndarray:
    """The array of a .npy file of real numbers (integer or floating dtype), as stored; floats in
    double precision, their NaN (a byte-swapped float32 holds signalling ones, numpy's cast warned of
    them above the refusal) and overflow (float128) left for ``check_finite`` to name."""
    from .instrument_file import open_input

    with open_input(path, where) as fh:
        _check_npy_size(fh, where)
        try:
            data = np.load(fh, allow_pickle=False)
        except MemoryError:  # the header asks for more than this process can allocate (a line's too: no "map")
            raise ValueError(f"{where}: {_claimed_array(fh)} does not fit in this process's memory; save a part "
                             "of it (a crop, or every n-th point) to a file of its own: region and downsample cut what "
                             "was read whole") from None  # fmt: skip
        except Exception as exc:  # noqa: BLE001 - a header numpy cannot read: why, in its words cut short
            raise ValueError(f"{where}: {_unreadable_npy(fh, exc)}") from None
    if data.dtype.kind not in "iuf":  # numpy counts a timedelta64 as an integer
        raise ValueError(f"{where}: non-numeric content (array dtype {data.dtype}); expected real numbers")
    if data.dtype.kind == "f":
        with np.errstate(invalid="ignore", over="ignore"):
            return data.astype(np.float64, copy=False)
    return data


def npy_shape(path: Path, where: str) -> tuple[int, ...] | None:
    """The shape a .npy file's header announces, read without its data (None if the header
    cannot be read, or the file does not hold what it announces: loading it then names the problem)."""
    from .instrument_file import open_input

    with open_input(path, where) as fh:
        header = _npy_header(fh)
        held = os.fstat(fh.fileno()).st_size - header[2] if header else None
    if header is None or held != _npy_bytes(header):  # a header that lies: loading the file names it
        return None
    return header[0]


def _npy_header(fh) -> tuple[tuple[int, ...], np.dtype, int] | None:
    """The shape and dtype a .npy header announces (a file may announce more than it holds),
    and where its data starts."""
    if _header_overrun(fh) is not None:  # numpy would first read the length it declares into one buffer
        return None
    fh.seek(0)
    try:
        version = np.lib.format.read_magic(fh)
        read_header = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}
        shape, _, dtype = read_header[version](fh)
    except Exception:  # noqa: BLE001 - not a header numpy reads
        return None
    return tuple(int(n) for n in shape), dtype, fh.tell()


_LENGTH_FIELD = {1: 2, 2: 4, 3: 4}  # bytes of a .npy header's length field, by the format's major version
LENGTH_FIELD_BYTES = 4  # the longest of them


def _header_overrun(fh) -> str | None:
    """What is wrong with a .npy file whose header declares itself longer than the file (numpy
    reads that many bytes into one buffer before it looks at them: up to 4 GiB for a forged file
    of 20 bytes, refused as memory under ulimit -v), or None. ``fh`` is left at its start."""
    fh.seek(0)
    try:
        major, _ = np.lib.format.read_magic(fh)
    except Exception:  # noqa: BLE001 - not a .npy file: np.load names it
        major = None
    field = fh.read(LENGTH_FIELD_BYTES)[: _LENGTH_FIELD[major]] if major in _LENGTH_FIELD else b""
    fh.seek(0)
    if not field or len(field) != _LENGTH_FIELD[major]:  # another version, or a file cut short: np.load names it
        return None
    start = 8 + len(field)  # the magic string (6 bytes), the version (2), the length field
    declared, held = int.from_bytes(field, "little"), os.fstat(fh.fileno()).st_size - start
    if declared <= held:
        return None
    return f"its header declares a length of {declared:,} bytes, but the file holds {max(held, 0):,} bytes after it"


def _npy_bytes(header: tuple[tuple[int, ...], np.dtype, int]) -> int:
    """The bytes of data a .npy header (``_npy_header``) announces."""
    return math.prod(header[0]) * header[1].itemsize


def _check_npy_size(fh, where: str) -> None:
    """ValueError unless the file holds the array its header announces, no more and no less: a
    file cut short (its header may announce terabytes) or with bytes after its array is
    damaged, named before anything is allocated; an .npz archive (np.load gives no array of
    it) is named as such."""
    head = fh.read(6)
    fh.seek(0)
    if head.startswith(b"PK"):
        raise ValueError(f"{where}: an .npz archive (arrays zipped together), not a .npy array; save the "
                         "heights alone with numpy.save")  # fmt: skip
    if (overrun := _header_overrun(fh)) is not None:
        raise ValueError(f"{where}: a damaged .npy file: {overrun}; save the array again")
    header = _npy_header(fh)
    fh.seek(0)
    if header is not None and header[1].hasobject:  # pickled: np.load refuses it without a word of why
        raise ValueError(f"{where}: an array of Python objects (dtype {header[1]}), which is never unpickled (that "
                         "could run code); expected real numbers: save the heights as a float array")  # fmt: skip
    if header is None:  # np.load names it
        return
    if any(side < 0 for side in header[0]):
        raise ValueError(f"{where}: a damaged .npy file: its header declares an array of shape {header[0]}, a "
                         "negative number of points; save the array again")  # fmt: skip
    held, declared = os.fstat(fh.fileno()).st_size - header[2], _npy_bytes(header)
    if held != declared:
        raise ValueError(
            f"{where}: a damaged .npy file: its header declares an array of shape {header[0]} of {header[1]} "
            f"({declared:,} bytes), but the file holds {held:,} bytes after it; save the array again"
        )


def _unreadable_npy(fh, exc: Exception) -> str:
    """Why np.load could not read a .npy file: not one at all (no magic string), or a header
    it refuses (a format version it does not know, a key too many), as numpy says."""
    import tokenize  # numpy parses the header with it: a cut one raises its TokenError

    from .reader_failures import reason_said

    fh.seek(0)
    if fh.read(6) != b"\x93NUMPY":
        return ("not a .npy file (it does not start as numpy.save writes one); save the heights with numpy.save, "
                "or as a .csv/.txt table of numbers")  # fmt: skip
    if isinstance(exc, (SyntaxError, tokenize.TokenError)) or isinstance(exc.__context__, SyntaxError):
        reason = "it is not a whole Python dictionary: cut short or edited"  # the parser's own words name no field
    else:  # numpy's words name the field, then quote the header's text ("descr is not a valid dtype descriptor: 'zz9'")
        reason = (reason_said(exc) or type(exc).__name__).split(":", 1)[0]
        if reason == "Header does not contain the correct keys":
            reason = "its keys are not numpy's descr, fortran_order and shape"
    return f"a damaged .npy file: numpy cannot read its header ({reason}); save the array again"


def _claimed_array(fh) -> str:
    """The array a .npy header announces, its shape and size."""
    header = _npy_header(fh)
    if header is None:
        return "its array"
    shape, dtype, _ = header
    return f"its array of shape {shape} ({math.prod(shape) * dtype.itemsize / 2**30:.3g} GiB)"


def table_fill_advice(p, instrument: bool) -> str:
    """What ``check_finite`` adds of a table's values that are not finite: what to do (its NaN are
    filled with ``undefined: harmonic``: ``fill_table``), and, when the preset asks to fill
    undefined points, why these were not."""
    if instrument:
        return ""
    fix = "fix them before saving the table" + (", or leave them out with region" if "region" in type(p).model_fields
                                                else "")  # fmt: skip
    if p.undefined != "harmonic":
        return f"; set undefined: harmonic to fill NaN (points not measured) from their neighbours, or {fix}"
    return (f"; undefined: harmonic fills a table's NaN (points not measured), not an inf or a number beyond "
            f"{MAX_MAGNITUDE:g}: write NaN there, or {fix}")


def fill_table(where: str, z: np.ndarray, p) -> dict:
    """Fill a table's NaN (points not measured) in place when the preset says ``undefined:
    harmonic``, as an instrument file's undefined points are; what its summary says of them."""
    from .instrument_file import filled_caveat
    from .instrument_reader import check_fill_room
    from .scan_shaping.filling import fill_harmonic

    if p.undefined != "harmonic" or not (missing := int(np.count_nonzero(np.isnan(z)))):
        return {}
    with np.errstate(invalid="ignore"):
        if np.any(np.abs(z) > MAX_MAGNITUDE):  # inf too: refused with the NaN by check_finite, nothing filled from it
            return {}
    if missing == z.size:  # nothing to fill from
        raise ValueError(f"{where}: all {missing} heights are NaN (not measured): nothing to press")
    check_fill_room(where, z.shape, missing)  # before the solve, which took the memory mid-read
    fill_harmonic(z, bool(p.periodic))
    caveat = filled_caveat(missing, z.size, p, z.ndim)
    return {"undefined_points": missing, "filled_by": p.undefined, **({"caveats": [caveat]} if caveat else {})}


def check_finite(where: str, what: str, values: np.ndarray, advice: str = "", table: Path | None = None,
                 column: int | None = None, start: int = 0) -> None:
    """ValueError counting the NaN/inf in ``values``, or values beyond a preset number's largest
    magnitude (1e100: squares and sums of them must stay finite), locating the first (by its line
    and column in the text file ``table`` the values are its ``column`` of, if given; a line's
    values cropped from its point ``start``: their index in the file); ``advice`` after."""
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(values) | (np.abs(values) > MAX_MAGNITUDE)
    if bad.any():
        from .text_table import first_not_finite

        first = np.unravel_index(int(np.argmax(bad)), bad.shape)
        at = f"index {start + int(first[0])}" if bad.ndim == 1 else f"row {int(first[0])}, column {int(first[1])}"
        if table is not None and (cell := first_not_finite(table, where, column, start)) is not None:
            at = f"line {cell[0]}, column {cell[1]} of the file"
        raise ValueError(
            f"{where}: {int(bad.sum())} value(s) in {what} not finite (NaN or inf) or beyond {MAX_MAGNITUDE:g} "
            f"in magnitude, the first at {at}{advice}"
        )


def check_heights_not_underflowing(where: str, heights: np.ndarray) -> None:
    """ValueError when every height is nonzero-small, below 1e-100 in magnitude: they vary, but the
    squares of their rms underflow to 0, which would call them flat."""
    largest = max(float(np.max(heights)), -float(np.min(heights))) if heights.size else 0.0  # no copy of a large map
    if 0.0 < largest < 1.0 / MAX_MAGNITUDE:
        raise ValueError(
            f"{where}: every value in heights is below {1.0 / MAX_MAGNITUDE:g} in magnitude (the largest "
            f"{largest:.3g}), too small for a run's arithmetic; store them in a unit that makes them larger"
        )
