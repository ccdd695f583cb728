"""``frictionlab report``: run the study's Figs. 2 to 5 and write REPRODUCTION.md
with its figures, the study's numbers beside frictionlab's.

With ``--readings`` it also runs readings of the study's method (cut-off,
amplitudes, slope estimator, averaging over realizations, normalisation per H)
and tabulates what each gives, and reruns Fig. 5 with h calibrated at each H
(``fig5_calibrated_readings``). Every reading is a preset plus ``--set``
options (printed in the table, so any row can be rerun with ``frictionlab run``),
except the averaging readings, which re-average the default run's
``realizations.npz`` (``average_curve``).
"""

from __future__ import annotations

import datetime
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import __version__, engine
from .errors import FrictionlabError
from .fit import least_squares
from .preset import apply_overrides, build_scene, load_preset_file
from .runner import run_to_folder
from .seeds import bootstrap_rng


@dataclass(frozen=True)
class StudyFigure:
    """What the study reports for one figure."""

    key: str
    preset: str  # file name in the presets folder
    title: str
    a: float | None
    b: float | None
    counts: dict[float, float] = field(default_factory=dict)  # force -> mean points in contact
    note: str = ""


STUDY = (
    StudyFigure("fig2", "benad2012-fig2.yaml", "Fig. 2: H = 1, F = 1..20", 1.8847, 0.0805, {1.0: 4.0, 20.0: 12.0}),
    StudyFigure("fig3", "benad2012-fig3.yaml", "Fig. 3: H = 1, F = 1..500", 1.5289, 0.0614, {500.0: 40.0}),
    StudyFigure("fig4", "benad2012-fig4.yaml", "Fig. 4: H = 0.5, F = 1..20", 2.6252, 0.1341, {},
                "the study: the log fit is visibly poorer than at H = 1; contact counts not stated"),
    StudyFigure("fig5", "benad2012-fig5.yaml", "Fig. 5: a and b against H, each point as Fig. 2", 2.9, 0.14, {},
                "the study: a about 2.9 and b about 0.14 near H = 0.7"),
)  # fmt: skip
STUDY_H07 = (0.7, 2.9, 0.14)  # H, a, b "about", as the study states them
STUDY_POINTS_VS_H = ((1.0, 1.8847, 0.0805, "Fig. 2"), (0.5, 2.6252, 0.1341, "Fig. 4"))
COUNT_TARGETS = {1.0: 4.0, 20.0: 12.0}  # the study's Fig. 2 contact counts, used to calibrate h


# ------------------------------------------------------------------ averaging readings

AVERAGES = {
    "mean": "mean of xi over realizations (the default)",
    "pooled": "rms slope over the contact points of all realizations pooled, over the pooled line rms slope",
    "rms": "root mean square of xi over realizations",
}


def average_curve(per: dict[str, np.ndarray], method: str, weights: np.ndarray | None = None) -> np.ndarray:
    """xi(F) from per-realization arrays (``realizations.npz``) by one reading of
    "averaged over realizations"; ``weights`` (M,) or (B, M) are bootstrap counts."""
    xi = np.asarray(per["xi"], float)  # (M, F)
    w = np.ones(xi.shape[0]) if weights is None else np.asarray(weights, float)
    if method == "mean":
        return (w @ xi) / w.sum(axis=-1)[..., None]
    if method == "rms":
        return np.sqrt((w @ xi**2) / w.sum(axis=-1)[..., None])
    if method == "pooled":
        n = np.asarray(per["contact_count"], float)  # (M, F)
        s2 = np.asarray(per["slope_rms_line"], float) ** 2  # (M,)
        contact_sq = n * xi**2 * s2[:, None]  # sum of squared slopes over each line's contact points
        line = (w @ s2) / w.sum(axis=-1)
        return np.sqrt((w @ contact_sq) / (w @ n) / np.asarray(line)[..., None])
    raise FrictionlabError(f"average must be one of {', '.join(AVERAGES)}. Got {method!r} instead.")


@dataclass(frozen=True)
class Refit:
    a: float
    b: float
    a_ci: tuple[float, float]
    b_ci: tuple[float, float]
    r2: float


def refit(f, per, method: str, *, bootstrap: int, confidence: float, seed: int) -> Refit:
    """Fit xi = a + b ln f to ``average_curve(per, method)``, with a percentile bootstrap
    over realizations drawn like the run's own (same stream, same resample counts):
    for ``mean`` this gives the run's summary numbers exactly."""
    coef, _, r2, _ = least_squares(f, average_curve(per, method))
    m = per["xi"].shape[0]
    counts = bootstrap_rng(seed).multinomial(m, np.full(m, 1.0 / m), size=bootstrap)
    curves = average_curve(per, method, counts)  # (B, F)
    design = np.column_stack([np.ones_like(f), np.log(f)])
    samples = curves @ np.linalg.pinv(design).T  # (B, 2)
    tail = 100 * (1 - confidence) / 2
    low, high = np.percentile(samples, [tail, 100 - tail], axis=0)
    return Refit(float(coef[0]), float(coef[1]), (low[0], high[0]), (low[1], high[1]), float(r2))


