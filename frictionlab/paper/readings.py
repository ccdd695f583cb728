"""Readings of the paper's method: what it may have done where it does not say (cut-off,
amplitudes, slope estimator, averaging over realizations, normalisation per H), each
run for real and fitted like a run. Every reading is a preset plus ``--set`` options
(printed in the report's table, so any row can be rerun with ``frictionlab run``),
except the averaging readings, which re-average the default run's
``realizations.npz`` (``average_curve``)."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from ..errors import FrictionlabError
from ..fit import LogFit, fit_log_law
from ..options import RunOptions
from ..preset import apply_overrides, build_scene, load_preset_file
from ..runner import run_to_folder
from ..signals import interrupted_since, mark
from ..seeds import bootstrap_rng
from .calibration import calibrated_rms_height
from .figures import FigureRun


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


@dataclass
class ReadingRow:
    """What one reading gave: its fit of the averaged curve, contact counts at the first and last load."""

    reading: Reading
    overrides: list[str]
    fit: LogFit
    counts: tuple[float, float]
    loads: tuple[float, float]
    folder: Path | None
    rms_height: float | None = None  # the calibrated h, when the reading calibrates

    def hurst(self) -> float:
        """H of a Fig. 5 reading, from its ``--set`` options."""
        prefix = "spectrum.params.hurst="
        return float(yaml.safe_load(next(o for o in self.overrides if o.startswith(prefix))[len(prefix):]))


def run_readings(runs: list[FigureRun], out_dir: Path, options: RunOptions = RunOptions(), *, readings=READINGS,
                 folder_name="readings", progress: bool = False) -> list[ReadingRow]:  # fmt: skip
    from ..progress import ProgressReporter

    by_key = {run.figure.key: run for run in runs}
    listeners = (lambda: [ProgressReporter()]) if progress else list
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
        if reading.calibrate:
            h = calibrated_rms_height(apply_overrides(data, overrides), options=options, listeners=listeners())
            overrides.append(f"spectrum.params.rms_height={h!r}")
        if not overrides:  # the figure's own run, maybe re-averaged
            scene, outcome, folder = base.scene, base.outcome, base.folder
        else:
            scene = build_scene(apply_overrides(data, [*overrides, "output.plot=false"]), source=str(base.preset_path))
            folder = out_dir / folder_name / f"{number:02d}-{reading.figure}"
            seen = mark()
            outcome, _ = run_to_folder(scene, folder, options, listeners=listeners())
            if outcome.status in ("interrupted", "cancelled") or interrupted_since(seen):
                raise KeyboardInterrupt  # the report stops: what finished is kept
        settings = scene.preset.fit
        fit = refit(outcome.f, outcome.per_realization, reading.average,
                    bootstrap=settings.bootstrap, confidence=settings.confidence, seed=scene.preset.seed)  # fmt: skip
        counts = (float(outcome.contact_count[0]), float(outcome.contact_count[-1]))
        loads = (float(outcome.loads[0]), float(outcome.loads[-1]))
        rows.append(ReadingRow(reading, overrides, fit, counts, loads, folder, h))
    return rows
