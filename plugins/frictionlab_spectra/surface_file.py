"""A measured surface as a spectrum generator: ``surface-file``, and its MDR-equivalent line.

The file holds a height map z[row, column] of shape (Ny, Nx) (an AFM, profilometer or
interferometer topography; printed x by y, Nx x Ny, as instruments give it):

- ``.npy``: a 2D array of real numbers; a bare array in ``.npz``, ``.mat`` or ``.h5`` (no
  axes) is read the same way, its rows along y;
- ``.csv`` / ``.txt``: a matrix of numbers, one row of the map per line, separated by
  commas, semicolons or whitespace; ``#`` starts a comment and one header line (more
  of its cells text than numbers) is skipped;
- any other file: an instrument file (X3P, SUR, DATX, OPD, NetCDF...) read by the optional
  extra ``topography`` (``instrument_file.py``), with its own pixel size and unit.

Bare numbers carry no length: ``spacing`` (and ``unit``, a label then) say what they are.
An instrument file's heights and pixel size are converted to ``unit`` (by default the
file's own); ``spacing`` then replaces the file's pixel size. ``input_summary()`` says
which were used.

A measured map is not periodic (``periodic`` unset: as an instrument file says, else
false): its opposite edges do not meet, so slopes are not taken across them and solvers of
periodic surfaces refuse it. ``periodic: true`` declares a map that does tile the plane.
Between the file and the solver the map is cropped, levelled (``detrend``: the least-squares
plane by default for an instrument file, the mean for a periodic one), despiked on request,
put on square pixels and downsampled on request (``map_pipeline.py``); the input summary
records each step. A periodic map is refused with a crop or a resampling, after which it
would no longer tile the plane.

Solvers of lines (``mdr``, ``mdr-bisection``) get ``equivalent_line()``: the surface's
``mdr-equivalent-line`` (``equivalent_line.py``) from the map's own modes (one FFT of the
detrended map), scaled to the map's rms height (the h of f). A non-periodic map is made
periodic for that FFT by reflecting it across its edges (the 2Ny x 2Nx even extension,
whose spectrum is the map's cosine transform): the copy has the map's heights and
gradient magnitudes and no step where it repeats, which would otherwise put a spurious
q^-2 tail into the spectrum (on H = 0.3 to 0.8 test maps the line's rms slope was 1.3 to
3.3 times the scan's without it, within 1 % with it; a Hann window was 10 to 50 % off,
because it weights the longest waves, which carry most of the height, by chance). Its
lines are random-phase syntheses (phases from the rng: realizations differ, seeds
reproduce).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from pydantic import Field, model_validator

from frictionlab import InputFile

from .equivalent_line import EquivalentLine
# The readers (instrument_file, text_table, header_units) are imported where a file is read:
# a run of a generated surface, and every command, registers this class without them.
from .file_kinds import LENGTH_UNITS, MIN_SIDE, ScanHeader, is_instrument_file
from .map_pipeline import Downsample, Level, Region, crop, shape_map, square_shape, undefined_in_region
from .measured import Measured, MeasuredFile, MeasuredParams, table_unit
from .params_cache import cached_on_params
from .power_law import TWO_PI
from .profile_file import (
    MIN_POINTS, check_finite, check_heights_not_underflowing, file_suffix, fill_table, load_npy, npy_shape,
    table_fill_advice,
)
from .scan_shaping.height_caveats import FLAT, flat_rms, units_warning

MODES_PER_BLOCK = 2**20  # modes of the map's spectrum given to its MDR line at a time
# The peak of ``equivalent_line``, measured with tracemalloc (ru_maxrss agrees), plus a third:
# per point of the map, the read or the FFT (36 bytes for a periodic map, 72 for one
# reflected across its edges), and per mode of a block given to the line, its temporaries (58).
LINE_BYTES_PER_POINT = {True: 48, False: 96}  # by periodic()
LINE_BYTES_PER_MODE = 80
SQUARE_PIXEL = 1e-3  # relative: a pixel whose sides differ by less is square (a header prints its sizes rounded)


@dataclass(frozen=True)
class RadialPSD:
    """Radially averaged C2D of a map in annuli |q| / width in [k - 1/2, k + 1/2), k = 1, 2, ...
    (the modes below width / 2 join k = 1): psd[k-1] = (sum of |z_q|^2 over the annulus) /
    (2 pi q_k width), the annulus' power per unit area of the q plane, so that
    sum_k 2 pi q_k width psd_k = mean(z^2) exactly. A diagnostic: the MDR line is built from the
    modes themselves (``equivalent_line``)."""

    wavenumber: np.ndarray  # q_k = k * width
    psd: np.ndarray  # C2D_k
    count: np.ndarray  # modes of the map in annulus k


def radial_psd(heights: np.ndarray, spacing: float, width: float | None = None) -> RadialPSD:
    """The radial average of a map's C2D (one FFT of the map as it is: a non-periodic map's
    edge step adds a q^-2 tail). The default ``width`` is min(dqx, dqy), the finer of the
    map's own wavenumber steps."""
    ny, nx = heights.shape
    dqx, dqy = TWO_PI / (nx * spacing), TWO_PI / (ny * spacing)
    width = min(dqx, dqy) if width is None else width
    import scipy.fft  # imported on first use: a run that needs no FFT here starts faster
    power = np.abs(scipy.fft.fft2(heights)) ** 2 / float(nx * ny) ** 2  # sums to mean(z^2)
    power[0, 0] = 0.0  # the mean is no roughness
    q = np.hypot((dqy * np.fft.fftfreq(ny, 1.0 / ny))[:, None], (dqx * np.fft.fftfreq(nx, 1.0 / nx))[None, :])
    index = np.maximum(np.floor(q / width + 0.5).astype(np.int64), 1).ravel()
    count = np.bincount(index)[1:]
    wavenumber = width * np.arange(1, count.size + 1)
    annulus_power = np.bincount(index, weights=power.ravel())[1:]
    count[0] -= 1  # the q = 0 mode was put in k = 1 with zero power
    return RadialPSD(wavenumber, annulus_power / (TWO_PI * wavenumber * width), count)