# ------------------------------------------------------------------ normalisation readings


@dataclass(frozen=True)
class CountCurve:
    """Mean contact count against F / h, from one ensemble at h = 1: with fixed
    amplitudes the count depends on F / (E* h) only, so this serves every h."""

    log_g: np.ndarray  # log(F / h)
    log_n: np.ndarray  # log(mean count), non-decreasing in log_g

    def mean_count(self, force: float, h: float) -> float:
        return math.exp(float(np.interp(math.log(force / h), self.log_g, self.log_n)))

    def rms_height_alone(self, force: float, count: float) -> float:
        """The h that gives ``count`` at ``force`` (the curve inverted)."""
        return force / math.exp(float(np.interp(math.log(count), self.log_n, self.log_g)))

    def fit_rms_height(self, targets: dict[float, float]) -> float:
        """Least squares in log count over the targets."""
        from scipy.optimize import minimize_scalar

        def misfit(log_h):
            return sum((np.interp(math.log(F) - log_h, self.log_g, self.log_n) - math.log(n)) ** 2 for F, n in targets.items())

        alone = [math.log(self.rms_height_alone(F, n)) for F, n in targets.items()]
        best = minimize_scalar(misfit, bounds=(min(alone) - 1e-9, max(alone) + 1e-9), method="bounded")
        return math.exp(best.x)


def count_curve(data: dict, workers=None) -> CountCurve:
    """One ensemble of the preset ``data`` at h = 1 over a wide log force range."""
    wide = [
        "spectrum.params.rms_height=1.0", "spectrum.params.c0=null", "loading.start=1.0e-6", "loading.stop=1.0e+3",
        "loading.steps=2000", "loading.spacing=log", "fit.bootstrap=0", "sweep=null",
    ]  # fmt: skip
    outcome = engine.run(build_scene(apply_overrides(data, wide)), workers=workers)
    return CountCurve(np.log(outcome.loads), np.log(outcome.contact_count))


def calibrated_rms_height(data: dict, targets: dict[float, float] = COUNT_TARGETS, workers=None) -> float:
    """h that gives the target mean contact counts (3 significant figures), as
    tools/calibrate_rms_height.py finds it."""
    return float(f"{count_curve(data, workers).fit_rms_height(targets):.3g}")


@dataclass(frozen=True)
class Reading:
    figure: str
    name: str
    overrides: tuple[str, ...] = ()
    average: str = "mean"
    calibrate: bool = False  # h calibrated to the study's Fig. 2 counts (4 at F = 1, 12 at F = 20)
    same_c0_as: str | None = None  # a figure key: take its C0 (normalise by C0 instead of h)


# The study's eq. 6 read literally: pi / L <= q <= pi / (10 dx), a sum of cosines with q_k = k pi / L,
# k = 1 .. N / 10, on [0, L]: not periodic, the wave vectors twice as dense as the FFT grid's.
LITERAL = "eq. 6 literally: cosine series q_k = k pi / L, k = 1 .. N/10, not periodic, h calibrated to the counts"
LITERAL_SETS = ("spectrum.params.series=cosine", "spectrum.params.short_cutoff=20.0")  # q_max = pi / (10 dx), dx = 1

READINGS = (
    Reading("fig2", "defaults (the preset)"),
    Reading("fig2", "no short cut-off (lambda_s = 2 dx), h = 1e4", ("spectrum.params.short_cutoff=2.0",)),
    Reading("fig2", "no short cut-off, h calibrated to the counts", ("spectrum.params.short_cutoff=2.0",), calibrate=True),
    Reading("fig2", "short cut-off 20 dx, h calibrated to the counts", ("spectrum.params.short_cutoff=20.0",), calibrate=True),
    Reading("fig2", "Rayleigh amplitudes", ("spectrum.params.amplitudes=rayleigh",)),
    Reading("fig2", "central-difference slopes", ("slope.name=central-difference",)),
    Reading("fig2", "spectral slopes", ("slope.name=spectral",)),
    Reading("fig2", "no short cut-off, spectral slopes, h calibrated",
            ("spectrum.params.short_cutoff=2.0", "slope.name=spectral"), calibrate=True),
    Reading("fig2", "average: pooled contact points", average="pooled"),
    Reading("fig2", "average: rms of xi", average="rms"),
    Reading("fig2", LITERAL, LITERAL_SETS, calibrate=True),
    Reading("fig3", "defaults (the preset)"),
    Reading("fig3", "no short cut-off, h calibrated to the counts", ("spectrum.params.short_cutoff=2.0",), calibrate=True),
    Reading("fig3", "Rayleigh amplitudes", ("spectrum.params.amplitudes=rayleigh",)),
    Reading("fig3", "average: pooled contact points", average="pooled"),
    Reading("fig3", LITERAL, LITERAL_SETS, calibrate=True),
    Reading("fig4", "same h as Fig. 2 (the preset)"),
    Reading("fig4", "same C0 as Fig. 2", same_c0_as="fig2"),
    Reading("fig4", "h calibrated to Fig. 2's counts at H = 0.5", calibrate=True),
    Reading("fig4", "no short cut-off, h calibrated at H = 0.5", ("spectrum.params.short_cutoff=2.0",), calibrate=True),
    Reading("fig4", "Rayleigh amplitudes, h calibrated at H = 0.5", ("spectrum.params.amplitudes=rayleigh",),
            calibrate=True),
    Reading("fig4", "average: pooled contact points", average="pooled"),
    Reading("fig4", LITERAL + " at H = 0.5", LITERAL_SETS, calibrate=True),
)  # fmt: skip


