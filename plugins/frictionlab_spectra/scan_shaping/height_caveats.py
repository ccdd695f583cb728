"""Caveats of heights that are not a surface's: a few points far from the rest (outliers, a value
written for a missing pixel), heights in steps or clipped at a range, a map too flat to tell
from the rounding of its numbers (``FLAT``), and heights in another unit than the pixels'."""

from __future__ import annotations

import math

import numpy as np

from .spikes import SPIKE_K, despike, mean_square_slope

FLAT = 1e-12  # an rms height below this share of the largest height is the rounding of the numbers: flat
OUTLIER_RATIO = 5.0  # rms height over the robust one: Gaussian heights 1, a sine's 0.67, a map with a sentinel 100s
OUTLIER_MIN_POINTS = 64  # fewer, and the median says too little
MAD_TO_SIGMA = 1.4826  # the median absolute deviation of Gaussian heights times this is their rms height


def outlier_warning(z: np.ndarray, what: str) -> str | None:
    """The caveat of a levelled map or line (``what``) whose rms height is more than
    OUTLIER_RATIO times its robust one (MAD_TO_SIGMA times the median distance from the median,
    which a few points cannot move): a value an instrument writes for a missing pixel (-9999,
    1e38), spikes down as much as up, scratches. The rms height h, and with it f's unit E* h L,
    are then theirs. ``spike_warning`` looks only at the points that touch first, and measures
    them in the rms height these points inflate. Takes one copy of the map."""
    if z.size < OUTLIER_MIN_POINTS:
        return None
    values = np.array(z, dtype=np.float64).ravel()
    largest = max(float(values.max()), -float(values.min()))  # no temporary |values|
    if not 0 < largest < math.inf:
        return None
    values /= largest  # no overflow from heights of 1e200
    rms = math.sqrt(float(np.dot(values, values)) / values.size)
    middle = values.size // 2
    values.partition(middle)
    np.subtract(values, values[middle], out=values)
    np.abs(values, out=values)
    values.partition(middle)
    robust = MAD_TO_SIGMA * float(values[middle])
    if rms <= OUTLIER_RATIO * robust:
        return None
    ratio = f"{rms / robust:.3g} times" if robust > 0 else f"more than {OUTLIER_RATIO:g} times"
    zero = "" if robust > 0 else "; here zero: more than half of them have one height"
    fix = "remove them (despike, region), or mark them undefined in the file (a table's NaN)" if what == "map" else \
        "remove them (despike; region at its ends), or write NaN in their place in the file"
    return (f"the {what}'s rms height is {ratio} what most of its points say ({MAD_TO_SIGMA} times their median "
            f"distance from the median, the rms height of Gaussian heights{zero}): a few points far from the rest make the "
            f"rms height h, and with it f's unit E* h L, theirs. A value written for a missing pixel, spikes or "
            f"scratches: {fix}, which undefined: harmonic fills, if they are not the surface's own")  # fmt: skip

FLAT_SHARE = 0.25  # of neighbouring pixels at exactly one height: from here on, the slopes are the steps'


def flat_neighbours_warning(z: np.ndarray, rms: float, what: str) -> str | None:
    """The caveat of a map or line as read (``z``, before levelling, which would make its equal
    heights unequal) whose neighbouring pixels have exactly the same height more often than
    FLAT_SHARE: heights quantized in steps coarser than the roughness between pixels (an
    instrument's height resolution), or clipped flat. Their slopes are zero: a smooth scan
    rounded to steps of a quarter of its rms height pressed to half its b, without a word."""
    if not rms > 0:
        return None
    pairs = equal = 0
    for axis in range(z.ndim):  # views: one boolean the size of the map at a time
        whole = [slice(None)] * z.ndim
        ahead, behind = tuple(whole[:axis] + [slice(1, None)]), tuple(whole[:axis] + [slice(None, -1)])
        pairs, equal = pairs + z[ahead].size, equal + int(np.count_nonzero(z[ahead] == z[behind]))
    if not pairs or equal <= FLAT_SHARE * pairs:
        return _clipped_warning(z, what)
    steps = np.abs(np.diff(z.ravel()))  # along the rows, and from a row's end to the next's start
    if not (steps > 0).any():  # all equal, their rms not 0 but rounding's (0.001 less their mean): refused as flat
        return None
    step = float(steps[steps > 0].min())
    points = "pixels" if what == "map" else "points"
    return (f"{100 * equal / pairs:.0f} % of the {what}'s neighbouring {points} have exactly the same height: its heights "
            f"are steps (the smallest {step:.3g}, {step / rms:.2g} rms heights) coarser than the roughness between "
            f"{points}, or clipped flat; their slopes are zero, so the rms slope and xi are the steps', not the "
            "surface's; measure or export the heights at a finer resolution (a float channel in double precision, or "
            "less their mean: single precision keeps 7 digits of heights far from zero)")  # fmt: skip


