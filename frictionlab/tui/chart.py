"""A small braille chart: xi against f on a log axis, drawn with text only.

Each character cell holds 2 x 4 dots (Unicode braille), so an 40 x 10 cell
plot has 80 x 40 dots: enough to see the mean curve and the fit line at 80x24.
No Textual here: ``render_chart`` returns rows of (text, style) segments.

Kept rather than textual-plotext (``benchmarks/bench_tui_chart.py`` measures it):
no dependency to install (plotext and its Textual wrapper add 850 kB and a
wrapper that must follow Textual's versions), about 100 ms less to import at
start-up, and at 80x24 13 of the chart's 14 rows show data against plotext's 10
(its frame and tick rows take the rest). plotext labels more ticks; here the
axes show their ends.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# dot (column, row) within a cell -> bit of the braille code point
_DOT_BITS = ((0x01, 0x02, 0x04, 0x40), (0x08, 0x10, 0x20, 0x80))
_BRAILLE = 0x2800


@dataclass(frozen=True)
class Series:
    x: np.ndarray  # f (> 0; plotted on a log axis)
    y: np.ndarray
    style: str
    line: bool = False  # join consecutive points (the fit line) instead of dots


def _ticks(low: float, high: float) -> str:
    return f"{low:.3g}", f"{high:.3g}"


NO_DATA = "no data yet"


def render_chart(series: list[Series], width: int, height: int, empty: str = NO_DATA) -> list[list[tuple[str, str]]]:
    """Rows of (text, style) segments filling ``width`` x ``height`` cells:
    y labels on the left, the plot, the log-f range on the bottom row; ``empty`` centred
    when there is no point to plot."""
    label_width = 7
    plot_w, plot_h = max(1, width - label_width), max(1, height - 1)
    points = []
    for s in series:
        x, y = np.asarray(s.x, float), np.asarray(s.y, float)
        keep = np.isfinite(x) & np.isfinite(y) & (x > 0)
        points.append((np.log(x[keep]), y[keep], s))
    xs = np.concatenate([p[0] for p in points]) if points else np.empty(0)
    ys = np.concatenate([p[1] for p in points]) if points else np.empty(0)
    if xs.size == 0:
        blank = [[(" " * width, "")] for _ in range(height)]
        blank[height // 2] = [(empty.center(width)[:width], "dim")]
        return blank
    x_lo, x_hi = float(xs.min()), float(xs.max())
    y_lo, y_hi = float(ys.min()), float(ys.max())
    if x_hi == x_lo:
        x_lo, x_hi = x_lo - 1, x_hi + 1
    if y_hi == y_lo:
        y_lo, y_hi = y_lo - 0.5, y_hi + 0.5
    pad = 0.05 * (y_hi - y_lo)
    y_lo, y_hi = y_lo - pad, y_hi + pad
    dots_w, dots_h = 2 * plot_w, 4 * plot_h
    cells = np.zeros((plot_h, plot_w), dtype=np.int64)
    styles = [["" for _ in range(plot_w)] for _ in range(plot_h)]

    def to_dots(lx, y):
        col = np.clip(np.round((lx - x_lo) / (x_hi - x_lo) * (dots_w - 1)), 0, dots_w - 1).astype(int)
        row = np.clip(np.round((y_hi - y) / (y_hi - y_lo) * (dots_h - 1)), 0, dots_h - 1).astype(int)
        return col, row

    for lx, y, s in points:
        if s.line and lx.size >= 2:
            # sample the line at every dot column it spans
            grid = np.linspace(lx.min(), lx.max(), dots_w)
            lx, y = grid, np.interp(grid, lx, y)
        col, row = to_dots(lx, y)
        for c, r in zip(col, row):
            cy, cx = r // 4, c // 2
            cells[cy, cx] |= _DOT_BITS[c % 2][r % 4]
            styles[cy][cx] = s.style
    rows = []
    for r in range(plot_h):
        if r == 0:
            label = f"{y_hi:6.3g} "
        elif r == plot_h - 1:
            label = f"{y_lo:6.3g} "
        elif r == plot_h // 2:
            label = "   xi  "
        else:
            label = "       "
        segments = [(label[:label_width].rjust(label_width), "dim")]
        for c in range(plot_w):
            bits = int(cells[r, c])
            segments.append((chr(_BRAILLE + bits) if bits else " ", styles[r][c]))
        rows.append(segments)
    rows.append([(_x_axis(*_ticks(math.exp(x_lo), math.exp(x_hi)), label_width, plot_w), "dim")])
    return rows


def _x_axis(left: str, right: str, label_width: int, plot_w: int) -> str:
    """The bottom row: the f range under the plot, its name between. Narrow (the Results plot
    at 60 columns), the name goes, then the row takes the labels' columns too: the ends whole."""
    middle = "f (log)"
    gap = plot_w - len(left) - len(right) - len(middle)
    if gap < 2:
        middle, gap = "", plot_w - len(left) - len(right)
    if gap < 1:
        return f"{left} {right}".rjust(label_width + plot_w)[-(label_width + plot_w):]
    return " " * label_width + left + " " * (gap // 2) + middle + " " * (gap - gap // 2) + right