def fig5_calibrated_readings(sweep) -> tuple[Reading, ...]:
    """Fig. 5 with h calibrated at each H: one reading per point of the sweep, the
    point's own ``--set`` options with h fitted to Fig. 2's counts on its own lines."""
    return tuple(Reading("fig5", f"h calibrated at {point.describe()}", ("sweep=null", *point.assignments),
                         calibrate=True) for point in sweep.points)  # fmt: skip


# ------------------------------------------------------------------ running


@dataclass
class FigureRun:
    study: StudyFigure
    preset_path: Path
    folder: Path
    scene: object = None  # Scene (single run)
    outcome: object = None  # RunOutcome (single run)
    sweep: object = None  # sweep.Sweep (Fig. 5)
    sweep_outcome: object = None


@dataclass
class ReadingRow:
    reading: Reading
    overrides: list[str]
    a: float
    b: float
    a_ci: tuple[float, float]
    b_ci: tuple[float, float]
    r2: float
    counts: tuple[float, float]
    loads: tuple[float, float]
    folder: Path | None
    rms_height: float | None = None  # the calibrated h, when the reading calibrates


def find_presets(presets_dir: str | Path | None) -> Path:
    candidates = [Path(presets_dir)] if presets_dir else [Path("presets"), Path(__file__).resolve().parents[1] / "presets"]
    for folder in candidates:
        if all((folder / fig.preset).is_file() for fig in STUDY):
            return folder
    wanted = ", ".join(fig.preset for fig in STUDY)
    raise FrictionlabError(
        f"--presets: no folder with the study's presets ({wanted}); looked in {', '.join(map(str, candidates))}"
    )


def run_figures(presets: Path, out_dir: Path, *, workers=None, force: bool = False) -> list[FigureRun]:
    from .sweep import load_sweep, run_sweep

    runs = []
    for fig in STUDY:
        path = presets / fig.preset
        run = FigureRun(fig, path, out_dir / fig.key)
        data = load_preset_file(path)
        if data.get("sweep") is not None:
            run.sweep = load_sweep(path)
            run.sweep_outcome = run_sweep(run.sweep, run.folder, workers=workers, plot=False, force=force)
        else:
            run.scene = build_scene(data, source=str(path))
            run.outcome, _ = run_to_folder(run.scene, run.folder, workers=workers, force=force)
        runs.append(run)
    return runs


def run_readings(runs: list[FigureRun], out_dir: Path, *, workers=None, readings=READINGS,
                 folder_name="readings", force: bool = False) -> list[ReadingRow]:  # fmt: skip
    by_key = {run.study.key: run for run in runs}
    rows = []
    for number, reading in enumerate(readings, start=1):
        base = by_key[reading.figure]
        data = load_preset_file(base.preset_path)
        overrides = list(reading.overrides)
        if reading.same_c0_as:
            c0 = by_key[reading.same_c0_as].scene.spectrum.c0()
            overrides += ["spectrum.params.rms_height=null", f"spectrum.params.c0={float(f'{c0:.6g}')!r}"]
        h = None
        if reading.calibrate:
            h = calibrated_rms_height(apply_overrides(data, overrides), workers=workers)
            overrides.append(f"spectrum.params.rms_height={h!r}")
        if not overrides:  # the figure's own run, maybe re-averaged
            scene, outcome, folder = base.scene, base.outcome, base.folder
        else:
            scene = build_scene(apply_overrides(data, [*overrides, "output.plot=false"]), source=str(base.preset_path))
            folder = out_dir / folder_name / f"{number:02d}-{reading.figure}"
            outcome, _ = run_to_folder(scene, folder, workers=workers, force=force)
        settings = scene.preset.fit
        fit = refit(outcome.f, outcome.per_realization, reading.average,
                    bootstrap=settings.bootstrap, confidence=settings.confidence, seed=scene.preset.seed)  # fmt: skip
        counts = (float(outcome.contact_count[0]), float(outcome.contact_count[-1]))
        loads = (float(outcome.loads[0]), float(outcome.loads[-1]))
        rows.append(ReadingRow(reading, overrides, fit.a, fit.b, fit.a_ci, fit.b_ci, fit.r2, counts, loads, folder, h))
    return rows


