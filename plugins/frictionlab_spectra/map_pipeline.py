"""A measured map from the pixels read to the pixels pressed, in this order: the crop
(``region``, in the file's own pixels), the levelling (``detrend``), the spikes
(``despike``, opt-in), square pixels, and the coarser grid (``downsample``). Each step is
recorded in the input summary.

Square pixels. Pixels whose sides differ by at most ``PIXEL_TOLERANCE`` (a fast and a slow
scan axis calibrated apart, 0.06 % on an NT-MDT map) are taken as square, of their mean
side. Truly rectangular pixels (an X3P of 0.128 x 0.315 um) are resampled onto square ones
of the finer side, along the coarser axis, by the map's band-limited cosine series
(``scan_shaping.resampling.cosine_resample``): it passes through every measured point and adds no
wavelength the scan did not have, so the rms height and the rms gradient are kept. Every
solver then presses square pixels: their kernels (the half-space's response to one pixel,
the spring of one MDR point) stay the ones checked against closed forms.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from frictionlab.plugin import MAX_MAGNITUDE

from .scan_shaping.edge_lines import edge_lines_warning
from .scan_shaping.height_caveats import flat_neighbours_warning, outlier_warning
from .scan_shaping.levelling import level, levelling_warning, periodic_levelling_problem
from .scan_shaping.line_offsets import line_offset_warning
from .scan_shaping.resampling import cosine_resample, resampled_points
from .scan_shaping.spikes import despike, spike_warning

PIXEL_TOLERANCE = 1e-3  # relative difference of a pixel's two sides still taken as square
SAME_SIDE = 1e-9  # relative difference of two sides that are the same side, rounded
Level = Literal["none", "mean", "plane", "quadratic"]


_Finite = Annotated[float, Field(allow_inf_nan=False)]  # NaN refused as the field's own, not again as an order


class Region(BaseModel):
    """A crop: ``x`` and ``y`` as [start, stop) along the map's columns and rows, in pixels of
    the file or in the run's length unit from the map's first pixel (``units``); either
    unset keeps the whole of that side."""

    model_config = ConfigDict(extra="forbid", defer_build=True)  # built when a preset reads a file
    x: tuple[_Finite, _Finite] | None = Field(None, description="[start, stop) along x (the map's columns)")
    y: tuple[_Finite, _Finite] | None = Field(None, description="[start, stop) along y (the map's rows)")
    units: Literal["pixels", "length"] = Field("pixels", description="pixels of the file, or the run's length unit")

    @model_validator(mode="after")
    def _ordered(self):
        check_span("x", self.x, self.units)
        check_span("y", self.y, self.units)
        return self


def check_span(name: str, span: tuple[float, float] | None, units: str) -> None:
    """ValueError unless the span ``region.<name>`` is ordered from 0 up and, in pixels, whole."""
    if span is not None and not 0 <= span[0] < span[1] < math.inf:
        raise ValueError(f"region.{name} = [{span[0]:g}, {span[1]:g}]: needs 0 <= start < stop")
    if span is not None and units == "pixels" and not all(float(v).is_integer() for v in span):
        raise ValueError(f"region.{name} = [{span[0]:g}, {span[1]:g}]: pixels are whole numbers")


class LineRegion(BaseModel):
    """A measured line's crop (``profile-file``): ``x`` as [start, stop) along the line, in points
    of the file or in the run's length unit from its first point (``units``), as a map's ``Region``."""

    model_config = ConfigDict(extra="forbid", defer_build=True)  # built when a preset reads a file
    x: tuple[_Finite, _Finite] | None = Field(None, description="[start, stop) along the line (its points)")
    units: Literal["pixels", "length"] = Field("pixels", description="points of the file, or the run's length unit")

    @model_validator(mode="before")
    @classmethod
    def _no_rows(cls, data: Any) -> Any:
        if isinstance(data, dict) and "y" in data:  # said before pydantic's 'extra inputs are not permitted'
            raise ValueError(f"region.y = {data['y']!r}: a line has no rows (y), only its points along x; give "
                             "region.x alone")  # fmt: skip
        return data

    @model_validator(mode="after")
    def _ordered(self):
        check_span("x", self.x, self.units)
        return self


class Downsample(BaseModel):
    """Coarser pixels: ``factor`` times the pixel side, or a ``pixel`` side in the run's unit."""

    model_config = ConfigDict(extra="forbid", defer_build=True)  # built when a preset reads a file
    factor: int | None = Field(None, ge=2, description="the new pixel side in pixels (an integer >= 2)")
    pixel: float | None = Field(None, gt=0.0, description="the new pixel side in the run's length unit")

    @model_validator(mode="after")
    def _one(self):
        if (self.factor is None) == (self.pixel is None):
            raise ValueError("downsample takes one of factor (an integer) or pixel (a length)")
        return self


