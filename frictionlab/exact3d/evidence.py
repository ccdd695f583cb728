"""What the page needs before it may say "converged", "a log law holds", or "kappa_r is
closer to constant": the grids compared on the same surfaces (paired) with bootstrap
intervals and a Richardson limit, the model test per H and family, g_r and kappa_r
against the load, and the few-spot regime. Read from finished ensembles; nothing here
runs a solver."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..compute.ensemble import area_law_ratio
from ..preset.seeds import bootstrap_rng
from .analysis import KAPPA_WINDOW
from .plan import MAIN, Ensemble, StudyRuns
from .statistics import Estimate, Extrapolation, ModelTest, compare_models, extrapolate, paired_bootstrap

MANY_SPOTS = 10  # contact spots per surface below which a load is in the few-spot regime
GRADIENT_WINDOW = (0.005, 0.2)  # contact fractions over which kappa and kappa_r are compared for constancy
QUANTITIES = ("a", "b", "κ")


def _nominal_area(e: Ensemble) -> float:
    return math.pi * (e.outcome.extent / 2) ** 2


def _rows(e: Ensemble, indices: np.ndarray, name: str) -> np.ndarray:
    per = e.outcome.per_realization
    keep = np.isin(per["index"], indices)
    return np.asarray(per[name][keep], float)


def _area(e: Ensemble) -> np.ndarray:
    """Each surface's corrected real area fraction per load (rows: its realizations)."""
    return np.asarray(e.outcome.per_realization["real_area_corrected"], float)


def kappa_rows(e: Ensemble, gradient: str = "slope_rms_line") -> np.ndarray:
    """kappa (``gradient`` the surface's rms gradient) or kappa_r (``real_gradient_rms``) per
    surface and load."""
    o = e.outcome
    return area_law_ratio(_area(e), o.force, _nominal_area(e), o.stiffness, o.per_realization[gradient])


def _window(e: Ensemble, window: tuple[float, float]) -> np.ndarray:
    fraction = _area(e).mean(axis=0)
    return (fraction > window[0]) & (fraction <= window[1])


# ------------------------------------------------------------------ convergence


@dataclass(frozen=True)
class Quantity:
    name: str
    values: np.ndarray  # per grid, on the paired surfaces
    low: np.ndarray
    high: np.ndarray
    changes: list[tuple[float, float, float]]  # (change, low, high) between successive grids
    limit: Extrapolation | None  # from the three finest grids


@dataclass(frozen=True)
class Convergence:
    hurst: float
    grids: list[Ensemble]
    surfaces: int
    quantities: dict[str, Quantity]
    xi_changes: list[Estimate]  # per load: finer grid's mean xi - coarser's, successive grids


def _law_and_kappa(f: np.ndarray, windows: list[np.ndarray], *rows: np.ndarray) -> np.ndarray:
    """[a per grid, b per grid, kappa per grid] of paired rows: xi rows of each grid, then kappa rows."""
    count = len(rows) // 2
    x = np.log(f)
    fits = [np.polyfit(x, xi.mean(axis=0), 1) for xi in rows[:count]]
    kappas = [k[:, w].mean() for k, w in zip(rows[count:], windows)]
    return np.array([*(p[1] for p in fits), *(p[0] for p in fits), *kappas])


def convergence(runs: StudyRuns, hurst: float, bootstrap: int, confidence: float = 0.95) -> Convergence | None:
    """The main family's regular grids at ``hurst`` (at least two), on the surfaces all of
    them ran: a, b and kappa per grid with intervals, their paired changes, and their
    Richardson limit from the three finest (the page says which grids are quoted); None
    with fewer than two grids."""
    grids = [e for e in runs.exact_grids(hurst, MAIN) if e.points in runs.plan.resolutions]
    if len(grids) < 2:
        return None
    common = grids[0].outcome.indices
    for e in grids[1:]:
        common = np.intersect1d(common, e.outcome.indices)
    f = grids[-1].outcome.f
    xi = [_rows(e, common, "xi") for e in grids]
    kappa = [kappa_rows(e)[np.isin(e.outcome.per_realization["index"], common)] for e in grids]
    windows = [_window(e, KAPPA_WINDOW) for e in grids]
    rng = bootstrap_rng(grids[-1].scene.preset.seed)
    est = paired_bootstrap([*xi, *kappa], lambda *rows: _law_and_kappa(f, windows, *rows), rng=rng,
                           bootstrap=bootstrap, confidence=confidence)  # fmt: skip
    n = len(grids)
    quantities = {}
    for q, name in enumerate(QUANTITIES):
        span = slice(q * n, (q + 1) * n)
        values, draws = np.asarray(est.value)[span], est.draws[:, span]
        changes = []
        for i in range(n - 1):
            diff = draws[:, i + 1] - draws[:, i]
            low, high = np.percentile(diff, [50 * (1 - confidence), 50 * (1 + confidence)]) if diff.size else (math.nan,) * 2
            changes.append((float(values[i + 1] - values[i]), float(low), float(high)))
        points = [e.points for e in grids[-3:]]
        limit = extrapolate(values[-3:], draws[:, -3:], points, confidence=confidence) if n >= 3 and draws.size else None
        quantities[name] = Quantity(name, values, np.asarray(est.interval[0])[span], np.asarray(est.interval[1])[span],
                                    changes, limit)  # fmt: skip
    xi_changes = [paired_bootstrap([c, d], lambda c, d: d.mean(axis=0) - c.mean(axis=0), rng=rng, bootstrap=bootstrap,
                                   confidence=confidence) for c, d in zip(xi, xi[1:])]  # fmt: skip
    return Convergence(hurst, grids, int(common.size), quantities, xi_changes)


