"""The numbers of the exact 3D law beyond the log fit: arrays in, numbers out.

* ``contact_area_law``: kappa of A / A0 = kappa p / (E* rms gradient) at small loads,
  with a bootstrap interval over realizations;
* ``nayak_parameter``: the breadth of a surface's spectrum, alpha = m0 m4 / m2^2 of
  its profiles (1 for a single wave, growing with the band);
* ``relative_gap``: how far one curve is from another at the same loads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..fit import percentile_interval

SMALL_LOAD_FRACTION = 0.05  # contact fraction below which the area is taken to grow linearly


@dataclass(frozen=True)
class Kappa:
    value: float
    interval: tuple[float, float]
    loads: int  # load steps averaged (those of mean contact fraction <= the bound)
    largest_fraction: float  # the mean contact fraction of the largest of them


def contact_area_law(
    fraction: np.ndarray,
    force: np.ndarray,
    area: float,
    stiffness: float,
    gradient: np.ndarray,
    *,
    rng: np.random.Generator,
    bootstrap: int = 1000,
    confidence: float = 0.95,
    max_fraction: float = SMALL_LOAD_FRACTION,
) -> Kappa:
    """kappa = (A / A0) E* g / p per realization (rows of ``fraction``, shape
    (realizations, loads)) and load, with p = F / A0 the nominal pressure and g the
    realization's rms gradient (``gradient``); averaged over the loads whose mean contact
    fraction is at most ``max_fraction`` (the two smallest loads if none is), then over
    realizations, with a percentile bootstrap over realizations."""
    fraction = np.atleast_2d(np.asarray(fraction, float))
    force = np.asarray(force, float)
    gradient = np.asarray(gradient, float).reshape(-1, 1)
    if fraction.shape[1] != force.size or gradient.shape[0] != fraction.shape[0]:
        raise ValueError(f"shapes differ: fraction {fraction.shape}, force {force.shape}, gradient {gradient.shape}")
    pressure = force / area
    per_load = fraction * stiffness * gradient / pressure
    mean_fraction = fraction.mean(axis=0)
    small = np.flatnonzero(mean_fraction <= max_fraction)
    if small.size < 2:
        small = np.argsort(mean_fraction)[:2]
    per_realization = per_load[:, small].mean(axis=1)
    value = float(per_realization.mean())
    interval = (math.nan, math.nan)
    rows = per_realization.size
    if bootstrap > 0 and rows >= 2:
        counts = rng.multinomial(rows, np.full(rows, 1.0 / rows), size=bootstrap)
        low, high = percentile_interval(counts @ per_realization / rows, confidence)
        interval = (float(low), float(high))
    return Kappa(value, interval, int(small.size), float(mean_fraction[small].max()))


def nayak_parameter(heights: np.ndarray, spacing: float) -> float:
    """alpha = m0 m4 / m2^2 of the profiles of a periodic surface along x (its rows),
    with m0 = <z^2>, m2 = <(dz/dx)^2>, m4 = <(d2z/dx2)^2> from the spectrum (exact
    derivatives; the mean and the Nyquist column dropped). For an isotropic surface
    it is the same in every direction."""
    z = np.asarray(heights, float)
    points = z.shape[-1]
    spectrum = np.fft.rfft(z - z.mean(), axis=-1)
    q = 2.0 * np.pi * np.fft.rfftfreq(points, d=spacing)
    weight = np.full(q.size, 2.0)  # each column stands for q and -q
    weight[0] = 0.0
    if points % 2 == 0:
        weight[-1] = 0.0  # the Nyquist mode has no real derivative
    power = (np.abs(spectrum) ** 2 * weight).sum(axis=tuple(range(z.ndim - 1)))
    m0, m2, m4 = (float(np.sum(power * q**order)) for order in (0, 2, 4))
    if m2 == 0.0:
        raise ValueError("the surface has no slope: its Nayak parameter is undefined")
    return m0 * m4 / m2**2


def relative_gap(values: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """(values - reference) / reference, point by point."""
    values, reference = np.asarray(values, float), np.asarray(reference, float)
    return (values - reference) / reference