# ------------------------------------------------------------------ figures

F_UNIT = 1e-9  # the study's f axis is in units of 1e-9


def plot_figure(run: FigureRun, fh, dpi: int = 90) -> None:
    """xi(f) on the study's axes (f in units of 1e-9, log), the fit, the study's law; counts below."""
    from .plot import plt

    o, fig_info = run.outcome, run.study
    fig, (ax, ax_n) = plt.subplots(
        2, 1, figsize=(6.0, 5.2), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]}, layout="constrained"
    )
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
                label=f"study: {fig_info.a} + {fig_info.b} ln f")  # fmt: skip
    ax.set_xscale("log")
    ax.set_ylabel(r"$\xi = \nabla z_{contact} / \nabla z$")
    ax.set_title(fig_info.title, fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)
    ax_n.plot(x, o.contact_count, "-", color="C2", label="frictionlab")
    if fig_info.counts:
        scale = o.f[0] / o.force[0]
        forces = list(fig_info.counts)
        ax_n.plot([F * scale / F_UNIT for F in forces], list(fig_info.counts.values()), "kx", ms=8, mew=2, label="study")
    ax_n.set_ylabel("points in contact")
    ax_n.set_xlabel(r"$f = F / (E^* h L)$ in units of $10^{-9}$")
    ax_n.grid(True, which="both", alpha=0.3)
    ax_n.legend(fontsize=7, loc="upper left")
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


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
    return {"H": np.array([_reading_hurst(r) for r in rows], float),
            "a": np.array([[r.a, *r.a_ci] for r in rows], float).reshape(-1, 3),
            "b": np.array([[r.b, *r.b_ci] for r in rows], float).reshape(-1, 3)}  # fmt: skip


def _preset_h(run: FigureRun) -> str:
    """The Fig. 5 preset's own rms height, as the text shows it."""
    return f"{run.sweep.base['spectrum']['params'].get('rms_height'):g}"


def _plot_against_h(axes, series, label: str, color: str, offset: float = 0.0) -> None:
    """a and b (with their intervals) against H on two axes."""
    for ax, coef in zip(axes, ("a", "b"), strict=True):
        y, low, high = series[coef].T
        ax.errorbar(series["H"] + offset, y, yerr=[y - low, high - y], fmt="o-", ms=4, capsize=3, color=color,
                    label=label)  # fmt: skip


def _mark_study_against_h(axes) -> None:
    for ax, col in zip(axes, (1, 2), strict=True):
        ax.plot([STUDY_H07[0]], [STUDY_H07[col]], "*", ms=14, color="C3", label="study, H ~ 0.7 (about)")
        ax.plot([p[0] for p in STUDY_POINTS_VS_H], [p[col] for p in STUDY_POINTS_VS_H], "ks", ms=6,
                label="study, Figs. 2 and 4")  # fmt: skip
        ax.set_xlabel("Hurst exponent H")
        ax.set_ylabel("ab"[col - 1])
        ax.grid(True, alpha=0.3)


def plot_fig5(run: FigureRun, fh, dpi: int = 90) -> None:
    """a and b against H with intervals, the study's points marked."""
    from .plot import plt

    fig, axes = plt.subplots(1, 2, figsize=(8.4, 3.6), layout="constrained")
    _plot_against_h(axes, _sweep_series(run), "frictionlab (95% CI)", "C0")
    _mark_study_against_h(axes)
    axes[0].legend(fontsize=7)
    fig.suptitle("Fig. 5: xi = a + b ln f against H (each point as Fig. 2, h = 1e4)", fontsize=10)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


def plot_fig5_calibrated(run: FigureRun, rows: list[ReadingRow], fh, dpi: int = 90) -> None:
    """a and b against H with h = 1e4 and with h calibrated at each H, the study's
    points marked; a third panel shows the calibrated h."""
    from .plot import plt

    fig, axes = plt.subplots(1, 3, figsize=(11.4, 3.6), layout="constrained")
    _plot_against_h(axes[:2], _sweep_series(run), f"h = {_preset_h(run)} at every H (the preset)", "C0", offset=-0.006)
    _plot_against_h(axes[:2], _calibrated_series(rows), "h calibrated at each H to Fig. 2's counts", "C2", offset=0.006)
    _mark_study_against_h(axes[:2])
    axes[0].legend(fontsize=7)
    axes[2].semilogy([_reading_hurst(r) for r in rows], [r.rms_height for r in rows], "o-", color="C2", ms=4)
    axes[2].axhline(float(_preset_h(run)), color="C0", ls="--", lw=1, label=f"h = {_preset_h(run)} (the preset)")
    axes[2].set_xlabel("Hurst exponent H")
    axes[2].set_ylabel("calibrated rms height h")
    axes[2].grid(True, which="both", alpha=0.3)
    axes[2].legend(fontsize=7)
    fig.suptitle("Fig. 5 with h calibrated at each H (counts 4 at F = 1, 12 at F = 20; 95% CI)", fontsize=10)
    fig.savefig(fh, format="png", dpi=dpi)
    plt.close(fig)


