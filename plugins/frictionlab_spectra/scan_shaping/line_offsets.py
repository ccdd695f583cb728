"""The caveat of a map whose rows (or columns) stand apart by one height each: a scanner's
offsets between lines."""

from __future__ import annotations

import math

import numpy as np

from .levelling import LINE_BLOCK

LINE_JUMP_SHARE = 0.5  # of the height change across lines that whole lines standing apart carry: said from here on
LINE_JUMP_CORRELATION = -0.4  # successive lines' jumps anticorrelated (a line's own offset in both): not a smooth form
LINE_HALVES_APART = 0.25  # the two halves of a line offset alike (their offsets' mean square difference, of theirs)
LINES_LOOKED_AT = 512  # consecutive lines (of a larger map) whose offsets are measured: enough to tell, in a second


def line_offset_warning(z: np.ndarray) -> str | None:
    """The caveat of a map whose rows (or columns) stand apart by a height the same all along
    each: a scanner's offsets between lines, left unless its lines were aligned. A line's offset
    against its neighbours is the median along it of its heights less the mean of its two
    neighbours' (zero for any plane, and any form along the line). Said when offsets carry most of
    that difference's variance (LINE_JUMP_SHARE), successive ones are anticorrelated (a line's
    own offset enters its own and its neighbours'; a form across the lines makes them correlated),
    and each line's two halves have the same offset (a surface whose lines differ by a wandering
    height has them apart). Offsets of a twentieth of the rms height took 40 % off MDR's b."""
    for axis, lines in ((0, "rows"), (1, "columns")):
        share, correlation, halves = _line_offsets(z if axis == 0 else z.T)
        if share > LINE_JUMP_SHARE and correlation < LINE_JUMP_CORRELATION and halves < LINE_HALVES_APART:
            along = "x" if axis == 0 else "y"
            return (f"the map's {lines} stand apart: {100 * share:.0f} % of its height change across them (a line "
                    f"against the mean of its two neighbours) is whole {lines} offset, by one height all along each "
                    "(a scanner's offsets between lines, as an AFM leaves them unless its lines are aligned): the "
                    f"slopes across the {lines}, and xi, are the offsets'; align the {lines} (Gwyddion: Align Rows, "
                    f"median) before exporting, if they are not the surface's own (grooves along {along})")  # fmt: skip
    return None


def _line_offsets(z: np.ndarray) -> tuple[float, float, float]:
    """For the rows of ``z`` less the mean of their neighbours: the share of the variance that each
    row's median carries, the lag-1 correlation of those medians, and the mean square difference
    of the medians of each row's two halves over that of the medians; a block of rows at a time."""
    ny, nx = z.shape
    rows, half = max(1, LINE_BLOCK // nx), nx // 2
    first = max(1, (ny - LINES_LOOKED_AT) // 2)  # a band of consecutive lines in the middle: offsets are everywhere
    last = min(ny - 1, first + LINES_LOOKED_AT)
    medians, apart, total = [], 0.0, 0.0
    for start in range(first, last, rows):
        stop = min(start + rows, last)
        against = z[start:stop] - 0.5 * (z[start - 1 : stop - 1] + z[start + 1 : stop + 1])
        total += float(np.vdot(against, against))
        medians.append(np.median(against, axis=1))
        difference = np.median(against[:, :half], axis=1) - np.median(against[:, half:], axis=1)
        apart += float(np.dot(difference, difference))
    offsets = np.concatenate(medians) if medians else np.zeros(0)
    power = float(np.dot(offsets, offsets))
    if not total > 0 or offsets.size < 3 or half < 1 or not power > 0:
        return 0.0, 0.0, math.inf
    return power * nx / total, float(np.dot(offsets[1:], offsets[:-1])) / power, apart / power
