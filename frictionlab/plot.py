"""The figures of a run and of a sweep (matplotlib, headless): plot.png, xi against f on a
log axis with the fitted law, like the source paper's figures; sweep.png, a and b per point."""

from __future__ import annotations

from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless servers: never ask for a display

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .ensemble import RunOutcome  # noqa: E402
from .preset import Scene  # noqa: E402


def plot_curve(scene: Scene, outcome: RunOutcome, fh) -> None:
    fig, (ax, ax_count) = plt.subplots(
        2, 1, figsize=(6.4, 5.6), sharex=True, gridspec_kw={"height_ratios": [3, 1.2]}, layout="constrained"
    )
    f, xi, sem = outcome.f, outcome.xi, outcome.xi_sem
    ax.fill_between(f, xi - 1.96 * sem, xi + 1.96 * sem, color="C0", alpha=0.25, lw=0, label="95% band of the mean")
    ax.plot(f, xi, "o", ms=2.5, color="C0", label=f"mean over {outcome.done} realizations")
    fit = outcome.fit
    if fit is not None:
        grid = np.geomspace(f.min(), f.max(), 200)
        ax.plot(
            grid,
            fit.a + fit.b * np.log(grid),
            "-",
            color="C3",
            label=f"fit a + b ln f: a = {fit.a:.4f}, b = {fit.b:.4f}, R² = {fit.r2:.3f}",
        )
    ax.set_xscale("log")
    ax.set_ylabel(r"$\xi = \nabla z_{contact} / \nabla z$")
    ax.set_title(f"{scene.preset.name}: {scene.generator.name}, {scene.solver.name}, {scene.slope.name}", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    ax.grid(True, which="both", alpha=0.3)
    ax_count.plot(f, outcome.contact_count, "-", color="C2")
    ax_count.set_yscale("log")
    ax_count.set_ylabel("points in contact")
    ax_count.set_xlabel(scene.normalisation.definition, fontsize=8)
    ax_count.grid(True, which="both", alpha=0.3)
    fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)


def _numeric(values) -> bool:
    return all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)


def plot_sweep(sweep, rows: list[dict[str, Any]], fh, dpi: int = 90) -> None:
    """sweep.png: a and b (rows of panels) against each swept parameter (columns),
    with their bootstrap intervals; in a grid the other parameters' values make the series."""
    paths = sweep.paths
    fig, axes = plt.subplots(2, len(paths), figsize=(4.2 * len(paths), 5.6), squeeze=False, layout="constrained")
    done = [r for r in rows if r["a"] is not None]
    for col, path in enumerate(paths):
        xs_all = [r[path] for r in done]
        numeric = _numeric(xs_all)
        order = sorted({repr(x) for x in xs_all})  # categorical positions when not numeric
        others = [p for p in paths if p != path]
        series: dict[str, list] = {}
        for r in done:
            key = ", ".join(f"{p.rsplit('.', 1)[-1]}={r[p]}" for p in others)
            series.setdefault(key, []).append(r)
        for row, coef in enumerate(("a", "b")):
            ax = axes[row][col]
            for i, (key, members) in enumerate(series.items()):
                members = sorted(members, key=lambda r: r[path] if numeric else repr(r[path]))
                x = [m[path] if numeric else order.index(repr(m[path])) for m in members]
                y = [m[coef] for m in members]
                lo = [m[coef] - m[f"{coef}_lo"] if m[f"{coef}_lo"] is not None else 0 for m in members]
                hi = [m[f"{coef}_hi"] - m[coef] if m[f"{coef}_hi"] is not None else 0 for m in members]
                ax.errorbar(x, y, yerr=[lo, hi], fmt="o-", ms=4, capsize=3, color=f"C{i}", label=key or None)
            if not numeric:
                ax.set_xticks(range(len(order)), [o.strip("'") for o in order], rotation=20, fontsize=8)
            elif sweep.spec.parameters[path].spacing == "log" and min(xs_all, default=1) > 0:
                ax.set_xscale("log")
            ax.set_ylabel(coef)
            ax.grid(True, alpha=0.3)
            if row == 1:
                ax.set_xlabel(path)
            if any(series) and row == 0 and col == 0 and len(series) > 1:
                ax.legend(fontsize=7)
    fig.suptitle(f"{sweep.name}: xi = a + b ln f per point (95% bootstrap intervals)", fontsize=10)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)