def square_shape(shape: tuple[int, int], pixel: tuple[float, float] | None, where: str,
                 unit: str | None = None) -> tuple[int, int]:  # fmt: skip
    """The (Ny, Nx) of a map of ``shape`` on pixels (dx, dy) (in ``unit``) once on square pixels
    (``shape_map``), from a file's header; refused, naming the pixels, as ``shape_map`` refuses
    it, when that map would not fit. Sides no run takes (0, NaN, below 1e-100 or above 1e100: a
    ratio of them may overflow) leave the shape as it is: the read refuses them by name."""
    if pixel is None or not all(1 / MAX_MAGNITUDE <= p <= MAX_MAGNITUDE for p in pixel) or _nearly_square(*pixel):
        return shape
    _check_room_to_resample(shape, pixel, where, unit)
    dx, dy = pixel
    ny, nx = shape
    return (resampled_points(ny, dy, dx), nx) if dy > dx else (ny, resampled_points(nx, dx, dy))


def _nearly_square(dx: float, dy: float) -> bool:
    return abs(dx - dy) <= PIXEL_TOLERANCE * max(dx, dy)


def crop(z: np.ndarray, pixel: tuple[float, float], region: Region | LineRegion, where: str) -> tuple[np.ndarray, list]:
    """``z`` (a map, or a line: then ``region`` a ``LineRegion``) cut to ``region``, and the spans
    kept in the file's pixels, [[x0, x1], [y0, y1]] (a line's [[x0, x1]])."""
    line = z.ndim == 1
    what, kind = ("line", "point") if line else ("map", "pixel")
    sides = [(region.x, pixel[0], z.shape[-1], "x")] + ([] if line else [(region.y, pixel[1], z.shape[0], "y")])
    bounds = []
    for span, side, count, name in sides:
        if span is None:
            bounds.append((0, count))
            continue
        start, stop = (round(v / side) for v in span) if region.units == "length" else (int(v) for v in span)
        along = "" if line else f" along {name}"
        if stop <= count and stop - start < 1:  # inside, in the run's length unit, but rounded to no pixel
            raise ValueError(f"{where}: region.{name} = [{span[0]:g}, {span[1]:g}] (length) is narrower than one "
                             f"{kind}, {side:g} (the run's length unit){along}")  # fmt: skip
        if stop > count:
            extent = f"{count} {kind}s" if region.units == "pixels" else f"{count * side:g} (the run's length unit)"
            raise ValueError(f"{where}: region.{name} = [{span[0]:g}, {span[1]:g}] ({region.units}) is not inside the "
                             f"{what}, {extent}{along}")  # fmt: skip
        bounds.append((start, stop))
    if line:
        (x0, x1), = bounds
        return z[x0:x1], [[x0, x1]]
    (x0, x1), (y0, y1) = bounds
    return z[y0:y1, x0:x1], [[x0, x1], [y0, y1]]


def undefined_in_region(mask: np.ndarray, undefined: int, pixel: tuple[float, float], p, where: str) -> dict[str, Any]:
    """What the summary says of a scan's ``undefined`` points (``mask``: a map's or a line's) once
    cropped: those inside ``region`` (filled, or refused) and those it leaves out."""
    from .instrument_file import filled_caveat

    region_mask = crop(mask, pixel, p.region, where)[0]  # the scan's shape: its size is the region's
    inside, size = int(np.count_nonzero(region_mask)), region_mask.size
    caveat = filled_caveat(inside, size, p, mask.ndim, "the region's")
    return {"undefined_points": inside, "undefined_outside_region": undefined - inside,
            "filled_by": p.undefined if inside and p.undefined != "refuse" else None,
            "caveats": [caveat] if caveat else []}  # fmt: skip


def check_still_periodic(pixel: tuple[float, float], p, where: str, what: str = "map") -> None:
    """Refuse a periodic map (``what``: or line) that a step of ``shape_map`` would leave no longer
    repeating: a crop, or a resampling (onto square pixels, or coarser), whose cosine series
    ends at the last sample rather than one pixel past it."""
    dx, dy = pixel
    steps = [*(["cropped to region"] if p.region is not None else []),
             *([f"resampled from pixels of {dx:.6g} x {dy:.6g} onto square ones"] if not _nearly_square(dx, dy) else []),
             *(["downsampled"] if what == "map" and p.downsample is not None else [])]  # fmt: skip
    repeats, edges, kind = ("tiles the plane", "edges", "pixels") if what == "map" else ("repeats", "ends", "points")
    if steps:
        raise ValueError(f"{where}: a periodic {what} (periodic: true, or as the file says) no longer {repeats} once "
                         f"{' and '.join(steps)}; set periodic: false (its slopes are then not taken across its {edges}), "
                         f"or leave the {what} whole on its own {kind}")  # fmt: skip


