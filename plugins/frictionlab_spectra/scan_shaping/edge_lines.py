"""The caveat of a map whose outermost rows or columns carry its slope: the lines a scan starts
or ends with where the scanner settles or the tip leaves the surface (an AFM's last lines, steep
and offset). The run's rms slope is the mean over every pixel of its forward-difference gradient,
the last segment counted again at an edge, so such lines make it theirs: on a real AFM map the
last 11 of 256 rows carried 97 % of it, with no spike among its highest points."""

from __future__ import annotations

import math

import numpy as np

EDGE_LINE_TIMES = 10.0  # a line's squared gradient, summed along it, over the median line's: an edge line above
EDGE_LINES_MOST = 0.05  # of a side's lines, at most, taken as edge lines from each end (at least one)
EDGE_SHARE = 0.2  # of the mean squared slope: edge lines carrying more are said (the rms slope 12 % above)


def _line_sums(z: np.ndarray, pixel: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The squared forward-difference gradient of each pixel of ``z`` (the last segment again at
    the far edges, as the run's estimator takes it), summed along each row and along each
    column; one axis's differences at a time (one copy of the map)."""
    rows, columns = np.zeros(z.shape[0]), np.zeros(z.shape[1])
    for axis, step in ((1, pixel[0]), (0, pixel[1])):
        square = np.diff(z, axis=axis)
        square /= step
        np.square(square, out=square)
        last = np.take(square, -1, axis=axis)  # the last pixel's: its segment's, again
        stacked = np.append(square.sum(axis=1 - axis), last.sum())  # the lines the differences run across
        along = square.sum(axis=axis) + last  # the lines they run along
        if axis == 1:
            columns += stacked
            rows += along
        else:
            rows += stacked
            columns += along
        del square  # before the other axis's: one copy of the map at a time
    return rows, columns


def _from_each_end(sums: np.ndarray) -> tuple[int, int]:
    """How many lines from the start and from the end of ``sums`` stand above EDGE_LINE_TIMES the
    median line, each counted inward until one does not (at most EDGE_LINES_MOST of them)."""
    typical = float(np.median(sums)) or float(np.mean(sums))
    most = max(1, int(EDGE_LINES_MOST * sums.size))
    steep = sums > EDGE_LINE_TIMES * typical
    counts = []
    for ordered in (steep, steep[::-1]):
        flat = np.flatnonzero(~ordered[:most])
        counts.append(int(flat[0]) if flat.size else most)
    return counts[0], counts[1]


def edge_lines_warning(z: np.ndarray, pixel: tuple[float, float], region=None) -> str | None:
    """The caveat of a levelled map (pixels ``pixel`` = (dx, dy)) whose edge lines (``_from_each_end``)
    carry more than EDGE_SHARE of its mean squared slope, with the ``region`` (in the file's pixels:
    ``region`` is the crop already made, [[x0, x1], [y0, y1]], or None) that leaves them out."""
    if min(z.shape) < 3:
        return None
    rows, columns = _line_sums(z, pixel)
    total = float(rows.sum())
    if not total > 0:
        return None
    (top, bottom), (left, right) = _from_each_end(rows), _from_each_end(columns)
    ny, nx = z.shape
    kept = z[top : ny - bottom, left : nx - right]
    if kept.shape == z.shape or min(kept.shape) < 3:
        return None
    rest = float(_line_sums(kept, pixel)[0].sum()) / kept.size
    whole = total / z.size
    if not rest < (1.0 - EDGE_SHARE) * whole:
        return None
    (x0, _), (y0, _) = region if region is not None else ((0, nx), (0, ny))
    said = [f"{where} {n} {kind}" for n, where, kind in ((top, "first", "rows"), (bottom, "last", "rows"),
                                                        (left, "first", "columns"), (right, "last", "columns")) if n]  # fmt: skip
    crop = ", ".join(f"{axis}: [{start}, {stop}]" for axis, start, stop, cut in (
        ("x", x0 + left, x0 + nx - right, left or right), ("y", y0 + top, y0 + ny - bottom, top or bottom)) if cut)  # fmt: skip
    return (f"the map's {' and '.join(said)} carry {100 * (1 - rest / whole):.0f} % of its mean squared slope, each "
            f"more than {EDGE_LINE_TIMES:g} times a typical line's (its rms slope is {math.sqrt(whole):.3g}, "
            f"{math.sqrt(whole / rest):.3g} times the {math.sqrt(rest):.3g} of the rest): lines a scan starts or ends "
            "with (a scanner settling, the tip leaving the surface), whose slopes the rms slope xi divides by, and the "
            f"full-contact estimate p = E* g, are then theirs; crop them with region ({crop}, pixels of the file), "
            "if they are not the surface's own")  # fmt: skip
