"""Instrument files (X3P, SUR, DATX, OPD, IBW, NMD, DI, NetCDF, Gwyddion...) read by
SurfaceTopography, the optional extra ``topography``: the heights with the pixel size
and the length unit the file carries, converted to the unit a preset asks for.

SurfaceTopography is imported here only when such a file is read (its import takes
seconds). It lays a map out as heights[x, y]; a map here is z[row, column] = z[y, x],
so its array is transposed. Undefined points (an optical scan's dropouts) are refused,
or filled by the solution of Laplace's equation from their defined neighbours (SurfaceTopography's
harmonic interpolation) when the preset chooses ``undefined: harmonic``.
"""

from __future__ import annotations

import math
import os
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from frictionlab import InputFileProblem, open_regular_file
from frictionlab.plugin import MAX_MAGNITUDE

TOPOGRAPHY_EXTRA = 'pip install "frictionlab[topography]"'
TABLE_SUFFIXES = (".npy", ".csv", ".txt")  # read by frictionlab itself: bare numbers, no unit
# the units a preset may ask for, in metres
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9, "pm": 1e-12}
Unit = Literal["m", "mm", "um", "nm", "pm"]
Undefined = Literal["refuse", "harmonic"]
SQUARE_TOLERANCE = 1e-6  # relative difference of a pixel's two sides still taken as square


@dataclass(frozen=True)
class Scan:
    """What an instrument file gave: heights and pixel size in ``unit`` (the preset's, or the
    file's own when the preset names none)."""

    heights: np.ndarray  # float64, (Ny, Nx) for a map, (N,) for a line
    spacing: float
    unit: str | None
    file_unit: str | None  # as the file says it (SurfaceTopography's spelling)
    periodic: bool
    format: str
    channel: str
    undefined: int  # points the file leaves undefined (filled when the preset says how)


def is_instrument_file(path: Path) -> bool:
    """Whether ``path`` is not one of frictionlab's own tables (.npy, .csv, .txt)."""
    return path.suffix.lower() not in TABLE_SUFFIXES


@dataclass(frozen=True)
class ScanHeader:
    """What an instrument file's metadata says without its heights being read."""

    shape: tuple[int, ...]  # as ``read_scan`` gives it: (Ny, Nx) for a map, (N,) for a line
    periodic: bool


def scan_header(path: Path, where: str, *, dimension: int) -> ScanHeader | None:
    """The shape and periodicity ``read_scan`` gives, from the reader's metadata alone: what
    the memory estimate needs before a run reads the file. None when the metadata does not
    say, or says another dimension (``read_scan`` then reads the file and names the problem)."""
    open_topography = _reader_opener(path, where)
    with open_input(path, where) as fh, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            with _closed_after(open_topography(_by_name(fh))) as reader:
                channel = reader.default_channel
                shape, periodic = tuple(int(n) for n in channel.nb_grid_pts), bool(channel.is_periodic)
        except Exception:  # noqa: BLE001 - the full read names what is wrong with the file
            return None
    return ScanHeader(shape[::-1], periodic) if len(shape) == dimension else None  # heights[x, y] is z[y, x]


def _by_name(fh):
    """The opened file by a name of its descriptor where the system has one (Linux): the same
    checked file, no race, and readers given a name may map it (given a stream, the NetCDF
    reader read all of a 128 MiB map's heights to tell its shape: 256 MiB)."""
    name = f"/proc/self/fd/{fh.fileno()}"
    return name if os.path.exists(name) else fh


def _reader_opener(path: Path, where: str):
    """SurfaceTopography's ``open_topography``, or a ValueError naming the extra to install."""
    try:
        from SurfaceTopography import open_topography
    except ImportError:
        raise ValueError(
            f"{where}: {path.suffix or 'a file without suffix'} is not a .npy, .csv or .txt table; instrument "
            f"files (X3P, SUR, DATX, OPD, IBW, NetCDF...) are read by the optional extra topography: "
            f"{TOPOGRAPHY_EXTRA}"
        ) from None
    return open_topography


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


