"""The statistics the page needs to say "converged" and "a log law holds": arrays in,
numbers out, each checked against a known answer (tests/exact3d/test_statistics.py).

* ``paired_bootstrap``: a statistic of several ensembles of the same surfaces (rows
  aligned), with a percentile bootstrap that resamples the surfaces jointly, so that a
  difference between two grids carries only the noise that does not cancel;
* ``richardson``: the continuum limit of a quantity on three grids refined by a fixed
  ratio, with the observed order; ``extrapolate``: the same on every bootstrap draw, so
  that the interval holds the order's uncertainty as well as the sampling's;
* ``compare_models``: the log law against a power law and a log law with curvature, by
  AIC, BIC and the runs test on the residuals' signs.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..compute.fit import percentile_interval

# the order of convergence taken when three grids cannot give it (differences of unlike
# sign, or not shrinking): the slowest a pixel perimeter error decays, one over the resolution
FALLBACK_ORDER = 1.0
ORDER_RANGE = (0.5, 4.0)  # orders outside are taken as not estimated (a bootstrap draw's is clipped into it)


@dataclass(frozen=True)
class Estimate:
    value: float | np.ndarray  # a number, or one per component of a statistic that returns several
    interval: tuple  # (low, high), numbers or arrays like value (nan without a draw)
    draws: np.ndarray  # the statistic on each bootstrap draw, (bootstrap, *value's shape); empty without one


def paired_bootstrap(
    samples: Sequence[np.ndarray],
    statistic: Callable[..., float | np.ndarray],
    *,
    rng: np.random.Generator,
    bootstrap: int = 1000,
    confidence: float = 0.95,
) -> Estimate:
    """``statistic(*samples)`` and its percentile interval over ``bootstrap`` draws that
    resample the surfaces (axis 0, the same rows of every sample: paired). A statistic may
    return several numbers (the three grids' values of a quantity): each gets its interval,
    and the draws keep them together."""
    count = {np.shape(s)[0] for s in samples}
    if len(count) != 1:
        raise ValueError(f"paired samples need the same surfaces in each: got {sorted(count)} rows")
    n = count.pop()
    value = np.asarray(statistic(*samples), float)
    if bootstrap <= 0 or n < 2:
        nan = np.full(value.shape, math.nan)
        return Estimate(_plain(value), (_plain(nan), _plain(nan)), np.empty((0, *value.shape)))
    draws = np.empty((bootstrap, *value.shape))
    for i in range(bootstrap):
        rows = rng.integers(0, n, n)
        draws[i] = statistic(*(np.asarray(s)[rows] for s in samples))
    finite = draws[np.all(np.isfinite(draws.reshape(bootstrap, -1)), axis=1)]
    if finite.shape[0]:
        low, high = percentile_interval(finite, confidence, axis=0)
    else:
        low = high = np.full(value.shape, math.nan)
    return Estimate(_plain(value), (_plain(low), _plain(high)), draws)


def _plain(values: np.ndarray) -> float | np.ndarray:
    values = np.asarray(values, float)
    return float(values) if values.ndim == 0 else values


@dataclass(frozen=True)
class Extrapolation:
    limit: float  # the continuum value (the finest grid's where the order was not estimated)
    order: float  # the observed order p (nan where not estimated)
    estimated: bool  # whether the three grids gave an order in ORDER_RANGE
    interval: tuple[float, float] = (math.nan, math.nan)  # with the order's and the sampling's uncertainty
    reason: str = ""  # why the order was not estimated


def _order_ratio(order: float, points: Sequence[float]) -> float:
    """(Q1 - Q2) / (Q2 - Q3) of Q(N) = Q + C N^-order on the grids ``points``."""
    h = [1.0 / float(n) for n in points]
    return (h[0] ** order - h[1] ** order) / (h[1] ** order - h[2] ** order)


def _order(d1: float, d2: float, points: Sequence[float]) -> float:
    """The order p whose ratio of successive changes is d1 / d2 (bisection: the ratio grows with
    p), or nan when no p in ORDER_RANGE gives it."""
    target = d1 / d2
    low, high = ORDER_RANGE
    if not _order_ratio(low, points) <= target <= _order_ratio(high, points):
        return math.nan
    step = float(points[1]) / float(points[0])
    if math.isclose(float(points[2]) / float(points[1]), step) and step > 1.0:  # a ratio of step^p: closed form
        return math.log(target) / math.log(step)
    for _ in range(100):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if _order_ratio(mid, points) < target else (low, mid)
    return 0.5 * (low + high)


def _limit(values: Sequence[float], points: Sequence[float], order: float) -> float:
    """Q3 + (Q3 - Q2) N3^-p / (N2^-p - N3^-p): the limit of Q(N) = Q + C N^-p through the last two."""
    h2, h3 = 1.0 / float(points[1]) ** order, 1.0 / float(points[2]) ** order
    return float(values[2]) + (float(values[2]) - float(values[1])) * h3 / (h2 - h3)


def richardson(values: Sequence[float], points: Sequence[float] = (512, 1024, 2048)) -> Extrapolation:
    """The limit of Q(N) = Q + C N^-p from Q on three grids of ``points`` pixels a side
    (``values``, coarsest first), p the observed order: the one whose successive changes
    have the ratio observed (ln(d1 / d2) / ln 2 on grids doubled each time). Where the
    changes differ in sign, do not shrink, or need p outside ORDER_RANGE, the order is not
    estimated: the finest value is the limit, and ``reason`` says why."""
    q1, q2, q3 = map(float, values)
    d1, d2 = q2 - q1, q3 - q2
    if d2 == 0.0:
        if d1 == 0.0:
            return Extrapolation(q3, math.inf, True)
        return Extrapolation(q3, math.nan, False, reason="the last change is zero, the one before is not")
    if d1 == 0.0 or d1 * d2 < 0:
        return Extrapolation(q3, math.nan, False, reason="the changes between grids differ in sign")
    if abs(d2) >= abs(d1):
        return Extrapolation(q3, math.nan, False, reason="the changes between grids do not shrink")
    order = _order(d1, d2, points)
    if not math.isfinite(order):
        return Extrapolation(q3, math.nan, False,
                             reason=f"their ratio needs an order outside {ORDER_RANGE[0]:g} to {ORDER_RANGE[1]:g}")  # fmt: skip
    return Extrapolation(_limit(values, points, order), order, True)


def extrapolate(
    values: Sequence[float], draws: np.ndarray, points: Sequence[float] = (512, 1024, 2048), confidence: float = 0.95
) -> Extrapolation:
    """``richardson`` of ``values`` with an interval from ``draws`` (bootstrap, 3: the three
    grids' values on each paired draw), each draw extrapolated with its own order, clipped
    into ORDER_RANGE (FALLBACK_ORDER where its changes differ in sign). Where the order of
    ``values`` is not estimated, the interval spans the finest grid's and the limit at
    FALLBACK_ORDER, with both's sampling: the page then says so."""
    point = richardson(values, points)
    draws = np.asarray(draws, float).reshape(-1, 3)
    if not draws.shape[0]:
        return point
    limits = []
    low_ratio, high_ratio = (_order_ratio(p, points) for p in ORDER_RANGE)
    for row in draws:
        d1, d2 = row[1] - row[0], row[2] - row[1]
        if d1 * d2 > 0:
            ratio = float(np.clip(d1 / d2, low_ratio, high_ratio))
            order = _order(ratio * d2, d2, points)
            order = order if math.isfinite(order) else FALLBACK_ORDER
        else:
            order = FALLBACK_ORDER
        limits.append(_limit(row, points, order))
    if point.estimated:
        low, high = percentile_interval(np.array(limits), confidence)
        return Extrapolation(point.limit, point.order, True, (float(low), float(high)))
    finest = percentile_interval(draws[:, 2], confidence)
    fallback = percentile_interval(np.array([_limit(r, points, FALLBACK_ORDER) for r in draws]), confidence)
    interval = (float(min(finest[0], fallback[0])), float(max(finest[1], fallback[1])))
    return Extrapolation(point.limit, point.order, False, interval, point.reason)


# ------------------------------------------------------------------ the model test

MODELS = ("log law", "power law", "log law + curvature")


@dataclass(frozen=True)
class ModelFit:
    name: str
    params: tuple[float, ...]
    residuals: np.ndarray
    aic: float
    bic: float
    runs_z: float  # the runs test on the residuals' signs: z < -2, fewer runs than chance (structure left)


def runs_test(residuals: np.ndarray) -> float:
    """Wald-Wolfowitz z of the number of runs of like signs in ``residuals`` (in load order):
    about 0 for residuals of independent signs, strongly negative when a curve is left in them."""
    signs = np.sign(np.asarray(residuals, float))
    signs = signs[signs != 0]
    plus, minus = int(np.sum(signs > 0)), int(np.sum(signs < 0))
    n = plus + minus
    if plus == 0 or minus == 0 or n < 3:
        return -math.inf if n >= 3 else math.nan  # one sign throughout: as structured as it gets
    runs = 1 + int(np.count_nonzero(signs[1:] != signs[:-1]))
    mean = 2.0 * plus * minus / n + 1.0
    variance = (mean - 1.0) * (mean - 2.0) / (n - 1.0)
    return (runs - mean) / math.sqrt(variance) if variance > 0 else math.nan


def _criteria(residuals: np.ndarray, params: int) -> tuple[float, float]:
    """(AIC, BIC) of a least-squares fit with Gaussian errors of unknown variance."""
    n = residuals.size
    rss = max(float(np.sum(residuals**2)), 1e-300)
    base = n * math.log(rss / n)
    return base + 2 * params, base + params * math.log(n)


def fit_models(f: np.ndarray, xi: np.ndarray) -> dict[str, ModelFit]:
    """The three models of xi(f) by least squares in xi: a + b ln f; c f^beta (from the
    straight line in ln xi, then Gauss-Newton in xi); a + b ln f + c (ln f)^2."""
    x, y = np.log(np.asarray(f, float)), np.asarray(xi, float)
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    fits = {}
    for name, degree in (("log law", 1), ("log law + curvature", 2)):
        coeffs = np.polyfit(x, y, degree)
        fits[name] = (tuple(coeffs[::-1]), y - np.polyval(coeffs, x))
    beta, log_c = np.polyfit(x, np.log(np.clip(y, 1e-300, None)), 1) if np.all(y > 0) else (0.0, math.log(abs(y.mean())))
    c = math.exp(log_c)
    for _ in range(50):  # Gauss-Newton on y = c exp(beta x)
        model = c * np.exp(beta * x)
        jac = np.column_stack([model / c, model * x])
        step, *_ = np.linalg.lstsq(jac, y - model, rcond=None)
        c, beta = c + step[0], beta + step[1]
        if np.all(np.abs(step) <= 1e-12 * (1 + np.abs([c, beta]))):
            break
    fits["power law"] = ((c, beta), y - c * np.exp(beta * x))
    out = {}
    for name in MODELS:
        params, residuals = fits[name]
        aic, bic = _criteria(residuals, len(params))
        out[name] = ModelFit(name, tuple(map(float, params)), residuals, aic, bic, runs_test(residuals))
    return out


def preferred(fits: dict[str, ModelFit], criterion: str = "bic", margin: float = 2.0) -> str | None:
    """The model whose criterion is lowest by at least ``margin`` (2: "positive evidence"
    on the usual scale), else None: the data do not tell the best two apart."""
    ranked = sorted(fits.values(), key=lambda m: getattr(m, criterion))
    if len(ranked) < 2 or getattr(ranked[1], criterion) - getattr(ranked[0], criterion) >= margin:
        return ranked[0].name
    return None


@dataclass(frozen=True)
class ModelTest:
    """The model test on the mean curve and on each surface's curve."""

    mean: dict[str, ModelFit]
    mean_choice: str | None  # by BIC, None when the best two are within the margin
    per_surface: dict[str | None, int]  # how many surfaces prefer each model by BIC (None: undecided)
    f_range: tuple[float, float]


def compare_models(f: np.ndarray, xi_rows: np.ndarray) -> ModelTest:
    """The model test of xi(f): on the mean over the surfaces (rows of ``xi_rows``) and per surface."""
    xi_rows = np.atleast_2d(np.asarray(xi_rows, float))
    mean = fit_models(f, np.nanmean(xi_rows, axis=0))
    counts: dict[str | None, int] = {name: 0 for name in (*MODELS, None)}
    for row in xi_rows:
        counts[preferred(fit_models(f, row))] += 1
    return ModelTest(mean, preferred(mean), counts, (float(np.min(f)), float(np.max(f))))
