"""Band-limited resampling of a map, onto square pixels or onto coarser ones, by its cosine
series: a scan's ends do not meet, so its samples are taken as one half of their even
extension (the map reflected across its edges, as the MDR-equivalent line takes it), whose
Fourier series is the discrete cosine transform (DCT-II). That series is band-limited and
passes through every sample; evaluating it on a new grid is interpolation without a step
where the scan ends (a plain FFT would put the jump between the first and last rows into
every mode). For a coarser grid the modes above the new grid's Nyquist wavenumber are
dropped first: an ideal low-pass, so no wavelength shorter than two new pixels folds back as
a false long one (aliasing), and every wavelength longer than that keeps its amplitude
(block averaging damps them by up to 36 % at the new Nyquist wavenumber and lets some
shorter ones through).
"""

from __future__ import annotations

import math

import numpy as np


def cosine_resample(z: np.ndarray, axis: int, step: float, new_step: float) -> np.ndarray:
    """``z`` sampled every ``step`` along ``axis`` (the first sample at 0), resampled every
    ``new_step`` from 0 to the last sample, by its band-limited cosine series; for a coarser
    grid, the modes the new grid cannot hold (shorter than two new pixels) are dropped."""
    import scipy.fft  # imported on first use

    n = z.shape[axis]
    points = resampled_points(n, step, new_step)
    coefficients = scipy.fft.dct(z, type=2, axis=axis, norm="ortho")
    ratio = step / new_step
    kept = n if ratio >= 1 else max(1, math.ceil(n * ratio - 1e-9))  # k < n * step / new_step: below the new Nyquist
    t = np.arange(points, dtype=np.float64) / ratio
    k = np.arange(kept, dtype=np.float64)
    # the inverse orthonormal DCT-II, evaluated off the grid: z(t) = sum_k w_k c_k cos(pi k (t + 1/2) / n)
    weights = np.full(kept, math.sqrt(2.0 / n))
    weights[0] = math.sqrt(1.0 / n)
    basis = weights[None, :] * np.cos(np.pi * np.outer(t + 0.5, k) / n)  # (points, kept)
    kept_coefficients = np.take(coefficients, np.arange(kept), axis=axis)
    return np.moveaxis(np.tensordot(basis, np.moveaxis(kept_coefficients, axis, 0), axes=1), 0, axis)


def resampled_points(n: int, step: float, new_step: float) -> int:
    """Points of ``n`` samples every ``step`` resampled every ``new_step`` (``cosine_resample``):
    positions m new_step from the first sample to the last."""
    return math.floor((n - 1) * step / new_step + 1e-9) + 1
