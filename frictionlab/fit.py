"""The fit xi = a + b ln f.

Least squares of the ensemble-mean xi over the force grid, with:
* classical standard errors of a and b from the residuals;
* bootstrap confidence intervals, resampling whole realizations (the
  independent units) with a seeded Generator, and refitting;
* R^2 and the residual rms, because the log law fits poorly at small H.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np


@dataclass(frozen=True)
class LogFit:
    a: float
    b: float
    a_se: float
    b_se: float
    a_ci: tuple[float, float]
    b_ci: tuple[float, float]
    confidence: float
    bootstrap: int
    r2: float
    residual_rms: float
    points: int

    def to_dict(self) -> dict:
        return {k: json_safe(v) for k, v in asdict(self).items()}


def json_safe(value):
    """NaN has no JSON spelling: write null."""
    if isinstance(value, tuple | list):
        return [json_safe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


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


def bootstrap_coefficients(f, xi_per_realization, bootstrap: int, rng: np.random.Generator) -> np.ndarray:
    """(bootstrap, 2) resampled (a, b) pairs, resampling whole realizations (rows).

    The fit is linear in the mean curve, so a resample's coefficients are the
    resampled mean of each realization's own coefficients: (B, M) @ (M, 2).
    The same ``rng`` state gives the same pairs (``frictionlab predict`` redraws a run's).
    """
    xi_per_realization = np.atleast_2d(np.asarray(xi_per_realization, float))
    realizations = xi_per_realization.shape[0]
    projector = np.linalg.pinv(_design(np.asarray(f, float)))  # (2, n_forces)
    per_realization = xi_per_realization @ projector.T  # (M, 2)
    counts = rng.multinomial(realizations, np.full(realizations, 1.0 / realizations), size=bootstrap)
    return counts @ per_realization / realizations


def fit_log_law(
    f: np.ndarray,
    xi_per_realization: np.ndarray,
    *,
    bootstrap: int = 1000,
    confidence: float = 0.95,
    rng: np.random.Generator | None = None,
) -> LogFit:
    """Fit the mean over realizations (rows) of xi against f, with bootstrap intervals."""
    xi_per_realization = np.atleast_2d(np.asarray(xi_per_realization, float))
    realizations = xi_per_realization.shape[0]
    if realizations == 0:
        raise ValueError("no finished realization to fit")
    mean = xi_per_realization.mean(axis=0)
    coef, se, r2, rms = least_squares(f, mean)
    intervals = [(math.nan, math.nan)] * 2
    if bootstrap > 0 and realizations >= 2:
        if rng is None:
            raise ValueError("bootstrap needs a numpy Generator (rng)")
        samples = bootstrap_coefficients(f, xi_per_realization, bootstrap, rng)
        tail = 100 * (1 - confidence) / 2
        low, high = np.percentile(samples, [tail, 100 - tail], axis=0)
        intervals = [(float(low[0]), float(high[0])), (float(low[1]), float(high[1]))]
    return LogFit(
        a=float(coef[0]),
        b=float(coef[1]),
        a_se=float(se[0]),
        b_se=float(se[1]),
        a_ci=intervals[0],
        b_ci=intervals[1],
        confidence=confidence,
        bootstrap=bootstrap if realizations >= 2 else 0,
        r2=float(r2),
        residual_rms=float(rms),
        points=int(np.size(f)),
    )
