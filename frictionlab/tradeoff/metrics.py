"""Error metrics of the trade-off study and the Pareto front. Pure arrays in,
numbers out: no scenes, no runs.

Every error is relative (a fraction, 0.02 = 2 %), so axes measured in
different units share one plot.
"""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np


def relative_difference(value: float, reference: float) -> float:
    """|value - reference| / |reference| (NaN when either is undefined or the reference is 0)."""
    if not (math.isfinite(value) and math.isfinite(reference)) or reference == 0:
        return math.nan
    return abs(value - reference) / abs(reference)


def _on_reference_axis(x: np.ndarray, y: np.ndarray, x_ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """y(x) interpolated (in ln x) at the points of ``x_ref`` that lie inside the
    range of ``x``; returns (mask over x_ref, interpolated values). Exact when the
    two axes are one."""
    x, y, x_ref = (np.asarray(v, float) for v in (x, y, x_ref))
    # One axis up to rounding (f = F / (k h L) with L = N * (L / N)): compare point by point.
    if x.shape == x_ref.shape and np.allclose(x, x_ref, rtol=1e-9, atol=0.0):
        return np.ones(x_ref.shape, bool), y
    keep = np.isfinite(x) & np.isfinite(y) & (x > 0)
    x, y = x[keep], y[keep]
    if x.size == 0:
        return np.zeros(x_ref.shape, bool), np.empty(0)
    # Average y over repeated x (a contact count that stays put over several loads),
    # so the interpolation abscissae strictly increase.
    unique, inverse = np.unique(x, return_inverse=True)
    y_mean = np.bincount(inverse, weights=y) / np.bincount(inverse)
    inside = np.isfinite(x_ref) & (x_ref >= unique[0]) & (x_ref <= unique[-1]) & (x_ref > 0)
    if unique.size == 1:
        return inside, np.full(int(inside.sum()), y_mean[0])
    return inside, np.interp(np.log(x_ref[inside]), np.log(unique), y_mean)


def curve_errors(x: np.ndarray, xi: np.ndarray, x_ref: np.ndarray, xi_ref: np.ndarray) -> tuple[float, float, int]:
    """Relative error of a curve xi(x) against a reference curve xi_ref(x_ref).

    Compared at the reference's abscissae inside the curve's range (ln-x
    interpolation when the axes differ). Returns (rms of (xi - xi_ref) / xi_ref,
    mean of the same signed: the bias, how many points were compared); NaNs when
    fewer than one point overlaps.
    """
    mask, values = _on_reference_axis(x, xi, x_ref)
    ref = np.asarray(xi_ref, float)[mask]
    good = np.isfinite(values) & np.isfinite(ref) & (ref != 0)
    if not good.any():
        return math.nan, math.nan, 0
    rel = (values[good] - ref[good]) / ref[good]
    return float(np.sqrt(np.mean(rel**2))), float(np.mean(rel)), int(good.sum())


def interval_half_width(interval: tuple[float, float], estimate: float) -> float:
    """Half the width of a confidence interval, relative to |estimate|."""
    low, high = interval
    if not (math.isfinite(low) and math.isfinite(high) and math.isfinite(estimate)) or estimate == 0:
        return math.nan
    return 0.5 * (high - low) / abs(estimate)


def mean_curve_half_width(xi: np.ndarray, sem: np.ndarray, confidence: float) -> float:
    """rms over the loads of the normal-theory half-width of the mean of xi, z * sem / xi."""
    z = NormalDist().inv_cdf(0.5 + confidence / 2)
    rel = z * np.asarray(sem, float) / np.asarray(xi, float)
    rel = rel[np.isfinite(rel)]
    return float(np.sqrt(np.mean(rel**2))) if rel.size else math.nan


def pareto_front(cost, error) -> np.ndarray:
    """Mask of the points no other point beats: a point is dominated when another
    costs no more and errs no more, and is better in at least one. Points with a
    non-finite cost or error are never on the front (nor dominate)."""
    cost, error = np.asarray(cost, float), np.asarray(error, float)
    on_front = np.zeros(cost.shape, bool)
    valid = np.flatnonzero(np.isfinite(cost) & np.isfinite(error))
    # Sweep by cost (ties: smaller error first); keep a point when it lowers the best error so far,
    # or equals the last kept point exactly (a duplicate dominates nothing).
    order = valid[np.lexsort((error[valid], cost[valid]))]
    best, last = math.inf, None
    for i in order:
        if error[i] < best:
            on_front[i], best, last = True, error[i], i
        elif last is not None and error[i] == error[last] and cost[i] == cost[last]:
            on_front[i] = True
    return on_front
