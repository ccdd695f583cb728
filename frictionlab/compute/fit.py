"""The fit xi = a + b ln f: one result type (``LogFit``) and one bootstrap.

Least squares of the ensemble-mean xi over the force grid, with:
* classical standard errors of a and b from the residuals;
* bootstrap confidence intervals, resampling whole realizations (the
  independent units) with a seeded Generator, and refitting;
* R^2 and the residual rms, because the log law fits poorly at small H.

The mean over realizations is the usual average; a study may fit another one
(``average``: a function of the realizations' weights, see ``fit_log_law``)
with the same resamples.
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace

import numpy as np

from ..io.values import number_or_nan

NAN2 = (math.nan, math.nan)

BOOTSTRAP_BLOCK_BYTES = 64 * 2**20
"""The most bytes of bootstrap counts (resamples x realizations, int64), or of resampled curves
(resamples x forces), formed at once: a bootstrap of 100,000 over 10,000 realizations drawn whole
took 7.5 GiB after the run, and failed there."""

Average = Callable[[np.ndarray | None], np.ndarray]
"""``average(weights)``: the curve xi(f) averaged over realizations with ``weights``
(M,) or (B, M) (whole-number bootstrap counts), or with weight 1 each for None."""


@dataclass(frozen=True)
class LogFit:
    """A fit of xi = a + b ln f. What is not known is NaN: an interim fit (no
    bootstrap) has no intervals; a law given by hand may have no errors."""

    a: float
    b: float
    a_se: float = math.nan  # least squares over the force grid: neighbouring forces correlate, it understates
    b_se: float = math.nan
    a_se_bootstrap: float = math.nan  # the bootstrap's standard deviation over realizations: the intervals' spread
    b_se_bootstrap: float = math.nan
    a_ci: tuple[float, float] = NAN2
    b_ci: tuple[float, float] = NAN2
    confidence: float = 0.95
    bootstrap: int = 0  # resamples behind the intervals (0: none)
    r2: float = math.nan
    residual_rms: float = math.nan
    points: int = 0  # load steps fitted

    def to_dict(self) -> dict:
        """As summary.json stores it (NaN written as null)."""
        return {k: json_safe(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict) -> LogFit:
        """The fit of a summary.json (null read as NaN); KeyError without a or b."""

        def interval(value) -> tuple[float, float]:
            if isinstance(value, list | tuple) and len(value) == 2:
                return number_or_nan(value[0]), number_or_nan(value[1])
            return NAN2

        return cls(
            a=number_or_nan(data["a"]),
            b=number_or_nan(data["b"]),
            a_se=number_or_nan(data.get("a_se")),
            b_se=number_or_nan(data.get("b_se")),
            a_se_bootstrap=number_or_nan(data.get("a_se_bootstrap")),
            b_se_bootstrap=number_or_nan(data.get("b_se_bootstrap")),
            a_ci=interval(data.get("a_ci")),
            b_ci=interval(data.get("b_ci")),
            confidence=number_or_nan(data.get("confidence", 0.95)),
            bootstrap=int(data.get("bootstrap") or 0),
            r2=number_or_nan(data.get("r2")),
            residual_rms=number_or_nan(data.get("residual_rms")),
            points=int(data.get("points") or 0),
        )

    @property
    def standard_errors(self) -> tuple[float, float]:
        """The standard errors of a and b a reader is shown: the bootstrap's over realizations,
        beside its intervals; the least-squares ones over the force grid where none ran."""
        if math.isnan(self.a_se_bootstrap):
            return self.a_se, self.b_se
        return self.a_se_bootstrap, self.b_se_bootstrap

    def xi(self, f):
        """a + b ln f."""
        return self.a + self.b * np.log(f)

    def __repr__(self) -> str:  # rounded as the CLI prints a fit; the exact numbers are the fields
        level = ci_label(self.confidence) + (f", bootstrap {self.bootstrap}" if self.bootstrap else "")
        fitted = f"; R² = {format_number(self.r2)}, {self.points} points" if self.points else ""  # else a law given by hand
        return f"LogFit(a = {format_estimate(self.a, self.a_ci)}, b = {format_estimate(self.b, self.b_ci)} ({level}){fitted})"


def json_safe(value):
    """NaN has no JSON spelling: write null."""
    if isinstance(value, tuple | list):
        return [json_safe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def format_number(value: float, digits: int = 4) -> str:
    """``value`` with ``digits`` decimals, or in ``g`` form when that would run long (from 1e6)."""
    return f"{value:.{digits}f}" if abs(value) < 1e6 else f"{value:.{digits + 2}g}"


def ci_label(confidence: float) -> str:
    """The intervals' level as every front end says it: ``95% CI``."""
    return f"{100 * confidence:g}% CI"


