"""The figures of the exact 3D law (matplotlib, headless)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")  # headless servers: never ask for a display

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import ScalarFormatter  # noqa: E402
import numpy as np  # noqa: E402

from ..plot import draw_interval  # noqa: E402
from .analysis import FEW_SPOTS, KAPPA_BUSH, KAPPA_PERSSON, KAPPA_SIMULATIONS, KAPPA_WINDOW  # noqa: E402
from .numbers import Numbers  # noqa: E402
from .plan import MAIN, SIDE, StudyRuns  # noqa: E402

EXACT, APPROX, SIDE_COLOR = "C0", "C3", "0.45"


def _shades(count: int) -> list:
    """Lighter for coarser grids, the finest darkest."""
    return [plt.cm.Blues(x) for x in np.linspace(0.35, 1.0, count)]


def _panels(count: int, width: float = 13, height: float = 7.5):
    fig, axes = plt.subplots(2, 3, figsize=(width, height), layout="constrained")
    for extra in axes.flat[count:]:
        extra.set_visible(False)
    return fig, axes.flat


def plot_xi_against_f(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """One panel per H: the exact mean xi(f) of the main family on every grid, the fitted
    law of the finest, MDR on the same surfaces, and the comparison family (long cut-off
    = side); the last panel: the surfaces' height skewness in both families."""
    hursts = runs.hursts()
    fig, axes = _panels(len(hursts) + 1)
    for ax, hurst in zip(axes, hursts):
        grids = runs.exact_grids(hurst)
        for e, color in zip(grids, _shades(len(grids))):
            o = e.outcome
            ax.errorbar(o.f, o.xi, yerr=1.96 * o.xi_sem, fmt="o", ms=3, color=color, capsize=1.5, lw=0.8,
                        label=f"exact, {e.points}² px ({e.pixels_per_short_cutoff:g} px on λs), {o.done} surf.")  # fmt: skip
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
        ax.legend(fontsize=6, loc="best")
    ax = axes[len(hursts)]
    for family, marker, color, shift in ((MAIN, "o", EXACT, -0.012), (SIDE, "^", SIDE_COLOR, 0.012)):
        label = {MAIN: "long cut-off = side / 4 (main)", SIDE: "long cut-off = side"}[family]
        for i, hurst in enumerate(runs.plan.hursts):
            stats = numbers.stats.get((family, hurst))
            if stats is not None:
                ax.plot(np.full(stats.skewness.size, hurst + shift), stats.skewness, marker, ms=3, color=color,
                        alpha=0.6, label=label if i == 0 else None)  # fmt: skip
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("H")
    ax.set_ylabel("height skewness of each surface")
    ax.set_title("do the surfaces self-average? (Gaussian: 0)", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_kappa(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """One panel per H: kappa = (A/A0) E* rms|∇z| / p against p / (E* rms|∇z|) from the
    corrected area on each grid of the main family (95 % bootstrap band), the pixel count's
    on the finest, the comparison family's; the literature as lines and a band; the loads
    of a few spots shaded."""
    hursts = runs.hursts()
    fig, axes = _panels(len(hursts))
    for ax, hurst in zip(axes, hursts):
        grids = runs.exact_grids(hurst)
        for e, color in zip(grids, _shades(len(grids))):
            c = numbers.kappa(e).curve
            ax.fill_between(c.x, c.low, c.high, color=color, alpha=0.25, lw=0)
            ax.plot(c.x, c.value, "o-", ms=2.5, lw=0.9, color=color,
                    label=f"{e.points}² ({e.pixels_per_short_cutoff:g} px on λs), corrected area")  # fmt: skip
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
        ax.legend(fontsize=5.5, loc="upper right")
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_convergence(runs: StudyRuns, numbers: Numbers, fh, dpi: int = 90) -> None:
    """a, b and kappa (0.5-5 % contact, corrected area) of the main family with 95 %
    intervals against the pixels on the short cut-off, per H (open: fewer than 16, not
    quoted); MDR's a and b on the finest grid at the right."""
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), layout="constrained")
    for i, hurst in enumerate(runs.hursts()):
        grids = runs.exact_grids(hurst)
        x = np.array([e.pixels_per_short_cutoff for e in grids]) * (1 + 0.04 * (i - 2))
        rows = {
            "a": [(e.outcome.fit.a, *e.outcome.fit.a_ci) for e in grids],
            "b": [(e.outcome.fit.b, *e.outcome.fit.b_ci) for e in grids],
            "κ": [(numbers.kappa(e).corrected.value, *numbers.kappa(e).corrected.interval) for e in grids],
        }
        quoted = np.array([e.quoted for e in grids])
        for ax, (name, values) in zip(axes, rows.items()):
            value, low, high = np.array(values).T
            draw_interval(ax, x, value, low, high, "-", capsize=2, color=f"C{i}", lw=0.9)
            ax.plot(x[quoted], value[quoted], "o", ms=4, color=f"C{i}", label=f"H = {hurst:g}")
            ax.plot(x[~quoted], value[~quoted], "o", ms=4, mfc="white", color=f"C{i}")
            if name != "κ":
                mdr = runs.find(hurst, exact=False)
                ax.plot(x[quoted][-1] * 1.5 if quoted.any() else x[-1] * 1.5, getattr(mdr.outcome.fit, name), "s",
                        mfc="none", color=f"C{i}")  # fmt: skip
    for ax, name in zip(axes, ("a", "b", "κ")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("pixels on the short cut-off λs")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.set_ylabel({"a": "a of ξ = a + b ln f", "b": "b of ξ = a + b ln f",
                       "κ": "κ at 0.5-5 % contact (corrected area)"}[name])  # fmt: skip
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("open circles: fewer than 16 pixels on λs, not quoted; open squares: MDR on the finest grid", fontsize=9)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)