CLIPPED_SHARE = 0.01  # of the points at exactly the highest (lowest) height: a range exceeded, not a surface's peaks
CLIPPED_POINTS = 8  # and at least this many: a few points alike at the top are a short line's rounding


def _clipped_warning(z: np.ndarray, what: str) -> str | None:
    """The caveat of a map or line as read with more than CLIPPED_SHARE of its points at its highest (lowest)
    height: an instrument out of its range (an AFM's z saturated), too few neighbours alike for the steps'."""
    for side, edge in (("highest", z.max()), ("lowest", z.min())):
        if (count := int(np.count_nonzero(z == edge))) >= CLIPPED_POINTS and count > CLIPPED_SHARE * z.size:
            return (f"{100 * count / z.size:.3g} % of the {what}'s points sit at exactly its {side} height, {float(edge):.6g}: "
                    "clipped (an instrument's height range exceeded), or a value written for missing points; "
                    f"{'the first contact lands on that plateau, and ' if side == 'highest' else ''}its slopes are "
                    f"zero; measure with a larger height range, or leave the clipped part out "
                    f"({'region' if what == 'map' else 'of the profile'}), if it is not the surface's own")  # fmt: skip
    return None

def flat_rms(rms: float, largest: float) -> tuple[str, str]:
    """The rms height of a map or line refused as flat (below FLAT of its ``largest`` height), as its
    message says it, and what it is: zero, or the rounding of its numbers (5 + 1e-14 noise is not 'zero')."""
    if rms == 0:
        return "zero", ""
    return f"{rms:.3g}", f", below {FLAT:g} of its largest height {largest:.3g}: the rounding of its numbers"


SLOPES = (1e-6, 10.0)  # rms slopes of measured surfaces lie inside, by far: outside, heights and pixels disagree in unit


def units_warning(z: np.ndarray, spacing: float, summary: dict, what: str) -> str | None:
    """The caveat of a levelled map or line (``what``, on square pixels of ``spacing``) whose rms
    slope is outside SLOPES: its heights and its pixel side are most likely in different units
    (heights in m beside pixels in um: slopes 1e-6 times a surface's). xi against f does not
    change with the ratio, but the force unit E* h L and E* g do, so F and p/E* are off by it.
    ``summary`` (the input summary) says which unit each was taken in and from where."""
    rows = z if z.ndim == 2 else z.reshape(1, -1)
    slope = math.sqrt(mean_square_slope(rows, (spacing, spacing)))
    if SLOPES[0] <= slope <= SLOPES[1] or not math.isfinite(slope) or (slope > SLOPES[1] and _spikes_steepen(rows, spacing)):
        return None
    unit = summary.get("unit")
    heights = f"heights in {unit}" if unit else "heights in no stated unit"
    if summary.get("file_unit") and summary["file_unit"] != unit:
        heights += f" (converted from the file's {summary['file_unit']})"
    else:
        heights += {"preset": " (the preset's unit)", "file": " (the file's)", "header": " (the header's)"}.get(
            summary.get("unit_from"), "")
    pixels = f"{'pixels' if what == 'map' else 'points'} {spacing:.3g}{f' {unit}' if unit else ''} apart " \
             f"({'the preset' if summary.get('spacing_from') == 'preset' else 'the file'}'s spacing)"
    side = "above" if slope > SLOPES[1] else "below"
    return (f"the {what}'s rms slope is {slope:.3g}, with its {heights} and its {pixels}: {side} any measured "
            f"surface's ({SLOPES[0]:g} to {SLOPES[1]:g}), as heights and pixel sides in different units make it "
            "(heights in m beside pixels in um: a millionth of the slope). xi against f does not change, but the force "
            "unit E* h L and the full-contact pressure E* g are off by the ratio of the units, and with them every "
            "F and p/E*: give the heights in the unit of the pixel side (unit, spacing), or convert the file")  # fmt: skip


def _spikes_steepen(rows: np.ndarray, spacing: float) -> bool:
    """Whether the map (or line, one row) is steeper than SLOPES only by what ``despike: 6``
    replaces: the spike caveat says so, and the units agree (a spike 1000 rms heights high made
    this caveat advise converting a file whose units were right)."""
    rms = math.sqrt(float(np.mean(np.square(rows))))
    try:
        cleaned, count = despike(rows, SPIKE_K, rms)
    except ValueError:  # too many points for spikes: not what makes it steep
        return False
    return count > 0 and math.sqrt(mean_square_slope(cleaned, (spacing, spacing))) <= SLOPES[1]