def format_interval(ci, digits: int = 4, missing: str = "n/a", sep: str = ", ") -> str:
    """``[low, high]`` with ``digits`` decimals, or ``missing`` when the interval is unknown (None or NaN)."""
    low, high = ci
    if low is None or high is None or not (math.isfinite(low) and math.isfinite(high)):
        return missing
    return f"[{format_number(low, digits)}{sep}{format_number(high, digits)}]"


def format_estimate(value: float, ci, digits: int = 4, missing: str = "n/a") -> str:
    """``1.2345 [1.2000, 1.3000]``: a coefficient and its interval (``missing`` for an unknown one)."""
    return f"{format_number(value, digits)} {format_interval(ci, digits, missing)}"


def percentile_interval(samples: np.ndarray, confidence: float, axis: int | None = None):
    """The central ``confidence`` interval of bootstrap ``samples``: (low, high) percentiles.

    The numbers of ``np.percentile(samples, [tail, 100 - tail], axis)`` (its default,
    linear interpolation), bit for bit, computed from one sort: numpy's own percentile
    imports ``numpy.ma`` on first use, a sixth of a short run's start-up.
    """
    tail = 100 * (1 - confidence) / 2
    ordered = np.sort(np.asarray(samples, dtype=float), axis=axis)
    axis = 0 if axis is None else axis
    n = ordered.shape[axis]
    if n == 0:
        raise ValueError("percentile_interval needs at least one sample")
    has_nan = np.isnan(np.take(ordered, -1, axis=axis))  # a NaN sorts last, and makes the percentile NaN
    bounds = []
    for percent in (tail, 100 - tail):
        q = percent / 100
        position = (n - 1) * q  # numpy's virtual index for the linear method
        below = min(max(math.floor(position), 0), n - 1)
        gamma = position - math.floor(position)
        low, high = np.take(ordered, below, axis=axis), np.take(ordered, min(below + 1, n - 1), axis=axis)
        step = high - low
        bound = high - step * (1 - gamma) if gamma >= 0.5 else low + step * gamma  # numpy's lerp, both halves
        bounds.append(np.where(has_nan, np.nan, bound))
    return np.array(bounds)


def _design(f: np.ndarray) -> np.ndarray:
    return np.column_stack([np.ones_like(f), np.log(f)])