class SurfaceFile(MeasuredFile):
    """A measured height map read from a file; every ``generate`` returns the same surface."""

    name: ClassVar[str] = "surface-file"
    summary: ClassVar[str] = (
        "Measured surface read from an instrument file (X3P, SUR, DATX, GWY...) or a .npy/.csv/.txt height map "
        "(Ny, Nx); levelled, cropped, resampled onto square pixels as asked"
    )
    references: ClassVar[tuple[str, ...]] = ()
    dimension: ClassVar[int] = 2

    class Params(MeasuredParams):
        path: InputFile = Field(description="file of heights (.npy 2D array, or .csv/.txt matrix: one map row per "
                                "line); a relative path is taken from the preset file's folder", min_length=1)
        spacing: float | None = Field(
            None,
            description="pixel side dx (square pixels), in the run's length unit: required for a .npy/.csv/.txt map; "
            "for an instrument file it replaces the pixel size the file gives",
            gt=0.0,
        )
        detrend: Level | None = Field(
            None,
            description="remove nothing, the mean, the least-squares plane or quadratic before use; default: plane "
            "for an instrument file (a scan is rarely level), mean for a table; a periodic map takes mean or none "
            "only (a plane taken off it would leave a step where it repeats)",
        )
        region: Region | None = Field(
            None, description="a crop, {x: [start, stop], y: [start, stop], units: pixels | length}: half-open spans "
            "along the map's columns (x) and rows (y), in the file's pixels (default) or in the run's length unit from "
            "the first pixel; a side left out is kept whole",
        )
        downsample: Downsample | None = Field(
            None, description="coarser pixels, {factor: N} (N >= 2 pixels) or {pixel: side} (in the run's length "
            "unit): wavelengths shorter than two new pixels are removed first (no aliasing), longer ones kept whole",
        )
        despike: float | None = Field(
            None, gt=0.0, description="replace points more than this many rms heights from the median of the 5 x 5 "
            "pixels around them by the solution of Laplace's equation from their neighbours (off by default; a value that "
            "would replace more than 5 % of the points is refused)",
        )
        spacing_y: float | None = Field(
            None, gt=0.0, description="pixel side along y (the map's rows), in the run's length unit, where it differs "
            "from spacing's along x (a slow scan axis coarser than the fast one): the map is resampled onto square "
            "pixels of the finer side; needs spacing",
        )

        @model_validator(mode="after")
        def _spacing_y_with_spacing(self):
            if self.spacing_y is not None and self.spacing is None:
                raise ValueError(f"spacing_y = {self.spacing_y:g} gives the pixel's side along y beside spacing's along "
                                 "x: give spacing too")  # fmt: skip
            return self

        def preset_pixel(self) -> tuple[float, float] | None:
            """The pixel (dx, dy) the preset gives, if it gives one."""
            if self.spacing is None:
                return None
            return (self.spacing, self.spacing if self.spacing_y is None else self.spacing_y)

    # ------------------------------------------------------------ contract

    def grid_shape(self) -> tuple[int, int]:
        """The map's shape, from the file's header when it has one (a .npy, an instrument
        file's metadata) and no crop or downsampling is asked: the memory estimate refuses a
        map too large before it is read."""
        header = self._header()
        p = self.params
        if header is None or p.region is not None or p.downsample is not None:
            return self._measured().heights.shape
        pixel = header.pixel if p.spacing is None else p.preset_pixel()
        return square_shape(header.shape, pixel, f"surface-file {str(p.path)!r}", p.unit or header.unit)

    def radial_psd(self) -> RadialPSD:
        """The detrended map's radially averaged C2D in annuli of the map's own finest dq."""
        surface = self._measured()
        return radial_psd(surface.heights, surface.spacing)

    def equivalent_line(self) -> EquivalentLine:
        """The MDR-equivalent line of this map (``equivalent_line.py``): length 2 sqrt(A / pi),
        each of its modes carrying the power of the map's modes around it, scaled to
        ``rms_height()``. A non-periodic map is reflected across its edges for its FFT.

        Memory: the map is real, so its modes with qx < 0 mirror those with qx > 0; only the
        half plane qx >= 0 is computed (``rfft2``), each mirrored column counted twice, and its
        modes go to the line a block of rows at a time: its allocations peak at about 120 bytes
        per point of the map, where the whole plane at once took 250 to 310 (a 4096 x 2048 scan
        is pressed by MDR in 0.65 GiB, under ulimit -v 2 GiB)."""
        surface = self._measured()
        heights = surface.heights
        if not surface.periodic:  # the even extension: periodic, no step where it repeats
            heights = np.block([[heights, heights[:, ::-1]], [heights[::-1, :], heights[::-1, ::-1]]])
        ny, nx = heights.shape
        import scipy.fft  # imported on first use: a run that needs no FFT here starts faster
        spectrum = scipy.fft.rfft2(heights)
        del heights
        power = np.abs(spectrum)
        del spectrum
        power *= power
        power[:, 1 : (nx + 1) // 2] *= 2.0  # these columns stand for themselves and their mirrors at -qx
        power[0, 0] = 0.0  # the mean is no roughness
        qy = TWO_PI / (ny * surface.spacing) * np.fft.fftfreq(ny, 1.0 / ny)
        qx = TWO_PI / (nx * surface.spacing) * np.arange(power.shape[1])
        rows = max(1, MODES_PER_BLOCK // power.shape[1])
        blocks = ((np.hypot(qy[start : start + rows, None], qx[None, :]), power[start : start + rows])
                  for start in range(0, ny, rows))  # fmt: skip
        return EquivalentLine.of_surface(
            area=surface.heights.size * surface.spacing**2, spacing=surface.spacing, modes=blocks,
            rms_height=surface.rms_height,
        )  # fmt: skip

    def equivalent_line_bytes(self) -> int:
        """The peak memory of ``equivalent_line`` (reading the map included), from the map's
        shape and periodicity: known from a header without reading the map."""
        ny, nx = self.grid_shape()
        periodic = self.periodic()
        modes = (1 if periodic else 4) * ny * nx // 2  # of the half plane, the map reflected or not
        return LINE_BYTES_PER_POINT[periodic] * ny * nx + LINE_BYTES_PER_MODE * min(modes, MODES_PER_BLOCK)

    # ------------------------------------------------------------ reading

    @cached_on_params
    def _header(self) -> ScanHeader | None:
        """The map's shape (and an instrument file's periodicity) without reading its heights;
        None for a text table, or a header that does not describe a valid map."""
        from .instrument_file import scan_header

        path = Path(self.params.path)
        where = f"surface-file {str(path)!r}"
        if is_instrument_file(path, self.params.format):
            header = scan_header(path, where, dimension=2, channel=self.params.channel)
        elif file_suffix(path, where) == ".npy" and (shape := npy_shape(path, where)) is not None:
            header = ScanHeader(shape, bool(self.params.periodic))
        else:
            return None
        valid = header is not None and len(header.shape) == 2 and min(header.shape) >= MIN_SIDE
        return header if valid else None

    @cached_on_params
    def _measured(self) -> Measured:
        p = self.params
        path = Path(p.path)
        where = f"surface-file {str(path)!r}"
        z, pixel, summary = _read_map(path, where, p)
        _check_defined(z, pixel, p, path, where)
        check_heights_not_underflowing(where, z)
        heights, spacing, shaped = shape_map(z, pixel, p, where, instrument=is_instrument_file(path, p.format),
                                             periodic=summary["periodic"])
        caveats = [*summary.pop("caveats", ()), *shaped.pop("caveats", ())]  # the file's, then the shaping's
        summary.update(shaped, **({"caveats": caveats} if caveats else {}))
        if min(heights.shape) < MIN_SIDE:
            nx, ny = heights.shape[::-1]
            raise ValueError(f"{where}: after the crop, resampling and downsampling the map has {nx} x {ny} pixels (x by y); at "
                             f"least {MIN_SIDE} x {MIN_SIDE} are needed")  # fmt: skip
        rms = float(np.std(heights))  # after the size check: a map downsampled to one pixel is small, not flat
        largest = float(np.nanmax(np.abs(z)))
        if not rms > FLAT * largest:  # also true for an all-zero map; NaN only outside region
            replaced = shaped.get("despiked", {}).get("points")
            despiked = f" and despike {p.despike:g}, which replaced {replaced} points" if replaced else ""
            said = flat_rms(rms, largest)
            raise ValueError(
                f"{where}: the map is constant (rms height {said[0]} after detrend={shaped['detrend']!r}{despiked}"
                f"{said[1]}); "
                "a flat surface has no roughness"
            )
        heights.flags.writeable = False
        summary.update(shape=list(heights.shape), spacing=float(spacing), rms_height=rms)
        if caveat := units_warning(heights, spacing, summary, "map"):
            summary["caveats"] = [*summary.get("caveats", ()), caveat]
        return Measured(heights, spacing, rms, summary["periodic"], summary)


def _check_defined(z: np.ndarray, pixel: tuple[float, float], p: SurfaceFile.Params, path: Path, where: str) -> None:
    """Refuse undefined points (an instrument's NaN) or NaN/inf inside the part of the map pressed:
    a crop (``region``) that leaves them out is read. A text table's first is named by its line."""
    from .instrument_file import undefined_message

    instrument = is_instrument_file(path, p.format)
    inside = crop(z, pixel, p.region, where)[0] if p.region is not None else z
    if instrument and (missing := int(np.count_nonzero(np.isnan(inside)))):
        raise ValueError(undefined_message(where, missing, inside.size, " of the region"))
    text = not instrument and file_suffix(path, where) != ".npy"
    check_finite(where, "heights" if p.region is None else "the region's heights (rows, columns from its corner)", inside,
                 table_fill_advice(p, instrument), path if text and p.region is None else None)


def _square_over_oblong(pixel: tuple[float, float] | None, p: SurfaceFile.Params, unit: str | None,
                        whose: str = "the file's", use: str = "leave spacing out") -> str | None:
    """The caveat of ``spacing`` alone replacing a file's ``pixel`` (dx, dy in ``unit``; None where
    it states none) that is not square: the preset's square pixel stretches the map along one axis
    against the other, its slopes with it. Square within SQUARE_PIXEL: a header's sizes are rounded."""
    if pixel is None or p.spacing is None or p.spacing_y is not None or math.isclose(*pixel, rel_tol=SQUARE_PIXEL):
        return None
    (dx, dy), said = pixel, f" {unit}" if unit else ""
    return (f"spacing {p.spacing:g} replaces {whose} pixel of {dx:.6g} x {dy:.6g}{said} (x by y), which is not square, "
            f"by a square one: against its x side, the map's y side becomes {dx / dy:.4g} times what the file says (its "
            f"slopes along y {dy / dx:.4g} times as steep); give spacing_y too ({p.spacing * dy / dx:.6g} keeps the "
            f"file's shape), or {use} to use the file's pixel")  # fmt: skip


def _table_checks(path: Path, where: str, data: np.ndarray, p: SurfaceFile.Params, unit: dict) -> dict[str, Any]:
    """What the summary says of a table map (of at least MIN_SIDE points each way): the pixel its
    header states (Gwyddion's text export, read with format: table), in the run's ``unit``
    (``table_unit``), which ``validate`` names where the preset's differs; and the caveats of an
    export's axes read as heights, and of a square ``spacing`` over the header's oblong pixel."""
    said = unit["unit"] if unit["unit"] in LENGTH_UNITS else None
    text = file_suffix(path, where) != ".npy"
    stated = _header_pixel(path, where, data.shape, said) if text and said else None
    oblong = _square_over_oblong(stated, p, said, "its header's", "read it with format: instrument")
    caveats = [caveat for caveat in (_axes_in_region(data, p.preset_pixel(), p, where), oblong) if caveat]
    spacing = {} if stated is None else {"file_spacing": stated[0] if stated[0] == stated[1] else list(stated)}
    return {**spacing, **({"caveats": caveats} if caveats else {})}


def _header_pixel(path: Path, where: str, shape: tuple[int, int], unit: str) -> tuple[float, float] | None:
    """The pixel (dx, dy) a table's header states (``stated_pixel``), in ``unit``."""
    from .header_units import stated_pixel

    if (pixel := stated_pixel(path, where, shape)) is None:
        return None
    return pixel[0] / LENGTH_UNITS[unit], pixel[1] / LENGTH_UNITS[unit]


def _axes_in_region(data: np.ndarray, pixel, p: SurfaceFile.Params, where: str) -> str | None:
    """``axes_warning`` of a table map, of the first row and column that ``region`` keeps."""
    from .text_table import axes_warning

    (x0, _), (y0, _) = crop(data, pixel, p.region, where)[1] if p.region is not None else ((0, 0), (0, 0))
    return axes_warning(data, (y0 == 0, x0 == 0))


def _read_map(path: Path, where: str, p: SurfaceFile.Params) -> tuple[np.ndarray, tuple[float, float], dict[str, Any]]:
    """The (Ny, Nx) float64 map of a table or an instrument file (at least MIN_SIDE points each
    way), its pixel sides (dx, dy) in the run's unit, and what was read and used (``input_summary``)."""
    from .instrument_file import read_scan, scan_summary
    from .instrument_reader import HEIGHT_COPIES
    from .text_table import read_text_table

    if is_instrument_file(path, p.format):
        undefined = "keep" if p.region is not None and p.undefined == "refuse" else p.undefined  # outside: cropped
        scan = read_scan(path, where, dimension=2, unit=p.unit, undefined=undefined, channel=p.channel,
                         spacing_given=p.spacing is not None)  # fmt: skip
        data, pixel = scan.heights, scan.pixel if p.spacing is None else p.preset_pixel()
        summary = scan_summary(scan, p)
        if p.region is not None and scan.undefined:  # its caveat replaces the whole file's
            summary.update(undefined_in_region(scan.undefined_mask, scan.undefined, pixel, p, where))
        if caveat := _square_over_oblong(scan.pixel if scan.pixel_stated else None, p, summary.get("unit")):
            summary["caveats"] = [*summary.get("caveats", ()), caveat]
        periodic = scan.periodic if p.periodic is None else p.periodic
    else:
        table = file_suffix(path, where) != ".npy"
        unit = table_unit(path, where, p, table)  # first: an export stating its pixel is told how to read it, not to give spacing
        if p.spacing is None:
            raise ValueError(
                f"{where}: a {path.suffix.lower()} map holds bare numbers, so the parameter spacing (the pixel side) "
                "is required"
            )
        data = read_text_table(path, where, HEIGHT_COPIES) if table else load_npy(path, where)
        if data.size == 0:  # not 'a map of 1 x 0 pixels, one pixel wide: a line'
            held = f"an array of shape {data.shape}" if data.ndim != 2 or path.suffix.lower() == ".npy" else \
                "a table of no numbers (a header, comments or blank lines only)"
            raise ValueError(f"{where}: {held}: no heights; expected a map of at least {MIN_SIDE} x {MIN_SIDE} points")
        pixel = p.preset_pixel()
        summary = {
            "format": path.suffix.lower(), "spacing_from": "preset", **unit,
            "periodic_from": "preset" if p.periodic is not None else "default",
        }  # fmt: skip
        if data.ndim == 2 and min(data.shape) >= MIN_SIDE:
            holes = np.isnan(data) if p.region is not None and p.undefined == "harmonic" else None
            checked, filled = _table_checks(path, where, data, p, unit), fill_table(where, data, p)
            if filled and holes is not None:  # counted inside the region, as an instrument file's
                filled = undefined_in_region(holes, filled["undefined_points"], pixel, p, where)
            caveats = [*checked.pop("caveats", ()), *filled.pop("caveats", ())]
            summary.update(checked, **filled, **({"caveats": caveats} if caveats else {}))
        periodic = bool(p.periodic)
    if data.ndim == 2 and 1 in data.shape:
        ny, nx = data.shape
        if nx * ny < MIN_POINTS:  # profile-file would refuse it too
            heights = f"{nx * ny} height{'s' * (nx * ny > 1)}"
            raise ValueError(f"{where}: a map of {nx} x {ny} pixels (x by y): {heights}, too few for a map (at least "
                             f"{MIN_SIDE} x {MIN_SIDE}) or a line (profile-file: at least {MIN_POINTS} points)")
        raise ValueError(f"{where}: a map of {nx} x {ny} pixels (x by y), one pixel wide: a line; use profile-file")
    if data.ndim != 2:
        raise ValueError(
            f"{where}: array of shape {data.shape}; expected a 2D height map (Ny, Nx) "
            "(for a single line use profile-file)"
        )
    if min(data.shape) < MIN_SIDE:
        ny, nx = data.shape
        table = not is_instrument_file(path, p.format) and path.suffix.lower() != ".npy"
        points = {3: "; columns of x, y and z per point (an instrument's export) are read with format: instrument"
                  if table else "", 2: "; columns of x and z (a line) are read by profile-file",
                  4: "; columns of x, y, z and another channel per point (an intensity): export x, y and the heights "
                  "alone, read with format: instrument"}.get(nx if ny > nx else 0, "")  # fmt: skip
        raise ValueError(f"{where}: map of {nx} x {ny} pixels (x by y); at least {MIN_SIDE} x {MIN_SIDE} are needed{points}")
    summary = {"file": str(path), **summary, "file_shape": list(data.shape), "periodic": periodic,
               **({"spacing_given": list(pixel)} if p.spacing_y is not None else {})}  # fmt: skip
    return data.astype(np.float64, copy=False), (float(pixel[0]), float(pixel[1])), summary