# ------------------------------------------------------------------ the model test


@dataclass(frozen=True)
class Models:
    ensemble: Ensemble
    full: ModelTest  # every load
    many_spots: ModelTest | None  # the loads with at least MANY_SPOTS spots per surface (None: fewer than 6 such)


def model_test(e: Ensemble) -> Models:
    o = e.outcome
    xi = o.per_realization["xi"]
    spots = o.per_realization.get("contact_spots")
    many = None
    if spots is not None:
        keep = np.nanmean(spots, axis=0) >= MANY_SPOTS
        if np.count_nonzero(keep) >= 6:
            many = compare_models(o.f[keep], xi[:, keep])
    return Models(e, compare_models(o.f, xi), many)


# ------------------------------------------------------------------ g_r and kappa_r


@dataclass(frozen=True)
class GradientCurves:
    """g_r / g, kappa and kappa_r per load (mean over surfaces, bootstrap band), against
    x = p / (E* g); and the drift of kappa and kappa_r over GRADIENT_WINDOW: the slope of
    each against ln x over those loads, relative to its mean, with paired intervals."""

    ensemble: Ensemble
    x: np.ndarray
    ratio: Estimate  # g_r / g
    kappa: Estimate
    kappa_r: Estimate
    drift: Estimate | None  # [kappa's, kappa_r's, |kappa's| - |kappa_r's|]; None with fewer than 3 loads in the window


def _drift(x: np.ndarray, *rows: np.ndarray) -> np.ndarray:
    slopes = []
    for k in rows:
        mean = k.mean(axis=0)
        slopes.append(np.polyfit(np.log(x), mean, 1)[0] / mean.mean())
    return np.array([*slopes, abs(slopes[0]) - abs(slopes[1])])


def gradient_curves(e: Ensemble, bootstrap: int, confidence: float = 0.95) -> GradientCurves | None:
    per = e.outcome.per_realization
    if "real_gradient_rms" not in per or "real_area_corrected" not in per:
        return None
    g_r, g = np.asarray(per["real_gradient_rms"], float), np.asarray(per["slope_rms_line"], float)
    if not np.isfinite(g_r).all():  # a run from before g_r was recorded
        return None
    o = e.outcome
    x = o.force / _nominal_area(e) / (o.stiffness * float(np.mean(g)))
    kappa, kappa_r = kappa_rows(e), kappa_rows(e, "real_gradient_rms")
    rng = bootstrap_rng(e.scene.preset.seed)

    def band(rows):
        return paired_bootstrap([rows], lambda r: r.mean(axis=0), rng=rng, bootstrap=bootstrap, confidence=confidence)

    window = _window(e, GRADIENT_WINDOW)
    drift = None
    if np.count_nonzero(window) >= 3:
        drift = paired_bootstrap([kappa[:, window], kappa_r[:, window]], lambda a, b: _drift(x[window], a, b), rng=rng,
                                 bootstrap=bootstrap, confidence=confidence)  # fmt: skip
    return GradientCurves(e, x, band(g_r / g[:, None]), band(kappa), band(kappa_r), drift)


# ------------------------------------------------------------------ few spots


@dataclass(frozen=True)
class FewSpots:
    """Per load: the mean number of spots per surface, the corrected area fraction, and the
    local exponent d ln A / d ln F between successive loads (Hertzian spots that stay
    isolated: 2/3; many spots appearing as the load grows: about 1)."""

    ensemble: Ensemble
    force: np.ndarray
    spots: np.ndarray
    area: np.ndarray
    exponent: np.ndarray  # at the geometric mid-points of successive loads
    few: np.ndarray  # the loads with fewer than MANY_SPOTS spots per surface


def few_spots(e: Ensemble) -> FewSpots | None:
    spots = e.outcome.per_realization.get("contact_spots")
    if spots is None or not np.isfinite(spots).all():
        return None
    area = _area(e).mean(axis=0)
    force = e.outcome.force
    exponent = np.diff(np.log(area)) / np.diff(np.log(force))
    mean = spots.mean(axis=0)
    # the loads below the first with MANY_SPOTS: at large loads the spots merge and grow few again
    many = np.flatnonzero(mean >= MANY_SPOTS)
    few = np.arange(mean.size) < (many[0] if many.size else mean.size)
    return FewSpots(e, force, mean, area, exponent, few)
