"""The figures of the exact 3D law (matplotlib, headless)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")  # headless servers: never ask for a display

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .plan import StudyRuns  # noqa: E402

EXACT, APPROX = "C0", "C3"


def _shades(count: int) -> list:
    """Lighter for coarser grids, the finest darkest."""
    return [plt.cm.Blues(x) for x in np.linspace(0.35, 1.0, count)]


def plot_xi_against_f(runs: StudyRuns, fh, kappas: dict, dpi: int = 90) -> None:
    """One panel per H: the exact mean xi(f) on every grid, the fitted law of the finest,
    MDR on the same surfaces (finest grid); the last panel: kappa per grid and H."""
    hursts = runs.plan.hursts
    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5), layout="constrained")
    for ax, hurst in zip(axes.flat, hursts):
        grids = runs.exact_grids(hurst)
        for e, color in zip(grids, _shades(len(grids))):
            o = e.outcome
            ax.errorbar(o.f, o.xi, yerr=1.96 * o.xi_sem, fmt="o", ms=3, color=color, capsize=1.5, lw=0.8,
                        label=f"exact, {e.points}² px ({e.pixels_per_short_cutoff:g} px on λs), {o.done} surf.")  # fmt: skip
        finest = runs.find(hurst)
        fit = finest.outcome.fit
        grid = np.geomspace(finest.outcome.f.min(), finest.outcome.f.max(), 100)
        ax.plot(grid, fit.a + fit.b * np.log(grid), "-", color=EXACT,
                label=f"fit: a = {fit.a:.3f}, b = {fit.b:.3f}, R² = {fit.r2:.2f}")  # fmt: skip
        mdr = runs.find(hurst, exact=False)
        if mdr is not None:
            o = mdr.outcome
            ax.errorbar(o.f, o.xi, yerr=1.96 * o.xi_sem, fmt="s--", ms=3, color=APPROX, capsize=1.5, lw=0.8,
                        label=f"MDR on the same surfaces ({mdr.points}² px), a = {o.fit.a:.3f}, b = {o.fit.b:.3f}")  # fmt: skip
        ax.set_xscale("log")
        ax.set_title(f"H = {hurst:g} (Nayak α = {finest.nayak:.0f})", fontsize=10)
        ax.set_xlabel("f = F / (E* h L),  L = 2 √(A/π)")
        ax.set_ylabel("ξ = rms |∇z| in contact / rms |∇z|")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6.5, loc="best")
    ax = axes.flat[len(hursts)]
    for i, hurst in enumerate(hursts):
        rows = [(e.pixels_per_short_cutoff, kappas[(e.hurst, e.points)]) for e in runs.exact_grids(hurst)]
        x = np.array([r[0] for r in rows]) * (1 + 0.04 * (i - 2))
        value = np.array([r[1].value for r in rows])
        low = np.array([r[1].interval[0] for r in rows])
        high = np.array([r[1].interval[1] for r in rows])
        ax.errorbar(x, value, yerr=[value - low, high - value], fmt="o-", ms=3, capsize=2, label=f"H = {hurst:g}")
    ax.axhspan(1.6, 2.0, color="0.85", label="literature: 1.6 (Persson) to 2 (simulations)")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("pixels on the short cut-off λs")
    ax.set_ylabel("κ = (A/A0) E* rms|∇z| / p, small loads")
    ax.set_title("contact area law at small loads, per grid", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6.5)
    for extra in axes.flat[len(hursts) + 1 :]:
        extra.set_visible(False)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_convergence(runs: StudyRuns, fh, dpi: int = 90) -> None:
    """a and b of the exact law (95 % bootstrap intervals) against the pixels on the
    short cut-off, per H, with MDR's on the finest grid at the right."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for i, hurst in enumerate(runs.plan.hursts):
        grids = runs.exact_grids(hurst)
        x = np.array([e.pixels_per_short_cutoff for e in grids]) * (1 + 0.04 * (i - 2))
        for ax, name in zip(axes, ("a", "b")):
            value = np.array([getattr(e.outcome.fit, name) for e in grids])
            ci = np.array([getattr(e.outcome.fit, f"{name}_ci") for e in grids])
            ax.errorbar(x, value, yerr=[value - ci[:, 0], ci[:, 1] - value], fmt="o-", ms=3, capsize=2,
                        color=f"C{i}", label=f"H = {hurst:g}")  # fmt: skip
            mdr = runs.find(hurst, exact=False)
            if mdr is not None:
                ax.plot(x[-1] * 1.5, getattr(mdr.outcome.fit, name), "s", mfc="none", color=f"C{i}")
    for ax, name in zip(axes, ("a", "b")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("pixels on the short cut-off λs (open squares: MDR, finest grid)")
        ax.set_ylabel(f"{name} of ξ = a + b ln f")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)
