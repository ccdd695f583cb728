"""The figures of a run and of a sweep: plot.png, xi against f on a log axis with
the fitted law, like the source paper's figures; sweep.png, a and b per point.

Files are drawn on a bare ``matplotlib.figure.Figure`` (no pyplot, no backend
switch): nothing here needs a display, and a notebook's own backend is left alone.
``draw_curve`` draws onto any Axes (``frictionlab.Result.plot`` uses it).
"""

from __future__ import annotations

import math
import textwrap
from typing import TYPE_CHECKING, Any

import matplotlib.backends.backend_agg  # noqa: F401 (savefig's PNG canvas: imported with this module, ahead of drawing)
import numpy as np
from matplotlib import rc_context
from matplotlib.figure import Figure
from matplotlib.ticker import FixedLocator, LogFormatter
from PIL import Image

if TYPE_CHECKING:  # only these: the process that draws plot.png imports no more than matplotlib and numpy
    from .compute.fit import LogFit
    from .runs.figures import CurveFigure

Image.preinit()  # PIL's format drivers, which the first figure saved would import
XI_LABEL = "xi = rms slope in contact / rms slope"
FAST_PNG = {"compress_level": 1}  # zlib's fastest: a third of the encoding's time for a file 7% larger
UNHINTED = {"text.hinting": "no_hinting"}  # FreeType's hinting, run for each glyph, was 15% of drawing plot.png


AXES_NEEDS = ("errorbar", "fill_between", "grid", "legend", "plot", "set_title", "set_xlabel", "set_xscale",
              "set_xticks", "set_ylabel", "text")  # what draw_curve (and Result.plot) call on an Axes


def draw_curve(ax, f, xi, xi_sem, fit: LogFit | None, *, done: int, caveats=(), fontsize: float = 8) -> None:
    """xi against f (log axis) with its 95% band and the fitted law a + b ln f; each
    caveat written on the axes, where nobody reading the figure can miss it."""
    f, xi, xi_sem = (np.asarray(v, dtype=float) for v in (f, xi, xi_sem))
    ax.fill_between(f, xi - 1.96 * xi_sem, xi + 1.96 * xi_sem, color="C0", alpha=0.25, lw=0, label="95% band of the mean")
    ax.plot(f, xi, "o", ms=2.5, color="C0", label=f"mean over {done} realizations")
    if fit is not None:
        grid = np.geomspace(np.nanmin(f), np.nanmax(f), 200)
        label = f"fit a + b ln f: a = {fit.a:.4f}, b = {fit.b:.4f}, R² = {fit.r2:.3f}"
        ax.plot(grid, fit.xi(grid), "-", color="C3", label=label)
    ax.set_xscale("log")
    plain_log_labels(ax.xaxis)
    ax.set_ylabel(XI_LABEL, fontsize=fontsize + 1)
    ax.legend(fontsize=fontsize, loc="upper left")  # a fixed corner: "best" searches every data point
    ax.grid(True, which="both", alpha=0.3)
    if caveats:  # one block: caveats of several lines each, stacked by the text's own layout, never overlapping
        said = "\n".join("caveat: " + textwrap.fill(caveat, 70) for caveat in caveats)
        ax.text(0.99, 0.02, said, transform=ax.transAxes, ha="right", va="bottom", fontsize=fontsize - 1, color="C3",
                bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})  # fmt: skip


_SUPERSCRIPTS = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


class PlainLogFormatter(LogFormatter):
    """The labels of a log axis as plain text: 10⁻⁸ and 2×10⁻⁹ (4 and 20 from 1 to 1000), the
    ticks labelled being those matplotlib's own formatter labels. Its labels are mathtext,
    whose parser was half of drawing plot.png."""

    def __call__(self, x, pos=None) -> str:
        if not super().__call__(x, pos):  # a tick left unlabelled
            return ""
        exponent = math.floor(math.log10(abs(x)) + 1e-9)
        coeff = round(abs(x) / 10.0**exponent, 6)
        if 0 <= exponent <= 3:
            return self.fix_minus(f"{x:g}")
        power = f"10{str(exponent).translate(_SUPERSCRIPTS)}"
        sign = self.fix_minus("-") if x < 0 else ""
        return sign + (power if coeff == 1 else f"{coeff:g}\u00d7{power}")


def plain_log_labels(axis) -> None:
    """``axis`` (a log one) labelled by ``PlainLogFormatter``, its major and minor ticks."""
    axis.set_major_formatter(PlainLogFormatter(labelOnlyBase=False))
    axis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=False))


def draw_interval(ax, x, estimate, low, high, fmt: str, *, color, capsize: float = 3, label=None, **line) -> None:
    """Each estimate (joined as ``fmt`` says) with its interval drawn from its low end to its
    high end, wherever the estimate lies: a bootstrap's percentile interval need not contain
    its estimate (a small ensemble), and error bars measured from the estimate would then
    have a negative length. A missing end (NaN) draws no interval."""
    x, estimate, low, high = (np.asarray(v, dtype=float) for v in (x, estimate, low, high))
    ax.errorbar(x, (low + high) / 2, yerr=np.abs(high - low) / 2, fmt="none", ecolor=color, capsize=capsize,
                elinewidth=line.get("lw"))  # fmt: skip
    ax.plot(x, estimate, fmt, color=color, label=label, **line)


