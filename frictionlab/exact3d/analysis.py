"""The numbers of the exact 3D law beyond the log fit: arrays in, numbers out.

* ``contact_area_law``: kappa of A / A0 = kappa p / (E* rms gradient) over a window of
  contact fractions, with a bootstrap interval over realizations; ``kappa_curve``: kappa
  at each load, against p / (E* rms gradient), with a bootstrap band;
* ``height_moments``: a surface's height skewness and kurtosis (0 and 3 for a Gaussian);
* ``nayak_parameter``: the breadth of a surface's spectrum, alpha = m0 m4 / m2^2 of
  its profiles (1 for a single wave, growing with the band);
* ``relative_gap``: how far one curve is from another at the same loads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..compute.ensemble import area_law_ratio
from ..compute.fit import percentile_interval

SMALL_LOAD_FRACTION = 0.05  # contact fraction below which the area is taken to grow linearly
KAPPA_WINDOW = (0.005, SMALL_LOAD_FRACTION)  # contact fractions where simulations find kappa of about 2 to 2.3
FEW_SPOTS = (0.0, 0.003)  # contact fractions of a handful of spots per surface, shown apart
# kappa in the literature: the vanishing-load limit (Bush, Gibson and Thomas), Persson's theory,
# and what simulations find at 0.5-5 % contact
KAPPA_BUSH = math.sqrt(2 * math.pi)
KAPPA_PERSSON = math.sqrt(8 / math.pi)
KAPPA_SIMULATIONS = (2.0, 2.3)


@dataclass(frozen=True)
class Kappa:
    value: float  # nan when no load's mean contact fraction lies in the window
    interval: tuple[float, float]
    loads: int  # load steps averaged (those whose mean contact fraction lies in the window)
    largest_fraction: float  # the mean contact fraction of the largest of them (nan without any)


@dataclass(frozen=True)
class KappaCurve:
    """kappa at each load (the mean over realizations, with a bootstrap band), against
    x = p / (E* g), g the realizations' mean rms gradient, and the mean contact fraction."""

    x: np.ndarray
    value: np.ndarray
    low: np.ndarray
    high: np.ndarray
    fraction: np.ndarray


def _per_load_kappa(fraction, force, area, stiffness, gradient) -> tuple[np.ndarray, np.ndarray]:
    """(kappa per realization and load, the pressure p = F / A0 per load), checked shapes."""
    force = np.asarray(force, float)
    return area_law_ratio(fraction, force, area, stiffness, np.asarray(gradient, float).ravel()), force / area


def _bootstrap_means(rows: np.ndarray, rng: np.random.Generator, bootstrap: int) -> np.ndarray | None:
    """The means of ``bootstrap`` resamples of the realizations (axis 0), or None for fewer than 2."""
    count = rows.shape[0]
    if bootstrap <= 0 or count < 2:
        return None
    weights = rng.multinomial(count, np.full(count, 1.0 / count), size=bootstrap) / count
    return weights @ rows


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
    window: tuple[float, float] = (0.0, SMALL_LOAD_FRACTION),
) -> Kappa:
    """kappa = (A / A0) E* g / p per realization (rows of ``fraction``, shape
    (realizations, loads)) and load, with p = F / A0 the nominal pressure and g the
    realization's rms gradient (``gradient``); averaged over the loads whose mean contact
    fraction lies in ``window`` (low exclusive, high inclusive), then over realizations,
    with a percentile bootstrap over realizations. No load in the window: kappa is nan."""
    per_load, _ = _per_load_kappa(fraction, force, area, stiffness, gradient)
    mean_fraction = np.atleast_2d(np.asarray(fraction, float)).mean(axis=0)
    inside = np.flatnonzero((mean_fraction > window[0]) & (mean_fraction <= window[1]))
    if inside.size == 0:
        return Kappa(math.nan, (math.nan, math.nan), 0, math.nan)
    per_realization = per_load[:, inside].mean(axis=1)
    means = _bootstrap_means(per_realization, rng, bootstrap)
    interval = (math.nan, math.nan) if means is None else tuple(map(float, percentile_interval(means, confidence)))
    return Kappa(float(per_realization.mean()), interval, int(inside.size), float(mean_fraction[inside].max()))


def kappa_curve(
    fraction: np.ndarray,
    force: np.ndarray,
    area: float,
    stiffness: float,
    gradient: np.ndarray,
    *,
    rng: np.random.Generator,
    bootstrap: int = 1000,
    confidence: float = 0.95,
) -> KappaCurve:
    """kappa at every load (as ``contact_area_law`` forms it per realization), its mean
    over realizations and a percentile bootstrap band, against p / (E* g)."""
    per_load, pressure = _per_load_kappa(fraction, force, area, stiffness, gradient)
    value = per_load.mean(axis=0)
    means = _bootstrap_means(per_load, rng, bootstrap)
    low, high = (np.full(value.shape, math.nan),) * 2 if means is None else percentile_interval(means, confidence, axis=0)
    x = pressure / (stiffness * float(np.mean(gradient)))
    fraction = np.atleast_2d(np.asarray(fraction, float)).mean(axis=0)
    return KappaCurve(x, value, np.asarray(low, float), np.asarray(high, float), fraction)


def height_moments(heights: np.ndarray) -> tuple[float, float]:
    """(skewness, kurtosis) of a surface's heights: <(z - mean)^3> / s^3 and <(z - mean)^4> / s^4
    (0 and 3 for Gaussian heights)."""
    z = np.asarray(heights, float).ravel()
    z = z - z.mean()
    variance = float(np.mean(z * z))
    if variance == 0.0:
        raise ValueError("the surface is flat: its skewness and kurtosis are undefined")
    return float(np.mean(z**3)) / variance**1.5, float(np.mean(z**4)) / variance**2


def nayak_parameter(heights: np.ndarray, spacing: float) -> float:
    """alpha = m0 m4 / m2^2 of the profiles of a periodic surface along x (its rows),
    each about its own mean, as a profile trace is: m0 = <(z - row mean)^2>, m2 =
    <(dz/dx)^2>, m4 = <(d2z/dx2)^2> from the spectrum (exact derivatives; the column
    q_x = 0, the rows' means, and the Nyquist column dropped). m0 is therefore below
    the surface's <z^2> by the variance of its waves along y alone (about 6 % with a
    long cut-off of a quarter of the side, a fifth to a third with the side). For an
    isotropic surface it is the same in every direction."""
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
