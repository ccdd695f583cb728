"""Instrument files (X3P, SUR, DATX, OPD, IBW, NMD, DI, NetCDF, Gwyddion...) read by
SurfaceTopography, the optional extra ``topography``: the heights with the pixel size
and the length unit the file carries, converted to the unit a preset asks for.

SurfaceTopography is imported here only when such a file is read (its import takes
seconds). It lays a map out as heights[x, y]; a map here is z[row, column] = z[y, x],
so its array is transposed, except a bare array's (.npz, .mat, .h5: no axes), which is
z[y, x] already, as numpy saves a map and as a .npy map is read. Undefined points (an
optical scan's dropouts) are refused, or filled by the solution of Laplace's equation from
their defined neighbours (SurfaceTopography's harmonic interpolation) when the preset
chooses ``undefined: harmonic``.
"""

from __future__ import annotations

import logging
import math
import os
import re
import warnings
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from frictionlab import InputFileProblem, open_regular_file
from frictionlab.plugin import MAX_MAGNITUDE

from .channel_choice import pick_channel
from .file_kinds import LENGTH_UNITS, MIN_SIDE, ScanHeader
from .instrument_reader import (
    BARE_ARRAY_FORMATS, channel_list, check_channel_of_heights, check_declared_bytes, check_declared_points,
    check_fill_room, check_header_units, check_payload, check_stated_sides, check_text_heights, check_text_room,
    choose_reader, gwyddion_masked, parses_text, quoted, xy_order,
)
from .reader_failures import describe_failure
from .text_exports import check_declared_values, check_numbers_written, check_text_whole

TOPOGRAPHY_EXTRA = 'pip install "frictionlab[topography]"'
X_TOLERANCE = 1e-3  # allowed deviation of x from a uniform grid, as a fraction of the spacing


@dataclass(frozen=True)
class Scan:
    """What an instrument file gave: heights and pixel sides in ``unit`` (the preset's, or the
    file's own when the preset names none)."""

    heights: np.ndarray  # float64, (Ny, Nx) for a map, (N,) for a line
    pixel: tuple[float, ...]  # (dx, dy) for a map, (dx,) for a line
    unit: str | None
    file_unit: str | None  # as the file says it (SurfaceTopography's spelling)
    periodic: bool
    format: str
    channel: str
    channel_index: int
    channel_note: str | None  # which of several channels of one name was taken
    channels: list  # every channel of the file (index, name, points, units) when it has more than one
    undefined: int  # points the file leaves undefined (filled when the preset says how)
    pixel_stated: bool = True  # false: the file states no size, ``pixel`` is 1 per point and the preset's spacing is used
    undefined_mask: np.ndarray | None = None  # a map's undefined points, (Ny, Nx): which a crop leaves out
    x_decreasing: bool = False  # a line's x column runs backwards (scanned right to left): read mirrored


def scan_header(path: Path, where: str, *, dimension: int, channel: str | int | None = None) -> ScanHeader | None:
    """The shape and periodicity ``read_scan`` gives, from the reader's metadata alone: what
    the memory estimate needs before a run reads the file. None when the metadata does not
    say, or says another dimension (``read_scan`` then reads the file and names the problem)."""
    with open_input(path, where) as fh, _readers_quiet(), ExitStack() as stack:
        try:
            reader = stack.enter_context(_closed_after(_open_reader(fh, path, where)))
            check_payload(fh, type(reader), where, checksum=False)  # a shape its heights do not fill is no map's
            chosen, _ = pick_channel(reader, channel, where)
            shape, periodic = xy_order(reader, (int(n) for n in chosen.nb_grid_pts)), bool(chosen.is_periodic)
            check_declared_bytes(shape, where, fh)  # more points than its bytes hold: the full read names the damage
            sizes = chosen.physical_sizes
            pixel = None if sizes is None else tuple(float(s) / n for s, n in zip(xy_order(reader, sizes), shape))
            unit = chosen.unit if isinstance(chosen.unit, str) else None
            if unit is not None:
                length_factor(unit, "m", where, "the file's length unit")  # a message may name it: a length, not any text
        except Exception:  # noqa: BLE001 - the full read names what is wrong with the file
            return None
    if dimension == 1 and len(shape) == 2 and 1 in shape:  # a line stored as a map one pixel wide
        along = 0 if shape[1] == 1 else 1
        return ScanHeader((shape[along],), periodic, None if pixel is None else pixel[along : along + 1], unit)
    return ScanHeader(shape[::-1], periodic, pixel, unit) if len(shape) == dimension else None  # (Nx, Ny): z is (Ny, Nx)


