"""Readings of the paper's method: what it may have done where it does not say (cut-off,
amplitudes, slope estimator, averaging over realizations, normalisation per H), each
run for real and fitted like a run. Every reading is a preset plus ``--set`` options
(printed in the report's table, so any row can be rerun with ``frictionlab run``),
except the averaging readings, which re-average the default run's
``realizations.npz`` (``average_curve``)."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from ..errors import FrictionlabError, OutputRefused
from ..compute.fit import LogFit, fit_log_law
from ..options import RunOptions
from ..preset import apply_overrides, build_scene, load_preset_file
from ..runs.runfolder import output_subfolder
from ..compute.signals import interrupted_since, mark
from ..preset.seeds import bootstrap_rng, replicate_seeds
from .calibration import calibrated_rms_height
from .figures import FigureRun, refuse_foreign_files, run_or_read_back


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


def refit(f, per, method: str, *, bootstrap: int, confidence: float, seed: int) -> LogFit:
    """Fit xi = a + b ln f to ``average_curve(per, method)``, with the bootstrap of the
    run's own fit (same stream, same resamples): for ``mean`` this is the run's fit."""
    average = None if method == "mean" else (lambda weights: average_curve(per, method, weights))
    return fit_log_law(f, per["xi"], bootstrap=bootstrap, confidence=confidence, rng=bootstrap_rng(seed),
                       average=average)  # fmt: skip


@dataclass(frozen=True)
class Reading:
    figure: str
    name: str
    overrides: tuple[str, ...] = ()
    average: str = "mean"
    calibrate: bool = False  # h calibrated to the paper's Fig. 2 counts (4 at F = 1, 12 at F = 20)
    same_c0_as: str | None = None  # a figure key: take its C0 (normalise by C0 instead of h)


# The paper's eq. 6 read literally: pi / L <= q <= pi / (10 dx), a sum of cosines with q_k = k pi / L,
# k = 1 .. N / 10, on [0, L]: not periodic, the wave vectors twice as dense as the FFT grid's.
LITERAL = "eq. 6 literally: cosine series q_k = k pi / L, k = 1 .. N/10, not periodic, h calibrated to the counts"
LITERAL_SETS = ("spectrum.params.series=cosine", "spectrum.params.short_cutoff=20.0")  # q_max = pi / (10 dx), dx = 1

# The study's h (its eq. 8: the rms of the line's own heights about their mean) and its slope read literally
# (forward differences "only for points in contact": the last point of a line that does not repeat has none)
MEASURED_H = "spectrum.params.height_reference=measured"
LAST_POINT_UNDEFINED = "slope.params.line_end=undefined"


def literal_readings(figure: str, suffix: str = "") -> tuple[Reading, ...]:
    """Eq. 6 read literally, crossed with h nominal or measured per line and the last point's slope
    (the last segment's, or none), at h = 1e4 and calibrated: the calibrated nominal one with the
    last segment's slope is ``LITERAL`` itself, listed with the older readings."""
    readings = []
    for h_sets, h_name in (((), "h nominal"), ((MEASURED_H,), "h measured per line")):
        for end_sets, end_name in (((), "last point: last segment's slope"), ((LAST_POINT_UNDEFINED,), "last point: no slope")):
            for calibrate in (False, True):
                if calibrate and not h_sets and not end_sets:
                    continue
                h_value = "h calibrated to the counts" if calibrate else "h = 1e4"
                readings.append(Reading(figure, f"eq. 6 literally, {h_name}, {end_name}, {h_value}{suffix}",
                                        (*LITERAL_SETS, *h_sets, *end_sets), calibrate=calibrate))  # fmt: skip
    return tuple(readings)


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
    *literal_readings("fig2"),
    Reading("fig3", "defaults (the preset)"),
    Reading("fig3", "no short cut-off, h calibrated to the counts", ("spectrum.params.short_cutoff=2.0",), calibrate=True),
    Reading("fig3", "Rayleigh amplitudes", ("spectrum.params.amplitudes=rayleigh",)),
    Reading("fig3", "average: pooled contact points", average="pooled"),
    Reading("fig3", LITERAL, LITERAL_SETS, calibrate=True),
    *literal_readings("fig3"),
    Reading("fig4", "same h as Fig. 2 (the preset)"),
    Reading("fig4", "same C0 as Fig. 2", same_c0_as="fig2"),
    Reading("fig4", "h calibrated to Fig. 2's counts at H = 0.5", calibrate=True),
    Reading("fig4", "no short cut-off, h calibrated at H = 0.5", ("spectrum.params.short_cutoff=2.0",), calibrate=True),
    Reading("fig4", "Rayleigh amplitudes, h calibrated at H = 0.5", ("spectrum.params.amplitudes=rayleigh",),
            calibrate=True),
    Reading("fig4", "average: pooled contact points", average="pooled"),
    Reading("fig4", LITERAL + " at H = 0.5", LITERAL_SETS, calibrate=True),
    *literal_readings("fig4", " at H = 0.5"),
)  # fmt: skip


