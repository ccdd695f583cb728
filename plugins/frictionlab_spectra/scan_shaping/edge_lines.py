"""The caveat of a map whose outermost rows or columns carry its slope, and of a line whose first
or last points do: the lines a scan starts or ends with where the scanner settles or the tip
leaves the surface (an AFM's last lines, steep and offset), the points a profilometer's trace
starts or ends with (the stylus landing, the trace running off the sample). The run's rms slope
is the mean over every point of its forward-difference slope (a map's gradient), the last
segment counted again at an edge, so such lines make it theirs: on a real AFM map the last 11 of
256 rows carried 97 % of it, with no spike among its highest points."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

EDGE_LINE_TIMES = 10.0  # a line's squared gradient summed along it (a point's squared slope), over the median's
EDGE_LINES_MOST = 0.05  # of a side's lines (a line's points), at most, taken from each end (at least one)
EDGE_SHARE = 0.2  # of the mean squared slope: edge lines carrying more are said (the rms slope 12 % above)

Ends = tuple[tuple[int, int], ...]  # per axis, how many lines (points) from its start and from its end


def _squared_steps(z: np.ndarray, step: float, axis: int) -> np.ndarray:
    """The squared forward-difference slope of each segment of ``z`` along ``axis``."""
    square = np.diff(z, axis=axis)
    square /= step
    return np.square(square, out=square)


def _last_again(per_segment: np.ndarray) -> np.ndarray:
    """Per point from per segment along the differences: the last point's is its segment's again,
    as the run's estimator takes it where a scan's ends do not meet."""
    return np.append(per_segment, per_segment[-1])


def _line_sums(z: np.ndarray, pixel: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The squared forward-difference gradient of each pixel of ``z`` (the last segment again at
    the far edges, as the run's estimator takes it), summed along each row and along each
    column; one axis's differences at a time (one copy of the map)."""
    rows, columns = np.zeros(z.shape[0]), np.zeros(z.shape[1])
    for axis, step in ((1, pixel[0]), (0, pixel[1])):
        square = _squared_steps(z, step, axis)
        stacked = _last_again(square.sum(axis=1 - axis))  # the lines the differences run across
        along = square.sum(axis=axis) + np.take(square, -1, axis=axis)  # the lines they run along
        if axis == 1:
            columns += stacked
            rows += along
        else:
            rows += stacked
            columns += along
        del square  # before the other axis's: one copy of the map at a time
    return rows, columns


def _point_squares(z: np.ndarray, spacing: float) -> tuple[np.ndarray]:
    """The squared forward-difference slope of each point of the line ``z`` (the last segment's
    again at its end), as ``_line_sums`` gives a map's per line."""
    return (_last_again(_squared_steps(z, spacing, 0)),)


def _from_each_end(sums: np.ndarray, inner: bool = False) -> tuple[int, int]:
    """How many lines from the start and from the end of ``sums`` stand above EDGE_LINE_TIMES the
    median line, each counted inward until one does not (at most EDGE_LINES_MOST of them). With
    ``inner``, above EDGE_LINE_TIMES the mean of those between the most that could be: a line's
    points, each a single squared slope (skewed: the median is 0.45 of the mean on a Gaussian line,
    far less on a smooth short one: over the median, the ends of up to 15 % of self-affine lines of
    64 points were said, 5 % over this), not a map's lines, each a sum over hundreds of pixels."""
    most = max(1, int(EDGE_LINES_MOST * sums.size))
    if inner:
        typical = float(np.mean(sums[most:-most]))
    else:
        typical = float(np.median(sums)) or float(np.mean(sums))
    steep = sums > EDGE_LINE_TIMES * typical
    counts = []
    for ordered in (steep, steep[::-1]):
        flat = np.flatnonzero(~ordered[:most])
        counts.append(int(flat[0]) if flat.size else most)
    return counts[0], counts[1]


Sums = Callable[[np.ndarray], tuple[np.ndarray, ...]]  # a map's (line's) squared slopes per line (point), per axis


