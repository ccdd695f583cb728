"""The study's numbers, from its finished ensembles: kappa of every exact ensemble (the
corrected and the raw pixel area, in the 0.5-5 % window and among few spots, and as a
curve), the surfaces' own statistics, and the fits redone on paired surfaces. The page
and the figures read these; nothing here runs a solver."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..compute.fit import LogFit, fit_log_law
from ..preset.seeds import bootstrap_rng, realization_rng
from .analysis import (
    FEW_SPOTS,
    KAPPA_WINDOW,
    Kappa,
    KappaCurve,
    contact_area_law,
    height_moments,
    kappa_curve,
    nayak_parameter,
)
from .evidence import Convergence, FewSpots, GradientCurves, Models, convergence, few_spots, gradient_curves, model_test
from .plan import BROAD, MAIN, SIDE, SPECTRAL, Ensemble, StudyRuns


@dataclass(frozen=True)
class KappaSet:
    """kappa of one exact ensemble: from the corrected area and from the pixel count in the
    window of contact fractions KAPPA_WINDOW, among FEW_SPOTS, and at every load."""

    corrected: Kappa
    raw: Kappa
    few_spots: Kappa
    curve: KappaCurve
    raw_curve: KappaCurve


@dataclass(frozen=True)
class SurfaceStats:
    """Per-surface height skewness, kurtosis and Nayak parameter of one ensemble's surfaces."""

    skewness: np.ndarray
    kurtosis: np.ndarray
    nayak: np.ndarray


def nominal_area(e: Ensemble) -> float:
    """A0 of the ensemble's surfaces, from f's L = 2 sqrt(A0 / pi)."""
    o = e.outcome
    return math.pi * (o.extent / 2) ** 2


def kappa_set(e: Ensemble, bootstrap: int) -> KappaSet:
    o = e.outcome
    per = o.per_realization
    corrected, raw = per["real_area_corrected"], per["contact_count"] / e.points**2  # square grids
    args = (o.force, nominal_area(e), o.stiffness, per["slope_rms_line"])

    def law(fraction, window):
        return contact_area_law(fraction, *args, rng=bootstrap_rng(e.scene.preset.seed), bootstrap=bootstrap, window=window)

    return KappaSet(
        corrected=law(corrected, KAPPA_WINDOW),
        raw=law(raw, KAPPA_WINDOW),
        few_spots=law(corrected, FEW_SPOTS),
        curve=kappa_curve(corrected, *args, rng=bootstrap_rng(e.scene.preset.seed), bootstrap=bootstrap),
        raw_curve=kappa_curve(raw, *args, rng=bootstrap_rng(e.scene.preset.seed), bootstrap=0),
    )


def surface_stats(e: Ensemble) -> SurfaceStats:
    """Skewness, kurtosis and Nayak parameter of each surface the ensemble pressed."""
    rows = []
    for index in e.outcome.indices:
        heights = e.scene.spectrum.generate(realization_rng(e.scene.preset.seed, int(index))).heights
        rows.append((*height_moments(heights), nayak_parameter(heights, e.spacing)))
    skewness, kurtosis, nayak = np.array(rows).T
    return SurfaceStats(skewness, kurtosis, nayak)


def refit_on(e: Ensemble, indices: np.ndarray, bootstrap: int) -> LogFit:
    """The fit of ``e`` redone on its surfaces ``indices`` only (paired with another ensemble)."""
    per = e.outcome.per_realization
    keep = np.isin(per["index"], indices)
    return fit_log_law(e.outcome.f, per["xi"][keep], bootstrap=bootstrap, rng=bootstrap_rng(e.scene.preset.seed))


def kappa_on(e: Ensemble, indices: np.ndarray, bootstrap: int) -> Kappa:
    """kappa (corrected area, KAPPA_WINDOW) of ``e`` on its surfaces ``indices`` only."""
    o, per = e.outcome, e.outcome.per_realization
    keep = np.isin(per["index"], indices)
    return contact_area_law(
        per["real_area_corrected"][keep], o.force, nominal_area(e), o.stiffness, per["slope_rms_line"][keep],
        rng=bootstrap_rng(e.scene.preset.seed), bootstrap=bootstrap, window=KAPPA_WINDOW,
    )  # fmt: skip


@dataclass(frozen=True)
class Paired:
    """Two ensembles of the same first surfaces: ``other`` (a finer grid, spectral
    gradients) against ``base`` refitted on those surfaces."""

    base: Ensemble
    other: Ensemble
    base_fit: LogFit
    base_kappa: Kappa
    other_kappa: Kappa
    surfaces: int

    @property
    def xi_gap(self) -> np.ndarray:
        """other's mean xi - base's, on the same surfaces, per load."""
        per = self.base.outcome.per_realization
        keep = np.isin(per["index"], self.other.outcome.indices)
        return self.other.outcome.xi - per["xi"][keep].mean(axis=0)