def fig5_calibrated_readings(sweep) -> tuple[Reading, ...]:
    """Fig. 5 with h calibrated at each H: one reading per point of the sweep, the
    point's own ``--set`` options with h fitted to Fig. 2's counts on its own lines."""
    return tuple(Reading("fig5", f"h calibrated at {point.describe()}", ("sweep=null", *point.assignments),
                         calibrate=True) for point in sweep.points)  # fmt: skip


@dataclass
class ReadingRow:
    """What one reading gave: its fit of the averaged curve, contact counts at the first and last load;
    with replicates, the fit of each of K independent ensembles (the first is ``fit``, the preset's seed)."""

    reading: Reading
    overrides: list[str]
    fit: LogFit
    counts: tuple[float, float]
    loads: tuple[float, float]
    folder: Path | None
    rms_height: float | None = None  # the calibrated h, when the reading calibrates
    replicates: list[LogFit] = field(default_factory=list)  # one fit per ensemble, the first being ``fit``
    seeds: list[int] = field(default_factory=list)  # their root seeds
    last_counts: list[float] = field(default_factory=list)  # mean points in contact at the last load, per ensemble

    def spread(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """((mean, standard deviation) of a, the same of b) between the ensembles (sd NaN for one)."""
        a = np.array([fit.a for fit in self.replicates])
        b = np.array([fit.b for fit in self.replicates])
        sd = (lambda v: float(np.std(v, ddof=1)) if v.size >= 2 else float("nan"))  # noqa: E731
        return (float(a.mean()), sd(a)), (float(b.mean()), sd(b))

    def holding(self, a: float, b: float) -> int:
        """In how many ensembles both ``a`` and ``b`` lie inside the bootstrap intervals."""
        return sum(fit.a_ci[0] <= a <= fit.a_ci[1] and fit.b_ci[0] <= b <= fit.b_ci[1] for fit in self.replicates)

    def hurst(self) -> float:
        """H of a Fig. 5 reading, from its ``--set`` options."""
        prefix = "spectrum.params.hurst="
        return float(yaml.safe_load(next(o for o in self.overrides if o.startswith(prefix))[len(prefix):]))


READINGS_FOLDER = "readings"  # the readings' run folders, in the report's --out
CALIBRATED_FOLDER = "fig5-calibrated"  # the runs of Fig. 5 with h calibrated at each H


def check_reading_folders(out_dir: Path) -> None:
    """Refuse, before any figure runs, a folder of the readings' (``readings/NN-figK``,
    ``fig5-calibrated/...``) that holds files no frictionlab run wrote (``refuse_foreign_files``)."""
    for name in (READINGS_FOLDER, CALIBRATED_FOLDER):
        if (out_dir / name).is_dir() and not (out_dir / name).is_symlink():  # a link: refused as the readings start
            for folder in sorted(out_dir / name / child for child in os.listdir(out_dir / name)):
                if folder.is_dir() and not folder.is_symlink():
                    refuse_foreign_files(folder)


def run_readings(runs: list[FigureRun], out_dir: Path, options: RunOptions = RunOptions(), *, readings=READINGS,
                 folder_name=READINGS_FOLDER, progress: bool = False, replicates: int = 1) -> list[ReadingRow]:  # fmt: skip
    """Run each reading (calibrating h first where it says so) on ``replicates`` independent
    ensembles: the preset's seed, then seeds from one ``SeedSequence`` (``seeds.replicate_seeds``).
    h is calibrated once per reading, on the preset's seed, and kept for every ensemble."""
    from ..progress import ProgressReporter

    by_key = {run.figure.key: run for run in runs}
    listeners = (lambda: [ProgressReporter()]) if progress else list
    ensembles = {}  # (figure, --set options, seed) -> (scene, outcome): the averaging readings share them
    calibrated = {}  # (figure, --set options but the slopes') -> calibrated h

    def ensemble(base: FigureRun, data: dict, overrides: list[str], seed: int | None, folder: Path):
        """The reading's ensemble of root ``seed`` (None: the preset's own)."""
        if not overrides and seed is None:  # the figure's own run
            return base.scene, base.outcome
        key = (base.figure.key, tuple(overrides), seed)
        if key not in ensembles:
            seeded = overrides + ([] if seed is None else [f"seed={seed}"])
            scene = build_scene(apply_overrides(data, [*seeded, "output.plot=false"]), source=str(base.preset_path))
            output_subfolder(out_dir, str(folder.relative_to(out_dir)), "run the report again")
            seen = mark()
            try:
                outcome = run_or_read_back(scene, folder, options, listeners())
            except OutputRefused:
                refuse_foreign_files(folder)  # its run's advice, --force, does not lift it
                raise
            if outcome.status in ("interrupted", "cancelled") or interrupted_since(seen):
                raise KeyboardInterrupt  # the report stops: what finished is kept
            ensembles[key] = scene, outcome
        return ensembles[key]

    rows = []
    for number, reading in enumerate(readings, start=1):
        if progress:
            print(f"reading {number}/{len(readings)}: {reading.figure}, {reading.name}", file=sys.stderr, flush=True)
        base = by_key[reading.figure]
        data = load_preset_file(base.preset_path)
        overrides = list(reading.overrides)
        if reading.same_c0_as:
            c0 = by_key[reading.same_c0_as].scene.spectrum.c0()
            overrides += ["spectrum.params.rms_height=null", f"spectrum.params.c0={float(f'{c0:.6g}')!r}"]
        h = None
        if reading.calibrate:  # the counts do not depend on the slopes: one calibration serves every estimator
            lines = (reading.figure, *(o for o in overrides if not o.startswith("slope.")))
            if lines not in calibrated:
                calibrated[lines] = calibrated_rms_height(apply_overrides(data, overrides), options=options,
                                                          listeners=listeners())  # fmt: skip
            h = calibrated[lines]
            overrides.append(f"spectrum.params.rms_height={h!r}")
        folder = out_dir / folder_name / f"{number:02d}-{reading.figure}"
        first_scene, first = ensemble(base, data, overrides, None, folder)
        seeds = replicate_seeds(first_scene.preset.seed, replicates)
        fits, last_counts = [], []
        for k, seed in enumerate(seeds):
            scene, outcome = (first_scene, first) if k == 0 else ensemble(
                base, data, overrides, seed, folder.with_name(f"{folder.name}-r{k + 1}"))  # fmt: skip
            settings = scene.preset.fit
            fits.append(refit(outcome.f, outcome.per_realization, reading.average,
                              bootstrap=settings.bootstrap, confidence=settings.confidence, seed=scene.preset.seed))  # fmt: skip
            last_counts.append(float(outcome.contact_count[-1]))
        counts = (float(first.contact_count[0]), float(first.contact_count[-1]))
        loads = (float(first.loads[0]), float(first.loads[-1]))
        rows.append(ReadingRow(reading, overrides, fits[0], counts, loads, folder if overrides else base.folder, h,
                               fits, seeds, last_counts))  # fmt: skip
    return rows
