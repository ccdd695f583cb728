"""The figures of the exact 3D law (matplotlib, headless)."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")  # headless servers: never ask for a display

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import ScalarFormatter  # noqa: E402
import numpy as np  # noqa: E402

from ..plot import draw_interval  # noqa: E402
from .analysis import FEW_SPOTS, KAPPA_BUSH, KAPPA_PERSSON, KAPPA_SIMULATIONS, KAPPA_WINDOW  # noqa: E402
from .numbers import Numbers  # noqa: E402
from .plan import BROAD, MAIN, SIDE, StudyRuns  # noqa: E402

EXACT, APPROX, SIDE_COLOR, BROAD_COLOR = "C0", "C3", "0.45", "C1"


def _legend(ax, **options) -> None:
    """A legend where the panel has labelled artists (a panel of an H with nothing finished has none)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(**options)


def _shades(count: int) -> list:
    """Lighter for coarser grids, the finest darkest."""
    return [plt.cm.Blues(x) for x in np.linspace(0.35, 1.0, count)]


def _panels(count: int, width: float = 13, height: float = 7.5):
    """Up to three panels a row, as many rows as ``count`` needs (``width`` x ``height``: two full rows)."""
    columns, rows = min(max(count, 1), 3), max(1, math.ceil(count / 3))
    fig, axes = plt.subplots(rows, columns, figsize=(width * columns / 3, height * rows / 2), layout="constrained",
                             squeeze=False)  # fmt: skip
    for extra in axes.flat[count:]:
        extra.set_visible(False)
    return fig, axes.flat