def shape_map(z: np.ndarray, pixel: tuple[float, float], p, where: str, *, instrument: bool, periodic: bool):
    """The map to press, its square pixel side, and what was done (the summary's entries).
    A periodic map is levelled by its mean, or not at all: a plane taken off it would leave a
    step where it repeats (refused)."""
    done: dict[str, Any] = {}
    caveats: list[str] = []
    if periodic:
        check_still_periodic(pixel, p, where)
        if problem := periodic_levelling_problem(p.detrend, "map"):
            raise ValueError(f"{where}: {problem}")
    if p.region is not None:
        z, done["region_pixels"] = crop(z, pixel, p.region, where)
        if min(z.shape) < 2:  # a line, which no resampling makes a map: refused before its levelling divides by zero
            raise ValueError(f"{where}: region keeps {z.shape[1]} x {z.shape[0]} pixels (x by y) of the map, one pixel "
                             "wide: a line; give a larger region, or read a line with profile-file")  # fmt: skip
    mode = p.detrend if p.detrend is not None else "plane" if instrument and not periodic else "mean"
    levelled = level(z, mode)
    if p.despike is not None:
        try:
            despiked, count = despike(levelled.heights, p.despike, levelled.rms_after)
        except ValueError as exc:  # k too small: said with the file's name
            raise ValueError(f"{where}: {exc}") from None
        done["despiked"] = {"k": p.despike, "points": count}
        if count:  # level the file's map with the spikes replaced: the record says what levelling removed
            np.subtract(despiked, levelled.heights, out=despiked)  # what despike changed, in place
            del levelled  # let go before the new levelling: a copy of the map at a time
            levelled = level(np.add(despiked, z, out=despiked), mode)
            del despiked
    done.update(detrend=mode, detrend_from="preset" if p.detrend is not None else "default",
                rms_before_detrend=levelled.rms_before, rms_removed_fraction=_removed(levelled))  # fmt: skip
    # a periodic map's least-squares plane is no tilt (a tilted map does not repeat): nothing to say
    if not periodic and (warning := levelling_warning(levelled, mode)) is not None:
        caveats.append(warning)
    if p.despike is None and (warning := spike_warning(levelled.heights, levelled.rms_after, pixel)) is not None:
        caveats.append(warning)
    if (warning := outlier_warning(levelled.heights, "map")) is not None:
        caveats.append(warning)
    if (warning := flat_neighbours_warning(z, levelled.rms_after, "map")) is not None:
        caveats.append(warning)
    if (warning := line_offset_warning(levelled.heights)) is not None:
        caveats.append(warning)
    # a periodic map has no edges (its first and last lines are neighbours), and no region crops it
    if not periodic and (warning := edge_lines_warning(levelled.heights, pixel, done.get("region_pixels"))) is not None:
        caveats.append(warning)
    if (warning := _noise_warning(levelled.heights)) is not None:
        caveats.append(warning)
    z, spacing = levelled.heights, pixel[0]
    dx, dy = pixel
    scan = (z.shape[1] * dx, z.shape[0] * dy)  # the extent the scan's pixels cover, x by y
    if abs(dx - dy) > SAME_SIDE * max(dx, dy):  # not the rounding of a text file's coordinates (0.1 vs 0.1000...02)
        difference = abs(dx - dy) / max(dx, dy)
        if _nearly_square(dx, dy):
            spacing = 0.5 * (dx + dy)
            done["pixels"] = f"{dx:.6g} x {dy:.6g} taken as square ({100 * difference:.3g} % apart, tolerance " \
                             f"{100 * PIXEL_TOLERANCE:g} %)"
        else:
            spacing = min(dx, dy)
            axis = 0 if dy > dx else 1  # rows are along y
            before = z.shape
            _check_room_to_resample(before, (dx, dy), where)
            z = cosine_resample(z, axis, max(dx, dy), spacing)
            done["pixels"] = (f"{dx:.6g} x {dy:.6g} resampled onto square pixels of {spacing:.6g} along "
                              f"{'y' if axis == 0 else 'x'} (band-limited cosine series): {before[1]} x {before[0]} "
                              f"-> {z.shape[1]} x {z.shape[0]} pixels")  # fmt: skip
            if max(dx, dy) > LONG_PIXELS * spacing:
                caveats.append(_long_pixels_caveat((dx, dy), before[axis], z.shape[axis]))
    if p.downsample is not None:
        new = spacing * p.downsample.factor if p.downsample.factor is not None else p.downsample.pixel
        if not new > spacing * (1 + 1e-12):
            raise ValueError(f"{where}: downsample.pixel = {new:g} is not coarser than the map's pixel {spacing:g}")
        for axis in (0, 1):
            z = cosine_resample(z, axis, spacing, new)
        done["downsampled"] = {"from_pixel": spacing, "to_pixel": new}
        spacing = new
    z = z - np.mean(z) if mode != "none" else z
    pressed = (z.shape[1] * spacing, z.shape[0] * spacing)
    if abs(pressed[0] * pressed[1] / (scan[0] * scan[1]) - 1) > PIXEL_TOLERANCE:  # resampled points end at the last sample
        done["extent"] = {"scan": list(scan), "pressed": list(pressed)}
    if caveats:
        done["caveats"] = caveats
    return np.ascontiguousarray(z), float(spacing), done