def read_scan(path: Path, where: str, *, dimension: int, unit: str | None, undefined: str) -> Scan:
    """The scan in ``path`` (``dimension`` 2: a map, 1: a line), heights and spacing
    converted to ``unit``. ValueError naming ``where`` for anything wrong with the file."""
    open_topography = _reader_opener(path, where)
    from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

    with open_input(path, where) as fh, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # readers warn about their own internals (mmap, metadata)
        try:
            with _closed_after(open_topography(fh)) as reader:
                channel = reader.default_channel
                topography = reader.topography(channel_index=channel.index)
                heights = topography.heights()
        except Exception as exc:  # a third party's parser of untrusted bytes: named, never quoted
            raise ValueError(
                f"{where}: not an instrument file SurfaceTopography reads ({type(exc).__name__}); "
                "use an instrument format it lists, or a .npy, .csv or .txt table with spacing"
            ) from None
        if topography.dim != dimension:
            kind = {1: "a line scan", 2: "a 2D map"}
            advice = "use surface-file" if topography.dim == 2 else "use profile-file"
            raise ValueError(f"{where}: the file holds {kind.get(topography.dim, topography.dim)}; {advice}")
        missing = int(np.ma.count_masked(heights)) if np.ma.isMaskedArray(heights) else 0
        if missing == heights.size:  # harmonic filling would have nothing to fill from
            raise ValueError(f"{where}: all {missing} points are undefined in the file (not measured): nothing to press")
        if missing:
            if undefined == "refuse":
                raise ValueError(
                    f"{where}: {missing} of {heights.size} points are undefined in the file (not measured); "
                    "set undefined: harmonic to fill them from their neighbours, or fix the scan"
                )
            topography = topography.interpolate_undefined_data(method=undefined)
            heights = topography.heights()
        pixel = np.atleast_1d(np.asarray(topography.pixel_size, dtype=np.float64))
        periodic = bool(topography.is_periodic)
    shown = " x ".join(f"{p:g}" for p in pixel)
    if not np.all(pixel > 0):  # NaN too
        raise ValueError(f"{where}: pixels of {shown}; a pixel's size must be > 0")
    if not math.isclose(pixel.min(), pixel.max(), rel_tol=SQUARE_TOLERANCE):
        raise ValueError(f"{where}: pixels of {shown}; square pixels are needed")
    file_unit = topography.unit if isinstance(topography.unit, str) else None
    factor = 1.0
    if unit is not None and file_unit is not None:
        try:
            factor = float(get_unit_conversion_factor(file_unit, unit))
        except Exception:
            raise ValueError(f"{where}: the file's unit {file_unit!r} is not a length unit") from None
    spacing = check_spacing(where, "pixels of", float(pixel.mean()) * factor, unit or file_unit)
    z = np.array(np.ma.getdata(heights), dtype=np.float64) * factor
    return Scan(
        heights=np.ascontiguousarray(z.T) if dimension == 2 else z,  # C order, as a .npy map: the same sums
        spacing=spacing,
        unit=unit if unit is not None else file_unit,
        file_unit=file_unit,
        periodic=periodic,
        format=str(reader.name()),
        channel=str(channel.name),
        undefined=missing,
    )


def check_spacing(where: str, what: str, spacing: float, unit: str | None) -> float:
    """``spacing`` if it is a length a preset could give (1e-100 to 1e100: slopes, their squares
    and sums stay finite); else a ValueError saying ``what`` it is and the range allowed."""
    if not 1 / MAX_MAGNITUDE <= spacing <= MAX_MAGNITUDE:  # inf, NaN and 0 too
        in_unit = f" {unit}" if unit else ""
        raise ValueError(f"{where}: {what} {spacing:g}{in_unit}; a spacing must be between "
                         f"{1 / MAX_MAGNITUDE:g} and {MAX_MAGNITUDE:g} in the run's length unit")
    return spacing


def scan_not_periodic_advice(name: str) -> tuple[str, str]:
    """``SpectrumGenerator.not_periodic_advice`` of a measured line or map."""
    return (f"spectrum {name} is not periodic (periodic: false, a scan whose ends do not meet)",
            "set spectrum.params.periodic: true if its ends meet (after detrend)")  # fmt: skip