def plot_xi_against_f(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """One panel per H: the exact mean xi(f) of the main family on every regular grid, on
    the surfaces all of them ran, the fitted law of the finest (its whole ensemble), MDR
    on the same surfaces, and the comparison family (long cut-off = side); the last
    panel: the surfaces' height skewness in both families."""
    hursts = runs.hursts()
    fig, axes = _panels(len(hursts) + 1)
    for ax, hurst in zip(axes, hursts):
        grids = [e for e in runs.exact_grids(hurst) if e.folder.name in numbers.paired]
        for e, color in zip(grids, _shades(len(grids))):
            p = numbers.paired[e.folder.name]
            ax.errorbar(e.outcome.f, p.xi, yerr=p.xi_half, fmt="o", ms=3, color=color, capsize=1.5, lw=0.8,
                        label=f"exact, {e.points}² px ({e.pixels_per_short_cutoff:g} px on λs), same {p.surfaces} surf.")  # fmt: skip
        finest = runs.find(hurst)
        fit = finest.outcome.fit
        grid = np.geomspace(finest.outcome.f.min(), finest.outcome.f.max(), 100)
        ax.plot(grid, fit.a + fit.b * np.log(grid), "-", color=EXACT,
                label=f"fit, {finest.points}²: a = {fit.a:.3f}, b = {fit.b:.4f}")  # fmt: skip
        mdr = runs.find(hurst, exact=False)
        o = mdr.outcome
        ax.errorbar(o.f, o.xi, yerr=1.96 * o.xi_sem, fmt="s--", ms=3, color=APPROX, capsize=1.5, lw=0.8,
                    label=f"MDR, {o.done} lines ({runs.plan.mdr_lines} per surface), {mdr.points}²")  # fmt: skip
        for side in runs.exact_grids(hurst, SIDE)[-1:]:
            o = side.outcome
            ax.errorbar(o.f, o.xi, yerr=1.96 * o.xi_sem, fmt="^:", ms=3, color=SIDE_COLOR, capsize=1.5, lw=0.8,
                        label=f"exact, long cut-off = side, {side.points}², {o.done} surf.")  # fmt: skip
        ax.set_xscale("log")
        ax.set_title(f"H = {hurst:g}", fontsize=10)
        ax.set_xlabel("f = F / (E* h L),  L = 2 √(A/π)")
        ax.set_ylabel("ξ = rms |∇z| in contact / rms |∇z|")
        ax.grid(True, which="both", alpha=0.3)
        _legend(ax, fontsize=6, loc="best")
    ax = axes[len(hursts)]
    for family, marker, color, shift in ((MAIN, "o", EXACT, -0.012), (SIDE, "^", SIDE_COLOR, 0.012)):
        label = {MAIN: "long cut-off = side / 4 (main)", SIDE: "long cut-off = side"}[family]
        for hurst in runs.plan.hursts:
            stats = numbers.stats.get((family, hurst))
            if stats is not None:  # the family's first H that ran carries its label
                ax.plot(np.full(stats.skewness.size, hurst + shift), stats.skewness, marker, ms=3, color=color,
                        alpha=0.6, label=label)  # fmt: skip
                label = None
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("H")
    ax.set_ylabel("height skewness of each surface")
    ax.set_title("do the surfaces self-average? (Gaussian: 0)", fontsize=10)
    ax.grid(True, alpha=0.3)
    _legend(ax, fontsize=7)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_kappa(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """One panel per H: kappa = (A/A0) E* rms|∇z| / p against p / (E* rms|∇z|) from the
    corrected area on each regular grid of the main family, on the surfaces all of them
    ran (95 % bootstrap band), the pixel count's
    on the finest, the comparison family's; the literature as lines and a band; the loads
    of a few spots shaded."""
    hursts = runs.hursts()
    fig, axes = _panels(len(hursts))
    for ax, hurst in zip(axes, hursts):
        grids = [e for e in runs.exact_grids(hurst) if e.folder.name in numbers.paired]
        for e, color in zip(grids, _shades(len(grids))):
            p = numbers.paired[e.folder.name]
            c = p.kappa
            ax.fill_between(c.x, c.low, c.high, color=color, alpha=0.25, lw=0)
            ax.plot(c.x, c.value, "o-", ms=2.5, lw=0.9, color=color,
                    label=f"{e.points}² ({e.pixels_per_short_cutoff:g} px on λs), same {p.surfaces} surf., corrected area")  # fmt: skip
        finest = runs.find(hurst)
        k = numbers.kappa(finest)
        ax.plot(k.raw_curve.x, k.raw_curve.value, "x--", ms=3, lw=0.8, color=EXACT,
                label=f"{finest.points}², pixel count")  # fmt: skip
        for side in runs.exact_grids(hurst, SIDE)[-1:]:
            c = numbers.kappa(side).curve
            ax.plot(c.x, c.value, "^:", ms=3, lw=0.9, color=SIDE_COLOR, label=f"long cut-off = side, {side.points}²")
        few = k.curve.x[k.curve.fraction <= FEW_SPOTS[1]]
        if few.size:
            ax.axvspan(k.curve.x.min() * 0.9, few.max() * 1.1, color="0.9", zorder=0, label="< 0.3 % contact: few spots")
        window = k.curve.x[(k.curve.fraction > KAPPA_WINDOW[0]) & (k.curve.fraction <= KAPPA_WINDOW[1])]
        if window.size:
            ax.fill_between([window.min(), window.max()], *KAPPA_SIMULATIONS, color="C2", alpha=0.2, lw=0,
                            label="simulations, 0.5-5 % contact: 2 to 2.3")  # fmt: skip
        ax.axhline(KAPPA_BUSH, color="k", ls="--", lw=0.8, label="√(2π) = 2.51, vanishing load")
        ax.axhline(KAPPA_PERSSON, color="k", ls=":", lw=0.8, label="√(8/π) = 1.60, Persson's theory")
        ax.set_xscale("log")
        ax.set_ylim(1.4, min(4.5, max(3.0, float(np.nanmax([*k.curve.high, *k.raw_curve.value])) * 1.05)))
        ax.set_title(f"H = {hurst:g}", fontsize=10)
        ax.set_xlabel("p / (E* rms|∇z|)")
        ax.set_ylabel("κ = (A/A0) E* rms|∇z| / p")
        ax.grid(True, which="both", alpha=0.3)
        _legend(ax, fontsize=5.5, loc="upper right")
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_convergence(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """a, b and kappa (0.5-5 % contact, corrected area) of the main family against the
    pixels on the short cut-off, per H, on the surfaces every grid ran (paired: like with
    like), with 95 % bootstrap intervals (open: fewer than 16 pixels, not quoted); the
    Richardson limit at the right (diamond; hollow where the order was not estimated)."""
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), layout="constrained")
    for i, (hurst, c) in enumerate(sorted(numbers.convergence.items())):
        x = np.array([e.pixels_per_short_cutoff for e in c.grids]) * (1 + 0.04 * (i - 2))
        quoted = np.array([e.quoted for e in c.grids])
        for ax, q in zip(axes, c.quantities.values()):
            draw_interval(ax, x, q.values, q.low, q.high, "-", capsize=2, color=f"C{i}", lw=0.9)
            ax.plot(x[quoted], q.values[quoted], "o", ms=4, color=f"C{i}", label=f"H = {hurst:g}, {c.surfaces} surf.")
            ax.plot(x[~quoted], q.values[~quoted], "o", ms=4, mfc="white", color=f"C{i}")
            if q.limit is not None and all(map(np.isfinite, q.limit.interval)):
                low, high = q.limit.interval
                draw_interval(ax, [x[-1] * 2.2], [q.limit.limit], [low], [high], "D", ms=4, capsize=2, color=f"C{i}",
                              mfc=f"C{i}" if q.limit.estimated else "white")  # fmt: skip
    for ax, name in zip(axes, ("a", "b", "κ")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("pixels on the short cut-off λs (diamonds: Richardson limit)")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.set_ylabel({"a": "a of ξ = a + b ln f", "b": "b of ξ = a + b ln f",
                       "κ": "κ at 0.5-5 % contact (corrected area)"}[name])  # fmt: skip
        ax.grid(True, which="both", alpha=0.3)
        _legend(ax, fontsize=7)
    fig.suptitle("the same surfaces on every grid; open circles: fewer than 16 pixels on λs, not quoted", fontsize=9)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def _finest(runs: StudyRuns, hurst: float, family: str):
    grids = runs.exact_grids(hurst, family)
    return grids[-1] if grids else None


def plot_gradient(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """Per H: g_r / g (left axis family colours) and kappa, kappa_r against p / (E* g) on
    the finest grid of the main and the broad-band family, with 95 % bootstrap bands."""
    hursts = [h for h in runs.plan.hursts if (e := _finest(runs, h, MAIN)) is not None and e.folder.name in numbers.gradients]
    fig, axes = plt.subplots(2, max(1, len(hursts)), figsize=(3.2 * max(1, len(hursts)), 6.5), layout="constrained",
                             squeeze=False)  # fmt: skip
    for column, hurst in enumerate(hursts):
        top, bottom = axes[0][column], axes[1][column]
        for family, color in ((MAIN, EXACT), (BROAD, BROAD_COLOR)):
            e = _finest(runs, hurst, family)
            g = numbers.gradients.get(e.folder.name) if e is not None else None
            if g is None:
                continue
            label = f"{'main' if family == MAIN else 'broad band'}, {e.points}²"
            for ax, est, style, name in ((top, g.ratio, "o-", "g_r / g"), (bottom, g.kappa, "o-", "κ"),
                                         (bottom, g.kappa_r, "s--", "κ_r")):  # fmt: skip
                ax.fill_between(g.x, est.interval[0], est.interval[1], color=color, alpha=0.2, lw=0)
                ax.plot(g.x, est.value, style, ms=2.5, lw=0.9, color=color, label=f"{name}, {label}")
        bottom.axhline(KAPPA_BUSH, color="k", ls="--", lw=0.7)
        for ax in (top, bottom):
            ax.set_xscale("log")
            ax.grid(True, which="both", alpha=0.3)
            _legend(ax, fontsize=6)
        top.set_title(f"H = {hurst:g}", fontsize=10)
        top.set_ylabel("g_r / g (rms gradient in contact / overall)")
        bottom.set_ylabel("κ and κ_r")
        bottom.set_xlabel("p / (E* g)")
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_nayak(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """kappa (0.5-5 % contact, corrected area, 95 % interval) on the finest grid of each
    family against the family's mean Nayak parameter, per H; the literature's band."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
    for i, hurst in enumerate(runs.plan.hursts):
        for family, marker in ((MAIN, "o"), (BROAD, "D"), (SIDE, "^")):
            e, stats = _finest(runs, hurst, family), numbers.stats.get((family, hurst))
            if e is None or stats is None:
                continue
            k = numbers.kappa(e).corrected
            if np.isfinite(k.value):
                draw_interval(ax, [np.mean(stats.nayak)], [k.value], [k.interval[0]], [k.interval[1]], marker,
                              color=f"C{i}", capsize=2, ms=5, label=f"H = {hurst:g}" if family == MAIN else None)
    ax.axhspan(*KAPPA_SIMULATIONS, color="C2", alpha=0.15, label="simulations of broad spectra, 0.5-5 %: 2 to 2.3")
    ax.axhline(KAPPA_BUSH, color="k", ls="--", lw=0.8, label="√(2π), vanishing load")
    ax.set_xscale("log")
    for axis_formatter in (ax.xaxis.set_major_formatter, ax.xaxis.set_minor_formatter):
        axis_formatter(ScalarFormatter())  # α spans a decade or so: 4, 6, 10, 20, not 4×10⁰
    ax.set_xlabel("Nayak parameter α (mean over the surfaces)")
    ax.set_ylabel("κ at 0.5-5 % contact")
    ax.set_title("o main (side / 4), ◇ broad band, △ long cut-off = side", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    _legend(ax, fontsize=6)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_few_spots(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """Per H, the finest grid of the main family: the mean number of contact spots per
    surface and the corrected area against f (log-log, with f^(2/3) and f^1 guides: f is F
    in its own unit), and the local exponent d ln A / d ln f; the few-spot loads shaded."""
    hursts = [h for h in runs.plan.hursts if (e := _finest(runs, h, MAIN)) is not None and e.folder.name in numbers.spots]
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), layout="constrained")
    for i, hurst in enumerate(hursts):
        s = numbers.spots[_finest(runs, hurst, MAIN).folder.name]
        label = f"H = {hurst:g}, {s.ensemble.points}²"
        f = s.force / s.ensemble.outcome.force_unit
        axes[0].plot(f, s.spots, "o-", ms=3, color=f"C{i}", label=label)
        axes[1].plot(f, s.area, "o-", ms=3, color=f"C{i}", label=label)
        axes[2].plot(np.sqrt(f[1:] * f[:-1]), s.exponent, "o-", ms=3, color=f"C{i}", label=label)
        if s.few.any():
            for ax in axes:
                ax.axvspan(f.min(), f[s.few].max(), color=f"C{i}", alpha=0.06, lw=0)
    if hursts:
        s = numbers.spots[_finest(runs, hursts[0], MAIN).folder.name]
        f = s.force / s.ensemble.outcome.force_unit
        f0, a0 = f[0], s.area[0]
        grid = np.geomspace(f.min(), f.max(), 50)
        axes[1].plot(grid, a0 * (grid / f0) ** (2 / 3), "k:", lw=0.8, label="∝ f^(2/3): isolated Hertzian spots")
        axes[1].plot(grid, a0 * (grid / f0), "k--", lw=0.8, label="∝ f")
    axes[2].axhline(2 / 3, color="k", ls=":", lw=0.8)
    axes[2].axhline(1.0, color="k", ls="--", lw=0.8)
    for ax, ylabel, log in ((axes[0], "contact spots per surface", True), (axes[1], "A / A0 (corrected)", True),
                            (axes[2], "d ln A / d ln f", False)):  # fmt: skip
        ax.set_xscale("log")
        if log:
            ax.set_yscale("log")
        ax.set_xlabel("f = F / (E* h L)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        _legend(ax, fontsize=6)
    fig.suptitle("shaded: fewer than 10 spots per surface, where the finite surface stops standing for an infinite one",
                 fontsize=9)  # fmt: skip
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)