def paired(base: Ensemble, other: Ensemble, bootstrap: int) -> Paired:
    indices = other.outcome.indices
    return Paired(base, other, refit_on(base, indices, bootstrap), kappa_on(base, indices, bootstrap),
                  kappa_on(other, indices, bootstrap), int(indices.size))  # fmt: skip


@dataclass(frozen=True)
class PairedCurve:
    """One grid's mean xi (with the 95 % half-width of its standard error) and kappa curve on
    the surfaces every regular grid of its H ran: the figures set grids side by side on
    the same surfaces only, so a jump between them is not a change of ensemble."""

    surfaces: int
    xi: np.ndarray
    xi_half: np.ndarray
    kappa: KappaCurve


def paired_curves(runs: StudyRuns, bootstrap: int) -> dict[str, PairedCurve]:
    out = {}
    for hurst in runs.plan.hursts:
        grids = [e for e in runs.exact_grids(hurst) if e.points in runs.plan.resolutions]
        if not grids:
            continue
        common = grids[0].outcome.indices
        for e in grids[1:]:
            common = np.intersect1d(common, e.outcome.indices)
        for e in grids:
            o, per = e.outcome, e.outcome.per_realization
            keep = np.isin(per["index"], common)
            xi, n = per["xi"][keep], int(np.count_nonzero(keep))
            half = 1.96 * xi.std(axis=0, ddof=1) / math.sqrt(n) if n >= 2 else np.full(o.f.size, math.nan)
            kappa = kappa_curve(per["real_area_corrected"][keep], o.force, nominal_area(e), o.stiffness,
                                per["slope_rms_line"][keep], rng=bootstrap_rng(e.scene.preset.seed), bootstrap=bootstrap)  # fmt: skip
            out[e.folder.name] = PairedCurve(n, xi.mean(axis=0), half, kappa)
    return out


@dataclass
class Numbers:
    """Everything the page quotes, keyed by ensemble folder where per ensemble."""

    kappas: dict[str, KappaSet]
    stats: dict[tuple[str, float], SurfaceStats]  # (family, H): from the family's coarsest finished grid
    extra: list[Paired]  # finer grids against the finest regular one, same first surfaces
    spectral: list[Paired]  # spectral against forward-difference gradients, same grid and surfaces
    convergence: dict[float, Convergence]  # per H: the main family's quoted grids, paired
    models: dict[str, Models]  # per ensemble folder: the finest grid of each family and H
    gradients: dict[str, GradientCurves]  # per exact ensemble folder that recorded g_r
    spots: dict[str, FewSpots]  # per exact ensemble folder that counted spots
    paired: dict[str, PairedCurve]  # per regular grid of the main family: on the surfaces all of them ran

    def kappa(self, e: Ensemble) -> KappaSet:
        return self.kappas[e.folder.name]


def study_numbers(runs: StudyRuns) -> Numbers:
    bootstrap = runs.plan.bootstrap
    kappas = {e.folder.name: kappa_set(e, bootstrap) for e in runs.ensembles if e.exact}
    stats = {}
    for family in (MAIN, BROAD, SIDE):
        for hurst in runs.plan.hursts:
            grids = runs.exact_grids(hurst, family)
            if grids:
                stats[(family, hurst)] = surface_stats(grids[0])
    extra, spectral = [], []
    for hurst in runs.plan.hursts:
        regular = runs.find(hurst)
        for e in runs.exact_grids(hurst):
            if regular is not None and e.points not in runs.plan.resolutions:
                extra.append(paired(regular, e, bootstrap))
        for e in runs.exact_grids(hurst, SPECTRAL):
            base = runs.find(hurst, e.points)
            if base is not None:
                spectral.append(paired(base, e, bootstrap))
    converged = {h: c for h in runs.plan.hursts if (c := convergence(runs, h, bootstrap)) is not None}
    models = {}
    for family in (MAIN, BROAD):
        for hurst in runs.plan.hursts:
            grids = runs.exact_grids(hurst, family)
            if grids:
                models[grids[-1].folder.name] = model_test(grids[-1])
    exact = [e for e in runs.ensembles if e.exact]
    gradients = {e.folder.name: g for e in exact if (g := gradient_curves(e, bootstrap)) is not None}
    spots = {e.folder.name: s for e in exact if (s := few_spots(e)) is not None}
    return Numbers(kappas, stats, extra, spectral, converged, models, gradients, spots, paired_curves(runs, bootstrap))