@contextmanager
def _readers_quiet():
    """Readers warn and log about their own internals (mmap, metadata; igor2 logged a damaged
    file's bytes, 5 kB a line, through logging's last resort): what is wrong with the file is
    said once, by the ValueError naming it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = logging.root.manager.disable
        logging.disable(logging.CRITICAL)
        try:
            yield
        finally:
            logging.disable(before)


STREAM_ONLY = ("mitutoyo",)  # readers that judge a name by its suffix (openpyxl: .xlsx), which a descriptor's lacks


def _by_name(fh, reader_class):
    """The opened file by a name of its descriptor where the system has one (Linux): the same
    checked file, no race, and readers given a name may map it (given a stream, the NetCDF
    reader read all of a 128 MiB map's heights to tell its shape: 256 MiB). The stream itself
    to a reader in STREAM_ONLY: given /proc/self/fd/N, openpyxl refused a sound .xlsx."""
    name = f"/proc/self/fd/{fh.fileno()}"
    return name if os.path.exists(name) and reader_class.format() not in STREAM_ONLY else fh


def _open_reader(fh, path: Path, where: str):
    """The reader chosen for the file (``instrument_reader.choose_reader``), opened: its
    metadata parsed, its heights not read. ValueError naming ``where`` if it cannot be."""
    _require_extra(path, where)
    from SurfaceTopography.IO import open_topography

    reader_class = choose_reader(fh, path.suffix.lower().lstrip("."), where)
    if parses_text(reader_class, fh):  # parsed whole as it is opened
        check_text_room(fh, reader_class, where)
        check_text_whole(fh, reader_class, where)
        check_declared_values(fh, reader_class, where)
        check_numbers_written(fh, reader_class, where)
    try:
        return open_topography(_by_name(fh, reader_class), format=reader_class.format())
    except Exception as exc:  # a third party's parser of untrusted bytes: named, never quoted
        raise describe_failure(reader_class, exc, where, fh) from None


def _require_extra(path: Path, where: str) -> None:
    """A ValueError naming the extra to install when SurfaceTopography is missing."""
    try:
        import SurfaceTopography.IO  # noqa: F401
    except ImportError as exc:
        if _no_room(exc):  # installed, but under ulimit -v a library of it found no room: said as such
            raise
        raise ValueError(
            f"{where}: {path.suffix or 'a file without suffix'} is read as an instrument file; instrument "
            f"files (X3P, SUR, DATX, OPD, IBW, NetCDF...) are read by the optional extra topography: "
            f"{TOPOGRAPHY_EXTRA}"
        ) from None


def _no_room(exc: BaseException | None) -> bool:
    """Whether an import failed for want of address space (a library's 'failed to map segment',
    which scipy raises again as 'the install seems to be broken'), not for want of the package."""
    while exc is not None:
        if "failed to map segment" in str(exc):
            return True
        exc = exc.__cause__ or exc.__context__
    return False


@contextmanager
def _closed_after(reader):
    """``reader``, closed when the block ends, however it ends. A reader left open (the
    HDF5 one holds its h5py file in a cycle with its channels, which only the cycle collector
    frees, and the command freezes it at exit) is closed by libhdf5's own exit handler after
    Python has finalized: h5py's close callback for a Python file object then takes the GIL
    of an interpreter that is gone, and the process dies of SIGSEGV after its message."""
    try:
        yield reader
    finally:
        reader.close()


def open_input(path: Path, where: str):
    """The file opened for reading if it is a regular file (never a FIFO or a device)."""
    try:
        return open_regular_file(path)
    except InputFileProblem as exc:
        raise ValueError(f"{where}: {exc}") from None


def length_factor(unit: str | None, to: str, where: str, what: str) -> float:
    """The factor from ``unit`` (SurfaceTopography's spelling) to ``to``; ValueError naming
    ``what`` when ``unit`` is not a length."""
    from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

    try:
        factor = float(get_unit_conversion_factor(unit, to))
    except Exception:  # noqa: BLE001 - any unit it does not know
        factor = math.nan
    if not (math.isfinite(factor) and factor > 0):
        raise ValueError(f"{where}: {what} {quoted(unit)} is not a length unit ({', '.join(LENGTH_UNITS)}, ...); "
                         "choose a channel of heights, or convert the file")  # fmt: skip
    return factor


def read_scan(path: Path, where: str, *, dimension: int, unit: str | None, undefined: str,
              channel: str | int | None = None, spacing_given: bool = False) -> Scan:  # fmt: skip
    """The scan in ``path`` (``dimension`` 2: a map, 1: a line), heights and pixel sides
    converted to ``unit``. ValueError naming ``where`` for anything wrong with the file.
    ``undefined``: ``refuse``, ``harmonic``, or ``keep`` (left NaN, for a crop to check).
    ``spacing_given``: the preset gives the pixel side, so a file that states no physical
    size is read (its pixel a placeholder of 1, ``Scan.pixel_stated`` false) rather than refused."""
    with open_input(path, where) as fh, _readers_quiet(), ExitStack() as stack:
        reader = stack.enter_context(_closed_after(_open_reader(fh, path, where)))
        chosen, note = pick_channel(reader, channel, where)
        check_channel_of_heights(reader, chosen, where)
        if not spacing_given:
            check_stated_sides(reader, chosen, where)
        check_payload(fh, type(reader), where, checksum=False)
        if chosen.nb_grid_pts is not None:
            check_declared_points(tuple(int(n) for n in chosen.nb_grid_pts), where, fh, type(reader))
        check_payload(fh, type(reader), where)
        file_unit = chosen.unit if isinstance(chosen.unit, str) else None
        check_text_heights(fh, type(reader), where)
        header_unit = check_header_units(fh, type(reader), file_unit, unit, where)
        if file_unit is not None:
            length_factor(file_unit, "m", where, "the file's length unit")
        try:
            data_unit = chosen.data_unit
        except Exception:  # noqa: BLE001 - a reader that cannot say
            data_unit = None
        if isinstance(data_unit, str) and data_unit != file_unit:
            length_factor(data_unit, "m", where, f"the unit of channel {chosen.index}'s values")
        stated = chosen.physical_sizes is not None or not spacing_given or chosen.nb_grid_pts is None
        sizes = {} if stated else {"physical_sizes": tuple(float(n) for n in chosen.nb_grid_pts)}
        try:
            topography = reader.topography(channel_index=chosen.index, **sizes)
            heights = topography.heights()
        except Exception as exc:  # a third party's parser of untrusted bytes: named, never quoted
            raise describe_failure(type(reader), exc, where, fh) from None
        if not topography.is_uniform:  # x, z of a text export, x not evenly spaced: it has no pixel
            raise ValueError(f"{where}: a line scan whose {heights.size} points are not evenly spaced along x; heights "
                             "are pressed on a uniform grid: export the scan on one (as most instruments do), or "
                             "interpolate it onto one")  # fmt: skip
        backwards = False
        if topography.dim == 1 and parses_text(type(reader), fh) and (x := _text_x(fh, heights.size)) is not None:
            uniform_spacing(where, x)  # the reader takes x as even within 1e-6 in the file's unit: any x, in metres
            backwards = bool(x[-1] < x[0])  # its reader's pixel is then negative; the heights are in the file's order
        along = _line_axis(topography, dimension)
        if topography.dim != dimension and along is None:
            raise ValueError(_other_kind(where, topography.dim, xy_order(reader, topography.nb_grid_pts)))
        missing = int(np.ma.count_masked(heights)) if np.ma.isMaskedArray(heights) else 0
        if missing == heights.size:  # harmonic filling would have nothing to fill from
            raise ValueError(f"{where}: all {missing} points are undefined in the file (not measured): nothing to press")
        transpose = dimension == 2 and reader.format() not in BARE_ARRAY_FORMATS  # heights[x, y]: z[y, x] its transpose
        mask = np.ma.getmaskarray(heights) if missing and dimension == 2 else None
        mask = None if mask is None else np.ascontiguousarray(mask.T if transpose else mask)
        if missing:
            if undefined == "refuse":
                raise ValueError(undefined_message(where, missing, heights.size, gwyddion=gwyddion_masked(reader, chosen)))
            if undefined == "keep":  # NaN, for a crop to leave out (surface-file's region)
                heights = np.ma.filled(np.ma.asarray(heights, dtype=np.float64), np.nan)
            else:
                check_fill_room(where, tuple(topography.nb_grid_pts), missing)
                topography = topography.interpolate_undefined_data(method=undefined)
                heights = topography.heights()
        pixel = np.atleast_1d(np.asarray(topography.pixel_size, dtype=np.float64)) * (-1.0 if backwards else 1.0)
        if along is not None:  # a line stored as a map one pixel wide: its heights along its long side
            heights, pixel = heights.reshape(-1), pixel[along : along + 1]
        pixel = np.asarray(xy_order(reader, pixel))
        periodic = bool(topography.is_periodic)
        listed = channel_list(reader) if len(reader.channels) > 1 else []
        file_format = str(reader.name())
    if not np.all(pixel > 0):  # NaN too
        shown = " x ".join(f"{p:g}" for p in pixel) + (f" {file_unit}" if file_unit else "")
        raise ValueError(f"{where}: pixels of {shown} (x by y, as the file states them); a pixel's size must be > 0")
    factor = 1.0 if unit is None or file_unit is None else length_factor(file_unit, unit, where, "the file's unit")
    sides = tuple(check_spacing(where, "pixels of", float(p) * factor, unit or file_unit) for p in pixel)
    data = np.ma.getdata(heights)
    # one copy, in C order as a .npy map (the same sums), scaled in place
    z = np.ascontiguousarray(data.T if transpose else data, dtype=np.float64)
    if z is data or (dimension == 2 and np.shares_memory(z, data)):
        z = z.copy()
    if factor != 1.0:
        z *= factor
    return Scan(
        heights=z,
        pixel=sides,
        unit=unit if unit is not None else file_unit or header_unit,  # the header's: never converted, so as read
        file_unit=file_unit,
        periodic=periodic,
        format=file_format,
        channel=str(chosen.name),
        channel_index=int(chosen.index),
        channel_note=note,
        channels=listed,
        undefined=missing,
        pixel_stated=stated,
        undefined_mask=mask,
        x_decreasing=backwards,
    )


def undefined_message(where: str, missing: int, total: int, of: str = "", *, gwyddion: bool = False) -> str:
    """The refusal of a scan with points undefined (``of``: the part of the map they are in).
    A Gwyddion file's undefined points are those under its mask, which may instead be a
    selection (grains, a marked area) over measured heights: filling them would replace those."""
    if not gwyddion:
        return (f"{where}: {missing} of {total} points{of} are undefined in the file (not measured); set undefined: "
                "harmonic to fill them from their neighbours, or fix the scan")
    return (f"{where}: {missing} of {total} points{of} are undefined in the file: under its Gwyddion mask, read as "
            "points not measured; set undefined: harmonic to fill them from their neighbours, or fix the scan; a mask "
            "that is a selection (grains, a marked area) over measured heights would have them replaced: remove it in "
            "Gwyddion and save the file again")


FILLED_CAVEAT_SHARE = 0.05  # of a file's points filled by harmonic interpolation: a caveat from here on


def filled_caveat(filled: int, total: int, p, ndim: int, of: str = "the file's") -> str | None:
    """The caveat of a scan whose undefined points were filled (``filled`` of its ``total``), when
    they are a share of it that can move ξ: a filled patch is the smooth solution of Laplace's
    equation, so its slopes are the interpolation's, not the surface's."""
    share = filled / total if p.undefined == "harmonic" else 0.0
    if share < FILLED_CAVEAT_SHARE:
        return None
    crop = f"crop the {'map' if ndim == 2 else 'line'} to its measured part (region)"
    return (f"{100 * share:.3g} % of {of} points were undefined and filled by harmonic interpolation: their "
            "slopes are the interpolation's (smooth), not the surface's, nor is xi where a contact reaches them; "
            f"{crop} where it is large enough")  # fmt: skip


def scan_summary(scan: Scan, p) -> dict:
    """What an input summary says of a scan read from an instrument file, and of where each of
    its settings came from (``p``: the measured plugin's parameters)."""
    same = all(side == scan.pixel[0] for side in scan.pixel)
    return {
        "format": scan.format, "channel": scan.channel, "channel_index": scan.channel_index,
        **({"channel_note": scan.channel_note} if scan.channel_note else {}),
        **({"channels": scan.channels} if scan.channels else {}),
        "file_spacing": None if not scan.pixel_stated else scan.pixel[0] if same else list(scan.pixel),
        "spacing_from": "file" if p.spacing is None else "preset", "file_unit": scan.file_unit,
        "unit": scan.unit, "unit_from": "preset" if p.unit is not None else "file" if scan.file_unit else "header" if scan.unit else "none",
        "undefined_points": scan.undefined, "filled_by": p.undefined if scan.undefined else None,
        "periodic_from": "file" if p.periodic is None else "preset",
        **({"x_decreasing": True} if scan.x_decreasing else {}),
        **({"caveats": [caveat]} if (caveat := filled_caveat(scan.undefined, scan.heights.size, p, scan.heights.ndim)) else {}),
    }  # fmt: skip


def _line_axis(topography, dimension: int) -> int | None:
    """The axis (0: x, 1: y) of a line an instrument stored as a map one pixel wide, read by
    ``profile-file``; None for any other scan."""
    points = tuple(topography.nb_grid_pts)
    if dimension != 1 or topography.dim != 2 or 1 not in points:
        return None
    return 1 if points[0] == 1 else 0


def check_spacing(where: str, what: str, spacing: float, unit: str | None) -> float:
    """``spacing`` if it is a length a preset could give (1e-100 to 1e100: slopes, their squares
    and sums stay finite); else a ValueError saying ``what`` it is and the range allowed."""
    if not 1 / MAX_MAGNITUDE <= spacing <= MAX_MAGNITUDE:  # inf, NaN and 0 too
        in_unit = f" {unit}" if unit else ""
        raise ValueError(f"{where}: {what} {spacing:g}{in_unit}; a spacing must be between "
                         f"{1 / MAX_MAGNITUDE:g} and {MAX_MAGNITUDE:g} in the run's length unit")
    return spacing


def _other_kind(where: str, dim: int, points: tuple[int, ...]) -> str:
    """Why a file of ``dim`` dimensions is not what its plugin reads, and which plugin does: a map
    too narrow for surface-file is not sent there (it sent it back to profile-file)."""
    if dim == 2 and min(points) < MIN_SIDE:
        return (f"{where}: the file holds a 2D map of {points[0]} x {points[1]} pixels (x by y): too narrow for "
                f"surface-file (at least {MIN_SIDE} x {MIN_SIDE}), and profile-file reads a line (a map one pixel "
                "wide); export one of its lines from the instrument's software")  # fmt: skip
    kind = {1: "a line scan", 2: "a 2D map"}
    return f"{where}: the file holds {kind.get(dim, dim)}; use {'surface-file' if dim == 2 else 'profile-file'}"


def uniform_spacing(where: str, x: np.ndarray) -> float:
    """The step of ``x`` (a table's x column, a text export's), which must increase or decrease
    evenly (within X_TOLERANCE of a step), as its size; else a ValueError naming how far it is
    from even. A line scanned right to left (x decreasing) is read as written: mirrored, which
    changes none of its statistics, nor its contact."""
    n = x.size
    dx = (x[-1] - x[0]) / (n - 1)
    if not abs(dx) > 0:
        raise ValueError(f"{where}: x does not advance from its first row to its last (x[0] = {float(x[0]):g}, "
                         f"x[{n - 1}] = {float(x[-1]):g}); the x column must increase or decrease by one step a row")
    deviation = float(np.max(np.abs(x - (x[0] + dx * np.arange(n)))))
    dx = abs(dx)
    if deviation > X_TOLERANCE * dx:
        said = (f"{where}: x is not uniformly spaced: max deviation from a uniform grid of spacing {float(dx)!r} "
                f"is {deviation!r} ({deviation / dx:.3g} spacings; tolerance {X_TOLERANCE:g})")
        raise ValueError(said + _x_advice(x))
    return float(dx)


def _x_advice(x: np.ndarray) -> str:
    """What to do of an x column off a uniform grid: export it with more digits, where it is one
    printed too coarsely for its step (a profilometer's x in mm to 3 decimals, its step 0.0025 mm:
    its rounding alone moves points 0.4 steps); else export the scan on a uniform grid."""
    step, offset = np.polyfit(np.arange(x.size, dtype=np.float64), x, 1)
    rest = float(np.max(np.abs(x - offset - step * np.arange(x.size))))
    for decimals in range(13):  # the fewest decimals that write every x: the resolution it was printed to
        scaled = x * 10.0**decimals
        if np.all(np.abs(scaled - np.round(scaled)) <= 1e-9 * np.maximum(1.0, np.abs(scaled))):  # float64's error
            printed = 10.0**-decimals
            if rest <= printed:  # the print's rounding, not the scan, puts it off the grid
                return (f"; x is written to {decimals} decimals ({printed:g}), too coarse for its step of about "
                        f"{abs(step):.4g}: export x with more digits, or the heights alone (one column) with spacing "
                        "(the scan's step)")
            break
    return ": export the scan on a uniform grid (as most instruments do), or interpolate it onto one"


def _text_x(fh, points: int) -> np.ndarray | None:
    """The x column of a text export of a line (its rows of two numbers, x and z), or None when
    its rows of numbers are not ``points`` such rows (three columns, say)."""
    fh.seek(0)
    x = []
    for line in fh.read().decode("utf-8", errors="replace").splitlines():
        try:
            numbers = [float(word) for word in re.split(r"[\s,;]+", line.strip()) if word]
        except ValueError:  # a header
            continue
        if len(numbers) not in (0, 2):
            return None
        x += numbers[:1]
    fh.seek(0)
    return np.asarray(x) if len(x) == points else None