def plot_curve(figure: CurveFigure, fh) -> None:
    """plot.png: ``figure``'s curve and fit above, the points in contact below, on a shared f axis."""
    fig = Figure(figsize=(6.4, 5.6))  # fixed margins: a constrained layout would take 60% of the drawing time
    ax, ax_count = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.2]})
    fig.subplots_adjust(left=0.12, right=0.97, bottom=0.1, top=0.94, hspace=0.06)
    draw_curve(ax, figure.f, figure.xi, figure.xi_sem, figure.fit, done=figure.done, caveats=figure.caveats)
    title = wrap_title(figure.title, 6.4, 10)
    ax.set_title(title, fontsize=10, y=1.0)  # placed, not fitted above the tick labels that the shared x axis hides
    fig.subplots_adjust(top=0.94 - 0.03 * title.count("\n"))  # a long name: the title's lines inside the figure
    ax_count.plot(figure.f, figure.contact_count, "-", color="C2")
    ax_count.set_yscale("log")
    plain_log_labels(ax_count.yaxis)
    ax_count.set_ylabel("points in contact")
    label = wrap_title(figure.f_label, 6.4 * 0.85, 8)  # a map's definition is wider than the figure
    ax_count.set_xlabel(label, fontsize=8)
    fig.subplots_adjust(bottom=0.1 + 0.025 * label.count("\n"))
    ax_count.grid(True, which="both", alpha=0.3)
    for each in (ax, ax_count):
        ticks_in_view(each)
    with rc_context(UNHINTED):
        fig.savefig(fh, format="png", dpi=110, pil_kwargs=FAST_PNG)


def ticks_in_view(ax) -> None:
    """The ticks of ``ax`` (its data all in) only where they show: its limits kept as
    autoscaled, and its locators' ticks outside them dropped. Matplotlib makes a tick (three
    lines, two labels) at each location its locators give, a log axis's minor ones up to a
    decade beyond each end, and skips those outside as it draws: plot.png made 83 ticks and
    drew 36, a fifth of drawing it."""
    for axis, set_limits in ((ax.xaxis, ax.set_xlim), (ax.yaxis, ax.set_ylim)):
        low, high = axis.get_view_interval()  # autoscales now
        scale = axis.get_transform()
        ends = np.sort(scale.transform(np.array([low, high], dtype=float)))
        set_limits(low, high)  # fixed ticks would not follow a later autoscale
        pad = 1e-6 * (ends[1] - ends[0])  # a superset of the ticks matplotlib draws (its tolerance: 1e-10)
        for get, set_locator in ((axis.get_major_locator, axis.set_major_locator),
                                 (axis.get_minor_locator, axis.set_minor_locator)):  # fmt: skip
            locs = np.asarray(get()(), dtype=float)
            at = scale.transform(locs) if locs.size else locs
            set_locator(FixedLocator(locs[(at >= ends[0] - pad) & (at <= ends[1] + pad)]))


def _numeric(values) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def wrap_title(title: str, width_inches: float, fontsize: float) -> str:
    """``title`` broken into lines that fit a figure ``width_inches`` wide (a character
    is about 0.6 of the font size wide), so that none is clipped at the edges."""
    return textwrap.fill(title, max(20, int(width_inches * 72 / (0.6 * fontsize))), break_on_hyphens=False)


def plot_sweep(sweep, rows: list[dict[str, Any]], fh, dpi: int = 90) -> None:
    """sweep.png (``sweep_figure``)."""
    sweep_figure(sweep, rows).savefig(fh, format="png", dpi=dpi)


def sweep_figure(sweep, rows: list[dict[str, Any]], make=Figure) -> Figure:
    """a and b (rows of panels) against each swept parameter (columns), each axis
    named by what it is (``sweep.axis_label``), with their bootstrap intervals; in a
    grid the other parameters' values make the series. ``make``: pyplot.figure for a
    figure a notebook shows."""
    paths = sweep.paths
    width = 4.2 * len(paths)
    fig = make(figsize=(width, 5.6), layout="constrained")
    axes = fig.subplots(2, len(paths), squeeze=False)
    done = [r for r in rows if r["a"] is not None]
    for col, path in enumerate(paths):
        xs_all = [r[path] for r in done]
        numeric = _numeric(xs_all)
        order = sorted({repr(x) for x in xs_all})  # categorical positions when not numeric
        others = [p for p in paths if p != path]
        series: dict[str, list] = {}
        for r in done:
            key = ", ".join(f"{sweep.axis_label(p)} = {r[p]}" for p in others)
            series.setdefault(key, []).append(r)
        for row, coef in enumerate(("a", "b")):
            ax = axes[row][col]
            for i, (key, members) in enumerate(series.items()):
                members = sorted(members, key=lambda r: r[path] if numeric else repr(r[path]))
                x = [m[path] if numeric else order.index(repr(m[path])) for m in members]
                ends = [[math.nan if m[f"{coef}_{end}"] is None else m[f"{coef}_{end}"] for m in members] for end in ("lo", "hi")]
                draw_interval(ax, x, [m[coef] for m in members], *ends, "o-", ms=4, color=f"C{i}", label=key or None)
            if not numeric:
                ax.set_xticks(range(len(order)), [o.strip("'") for o in order], rotation=20, fontsize=8)
            elif sweep.spec.parameters[path].spacing == "log" and min(xs_all, default=1) > 0:
                ax.set_xscale("log")
                plain_log_labels(ax.xaxis)
            ax.set_ylabel(coef)
            ax.grid(True, alpha=0.3)
            if row == 1:
                ax.set_xlabel(sweep.axis_label(path))
            if any(series) and row == 0 and col == 0 and len(series) > 1:
                ax.legend(fontsize=7)
    title = f"{sweep.name}: xi = a + b ln f per point (95% bootstrap intervals)"
    fig.suptitle(wrap_title(title, width, 10), fontsize=10)
    return fig
