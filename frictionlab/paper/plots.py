"""The report's figures: xi(f) of Figs. 2 to 4 on the paper's axes, a and b against H (Fig. 5)."""

from __future__ import annotations

import numpy as np

from matplotlib.figure import Figure

from ..plot import draw_interval
from .figures import PAPER_H07, PAPER_POINTS_VS_H, FigureRun
from .readings import ReadingRow

FIGURE_MARK = {"Software": "frictionlab report"}  # in each figure's PNG: what report --force may replace
F_UNIT = 1e-9  # the paper's f axis is in units of 1e-9


def plot_figure(run: FigureRun, fh, dpi: int = 90) -> None:
    """xi(f) on the paper's axes (f in units of 1e-9, log), the fit, the paper's law; counts below."""
    o, fig_info = run.outcome, run.figure
    fig = Figure(figsize=(6.0, 5.2), layout="constrained")
    ax, ax_n = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.3]})
    x = o.f / F_UNIT
    ax.fill_between(x, o.xi - 1.96 * o.xi_sem, o.xi + 1.96 * o.xi_sem, color="C0", alpha=0.25, lw=0,
                    label="95% band of the mean")  # fmt: skip
    ax.plot(x, o.xi, ".", ms=2, color="C0", label=f"frictionlab, mean of {o.done} lines")
    grid = np.geomspace(o.f.min(), o.f.max(), 200)
    if o.fit is not None:
        ax.plot(grid / F_UNIT, o.fit.a + o.fit.b * np.log(grid), "-", color="C3",
                label=f"frictionlab fit: {o.fit.a:.4f} + {o.fit.b:.4f} ln f")  # fmt: skip
    if fig_info.a is not None:
        ax.plot(grid / F_UNIT, fig_info.a + fig_info.b * np.log(grid), "--", color="k",
                label=f"paper: {fig_info.a} + {fig_info.b} ln f")  # fmt: skip
    ax.set_xscale("log")
    ax.set_ylabel(r"$\xi = \nabla z_{contact} / \nabla z$")
    ax.set_title(fig_info.title, fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)
    ax_n.plot(x, o.contact_count, "-", color="C2", label="frictionlab")
    if fig_info.counts:
        scale = o.f[0] / o.force[0]
        forces = list(fig_info.counts)
        ax_n.plot([F * scale / F_UNIT for F in forces], list(fig_info.counts.values()), "kx", ms=8, mew=2, label="paper")
    ax_n.set_ylabel("points in contact")
    ax_n.set_xlabel(r"$f = F / (E^* h L)$ in units of $10^{-9}$")
    ax_n.grid(True, which="both", alpha=0.3)
    ax_n.legend(fontsize=7, loc="upper left")
    fig.savefig(fh, format="png", dpi=dpi, metadata=FIGURE_MARK)


def _sweep_series(run: FigureRun) -> dict:
    """The Fig. 5 sweep's finished points as arrays: H, and each coefficient with its interval."""
    path = run.sweep.paths[0]
    rows = [r for r in run.sweep_outcome.rows if r["a"] is not None]
    series = {"H": np.array([r[path] for r in rows], float)}
    for coef in ("a", "b"):
        series[coef] = np.array([[r[coef], r[f"{coef}_lo"], r[f"{coef}_hi"]] for r in rows], float).reshape(-1, 3)
    return series


def _calibrated_series(rows: list[ReadingRow]) -> dict:
    """The same arrays from the per-H calibrated readings of Fig. 5."""
    return {"H": np.array([r.hurst() for r in rows], float),
            "a": np.array([[r.fit.a, *r.fit.a_ci] for r in rows], float).reshape(-1, 3),
            "b": np.array([[r.fit.b, *r.fit.b_ci] for r in rows], float).reshape(-1, 3)}  # fmt: skip


def _plot_against_h(axes, series, label: str, color: str, offset: float = 0.0) -> None:
    """a and b (with their intervals) against H on two axes."""
    for ax, coef in zip(axes, ("a", "b"), strict=True):
        y, low, high = series[coef].T
        draw_interval(ax, series["H"] + offset, y, low, high, "o-", ms=4, color=color, label=label)


def _mark_paper_against_h(axes) -> None:
    for ax, col in zip(axes, (1, 2), strict=True):
        ax.plot([PAPER_H07[0]], [PAPER_H07[col]], "*", ms=14, color="C3", label="paper, H ~ 0.7 (about)")
        ax.plot([p[0] for p in PAPER_POINTS_VS_H], [p[col] for p in PAPER_POINTS_VS_H], "ks", ms=6,
                label="paper, Figs. 2 and 4")  # fmt: skip
        ax.set_xlabel("Hurst exponent H")
        ax.set_ylabel("ab"[col - 1])
        ax.grid(True, alpha=0.3)


def plot_fig5(run: FigureRun, fh, dpi: int = 90) -> None:
    """a and b against H with intervals, the paper's points marked."""
    fig = Figure(figsize=(8.4, 3.6), layout="constrained")
    axes = fig.subplots(1, 2)
    _plot_against_h(axes, _sweep_series(run), "frictionlab (95% CI)", "C0")
    _mark_paper_against_h(axes)
    axes[0].legend(fontsize=7)
    fig.suptitle("Fig. 5: xi = a + b ln f against H (each point as Fig. 2, h = 1e4)", fontsize=10)
    fig.savefig(fh, format="png", dpi=dpi, metadata=FIGURE_MARK)


def plot_fig5_calibrated(run: FigureRun, rows: list[ReadingRow], fh, dpi: int = 90) -> None:
    """a and b against H with h = 1e4 and with h calibrated at each H, the paper's
    points marked; a third panel shows the calibrated h."""
    fig = Figure(figsize=(11.4, 3.6), layout="constrained")
    axes = fig.subplots(1, 3)
    _plot_against_h(axes[:2], _sweep_series(run), f"h = {run.preset_rms_height()} at every H (the preset)", "C0", offset=-0.006)
    _plot_against_h(axes[:2], _calibrated_series(rows), "h calibrated at each H to Fig. 2's counts", "C2", offset=0.006)
    _mark_paper_against_h(axes[:2])
    axes[0].legend(fontsize=7)
    axes[2].semilogy([r.hurst() for r in rows], [r.rms_height for r in rows], "o-", color="C2", ms=4)
    axes[2].axhline(float(run.preset_rms_height()), color="C0", ls="--", lw=1, label=f"h = {run.preset_rms_height()} (the preset)")
    axes[2].set_xlabel("Hurst exponent H")
    axes[2].set_ylabel("calibrated rms height h")
    axes[2].grid(True, which="both", alpha=0.3)
    axes[2].legend(fontsize=7)
    fig.suptitle("Fig. 5 with h calibrated at each H (counts 4 at F = 1, 12 at F = 20; 95% CI)", fontsize=10)
    fig.savefig(fh, format="png", dpi=dpi, metadata=FIGURE_MARK)