# ------------------------------------------------------------------ markdown


def _ci(ci) -> str:
    low, high = ci
    return "n/a" if low is None or high is None or low != low else f"[{low:.4f}, {high:.4f}]"


def _inside(value, ci) -> str:
    if value is None or ci[0] is None or ci[0] != ci[0]:
        return ""
    return "" if ci[0] <= value <= ci[1] else " †"


def _counts_text(run: FigureRun) -> str:
    o, study = run.outcome, run.study
    parts = []
    for i, label in ((0, "first"), (-1, "last")):
        F = float(o.loads[i])
        wanted = study.counts.get(F)
        parts.append(f"{o.contact_count[i]:.2f} at F = {F:g}" + (f" ({wanted:g})" if wanted is not None else ""))
    return ", ".join(parts)


def _row_for_h(run: FigureRun, value: float):
    path = run.sweep.paths[0]
    return min(run.sweep_outcome.rows, key=lambda r: abs(r[path] - value))


def markdown(runs, images: dict[str, str], *, elapsed: float, readings=None, readings_elapsed=None,
             fig5_calibrated=None, fig5_calibrated_elapsed=None, workers=None,
             command="frictionlab report") -> str:  # fmt: skip
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    lines = [
        "# Reproducing Benad (2012) with frictionlab",
        "",
        f"Generated by `{command}` (frictionlab {__version__}, {datetime.date.today().isoformat()}). "
        f"**Wall time of the whole report (Figs. 2 to 5): {elapsed:.1f} s** on a {cores}-core machine"
        + (f" with `--workers {workers}`" if workers else "")
        + (f"; the readings below took another {readings_elapsed:.1f} s" if readings_elapsed is not None else "")
        + (f", Fig. 5 with h calibrated at each H {fig5_calibrated_elapsed:.1f} s" if fig5_calibrated_elapsed else "")
        + "."
        + " The study's numbers are those its Figs. 2 to 5 state; the presets are in `presets/` (their comments say"
        " how h = 1e4 was calibrated). Intervals are 95% percentile bootstrap over realizations;"
        " † marks a study value outside frictionlab's interval.",
        "",
        "| figure | study a | frictionlab a (95% CI) | study b | frictionlab b (95% CI) | R² | mean points in contact: frictionlab (study) |",
        "|---|---|---|---|---|---|---|",
    ]
    for run in runs:
        s = run.study
        if run.sweep is not None:
            row = _row_for_h(run, STUDY_H07[0])
            path = run.sweep.paths[0]
            lines.append(
                f"| Fig. 5 at H = {row[path]:g} | about {s.a} | {row['a']:.4f} {_ci((row['a_lo'], row['a_hi']))}"
                f"{_inside(s.a, (row['a_lo'], row['a_hi']))} | about {s.b} | {row['b']:.4f} "
                f"{_ci((row['b_lo'], row['b_hi']))}{_inside(s.b, (row['b_lo'], row['b_hi']))} | {row['r2']:.3f} | "
                f"{row['contact_first']:.2f} at F = 1, {row['contact_last']:.2f} at F = 20 (not stated) |"
            )
            continue
        fit = run.outcome.fit
        lines.append(
            f"| {s.title} | {s.a} | {fit.a:.4f} {_ci(fit.a_ci)}{_inside(s.a, fit.a_ci)} | {s.b} | {fit.b:.4f} "
            f"{_ci(fit.b_ci)}{_inside(s.b, fit.b_ci)} | {fit.r2:.3f} | {_counts_text(run)}"
            + ("" if s.counts else " (not stated)") + " |"
        )
    for run in runs:
        s = run.study
        lines += ["", f"## {s.title}", ""]
        if run.sweep is None:
            o = run.outcome
            f_lo, f_hi = float(o.f[0]), float(o.f[-1])
            law = lambda a, b, f: a + b * math.log(f)  # noqa: E731
            lines.append(
                f"Preset `{run.preset_path.name}`: {o.done} realizations in {o.elapsed:.2f} s. "
                f"Over f = {f_lo / F_UNIT:.3g}e-9 .. {f_hi / F_UNIT:.3g}e-9 the study's law gives "
                f"xi = {law(s.a, s.b, f_lo):.3f} .. {law(s.a, s.b, f_hi):.3f}; frictionlab measures "
                f"{o.xi[0]:.3f} .. {o.xi[-1]:.3f} (fit {law(o.fit.a, o.fit.b, f_lo):.3f} .. "
                f"{law(o.fit.a, o.fit.b, f_hi):.3f}). Mean points in contact: {_counts_text(run)}"
                + (f" (study in brackets)." if s.counts else ".")
                + (f" Note: {s.note}." if s.note else "")
            )
            zero = math.exp(-s.a / s.b)  # where the study's law reaches xi = 0
            if f_lo < zero:
                lines += ["", f"The study's law is negative below f = {zero / F_UNIT:.3g}e-9, so over F = "
                          f"{o.loads[0]:g}..{o.loads[-1]:g} the study's f cannot have started at {f_lo / F_UNIT:.3g}e-9:"
                          " its normalisation (h, or C0) for this figure must differ from the preset's."]  # fmt: skip
        else:
            path = run.sweep.paths[0]
            lines += [
                f"Preset `{run.preset_path.name}`: {len(run.sweep.points)} points ({path}), "
                f"{run.sweep_outcome.elapsed:.1f} s. Note: {s.note}; the study's Figs. 2 (H = 1) and 4 (H = 0.5) "
                "are marked too.",
                "",
                "| H | a (95% CI) | b (95% CI) | R² | points in contact at F = 1 / 20 |",
                "|---|---|---|---|---|",
            ]
            for row in run.sweep_outcome.rows:
                if row["a"] is None:
                    lines.append(f"| {row[path]:g} | {row['status']} | | | |")
                    continue
                lines.append(
                    f"| {row[path]:g} | {row['a']:.4f} {_ci((row['a_lo'], row['a_hi']))} | {row['b']:.4f} "
                    f"{_ci((row['b_lo'], row['b_hi']))} | {row['r2']:.3f} | "
                    f"{row['contact_first']:.2f} / {row['contact_last']:.2f} |"
                )
        lines += ["", f"![{s.title}]({images[s.key]})"]
    if readings is not None:
        lines += readings_markdown(readings)
    if fig5_calibrated is not None:
        fig5 = next(run for run in runs if run.sweep is not None)
        lines += fig5_calibrated_markdown(fig5, fig5_calibrated, images["fig5-calibrated"], fig5_calibrated_elapsed)
    return "\n".join(lines) + "\n"