def least_squares(f: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(coefficients [a, b], their standard errors, R^2, residual rms)."""
    f, xi = np.asarray(f, float), np.asarray(xi, float)
    if f.shape != xi.shape or f.ndim != 1:
        raise ValueError(f"f and xi must be 1-D arrays of one length. Got shapes {f.shape} and {xi.shape} instead.")
    if np.any(f <= 0) or not np.all(np.isfinite(f)):
        raise ValueError("f must be finite and > 0 for a fit in ln f")
    if np.ptp(np.log(f)) == 0:
        raise ValueError("the fit needs at least two distinct forces")
    design = _design(f)
    coef, *_ = np.linalg.lstsq(design, xi, rcond=None)
    residuals = xi - design @ coef
    ssr = float(residuals @ residuals)
    dof = f.size - 2
    if dof > 0:
        cov = ssr / dof * np.linalg.inv(design.T @ design)
        se = np.sqrt(np.diag(cov))
    else:
        se = np.full(2, np.nan)
    sst = float(((xi - xi.mean()) ** 2).sum())
    r2 = 1.0 - ssr / sst if sst > 0 else (1.0 if ssr == 0 else float("nan"))
    return coef, se, r2, math.sqrt(ssr / f.size)


def fit_curve(f: np.ndarray, xi: np.ndarray) -> LogFit:
    """Least squares of one curve xi(f): coefficients, standard errors, R^2; no intervals."""
    coef, se, r2, rms = least_squares(f, xi)
    return LogFit(
        a=float(coef[0]),
        b=float(coef[1]),
        a_se=float(se[0]),
        b_se=float(se[1]),
        r2=float(r2),
        residual_rms=float(rms),
        points=int(np.size(f)),
    )


def one_blas_thread(function):
    """Run ``function`` with BLAS on the calling thread only. A fit's products are small, and
    OpenBLAS's helper threads, once woken, spin for about 0.1 s of a core's time: taken from
    the worker processes on a machine with as many cores as workers, after every fit
    (a sweep's points, the TUI's interim fits)."""

    @functools.wraps(function)
    def limited(*args, **kwargs):
        with _blas_controller().limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return limited


_controller: tuple[int, object] | None = None  # (modules loaded when it was made, the controller)


def _blas_controller():
    """A controller of the BLAS libraries loaded now: made again once a module has been imported
    since (scipy brings an OpenBLAS of its own, which a controller made before it would not limit)."""
    global _controller
    from threadpoolctl import ThreadpoolController

    loaded = len(sys.modules)
    if _controller is None or _controller[0] != loaded:
        _controller = (loaded, ThreadpoolController())
    return _controller[1]


def bootstrap_coefficients(
    f, xi_per_realization, bootstrap: int, rng: np.random.Generator, average: Average | None = None
) -> np.ndarray:
    """(bootstrap, 2) resampled (a, b) pairs, resampling whole realizations (rows):
    each resample's counts of every realization weight its averaged curve, which is refitted.

    For the mean (``average`` None) the fit is linear in the curve, so a resample's
    coefficients are the resampled mean of each realization's own coefficients:
    (B, M) @ (M, 2). The same ``rng`` state gives the same pairs (``frictionlab predict``
    redraws a run's).
    """
    xi_per_realization = np.atleast_2d(np.asarray(xi_per_realization, float))
    realizations = xi_per_realization.shape[0]
    projector = np.linalg.pinv(_design(np.asarray(f, float)))  # (2, n_forces)
    per_realization = xi_per_realization @ projector.T if average is None else None  # (M, 2)
    widest = realizations if average is None else max(realizations, projector.shape[1])  # counts, or curves
    rows = max(1, BOOTSTRAP_BLOCK_BYTES // (8 * widest))  # this many resamples at once
    pairs = []
    for start in range(0, bootstrap, rows):  # the draws of one call of size=bootstrap, block by block
        counts = resample_counts(rng, realizations, min(rows, bootstrap - start))
        if average is None:
            pairs.append(counts @ per_realization / realizations)
        else:
            pairs.append(average(counts) @ projector.T)  # (B, n_forces) @ (n_forces, 2)
    return np.concatenate(pairs) if pairs else np.empty((0, 2))


def resample_counts(rng: np.random.Generator, realizations: int, resamples: int) -> np.ndarray:
    """(resamples, realizations): how often each realization is drawn in each of ``resamples``
    draws of ``realizations`` with replacement (a multinomial with equal chances), counted from
    uniform indices: a quarter of ``rng.multinomial``'s time, and the same numbers drawn in
    blocks as in one call."""
    drawn = rng.integers(0, realizations, size=(resamples, realizations))
    drawn += np.arange(resamples)[:, None] * realizations  # row r counts into bins r*M .. r*M + M - 1
    return np.bincount(drawn.reshape(-1), minlength=resamples * realizations).reshape(resamples, realizations)


def defined_mean(xi_per_realization: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """The mean over realizations (rows) of the xi that are defined (not NaN) at each
    force, each realization weighted by ``weights`` (M,) or (B, M) (1 for None): an
    ``Average``. NaN at a force where no weighted realization has xi defined."""
    defined = ~np.isnan(xi_per_realization)
    w = np.ones(xi_per_realization.shape[0]) if weights is None else np.asarray(weights, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (w @ np.where(defined, xi_per_realization, 0.0)) / (w @ defined)


def _over_defined(f, xi_per_realization: np.ndarray, average: Average | None):
    """(f, xi, average) of a fit: where some xi is undefined (NaN), the forces where any is
    defined and the mean over the defined ones (``defined_mean``); else as given."""
    if average is not None or not np.isnan(xi_per_realization).any():
        return f, xi_per_realization, average
    fitted = ~np.isnan(xi_per_realization).all(axis=0)
    xi = xi_per_realization[:, fitted]
    return np.asarray(f, float)[fitted], xi, lambda weights: defined_mean(xi, weights)


@one_blas_thread
def resample_pairs(f, xi_per_realization, bootstrap: int, rng: np.random.Generator,
                    average: Average | None = None) -> np.ndarray:  # fmt: skip
    """The (a, b) pairs of ``fit_log_law``'s bootstrap (``bootstrap_coefficients`` over the
    forces and the mean it fits), less any resample without a defined xi at a fitted force."""
    f, xi_per_realization, average = _over_defined(f, np.atleast_2d(np.asarray(xi_per_realization, float)), average)
    samples = bootstrap_coefficients(f, xi_per_realization, bootstrap, rng, average)
    return samples[~np.isnan(samples).any(axis=1)]


@one_blas_thread
def fit_log_law(
    f: np.ndarray,
    xi_per_realization: np.ndarray,
    *,
    bootstrap: int = 1000,
    confidence: float = 0.95,
    rng: np.random.Generator | None = None,
    average: Average | None = None,
) -> LogFit:
    """Fit the mean over realizations (rows) of xi against f (or the curve ``average``
    gives), with percentile bootstrap intervals over realizations.

    A realization may leave xi undefined (NaN) at some forces (no point in contact with
    a slope): the mean is then over the realizations where it is defined
    (``defined_mean``, in the fit and in every resample), the fit leaves out forces
    where none is, and a resample that has none at a fitted force is left out of the
    intervals."""
    xi_per_realization = np.atleast_2d(np.asarray(xi_per_realization, float))
    realizations = xi_per_realization.shape[0]
    if realizations == 0:
        raise ValueError("no finished realization to fit")
    f, xi_per_realization, average = _over_defined(f, xi_per_realization, average)
    curve = xi_per_realization.mean(axis=0) if average is None else average(None)
    fit = fit_curve(f, curve)
    intervals, spread = [NAN2] * 2, NAN2
    if bootstrap > 0 and realizations >= 2:
        if rng is None:
            raise ValueError("bootstrap needs a numpy Generator (rng)")
        samples = resample_pairs(f, xi_per_realization, bootstrap, rng, average)
        if samples.shape[0]:
            low, high = percentile_interval(samples, confidence, axis=0)
            intervals = [(float(low[0]), float(high[0])), (float(low[1]), float(high[1]))]
        one_curve = np.array_equal(xi_per_realization, np.broadcast_to(xi_per_realization[0], xi_per_realization.shape),
                                   equal_nan=True)  # every line alike (a measured one): no spread between lines to say
        if samples.shape[0] >= 2 and not one_curve:
            deviations = np.std(samples, axis=0, ddof=1)
            spread = (float(deviations[0]), float(deviations[1]))
    return replace(
        fit,
        a_se_bootstrap=spread[0],
        b_se_bootstrap=spread[1],
        a_ci=intervals[0],
        b_ci=intervals[1],
        confidence=confidence,
        bootstrap=bootstrap if realizations >= 2 else 0,
    )
