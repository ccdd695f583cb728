"""Collecting realizations into per-force statistics and the fit.

Rows are stored by realization index, so the statistics do not depend on the
order in which realizations finish (serial, pool, any worker count).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .fit import LogFit, fit_log_law
from ..plugin import ForceNormalisation
from ..preset import Scene
from ..preset.seeds import bootstrap_rng


MIN_CONTACTS_FIRST_LOAD = 3  # mean points in contact at the first load below which a fit carries a caveat


def few_contacts_caveat(count: float) -> str:
    """The caveat of a fit whose first load touches fewer than 3 points (mean ``count``)."""
    return (
        f"fewer than {MIN_CONTACTS_FIRST_LOAD} points in contact at the first load (mean {count:.2f}): "
        "xi there rests on one or two slopes, so the low-f end of the fit is unreliable"
    )


FULL_CONTACT = 0.999  # mean contact fraction from which the whole profile is taken to be in contact


def full_contact_caveat(first: int, loads: np.ndarray) -> str:
    """The caveat of a fit whose loads reach full contact, from load index ``first`` on."""
    return (
        f"the whole profile is in contact from load {first + 1} of {loads.size} on (load {loads[first]:.4g}): "
        "xi is 1 there by definition, so those loads measure no roughness; lower the loads"
    )


MIN_HALF_LOAD_POINTS = 5  # fewer points carrying half the force, at half the loads or more: a caveat
SPIKE_RMS = 8.0  # the highest point this many rms heights above the mean: a caveat (a Gaussian map of 1e9 points reaches 6.1)


def few_carriers_caveat(half: np.ndarray, f: np.ndarray) -> str | None:
    """The caveat of a run where, at half its loads or more, fewer than ``MIN_HALF_LOAD_POINTS``
    points carry half the force (mean ``half`` per load): a spike or one island carries it."""
    few = np.flatnonzero(half < MIN_HALF_LOAD_POINTS)
    if not half.size or few.size * 2 < half.size:
        return None
    return (
        f"at {few.size} of {half.size} loads (up to f = {float(f[few[-1]]):.4g}) fewer than {MIN_HALF_LOAD_POINTS} "
        f"points carry half the force (as few as {float(np.nanmin(half)):.3g}; half_load_points in curve.csv): xi "
        "there measures a spike or a single island, not the surface's roughness"
    )


def same_curves_caveat(xi: np.ndarray) -> str | None:
    """The caveat of a run of two or more realizations whose curves are all one (rows of ``xi``,
    NaN where undefined, equal to the last bit): nothing random varied, a measured profile or
    surface pressed as it is, so the bootstrap over realizations has no spread to measure."""
    if xi.shape[0] < 2 or not np.array_equal(xi[1], xi[0], equal_nan=True):  # the usual answer, in microseconds
        return None
    if not np.array_equal(xi, np.broadcast_to(xi[0], xi.shape), equal_nan=True):
        return None
    return (
        f"all {xi.shape[0]} realizations gave the same curve (nothing random varies: a measured profile or surface "
        "pressed as it is): the ensemble is one surface, the bootstrap interval has no spread between surfaces to "
        "measure (the std.err is the fit's own), and realizations: 1 gives the same numbers"
    )


def few_resamples_caveat(fit: LogFit) -> str | None:
    """The caveat of intervals drawn from too few bootstrap resamples: fewer than 2 / (1 -
    confidence) leave a tail of the percentile interval without a single resample (with 1, the
    interval is that resample's, which need not hold the estimate)."""
    need = math.ceil(2 / (1 - fit.confidence) - 1e-9)
    if not 0 < fit.bootstrap < need:
        return None
    return (
        f"the {100 * fit.confidence:g}% intervals rest on {fit.bootstrap} bootstrap resample(s): fewer than {need} "
        "leave a tail without one, so the interval is too narrow (or misses the estimate); raise fit.bootstrap"
    )


def spike_caveat(peak: float) -> str:
    """The caveat of a profile whose highest point stands ``peak`` rms heights above its mean."""
    return (
        f"the highest point stands {peak:.3g} rms heights above the mean height (more than {SPIKE_RMS:g}; a Gaussian "
        "surface of a billion points reaches about 6): a spike would carry the first loads alone; look at the scan"
    )


def constant_xi_refusal(per_count: np.ndarray, xi: np.ndarray, points: int, loads: np.ndarray) -> str | None:
    """Why no law is fitted when every load presses the same points (each realization's count
    the same at every load, and the mean xi with it, to 1e-9 relative), all of them or not;
    None when the contact changes with the load (a profile whose xi stays put while its
    contact grows, a sawtooth's, has a law: b = 0)."""
    defined = xi[np.isfinite(xi)]
    if not (per_count.size and defined.size) or np.any(np.ptp(per_count, axis=1) > 0):
        return None
    if np.ptp(defined) > 1e-9 * np.max(np.abs(defined)):
        return None
    span = f"from {loads[0]:.4g} to {loads[-1]:.4g}"
    if np.all(per_count == points):
        return (
            f"no law: the whole profile is in contact at every load {span} (xi is 1 by definition); lower the loads "
            "(frictionlab validate shows where full contact starts)"
        )
    return (
        f"no law: every load {span} presses the same points (mean {float(per_count[:, 0].mean()):.4g} in contact), "
        f"so xi is {float(defined[0]):.4g} at every load and a law in ln f is undefined; raise the loads or widen "
        "their range"
    )


@dataclass
class RunOutcome:
    """The statistics of what finished. Per-force arrays have one entry per load
    step; per-realization arrays one row per finished realization, in index order."""

    status: str  # completed | cancelled | interrupted | failed
    requested: int
    indices: np.ndarray  # finished ok, ascending
    failures: list[tuple[int, str]]
    loads: np.ndarray
    force: np.ndarray  # mean total load per step (its meaning: ``normalisation.load``)
    f: np.ndarray  # dimensionless force: force / force_unit (``normalisation.definition``)
    xi: np.ndarray  # ensemble mean of slope_rms_contact / slope_rms_line, over the lines where it is defined
    xi_sem: np.ndarray
    lines_used: np.ndarray  # how many realizations have xi defined at each step (all, unless slopes may be undefined)
    contact_count: np.ndarray  # ensemble mean
    contact_fraction: np.ndarray
    indentation: np.ndarray
    per_realization: dict[str, np.ndarray]
    fit: LogFit | None
    rms_height: float
    force_unit: float  # k h X: the load at f = 1
    own_rms_height: bool  # h of f is each profile's own measured rms height (profile_rms_height), not the nominal
    stiffness: float
    normalisation: ForceNormalisation
    elapsed: float  # wall time of this invocation (a resumed run counts only what it ran)
    workers: int
    error: str | None = None
    compute_seconds: float = 0.0  # summed over the finished realizations, restored ones included
    real_area_corrected: np.ndarray | None = None  # ensemble mean; None when the solver does not correct its area
    # g_r (the rms slope over the corrected real contact), kappa and kappa_r (area_law_ratio with the
    # surface's rms gradient and with g_r): means over the realizations; None unless the solver gives g_r
    real_gradient_rms: np.ndarray | None = None
    kappa: np.ndarray | None = None
    kappa_r: np.ndarray | None = None
    contact_spots: np.ndarray | None = None  # mean over realizations; None unless the solver counts spots
    extra: dict = field(default_factory=dict)
    # the spectrum's caveats: of the file it read (input_summary: a tilt left in), of its parameters (caveats())
    spectrum_caveats: tuple[str, ...] = ()
    half_load_points: np.ndarray | None = None  # ensemble mean of the points carrying half the force (NaN: not said)
    peak_rms: float = math.nan  # the largest (max z - mean z) / rms height over the profiles
    no_law: str | None = None  # why no law was fitted though realizations finished (xi the same at every load)

    @property
    def done(self) -> int:
        return int(self.indices.size)

    @property
    def sessions_elapsed(self) -> float:
        """Wall seconds of the run's sessions summed, as summary.json records them: a resume's
        own and what its folder recorded before (``extra["recorded_seconds"]``)."""
        return float(self.extra.get("recorded_seconds", self.elapsed))

    @property
    def caveats(self) -> list[str]:
        """What a reader of the fit must know: too few points in contact at the first load
        (the rms slope in contact of one or two points is mostly noise), the whole
        profile in contact from some load on (xi is 1 there by definition), or lines
        without xi at some load (averaged over fewer lines there)."""
        if self.no_law:  # and why, where a spike makes it
            return [self.no_law, *self.spectrum_caveats] + ([spike_caveat(self.peak_rms)] if self.peak_rms > SPIKE_RMS else [])
        if self.fit is None or not self.contact_count.size:
            return []
        caveats = list(self.spectrum_caveats)
        if caveat := few_resamples_caveat(self.fit):
            caveats.append(caveat)
        if self.contact_count[0] < MIN_CONTACTS_FIRST_LOAD:
            caveats.append(few_contacts_caveat(float(self.contact_count[0])))
        full = np.flatnonzero(self.contact_fraction >= FULL_CONTACT)
        if full.size:
            caveats.append(full_contact_caveat(int(full[0]), self.loads))
        half = self.half_load_points
        if half is not None and np.isfinite(half).all() and (caveat := few_carriers_caveat(half, self.f)):
            caveats.append(caveat)
        if self.peak_rms > SPIKE_RMS:
            caveats.append(spike_caveat(self.peak_rms))
        xi = self.per_realization.get("xi")  # None in a sweep's held copy (PointResult.held)
        if xi is not None and (caveat := same_curves_caveat(xi)) is not None:
            caveats.append(caveat)
        if self.lines_used.size and self.lines_used.min() < self.done:
            caveats.append(
                f"up to {self.done - int(self.lines_used.min())} of {self.done} lines have no xi at a load (no point "
                "in contact has a slope): xi there is the mean over the others (lines_used in curve.csv)"
            )
        return caveats

    @property
    def extent(self) -> float:
        """X of f = F / (k h X): the profile's length, area, MDR length, or 1."""
        return self.force_unit / (self.stiffness * self.rms_height)


def area_law_ratio(fraction, force, nominal_area: float, stiffness: float, gradient) -> np.ndarray:
    """(A / A0) E* g / p per realization (rows) and load: kappa of A / A0 = kappa p / (E* g),
    p = F / A0 the nominal pressure; ``gradient`` one rms gradient per realization (the
    surface's: kappa) or per realization and load (over the real contact, g_r: kappa_r)."""
    fraction = np.atleast_2d(np.asarray(fraction, float))
    force = np.asarray(force, float)
    gradient = np.asarray(gradient, float)
    gradient = gradient.reshape(-1, 1) if gradient.ndim == 1 else np.atleast_2d(gradient)
    if fraction.shape[-1] != force.shape[-1] or gradient.shape[0] != fraction.shape[0]:
        raise ValueError(f"shapes differ: fraction {fraction.shape}, force {force.shape}, gradient {gradient.shape}")
    return fraction * stiffness * gradient * nominal_area / force


def nominal_area(normalisation: ForceNormalisation, extent: float) -> float:
    """A0 of a surface from the X of its f: X itself, or A0 = pi (X / 2)^2 for X = 2 sqrt(A0 / pi)."""
    return math.pi * (extent / 2) ** 2 if normalisation.extent == "mdr length" else float(extent)


OWN_H_TOLERANCE = 1e-9  # relative spread allowed between the profiles' own rms heights


def defined_statistics(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per step: the mean of xi (realizations in rows) over the realizations where it is
    defined (not NaN: no point in contact had a slope), its standard error, and how many
    realizations that is. NaN where fewer than one (two, for the error) are."""
    used = np.count_nonzero(~np.isnan(xi), axis=0)
    if not xi.shape[0]:
        return np.full(xi.shape[1], math.nan), np.full(xi.shape[1], math.nan), used
    if used.min() == xi.shape[0]:  # every xi defined: the plain mean, bit for bit
        n = xi.shape[0]
        sem = xi.std(axis=0, ddof=1) / math.sqrt(n) if n >= 2 else np.full(xi.shape[1], math.nan)
        return xi.mean(axis=0), sem, used
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a step with no (or one) defined xi: NaN, said by used
        mean = np.nanmean(xi, axis=0)
        sem = np.nanstd(xi, axis=0, ddof=1) / np.sqrt(used)
    return mean, np.where(used >= 2, sem, math.nan), used


class Accumulator:
    """Collects RealizationResults of one scene."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.loads = scene.loads
        self.results = {}
        self.failures: dict[int, str] = {}

    @property
    def done(self) -> int:
        return len(self.results) + len(self.failures)

    def add(self, result) -> None:
        """Keep ``result``, replacing any earlier one of its index (never counted twice)."""
        if result.ok:
            self.failures.pop(result.index, None)
            self.results[result.index] = result
        else:
            self.results.pop(result.index, None)
            self.failures[result.index] = result.error

    def stack(self, name: str) -> np.ndarray:
        """One row per finished realization of its per-load array ``name`` (NaN where it has none)."""
        missing = np.full(self.loads.size, math.nan)
        rows = [row if (row := getattr(self.results[i], name)) is not None else missing for i in sorted(self.results)]
        return np.vstack(rows) if rows else np.empty((0, self.loads.size))

    def finish(self, *, status: str, elapsed: float, workers: int, error: str | None = None) -> RunOutcome:
        scene = self.scene
        indices = np.array(sorted(self.results), dtype=np.int64)
        per = {
            "index": indices,
            "xi": self.stack("xi"),
            "contact_count": self.stack("contact_count").astype(np.int64),
            "indentation": self.stack("indentation"),
            "slope_rms_line": np.array([self.results[i].slope_rms_line for i in indices]),
            "measured_rms_height": np.array([self.results[i].measured_rms_height for i in indices]),
        }
        own = np.array([self.results[i].own_rms_height for i in indices])
        peaks = np.array([self.results[i].peak_rms for i in indices])
        own_rms_height = bool(np.isfinite(own).any())
        if own_rms_height:
            per["own_rms_height"] = own
        if scene.forces_vary:
            per["force"] = self.stack("force")
        per["half_load_points"] = self.stack("half_load_points")
        if scene.solver.corrected_area:
            per["real_area_corrected"] = self.stack("real_area_corrected")
        if scene.solver.real_gradient:
            per["real_gradient_rms"] = self.stack("real_gradient_rms")
        if scene.solver.counts_spots:
            per["contact_spots"] = self.stack("contact_spots")
        n = indices.size
        first = self.results[indices[0]] if n else None
        points = first.points if first else 0
        unit = first.force_unit if first else math.nan  # every realization has the grid of the first
        rms_height = (float(own[0]) if own_rms_height else float(scene.generator.rms_height())) if n else math.nan
        stiffness = float(scene.solver.stiffness())
        given = self.loads if scene.solver_loads is None else scene.solver_loads  # NaN-free before any realization
        force = per["force"].mean(axis=0) if "force" in per and n else given.astype(float)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # an overflow is reported below
            f = force / unit if n else np.full(self.loads.size, math.nan)
        nan_row = np.full(self.loads.size, math.nan)
        xi_mean, xi_sem, used = defined_statistics(per["xi"])
        count = per["contact_count"].mean(axis=0) if n else nan_row
        fit, no_law = None, None
        if not n and self.failures and status == "completed":
            # every realization failed: nothing was computed, whatever the count says
            index, reason = min(self.failures.items())
            status, error = "failed", f"no realization finished: {len(self.failures)} failed; the first, #{index}: {reason}"
        if own_rms_height and not np.allclose(own, own[0], rtol=OWN_H_TOLERANCE, atol=0.0):
            status, error = "failed", (
                f"the profiles' own rms heights h (the spectrum's profile_rms_height) range from {np.nanmin(own):g} "
                f"to {np.nanmax(own):g}: f = F / (k h X) needs one h for the whole ensemble"
            )
        elif n and not np.all(np.isfinite(f) & (f > 0)):
            # a plugin's numbers overflowed: say which, rather than fail in the fit
            status, error = "failed", (
                f"the dimensionless force f = F / (k h X) is not finite and > 0 at every load step "
                f"(k h X = {unit:g} with stiffness k = {stiffness:g}, h = {rms_height:g}; F from {np.min(force):g} "
                f"to {np.max(force):g}): the preset's magnitudes (solver.params, spectrum.params, loading) "
                "leave double precision"
            )
        elif n and np.count_nonzero(used) < 2:
            status, error = "failed", (
                f"xi is defined at {np.count_nonzero(used)} of {used.size} load steps (at the others no point in "
                "contact has a slope: the slope estimator leaves the ends of the profile without one): a fit needs "
                "two; raise the loads"
            )
        elif n and (refusal := constant_xi_refusal(per["contact_count"], xi_mean, points, force)):
            status, error, no_law = "failed", refusal, refusal
        elif n:
            settings = scene.preset.fit
            fit = fit_log_law(
                f,
                per["xi"],
                bootstrap=settings.bootstrap,
                confidence=settings.confidence,
                rng=bootstrap_rng(scene.preset.seed),
            )
        gradients = self._gradients(per, force, points, unit / (stiffness * rms_height) if n else math.nan, stiffness)
        return RunOutcome(
            status=status,
            requested=scene.preset.realizations,
            indices=indices,
            failures=sorted(self.failures.items()),
            loads=self.loads,
            force=force,
            f=f,
            xi=xi_mean,
            xi_sem=xi_sem,
            lines_used=used,
            contact_count=count,
            contact_fraction=count / points if points else nan_row,
            indentation=per["indentation"].mean(axis=0) if n else nan_row,
            per_realization=per,
            fit=fit,
            rms_height=rms_height,
            force_unit=unit,
            own_rms_height=own_rms_height,
            stiffness=stiffness,
            normalisation=scene.normalisation,
            elapsed=elapsed,
            workers=workers,
            error=error,
            spectrum_caveats=(*(scene.spectrum.input_summary() or {}).get("caveats", ()), *scene.spectrum.caveats()),
            compute_seconds=float(sum(self.results[i].seconds for i in indices)),
            real_area_corrected=(per["real_area_corrected"].mean(axis=0) if n else nan_row)
            if scene.solver.corrected_area else None,
            **gradients,
            contact_spots=(per["contact_spots"].mean(axis=0) if n else nan_row) if scene.solver.counts_spots else None,
            half_load_points=per["half_load_points"].mean(axis=0) if n else nan_row,
            peak_rms=float(np.nanmax(peaks)) if np.isfinite(peaks).any() else math.nan,
            no_law=no_law,
        )

    def _gradients(self, per: dict, force: np.ndarray, points: int, extent: float, stiffness: float) -> dict:
        """g_r, kappa and kappa_r, each the mean over the realizations per load (NaN where a
        chunk of an older version has no g_r); {} when the solver gives no g_r. The area is
        the corrected one where the solver corrects it, else the pixel count."""
        if not self.scene.solver.real_gradient:
            return {}
        if not per["index"].size:
            nan_row = np.full(self.loads.size, math.nan)
            return {"real_gradient_rms": nan_row, "kappa": nan_row, "kappa_r": nan_row}
        area = per.get("real_area_corrected", per["contact_count"] / points)
        loads = per.get("force", force)
        a0 = nominal_area(self.scene.normalisation, extent)
        kappa = area_law_ratio(area, loads, a0, stiffness, per["slope_rms_line"])
        kappa_r = area_law_ratio(area, loads, a0, stiffness, per["real_gradient_rms"])
        return {"real_gradient_rms": per["real_gradient_rms"].mean(axis=0), "kappa": kappa.mean(axis=0),
                "kappa_r": kappa_r.mean(axis=0)}  # fmt: skip