def _reading_hurst(row: ReadingRow) -> float:
    """H of a Fig. 5 reading, from its ``--set`` options."""
    import yaml

    prefix = "spectrum.params.hurst="
    return float(yaml.safe_load(next(o for o in row.overrides if o.startswith(prefix))[len(prefix):]))


def _study_at_h(hurst: float):
    """(a, b, label) the study states at this H, or None."""
    known = [(h, a, b, f"{label}: {a}, {b}") for h, a, b, label in STUDY_POINTS_VS_H]
    known.append((*STUDY_H07, f"about {STUDY_H07[1]}, about {STUDY_H07[2]}"))
    return next(((a, b, text) for h, a, b, text in known if abs(h - hurst) < 1e-9), None)


def fig5_calibrated_markdown(run: FigureRun, rows: list[ReadingRow], image: str, elapsed: float | None) -> list[str]:
    """Fig. 5 rerun with h calibrated at each H, beside the preset's h = 1e4 and the study."""
    path = run.sweep.paths[0]
    default = {r[path]: r for r in run.sweep_outcome.rows if r["a"] is not None}
    took = f" {len(rows)} calibrations and runs took {elapsed:.1f} s." if elapsed is not None else ""
    lines = [
        "",
        "## Fig. 5 with h calibrated at each H",
        "",
        "Each point of Fig. 5 rerun with its own h: fitted, as for the readings above, to Fig. 2's contact"
        f" counts (4 at F = 1, 12 at F = 20) on that point's lines, instead of h = {_preset_h(run)} at every H. Rerun a"
        " point: `frictionlab run presets/benad2012-fig5.yaml --set sweep=null --set spectrum.params.hurst=H"
        f" --set spectrum.params.rms_height=h` with h from the table.{took} The study states a and b at"
        " H = 1 (Fig. 2), H = 0.5 (Fig. 4) and near H = 0.7 (about); † marks a study value outside the"
        " calibrated interval.",
        "",
        "| H | calibrated h | a (95% CI) | b (95% CI) | R² | points in contact at F = 1 / 20 "
        f"| h = {_preset_h(run)}: a, b | study a, b |",
        "|---|---|---|---|---|---|---|---|",
    ]
    verdicts = []
    for r in rows:
        hurst = _reading_hurst(r)
        study = _study_at_h(hurst)
        a_mark = _inside(study[0], r.a_ci) if study else ""
        b_mark = _inside(study[1], r.b_ci) if study else ""
        base = default.get(hurst)
        base_text = f"{base['a']:.4f}, {base['b']:.4f}" if base else "n/a"
        lines.append(
            f"| {hurst:g} | {r.rms_height:g} | {r.a:.4f} {_ci(r.a_ci)}{a_mark} | {r.b:.4f} {_ci(r.b_ci)}{b_mark} | "
            f"{r.r2:.3f} | {r.counts[0]:.2f} / {r.counts[1]:.2f} | {base_text} | {study[2] if study else ''} |"
        )
        if study:
            inside = [name for name, mark in (("a", a_mark), ("b", b_mark)) if not mark]
            verdicts.append(f"H = {hurst:g}: " + (" and ".join(inside) + " inside" if inside else "neither inside"))
    top = max(rows, key=lambda r: r.a)
    lines += ["", f"Largest a with h calibrated: {top.a:.4f} {_ci(top.a_ci)} at H = {_reading_hurst(top):g}"]
    if default:
        top_h = max(default, key=lambda h: default[h]["a"])
        lines[-1] += f"; with h = {_preset_h(run)}: {default[top_h]['a']:.4f} at H = {top_h:g}"
    lines[-1] += f"; the study: about {STUDY_H07[1]} near H = {STUDY_H07[0]:g}."
    top_holders = ", ".join(f"{_reading_hurst(r):g}" for r in rows if r.a_ci[0] <= top.a <= r.a_ci[1])
    lines[-1] += f" The a intervals that hold this largest a: H = {top_holders}."
    near = next((r for r in rows if abs(_reading_hurst(r) - STUDY_H07[0]) < 1e-9), None)
    if near is not None:
        lines[-1] += (f" At H = {STUDY_H07[0]:g}: a {near.a / STUDY_H07[1] - 1:+.0%} and b {near.b / STUDY_H07[2] - 1:+.0%}"
                      " from the study's values.")  # fmt: skip
    if verdicts:
        lines += ["", "The study's values against the calibrated intervals: " + "; ".join(verdicts) + "."]
    lines += ["", f"![Fig. 5 with h calibrated at each H]({image})"]
    return lines