def _steep_edges(z: np.ndarray, sums_of: Sums, inner: bool = False) -> tuple[Ends, float, float] | None:
    """The edge lines of ``z`` along each axis (``_from_each_end``, ``inner`` as there, of
    ``sums_of``'s squared slopes per line, an array per axis), and the mean squared slope of ``z``
    with and without them; None unless they carry more than EDGE_SHARE of it, and leave at least 3
    points along each axis."""
    if min(z.shape) < 3:
        return None
    sums = sums_of(z)
    total = float(sums[0].sum())
    if not total > 0:
        return None
    ends = tuple(_from_each_end(along, inner) for along in sums)
    kept = z[tuple(slice(start, n - end) for (start, end), n in zip(ends, z.shape))]
    if kept.shape == z.shape or min(kept.shape) < 3:
        return None
    whole, rest = total / z.size, float(sums_of(kept)[0].sum()) / kept.size
    return (ends, whole, rest) if rest < (1.0 - EDGE_SHARE) * whole else None


def _share_said(whole: float, rest: float, kind: str, why: str, one: bool = False) -> str:
    """The clause of the edge ``kind``s (line, point; ``one``: a single one): the share of the
    mean squared slope ``whole`` they carry (``rest`` without them), the rms slopes, and what
    follows of them (a scan starts or ends with them: ``why``)."""
    than = f"{math.sqrt(whole / rest):.3g} times the {math.sqrt(rest):.3g} of the rest" if rest else "the rest level"
    carry, each = ("carries", "") if one else ("carry", "each ")
    return (f"{carry} {100 * (1 - rest / whole):.0f} % of its mean squared slope, {each}more than {EDGE_LINE_TIMES:g} "
            f"times a typical {kind}'s (its rms slope is {math.sqrt(whole):.3g}, {than}): {kind}s a scan starts or "
            f"ends with ({why}), whose slopes the rms slope xi divides by, and the full-contact estimate p = E* g, "
            "are then theirs")


def _ends_said(counts: tuple[int, int], kind: str) -> list[str]:
    """"first row", "last 4 rows": the edge ``kind``s (row, column, point) at each end that has some."""
    return [f"{where} {kind}" if n == 1 else f"{where} {n} {kind}s" for n, where in zip(counts, ("first", "last")) if n]


def edge_lines_warning(z: np.ndarray, pixel: tuple[float, float], region=None) -> str | None:
    """The caveat of a levelled map (pixels ``pixel`` = (dx, dy)) whose edge lines (``_from_each_end``)
    carry more than EDGE_SHARE of its mean squared slope, with the ``region`` (in the file's pixels:
    ``region`` is the crop already made, [[x0, x1], [y0, y1]], or None) that leaves them out."""
    steep = _steep_edges(z, lambda heights: _line_sums(heights, pixel))
    if steep is None:
        return None
    ((top, bottom), (left, right)), whole, rest = steep
    ny, nx = z.shape
    (x0, _), (y0, _) = region if region is not None else ((0, nx), (0, ny))
    said = _ends_said((top, bottom), "row") + _ends_said((left, right), "column")
    crop = ", ".join(f"{axis}: [{start}, {stop}]" for axis, start, stop, cut in (
        ("x", x0 + left, x0 + nx - right, left or right), ("y", y0 + top, y0 + ny - bottom, top or bottom)) if cut)  # fmt: skip
    why = "a scanner settling, the tip leaving the surface"
    return (f"the map's {' and '.join(said)} {_share_said(whole, rest, 'line', why, top + bottom + left + right == 1)}; crop them with region "
            f"({crop}, pixels of the file), if they are not the surface's own")


def edge_points_warning(z: np.ndarray, spacing: float, region=None) -> str | None:
    """The caveat of a levelled line (points ``spacing`` apart) whose first or last points, each
    counted in from its end as a map's edge lines are, carry more than EDGE_SHARE of its mean
    squared slope, with the ``region`` that leaves them out, in the file's points (``region`` is the
    crop already made, [[x0, x1]], or None), as ``edge_lines_warning`` gives a map's."""
    steep = _steep_edges(z, lambda heights: _point_squares(heights, spacing), inner=True)
    if steep is None:
        return None
    ((first, last),), whole, rest = steep
    ((x0, _),) = region if region is not None else ((0, z.size),)
    said = " and ".join(_ends_said((first, last), "point"))
    why = "a stylus landing or settling, the trace running off the sample"
    return (f"the line's {said} {_share_said(whole, rest, 'point', why, first + last == 1)}; crop them with region "
            f"(x: [{x0 + first}, {x0 + z.size - last}], pixels of the file), if they are not the surface's own")