LONG_PIXELS = 4.0  # times longer one way than the other: from here on, most of the map pressed is interpolated


def _long_pixels_caveat(pixel: tuple[float, float], measured: int, pressed: int) -> str:
    """The caveat of a map on pixels more than LONG_PIXELS times longer one way: the lines pressed
    between the measured ones are their cosine series, with none of the roughness shorter than
    two measured lines (a self-affine surface's slopes are mostly there)."""
    dx, dy = pixel
    along, ratio, long = ("y", dy / dx, dy) if dy > dx else ("x", dx / dy, dx)
    lines = "rows" if along == "y" else "columns"
    return (f"the file's pixels are {ratio:.4g} times longer along {along}: {measured} of the {pressed} {lines} pressed "
            f"were measured, the rest are their cosine series, with no roughness along {along} shorter than two "
            f"measured {lines} ({2 * long:.3g}); the slopes along {along}, and the rms slope xi divides by, miss it. "
            f"Measure on square pixels, or press one measured line with profile-file")  # fmt: skip


WHITE = 0.1  # correlation of neighbouring heights' signs below which a scan is noise: a measured surface's is near 1


def _noise_warning(z: np.ndarray) -> str | None:
    """The caveat of a levelled map whose neighbouring heights' signs (above or below the mean: a few
    points far from the rest cannot move them) are uncorrelated along x and y: white noise, which no
    surface is. Bytes read in the wrong order (an int16 byte-swapped) gave a map of it, pressed without
    a word; an instrument's noise on a surface smoother than it resolves gives one too."""
    below = np.signbit(z)  # a byte a point
    said = {axis: 2.0 * np.count_nonzero(a == b) / a.size - 1.0 for axis, a, b in (("x", below[:, 1:], below[:, :-1]),
                                                                                 ("y", below[1:], below[:-1]))}  # fmt: skip
    if max(said.values()) >= WHITE or not np.any(z):
        return None
    along = ", ".join(f"{c:.2f} along {axis}" for axis, c in said.items())
    return (f"the signs of the map's neighbouring heights are uncorrelated ({along}; a measured surface's are near 1): "
            "white noise, as bytes read in the wrong order or as the wrong type give, or an instrument's noise on a "
            "surface smoother than it resolves; the slopes, and xi, are the noise's, not the surface's")  # fmt: skip


RESAMPLE_COPIES = 3  # (new points x kept modes) arrays alive at once while cosine_resample builds its basis


def _check_room_to_resample(shape: tuple[int, int], pixel: tuple[float, float], where: str,
                            unit: str | None = None) -> None:  # fmt: skip
    """Refuse, before it is built, a map on square pixels larger than this process can hold:
    pixels thousands of times longer one way (a header that lies: Gwyddion reads a zero width
    as 1 m) would make millions of rows of a small scan."""
    from . import instrument_reader  # the readers, only when a map is resampled

    dx, dy = pixel
    axis = 0 if dy > dx else 1  # rows are along y
    points = resampled_points(shape[axis], max(dx, dy), min(dx, dy))
    other = shape[1 - axis]
    need = 8 * points * (other * instrument_reader.HEIGHT_COPIES + shape[axis] * RESAMPLE_COPIES)
    room, source = instrument_reader.room_to_read()  # looked up when called: a test may set the room
    if need > room:
        nx, ny = (other, points) if axis == 0 else (points, other)
        raise ValueError(
            f"{where}: pixels of {dx:.6g} x {dy:.6g}{f' {unit}' if unit else ''}, {max(dx, dy) / min(dx, dy):.4g} "
            f"times longer along {'y' if axis == 0 else 'x'}, make the map on square pixels {_count(nx)} x "
            f"{_count(ny)} pixels (x by y), about "
            f"{need / 2**30:.3g} GiB, more than the {room / 2**30:.3g} GiB this process may use ({source}); crop it "
            "with region, or, if the file's pixel size is wrong, give spacing (square pixels of that side)"
        )


def _count(points: int) -> str:
    """A count of pixels as a person reads it: whole up to 1e12, in three digits beyond."""
    return str(points) if points < 10**12 else f"{points:.3g}"


def _removed(levelled) -> float:
    """The share of the rms height (about the mean) that the levelling removed."""
    return 1.0 - levelled.rms_after / levelled.rms_before if levelled.rms_before > 0 else 0.0
