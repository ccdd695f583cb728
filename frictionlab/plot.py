"""plot.png: xi against f on a log axis with the fitted law, like the study's figures."""

from __future__ import annotations

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
    ax.set_title(f"{scene.preset.name}: {scene.spectrum.name}, {scene.solver.name}, {scene.slope.name}", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    ax.grid(True, which="both", alpha=0.3)
    ax_count.plot(f, outcome.contact_count, "-", color="C2")
    ax_count.set_yscale("log")
    ax_count.set_ylabel("points in contact")
    ax_count.set_xlabel(scene.normalisation.definition, fontsize=8)
    ax_count.grid(True, which="both", alpha=0.3)
    fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)