def readings_markdown(rows: list[ReadingRow]) -> list[str]:
    by_figure = {s.key: s for s in STUDY}
    lines = [
        "",
        "## Readings of the study's method",
        "",
        "Each row is one reading of what the study may have done, run for real (`frictionlab report --readings`)."
        " The defaults are frictionlab's (periodic lines, q_k = 2 pi k / L); no reading is tuned to the study's"
        " numbers: a calibrated h is found"
        " from the study's Fig. 2 contact counts (4 at F = 1, 12 at F = 20) by the method of"
        " `tools/calibrate_rms_height.py`, applied to the reading's own lines. Averages: "
        + "; ".join(f"`{k}`: {v}" for k, v in AVERAGES.items())
        + ". Rerun a row: `frictionlab run presets/<figure preset> --set ...` with the options shown"
        " (averaging rows re-average the default run's `realizations.npz`). † marks a study value outside the interval.",
        "",
        "| figure | reading | --set | average | a (95% CI) | b (95% CI) | R² | points in contact |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        s = by_figure[r.reading.figure]
        sets = " ".join(f"`{o}`" for o in r.overrides) or "(none)"
        counts = f"{r.counts[0]:.2f} at F = {r.loads[0]:g}, {r.counts[1]:.2f} at F = {r.loads[1]:g}"
        lines.append(
            f"| {s.key[-1]} | {r.reading.name} | {sets} | {r.reading.average} | {r.a:.4f} {_ci(r.a_ci)}"
            f"{_inside(s.a, r.a_ci)} | {r.b:.4f} {_ci(r.b_ci)}{_inside(s.b, r.b_ci)} | {r.r2:.3f} | {counts} |"
        )
    lines += ["", "Study: " + "; ".join(
        f"Fig. {s.key[-1]}: a = {s.a}, b = {s.b}"
        + (" (counts " + ", ".join(f"{n:g} at F = {F:g}" for F, n in s.counts.items()) + ")" if s.counts else "")
        for s in STUDY if s.key != "fig5") + "."]  # fmt: skip
    hits = [
        f"{r.reading.figure} / {r.reading.name}"
        for r in rows
        if _inside(by_figure[r.reading.figure].a, r.a_ci) == "" and _inside(by_figure[r.reading.figure].b, r.b_ci) == ""
    ]
    lines += ["", "Readings whose intervals hold both of the study's a and b: " + (", ".join(hits) if hits else "none") + "."]
    return lines


# ------------------------------------------------------------------ the command


FIGURE_FILES = ("fig2.png", "fig3.png", "fig4.png", "fig5.png", "fig5-calibrated.png")


def report_paths(out_dir=None, markdown_path=None, figures_dir=None, *, force: bool = False) -> tuple[Path, Path, Path]:
    """The run folders, the markdown and the figures folder of a report: by
    default all in a fresh folder ``runs/report-<timestamp>/`` (``REPRODUCTION.md``,
    ``figures/``). An existing markdown or figure is refused unless ``force``."""
    from .errors import OutputRefused

    out_dir = Path(out_dir) if out_dir else Path("runs") / f"report-{time.strftime('%Y%m%d-%H%M%S')}"
    markdown_path = Path(markdown_path) if markdown_path else out_dir / "REPRODUCTION.md"
    figures_dir = Path(figures_dir) if figures_dir else out_dir / "figures"
    taken = [p for p in (markdown_path, *(figures_dir / name for name in FIGURE_FILES)) if os.path.lexists(p)]
    if taken and not force:
        shown = ", ".join(str(p) for p in taken[:3]) + (", ..." if len(taken) > 3 else "")
        raise OutputRefused(f"the report would overwrite {shown}: give other --out/--markdown/--figures, or --force")
    return out_dir, markdown_path, figures_dir


def write_report(
    *, presets_dir=None, out_dir=None, markdown_path=None, figures_dir=None,
    workers=None, readings=False, quiet=False, dpi=90, force=False,
) -> Path:  # fmt: skip
    """Run Figs. 2 to 5 (and the readings), write the figures and the markdown; return its path.
    Paths default to a fresh folder (``report_paths``); nothing existing is overwritten unless ``force``."""
    import sys

    from .results import atomic_write

    presets = find_presets(presets_dir)
    out_dir, markdown_path, figures_dir = report_paths(out_dir, markdown_path, figures_dir, force=force)
    log = (lambda text: None) if quiet else (lambda text: print(text, file=sys.stderr, flush=True))
    started = time.perf_counter()
    log(f"report: running Figs. 2 to 5 from {presets}/ into {out_dir}/")
    runs = run_figures(presets, out_dir, workers=workers, force=force)
    log(f"report: Figs. 2 to 5 ran in {time.perf_counter() - started:.1f} s; drawing")
    images = {}
    for run in runs:
        name = f"{run.study.key}.png"
        draw = plot_fig5 if run.sweep is not None else plot_figure
        atomic_write(figures_dir / name, lambda fh, run=run, draw=draw: draw(run, fh, dpi=dpi), binary=True)
        images[run.study.key] = os.path.relpath(figures_dir / name, markdown_path.parent or Path("."))
    elapsed = time.perf_counter() - started
    reading_rows = readings_elapsed = fig5_rows = fig5_elapsed = None
    if readings:
        log(f"report: running {len(READINGS)} readings")
        t0 = time.perf_counter()
        reading_rows = run_readings(runs, out_dir, workers=workers, force=force)
        readings_elapsed = time.perf_counter() - t0
        fig5 = next(run for run in runs if run.sweep is not None)
        log(f"report: Fig. 5 with h calibrated at each of {len(fig5.sweep.points)} H")
        t0 = time.perf_counter()
        fig5_rows = run_readings(runs, out_dir, workers=workers, readings=fig5_calibrated_readings(fig5.sweep),
                                 folder_name="fig5-calibrated", force=force)  # fmt: skip
        fig5_elapsed = time.perf_counter() - t0
        name = "fig5-calibrated.png"
        atomic_write(figures_dir / name, lambda fh: plot_fig5_calibrated(fig5, fig5_rows, fh, dpi=dpi), binary=True)
        images["fig5-calibrated"] = os.path.relpath(figures_dir / name, markdown_path.parent or Path("."))
    command = "frictionlab report" + (" --readings" if readings else "")
    text = markdown(runs, images, elapsed=elapsed, readings=reading_rows, readings_elapsed=readings_elapsed,
                    fig5_calibrated=fig5_rows, fig5_calibrated_elapsed=fig5_elapsed, workers=workers,
                    command=command)  # fmt: skip
    atomic_write(markdown_path, lambda fh: fh.write(text))
    log(f"report: wrote {markdown_path} and {len(images)} figures in {figures_dir}/ ({elapsed:.1f} s for Figs. 2 to 5)")
    return markdown_path


def cmd_report(args) -> int:
    from .errors import ExitCode

    if args.workers is not None and args.workers < 1:
        raise FrictionlabError(f"--workers must be >= 1. Got {args.workers} instead.")
    path = write_report(
        presets_dir=args.presets, out_dir=args.out, markdown_path=args.markdown, figures_dir=args.figures,
        workers=args.workers, readings=args.readings, quiet=args.quiet, force=args.force,
    )  # fmt: skip
    print(path)
    return ExitCode.OK


def add_parser(sub) -> None:
    """The ``report`` subcommand (registered by cli.build_parser)."""
    p = sub.add_parser("report", help="run the study's Figs. 2 to 5 and write REPRODUCTION.md with figures")
    p.add_argument("--presets", metavar="DIR", help="folder with benad2012-fig2..5.yaml (default: ./presets)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: a new runs/report-<timestamp>)")
    p.add_argument("--markdown", metavar="FILE", help="the report (default: REPRODUCTION.md in --out)")
    p.add_argument("--figures", metavar="DIR", help="PNG folder (default: figures/ in --out)")
    p.add_argument("--force", action="store_true", help="overwrite an existing report, its figures and runs")
    p.add_argument("--workers", type=int, metavar="N", help="worker processes (default: all cores)")
    p.add_argument("--readings", action="store_true", help="also run the readings of the study's method (slower)")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(handler=cmd_report)
